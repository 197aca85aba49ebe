//! The renderer: scene resources, the transient pool, pipelines and the GPU timer, and the
//! execution of one frame's graph.

use crate::clusters::ClusterResources;
use crate::context::{GpuContext, RenderError};
use crate::gpu_types::LAVAPIPE_LOOP_LIMIT;
use crate::graph::{OUTPUT, PassContext, RenderGraph};
use crate::pipelines::PipelineCache;
use crate::pool::{TextureKey, TransientPool};
use crate::resources::SceneResources;
use crate::snapshot::{FrameSnapshot, RenderView};
use crate::stats::{FrameReport, PassTiming};
use crate::timing::{GpuTimer, MAX_TIMED_PASSES};
use std::collections::HashMap;
use std::time::Instant;

/// Everything that lives across frames on the render side.
pub struct Renderer {
    /// Device and queue.
    pub gpu: GpuContext,
    /// Uploaded scene data.
    pub scene: SceneResources,
    /// Pipelines created so far.
    pub pipelines: PipelineCache,
    /// Cluster buffers of each view (by its position in the frame's views), created the first
    /// time the view needs them: views keep their own grids, lists and statistics.
    pub clusters: Vec<Option<ClusterResources>>,
    pool: TransientPool,
    timer: Option<GpuTimer>,
    cpu_adapter: bool,
    last_textures: HashMap<crate::graph::ResourceName, wgpu::TextureView>,
}

impl Renderer {
    /// Creates the renderer on a context.
    pub fn new(gpu: GpuContext) -> Renderer {
        let timer = GpuTimer::new(&gpu.device, &gpu.queue, gpu.timestamps);
        let cpu_adapter = gpu.info.device_type == wgpu::DeviceType::Cpu;
        Renderer {
            scene: SceneResources::new(&gpu),
            pipelines: PipelineCache::default(),
            clusters: Vec::new(),
            pool: TransientPool::default(),
            timer,
            cpu_adapter,
            last_textures: HashMap::new(),
            gpu,
        }
    }

    /// Uploads the data the frame's views share (the `Prepare` step): lights, instances,
    /// meshes and materials, once per frame; starts the frame's transient textures.
    pub fn prepare(&mut self, snapshot: &FrameSnapshot) -> Result<(), RenderError> {
        let settings = &snapshot.settings;
        if settings.pipeline.is_deferred() && !settings.gbuffer.supports(settings.normal_codec) {
            return Err(RenderError::UnsupportedSettings(format!(
                "the {} G-buffer cannot store normals with the {} codec",
                settings.gbuffer.name(),
                settings.normal_codec.name()
            )));
        }
        self.pool.begin_frame();
        self.scene.prepare(&self.gpu, snapshot)?;
        // Views that went away free their cluster buffers.
        self.clusters.truncate(snapshot.views.len().max(1));
        Ok(())
    }

    /// Writes one view's constants and, when it needs them, its cluster grid and light
    /// spheres (before the view is executed; views run one after the other).
    /// `has_lights`: the frame has a valid light ([`FrameSnapshot::has_lights`]).
    pub fn prepare_view(&mut self, view: &RenderView, has_lights: bool) -> Result<(), RenderError> {
        self.scene.prepare_view(&self.gpu, view);
        if view.needs_clusters(has_lights) {
            if self.clusters.len() <= view.index {
                self.clusters.resize_with(view.index + 1, || None);
            }
            let gpu = &self.gpu;
            let clusters = self.clusters[view.index].get_or_insert_with(|| ClusterResources::new(gpu));
            let view_from_world = view.camera.map(|c| c.view_from_world()).unwrap_or_default();
            clusters.prepare(gpu, view, &view_from_world, &self.scene.light_spheres)?;
        }
        Ok(())
    }

    /// The cluster buffers of view `index`, if it built clusters.
    pub fn view_clusters(&self, index: usize) -> Option<&ClusterResources> {
        self.clusters.get(index).and_then(Option::as_ref)
    }

    /// The last frame's depth buffer (reverse-Z, row-major), if the frame had one.
    pub fn read_depth(&self) -> Result<Option<(u32, u32, Vec<f32>)>, RenderError> {
        let Some(view) = self.last_textures.get(crate::passes::DEPTH) else {
            return Ok(None);
        };
        let texture = view.texture();
        let bytes = crate::readback::read_texture(&self.gpu, texture, wgpu::TextureAspect::DepthOnly, 4)?;
        let (w, h) = (texture.width(), texture.height());
        let depth = bytemuck::pod_collect_to_vec::<u8, f32>(&bytes);
        Ok(Some((w, h, depth)))
    }

    /// The transient pool (tests read its allocation counts).
    pub fn pool(&self) -> &TransientPool {
        &self.pool
    }

    /// Runs `graph` for `view` into `output` (the `Execute` step) and waits for the GPU to
    /// finish. The light lists were sized by their CPU bounds in [`Renderer::prepare_view`], so
    /// the build cannot overflow them; only when a bound exceeded what the device can bind (and
    /// the lists were sized to the limit) can the counters show a list short, and then it grows
    /// and the frame is rendered again (`ClusterReport::regrows`), so no light is ever lost to
    /// a buffer size.
    pub fn execute(
        &mut self,
        graph: &RenderGraph,
        snapshot: &FrameSnapshot,
        view: &RenderView,
        output: &wgpu::TextureView,
        output_format: wgpu::TextureFormat,
    ) -> Result<FrameReport, RenderError> {
        let names = graph.pass_names()?;
        let builds_clusters = names.contains(&"cluster_build");
        let loop_limited = crate::gpu_types::has_loop_limit(&self.gpu.info);
        // Naive forward loops over every light, four per iteration.
        let naive_iterations = u64::from(self.scene.light_count).div_ceil(4);
        if loop_limited && names.contains(&"forward") && naive_iterations > u64::from(LAVAPIPE_LOOP_LIMIT) {
            return Err(RenderError::LoopLimit {
                what: format!("naive forward's loop over {} lights", self.scene.light_count),
                iterations: naive_iterations,
                limit: LAVAPIPE_LOOP_LIMIT,
            });
        }
        let mut regrows = 0;
        loop {
            let mut report = self.execute_once(graph, snapshot, view, output, output_format)?;
            let Some(clusters) =
                self.clusters.get_mut(view.index).and_then(Option::as_mut).filter(|_| builds_clusters)
            else {
                return Ok(report);
            };
            let counters = clusters.read_counters(&self.gpu)?;
            ClusterResources::check_saturation(&counters)?;
            if regrows < 4 && clusters.grow_if_needed(&self.gpu, &counters)? {
                regrows += 1;
                tracing::debug!("light-index list grew to {} entries", clusters.params.index_capacity);
                continue;
            }
            if clusters.lists_short(&counters) {
                // Never show a frame with lights missing from the lists.
                return Err(RenderError::ListsTooSmall {
                    regrows,
                    needed: u64::from(counters.total_entries.max(counters.tile_entries)),
                    capacity: u64::from(
                        clusters.params.index_capacity.min(clusters.params.tile_index_capacity),
                    ),
                });
            }
            if loop_limited && counters.max_tile_lights > LAVAPIPE_LOOP_LIMIT {
                // The build's loops over that tile list (and shading over its clusters' lists)
                // ended early: lights would be missing.
                return Err(RenderError::LoopLimit {
                    what: "a tile's light list".into(),
                    iterations: u64::from(counters.max_tile_lights),
                    limit: LAVAPIPE_LOOP_LIMIT,
                });
            }
            report.clusters = Some(clusters.report(&counters, regrows));
            return Ok(report);
        }
    }

    fn execute_once(
        &mut self,
        graph: &RenderGraph,
        snapshot: &FrameSnapshot,
        view: &RenderView,
        output: &wgpu::TextureView,
        output_format: wgpu::TextureFormat,
    ) -> Result<FrameReport, RenderError> {
        let frame_start = Instant::now();
        let order = graph.compile()?;
        // Views of one frame run one after the other: they may share transient textures.
        self.pool.release_all();
        let size = view.size;
        let mut textures = HashMap::new();
        textures.insert(OUTPUT, output.clone());
        for &i in &order {
            for spec in graph.pass(i).creates() {
                let scaled = |v: u32| ((v as f32 * spec.scale).round() as u32).max(1);
                let key = TextureKey {
                    width: scaled(size.x),
                    height: scaled(size.y),
                    format: spec.format,
                    usage: spec.usage,
                };
                textures.insert(spec.name, self.pool.acquire(&self.gpu.device, key, spec.name));
            }
        }

        let mut encoder =
            self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        let mut passes = Vec::with_capacity(order.len());
        let mut written = Vec::with_capacity(order.len());
        for (slot, &i) in order.iter().enumerate() {
            let pass = graph.pass(i);
            let timed = self.timer.as_ref().filter(|_| (slot as u32) < MAX_TIMED_PASSES);
            let mut ctx = PassContext {
                gpu: &self.gpu,
                scene: &self.scene,
                pipelines: &self.pipelines,
                clusters: self.clusters.get(view.index).and_then(Option::as_ref),
                encoder: &mut encoder,
                output_format,
                textures: &textures,
                timer: timed.map(|t| t.query_set()),
                pass_index: slot as u32,
                stamps: (false, false),
            };
            let start = Instant::now();
            pass.record(&mut ctx)?;
            let cpu_ms = start.elapsed().as_secs_f64() * 1e3;
            written.push(ctx.stamps.0 && ctx.stamps.1);
            passes.push(PassTiming {
                name: pass.name().to_string(),
                gpu_ms: None,
                gpu_trusted: !(pass.is_compute() && self.cpu_adapter),
                cpu_ms,
            });
        }
        if let Some(t) = &self.timer {
            t.resolve(&mut encoder, order.len() as u32);
        }
        self.gpu.queue.submit([encoder.finish()]);
        self.gpu.wait_idle()?;
        if let Some(t) = &self.timer {
            for (p, ms) in passes.iter_mut().zip(t.read(&self.gpu.device, &written)) {
                p.gpu_ms = ms;
            }
        }
        self.last_textures = textures;
        let errors = self.gpu.take_errors();
        if !errors.is_empty() {
            return Err(RenderError::Device(errors.join("; ")));
        }
        let nonfinite_pixels = match passes.iter().any(|p| p.name == crate::passes::tonemap::TONEMAP) {
            true => Some(self.scene.nonfinite.read(&self.gpu)?),
            false => None,
        };
        if let Some(n) = nonfinite_pixels.filter(|&n| n > 0) {
            tracing::warn!("frame {}: {n} pixels have a NaN or infinite HDR colour", snapshot.frame_index);
        }
        let gpu_times: Vec<f64> = passes.iter().filter_map(|p| p.gpu_ms).collect();
        Ok(FrameReport {
            frame_index: snapshot.frame_index,
            width: size.x,
            height: size.y,
            pipeline: view.settings.pipeline.name().to_string(),
            frame_gpu_ms: (!gpu_times.is_empty()).then(|| gpu_times.iter().sum()),
            passes,
            frame_cpu_ms: frame_start.elapsed().as_secs_f64() * 1e3,
            light_count: self.scene.light_count,
            invalid_lights: self.scene.invalid_lights,
            invalid_cameras: 0,
            sanitized_cameras: 0,
            nonfinite_pixels,
            instance_count: self.scene.draws.len() as u32,
            invalid_instances: self.scene.invalid_instances,
            collapsed_instances: self.scene.collapsed_instances,
            transient_textures: self.pool.live() as u32,
            transient_bytes: self.pool.frame_bytes(),
            transient_allocations: self.pool.allocations(),
            clusters: None,
            views: Vec::new(),
            light_uploads: 0,
            light_upload_bytes: 0,
            device_recoveries: 0,
        })
    }
}
