//! How `render` and `check` draw a scene through the app, headless: the scene, an animated
//! light rig, post stages on the camera, a debug view and shadows, and the last frame back.

use anyhow::Result;
use bevy_app::Startup;
use bevy_ecs::system::Commands;
use glam::UVec2;
use manylight_app::headless::render_headless;
use manylight_app::scene::{spawn_light_rig, spawn_scene};
use manylight_app::{FrameStats, RenderSettings};
use manylight_scene::Scene;

/// What `render_scene` adds beyond the scene: post stages and an environment on the camera,
/// and the debug view.
#[derive(Clone, Debug, Default)]
pub(crate) struct Extras {
    pub(crate) bloom: Option<manylight_app::Bloom>,
    pub(crate) motion_blur: Option<manylight_app::MotionBlur>,
    pub(crate) debug: manylight_app::DebugView,
    /// Every light casts a shadow.
    pub(crate) shadows: bool,
    /// The panorama that lights the camera's view, and whether it shows behind it.
    pub(crate) environment: Option<CameraEnvironment>,
}

/// An environment on the camera: the panorama, its intensity and whether it is the skybox too.
#[derive(Clone, Debug)]
pub(crate) struct CameraEnvironment {
    pub(crate) image: std::sync::Arc<manylight_core::environment::EquirectImage>,
    pub(crate) intensity: f32,
    pub(crate) skybox: bool,
}

/// Camera turn per frame under `--motion-blur` (about 20 px of motion at 1280 px wide).
const MOTION_BLUR_TURN: f32 = 0.015;

/// Renders `scene` headless through the plugin and returns the last frame and its stats.
pub(crate) fn render_scene(
    scene: Scene,
    size: UVec2,
    frames: u32,
    lights: usize,
    seed: u64,
    settings: RenderSettings,
    extras: Extras,
) -> Result<(image::RgbaImage, FrameStats)> {
    use bevy_ecs::prelude::{Entity, Query, With};
    use manylight_app::{Camera3d, Transform};
    let aspect = size.x as f32 / size.y as f32;
    let bounds = scene.bounds();
    let frame = render_headless(size, frames, move |app| {
        // The panorama's resource only when there is one: an app without an environment is
        // the app it was before environments existed, entity for entity.
        let environment = extras.environment.clone().map(|e| {
            let mut images = manylight_app::EnvironmentImages::default();
            let handle = images.add(e.image);
            app.insert_resource(images);
            (handle, e.intensity, e.skybox)
        });
        app.insert_resource(settings).insert_resource(extras.debug).add_systems(
            Startup,
            move |mut commands: Commands| {
                spawn_scene(&mut commands, &scene, true, aspect);
                // The count was checked before the app was built; memory taken since then fails
                // the run with the error instead of a frame without the lights.
                if let Err(e) = spawn_light_rig(&mut commands, lights, bounds, seed) {
                    commands.insert_resource(manylight_app::RenderFailure(Some(format!("--lights: {e}"))));
                }
            },
        );
        app.add_systems(
            bevy_app::PostStartup,
            move |mut commands: Commands, cameras: Query<Entity, With<Camera3d>>| {
                for camera in &cameras {
                    let mut camera = commands.entity(camera);
                    if let Some(bloom) = extras.bloom {
                        camera.insert(bloom);
                    }
                    if let Some(motion_blur) = extras.motion_blur {
                        camera.insert(motion_blur);
                    }
                    if let Some((image, intensity, skybox)) = environment {
                        camera.insert(manylight_app::EnvironmentMapLight {
                            intensity,
                            ..manylight_app::EnvironmentMapLight::new(image)
                        });
                        if skybox {
                            camera.insert(manylight_app::Skybox::new(image));
                        }
                    }
                }
            },
        );
        if extras.shadows {
            app.add_systems(bevy_app::PostStartup, |world: &mut bevy_ecs::world::World| {
                manylight_app::scene::set_shadows(world, true)
            });
        }
        if extras.motion_blur.is_some() {
            app.add_systems(bevy_app::Update, |mut cameras: Query<&mut Transform, With<Camera3d>>| {
                for mut t in &mut cameras {
                    t.rotation = glam::Quat::from_rotation_y(MOTION_BLUR_TURN) * t.rotation;
                }
            });
        }
    })
    .map_err(anyhow::Error::msg)?;
    Ok((frame.image, frame.stats))
}
