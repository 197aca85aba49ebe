//! Photometric units as Bevy and glTF use them: `PointLight`/`SpotLight` intensities in lumens
//! (rendered as `lumens / 4π` candela), scene (glTF) lights in candela, and a camera's
//! `Exposure` (EV100) equal to the settings' exposure multiplier it stands for.

mod support;

use manylight::app::RenderSettings;
use manylight::app::headless::render_headless;
use manylight::math::LightShape;
use manylight::math::lumens_from_candela;
use manylight::prelude::*;
use manylight::scene::SceneLight;
use support::{STRICT, assert_similar, gpu};

const SIZE: UVec2 = UVec2::new(128, 72);

fn camera() -> Transform {
    Transform::from_xyz(-18.0, 1.7, 0.0).looking_at(Vec3::new(0.0, 1.0, 0.0), Vec3::Y)
}

/// Two lights along the hall, in candela.
fn candela_lights() -> Vec<SceneLight> {
    [(-12.0, Vec3::new(1.0, 0.6, 0.3)), (-6.0, Vec3::new(0.3, 0.6, 1.0))]
        .map(|(x, color)| SceneLight {
            position: Vec3::new(x, 1.0, 2.0),
            color,
            intensity: 6.0,
            radius: 8.0,
            shape: LightShape::Point,
        })
        .to_vec()
}

/// The default scene without its own lights, seen through `camera()`, lit by `lights` spawned by
/// the closure; `settings` as given.
fn render(
    settings: RenderSettings,
    lights: impl Fn(&mut Commands) + Send + Sync + 'static,
) -> image::RgbaImage {
    let frame = render_headless(SIZE, 1, move |app| {
        app.insert_resource(settings).add_systems(Startup, move |mut commands: Commands| {
            let mut scene = default_scene();
            scene.lights.clear();
            spawn_scene(&mut commands, &scene, false, 1.0);
            lights(&mut commands);
        });
    })
    .unwrap_or_else(|e| panic!("render failed: {e}"));
    support::assert_finite(&frame);
    frame.image
}

/// A `PointLight` of `4π · I` lumens lights the hall as a glTF light of `I` candela does.
#[test]
fn point_light_lumens_are_scene_light_candela() {
    let _gpu = gpu();
    let settings = RenderSettings { ambient: 0.0, ..RenderSettings::default() };
    let from_scene = render(settings, |commands| {
        let lights = Scene { lights: candela_lights(), ..Scene::default() };
        spawn_scene(commands, &lights, false, 1.0);
        commands.spawn((camera(), Camera3d));
    });
    let from_components = render(settings, |commands| {
        for l in candela_lights() {
            let intensity = lumens_from_candela(l.intensity);
            commands.spawn((
                Transform::from_translation(l.position),
                PointLight {
                    color: manylight::app::from_linear_rgb(l.color),
                    intensity,
                    range: l.radius,
                    radius: 0.0,
                    ..Default::default()
                },
            ));
        }
        commands.spawn((camera(), Camera3d));
    });
    let dark = render(settings, |commands| {
        commands.spawn((camera(), Camera3d));
    });
    assert_similar("lumens vs candela", &from_scene, &from_components, STRICT);
    let lit = from_scene.pixels().zip(dark.pixels()).filter(|(a, b)| a != b).count();
    assert!(lit > (SIZE.x * SIZE.y / 10) as usize, "the lights must light the hall ({lit} pixels)");
}

/// A camera's `Exposure` multiplies the image as `RenderSettings::exposure` does, and the
/// photographic presets are in the right order.
#[test]
fn camera_exposure_equals_the_settings_multiplier() {
    let _gpu = gpu();
    let lights = |commands: &mut Commands| {
        let scene = Scene { lights: candela_lights(), ..Scene::default() };
        spawn_scene(commands, &scene, false, 1.0);
    };
    let by_settings =
        render(RenderSettings { exposure: 0.3, ..RenderSettings::default() }, move |commands| {
            lights(commands);
            commands.spawn((camera(), Camera3d));
        });
    let by_camera = render(RenderSettings { exposure: 5.0, ..RenderSettings::default() }, move |commands| {
        lights(commands);
        commands.spawn((camera(), Camera3d, Exposure::from_multiplier(0.3)));
    });
    let unexposed = render(RenderSettings::default(), move |commands| {
        lights(commands);
        commands.spawn((camera(), Camera3d));
    });
    assert_similar("camera exposure vs settings exposure", &by_settings, &by_camera, STRICT);
    assert_ne!(by_settings, unexposed, "an exposure of 0.3 must darken the image");
    assert!((Exposure::from_multiplier(0.3).multiplier() - 0.3).abs() < 1e-6);
    assert!(Exposure::SUNLIGHT.multiplier() < Exposure::OVERCAST.multiplier());
    assert!(Exposure::BLENDER.multiplier() < Exposure::INDOOR.multiplier());
    assert_eq!(Exposure::default(), Exposure::BLENDER);
    assert_eq!(Exposure { ev100: f32::NAN }.multiplier(), 1.0);
}
