//! Bloom: light above a threshold spreads into its surroundings. Three kinds of pass, all in
//! `shaders/bloom.wgsl`, added only when the camera has bloom:
//! 1. [`BloomBrightPass`]: the soft-thresholded HDR colour into level 0 (half resolution in the
//!    downsampled chain, full resolution in the full-resolution chain);
//! 2. [`BloomBlurPass`] × 2 per iteration: a separable 9-tap gaussian, horizontal then
//!    vertical. In the downsampled chain iteration `k` reads level `k − 1` (twice its size, so the
//!    bilinear taps also box-filter it down) and writes level `k` at `1/2^(k+1)` of the viewport;
//!    in the full-resolution chain every iteration blurs level 0 again at full resolution;
//! 3. [`BloomUpsamplePass`] (downsampled chain only), from the smallest level up: level `k` is
//!    added (bilinear, blend One + One) to level `k − 1`, so level 0 ends up holding the sum of
//!    all levels at a fraction of the cost of sampling each at full resolution;
//! 4. [`BloomCompositePass`]: level 0 ÷ level count × intensity (the mean of the levels), added
//!    (blend One + One) to the HDR target before tone mapping.

use super::HDR;
use super::common::{FullscreenPipelineDesc, fullscreen_pipeline_desc};
use crate::bindings::Binding;
use crate::context::RenderError;
use crate::graph::{NamedPass, Pass, PassContext, ResourceName, TextureSpec};
use crate::layouts::{BLOOM_GROUP, GroupLayout};
use crate::pipelines::PipelineKey;
use crate::plan::PlanInputs;
use crate::resources::HDR_FORMAT;
pub use crate::settings::{BloomChain, BloomSettings, MAX_BLOOM_LEVELS};

/// Graph resources: the blurred levels of the chain.
pub const BLOOM_LEVELS: [ResourceName; MAX_BLOOM_LEVELS] = [
    crate::resource!("bloom_0"),
    crate::resource!("bloom_1"),
    crate::resource!("bloom_2"),
    crate::resource!("bloom_3"),
    crate::resource!("bloom_4"),
    crate::resource!("bloom_5"),
];

/// Graph resources: the horizontally blurred intermediate of each level.
pub const BLOOM_TEMPS: [ResourceName; MAX_BLOOM_LEVELS] = [
    crate::resource!("bloom_tmp_0"),
    crate::resource!("bloom_tmp_1"),
    crate::resource!("bloom_tmp_2"),
    crate::resource!("bloom_tmp_3"),
    crate::resource!("bloom_tmp_4"),
    crate::resource!("bloom_tmp_5"),
];

/// The passes of `bloom`, in order.
pub fn bloom_passes(bloom: &BloomSettings) -> Vec<Box<dyn Pass>> {
    let settings = bloom.sanitized();
    let levels = bloom.levels();
    let mut passes: Vec<Box<dyn Pass>> = Vec::with_capacity(2 + 2 * levels);
    let full = bloom.chain == BloomChain::FullResolution;
    let scale = |k: usize| if full { 1.0 } else { 0.5f32.powi(k as i32 + 1) };
    passes.push(Box::new(BloomBrightPass { settings, scale: scale(0) }));
    for k in 0..levels {
        // Downsampled: level k from level k-1 (level 0 blurs the bright pass in place).
        // Full resolution: level 0 again and again.
        let (level, source) = if full { (0, 0) } else { (k, k.saturating_sub(1)) };
        let creates = !full || k == 0;
        passes.push(Box::new(BloomBlurPass {
            source: BLOOM_LEVELS[source],
            target: BLOOM_TEMPS[level],
            horizontal: true,
            create: creates.then_some(scale(level)),
        }));
        passes.push(Box::new(BloomBlurPass {
            source: BLOOM_TEMPS[level],
            target: BLOOM_LEVELS[level],
            horizontal: false,
            create: (creates && level > 0).then_some(scale(level)),
        }));
    }
    let used = if full { 1 } else { levels };
    for k in (1..used).rev() {
        passes.push(Box::new(BloomUpsamplePass { source: BLOOM_LEVELS[k], target: BLOOM_LEVELS[k - 1] }));
    }
    passes.push(Box::new(BloomCompositePass { levels: used, intensity: settings.intensity }));
    passes
}

/// Uniforms of the bloom shader (`BloomParams` in `shaders/bloom.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct BloomParams {
    direction: [f32; 2],
    threshold: f32,
    knee: f32,
    intensity: f32,
    level_count: u32,
    _pad: [u32; 2],
}

impl BloomParams {
    fn new() -> Self {
        bytemuck::Zeroable::zeroed()
    }
}

const LEVEL_USAGE: wgpu::TextureUsages =
    wgpu::TextureUsages::RENDER_ATTACHMENT.union(wgpu::TextureUsages::TEXTURE_BINDING);

fn level_spec(name: ResourceName, scale: f32) -> TextureSpec {
    TextureSpec { name, format: HDR_FORMAT, usage: LEVEL_USAGE, scale }
}

/// Which entry point of `bloom.wgsl` a pipeline runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Stage {
    Bright,
    Blur,
    Upsample,
    Composite,
}

impl Stage {
    /// Stages that add to their target instead of replacing it.
    fn adds(self) -> bool {
        matches!(self, Stage::Upsample | Stage::Composite)
    }
}

/// Bloom's pipelines: one per stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct BloomKey {
    stage: Stage,
}

impl PipelineKey for BloomKey {
    type Pipeline = BloomPipeline;
}

/// The pipeline of one bloom stage.
struct BloomPipeline {
    pipeline: wgpu::RenderPipeline,
    layout: GroupLayout,
    sampler: wgpu::Sampler,
}

impl BloomPipeline {
    fn new(device: &wgpu::Device, stage: Stage) -> Result<Self, RenderError> {
        let (label, entry) = match stage {
            Stage::Bright => ("bloom_bright", "fs_bright"),
            Stage::Blur => ("bloom_blur", "fs_blur"),
            Stage::Upsample => ("bloom_upsample", "fs_upsample"),
            Stage::Composite => ("bloom_composite", "fs_composite"),
        };
        let layout = BLOOM_GROUP.create_layout(device, Default::default());
        // The composite adds to the HDR image; the other stages overwrite their level.
        let blend = stage.adds().then_some(wgpu::BlendState {
            color: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::One,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
            alpha: wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::Zero,
                dst_factor: wgpu::BlendFactor::One,
                operation: wgpu::BlendOperation::Add,
            },
        });
        let pipeline = fullscreen_pipeline_desc(
            device,
            &FullscreenPipelineDesc {
                label,
                shader: "bloom.wgsl",
                layouts: &[&layout],
                fragment: entry,
                output: HDR_FORMAT,
                blend,
                depth: None,
                constants: &[],
            },
        )?;
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some(label),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Ok(BloomPipeline { pipeline, layout, sampler })
    }
}

/// Records one full-screen draw of `stage` into `target` with `params` and `sources`.
fn draw(
    ctx: &mut PassContext<'_>,
    stage: Stage,
    params: BloomParams,
    sources: &[ResourceName],
    target: ResourceName,
) -> Result<(), RenderError> {
    let device = &ctx.gpu.device;
    let pipeline =
        ctx.pipelines.get_or_create(BloomKey { stage }, |k| BloomPipeline::new(device, k.stage))?;
    // One uniform per draw of the chain: each stage is a pass type of its own, and a stage's
    // passes write different levels.
    let level =
        BLOOM_LEVELS.iter().chain(&BLOOM_TEMPS).position(|&n| n == target).map_or(u64::MAX, |i| i as u64);
    let params = ctx.uniform_at(level, &params);
    let textures = sources.iter().map(|&name| ctx.texture(name)).collect::<Result<Vec<_>, _>>()?;
    let mut bindings = vec![Binding::Buffer(&params), Binding::Sampler(&pipeline.sampler)];
    bindings.extend(textures.into_iter().map(Binding::Texture));
    let bind_group = ctx.bind_group(&pipeline.layout, &bindings);
    let view = ctx.texture(target)?;
    let timestamps = ctx.render_timestamps(true, true);
    // The composite loads the HDR image and adds to it; the other stages replace their level.
    let load = if stage.adds() { wgpu::LoadOp::Load } else { wgpu::LoadOp::Clear(wgpu::Color::BLACK) };
    let mut pass = ctx.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("bloom"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
        })],
        depth_stencil_attachment: None,
        timestamp_writes: timestamps,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    pass.set_pipeline(&pipeline.pipeline);
    pass.set_bind_group(BLOOM_GROUP.index, &bind_group, &[]);
    pass.draw(0..3, 0..1);
    Ok(())
}

/// Bright pass: the HDR colour above the (soft) threshold into level 0.
pub struct BloomBrightPass {
    /// Threshold and knee.
    pub settings: BloomSettings,
    /// Size of level 0 relative to the viewport.
    pub scale: f32,
}

impl NamedPass for BloomBrightPass {
    const NAME: &'static str = "bloom_bright";
}

impl Pass for BloomBrightPass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        vec![HDR]
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![BLOOM_LEVELS[0]]
    }
    fn creates(&self) -> Vec<TextureSpec> {
        vec![level_spec(BLOOM_LEVELS[0], self.scale)]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let params = BloomParams {
            threshold: self.settings.threshold,
            knee: self.settings.knee,
            ..BloomParams::new()
        };
        draw(ctx, Stage::Bright, params, &[HDR], BLOOM_LEVELS[0])
    }
}

/// One direction of the separable 9-tap gaussian, from `source` into `target`.
pub struct BloomBlurPass {
    /// Level read.
    pub source: ResourceName,
    /// Level written.
    pub target: ResourceName,
    /// Horizontal (1×9) or vertical (9×1).
    pub horizontal: bool,
    /// `Some(scale)` when this pass creates `target` (its first writer).
    pub create: Option<f32>,
}

impl Pass for BloomBlurPass {
    fn name(&self) -> &'static str {
        if self.horizontal { "bloom_blur_h" } else { "bloom_blur_v" }
    }
    fn reads(&self) -> Vec<ResourceName> {
        vec![self.source]
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![self.target]
    }
    fn creates(&self) -> Vec<TextureSpec> {
        self.create.map(|scale| level_spec(self.target, scale)).into_iter().collect()
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        // One texel of the target along the blur direction, in uv units.
        let target = ctx.texture(self.target)?.texture();
        let direction = if self.horizontal {
            [1.0 / target.width().max(1) as f32, 0.0]
        } else {
            [0.0, 1.0 / target.height().max(1) as f32]
        };
        draw(ctx, Stage::Blur, BloomParams { direction, ..BloomParams::new() }, &[self.source], self.target)
    }
}

/// Adds level `source` (bilinearly upsampled) to the next larger level `target`.
pub struct BloomUpsamplePass {
    /// The smaller level.
    pub source: ResourceName,
    /// The level twice its size, added to.
    pub target: ResourceName,
}

impl NamedPass for BloomUpsamplePass {
    const NAME: &'static str = "bloom_upsample";
}

impl Pass for BloomUpsamplePass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        vec![self.source, self.target]
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![self.target]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        draw(ctx, Stage::Upsample, BloomParams::new(), &[self.source], self.target)
    }
}

/// Adds level 0 (holding the sum of `levels` levels) ÷ `levels` × intensity to the HDR image.
pub struct BloomCompositePass {
    /// Levels summed into level 0 (1 to [`MAX_BLOOM_LEVELS`]).
    pub levels: usize,
    /// Weight of the bloom.
    pub intensity: f32,
}

impl NamedPass for BloomCompositePass {
    const NAME: &'static str = "bloom_composite";
}

impl Pass for BloomCompositePass {
    fn name(&self) -> &'static str {
        Self::NAME
    }
    fn reads(&self) -> Vec<ResourceName> {
        // HDR: ordered after the lighting that writes it (it is blended into, not sampled).
        vec![HDR, BLOOM_LEVELS[0]]
    }
    fn writes(&self) -> Vec<ResourceName> {
        vec![HDR]
    }
    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let levels = self.levels.clamp(1, MAX_BLOOM_LEVELS) as u32;
        let params = BloomParams { intensity: self.intensity, level_count: levels, ..BloomParams::new() };
        draw(ctx, Stage::Composite, params, &[BLOOM_LEVELS[0]], HDR)
    }
}

/// Bright pass, blur chain and composite: needed when the camera has bloom and no debug view
/// replaces the image.
pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn Pass>>) {
    if let Some(mut bloom) = p.view.camera.and_then(|c| c.bloom)
        && p.shows_image()
    {
        // The threshold is in exposed brightness: the bright pass reads the HDR image before
        // the tone map multiplies it by the exposure.
        bloom.threshold /= p.view.exposure().max(f32::MIN_POSITIVE);
        out.extend(bloom_passes(&bloom));
    }
}
