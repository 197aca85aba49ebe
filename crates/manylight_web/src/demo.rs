//! What the page shows, as plain app setup: the same on the page and in the native tests that
//! compare the page's image with the native renderer's.

use crate::options::{WebClock, WebOptions, WebScene};
use manylight::app::scene::set_shadows;
use manylight::prelude::*;
use manylight::scene::{
    SHELL_LIGHT_RANGE, SHELL_RADIUS, Scene, rig_bounds, sphere_shell_lights, sphere_shell_scene,
};

/// Seed of the light rig and the shell's colours (the native demo's).
const SEED: u64 = 1;

/// A scene ready to spawn: a built-in one, or a glTF file the page has loaded.
pub enum DemoScene {
    /// The embedded hall with a rig of `lights` animated lights.
    Hall,
    /// `lights` still lights on the sphere shell.
    SphereShell,
    /// A loaded glTF file (its own lights and camera, or a camera that frames it) with a rig of
    /// `lights` animated lights around it.
    Loaded(Box<Scene>),
}

impl DemoScene {
    /// The built-in scene `scene` names; `None` for a glTF file, which the page loads first.
    pub fn built_in(scene: &WebScene) -> Option<DemoScene> {
        match scene {
            WebScene::Hall => Some(DemoScene::Hall),
            WebScene::SphereShell => Some(DemoScene::SphereShell),
            WebScene::Gltf(_) => None,
        }
    }
}

/// Adds what `options` ask for to `app` (which has the manylight plugin): the settings, the
/// clock, and a `Startup` system that spawns `scene` for a view of `aspect` (width / height).
/// The light count was checked when the options were parsed.
pub fn add_scene(app: &mut App, options: &WebOptions, scene: DemoScene, aspect: f32) {
    let settings = RenderSettings { pipeline: options.pipeline, ..RenderSettings::default() };
    app.insert_resource(settings)
        .insert_resource(DebugView { mode: options.debug_view, ..DebugView::default() });
    if options.clock == WebClock::Fixed {
        app.insert_resource(TimeUpdateStrategy::ManualDuration(manylight::app::HEADLESS_TIME_STEP));
    }
    let (lights, shadows) = (options.lights, options.shadows);
    let mut scene = Some(scene);
    app.add_systems(Startup, move |world: &mut World| {
        let Some(scene) = scene.take() else { return };
        let mut commands = world.commands();
        let spawned = match scene {
            DemoScene::Hall => {
                let hall = default_scene();
                spawn_scene(&mut commands, &hall, true, aspect);
                spawn_light_rig(&mut commands, lights, hall.bounds(), SEED)
            }
            DemoScene::SphereShell => {
                let mut shell = sphere_shell_scene();
                sphere_shell_lights(lights, SHELL_RADIUS, SHELL_LIGHT_RANGE, SEED).map(|l| {
                    shell.lights = l;
                    spawn_scene(&mut commands, &shell, true, aspect);
                })
            }
            DemoScene::Loaded(gltf) => {
                spawn_scene(&mut commands, &gltf, true, aspect);
                spawn_light_rig(&mut commands, lights, rig_bounds(gltf.bounds()), SEED)
            }
        };
        world.flush();
        if let Err(e) = spawned {
            world.insert_resource(manylight::app::RenderFailure(Some(e.to_string())));
        }
        set_shadows(world, shadows);
    });
}
