//! Spot and directional lights. Spot lights in every pipeline: the same image as naive forward, which evaluates every light
//! at every pixel, so a cone culled too tightly anywhere would show. The CPU twin of the cone's
//! falloff is checked in `tests/pbr.rs`, the lists in `tests/clusters.rs`.

mod support;

use manylight::app::RenderSettings;
use manylight::math::LightShape;
use manylight::math::SpotCone;
use manylight::prelude::*;
use manylight::scene::light_rig;
use support::{COMPACT, STRICT, assert_similar, flip, gpu, render_scene};

const SIZE: UVec2 = UVec2::new(160, 96);

/// The default scene lit by rig lights turned into spot lights of every width, pointing every
/// which way (some at the camera, some away; one cone is a hemisphere, one a hair).
fn spot_scene(count: usize) -> Scene {
    let mut scene = default_scene();
    for (i, anim) in light_rig(count, scene.bounds(), 7).expect("the rig's lights fit").iter().enumerate() {
        let a = i as f32 * 2.399;
        let outer = [0.05, 0.35, 0.7, 1.2, std::f32::consts::FRAC_PI_2][i % 5];
        let mut light = manylight::scene::animated_light_at(anim, 0.0);
        light.intensity *= 3.0;
        light.shape = LightShape::Spot(SpotCone {
            direction: Vec3::new(a.cos(), (i % 5) as f32 / 2.0 - 1.5, a.sin()),
            inner_angle: if i % 4 == 0 { outer } else { outer * 0.6 },
            outer_angle: outer,
        });
        scene.lights.push(light);
    }
    scene
}

fn settings(pipeline: PipelineKind) -> RenderSettings {
    RenderSettings { pipeline, ..RenderSettings::default() }
}

#[test]
fn spot_lights_give_the_naive_image_in_every_pipeline() {
    let _gpu = gpu();
    let naive = render_scene(spot_scene(120), SIZE, 0, settings(PipelineKind::NaiveForward));
    // The cones show: the same lights as point lights light another image.
    let mut points = spot_scene(120);
    points.lights.iter_mut().for_each(|l| l.shape = LightShape::Point);
    let as_points = render_scene(points, SIZE, 0, settings(PipelineKind::NaiveForward));
    assert!(flip(&naive.image, &as_points.image).mean > 0.02, "the cones change little");
    let variants = support::pipelines_besides_naive("spot", settings);
    for (name, s) in variants {
        let frame = render_scene(spot_scene(120), SIZE, 0, s);
        let tolerance = if name.ends_with("compact") { COMPACT } else { STRICT };
        let stats = assert_similar(&name, &naive.image, &frame.image, tolerance);
        eprintln!("{name}: {stats:?}");
    }
}

/// The default scene without its lights and ambient, plus what `spawn` adds, rendered once.
fn render_unlit_hall_with(
    spawn: impl Fn(&mut Commands) + Clone + Send + Sync + 'static,
) -> manylight::app::headless::HeadlessFrame {
    manylight::app::headless::render_headless(SIZE, 1, move |app| {
        let spawn = spawn.clone();
        app.insert_resource(RenderSettings { ambient: 0.0, ..RenderSettings::default() }).add_systems(
            Startup,
            move |mut commands: Commands| {
                let mut scene = default_scene();
                scene.lights.clear();
                spawn_scene(&mut commands, &scene, true, SIZE.x as f32 / SIZE.y as f32);
                spawn(&mut commands);
            },
        );
    })
    .expect("renders")
}

/// A spot light placed through the ECS (`SpotLight`, pointing down its entity's -Z) lights
/// only what lies in its cone.
#[test]
fn a_spot_light_component_lights_only_its_cone() {
    let _gpu = gpu();
    let render = |light: Option<SpotLight>| {
        render_unlit_hall_with(move |commands: &mut Commands| {
            if let Some(light) = light {
                // Above the floor of the nave, pointing straight down.
                let at = Transform::from_xyz(-12.0, 5.0, 0.0).looking_to(Vec3::NEG_Y, Vec3::X);
                commands.spawn((at, light));
            }
        })
        .image
    };
    let dark = render(None);
    let lit = render(Some(SpotLight {
        intensity: 2500.0,
        range: 30.0,
        inner_angle: 0.3,
        outer_angle: 0.5,
        ..SpotLight::default()
    }));
    let changed: Vec<(u32, u32)> = lit
        .enumerate_pixels()
        .filter(|(x, y, p)| *p != dark.get_pixel(*x, *y))
        .map(|(x, y, _)| (x, y))
        .collect();
    let total = (SIZE.x * SIZE.y) as usize;
    // A pool of light on the floor: some pixels, far from all of them.
    assert!(changed.len() > 50 && changed.len() < total / 4, "{} of {total} pixels lit", changed.len());
}

/// A `DirectionalLight` lights every surface facing it, whatever the distance; past
/// `MAX_DIRECTIONAL_LIGHTS` the extra ones are not drawn, and the report counts them.
#[test]
fn directional_lights_light_everything_and_extra_ones_are_counted() {
    use manylight::render::gpu_types::MAX_DIRECTIONAL_LIGHTS;
    let _gpu = gpu();
    let render = |count: u32| {
        render_unlit_hall_with(move |commands: &mut Commands| {
            for _ in 0..count {
                // Straight down onto the floor of the nave.
                let down = Transform::default().looking_to(Vec3::NEG_Y, Vec3::X);
                commands.spawn((down, DirectionalLight { illuminance: 0.4, ..default() }));
            }
        })
    };
    let dark = render(0);
    let one = render(1);
    let lit = one.image.pixels().zip(dark.image.pixels()).filter(|(a, b)| a != b).count();
    let total = (SIZE.x * SIZE.y) as usize;
    assert!(lit > total / 4, "{lit} of {total} pixels lit by a directional light");
    let report = one.stats.last.as_ref().expect("report");
    assert_eq!((report.directional_lights, report.dropped_directional_lights), (1, 0));
    let many = render(MAX_DIRECTIONAL_LIGHTS + 3);
    let report = many.stats.last.as_ref().expect("report");
    assert_eq!((report.directional_lights, report.dropped_directional_lights), (MAX_DIRECTIONAL_LIGHTS, 3));
    assert!(flip(&one.image, &many.image).mean > 0.01, "eight lights are brighter than one");
}

/// Spot lights on hard cases render the naive image in every pipeline, with no non-finite
/// pixel: the apex at the camera, a huge and a zero range, zero and right-angle cones, equal
/// inner and outer angles, and bad input the renderer must make usable (a zero direction, NaN
/// and infinite angles).
#[test]
fn spot_lights_on_hard_cases_stay_finite_and_exact() {
    let _gpu = gpu();
    let scene = || {
        let mut scene = default_scene();
        let eye = scene.cameras[0].transform.w_axis.truncate();
        let forward = -scene.cameras[0].transform.z_axis.truncate().normalize();
        let cone = |direction: Vec3, inner: f32, outer: f32| {
            LightShape::Spot(SpotCone { direction, inner_angle: inner, outer_angle: outer })
        };
        let spot = |position: Vec3, radius: f32, shape| manylight::scene::SceneLight {
            position,
            color: Vec3::new(1.0, 0.8, 0.6),
            intensity: 20.0,
            radius,
            shape,
        };
        scene.lights.extend([
            spot(eye, 40.0, cone(forward, 0.2, 0.4)),
            spot(eye + forward * 3.0, 1e6, cone(Vec3::NEG_Y, 0.3, 0.5)),
            spot(eye + forward * 5.0, 0.0, cone(forward, 0.1, 0.2)),
            spot(eye + forward * 6.0, 10.0, cone(Vec3::NEG_Y, 0.0, 0.0)),
            spot(eye + forward * 7.0, 10.0, cone(Vec3::X, 1.0, std::f32::consts::FRAC_PI_2)),
            spot(eye + forward * 8.0, 10.0, cone(Vec3::NEG_Y, 0.6, 0.6)),
            spot(eye + forward * 9.0, 10.0, cone(Vec3::ZERO, f32::NAN, f32::INFINITY)),
        ]);
        scene
    };
    let naive = render_scene(scene(), SIZE, 0, settings(PipelineKind::NaiveForward));
    for (name, s) in support::pipelines_besides_naive("spot_hard", settings) {
        let frame = render_scene(scene(), SIZE, 0, s);
        let tolerance = if name.ends_with("compact") { COMPACT } else { STRICT };
        assert_similar(&name, &naive.image, &frame.image, tolerance);
    }
}
