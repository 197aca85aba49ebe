//! What one rendered frame reports: passes in order with their GPU and CPU times.

use serde::Serialize;

/// Timing of one pass.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PassTiming {
    /// The pass name (also its wgpu label).
    pub name: String,
    /// The pass's type, which code finds it by ([`PassTiming::is`], [`FrameReport::pass`]);
    /// `None` for a timing not made by the renderer.
    #[serde(skip)]
    pub pass_type: Option<std::any::TypeId>,
    /// GPU time from timestamp queries, when the adapter supports them.
    pub gpu_ms: Option<f64>,
    /// False when the figure is known to be unreliable (compute passes on lavapipe).
    pub gpu_trusted: bool,
    /// CPU time spent recording the pass.
    pub cpu_ms: f64,
}

impl PassTiming {
    /// True when the pass timed is a `P`.
    pub fn is<P: crate::graph::Pass>(&self) -> bool {
        self.pass_type == Some(std::any::TypeId::of::<P>())
    }
}

/// Where a frame's CPU time went, by phase (milliseconds), and how many bytes it handed to the
/// GPU. The render-side phases sum to most of [`FrameReport::frame_cpu_ms`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct CpuPhases {
    /// The main world's extraction of the frame's snapshot
    /// ([`crate::FrameSnapshot::extract_cpu_ms`]; 0 for a snapshot made without an app).
    pub extract_ms: f64,
    /// Uploading what the views share: lights, instances, meshes, materials, textures and the
    /// shadow plan (`Renderer::prepare`).
    pub upload_ms: f64,
    /// Bytes handed to the GPU while the frame was prepared and recorded, every phase
    /// (`GpuCounts::bytes_uploaded`).
    pub upload_bytes: u64,
    /// Each view's constants, cluster grid and list sizes (`Renderer::prepare_view`), summed
    /// over the views.
    pub prepare_ms: f64,
    /// Recording the passes, summed over the views.
    pub record_ms: f64,
    /// Handing the command buffers to the queue, summed over the views.
    pub submit_ms: f64,
}

/// The report of one frame. Flat, over 15 fields: it is the `last_frame` object of
/// `manylight render --stats-json` and of the page's `manylight.stats()`, whose field names
/// scripts read; the figures that belong together are already objects of their own
/// ([`CpuPhases`], [`crate::clusters::ClusterReport`], [`crate::settings::ShadowReport`],
/// [`ViewReport`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct FrameReport {
    /// Frame counter.
    pub frame_index: u64,
    /// Viewport size.
    pub width: u32,
    /// Viewport size.
    pub height: u32,
    /// Pipeline name.
    pub pipeline: crate::settings::PipelineKind,
    /// Passes that ran, in order.
    pub passes: Vec<PassTiming>,
    /// CPU time of the frame on the render side: uploads, cluster bounds, recording and
    /// submitting every view (and any wait the frame had: [`FrameReport::blocking_waits`]).
    pub frame_cpu_ms: f64,
    /// The frame's CPU time by phase, and its upload bytes.
    pub cpu: CpuPhases,
    /// Sum of the passes' GPU times, when known.
    pub frame_gpu_ms: Option<f64>,
    /// Point and spot lights rendered (the valid ones).
    pub light_count: u32,
    /// Lights not drawn because a parameter was NaN, infinite or negative (directional ones
    /// included).
    pub invalid_lights: u32,
    /// Directional lights drawn (at most `MAX_DIRECTIONAL_LIGHTS`).
    pub directional_lights: u32,
    /// Valid directional lights past `MAX_DIRECTIONAL_LIGHTS`, not drawn.
    pub dropped_directional_lights: u32,
    /// Cameras refused because their transform was not finite or not invertible (the frame
    /// rendered nothing).
    pub invalid_cameras: u32,
    /// Cameras whose projection was changed to render (see `Projection::sanitized`): a NaN or
    /// infinite parameter, a near plane ≤ 0, a far plane missing or not beyond the near plane,
    /// a field of view outside [`MIN_FOV_Y`, `MAX_FOV_Y`] (`manylight_core::camera`). The frame renders with the changed projection.
    pub sanitized_cameras: u32,
    /// Pixels whose HDR colour was NaN or infinite (counted by the tone map, shown black);
    /// `None` when the frame had no tone map (a debug view replaced it).
    pub nonfinite_pixels: Option<u32>,
    /// Mesh instances drawn.
    pub instance_count: u32,
    /// Instances not drawn because their transform is NaN or infinite.
    pub invalid_instances: u32,
    /// Instances not drawn because their transform collapses the mesh to a line or a point (a
    /// zero scale on two or three axes, of the mesh or of a parent node): they cover no pixel.
    pub collapsed_instances: u32,
    /// Transient textures alive in the pool after the frame.
    pub transient_textures: u32,
    /// Bytes of the transient textures this frame used (render targets, G-buffer, post-stage
    /// chains; texel size × pixels; the output target is not counted).
    pub transient_bytes: u64,
    /// Transient textures created since start-up (reuse keeps this flat).
    pub transient_allocations: u64,
    /// Cluster statistics, when the frame built clusters.
    pub clusters: Option<crate::clusters::ClusterReport>,
    /// What the shadows took, when a light asked to cast one.
    pub shadows: Option<crate::settings::ShadowReport>,
    /// What the environments took, when a view named one: panoramas prefiltered this frame,
    /// views drawn without theirs, prefiltered environments on the GPU.
    pub environment: Option<crate::environment::EnvironmentReport>,
    /// The views the frame rendered, in order (the passes of each are in [`FrameReport::passes`],
    /// one view after the other).
    pub views: Vec<ViewReport>,
    /// Times the light buffer was written this frame: 1 when the frame has lights, whatever the
    /// number of views (they share it).
    pub light_uploads: u32,
    /// Bytes written to the light buffer this frame: only the lights that changed since the
    /// last frame (0 for still lights after their first frame).
    pub light_upload_bytes: u64,
    /// Times the GPU device was found lost and recreated while this frame was rendered (0
    /// normally). A frame in which the loss was found reports no passes: its work went to the
    /// lost device, and the next frame renders on the new one.
    pub device_recoveries: u32,
    /// Times the CPU blocked until the GPU finished work while this frame was prepared and
    /// recorded: 0 in steady state. A frame waits when every read-back slot is still in
    /// flight, when a view's lists have no counts to be sized from
    /// (`ClusterReport::counted_first`), and when pixels are read back (a capture, a
    /// render-to-texture camera).
    pub blocking_waits: u64,
    /// GPU buffers created while this frame was prepared and recorded (0 in steady state: only
    /// new meshes, materials, grown lists and changed sizes create any).
    pub buffers_created: u64,
    /// Bind groups created while this frame was prepared and recorded (0 in steady state).
    pub bind_groups_created: u64,
    /// Frames submitted and not yet read back when this frame was submitted, itself included.
    pub frames_in_flight: u32,
    /// The most frames that may be in flight (the renderer's setting).
    pub frames_in_flight_limit: u32,
}

/// What one view of a frame did.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ViewReport {
    /// Position in the frame's views.
    pub index: usize,
    /// Its render order (`Camera::order`).
    pub order: isize,
    /// `main`, or `texture N` for a render-to-texture view.
    pub target: String,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Names of its passes, in order.
    pub passes: Vec<String>,
    /// Its cluster statistics, when it built clusters.
    pub clusters: Option<crate::clusters::ClusterReport>,
    /// CPU time of the view on the render side (view constants, clusters, record, submit, wait).
    pub cpu_ms: f64,
    /// Sum of its passes' GPU times, when known.
    pub gpu_ms: Option<f64>,
}

impl FrameReport {
    /// Names of the passes in the order they ran.
    pub fn pass_names(&self) -> Vec<&str> {
        self.passes.iter().map(|p| p.name.as_str()).collect()
    }

    /// The timing of the first pass of type `P` this frame ran, if it ran one.
    pub fn pass<P: crate::graph::Pass>(&self) -> Option<&PassTiming> {
        self.passes.iter().find(|p| p.is::<P>())
    }

    /// GPU milliseconds of the first pass of type `P`, if it ran and was timed.
    pub fn pass_gpu_ms<P: crate::graph::Pass>(&self) -> Option<f64> {
        self.pass::<P>().and_then(|p| p.gpu_ms)
    }
}
