//! The renderer: scene resources, the transient pool, pipelines, the ring of frames in flight,
//! and the execution of one frame's graph.
//!
//! A frame is [`Renderer::prepare`]d (its shared uploads; it takes a read-back slot, waiting
//! only when every slot still holds a frame on the GPU), then each view is
//! [`Renderer::prepare_view`]ed and [`Renderer::execute`]d (recorded and submitted, no wait),
//! then [`Renderer::finish_frame`] hands the frame's report to its slot. Reports come back
//! complete, with GPU times and cluster counts, from [`Renderer::take_reports`] once the GPU
//! has finished them.

use crate::bindings::BindingCache;
use crate::clusters::ClusterResources;
use crate::context::{GpuContext, GpuCounts, RenderError};
use crate::gpu_types::{GpuClusterCounters, LAVAPIPE_LOOP_LIMIT};
use crate::graph::{HDR, HDR_SWAP, OUTPUT, Pass, PassContext, RenderGraph, ResourceName};
use crate::inflight::{DEFAULT_FRAMES_IN_FLIGHT, FrameRing};
use crate::pipelines::PipelineCache;
use crate::pool::{TextureKey, TransientPool};
use crate::resources::SceneResources;
use crate::snapshot::{FrameSnapshot, RenderView};
use crate::stats::{CpuPhases, FrameReport, PassTiming};
use std::collections::HashMap;
use web_time::Instant;

/// Everything that lives across frames on the render side.
pub struct Renderer {
    /// Device and queue.
    pub gpu: GpuContext,
    /// Uploaded scene data.
    pub scene: SceneResources,
    /// The shadow atlas and its pass's buffers.
    pub shadows: crate::shadows::ShadowResources,
    /// The shadow rays' geometry and casting lights, when the frame traces rays.
    pub rays: crate::ray_geometry::ShadowRays,
    /// The prefiltered environment maps the views name.
    pub environments: crate::environment::EnvironmentMaps,
    /// Pipelines created so far.
    pub pipelines: PipelineCache,
    /// Cluster buffers of each view (by its position in the frame's views), created the first
    /// time the view needs them: views keep their own grids, lists and statistics.
    pub clusters: Vec<Option<ClusterResources>>,
    pool: TransientPool,
    bindings: BindingCache,
    ring: FrameRing,
    /// Reports completed and not yet taken.
    arrived: Vec<FrameReport>,
    /// The context's counts when the frame began.
    counts_at_begin: GpuCounts,
    cpu_adapter: bool,
    last_textures: HashMap<crate::graph::ResourceName, wgpu::TextureView>,
    /// Whether the last frame's HDR image ended in [`HDR_SWAP`] (an odd number of
    /// post-processing passes swapped it there).
    last_hdr_swapped: bool,
    /// Whether frames make their HDR textures copyable, for [`Renderer::read_hdr`]
    /// ([`Renderer::set_hdr_readback`]; off for ordinary frames).
    hdr_readback: bool,
    /// This frame's `FrameSnapshot::pixel_light_lists`.
    pixel_light_lists: Option<std::sync::Arc<manylight_core::cluster::ClusterAssignment>>,
    /// This frame's CPU time by phase so far.
    phases: CpuPhases,
}

impl Renderer {
    /// Creates the renderer on a context, with [`DEFAULT_FRAMES_IN_FLIGHT`] frames in flight.
    pub fn new(gpu: GpuContext) -> Renderer {
        Self::with_frames_in_flight(gpu, DEFAULT_FRAMES_IN_FLIGHT)
    }

    /// Creates the renderer on a context; at most `frames_in_flight` frames (1 to
    /// [`crate::MAX_FRAMES_IN_FLIGHT`]) are submitted and not yet read back.
    pub fn with_frames_in_flight(gpu: GpuContext, frames_in_flight: u32) -> Renderer {
        let cpu_adapter = gpu.info.device_type == wgpu::DeviceType::Cpu;
        Renderer {
            scene: SceneResources::new(&gpu),
            shadows: crate::shadows::ShadowResources::new(&gpu),
            rays: Default::default(),
            environments: crate::environment::EnvironmentMaps::new(),
            pipelines: PipelineCache::default(),
            clusters: Vec::new(),
            pool: TransientPool::default(),
            bindings: BindingCache::default(),
            ring: FrameRing::new(&gpu, frames_in_flight),
            arrived: Vec::new(),
            counts_at_begin: gpu.counts(),
            cpu_adapter,
            last_textures: HashMap::new(),
            last_hdr_swapped: false,
            hdr_readback: false,
            pixel_light_lists: None,
            phases: CpuPhases::default(),
            gpu,
        }
    }

    /// The most frames that can be in flight.
    pub fn frames_in_flight(&self) -> u32 {
        self.ring.frames_in_flight()
    }

    /// Whether the next frame can start without waiting for the GPU (see
    /// [`FrameRing::can_begin`]).
    pub fn can_begin_frame(&self) -> bool {
        self.ring.can_begin(&self.gpu)
    }

    /// Uploads the data the frame's views share (the `Prepare` step): lights, instances,
    /// meshes and materials, once per frame; starts the frame's transient textures and takes
    /// its read-back slot (waiting for the frame that held it only when every slot is in
    /// flight).
    pub fn prepare(&mut self, snapshot: &FrameSnapshot) -> Result<(), RenderError> {
        let start = Instant::now();
        self.phases = CpuPhases { extract_ms: snapshot.extract_cpu_ms, ..CpuPhases::default() };
        let settings = &snapshot.settings;
        settings.check_values().map_err(RenderError::UnsupportedSettings)?;
        if settings.pipeline.is_deferred() && !settings.gbuffer.supports(settings.normal_codec) {
            return Err(RenderError::UnsupportedSettings(format!(
                "the {} G-buffer cannot store normals with the {} codec",
                settings.gbuffer.name(),
                settings.normal_codec.name()
            )));
        }
        self.counts_at_begin = self.gpu.counts();
        let arrived = self.ring.begin(&self.gpu, snapshot.views.len().max(1))?;
        self.observe_lists(&arrived);
        self.arrived.extend(arrived);
        self.pool.begin_frame();
        self.bindings.begin_frame();
        self.scene.prepare(&self.gpu, snapshot)?;
        self.shadows.prepare(&self.gpu, &self.scene, snapshot)?;
        self.rays.prepare(&self.gpu, snapshot);
        self.environments.prepare(&self.gpu, snapshot)?;
        self.scene.bind_view(&self.gpu, self.shadows.bindings(), None, self.rays.bindings());
        self.pixel_light_lists = snapshot.pixel_light_lists.clone();
        // Views that went away free their cluster buffers.
        self.clusters.truncate(snapshot.views.len().max(1));
        self.phases.upload_ms = start.elapsed().as_secs_f64() * 1e3;
        Ok(())
    }

    /// Writes one view's constants and, when it needs them, its cluster grid and light
    /// spheres (before the view is executed; views run one after the other).
    /// `has_lights`: the frame has a valid light ([`FrameSnapshot::has_lights`]);
    /// `options`: depth bounds and refined lists, from the view's plan
    /// ([`crate::PlanInputs::list_options`]).
    pub fn prepare_view(
        &mut self,
        view: &RenderView,
        has_lights: bool,
        options: crate::clusters::ListOptions,
    ) -> Result<(), RenderError> {
        let start = Instant::now();
        self.prepare_view_timed(view, has_lights, options)?;
        self.phases.prepare_ms += start.elapsed().as_secs_f64() * 1e3;
        Ok(())
    }

    /// [`Renderer::prepare_view`] without its timing.
    fn prepare_view_timed(
        &mut self,
        view: &RenderView,
        has_lights: bool,
        options: crate::clusters::ListOptions,
    ) -> Result<(), RenderError> {
        // A view whose camera's shadows checkbox is off binds and shades without shadows.
        let shadows = self.shadows.bindings().filter(|_| view.settings.render.shadows.enabled);
        let rays = self.rays.bindings().filter(|_| view.settings.render.shadows.enabled);
        let filter = view.settings.render.environment_filter;
        let environment =
            view.camera.and_then(|c| c.environment).and_then(|e| self.environments.bindings(e.image, filter));
        self.scene.bind_view(&self.gpu, shadows, environment, rays);
        // After binding: the view uniform carries the shadow rays' root.
        self.scene.prepare_view(&self.gpu, view);
        if view.needs_clusters(has_lights) {
            if self.clusters.len() <= view.index {
                self.clusters.resize_with(view.index + 1, || None);
            }
            let gpu = &self.gpu;
            let clusters = self.clusters[view.index].get_or_insert_with(|| ClusterResources::new(gpu));
            let view_from_world = view.camera.map(|c| c.view_from_world()).unwrap_or_default();
            let lights = (self.scene.lights.count, &self.scene.lights.reach);
            match &self.pixel_light_lists {
                Some(lists) => clusters.prepare_pixel_lists(gpu, view, &view_from_world, lights, lists)?,
                None => clusters.prepare(gpu, view, &view_from_world, lights, options)?,
            }
        }
        Ok(())
    }

    /// The cluster buffers of view `index`, if it built clusters.
    pub fn view_clusters(&self, index: usize) -> Option<&ClusterResources> {
        self.clusters.get(index).and_then(Option::as_ref)
    }

    /// The last frame's depth buffer (reverse-Z, row-major), if the frame had one.
    pub fn read_depth(&self) -> Result<Option<(u32, u32, Vec<f32>)>, RenderError> {
        let Some(view) = self.last_textures.get(&crate::passes::DEPTH) else {
            return Ok(None);
        };
        let texture = view.texture();
        let bytes = crate::readback::read_texture(&self.gpu, texture, wgpu::TextureAspect::DepthOnly, 4)?;
        let (w, h) = (texture.width(), texture.height());
        let depth = bytemuck::pod_collect_to_vec::<u8, f32>(&bytes);
        Ok(Some((w, h, depth)))
    }

    /// Makes the HDR textures of the frames that follow copyable (`keep`), so that
    /// [`Renderer::read_hdr`] can read the image the tone map reads; or not, as ordinary frames
    /// are. While it is set the frames take their HDR textures from the pool under their own key
    /// (an extra usage), so ordinary frames never pay for it.
    pub fn set_hdr_readback(&mut self, keep: bool) {
        self.hdr_readback = keep;
    }

    /// The last frame's HDR image as the tone map read it (linear radiance before exposure and
    /// tone mapping, after any post-processing), as the bits of its `Rgba16Float` texels, row
    /// by row: `(width, height, rgba)`. `None` when the frame had no HDR image (a debug view
    /// replaced it); an error when the frame was not rendered after
    /// [`Renderer::set_hdr_readback`]`(true)`. Waits for the GPU.
    pub fn read_hdr(&self) -> Result<Option<(u32, u32, Vec<u16>)>, RenderError> {
        let name = if self.last_hdr_swapped { HDR_SWAP } else { HDR };
        let Some(view) = self.last_textures.get(&name) else {
            return Ok(None);
        };
        let texture = view.texture();
        if !texture.usage().contains(wgpu::TextureUsages::COPY_SRC) {
            return Err(RenderError::Readback(
                "the frame's HDR image cannot be copied: render it after set_hdr_readback(true)".into(),
            ));
        }
        if texture.format() != crate::resources::HDR_FORMAT {
            return Err(RenderError::Readback(format!(
                "the frame's HDR image is {:?}, not {:?}",
                texture.format(),
                crate::resources::HDR_FORMAT
            )));
        }
        // Rgba16Float: four 2-byte channels per texel.
        let bytes = crate::readback::read_texture(&self.gpu, texture, wgpu::TextureAspect::All, 8)?;
        let rgba = bytemuck::pod_collect_to_vec::<u8, u16>(&bytes);
        Ok(Some((texture.width(), texture.height(), rgba)))
    }

    /// The shadow test the last frame's shading made at each of `probes`, in [0, 1]
    /// ([`crate::shadow_probe::probe_shadows`]; waits for the GPU).
    pub fn probe_shadows(
        &self,
        probes: &[crate::shadow_probe::ShadowProbe],
    ) -> Result<Vec<f32>, RenderError> {
        let lights = self.scene.lights.buffer.buffer();
        if self.rays.bindings().is_some() {
            return crate::ray_geometry::probe_lights(
                &self.gpu,
                &self.rays,
                lights,
                self.scene.lights.count,
                probes,
            );
        }
        crate::shadow_probe::probe_shadows(&self.gpu, &self.shadows, lights, self.scene.lights.count, probes)
    }

    /// The transient pool (tests read its allocation counts).
    pub fn pool(&self) -> &TransientPool {
        &self.pool
    }

    /// Records `graph` for `view` into `output` and submits it (the `Execute` step), without
    /// waiting for the GPU: the returned report has the CPU-side figures, and its GPU times
    /// and cluster counts arrive with the frame's read-back ([`Renderer::take_reports`]).
    ///
    /// The light lists were sized in [`Renderer::prepare_view`] from the counters of the latest
    /// frame read back; a cluster whose list still does not fit shades from every light that
    /// frame (exact, slower), so no light is lost and no frame is rendered twice. Only when the
    /// lists have no counts to go by (the view's first frame, or the light count more than
    /// doubled) does the view run its build once before the frame, only to count, and wait for
    /// those counters (`ClusterReport::counted_first`); where the CPU may not wait
    /// ([`GpuContext::can_block`]) the lists are sized for every light instead.
    pub fn execute(
        &mut self,
        graph: &RenderGraph,
        snapshot: &FrameSnapshot,
        view: &RenderView,
        output: &wgpu::TextureView,
        output_format: wgpu::TextureFormat,
    ) -> Result<FrameReport, RenderError> {
        let passes: Vec<&dyn Pass> = graph.compile()?.into_iter().map(|i| graph.pass(i)).collect();
        let has = |is: fn(&dyn Pass) -> bool| passes.iter().any(|p| is(*p));
        let builds_clusters = has(crate::graph::is::<crate::passes::cluster_build::ClusterBuildPass>);
        let loop_limited = crate::gpu_types::has_loop_limit(&self.gpu.info);
        // Naive forward loops over every light, four per iteration.
        let naive_iterations = u64::from(self.scene.lights.count).div_ceil(4);
        if loop_limited
            && has(crate::graph::is::<crate::passes::forward::ForwardPass>)
            && naive_iterations > u64::from(LAVAPIPE_LOOP_LIMIT)
        {
            return Err(RenderError::LoopLimit {
                what: format!("naive forward's loop over {} lights", self.scene.lights.count),
                iterations: naive_iterations,
                limit: LAVAPIPE_LOOP_LIMIT,
            });
        }
        if builds_clusters && self.view_clusters(view.index).is_some_and(ClusterResources::needs_counting) {
            if self.gpu.can_block() {
                self.count_lists(snapshot, view, output, output_format)?;
            } else if let Some(clusters) = self.clusters.get_mut(view.index).and_then(Option::as_mut) {
                // Where nothing may wait (a browser) the lists are sized for every light until
                // the frame's counters come back and size them.
                clusters.size_for_every_light(&self.gpu)?;
            }
        }
        let mut report =
            self.execute_once(&passes, builds_clusters, snapshot, view, output, output_format)?;
        if let Some(clusters) = self.view_clusters(view.index).filter(|_| builds_clusters) {
            report.clusters = Some(clusters.report(&GpuClusterCounters::default()));
        }
        Ok(report)
    }

    /// Runs the cluster build of `view` alone, only to count, and sizes its lists from the
    /// counters (waiting for them), again while a list proved short (a level below a short one
    /// counts short too); then puts the frame's parameters back.
    fn count_lists(
        &mut self,
        snapshot: &FrameSnapshot,
        view: &RenderView,
        output: &wgpu::TextureView,
        output_format: wgpu::TextureFormat,
    ) -> Result<(), RenderError> {
        let build = crate::passes::cluster_build::ClusterBuildPass {
            workgroup_size: view.settings.clusters.workgroup_size,
            depth_bounds: false,
        };
        // Each level can be short once: coarse, tile and cluster lists.
        for _ in 0..3 {
            let Some(clusters) = self.clusters.get_mut(view.index).and_then(Option::as_mut) else {
                return Ok(());
            };
            clusters.count_first(&self.gpu, true);
            let first_pass = self.ring.passes_recorded();
            self.execute_once(&[&build], true, snapshot, view, output, output_format)?;
            self.ring.rewind_view(first_pass);
            let Some(clusters) = self.clusters.get_mut(view.index).and_then(Option::as_mut) else {
                return Ok(());
            };
            let counters = clusters.read_counters(&self.gpu)?;
            ClusterResources::check_saturation(&counters)?;
            if !clusters.grow_to_counts(&self.gpu, &counters)? {
                break;
            }
            tracing::debug!("light lists grew to {} entries", clusters.params.index_capacity);
        }
        if let Some(clusters) = self.clusters.get_mut(view.index).and_then(Option::as_mut) {
            clusters.count_first(&self.gpu, false);
        }
        Ok(())
    }

    /// Hands what the frames in `reports` read back of each view's lists to that view's
    /// cluster buffers: the following frames' lists are sized to it.
    fn observe_lists(&mut self, reports: &[FrameReport]) {
        for view in reports.iter().flat_map(|r| &r.views) {
            let (Some(c), Some(Some(clusters))) = (&view.clusters, self.clusters.get_mut(view.index)) else {
                continue;
            };
            clusters.observe(c);
        }
    }

    /// Ends the frame: `report` (the frame's views merged) goes to the frame's read-back slot,
    /// with what the frame created and waited for, and comes back complete from
    /// [`Renderer::take_reports`].
    pub fn finish_frame(&mut self, mut report: FrameReport) {
        let counts = self.gpu.counts().since(self.counts_at_begin);
        report.blocking_waits = counts.blocking_waits;
        report.buffers_created = counts.buffers;
        report.bind_groups_created = counts.bind_groups;
        report.cpu = CpuPhases { upload_bytes: counts.bytes_uploaded, ..self.phases };
        report.frames_in_flight = self.ring.pending() + 1;
        report.frames_in_flight_limit = self.ring.frames_in_flight();
        self.ring.finish(&self.gpu, report);
    }

    /// The reports of the frames whose GPU figures have arrived, oldest first; with `wait`,
    /// waits for every frame in flight first (a blocking wait).
    pub fn take_reports(&mut self, wait: bool) -> Result<Vec<FrameReport>, RenderError> {
        let collected = self.ring.collect(&self.gpu, wait)?;
        self.observe_lists(&collected);
        self.arrived.extend(collected);
        Ok(std::mem::take(&mut self.arrived))
    }

    /// The query set and index for a pass recorded outside the graph (the window overlay), if
    /// it can be timed; call [`Renderer::pass_recorded`] after it.
    pub fn pass_timer(&self) -> Option<(&wgpu::QuerySet, u32)> {
        self.ring.timer()
    }

    /// Notes a pass recorded outside the graph (`timed`: both its timestamps were written); its
    /// timing must be the next entry of the frame report's passes.
    pub fn pass_recorded(&mut self, timed: bool) {
        self.ring.pass_recorded(timed);
    }

    /// Records `passes` (in order) for `view` and submits them; `builds_clusters` says whether
    /// one of them is the cluster build, whose counters go to the read-back slot.
    fn execute_once(
        &mut self,
        passes: &[&dyn Pass],
        builds_clusters: bool,
        snapshot: &FrameSnapshot,
        view: &RenderView,
        output: &wgpu::TextureView,
        output_format: wgpu::TextureFormat,
    ) -> Result<FrameReport, RenderError> {
        let frame_start = Instant::now();
        // Views of one frame run one after the other: they may share transient textures.
        self.pool.release_all();
        let textures = self.acquire_textures(passes, view.size, output);
        let mut encoder =
            self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        // The frame's first encoder animates the lights first, before any pass reads them.
        let animation = crate::passes::light_animation::LightAnimationPass;
        let mut with_animation = Vec::new();
        let passes = if self.scene.lights.motions.pending() {
            with_animation.push(&animation as &dyn Pass);
            with_animation.extend_from_slice(passes);
            &with_animation[..]
        } else {
            passes
        };
        let timings = self.record_passes(passes, &mut encoder, view.index, &textures, output_format)?;
        self.scene.lights.motions.recorded();
        // The view's counters go to the frame's read-back slot, after the passes wrote them.
        let clusters = self.clusters.get(view.index).and_then(Option::as_ref);
        let tonemapped = passes.iter().any(|p| crate::graph::is::<crate::passes::tonemap::TonemapPass>(*p));
        self.ring.end_view(
            &mut encoder,
            clusters.filter(|_| builds_clusters).map(|c| c.counters_buffer()),
            tonemapped.then_some(&self.scene.nonfinite.counter),
            timings.len(),
        );
        let submit = Instant::now();
        self.gpu.queue.submit([encoder.finish()]);
        self.phases.submit_ms += submit.elapsed().as_secs_f64() * 1e3;
        self.last_textures = textures;
        let errors = self.gpu.take_errors();
        if !errors.is_empty() {
            return Err(RenderError::Device(errors.join("; ")));
        }
        let mut report = self.view_report(snapshot, view, timings);
        report.frame_cpu_ms = frame_start.elapsed().as_secs_f64() * 1e3;
        Ok(report)
    }

    /// The transient textures `passes` create, at `size` scaled by each spec, from the pool;
    /// with [`OUTPUT`] as `output`.
    fn acquire_textures(
        &mut self,
        passes: &[&dyn Pass],
        size: glam::UVec2,
        output: &wgpu::TextureView,
    ) -> HashMap<ResourceName, wgpu::TextureView> {
        let mut textures = HashMap::new();
        textures.insert(OUTPUT, output.clone());
        for pass in passes {
            for spec in pass.creates() {
                // Passes may create the same texture (post-processing passes, the HDR swap).
                if textures.contains_key(&spec.name) {
                    continue;
                }
                let scaled = |v: u32| ((v as f32 * spec.scale).round() as u32).max(1);
                // HDR images to be read back (`set_hdr_readback`) must be copyable.
                let usage = if self.hdr_readback && (spec.name == HDR || spec.name == HDR_SWAP) {
                    spec.usage | wgpu::TextureUsages::COPY_SRC
                } else {
                    spec.usage
                };
                let key =
                    TextureKey { width: scaled(size.x), height: scaled(size.y), format: spec.format, usage };
                textures.insert(spec.name, self.pool.acquire(&self.gpu.device, key, spec.name.name()));
            }
        }
        textures
    }

    /// Records `passes` into `encoder` for view `view_index`, timing each on the CPU and, where
    /// the device can, on the GPU.
    fn record_passes(
        &mut self,
        passes: &[&dyn Pass],
        encoder: &mut wgpu::CommandEncoder,
        view_index: usize,
        textures: &HashMap<ResourceName, wgpu::TextureView>,
        output_format: wgpu::TextureFormat,
    ) -> Result<Vec<PassTiming>, RenderError> {
        let mut timings = Vec::with_capacity(passes.len());
        let clusters = self.clusters.get(view_index).and_then(Option::as_ref);
        let hdr_swapped = std::cell::Cell::new(false);
        for pass in passes {
            let timer = self.ring.timer();
            let mut ctx = PassContext {
                gpu: &self.gpu,
                scene: &self.scene,
                pipelines: &self.pipelines,
                clusters,
                shadows: Some(&self.shadows),
                environments: Some(&self.environments),
                bindings: &self.bindings,
                encoder,
                output_format,
                textures,
                hdr_swapped: &hdr_swapped,
                timer: timer.map(|(query_set, _)| query_set),
                pass_index: timer.map_or(0, |(_, index)| index),
                stamps: (false, false),
                pass_type: (&**pass as &dyn std::any::Any).type_id(),
            };
            let start = Instant::now();
            pass.record(&mut ctx)?;
            let cpu_ms = start.elapsed().as_secs_f64() * 1e3;
            self.phases.record_ms += cpu_ms;
            let timed = ctx.stamps.0 && ctx.stamps.1;
            self.ring.pass_recorded(timed);
            timings.push(PassTiming {
                name: pass.name().to_string(),
                pass_type: Some((&**pass as &dyn std::any::Any).type_id()),
                gpu_ms: None,
                gpu_trusted: !(pass.is_compute() && self.cpu_adapter),
                cpu_ms,
            });
        }
        self.last_hdr_swapped = hdr_swapped.get();
        Ok(timings)
    }

    /// The report of a view just submitted, with its passes' `timings` (GPU times, the
    /// non-finite count and the cluster report arrive with the read-back).
    fn view_report(
        &self,
        snapshot: &FrameSnapshot,
        view: &RenderView,
        timings: Vec<PassTiming>,
    ) -> FrameReport {
        FrameReport {
            frame_index: snapshot.frame_index,
            width: view.size.x,
            height: view.size.y,
            pipeline: view.settings.pipeline,
            frame_gpu_ms: None,
            passes: timings,
            light_count: self.scene.lights.count - self.scene.lights.invalid_point_lights,
            invalid_lights: self.scene.lights.invalid_lights,
            directional_lights: self.scene.lights.directional_count,
            dropped_directional_lights: self.scene.lights.dropped_directional_lights,
            invalid_cameras: 0,
            sanitized_cameras: 0,
            nonfinite_pixels: None,
            instance_count: self.scene.instances.draws.len() as u32,
            invalid_instances: self.scene.instances.invalid_instances,
            collapsed_instances: self.scene.instances.collapsed_instances,
            transient_textures: self.pool.live() as u32,
            transient_bytes: self.pool.frame_bytes(),
            transient_allocations: self.pool.allocations(),
            clusters: None,
            views: Vec::new(),
            light_uploads: 0,
            light_upload_bytes: 0,
            device_recoveries: 0,
            shadows: (self.shadows.report.casting_lights > 0).then_some(self.shadows.report),
            environment: self.environments.report.named.then_some(self.environments.report),
            ..Default::default()
        }
    }
}
