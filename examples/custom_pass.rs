//! A pass of the app's own, added from outside manylight's crates: a vignette on one of two
//! cameras. The app writes the pass (its WGSL is `custom_pass.wgsl`), copies its camera
//! component into the views (`ExtractCameraComponentPlugin`), and places its stage before tone
//! mapping by type; the pass reads the HDR image and writes the filtered one through
//! `PassContext::post_process_write`. The left camera has no `Vignette` and runs no extra pass.
//!
//! `cargo run --release --example custom_pass` opens a window (Esc closes it);
//! `cargo run --release --example custom_pass -- --headless out.png` renders 30 frames headless
//! and writes the last one.

#[path = "support/mod.rs"]
mod support;

use manylight::prelude::*;
use manylight::render::bindings::Binding;
use manylight::render::layouts::{BindGroupDecl, BindingDecl, GroupLayout, UNFILTERED};
use manylight::render::passes::common::{
    FullscreenPipelineDesc, draw_fullscreen, fullscreen_pipeline_with_module,
};
use manylight::render::passes::{HDR, TonemapPass, post_process_texture};
use manylight::render::pipelines::PipelineKey;
use manylight::render::resources::HDR_FORMAT;
use manylight::render::shaders::create_module_from_source;
use manylight::render::wgpu;

/// The vignette's WGSL.
pub const VIGNETTE_WGSL: &str = include_str!("custom_pass.wgsl");

/// Darkens a camera's image towards its corners: the camera's view gets a [`VignettePass`].
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Vignette {
    /// How dark the corners get: 0 none, 1 black.
    pub strength: f32,
    /// Where the darkening starts, as a fraction of the centre-to-corner distance.
    pub radius: f32,
}

impl Default for Vignette {
    fn default() -> Self {
        Vignette { strength: 0.85, radius: 0.3 }
    }
}

/// The pass: the HDR image in, the vignetted HDR image out, before tone mapping.
pub struct VignettePass(pub Vignette);

/// The vignette's pipeline (one: it depends on nothing the view chooses).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
struct VignetteKey;

impl PipelineKey for VignetteKey {
    type Pipeline = VignettePipeline;
}

/// The vignette's bind group, as `custom_pass.wgsl` declares it: its layout and every bind group
/// made for it come from here.
static VIGNETTE_GROUP: BindGroupDecl = BindGroupDecl {
    label: "vignette",
    entries: &[
        BindingDecl::uniform(0, "params", wgpu::ShaderStages::FRAGMENT),
        BindingDecl::texture(1, "source", UNFILTERED, wgpu::ShaderStages::FRAGMENT),
    ],
};

/// The pipeline and its bind group layout.
struct VignettePipeline {
    pipeline: wgpu::RenderPipeline,
    layout: GroupLayout,
}

impl VignettePipeline {
    fn new(device: &wgpu::Device) -> Result<Self, RenderError> {
        let layout = VIGNETTE_GROUP.create_layout(device, Default::default());
        let module = create_module_from_source(device, "custom_pass.wgsl", VIGNETTE_WGSL)?;
        let desc = FullscreenPipelineDesc {
            label: "vignette",
            shader: "custom_pass.wgsl",
            layouts: &[&layout],
            fragment: "fs_vignette",
            output: HDR_FORMAT,
            blend: None,
            depth: None,
            constants: &[],
        };
        Ok(VignettePipeline { pipeline: fullscreen_pipeline_with_module(device, &desc, &module), layout })
    }
}

impl Pass for VignettePass {
    fn name(&self) -> &'static str {
        "vignette"
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
        let pipeline = ctx.pipelines.get_or_create(VignetteKey, |_| VignettePipeline::new(device))?;
        // `VignetteParams` in the WGSL: strength, radius, two words of padding.
        let params: Vec<u8> =
            [self.0.strength, self.0.radius, 0.0, 0.0].iter().flat_map(|v| v.to_ne_bytes()).collect();
        let params = ctx.uniform(("vignette", 0), &params);
        let target = ctx.post_process_write()?;
        let group =
            ctx.bind_group(&pipeline.layout, &[Binding::Buffer(&params), Binding::Texture(target.source)]);
        let timestamps = ctx.render_timestamps(true, true);
        draw_fullscreen(
            ctx.encoder,
            "vignette",
            target.destination,
            timestamps,
            &pipeline.pipeline,
            &[&group],
        );
        Ok(())
    }
}

/// The stage: a [`VignettePass`] for each view whose camera carries a [`Vignette`], unless a
/// debug view replaces the image.
pub fn plan_vignette(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn Pass>>) {
    if let Some(vignette) = p.components.get::<Vignette>()
        && p.shows_image()
    {
        out.push(Box::new(VignettePass(*vignette)));
    }
}

/// Adds the vignette to `app`: the component's extraction and the stage, before tone mapping.
pub fn add_vignette(app: &mut App) -> Result<(), StageError> {
    app.add_plugins(ExtractCameraComponentPlugin::<Vignette>::default());
    app.add_render_stage_before::<TonemapPass>(Stage::new::<VignettePass>(plan_vignette))?;
    Ok(())
}

/// Which half of the image a camera takes (0 left, 1 right).
#[derive(Component, Clone, Copy)]
pub struct Half(pub u32);

/// The hall with 256 lights, seen by two cameras side by side from the same place; the right
/// one carries `vignette`, if any.
pub fn setup(commands: &mut Commands, vignette: Option<Vignette>) {
    let scene = default_scene();
    spawn_scene(commands, &scene, false, 8.0 / 9.0);
    spawn_light_rig(commands, 256, scene.bounds(), 3).expect("256 lights fit");
    let eye = Transform::from_xyz(-16.0, 2.0, 0.0).looking_at(Vec3::new(0.0, 1.2, 0.0), Vec3::Y);
    commands.spawn((eye, Camera3d, Camera { order: 0, ..default() }, Half(0)));
    let right = commands.spawn((eye, Camera3d, Camera { order: 1, ..default() }, Half(1))).id();
    if let Some(vignette) = vignette {
        commands.entity(right).insert(vignette);
    }
}

/// Keeps each camera in its half of the image, whatever its size.
pub fn layout(size: Res<manylight::app::ViewportSize>, mut cameras: Query<(&mut Camera, &Half)>) {
    let half = UVec2::new(size.0.x / 2, size.0.y).max(UVec2::ONE);
    for (mut camera, side) in &mut cameras {
        let viewport = Viewport { physical_position: UVec2::new(side.0 * half.x, 0), physical_size: half };
        if camera.viewport != Some(viewport) {
            camera.viewport = Some(viewport);
        }
    }
}

fn main() -> AppExit {
    tracing_subscriber::fmt().with_env_filter("warn,winit=error,manylight_app=info").init();
    let plugin = support::ExampleArgs::from_env().plugin("custom_pass.png");
    let mut app = App::new();
    app.add_plugins(plugin)
        .add_systems(Startup, |mut commands: Commands| setup(&mut commands, Some(Vignette::default())))
        .add_systems(Update, layout);
    if let Err(e) = add_vignette(&mut app) {
        eprintln!("custom_pass: {e}");
        return AppExit::error();
    }
    app.run()
}
