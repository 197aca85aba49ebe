//! What an app needs to add a pass of its own: the documented boundary between manylight's
//! render graph and the app's code (`manylight::render::ext`).
//!
//! - A full-screen filter of the HDR image before tone mapping is a [`PostPass`]: a name, its
//!   WGSL and its uniform. Everything else (reads, writes, the second HDR image it writes into,
//!   its pipeline, bind group and uniform buffer, timings) follows from those.
//! - Any other pass implements [`Pass`] and records with its [`PassContext`]:
//!   [`PassContext::uniform`] (a buffer per pass type and contents type, written only when the
//!   value changes), [`PassContext::bind_group`], [`PassContext::post_process_write`].
//! - A stage ([`Stage`]) places the pass next to a built-in one by type: the built-in passes'
//!   types are re-exported here ([`TonemapPass`], …).
//! - A graph resource of the app's own is declared with [`resource!`]: a handle whose identity
//!   is its declaration, so two passes that pick the same label never share it by accident.
//!
//! ```no_run
//! use manylight_render::ext::{PostPass, bytemuck};
//!
//! #[repr(C)]
//! #[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
//! #[bytemuck(crate = "manylight_render::ext::bytemuck")]
//! struct Tint {
//!     rgb_pad: [f32; 4],
//! }
//!
//! struct TintPass(Tint);
//!
//! impl PostPass for TintPass {
//!     const NAME: &'static str = "tint";
//!     const WGSL: &'static str = "//!include common/fullscreen.wgsl
//! @group(0) @binding(0) var<uniform> params: vec4<f32>;
//! @group(0) @binding(1) var source: texture_2d<f32>;
//! @fragment
//! fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
//!     return textureLoad(source, vec2<i32>(in.position.xy), 0) * vec4<f32>(params.rgb, 1.0);
//! }";
//!     type Params = Tint;
//!     fn params(&self) -> Tint {
//!         self.0
//!     }
//! }
//! ```

use crate::graph::NamedPass;
use crate::layouts::{BindGroupDecl, BindingDecl, GroupLayout, UNFILTERED};
use crate::passes::common::{FullscreenPipelineDesc, draw_fullscreen, fullscreen_pipeline_with_module};
use crate::pipelines::PipelineKey;
use std::marker::PhantomData;

pub use crate::bindings::Binding;
pub use crate::context::{GpuContext, RenderError};
pub use crate::graph::{HDR, OUTPUT, Pass, PassContext, PostProcessWrite, ResourceName, TextureSpec};
pub use crate::passes::{
    BloomBrightPass, ClusteredForwardPass, DebugViewPass, DeferredLightingPass, ForwardPass, GBufferPass,
    LightVolumesPass, MotionBlurPass, TiledDeferredPass, TonemapPass, TransparentPass, post_process_texture,
};
pub use crate::plan::PlanInputs;
pub use crate::planner::{FramePlanner, Stage, StageError, StageId};
pub use crate::resource;
pub use crate::resources::HDR_FORMAT;
pub use crate::snapshot::ViewComponents;
pub use bytemuck;
pub use wgpu;

/// A full-screen pass over the HDR image, before tone mapping: it reads the image as the passes
/// before it left it and writes the filtered image, which the passes after it read. Its WGSL
/// declares, in group 0, binding 0 `var<uniform> params` (a struct laid out as
/// [`PostPass::Params`]) and binding 1 `var source: texture_2d<f32>` (the HDR image, read with
/// `textureLoad`), and a fragment entry point [`PostPass::FRAGMENT`] taking `FullscreenOut`;
/// `//!include common/fullscreen.wgsl` brings the vertex stage. The WGSL is checked (and its
/// includes resolved) when the pipeline is made: an error is a [`RenderError`] naming
/// [`PostPass::NAME`].
///
/// Every `PostPass` is a [`Pass`] (and a [`NamedPass`]), so a stage places it by type:
/// `Stage::new::<MyPass>(plan)`.
pub trait PostPass: Send + Sync + 'static {
    /// The pass's name (snake_case): its entry in the frame's pass list and timings, and the
    /// label of its pipeline.
    const NAME: &'static str;
    /// Its WGSL source.
    const WGSL: &'static str;
    /// Its fragment entry point.
    const FRAGMENT: &'static str = "fs_main";
    /// Its uniform: `#[repr(C)]` and as the WGSL struct lays it out (a multiple of 16 bytes).
    type Params: bytemuck::Pod;
    /// This frame's uniform.
    fn params(&self) -> Self::Params;
}

/// The bind group every [`PostPass`] declares.
static POST_PASS_GROUP: BindGroupDecl = BindGroupDecl {
    label: "post_pass",
    index: 0,
    entries: &[
        BindingDecl::uniform(0, "params", wgpu::ShaderStages::FRAGMENT),
        BindingDecl::texture(1, "source", UNFILTERED, wgpu::ShaderStages::FRAGMENT),
    ],
};

/// The pipeline of post pass `P` (one per pass type).
struct PostPipelineKey<P>(PhantomData<fn() -> P>);

impl<P> Clone for PostPipelineKey<P> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<P> Copy for PostPipelineKey<P> {}
impl<P> PartialEq for PostPipelineKey<P> {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}
impl<P> Eq for PostPipelineKey<P> {}
impl<P> std::hash::Hash for PostPipelineKey<P> {
    fn hash<H: std::hash::Hasher>(&self, _: &mut H) {}
}
impl<P> std::fmt::Debug for PostPipelineKey<P> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "PostPipelineKey<{}>", std::any::type_name::<P>())
    }
}

impl<P: PostPass> PipelineKey for PostPipelineKey<P> {
    type Pipeline = PostPipeline;
}

/// A post pass's pipeline and its group's layout.
struct PostPipeline {
    pipeline: wgpu::RenderPipeline,
    layout: GroupLayout,
}

impl PostPipeline {
    fn new<P: PostPass>(device: &wgpu::Device) -> Result<PostPipeline, RenderError> {
        let layout = POST_PASS_GROUP.create_layout(device, Default::default());
        let module = crate::shaders::create_module_from_source(device, P::NAME, P::WGSL)?;
        let desc = FullscreenPipelineDesc {
            label: P::NAME,
            shader: P::NAME,
            layouts: &[&layout],
            fragment: P::FRAGMENT,
            output: HDR_FORMAT,
            blend: None,
            depth: None,
            constants: &[],
        };
        Ok(PostPipeline { pipeline: fullscreen_pipeline_with_module(device, &desc, &module), layout })
    }
}

impl<P: PostPass> Pass for P {
    fn name(&self) -> &'static str {
        P::NAME
    }

    fn reads(&self) -> Vec<ResourceName> {
        vec![HDR]
    }

    fn writes(&self) -> Vec<ResourceName> {
        vec![HDR]
    }

    fn creates(&self) -> Vec<TextureSpec> {
        vec![post_process_texture()]
    }

    fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
        let device = &ctx.gpu.device;
        let pipeline = ctx
            .pipelines
            .get_or_create(PostPipelineKey::<P>(PhantomData), |_| PostPipeline::new::<P>(device))?;
        let params = ctx.uniform(&self.params());
        let target = ctx.post_process_write()?;
        let group =
            ctx.bind_group(&pipeline.layout, &[Binding::Buffer(&params), Binding::Texture(target.source)]);
        let timestamps = ctx.render_timestamps(true, true);
        draw_fullscreen(ctx.encoder, P::NAME, target.destination, timestamps, &pipeline.pipeline, &[&group]);
        Ok(())
    }
}

impl<P: PostPass> NamedPass for P {
    const NAME: &'static str = <P as PostPass>::NAME;
}
