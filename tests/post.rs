//! Bloom and motion blur on rendered images (lavapipe in CI): bloom spreads a very bright
//! light's energy beyond the area it lights and is off by default; motion blur leaves a still
//! camera's image (and the first frame's) unchanged and blurs a turning camera's.

mod support;

use manylight::app::headless::{HeadlessFrame, render_headless};
use manylight::math::image_metrics::flip_compare;
use manylight::prelude::*;
use support::gpu;

const SIZE: UVec2 = UVec2::new(128, 72);

/// What a test puts on the camera and how the camera moves.
#[derive(Clone, Copy, Default)]
struct Setup {
    bloom: Option<Bloom>,
    motion_blur: Option<MotionBlur>,
    /// Camera yaw per frame, radians.
    turn: f32,
    /// Replace the scene's lights by one very bright small light.
    one_bright_light: bool,
}

fn render(setup: Setup, frames: u32) -> HeadlessFrame {
    let scene = default_scene();
    let aspect = SIZE.x as f32 / SIZE.y as f32;
    let frame = render_headless(SIZE, frames, move |app| {
        app.add_systems(Startup, move |mut commands: Commands| {
            let mut scene = scene.clone();
            if setup.one_bright_light {
                let centre = scene.bounds().center();
                let mut light = scene.lights[0];
                light.position = glam::Vec3::new(centre.x, scene.bounds().min.y + 0.6, centre.z);
                light.color = Vec3::ONE;
                light.intensity = 4000.0;
                light.radius = 2.5;
                scene.lights = vec![light];
            }
            spawn_scene(&mut commands, &scene, true, aspect);
        });
        app.add_systems(
            PostStartup,
            move |mut commands: Commands, cameras: Query<Entity, With<Camera3d>>| {
                for camera in &cameras {
                    let mut camera = commands.entity(camera);
                    if let Some(b) = setup.bloom {
                        camera.insert(b);
                    }
                    if let Some(m) = setup.motion_blur {
                        camera.insert(m);
                    }
                }
            },
        );
        if setup.turn != 0.0 {
            app.add_systems(Update, move |mut cameras: Query<&mut Transform, With<Camera3d>>| {
                for mut t in &mut cameras {
                    t.rotation = Quat::from_rotation_y(setup.turn) * t.rotation;
                }
            });
        }
    })
    .unwrap_or_else(|e| panic!("render failed: {e}"));
    support::assert_finite(&frame);
    frame
}

fn passes(frame: &HeadlessFrame) -> Vec<String> {
    frame.stats.pass_names()
}

fn luminance(p: &image::Rgba<u8>) -> f32 {
    0.2126 * p[0] as f32 + 0.7152 * p[1] as f32 + 0.0722 * p[2] as f32
}

fn flip_mean(a: &image::RgbaImage, b: &image::RgbaImage) -> f32 {
    flip_compare(a.dimensions(), a.as_raw(), b.dimensions(), b.as_raw()).expect("same size").0.mean
}

#[test]
fn bloom_spreads_a_bright_lights_energy_and_is_off_by_default() {
    let _gpu = gpu();
    let plain = render(Setup { one_bright_light: true, ..Setup::default() }, 1);
    assert!(!passes(&plain).iter().any(|n| n.starts_with("bloom")), "off by default: {:?}", passes(&plain));
    for bloom in [Bloom::default(), Bloom::full_resolution()] {
        let bloomed = render(Setup { one_bright_light: true, bloom: Some(bloom), ..Setup::default() }, 1);
        assert!(passes(&bloomed).contains(&"bloom_composite".to_string()), "{:?}", passes(&bloomed));
        let out = support::output_dir();
        let _ = plain.image.save(out.join("bloom_off.png"));
        let _ = bloomed.image.save(out.join(format!("bloom_{}.png", bloom.chain.name())));
        // The lit area: pixels the light makes bright in the plain image. Outside it (dark in
        // the plain image), bloom must add light; nowhere may it remove any.
        let (mut dark_plain, mut dark_bloom, mut dark) = (0.0f64, 0.0f64, 0u32);
        for (p, b) in plain.image.pixels().zip(bloomed.image.pixels()) {
            let (lp, lb) = (luminance(p), luminance(b));
            assert!(lb + 1.5 >= lp, "bloom only adds light ({lp} → {lb})");
            if lp < 40.0 {
                dark_plain += lp as f64;
                dark_bloom += lb as f64;
                dark += 1;
            }
        }
        assert!(dark > SIZE.x * SIZE.y / 4, "most of the image is outside the lit area ({dark} px)");
        let (mp, mb) = (dark_plain / dark as f64, dark_bloom / dark as f64);
        eprintln!("{:?}: mean luminance outside the lit area {mp:.2} → {mb:.2}", bloom.chain);
        assert!(
            mb > mp + 2.0,
            "{:?}: bloom must spread energy outside the lit area: {mp:.2} → {mb:.2}",
            bloom.chain
        );
    }
}

#[test]
fn motion_blur_with_a_still_camera_changes_nothing() {
    let _gpu = gpu();
    let blur = Some(MotionBlur::default());
    // First frame: no previous matrix, no blur and no garbage.
    let first = render(Setup { motion_blur: blur, ..Setup::default() }, 1);
    let first_plain = render(Setup::default(), 1);
    assert!(passes(&first).contains(&"motion_blur".to_string()));
    let m = flip_mean(&first_plain.image, &first.image);
    assert!(m <= 0.001, "first frame: FLIP mean {m}");
    // A still camera over several frames.
    let still = render(Setup { motion_blur: blur, ..Setup::default() }, 3);
    let plain = render(Setup::default(), 3);
    let m = flip_mean(&plain.image, &still.image);
    assert!(m <= 0.001, "still camera: FLIP mean {m}");
    // A camera that moves by far less than a pixel runs the blur shader, whose per-pixel
    // early-out keeps every colour exact.
    let turn = 1e-6;
    let creeping = render(Setup { motion_blur: blur, turn, ..Setup::default() }, 3);
    let plain = render(Setup { turn, ..Setup::default() }, 3);
    let m = flip_mean(&plain.image, &creeping.image);
    assert!(m <= 0.001, "sub-pixel motion: FLIP mean {m}");
    let gpu_ms = |f: &HeadlessFrame| {
        f.stats.last.as_ref().and_then(|r| r.passes.iter().find(|p| p.name == "motion_blur")?.gpu_ms)
    };
    assert!(gpu_ms(&still).is_none(), "a still camera records no motion-blur work");
    assert!(gpu_ms(&creeping).is_some(), "a moving camera runs the blur");
}

#[test]
fn motion_blur_with_a_turning_camera_blurs() {
    let _gpu = gpu();
    let turn = 0.06; // ≈ 7 px per frame at 128 px wide
    let moving = render(Setup { motion_blur: Some(MotionBlur::default()), turn, ..Setup::default() }, 3);
    let plain = render(Setup { turn, ..Setup::default() }, 3);
    let m = flip_mean(&plain.image, &moving.image);
    eprintln!("turning camera: FLIP mean {m}");
    assert!(m > 0.01, "a turning camera must blur: FLIP mean {m}");
    // Blur averages neighbours: the image has less high-frequency detail horizontally.
    let detail = |img: &image::RgbaImage| -> f64 {
        let (w, h) = img.dimensions();
        let mut sum = 0.0;
        for y in 0..h {
            for x in 1..w {
                sum += (luminance(img.get_pixel(x, y)) - luminance(img.get_pixel(x - 1, y))).abs() as f64;
            }
        }
        sum
    };
    let (dp, dm) = (detail(&plain.image), detail(&moving.image));
    assert!(dm < dp * 0.9, "horizontal detail {dp:.0} → {dm:.0}");
}
