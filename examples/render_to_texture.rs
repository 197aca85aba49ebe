//! Render to texture: a security camera at the far end of the hall renders into a
//! `RenderImage`; the app takes its pixels from `RenderedImages` and shows them on a monitor
//! standing in front of the main camera, so the monitor shows the hall from the other end,
//! lights moving, one frame behind.
//!
//! `cargo run --release --example render_to_texture` opens a window (Esc closes it);
//! `cargo run --release --example render_to_texture -- --headless out.png --frames 30` renders
//! 30 frames headless and writes the last one (and the security camera's own image beside it,
//! as `out.camera.png`).

use manylight::math::TextureData;
mod support;

use manylight::prelude::*;
use std::sync::Arc;

/// The image the security camera renders into.
#[derive(Resource, Clone, Copy)]
struct SecurityFeed(RenderImage);

/// The monitor's screen.
#[derive(Component)]
struct Screen;

/// The frame last shown on the screen.
#[derive(Default)]
struct Shown(Option<u64>);

const FEED: UVec2 = UVec2::new(320, 180);

fn setup(mut commands: Commands) {
    let scene = default_scene();
    spawn_scene(&mut commands, &scene, true, 16.0 / 9.0);
    spawn_light_rig(&mut commands, 256, scene.bounds(), 3).expect("256 lights fit");
    let feed = RenderImage::new(FEED.x, FEED.y);
    commands.insert_resource(SecurityFeed(feed));
    // Rendered before the main camera, into its image.
    commands.spawn((
        Transform::from_xyz(18.5, 6.0, 6.5).looking_at(Vec3::new(-6.0, 0.5, -1.0), Vec3::Y),
        Camera3d,
        Camera { order: -1, target: RenderTarget::Image(feed), ..default() },
        Bloom::default(),
    ));
    // A 16:9 screen in front of the main camera (at x = -18 looking down +X), facing it.
    let quad = MeshData::from_attributes(
        "screen",
        &[
            Vec3::new(0.0, -0.9, 1.6),
            Vec3::new(0.0, -0.9, -1.6),
            Vec3::new(0.0, 0.9, -1.6),
            Vec3::new(0.0, 0.9, 1.6),
        ],
        Some(&[Vec3::NEG_X; 4]),
        Some(&[Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)]),
        Some(vec![0, 1, 2, 0, 2, 3]),
    )
    .expect("a valid quad");
    commands.spawn((
        Transform::from_xyz(-11.0, 2.0, 0.0),
        Mesh3d(Arc::new(quad)),
        Material(Arc::new(MaterialData { label: "screen".into(), ..MaterialData::default() })),
        Screen,
    ));
    // A lamp that lights the screen.
    commands.spawn((
        Transform::from_xyz(-13.5, 2.0, 0.0),
        PointLight { color: Color::WHITE, intensity: 125.0, range: 6.0, ..default() },
    ));
}

/// Puts the newest security image on the screen (as its base-colour texture, sRGB-encoded).
fn show_on_screen(
    mut shown: Local<Shown>,
    feed: Res<SecurityFeed>,
    images: Res<RenderedImages>,
    mut screens: Query<&mut Material, With<Screen>>,
) {
    let (Some(image), Some(frame)) = (images.get(&feed.0), images.frame_of(&feed.0)) else {
        return;
    };
    if shown.0 == Some(frame) {
        return;
    }
    shown.0 = Some(frame);
    let texture = Arc::new(TextureData {
        label: "security_feed".into(),
        width: image.width(),
        height: image.height(),
        rgba8: image.as_raw().clone(),
        srgb: true,
    });
    for mut material in &mut screens {
        let mut m = (*material.0).clone();
        m.base_color_texture = Some(texture.clone().into());
        material.0 = Arc::new(m);
    }
}

/// Headless: writes the security camera's last image beside the main output.
fn save_feed(path: std::path::PathBuf) -> impl FnMut(Res<SecurityFeed>, Res<RenderedImages>) {
    move |feed, images| {
        if let Some(image) = images.get(&feed.0) {
            let out = path.with_extension("camera.png");
            if let Err(e) = manylight::app::headless::save_png(image, &out) {
                eprintln!("{e}");
            }
        }
    }
}

fn main() -> AppExit {
    tracing_subscriber::fmt().with_env_filter("warn,winit=error,manylight_app=info").init();
    let args = support::ExampleArgs::from_env();
    let mut app = App::new();
    app.add_plugins(args.plugin("render_to_texture.png"))
        .add_systems(Startup, setup)
        .add_systems(Update, show_on_screen);
    if let Some(output) = args.output("render_to_texture.png") {
        app.add_systems(Last, save_feed(output));
    }
    app.run()
}
