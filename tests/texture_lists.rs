//! The WebGL2 path (`manylight::render::texture_lists`: clustered forward with CPU-built lists
//! in textures) on a native device held to WebGL2's limits (`GpuContext::webgl2_with_instance`): a
//! storage buffer or a compute shader would fail wgpu's validation there, as on WebGL2. The
//! web demo's hall with 1,024 rig lights renders as the native clustered forward renderer
//! renders it (FLIP), with the same lights and no NaN: on the native renderer's own device
//! (Vulkan), and on wgpu's GL backend, which runs the shader as naga's GLSL ES 3.00 as a
//! browser's WebGL2 does.

mod support;

use manylight::app::backend::RenderBackend;
use manylight::app::headless::{HeadlessFrame, finish_frames, finish_plugins};
use manylight::app::{FrameStats, HeadlessCapture, RenderFailure};
use manylight::prelude::*;
use manylight::render::GpuContext;
use manylight::render::texture_lists::TextureListRenderer;
use manylight_web::demo::{DemoScene, add_scene};
use manylight_web::options::WebOptions;
use manylight_web::webgl::TextureListSink;

/// Renders `frames` updates of the page's scene for `query` through the texture-list sink, on
/// a device of `instance` held to WebGL2's limits.
fn render_texture_lists(instance: wgpu::Instance, query: &str, size: UVec2, frames: u32) -> HeadlessFrame {
    let options = WebOptions::from_query(query).expect("a valid query");
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(size));
    add_scene(&mut app, &options, DemoScene::Hall, size.x as f32 / size.y as f32);
    finish_plugins(&mut app);
    let gpu = GpuContext::webgl2_with_instance(instance).expect("a device with WebGL2's limits");
    let renderer = TextureListRenderer::new(gpu).expect("the texture-list renderer");
    app.insert_resource(RenderBackend::start(Box::new(TextureListSink::new(renderer, None)), false));
    for _ in 0..frames {
        app.update();
        if let Some(message) = &app.world().resource::<RenderFailure>().0 {
            panic!("the texture-list frame failed: {message}");
        }
    }
    finish_frames(&mut app);
    let image = app.world().resource::<HeadlessCapture>().image.clone().expect("a frame read back");
    HeadlessFrame { image, stats: app.world().resource::<FrameStats>().clone() }
}

/// The page's fixed-clock query at 128×128 (what `tests/web.rs` captures).
fn query(lights: usize) -> String {
    format!("?lights={lights}&size=128x128&overlay=off&clock=fixed&capture=3&present=read-back")
}

/// The hall with 1,024 rig lights on a device of `instance` against the native clustered
/// forward frame.
fn hall_matches_clustered_forward(name: &str, instance: wgpu::Instance, tolerance: support::Tolerance) {
    let _gpu = support::gpu();
    let size = UVec2::new(128, 128);
    let query = query(1024);
    let options = WebOptions::from_query(&query).expect("a valid query");
    let expected = manylight::app::headless::render_headless(size, 3, |app| {
        manylight_web::demo::add_scene(app, &options, DemoScene::Hall, 1.0);
    })
    .expect("the native frame");
    let actual = render_texture_lists(instance, &query, size, 3);
    let report = actual.stats.last.as_ref().expect("a frame report");
    assert_eq!(report.light_count, 1030, "the hall's 6 lights and the rig's 1,024");
    assert_eq!(report.pipeline, manylight::render::PipelineKind::ClusteredForward);
    assert_eq!(report.nonfinite_pixels, Some(0));
    assert_eq!(report.pass_names(), ["cluster_assign", "texture_lists"]);
    let clusters = report.clusters.as_ref().expect("the assignment's statistics");
    assert_eq!(clusters.lights, 1030);
    assert!(clusters.total_entries > 0 && clusters.dropped_pairs == 0, "{clusters:?}");
    let flip = support::assert_similar(name, &expected.image, &actual.image, tolerance);
    println!("{name} against clustered forward: FLIP mean {:.4}, p99 {:.4}", flip.mean, flip.p99);
}

/// On the default device (lavapipe's Vulkan in CI) held to WebGL2's limits: the native
/// renderer's own device, so within the strict thresholds.
#[test]
fn hall_on_webgl2_limits_matches_clustered_forward() {
    let instance = manylight::render::context::new_instance();
    hall_matches_clustered_forward("texture_lists_hall", instance, support::STRICT);
}

/// On wgpu's GL backend (Mesa's llvmpipe through EGL), which runs the shader as naga's GLSL
/// ES 3.00, as a browser's WebGL2 does: another driver than the native frame's, so within the
/// thresholds across devices.
#[test]
fn hall_on_gl_matches_clustered_forward() {
    let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
    desc.backends = wgpu::Backends::GL;
    hall_matches_clustered_forward("texture_lists_hall_gl", wgpu::Instance::new(desc), support::CROSS_DEVICE);
}
