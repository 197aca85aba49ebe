//! The light animation pass: lights with an [`ExtractedPointLight::animation`] move and
//! flicker on the GPU. Their motions live in a buffer beside the light buffer (one
//! [`GpuLightMotion`] per light, at the light's index), written only when a light changed; each
//! frame one dispatch (`shaders/light_animation.wgsl`, `passes::light_animation`, first in the
//! frame's first command encoder) writes every animated light's position and colour at
//! [`crate::FrameSnapshot::elapsed_secs`] into the light buffer, before any pass reads it. A scene without animated lights has neither the buffer nor the dispatch.
//!
//! The pass works in f32 from angles the CPU took at an epoch (in f64), adding
//! `speed × (t − epoch)`; to keep that product small, a chunk of lights whose epochs are more
//! than [`EPOCH_SPAN_SECS`] from the frame's time has its angles taken again (one chunk a
//! frame, at most [`LIGHT_CHUNK`] motions).

use crate::bindings::Binding;
use crate::context::{GpuContext, RenderError};
use crate::gpu_types::{GpuLightAnimationParams, GpuLightMotion};
use crate::layouts::{GroupLayout, LIGHT_ANIMATION_GROUP};
use crate::lights::gpu_light_motion;
use crate::pool::GrowableBuffer;
use crate::shaders::ShaderDefs;
use crate::snapshot::{ExtractedPointLight, LIGHT_CHUNK, PointLights};

/// The most seconds between a light's epoch and the time it is shown at before its angles
/// are taken again: at the rig's fastest wave (8.1 rad/s) the pass adds at most ~520 rad, which
/// f32 holds to ~3·10⁻⁵ rad.
pub const EPOCH_SPAN_SECS: f32 = 64.0;

/// Invocations per workgroup of the pass.
pub const WORKGROUP_SIZE: u32 = 64;

/// The pass's group layout and parameters, made the first time a frame animates a light (the
/// pass makes its pipeline through the renderer's pipeline cache).
struct AnimationBindings {
    layout: GroupLayout,
    params: wgpu::Buffer,
}

/// The earliest and latest epoch among a chunk's animated lights.
#[derive(Clone, Copy, Debug, PartialEq)]
struct EpochRange {
    first: f32,
    last: f32,
}

/// The motions of the animated lights on the GPU and the pass that applies them.
#[derive(Default)]
pub struct LightMotions {
    /// One motion per light of the light buffer (`None` while no light animates).
    motions: Option<GrowableBuffer>,
    bindings: Option<AnimationBindings>,
    /// The bind group and the generations of the (light, motion) buffers it was made from.
    bound: Option<((u64, u64), wgpu::BindGroup)>,
    /// Per chunk of lights, the epochs of its animated lights (`None`: it has none).
    epochs: Vec<Option<EpochRange>>,
    /// The chunk the next look for stale epochs starts at.
    cursor: usize,
    /// One run of motions, packed (kept so that it is not allocated again).
    packed: Vec<GpuLightMotion>,
    /// The frame's dispatch is readied and not recorded yet.
    pending: bool,
}

impl LightMotions {
    /// Makes room for the motions of `lights` when any animates, or lets the buffer go when
    /// none does. True when the buffer was (re-)created: every light's motion must be written
    /// again.
    pub fn reserve(&mut self, gpu: &GpuContext, lights: &PointLights) -> Result<bool, RenderError> {
        if lights.animated() == 0 {
            if self.motions.take().is_some() {
                (self.bound, self.epochs) = (None, Vec::new());
            }
            return Ok(false);
        }
        let bytes = (lights.len().max(1) * std::mem::size_of::<GpuLightMotion>()) as u64;
        let created = match &mut self.motions {
            Some(buffer) => buffer.reserve(gpu, bytes)?,
            None => {
                let usage = wgpu::BufferUsages::STORAGE;
                self.motions = Some(GrowableBuffer::new(gpu, "light_motions", usage, bytes));
                self.bound = None;
                true
            }
        };
        if created {
            self.epochs.clear();
        }
        self.epochs.resize(lights.chunks().len(), None);
        Ok(created)
    }

    /// Writes the motions of `lights`, the lights from index `first` on, with their angles at
    /// `t` seconds; returns the bytes written (0 while no light animates).
    pub fn write(&mut self, gpu: &GpuContext, first: usize, lights: &[ExtractedPointLight], t: f32) -> u64 {
        let Some(buffer) = &self.motions else { return 0 };
        self.packed.clear();
        self.packed.extend(lights.iter().map(|l| gpu_light_motion(l, t)));
        let offset = (first * std::mem::size_of::<GpuLightMotion>()) as u64;
        gpu.write_buffer(buffer.buffer(), offset, bytemuck::cast_slice(&self.packed));
        if lights.iter().any(|l| l.animation.is_some())
            && let Some(epochs) = self.epochs.get_mut(first / LIGHT_CHUNK)
        {
            *epochs = Some(match *epochs {
                Some(e) => EpochRange { first: e.first.min(t), last: e.last.max(t) },
                None => EpochRange { first: t, last: t },
            });
        }
        std::mem::size_of_val(self.packed.as_slice()) as u64
    }

    /// Takes the angles of one chunk whose epochs are more than [`EPOCH_SPAN_SECS`] from `t`
    /// again, at `t` (the first such chunk from where the last look stopped); returns the bytes
    /// written.
    pub fn refresh_epochs(&mut self, gpu: &GpuContext, lights: &PointLights, t: f32) -> u64 {
        let count = self.epochs.len().min(lights.chunks().len());
        let stale = |e: &Option<EpochRange>| {
            e.is_some_and(|e| {
                !((t - e.first).abs() <= EPOCH_SPAN_SECS && (e.last - t).abs() <= EPOCH_SPAN_SECS)
            })
        };
        let Some(k) = (0..count).map(|i| (self.cursor + i) % count).find(|&k| stale(&self.epochs[k])) else {
            return 0;
        };
        self.cursor = (k + 1) % count;
        let chunk = lights.chunks()[k].clone();
        self.epochs[k] = None;
        self.write(gpu, k * LIGHT_CHUNK, chunk.lights(), t)
    }

    /// Readies the frame's dispatch, which writes each animated light's position and colour at
    /// `t` seconds into `lights` (`light_count` lights): nothing while no light animates. The
    /// renderer records it (`passes::light_animation::LightAnimationPass`) at the start of the frame's first command
    /// encoder, before any pass reads the lights. Returns the bytes written (the parameters).
    pub fn prepare(
        &mut self,
        gpu: &GpuContext,
        lights: &GrowableBuffer,
        light_count: u32,
        t: f32,
    ) -> Result<u64, RenderError> {
        self.pending = false;
        let Some(motions) = &self.motions else { return Ok(0) };
        let bindings = self.bindings.get_or_insert_with(|| AnimationBindings::new(gpu));
        let params = GpuLightAnimationParams { elapsed_secs: t, light_count, pad: [0; 2] };
        gpu.write_buffer(&bindings.params, 0, bytemuck::bytes_of(&params));
        let generations = (lights.generation(), motions.generation());
        if self.bound.as_ref().is_none_or(|(g, _)| *g != generations) {
            let group = bindings.layout.create_bind_group(
                gpu,
                &[
                    Binding::Buffer(&bindings.params),
                    Binding::Buffer(motions.buffer()),
                    Binding::Buffer(lights.buffer()),
                ],
            );
            self.bound = Some((generations, group));
        }
        self.pending = true;
        Ok(std::mem::size_of::<GpuLightAnimationParams>() as u64)
    }

    /// Whether the frame's dispatch is readied and not recorded yet.
    pub fn pending(&self) -> bool {
        self.pending
    }

    /// The group layout and bind group of the frame's dispatch (one invocation per light, in
    /// workgroups of [`WORKGROUP_SIZE`]), while it is readied and not recorded yet.
    pub fn dispatch(&self) -> Option<(&GroupLayout, &wgpu::BindGroup)> {
        let (bindings, (_, group)) = (self.bindings.as_ref()?, self.bound.as_ref()?);
        self.pending.then_some((&bindings.layout, group))
    }

    /// Marks the frame's dispatch recorded.
    pub fn recorded(&mut self) {
        self.pending = false;
    }
}

impl AnimationBindings {
    fn new(gpu: &GpuContext) -> AnimationBindings {
        let layout = LIGHT_ANIMATION_GROUP.create_layout(&gpu.device, ShaderDefs::default());
        let params = gpu.create_buffer(&wgpu::BufferDescriptor {
            label: Some("light_animation_params"),
            size: std::mem::size_of::<GpuLightAnimationParams>() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        AnimationBindings { layout, params }
    }
}
