//! Rendered images against stored references (FLIP), on a real device (lavapipe in CI).

mod support;

use manylight::app::RenderSettings;
use manylight::app::headless::{HeadlessFrame, render_headless};
use manylight::prelude::*;
use support::{STRICT, assert_matches_reference, gpu, shared_asset};

/// Renders `scene` at `size` with `lights` rig lights (seed 1) through the headless plugin.
fn render(scene: Scene, size: UVec2, lights: usize, settings: RenderSettings) -> HeadlessFrame {
    let aspect = size.x as f32 / size.y as f32;
    let bounds = scene.bounds();
    render_headless(size, 1, move |app| {
        app.insert_resource(settings).add_systems(Startup, move |mut commands: Commands| {
            spawn_scene(&mut commands, &scene, true, aspect);
            spawn_light_rig(&mut commands, lights, bounds, 1);
        });
    })
    .unwrap_or_else(|e| panic!("render failed: {e}"))
}

#[test]
fn default_scene_matches_reference() {
    let _gpu = gpu();
    let frame = render(default_scene(), UVec2::new(256, 144), 32, RenderSettings::default());
    assert_matches_reference("default_scene_naive", &frame.image, STRICT);
}

#[test]
fn gltf_scene_matches_reference() {
    let _gpu = gpu();
    let path = shared_asset("CornellBox/CornellBoxManyLights.gltf");
    let scene = load_gltf(&path, &LoadOptions::default()).expect("CornellBoxManyLights loads");
    let settings = RenderSettings { exposure: 4.0, ..RenderSettings::default() };
    let frame = render(scene, UVec2::new(128, 128), 0, settings);
    assert_matches_reference("cornell_box_many_lights_naive", &frame.image, STRICT);
}

#[test]
fn shading_models_give_different_images() {
    let _gpu = gpu();
    let size = UVec2::new(128, 72);
    let lambert = render(
        default_scene(),
        size,
        16,
        RenderSettings { shading: ShadingModel::Lambert, ..RenderSettings::default() },
    );
    let blinn = render(
        default_scene(),
        size,
        16,
        RenderSettings { shading: ShadingModel::BlinnPhong, ..RenderSettings::default() },
    );
    let (stats, _) = manylight::core::image_metrics::flip_compare(
        lambert.image.dimensions(),
        lambert.image.as_raw(),
        blinn.image.dimensions(),
        blinn.image.as_raw(),
    )
    .expect("same size");
    assert!(stats.max > 0.05, "Blinn-Phong adds specular highlights, so the images must differ: {stats:?}");
}
