//! Several cameras: each renders its own view (clusters, post components, debug view) into a
//! viewport of the window or into an offscreen image; the frame's lights are uploaded once.

mod support;

use manylight::app::headless::render_headless;
use manylight::app::{FrameStats, RenderedImages};
use manylight::prelude::*;
use manylight::render::FrameReport;
use support::{STRICT, assert_similar, gpu};

const SIZE: UVec2 = UVec2::new(192, 96);
const HALF: UVec2 = UVec2::new(96, 96);

/// Down the hall from the default scene's entrance, and from its far end back.
fn near_camera() -> Transform {
    Transform::from_xyz(-18.0, 1.7, 0.0).looking_at(Vec3::new(0.0, 1.0, 0.0), Vec3::Y)
}

fn far_camera() -> Transform {
    Transform::from_xyz(12.0, 4.0, 5.0).looking_at(Vec3::new(-6.0, 0.5, -2.0), Vec3::Y)
}

/// The default scene with 48 lights along the hall, without a camera.
fn scene(commands: &mut Commands) {
    spawn_scene(commands, &default_scene(), false, 1.0);
    for i in 0..48 {
        let x = -18.0 + 36.0 * (i as f32 + 0.5) / 48.0;
        let z = if i % 2 == 0 { -4.0 } else { 4.0 };
        let color =
            Color::linear_rgb(1.0, 0.4 + 0.5 * (i % 3) as f32 / 2.0, 0.2 + 0.6 * (i % 5) as f32 / 4.0);
        commands.spawn((
            Transform::from_xyz(x, 0.6, z),
            PointLight { color, intensity: 400.0, range: 4.0, radius: 0.0, ..Default::default() },
        ));
    }
}

/// The left and right halves of a frame.
fn half(image: &image::RgbaImage, right: bool) -> image::RgbaImage {
    image::imageops::crop_imm(image, if right { HALF.x } else { 0 }, 0, HALF.x, HALF.y).to_image()
}

fn render(
    size: UVec2,
    cameras: impl Fn(&mut Commands) + Send + Sync + 'static,
) -> (image::RgbaImage, FrameStats) {
    let frame = render_headless(size, 1, move |app| {
        app.add_systems(Startup, move |mut commands: Commands| {
            scene(&mut commands);
            cameras(&mut commands);
        });
    })
    .unwrap_or_else(|e| panic!("render failed: {e}"));
    support::assert_finite(&frame);
    (frame.image, frame.stats)
}

fn last(stats: &FrameStats) -> &FrameReport {
    stats.last.as_ref().expect("a report")
}

fn viewport(x: u32) -> Option<Viewport> {
    Some(Viewport { physical_position: UVec2::new(x, 0), physical_size: HALF })
}

/// Split screen: two cameras, each in its half of the target. Each half is the image that
/// camera renders alone at the half's size; the views' cluster statistics differ, only the
/// camera with `Bloom` runs bloom passes, and the lights are uploaded once for both.
#[test]
fn split_screen_cameras_render_their_own_views() {
    let _gpu = gpu();
    let (split, stats) = render(SIZE, |commands| {
        commands.spawn((near_camera(), Camera3d, Camera { viewport: viewport(0), ..default() }));
        commands.spawn((
            far_camera(),
            Camera3d,
            Camera { viewport: viewport(HALF.x), order: 1, ..default() },
            Bloom::default(),
        ));
    });
    let (left, _) = render(HALF, |commands| {
        commands.spawn((near_camera(), Camera3d));
    });
    let (right, _) = render(HALF, |commands| {
        commands.spawn((far_camera(), Camera3d, Bloom::default()));
    });
    assert_similar("split_screen_left", &left, &half(&split, false), STRICT);
    assert_similar("split_screen_right", &right, &half(&split, true), STRICT);

    let report = last(&stats);
    assert_eq!(report.views.len(), 2, "{:?}", report.views);
    let (a, b) = (&report.views[0], &report.views[1]);
    assert_eq!((a.width, a.height, b.width, b.height), (HALF.x, HALF.y, HALF.x, HALF.y));
    let bloom = |names: &[String]| names.iter().filter(|n| n.starts_with("bloom")).count();
    assert_eq!(bloom(&a.passes), 0, "the camera without Bloom: {:?}", a.passes);
    assert!(bloom(&b.passes) > 0, "the camera with Bloom: {:?}", b.passes);
    let (ca, cb) = (a.clusters.as_ref().expect("clusters"), b.clusters.as_ref().expect("clusters"));
    assert_ne!(
        (ca.non_empty, ca.total_entries),
        (cb.non_empty, cb.total_entries),
        "the two views see the lights differently"
    );
    assert_eq!(report.light_uploads, 1, "lights are uploaded once for both views");
    // The scene's own lights and the 48 spawned here, 48 bytes each, once.
    assert!(report.light_count > 48, "{}", report.light_count);
    let light_bytes = std::mem::size_of::<manylight::render::gpu_types::GpuPointLight>() as u64;
    assert_eq!(light_bytes, 48);
    assert_eq!(report.light_upload_bytes, u64::from(report.light_count) * light_bytes);
    assert_eq!(report.passes.len(), a.passes.len() + b.passes.len());
}

/// Cameras render by `order`, whatever order they were spawned in; an inactive camera renders
/// nothing; a camera's own debug view replaces only its image.
#[test]
fn order_activity_and_a_per_camera_debug_view() {
    let _gpu = gpu();
    let (_, stats) = render(SIZE, |commands| {
        commands.spawn((
            far_camera(),
            Camera3d,
            Camera { viewport: viewport(HALF.x), order: 2, ..default() },
            CameraDebugView(DebugViewMode::LightCount),
        ));
        commands.spawn((near_camera(), Camera3d, Camera { viewport: viewport(0), order: -1, ..default() }));
        commands.spawn((near_camera(), Camera3d, Camera { order: 5, is_active: false, ..default() }));
    });
    let report = last(&stats);
    let orders: Vec<isize> = report.views.iter().map(|v| v.order).collect();
    assert_eq!(orders, [-1, 2]);
    assert_eq!(report.views[0].passes.last().map(String::as_str), Some("tonemap"));
    assert_eq!(report.views[1].passes.last().map(String::as_str), Some("debug_view"));
}

/// A camera that renders into a `RenderImage`: the app receives its pixels, equal to the same
/// camera rendering the main target; the main target shows the other camera.
#[test]
fn a_camera_renders_into_an_image_the_app_reads() {
    let _gpu = gpu();
    let target = RenderImage::new(HALF.x, HALF.y);
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(SIZE)).add_systems(Startup, move |mut commands: Commands| {
        scene(&mut commands);
        commands.spawn((near_camera(), Camera3d));
        commands.spawn((
            far_camera(),
            Camera3d,
            Camera { target: RenderTarget::Image(target), order: -1, ..default() },
        ));
    });
    app.update();
    let images = app.world().resource::<RenderedImages>();
    let texture = images.get(&target).expect("the camera's image arrived").clone();
    assert_eq!(images.frame_of(&target), Some(0));
    assert_eq!(texture.dimensions(), (HALF.x, HALF.y));
    let report = app.world().resource::<FrameStats>().last.clone().expect("a report");
    let targets: Vec<&str> = report.views.iter().map(|v| v.target.as_str()).collect();
    assert_eq!(targets, [format!("texture {}", target.id.0).as_str(), "main"]);

    let (alone, _) = render(HALF, |commands| {
        commands.spawn((far_camera(), Camera3d));
    });
    assert_similar("render_to_texture", &alone, &texture, STRICT);
    let (main, _) = render(SIZE, |commands| {
        commands.spawn((near_camera(), Camera3d));
    });
    let shown =
        app.world_mut().resource_mut::<manylight::app::HeadlessCapture>().image.take().expect("a frame");
    assert_similar("render_to_texture_main", &main, &shown, STRICT);
}

/// Where no camera's viewport reaches, the target shows the clear colour; a viewport reaching
/// past the target is clipped to it.
#[test]
fn uncovered_pixels_show_the_clear_colour() {
    let _gpu = gpu();
    let (image, stats) = render(SIZE, |commands| {
        let oversized =
            Viewport { physical_position: UVec2::new(HALF.x, 0), physical_size: UVec2::new(500, 500) };
        commands.spawn((far_camera(), Camera3d, Camera { viewport: Some(oversized), ..default() }));
    });
    let report = last(&stats);
    assert_eq!((report.views[0].width, report.views[0].height), (HALF.x, HALF.y), "clipped to the target");
    let left = half(&image, false);
    let first = *left.get_pixel(0, 0);
    assert!(left.pixels().all(|p| *p == first), "the uncovered half is one colour");
    assert!(first.0[..3].iter().all(|&c| c < 40), "and it is the dark clear colour: {first:?}");
    let right = half(&image, true);
    assert!(right.pixels().any(|p| *p != first), "the covered half shows the scene");
}

/// A viewport that changes size every frame (a split-screen window being resized) leaves no
/// image behind: only the sizes of the last frame are kept.
#[test]
fn viewport_images_of_old_sizes_are_freed() {
    let _gpu = gpu();
    let mut renderer = manylight::app::render_world::HeadlessRenderer::new().expect("adapter");
    let scene = default_scene();
    for (frame, width) in [40u32, 48, 56, 64, 72].into_iter().enumerate() {
        let mut snap =
            manylight::app::scene::scene_snapshot(&scene, Vec::new(), SIZE, Default::default(), frame as u64);
        let camera = *snap.camera().expect("a camera");
        snap.views = vec![manylight::render::ExtractedView {
            rect: Some(manylight::render::ViewRect { origin: UVec2::new(8, 8), size: UVec2::new(width, 40) }),
            ..manylight::render::ExtractedView::main(camera)
        }];
        let (report, _) = renderer.render(snap, false).expect("renders");
        assert_eq!((report.views[0].width, report.views[0].height), (width, 40));
        assert_eq!(renderer.render_world.view_image_count(), 1, "frame {frame}");
    }
}

/// A camera that cannot be looked through is counted and skipped, also when another camera of
/// the frame renders.
#[test]
fn an_invalid_camera_beside_a_valid_one_is_counted() {
    let _gpu = gpu();
    let mut renderer = manylight::app::render_world::HeadlessRenderer::new().expect("adapter");
    let mut snap =
        manylight::app::scene::scene_snapshot(&default_scene(), Vec::new(), SIZE, Default::default(), 0);
    let camera = *snap.camera().expect("a camera");
    let broken = manylight::render::ExtractedCamera { world_from_view: glam::Mat4::ZERO, ..camera };
    snap.views.push(manylight::render::ExtractedView::main(broken));
    let (report, _) = renderer.render(snap, false).expect("renders");
    assert_eq!(report.invalid_cameras, 1);
    assert_eq!(report.views.len(), 1);
}
