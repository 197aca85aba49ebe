//! Every buffer, bind group, upload and blocking wait wgpu sees is one `GpuContext` counted
//! (`FrameReport::buffers_created`, `bind_groups_created`, `blocking_waits`,
//! `cpu.upload_bytes`), and after the first frames wgpu creates nothing: wgpu-core's own log of
//! its device and queue calls (`gpu_creation/wgpu_calls.rs`) is compared, frame by frame, with
//! the context's counts over frames of every pipeline, with shadows and post stages, on a real
//! device (lavapipe in CI; a missing adapter fails). The render crate's
//! `tests/counted_creation.rs` checks the same promise on the code.

#[path = "gpu_creation/wgpu_calls.rs"]
mod wgpu_calls;

use manylight::app::render_world::HeadlessRenderer;
use manylight::app::scene::{extracted_light, scene_snapshot, with_shadow};
use manylight::render::{
    BloomSettings, FrameSettings, GBufferLayout, MotionBlurSettings, PipelineKind, RenderSettings,
};

const SIZE: glam::UVec2 = glam::UVec2::new(96, 64);
const LIGHTS: usize = 64;
/// Frames per configuration; from [`WARMUP`] on, nothing may be created.
const FRAMES: u64 = 6;
const WARMUP: u64 = 3;

/// Every pipeline; then clustered forward with every light casting a shadow, bloom and
/// motion blur.
fn configurations() -> Vec<(String, RenderSettings, bool)> {
    let mut out: Vec<(String, RenderSettings, bool)> = PipelineKind::ALL
        .into_iter()
        .map(|pipeline| {
            let settings = RenderSettings { pipeline, gbuffer: GBufferLayout::Compact, ..Default::default() };
            (pipeline.name().to_string(), settings, false)
        })
        .collect();
    out.push((
        "clustered forward with shadows, bloom and motion blur".into(),
        RenderSettings::default(),
        true,
    ));
    out
}

#[test]
fn wgpu_creates_and_waits_only_what_the_context_counts() {
    wgpu_calls::install();
    let mut renderer = HeadlessRenderer::new().unwrap_or_else(|e| panic!("GPU test needs an adapter: {e}"));
    let scene = manylight::scene::default_scene();
    let rig = manylight::scene::light_rig(LIGHTS, scene.bounds(), 7).expect("the rig's lights fit");
    let mut seen_in_all = wgpu_calls::Calls::default();
    for (name, settings, extras) in configurations() {
        for frame in 0..FRAMES {
            let t = frame as f32 / 60.0;
            let rig_lights = rig.iter().map(|a| extracted_light(&manylight::scene::animated_light_at(a, t)));
            let lights =
                scene.lights.iter().map(extracted_light).chain(rig_lights).map(|l| with_shadow(l, extras));
            let mut snapshot =
                scene_snapshot(&scene, lights.collect(), SIZE, FrameSettings::from(settings), frame);
            if extras {
                let camera = &mut snapshot.views[0].camera;
                camera.bloom = Some(BloomSettings::default());
                camera.motion_blur = Some(MotionBlurSettings::default());
                camera.prev_clip_from_world = Some(glam::Mat4::from_rotation_y(0.01 * frame as f32));
            }
            let (seen_before, counted_before) = (wgpu_calls::calls(), renderer.render_world.gpu().counts());
            renderer.render(snapshot, false).unwrap_or_else(|e| panic!("{name}, frame {frame}: {e}"));
            let seen = wgpu_calls::calls().since(seen_before);
            let counted = renderer.render_world.gpu().counts().since(counted_before);
            let at = format!("{name}, frame {frame}: wgpu saw {seen:?}, GpuContext counted {counted:?}");
            assert_eq!(seen.buffers, counted.buffers, "{at}");
            assert_eq!(seen.bind_groups, counted.bind_groups, "{at}");
            assert_eq!(seen.waits, counted.blocking_waits, "{at}");
            // Uploads are counted in bytes: a frame whose writes wgpu saw counted some.
            assert!(seen.writes == 0 || counted.bytes_uploaded > 0, "{at}");
            if frame >= WARMUP {
                assert_eq!((seen.buffers, seen.bind_groups), (0, 0), "{at}: created after the warm-up");
            }
            seen_in_all = wgpu_calls::Calls {
                buffers: seen_in_all.buffers + seen.buffers,
                bind_groups: seen_in_all.bind_groups + seen.bind_groups,
                writes: seen_in_all.writes + seen.writes,
                waits: seen_in_all.waits + seen.waits,
            };
        }
    }
    // The log was read: without it every comparison above would hold with zeros.
    let s = seen_in_all;
    assert!(s.buffers > 0 && s.bind_groups > 0 && s.writes > 0 && s.waits > 0, "{s:?}");
}
