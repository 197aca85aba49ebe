//! The GPU context: instance, adapter, device and queue, for headless rendering or a surface.

use manylight_core::LightLimit;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use thiserror::Error;

/// What to tell a user whose machine has no usable GPU adapter.
pub const NO_ADAPTER_HELP: &str = "no GPU adapter found. manylight needs Vulkan, Metal, DX12 or \
OpenGL. On Debian/Ubuntu without a GPU install the software Vulkan driver (lavapipe): \
`sudo apt-get install -y mesa-vulkan-drivers`; with a GPU, install its vendor driver";

/// Errors of the GPU side.
#[derive(Clone, Debug, Error)]
pub enum RenderError {
    /// No adapter could be found.
    #[error("{NO_ADAPTER_HELP} ({0})")]
    NoAdapter(String),
    /// The adapter refused to create a device.
    #[error("could not create a GPU device on `{adapter}`: {message}")]
    NoDevice {
        /// Adapter name.
        adapter: String,
        /// Driver's message.
        message: String,
    },
    /// The window surface could not be created.
    #[error("could not create a window surface: {0}")]
    Surface(String),
    /// The render settings ask for a combination that cannot work.
    #[error("unsupported render settings: {0}")]
    UnsupportedSettings(String),
    /// A shader was not embedded.
    #[error(transparent)]
    Shader(#[from] crate::shaders::ShaderError),
    /// Reading back a texture or query buffer failed.
    #[error("GPU readback failed: {0}")]
    Readback(String),
    /// A texture of the scene exceeds what the device supports.
    #[error("texture `{label}` is {width}x{height}, larger than this device's limit of {limit}")]
    TextureTooLarge {
        /// Texture label (file name).
        label: String,
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// Device limit.
        limit: u32,
    },
    /// A pipeline does not match its bind groups' declaration ([`crate::layouts`]).
    #[error(transparent)]
    Binding(#[from] BindingError),
    /// The render graph is inconsistent (a pass reads what nobody writes, or a cycle).
    #[error("render graph: {0}")]
    Graph(String),
    /// The device reported a validation or out-of-memory error.
    #[error("GPU error: {0}")]
    Device(String),
    /// A buffer (lights, instances, cluster lists, a mesh) would exceed what the device can
    /// bind or allocate.
    #[error("`{label}` needs {bytes} bytes, more than this device's {limit_name} of {limit} bytes")]
    BufferTooLarge {
        /// The buffer's label.
        label: String,
        /// Bytes the frame needs.
        bytes: u64,
        /// The device's limit.
        limit: u64,
        /// Which limit: `max_storage_buffer_binding_size` or `max_buffer_size`.
        limit_name: &'static str,
    },
    /// The frame has 2³² − 1 or more light–cluster (or light–tile) pairs: more than the cluster
    /// build's u32 counters and offsets hold. Refused rather than built from a wrapped total.
    #[error(
        "the frame has at least {} {what} pairs, more than the cluster build's 32-bit counters hold (PAIR_COUNT_SATURATED); use fewer or smaller lights, or a coarser grid",
        u32::MAX
    )]
    TooManyPairs {
        /// `light–cluster`, `light–tile` or `light–coarse-tile`.
        what: &'static str,
    },
    /// A shader loop would run longer than the adapter lets one invocation loop (lavapipe
    /// ends an invocation after 65 535 iterations, which would drop lights silently).
    #[error(
        "{what} needs {iterations} loop iterations in one shader invocation, more than this adapter's limit of {limit} (LAVAPIPE_LOOP_LIMIT: llvmpipe would end the invocation and drop lights); use fewer or smaller lights, a finer cluster grid, or a GPU"
    )]
    LoopLimit {
        /// The loop: a tile's or cluster's light list, naive forward's light loop.
        what: String,
        /// Iterations it needs.
        iterations: u64,
        /// The adapter's limit.
        limit: u32,
    },
    /// A render target larger than the device's largest 2D texture.
    #[error(
        "a {width}x{height} render target exceeds this device's limit of {limit} pixels per side (max_texture_dimension_2d)"
    )]
    TargetTooLarge {
        /// Requested width.
        width: u32,
        /// Requested height.
        height: u32,
        /// The device's limit.
        limit: u32,
    },
    /// The GPU device was lost (driver reset, device removed, `Device::destroy`) and the
    /// renderer could not go on: recreating it failed, or it was lost too often.
    #[error("the GPU device was lost ({reason}) and could not be recreated: {why}")]
    DeviceLost {
        /// What the driver said when the device was lost.
        reason: String,
        /// Why the renderer gave up.
        why: String,
    },
    /// Something asked to wait for the GPU in a browser, where nothing may block (a read-back
    /// that is not asynchronous, or more frames in flight than the ring holds).
    #[error("a blocking wait for the GPU was asked for, and a browser cannot block")]
    BlockingWait,
    /// The GPU did not finish submitted work within [`GPU_WAIT_TIMEOUT`] (a hung or lost
    /// device); the frame is abandoned instead of freezing the caller.
    #[error(
        "the GPU did not finish its work within {seconds} s (GPU_WAIT_TIMEOUT): hung or lost device ({message})"
    )]
    GpuTimeout {
        /// The limit that was reached.
        seconds: u64,
        /// What the driver said.
        message: String,
    },
}

/// Longest wait for the GPU to finish submitted work. Generous, because a CPU rasteriser
/// (lavapipe) takes minutes for naive forward with a hundred thousand lights; past it a
/// frame fails with [`RenderError::GpuTimeout`] instead of freezing the app.
pub const GPU_WAIT_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(600);

/// Instance, adapter, device and queue, shared by every part of the renderer.
#[derive(Clone)]
pub struct GpuContext {
    /// The wgpu instance (needed to create surfaces).
    pub instance: wgpu::Instance,
    /// The chosen adapter.
    pub adapter: wgpu::Adapter,
    /// The logical device.
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// Adapter name, driver and backend, for logs and reports.
    pub info: wgpu::AdapterInfo,
    /// True when render-pass timestamp queries are available.
    pub timestamps: bool,
    /// Uncaptured errors, recorded by the error callback.
    pub errors: Arc<std::sync::Mutex<Vec<String>>>,
    /// Set by the device-lost callback: why the device was lost.
    lost: Arc<std::sync::Mutex<Option<String>>>,
    /// What this device was asked to create and wait for (see [`GpuCounts`]).
    counters: Arc<GpuCounters>,
}

/// Running totals of what a [`GpuContext`] created and how often the CPU waited for the GPU.
/// The renderer creates every buffer and bind group and does every wait through the context,
/// so the totals are complete; a frame reports its share in `FrameReport`.
#[derive(Debug, Default)]
struct GpuCounters {
    buffers: AtomicU64,
    bind_groups: AtomicU64,
    blocking_waits: AtomicU64,
    bytes_uploaded: AtomicU64,
}

/// A copy of a context's totals ([`GpuContext::counts`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuCounts {
    /// Buffers created.
    pub buffers: u64,
    /// Bind groups created.
    pub bind_groups: u64,
    /// Times the CPU blocked until the GPU finished submitted work.
    pub blocking_waits: u64,
    /// Bytes the CPU handed to the GPU: buffer and texture writes and the contents of buffers
    /// created with data ([`GpuContext::write_buffer`], [`GpuContext::write_texture`],
    /// [`GpuContext::create_buffer_init`]).
    pub bytes_uploaded: u64,
}

impl GpuCounts {
    /// What happened between `earlier` and `self`.
    pub fn since(self, earlier: GpuCounts) -> GpuCounts {
        GpuCounts {
            buffers: self.buffers.saturating_sub(earlier.buffers),
            bind_groups: self.bind_groups.saturating_sub(earlier.bind_groups),
            blocking_waits: self.blocking_waits.saturating_sub(earlier.blocking_waits),
            bytes_uploaded: self.bytes_uploaded.saturating_sub(earlier.bytes_uploaded),
        }
    }
}

impl GpuContext {
    /// Waits until the GPU has finished all submitted work, at most [`GPU_WAIT_TIMEOUT`]
    /// (a blocking wait: counted in [`GpuCounts::blocking_waits`]).
    pub fn wait_idle(&self) -> Result<(), RenderError> {
        self.wait_for(None)
    }

    /// Waits until the GPU has finished `submission` (all submitted work when `None`), at most
    /// [`GPU_WAIT_TIMEOUT`]; counted in [`GpuCounts::blocking_waits`].
    ///
    /// A browser cannot block: there this returns [`RenderError::BlockingWait`] and counts
    /// nothing, so a path that would wait fails with a message instead of freezing the page.
    pub fn wait_for(&self, submission: Option<wgpu::SubmissionIndex>) -> Result<(), RenderError> {
        if cfg!(target_arch = "wasm32") {
            return Err(RenderError::BlockingWait);
        }
        self.counters.blocking_waits.fetch_add(1, Ordering::Relaxed);
        self.device
            .poll(wgpu::PollType::Wait { submission_index: submission, timeout: Some(GPU_WAIT_TIMEOUT) })
            .map(|_| ())
            .map_err(|e| RenderError::GpuTimeout {
                seconds: GPU_WAIT_TIMEOUT.as_secs(),
                message: e.to_string(),
            })
    }

    /// Whether the CPU may wait for the GPU here: everywhere but a browser, where a wait would
    /// freeze the page (there read-backs arrive between animation frames).
    pub fn can_block(&self) -> bool {
        cfg!(not(target_arch = "wasm32"))
    }

    /// Lets finished GPU work run its callbacks (mapped read-backs) without waiting.
    pub fn poll(&self) {
        let _ = self.device.poll(wgpu::PollType::Poll);
    }

    /// Creates a buffer (counted in [`GpuCounts::buffers`]).
    pub fn create_buffer(&self, desc: &wgpu::BufferDescriptor<'_>) -> wgpu::Buffer {
        self.counters.buffers.fetch_add(1, Ordering::Relaxed);
        self.device.create_buffer(desc)
    }

    /// Creates a buffer with its contents (counted in [`GpuCounts::buffers`]).
    ///
    /// As wgpu's `DeviceExt::create_buffer_init` (mapped at creation, size padded to
    /// `COPY_BUFFER_ALIGNMENT`), but a buffer that cannot be mapped — its device is lost or out
    /// of memory, so the buffer is invalid — is returned unfilled instead of panicking: the frame
    /// then fails on the lost device and the renderer recovers (wgpu's helper panics there,
    /// inside the frame, where no recovery can run).
    pub fn create_buffer_init(&self, desc: &wgpu::util::BufferInitDescriptor<'_>) -> wgpu::Buffer {
        self.counters.buffers.fetch_add(1, Ordering::Relaxed);
        let len = desc.contents.len() as u64;
        self.counters.bytes_uploaded.fetch_add(len, Ordering::Relaxed);
        let align = wgpu::COPY_BUFFER_ALIGNMENT;
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: desc.label,
            size: len.div_ceil(align).max(1) * align,
            usage: desc.usage,
            mapped_at_creation: true,
        });
        match buffer.get_mapped_range_mut(..) {
            Ok(mut range) => range.slice(..desc.contents.len()).copy_from_slice(desc.contents),
            Err(e) => tracing::warn!(
                "buffer `{}` could not be filled (lost device or out of memory): {e}",
                desc.label.unwrap_or("unnamed")
            ),
        }
        buffer.unmap();
        buffer
    }

    /// Writes `data` into `buffer` at `offset` (the queue's write; counted in
    /// [`GpuCounts::bytes_uploaded`]).
    pub fn write_buffer(&self, buffer: &wgpu::Buffer, offset: u64, data: &[u8]) {
        self.counters.bytes_uploaded.fetch_add(data.len() as u64, Ordering::Relaxed);
        self.queue.write_buffer(buffer, offset, data);
    }

    /// Writes `data` into a texture (the queue's write; counted in
    /// [`GpuCounts::bytes_uploaded`]).
    pub fn write_texture(
        &self,
        texture: wgpu::TexelCopyTextureInfo<'_>,
        data: &[u8],
        layout: wgpu::TexelCopyBufferLayout,
        size: wgpu::Extent3d,
    ) {
        self.counters.bytes_uploaded.fetch_add(data.len() as u64, Ordering::Relaxed);
        self.queue.write_texture(texture, data, layout, size);
    }

    /// Creates a bind group (counted in [`GpuCounts::bind_groups`]).
    pub fn create_bind_group(&self, desc: &wgpu::BindGroupDescriptor<'_>) -> wgpu::BindGroup {
        self.counters.bind_groups.fetch_add(1, Ordering::Relaxed);
        self.device.create_bind_group(desc)
    }

    /// What this context created and waited for so far.
    pub fn counts(&self) -> GpuCounts {
        GpuCounts {
            buffers: self.counters.buffers.load(Ordering::Relaxed),
            bind_groups: self.counters.bind_groups.load(Ordering::Relaxed),
            blocking_waits: self.counters.blocking_waits.load(Ordering::Relaxed),
            bytes_uploaded: self.counters.bytes_uploaded.load(Ordering::Relaxed),
        }
    }

    /// Creates a context without a surface (headless rendering, tests, benchmarks). Blocks
    /// until the device arrives: native only (a browser uses [`GpuContext::request`]).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn headless() -> Result<GpuContext, RenderError> {
        let instance = new_instance();
        Self::with_instance(instance, None)
    }

    /// A context on `instance` held to WebGL2's limits ([`GpuContext::request_webgl2`]),
    /// without a surface. Blocks until the device arrives: native only (tests of the
    /// texture-list path; an instance of `wgpu::Backends::GL` runs it through naga's GLSL).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn webgl2_with_instance(instance: wgpu::Instance) -> Result<GpuContext, RenderError> {
        pollster::block_on(Self::request_webgl2(instance, None))
    }

    /// Creates a context on `instance` whose adapter can present to `surface` (if given).
    /// Blocks until the device arrives: native only (a browser uses [`GpuContext::request`]).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn with_instance(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<GpuContext, RenderError> {
        pollster::block_on(Self::request(instance, surface))
    }

    /// Requests an adapter and a device on `instance` (one able to present to `surface`, if
    /// given) and resolves to the context when the device arrives. Native callers block on it
    /// ([`GpuContext::with_instance`]); a browser awaits it, as its API is asynchronous.
    ///
    /// The device gets the adapter's limits, so a browser's WebGPU adapter that offers more
    /// than WebGPU's defaults (storage buffers per stage, colour attachment bytes) lends them.
    pub async fn request(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<GpuContext, RenderError> {
        let adapter = request_adapter(&instance, surface).await?;
        let timestamps = adapter.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let mut required_features = wgpu::Features::empty();
        if timestamps {
            required_features |= wgpu::Features::TIMESTAMP_QUERY;
        }
        // Light volumes keep sphere proxies that cross the far plane (depth clamped, not clipped).
        let unclipped_depth = adapter.features().contains(wgpu::Features::DEPTH_CLIP_CONTROL);
        if unclipped_depth {
            required_features |= wgpu::Features::DEPTH_CLIP_CONTROL;
        }
        // Light volumes sum their lights in an rgba32f target where blending it is supported.
        if adapter.features().contains(wgpu::Features::FLOAT32_BLENDABLE) {
            required_features |= wgpu::Features::FLOAT32_BLENDABLE;
        }
        // The shadow pass cuts each cube face to its atlas tile with clip distances where it can
        // (otherwise it discards the fragments outside the tile).
        if adapter.features().contains(wgpu::Features::CLIP_DISTANCES) {
            required_features |= wgpu::Features::CLIP_DISTANCES;
        }
        let required_limits = required_limits(&adapter.limits());
        Self::open(instance, adapter, required_features, required_limits).await
    }

    /// Requests an adapter and a device held to WebGL2's limits
    /// (`wgpu::Limits::downlevel_webgl2_defaults`, with the adapter's texture sizes) and no
    /// optional feature: the device of the texture-list path ([`crate::texture_lists`]). In a
    /// browser `instance` has the GL backend and `surface` is a canvas's (wgpu's WebGL2 backend
    /// finds its adapter through a surface); natively any adapter is held to those limits, so
    /// a storage buffer or a compute shader fails wgpu's validation as it would on WebGL2.
    pub async fn request_webgl2(
        instance: wgpu::Instance,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<GpuContext, RenderError> {
        let adapter = request_adapter(&instance, surface).await?;
        let limits = wgpu::Limits::downlevel_webgl2_defaults().using_resolution(adapter.limits());
        Self::open(instance, adapter, wgpu::Features::empty(), limits).await
    }

    /// The device and queue of `adapter` with `required_features` and `required_limits`, with
    /// the error and device-loss callbacks installed.
    async fn open(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
        required_features: wgpu::Features,
        required_limits: wgpu::Limits,
    ) -> Result<GpuContext, RenderError> {
        let info = adapter.get_info();
        let timestamps = required_features.contains(wgpu::Features::TIMESTAMP_QUERY);
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("manylight"),
                required_features,
                required_limits,
                ..Default::default()
            })
            .await
            .map_err(|e| RenderError::NoDevice { adapter: info.name.clone(), message: e.to_string() })?;
        let errors = Arc::new(std::sync::Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            // The display text lists the causes on the lines after the kind.
            let message = e.to_string().split_whitespace().collect::<Vec<_>>().join(" ");
            tracing::error!("wgpu: {message}");
            if let Ok(mut v) = sink.lock() {
                v.push(message);
            }
        }));
        let lost = Arc::new(std::sync::Mutex::new(None));
        let lost_sink = lost.clone();
        device.set_device_lost_callback(move |reason, message| {
            let what = match reason {
                wgpu::DeviceLostReason::Destroyed => "destroyed".to_string(),
                wgpu::DeviceLostReason::Unknown if message.is_empty() => "lost by the driver".to_string(),
                wgpu::DeviceLostReason::Unknown => format!("lost by the driver: {message}"),
            };
            tracing::error!("the GPU device was {what}");
            if let Ok(mut slot) = lost_sink.lock() {
                slot.get_or_insert(what);
            }
        });
        tracing::info!(
            "GPU adapter: {} ({:?}, {:?}, driver {}), timestamps: {timestamps}",
            info.name,
            info.device_type,
            info.backend,
            info.driver_info
        );
        let counters = Arc::new(GpuCounters::default());
        Ok(GpuContext { instance, adapter, device, queue, info, timestamps, errors, lost, counters })
    }

    /// A new device and queue on the same instance, after this one was lost; `surface`, when
    /// given, is a window surface the new adapter must be able to present to.
    ///
    /// In a browser a device arrives asynchronously, so it cannot be recreated within a frame:
    /// the loss is returned as [`RenderError::DeviceLost`] and the page reloads to recover.
    pub fn recreate(&self, surface: Option<&wgpu::Surface<'_>>) -> Result<GpuContext, RenderError> {
        #[cfg(not(target_arch = "wasm32"))]
        return Self::with_instance(self.instance.clone(), surface);
        #[cfg(target_arch = "wasm32")]
        {
            let _ = surface;
            Err(RenderError::DeviceLost {
                reason: self.lost().unwrap_or_else(|| "lost".into()),
                why: "a browser's device arrives asynchronously; reload the page".into(),
            })
        }
    }

    /// Why the device was lost, if it was. Polls the device without waiting first, so a loss
    /// that the driver reported since the last wait is seen.
    pub fn lost(&self) -> Option<String> {
        if let Some(reason) = self.lost_reason() {
            return Some(reason);
        }
        // A lost device may answer the poll with an error; the callback has fired by then.
        self.poll();
        self.lost_reason()
    }

    fn lost_reason(&self) -> Option<String> {
        self.lost.lock().ok().and_then(|slot| slot.clone())
    }

    /// Most lights this device's light buffer can hold (its largest storage binding over the
    /// size of a `GpuPointLight`): past it a frame fails with [`RenderError::BufferTooLarge`].
    pub fn light_limit(&self) -> LightLimit {
        light_limit_of(&self.device.limits())
    }

    /// Largest 2D texture side this device accepts.
    pub fn max_texture_size(&self) -> u32 {
        self.device.limits().max_texture_dimension_2d
    }

    /// Takes the device errors recorded since the last call.
    pub fn take_errors(&self) -> Vec<String> {
        self.errors.lock().map(|mut v| std::mem::take(&mut *v)).unwrap_or_default()
    }
}

/// The adapter a context on `instance` renders with (one able to present to `surface`, if given).
async fn request_adapter(
    instance: &wgpu::Instance,
    surface: Option<&wgpu::Surface<'_>>,
) -> Result<wgpu::Adapter, RenderError> {
    instance
        .request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: wgpu::PowerPreference::HighPerformance,
            force_fallback_adapter: false,
            compatible_surface: surface,
            apply_limit_buckets: false,
        })
        .await
        .map_err(|e| RenderError::NoAdapter(e.to_string()))
}

/// The limits a device is requested with: WebGPU's defaults (`wgpu::Limits::default()`, what
/// every adapter gives), raised to the adapter's where the renderer benefits: texture and
/// buffer sizes bound the light count and the target size, the compute limits the cluster
/// build's workgroups, the colour attachment bytes the Full and Packed G-buffers (40 bytes a
/// pixel; WebGPU's default is 32). Everything else stays at WebGPU's defaults, so what
/// runs natively fits a browser's device.
pub fn required_limits(adapter: &wgpu::Limits) -> wgpu::Limits {
    wgpu::Limits {
        max_texture_dimension_2d: adapter.max_texture_dimension_2d,
        max_storage_buffer_binding_size: adapter.max_storage_buffer_binding_size,
        max_buffer_size: adapter.max_buffer_size,
        max_compute_workgroup_storage_size: adapter.max_compute_workgroup_storage_size,
        max_compute_invocations_per_workgroup: adapter.max_compute_invocations_per_workgroup,
        max_compute_workgroup_size_x: adapter.max_compute_workgroup_size_x,
        max_color_attachment_bytes_per_sample: adapter.max_color_attachment_bytes_per_sample,
        ..wgpu::Limits::default()
    }
}

/// The light limit of the adapter a headless context would render with, read without creating
/// a device: for checking a light count before anything is allocated.
#[cfg(not(target_arch = "wasm32"))]
pub fn adapter_light_limit() -> Result<LightLimit, RenderError> {
    let adapter = pollster::block_on(request_adapter(&new_instance(), None))?;
    Ok(light_limit_of(&adapter.limits()))
}

/// The largest buffer a device with `limits` can bind as storage, in bytes (a multiple of 4),
/// and the name of the limit that sets it.
pub(crate) fn max_binding_bytes(limits: &wgpu::Limits) -> (u64, &'static str) {
    if limits.max_storage_buffer_binding_size <= limits.max_buffer_size {
        (limits.max_storage_buffer_binding_size & !3, "max_storage_buffer_binding_size")
    } else {
        (limits.max_buffer_size & !3, "max_buffer_size")
    }
}

/// Most lights a device with `limits` binds in its light buffer.
fn light_limit_of(limits: &wgpu::Limits) -> LightLimit {
    let (bytes, name) = max_binding_bytes(limits);
    LightLimit::from_buffer(bytes, std::mem::size_of::<crate::gpu_types::GpuPointLight>() as u64, name)
}

/// A wgpu instance on the backends from `WGPU_BACKEND` (default: Vulkan, Metal, DX12; set
/// `WGPU_BACKEND=gl` for OpenGL).
pub fn new_instance() -> wgpu::Instance {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
    wgpu::Instance::new(desc)
}

/// A pipeline made with other bind group layouts than its shader's declaration.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum BindingError {
    /// A pipeline was made with other layouts than [`crate::layouts::SHADER_BIND_GROUPS`] gives its entry point.
    #[error(
        "`{shader}` `{entry_point}`: group {group} is declared `{declared}`, the pipeline was given `{given}`"
    )]
    Pipeline {
        /// Shader file.
        shader: String,
        /// Entry point.
        entry_point: String,
        /// Group index.
        group: usize,
        /// The declared group's label (`none` past the declared groups).
        declared: &'static str,
        /// The given layout's label (`none` past the given layouts).
        given: &'static str,
    },
    /// No row of [`crate::layouts::SHADER_BIND_GROUPS`] covers the entry point.
    #[error("`{shader}` `{entry_point}` has no row in SHADER_BIND_GROUPS")]
    Undeclared {
        /// Shader file.
        shader: String,
        /// Entry point.
        entry_point: String,
    },
}
