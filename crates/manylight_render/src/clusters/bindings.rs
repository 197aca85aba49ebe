//! The layouts and bind groups over the cluster buffers: the build's, and the ones the
//! shading, `cluster_depth` and `light_refine` passes read; re-made when a buffer grew.

use super::buffers::ClusterBuffers;
use crate::bindings::Binding;
use crate::context::GpuContext;
use crate::layouts::{
    CLUSTER_BUILD_GROUP, CLUSTER_DEPTH_GROUP, CLUSTER_LISTS_GROUP, GroupLayout, LIGHT_REFINE_GROUP,
    LIGHT_SPHERES_GROUP,
};
use crate::shaders::ShaderDefs;

/// The cluster groups' layouts, and the two groups made over one view's buffers.
pub struct ClusterBindings {
    /// Layout of the build's group 0 ([`CLUSTER_BUILD_GROUP`]).
    pub build_layout: GroupLayout,
    /// Layout of the build's first dispatch, the lights' view-space spheres
    /// ([`LIGHT_SPHERES_GROUP`]; its group reads the scene's light buffer, so the pass makes
    /// it through the binding cache).
    pub spheres_layout: GroupLayout,
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
            spheres_layout: LIGHT_SPHERES_GROUP.create_layout(&gpu.device, defs),
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
