//! Clustered forward for devices without storage buffers or compute shaders: WebGL2, through
//! wgpu's GL backend. The WebGL clustered renderers build their clusters on the CPU and hand
//! the lists to the fragment shader in textures; this path does the same with the CPU twin of
//! the GPU build (`manylight_core::cluster::assign_lights`, checked light for light against it).
//! One frame, one view:
//!
//! 1. **Lights**: every point and spot light in the frame's order, an animated one at the
//!    frame's time (`manylight_core::AnimatedLight`, the CPU twin of the light animation
//!    pass), packed as the light buffer packs it into an `Rgba32Float` texture, three texels
//!    a light ([`lists::FrameLights`]).
//! 2. **Lists**: the view's cluster grid, as the GPU build makes it (the settings' grid and
//!    culling test, an infinite projection sliced up to what the lights reach); the CPU
//!    assignment's `(offset, count)` per cluster into an `Rg32Uint` texture and the light
//!    indices into an `R32Uint` one.
//! 3. **Draw**: one render pass into the sRGB output, reverse-Z depth; each instance is one
//!    draw whose transforms are per-instance vertex attributes (no storage buffer). The
//!    fragment shader (`shaders/texture_lists.wgsl`) shades its cluster's lights and tone maps,
//!    and marks a pixel whose HDR colour was not finite with alpha 0.
//! 4. **Report**: the frame's report names its two passes (`cluster_assign` on the CPU,
//!    `texture_lists` on the GPU, without GPU times) and the assignment's cluster statistics;
//!    the caller reads the image back and counts the marked pixels
//!    ([`lists::take_nonfinite`]) into `nonfinite_pixels`.
//!
//! What the path does not draw is a downgrade, not an error, and the report says which ran:
//! its pipeline is `clustered-forward` whatever was asked, it draws no shadows (no shadow
//! report), no bloom or motion blur, no debug view, only the first view, and no blended
//! material (each warned about once).

pub mod lists;
mod pipeline;
pub mod textures;

use crate::layouts::{TEXTURE_LISTS_GROUP, TEXTURE_LISTS_VIEW_GROUP};

use crate::assets::SceneAssets;
use crate::bindings::Binding;
use crate::context::{GpuContext, RenderError};
use crate::gpu_types::{GpuClusterParams, GpuInstance, ViewUniform};
use crate::layouts::GroupLayout;
use crate::lights::pack_directional_lights;
use crate::readback::HeadlessTarget;
use crate::resources::view_uniform;
use crate::resources::{DEPTH_FORMAT, SurfaceVariant};
use crate::shaders::ShaderDefs;
use crate::snapshot::{FrameSnapshot, PipelineKind, RenderView};
use crate::stats::{FrameReport, PassTiming, ViewReport};
use glam::{Mat4, UVec2, Vec3};
use lists::{FrameLights, TEXELS_PER_LIGHT, padded};
use pipeline::{create_pipeline, instance_buffer, lists_group};
use std::collections::HashMap;
use textures::ListTexture;

/// The shader of the path.
pub const SHADER: &str = "texture_lists.wgsl";

/// Texels a row of the list textures (at most the device's largest texture side): 4096 rows of
/// it hold 16 M list entries.
pub const LIST_TEXTURE_WIDTH: u32 = 4096;

/// One draw: an instance of a mesh with a material.
struct Draw {
    mesh: usize,
    material: usize,
    order: (u64, u64),
    variant: SurfaceVariant,
}

/// The output target and its depth buffer, made again when the size changes.
struct Target {
    color: HeadlessTarget,
    depth: wgpu::TextureView,
}

/// Everything the texture-list path keeps across frames. Over 15 fields: it is a renderer of its
/// own (device, layouts, pipeline, the three list textures, uniforms, vertex buffers, target and
/// the CPU lists it refills), kept flat so that one frame's steps borrow each part apart.
pub struct TextureListRenderer {
    gpu: GpuContext,
    assets: SceneAssets,
    view_layout: GroupLayout,
    lists_layout: GroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
    module: wgpu::ShaderModule,
    pipelines: HashMap<SurfaceVariant, wgpu::RenderPipeline>,
    view_buffer: wgpu::Buffer,
    params_buffer: wgpu::Buffer,
    view_group: wgpu::BindGroup,
    lights: ListTexture,
    ranges: ListTexture,
    indices: ListTexture,
    lists_group: wgpu::BindGroup,
    instances: wgpu::Buffer,
    target: Option<Target>,
    warned: Vec<&'static str>,
}

impl TextureListRenderer {
    /// The path's layouts, shader and textures on `gpu` (any device: it needs no storage
    /// buffer, no compute shader, and fits WebGL2's limits).
    pub fn new(gpu: GpuContext) -> Result<TextureListRenderer, RenderError> {
        let device = &gpu.device;
        let defs = ShaderDefs::default();
        let view_layout = TEXTURE_LISTS_VIEW_GROUP.create_layout(device, defs);
        let lists_layout = TEXTURE_LISTS_GROUP.create_layout(device, defs);
        let assets = SceneAssets::new(&gpu);
        let layouts = [&view_layout, &assets.material_layout, &lists_layout];
        crate::layouts::check_pipeline(SHADER, &["vs_main", "fs_main"], &layouts)?;
        let pipeline_layout = crate::layouts::pipeline_layout(device, "texture_lists", &layouts);
        let module = crate::shaders::create_module_with(device, SHADER, defs)?;
        let uniform = |label, size: usize| {
            gpu.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let view_buffer = uniform("texture_lists_view", std::mem::size_of::<ViewUniform>());
        let params_buffer = uniform("texture_lists_params", std::mem::size_of::<GpuClusterParams>());
        let view_group = view_layout.create_bind_group(&gpu, &[Binding::Buffer(&view_buffer)]);
        let width = LIST_TEXTURE_WIDTH.min(gpu.max_texture_size());
        let light_width = (width / TEXELS_PER_LIGHT) * TEXELS_PER_LIGHT;
        let lights =
            ListTexture::new(&gpu, "texture_lists_lights", wgpu::TextureFormat::Rgba32Float, light_width);
        let ranges = ListTexture::new(&gpu, "texture_lists_ranges", wgpu::TextureFormat::Rg32Uint, width);
        let indices = ListTexture::new(&gpu, "texture_lists_indices", wgpu::TextureFormat::R32Uint, width);
        let lists_group = lists_group(&gpu, &lists_layout, &params_buffer, [&lights, &ranges, &indices]);
        let instances = instance_buffer(&gpu, 1);
        Ok(TextureListRenderer {
            gpu,
            assets,
            view_layout,
            lists_layout,
            pipeline_layout,
            module,
            pipelines: HashMap::new(),
            view_buffer,
            params_buffer,
            view_group,
            lights,
            ranges,
            indices,
            lists_group,
            instances,
            target: None,
            warned: Vec::new(),
        })
    }

    /// The device it renders with.
    pub fn gpu(&self) -> &GpuContext {
        &self.gpu
    }

    /// The output the last frame was drawn into (`None` before the first frame).
    pub fn target(&self) -> Option<&HeadlessTarget> {
        self.target.as_ref().map(|t| &t.color)
    }

    /// The layout of group 0 (the view uniform).
    pub fn view_layout(&self) -> &GroupLayout {
        &self.view_layout
    }

    /// Renders `snapshot`'s first view into the output (module docs) and submits it without
    /// waiting. The report's `nonfinite_pixels` is left for the read-back to fill.
    pub fn render(&mut self, snapshot: &FrameSnapshot) -> Result<FrameReport, RenderError> {
        let start = web_time::Instant::now();
        let gpu_before = self.gpu.counts();
        let mut snapshot_views = snapshot.views.clone();
        let before = snapshot_views.len();
        snapshot_views.retain(|v| v.camera.is_valid());
        let invalid_cameras = (before - snapshot_views.len()) as u32;
        let mut frame = FrameSnapshot { views: snapshot_views, ..Default::default() };
        frame.viewport = snapshot.viewport;
        frame.settings = snapshot.settings;
        self.downgrades(snapshot);
        let view = frame.render_view(0);
        let size = view.size.max(UVec2::ONE);
        let mut report = FrameReport {
            frame_index: snapshot.frame_index,
            width: size.x,
            height: size.y,
            pipeline: PipelineKind::ClusteredForward,
            invalid_cameras,
            sanitized_cameras: snapshot.sanitized_cameras(),
            frames_in_flight: 1,
            frames_in_flight_limit: 1,
            light_uploads: 1,
            ..Default::default()
        };
        self.ensure_target(size);

        // 1. Lights, at the frame's time.
        let upload_start = web_time::Instant::now();
        let lights = FrameLights::new(&snapshot.lights, snapshot.elapsed_secs);
        report.light_count = lights.valid;
        let texels = lights.texels(self.lights.width() / TEXELS_PER_LIGHT);
        let mut rebind = self.lights.write(&self.gpu, bytemuck::cast_slice(&texels))?;
        report.light_upload_bytes =
            (lights.packed.len() * std::mem::size_of::<crate::gpu_types::GpuPointLight>()) as u64;
        let directional = pack_directional_lights(&snapshot.directional_lights);
        report.directional_lights = directional.count;
        report.dropped_directional_lights = directional.dropped;
        report.invalid_lights = (snapshot.lights.len() as u32 - lights.valid) + directional.invalid;
        let (draws, instances) = self.prepare_draws(snapshot, &view, &mut report)?;
        report.cpu.upload_ms = ms_since(upload_start);

        // 2. The view's lists, by the CPU assignment.
        let assign_start = web_time::Instant::now();
        let camera = view.camera;
        let view_from_world = camera.map_or(Mat4::IDENTITY, |c| c.view_from_world());
        let settings = &view.settings.clusters;
        let projection = camera
            .map(|c| c.projection)
            .unwrap_or_default()
            .finite_for(lights.reach.farthest(&view_from_world));
        let grid = manylight_core::cluster::ClusterGrid::new(
            size,
            &projection,
            &settings.grid_for(PipelineKind::ClusteredForward),
        );
        let assignment = lights.assign(&grid, &view_from_world, settings.cull, settings.cap);
        let width = self.ranges.width();
        rebind |=
            self.ranges.write(&self.gpu, bytemuck::cast_slice(&padded(&assignment.ranges, width, [0, 0])))?;
        rebind |=
            self.indices.write(&self.gpu, bytemuck::cast_slice(&padded(&assignment.indices, width, 0)))?;
        let params = GpuClusterParams {
            dims: [grid.dims.x, grid.dims.y, grid.dims.z, grid.cluster_count()],
            viewport: [size.x as f32, size.y as f32, grid.near, grid.far],
            light_count: lights.packed.len() as u32,
            slicing: grid.slicing.gpu_id(),
            log_far_over_near: (grid.far / grid.near).ln(),
            view_from_world: view_from_world.to_cols_array_2d(),
            ..Default::default()
        };
        self.gpu.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));
        if rebind {
            let textures = [&self.lights, &self.ranges, &self.indices];
            self.lists_group = lists_group(&self.gpu, &self.lists_layout, &self.params_buffer, textures);
        }
        let list_stats = assignment.stats();
        let clusters = crate::clusters::ClusterReport {
            dims: grid.dims.to_array(),
            clusters: list_stats.clusters,
            lights: lights.valid,
            non_empty: list_stats.non_empty,
            total_entries: list_stats.total_entries,
            max_per_cluster: list_stats.max_per_cluster,
            mean_per_cluster: f64::from(list_stats.mean_per_cluster),
            mean_per_non_empty: f64::from(list_stats.mean_per_non_empty),
            dropped_pairs: assignment.dropped_pairs,
            clusters_overflowed: assignment.clusters_overflowed,
            index_capacity: assignment.indices.len() as u64,
            cull_test: settings.cull.name().to_string(),
            z_slicing: grid.slicing.name().to_string(),
            ..Default::default()
        };
        report.clusters = Some(clusters);
        let assign_ms = ms_since(assign_start);
        report.passes.push(PassTiming {
            name: "cluster_assign".into(),
            pass_type: None,
            gpu_ms: None,
            gpu_trusted: false,
            cpu_ms: assign_ms,
        });
        report.cpu.prepare_ms = assign_ms;

        // 3. The draw.
        let record_start = web_time::Instant::now();
        let uniform = view_uniform(&view, lights.packed.len() as u32, directional.count, directional.packed);
        self.gpu.write_buffer(&self.view_buffer, 0, bytemuck::bytes_of(&uniform));
        let bytes = bytemuck::cast_slice::<GpuInstance, u8>(&instances);
        if self.instances.size() < bytes.len() as u64 {
            self.instances = instance_buffer(&self.gpu, instances.len());
        }
        self.gpu.write_buffer(&self.instances, 0, bytes);
        for d in &draws {
            if !self.pipelines.contains_key(&d.variant) {
                let pipeline =
                    create_pipeline(&self.gpu.device, &self.pipeline_layout, &self.module, d.variant);
                self.pipelines.insert(d.variant, pipeline);
            }
        }
        let clear =
            manylight_core::tonemap::aces_fitted(Vec3::from(view.settings.clear_color) * view.exposure());
        let target = self.target.as_ref().ok_or_else(|| RenderError::Readback("no output target".into()))?;
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("texture_lists") });
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("texture_lists"),
                color_attachments: &[crate::passes::common::color_attachment(
                    target.color.view(),
                    crate::passes::common::clear_color(clear.to_array()),
                )],
                depth_stencil_attachment: crate::passes::common::depth_attachment(&target.depth, true),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if camera.is_some() {
                pass.set_bind_group(TEXTURE_LISTS_VIEW_GROUP.index, &self.view_group, &[]);
                pass.set_bind_group(TEXTURE_LISTS_GROUP.index, &self.lists_group, &[]);
                let stride = std::mem::size_of::<GpuInstance>() as u64;
                for (i, d) in draws.iter().enumerate() {
                    let (Some(mesh), Some(material), Some(pipeline)) = (
                        self.assets.mesh(d.mesh),
                        self.assets.material(d.material),
                        self.pipelines.get(&d.variant),
                    ) else {
                        continue;
                    };
                    pass.set_pipeline(pipeline);
                    pass.set_bind_group(crate::layouts::MATERIAL_GROUP.index, &material.bind_group, &[]);
                    pass.set_vertex_buffer(0, mesh.vertices.slice(..));
                    pass.set_vertex_buffer(
                        1,
                        self.instances.slice(i as u64 * stride..(i as u64 + 1) * stride),
                    );
                    pass.set_index_buffer(mesh.indices.slice(..), wgpu::IndexFormat::Uint32);
                    pass.draw_indexed(0..mesh.index_count, 0, 0..1);
                }
            }
        }
        let record_ms = ms_since(record_start);
        report.passes.push(PassTiming {
            name: SHADER_PASS.into(),
            pass_type: None,
            gpu_ms: None,
            gpu_trusted: false,
            cpu_ms: record_ms,
        });
        report.cpu.record_ms = record_ms;
        let submit_start = web_time::Instant::now();
        self.gpu.queue.submit([encoder.finish()]);
        report.cpu.submit_ms = ms_since(submit_start);
        self.assets.evict_unused();
        if let Some(e) = self.gpu.take_errors().into_iter().next() {
            return Err(RenderError::Device(e));
        }
        let used = self.gpu.counts().since(gpu_before);
        report.cpu.upload_bytes = used.bytes_uploaded;
        report.cpu.extract_ms = snapshot.extract_cpu_ms;
        report.buffers_created = used.buffers;
        report.bind_groups_created = used.bind_groups;
        report.frame_cpu_ms = ms_since(start);
        report.views = vec![ViewReport {
            index: 0,
            order: frame.views.first().map_or(0, |v| v.order),
            target: "main".into(),
            width: size.x,
            height: size.y,
            passes: report.passes.iter().map(|p| p.name.clone()).collect(),
            clusters: report.clusters.clone(),
            cpu_ms: report.frame_cpu_ms,
            gpu_ms: None,
        }];
        Ok(report)
    }

    /// The frame's draws, in the order the native passes draw them, and their instances (one
    /// per draw); counts what is not drawn.
    fn prepare_draws(
        &mut self,
        snapshot: &FrameSnapshot,
        view: &RenderView,
        report: &mut FrameReport,
    ) -> Result<(Vec<Draw>, Vec<GpuInstance>), RenderError> {
        self.assets.begin_frame();
        let mut draws = Vec::with_capacity(snapshot.instances.len());
        for inst in &snapshot.instances {
            if !inst.world_from_local.is_finite() {
                report.invalid_instances += 1;
                continue;
            }
            let Some(gpu_instance) = GpuInstance::drawable(inst.world_from_local) else {
                report.collapsed_instances += 1;
                continue;
            };
            if inst.mesh.indices.is_empty() {
                continue;
            }
            let mirrored = glam::Mat3::from_mat4(inst.world_from_local).determinant() < 0.0;
            let variant =
                SurfaceVariant::of(&inst.material, mirrored).resolved(view.settings.shading.gpu_id());
            if variant.blend {
                continue;
            }
            let (mesh, mesh_order, _, _) = self.assets.mesh_entry(&self.gpu, &inst.mesh)?;
            let (material, material_order) = self.assets.material_entry(&self.gpu, &inst.material)?;
            draws.push((Draw { mesh, material, order: (material_order, mesh_order), variant }, gpu_instance));
        }
        draws.sort_by_key(|(d, _)| d.order);
        report.instance_count = draws.len() as u32;
        Ok(draws.into_iter().unzip())
    }

    /// Warns once about each part of `snapshot` the path does not draw.
    fn downgrades(&mut self, snapshot: &FrameSnapshot) {
        let mut warn = |what: &'static str, message: &str| {
            if !self.warned.contains(&what) {
                self.warned.push(what);
                tracing::warn!("texture lists (WebGL2): {message}");
            }
        };
        if snapshot.settings.pipeline != PipelineKind::ClusteredForward {
            warn("pipeline", "renders clustered forward whatever pipeline is asked for");
        }
        if snapshot.casts_shadows() {
            warn("shadows", "draws no shadows (they need storage buffers)");
        }
        if snapshot.views.len() > 1 {
            warn("views", "draws the first view only");
        }
        if snapshot.has_blended() {
            warn("blend", "does not draw blended materials");
        }
        if snapshot.settings.debug_view != crate::snapshot::DebugViewMode::None {
            warn("debug", "has no debug views");
        }
        if snapshot.views.iter().any(|v| v.camera.bloom.is_some() || v.camera.motion_blur.is_some()) {
            warn("post", "has no bloom or motion blur");
        }
    }

    fn ensure_target(&mut self, size: UVec2) {
        if self.target.as_ref().is_some_and(|t| t.color.size() == (size.x, size.y)) {
            return;
        }
        let color = HeadlessTarget::new(&self.gpu, size.x, size.y);
        let depth = self.gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("texture_lists_depth"),
            size: wgpu::Extent3d { width: size.x, height: size.y, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let depth = depth.create_view(&wgpu::TextureViewDescriptor::default());
        self.target = Some(Target { color, depth });
    }
}

/// The name of the pass that draws and shades (its report's entry).
pub const SHADER_PASS: &str = "texture_lists";

fn ms_since(t: web_time::Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}
