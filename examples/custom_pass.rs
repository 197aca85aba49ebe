//! An app's own pass: a vignette (a `PostPass`: a name, `custom_pass.wgsl`, a uniform) on the
//! right of two cameras, placed before tone mapping by type; the left camera runs no extra pass.
//! `cargo run --release --example custom_pass` opens a window (Esc closes it); add
//! `-- --headless out.png` to render 30 frames headless.

#[path = "support/mod.rs"]
mod support;

use manylight::prelude::*;
use manylight::render::ext::{PostPass, TonemapPass};

/// Darkens a camera's image towards its corners.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Vignette {
    /// How dark the corners get: 0 none, 1 black.
    pub strength: f32,
    /// Where the darkening starts, as a fraction of the centre-to-corner distance.
    pub radius: f32,
}

/// The pass: the HDR image in, the vignetted HDR image out.
pub struct VignettePass(pub Vignette);

impl PostPass for VignettePass {
    const NAME: &'static str = "vignette";
    const WGSL: &'static str = include_str!("custom_pass.wgsl");
    /// `VignetteParams` in the WGSL: strength, radius, two words of padding.
    type Params = [f32; 4];
    fn params(&self) -> [f32; 4] {
        [self.0.strength, self.0.radius, 0.0, 0.0]
    }
}

/// Adds the vignette to `app`: a [`VignettePass`] for each view whose camera carries a
/// [`Vignette`], unless a debug view replaces the image.
pub fn add_vignette(app: &mut App) -> Result<&mut App, StageError> {
    app.add_plugins(ExtractCameraComponentPlugin::<Vignette>::default());
    app.add_render_stage_before::<TonemapPass>(Stage::new::<VignettePass>(|p, out| {
        if let Some(vignette) = p.components.get::<Vignette>().filter(|_| p.shows_image()) {
            out.push(Box::new(VignettePass(*vignette)));
        }
    }))
}

/// The hall with 256 lights, seen by two cameras side by side; the right one carries `vignette`.
pub fn setup(commands: &mut Commands, vignette: Option<Vignette>) {
    let scene = default_scene();
    spawn_scene(commands, &scene, false, 8.0 / 9.0);
    spawn_light_rig(commands, 256, scene.bounds(), 3).expect("256 lights fit");
    let eye = Transform::from_xyz(-16.0, 2.0, 0.0).looking_at(Vec3::new(0.0, 1.2, 0.0), Vec3::Y);
    commands.spawn((eye, Camera3d, Camera { order: 0, ..default() }));
    let right = commands.spawn((eye, Camera3d, Camera { order: 1, ..default() })).id();
    if let Some(v) = vignette {
        commands.entity(right).insert(v);
    }
}

/// Keeps each camera (by its order) in its half of the image, whatever its size.
pub fn layout(size: Res<manylight::app::ViewportSize>, mut cameras: Query<&mut Camera>) {
    let half = UVec2::new(size.0.x / 2, size.0.y).max(UVec2::ONE);
    for mut camera in &mut cameras {
        let x = camera.order.clamp(0, 1) as u32 * half.x;
        let viewport = Some(Viewport { physical_position: UVec2::new(x, 0), physical_size: half });
        camera.set_if_neq(Camera { viewport, ..*camera });
    }
}

fn main() -> AppExit {
    tracing_subscriber::fmt().with_env_filter("warn,winit=error,manylight_app=info").init();
    let mut app = App::new();
    app.add_plugins(support::ExampleArgs::from_env().plugin("custom_pass.png"))
        .add_systems(Startup, |mut c: Commands| setup(&mut c, Some(Vignette { strength: 0.85, radius: 0.3 })))
        .add_systems(Update, layout);
    let run = add_vignette(&mut app).map(App::run);
    run.unwrap_or_else(|e| {
        eprintln!("custom_pass: {e}");
        AppExit::error()
    })
}
