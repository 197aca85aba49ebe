//! The layouts and bind groups over the cluster buffers: the build's, and the ones the
//! shading, `cluster_depth` and `light_refine` passes read; re-made when a buffer grew.

use super::buffers::ClusterBuffers;
use crate::bindings::Binding;
use crate::context::GpuContext;
use crate::layouts::{BindGroupDecl, BindingDecl, GroupLayout, SHADING};
use crate::shaders::ShaderDefs;

const COMPUTE: wgpu::ShaderStages = wgpu::ShaderStages::COMPUTE;

/// Group 0 of the cluster build (`shaders/cluster_build.wgsl`): the parameters, the cluster
/// bounds and light spheres it reads, the lists it writes, its counters, and the per-tile
/// bounds and lists.
pub static CLUSTER_BUILD_GROUP: BindGroupDecl = BindGroupDecl {
    label: "cluster_build",
    entries: &[
        BindingDecl::uniform(0, "params", COMPUTE),
        BindingDecl::storage(1, "bounds", COMPUTE),
        BindingDecl::storage(2, "spheres", COMPUTE),
        BindingDecl::storage_rw(3, "ranges", COMPUTE),
        BindingDecl::storage_rw(4, "indices", COMPUTE),
        BindingDecl::storage_rw(5, "build", COMPUTE),
        BindingDecl::storage(6, "tile_bounds", COMPUTE),
        BindingDecl::storage_rw(7, "tile_ranges", COMPUTE),
        BindingDecl::storage_rw(8, "tile_indices", COMPUTE),
    ],
};

/// Group 2 of the passes that shade through the cluster lists (`common/cluster_lists.wgsl`,
/// `tiled_deferred.wgsl`): the parameters, each cluster's range and the light indices.
pub static CLUSTER_LISTS_GROUP: BindGroupDecl = BindGroupDecl {
    label: "cluster_lists",
    entries: &[
        BindingDecl::uniform(0, "cluster_params", SHADING),
        BindingDecl::storage(1, "cluster_ranges", SHADING),
        BindingDecl::storage(2, "cluster_indices", SHADING),
    ],
};

/// Group 2 of the `cluster_depth` pass (`shaders/cluster_depth.wgsl`): the parameters, and the
/// ranges buffer, whose per-cluster depth ranges it writes after the cluster ranges.
pub static CLUSTER_DEPTH_GROUP: BindGroupDecl = BindGroupDecl {
    label: "cluster_depth",
    entries: &[
        BindingDecl::storage(0, "cluster_params", COMPUTE),
        BindingDecl::storage_rw(1, "cluster_depths", COMPUTE),
    ],
};

/// Group 2 of the `light_refine` pass (`shaders/light_refine.wgsl`): the parameters, the light
/// spheres, and the ranges and index buffers, whose refined part it writes.
pub static LIGHT_REFINE_GROUP: BindGroupDecl = BindGroupDecl {
    label: "light_refine",
    entries: &[
        BindingDecl::storage(0, "cluster_params", COMPUTE),
        BindingDecl::storage(1, "spheres", COMPUTE),
        BindingDecl::storage_rw(2, "ranges", COMPUTE),
        BindingDecl::storage_rw(3, "indices", COMPUTE),
    ],
};

/// The cluster groups' layouts, and the two groups made over one view's buffers.
pub struct ClusterBindings {
    /// Layout of the build's group 0 ([`CLUSTER_BUILD_GROUP`]).
    pub build_layout: GroupLayout,
    /// Layout of the shading passes' cluster group ([`CLUSTER_LISTS_GROUP`]).
    pub lists_layout: GroupLayout,
    /// Layout of group 2 of the `cluster_depth` pass ([`CLUSTER_DEPTH_GROUP`]).
    pub depth_layout: GroupLayout,
    /// Layout of group 2 of the `light_refine` pass ([`LIGHT_REFINE_GROUP`]).
    pub refine_layout: GroupLayout,
    /// Group 0 of the build.
    pub build_group: wgpu::BindGroup,
    /// The shading passes' group.
    pub lists_group: wgpu::BindGroup,
    /// The buffers' generations the groups were made for.
    generations: [u64; 8],
}

impl ClusterBindings {
    /// The layouts, and the groups over `buffers`.
    pub fn new(gpu: &GpuContext, buffers: &ClusterBuffers) -> ClusterBindings {
        let defs = ShaderDefs::default();
        let build_layout = CLUSTER_BUILD_GROUP.create_layout(&gpu.device, defs);
        let lists_layout = CLUSTER_LISTS_GROUP.create_layout(&gpu.device, defs);
        let (build_group, lists_group) = Self::groups(gpu, &build_layout, &lists_layout, buffers);
        ClusterBindings {
            build_layout,
            lists_layout,
            depth_layout: CLUSTER_DEPTH_GROUP.create_layout(&gpu.device, defs),
            refine_layout: LIGHT_REFINE_GROUP.create_layout(&gpu.device, defs),
            build_group,
            lists_group,
            generations: buffers.generations(),
        }
    }

    fn groups(
        gpu: &GpuContext,
        build_layout: &GroupLayout,
        lists_layout: &GroupLayout,
        b: &ClusterBuffers,
    ) -> (wgpu::BindGroup, wgpu::BindGroup) {
        let build = [
            &b.params,
            b.bounds.buffer(),
            b.spheres.buffer(),
            b.ranges.buffer(),
            b.indices.buffer(),
            b.counters.buffer(),
            b.tile_bounds.buffer(),
            b.tile_ranges.buffer(),
            b.tile_indices.buffer(),
        ]
        .map(Binding::Buffer);
        let lists = [&b.params, b.ranges.buffer(), b.indices.buffer()].map(Binding::Buffer);
        (build_layout.create_bind_group(gpu, &build), lists_layout.create_bind_group(gpu, &lists))
    }

    /// Makes the groups again when one of `buffers` was re-created (it grew).
    pub fn rebind_if_grown(&mut self, gpu: &GpuContext, buffers: &ClusterBuffers) {
        let generations = buffers.generations();
        if generations != self.generations {
            (self.build_group, self.lists_group) =
                Self::groups(gpu, &self.build_layout, &self.lists_layout, buffers);
            self.generations = generations;
        }
    }
}
