//! "Only what the scene calls for": the exact pass list for the matrix {lights yes/no} ×
//! {Bloom yes/no} × {MotionBlur yes/no} × {clustered forward / clustered deferred} × {debug view
//! on/off}, planned without a GPU for every point and rendered on the device for every point
//! (one app, toggled at run time: each change shows in the next frame), and transients of a
//! removed effect freed after a few frames.

mod support;

// The custom_pass example's vignette: a pass an app adds from outside the crates.
#[allow(dead_code)]
#[path = "../examples/custom_pass.rs"]
mod custom_pass;

use manylight::app::render_world::plan_passes;
use manylight::app::scene::scene_snapshot;
use manylight::app::{DebugView, FrameStats};
use manylight::prelude::*;
use manylight::render::{
    BloomSettings, DebugViewMode, ExtractedPointLight, FrameSettings, MotionBlurSettings,
};
use support::gpu;

const SIZE: UVec2 = UVec2::new(64, 48);

/// One point of the matrix.
#[derive(Clone, Copy, Debug)]
struct Point {
    lights: bool,
    bloom: bool,
    motion_blur: bool,
    deferred: bool,
    debug: bool,
}

fn matrix() -> Vec<Point> {
    let mut points = Vec::new();
    for i in 0..32u32 {
        let bit = |b: u32| i & (1 << b) != 0;
        points.push(Point {
            lights: bit(0),
            bloom: bit(1),
            motion_blur: bit(2),
            deferred: bit(3),
            debug: bit(4),
        });
    }
    points
}

fn pipeline(p: Point) -> PipelineKind {
    if p.deferred { PipelineKind::ClusteredDeferred } else { PipelineKind::ClusteredForward }
}

/// The debug view of the "on" points: the light-count heatmap (it needs cluster data).
const DEBUG_MODE: DebugViewMode = DebugViewMode::LightCount;

/// The passes a point needs, written out rule by rule.
fn expected(p: Point) -> Vec<&'static str> {
    let mut passes: Vec<&'static str> = match (p.debug, p.deferred, p.lights) {
        // Shading: clustered forward (with its depth pre-pass) or G-buffer + deferred lighting,
        // each with per-cluster depth bounds between the depth and the build and refined light
        // lists after it.
        (false, false, true) => {
            vec!["depth_prepass", "cluster_depth", "cluster_build", "light_refine", "clustered_forward"]
        }
        (false, true, true) => {
            vec!["gbuffer", "cluster_depth", "cluster_build", "light_refine", "deferred_lighting"]
        }
        // No lights: no cluster build, no light lists, no G-buffer: the ambient forward pass.
        (false, _, false) => vec!["forward"],
        // The light-count view replaces shading: depth (pre-pass or G-buffer) + clusters only.
        (true, false, true) => vec!["depth_prepass", "cluster_build"],
        (true, true, true) => vec!["cluster_build", "gbuffer"],
        // … and shows the (empty) grid without lights, over the forward pass's depth.
        (true, _, false) => vec!["cluster_build", "forward"],
    };
    if p.debug {
        // The debug view replaces tone mapping and the post stages with it.
        passes.push("debug_view");
        return passes;
    }
    if p.motion_blur {
        passes.push("motion_blur");
    }
    if p.bloom {
        passes.push("bloom_bright");
        for _ in 0..BloomSettings::default().iterations {
            passes.extend(["bloom_blur_h", "bloom_blur_v"]);
        }
        // Downsampled chain: the levels are summed from the smallest up.
        passes.extend(std::iter::repeat_n("bloom_upsample", BloomSettings::default().levels() - 1));
        passes.push("bloom_composite");
    }
    passes.push("tonemap");
    passes
}

fn snapshot(p: Point) -> manylight::render::FrameSnapshot {
    let scene = default_scene();
    let lights: Vec<ExtractedPointLight> = if p.lights {
        scene.lights.iter().map(manylight::app::scene::extracted_light).collect()
    } else {
        Vec::new()
    };
    assert!(!p.lights || !lights.is_empty(), "the default scene brings lights");
    let settings = FrameSettings {
        render: RenderSettings { pipeline: pipeline(p), ..Default::default() },
        debug_view: if p.debug { DEBUG_MODE } else { DebugViewMode::None },
        ..FrameSettings::default()
    };
    let mut s = scene_snapshot(&scene, lights, SIZE, settings, 0);
    if let Some(camera) = s.camera_mut() {
        camera.bloom = p.bloom.then(BloomSettings::default);
        camera.motion_blur = p.motion_blur.then(MotionBlurSettings::default);
    }
    s
}

#[test]
fn planned_pass_lists_match_the_matrix() {
    for p in matrix() {
        let planned = plan_passes(snapshot(p)).unwrap_or_else(|e| panic!("{p:?}: {e}"));
        assert_eq!(planned, expected(p), "{p:?}");
    }
}

#[test]
fn other_debug_views_need_only_their_data() {
    let with = |pipeline, view, lights| {
        let p = Point { lights, bloom: true, motion_blur: true, deferred: false, debug: true };
        let mut s = snapshot(p);
        s.settings.pipeline = pipeline;
        s.settings.debug_view = view;
        plan_passes(s).expect("plan")
    };
    use DebugViewMode::*;
    use PipelineKind::*;
    // Surface views draw the Full G-buffer instead of shading, in forward pipelines too.
    assert_eq!(with(ClusteredForward, Albedo, true), ["gbuffer", "debug_view"]);
    assert_eq!(with(NaiveForward, Normal, true), ["gbuffer", "debug_view"]);
    assert_eq!(with(ClusteredDeferred, Normal, false), ["gbuffer", "debug_view"]);
    // Depth needs depth only: no cluster build, no lighting.
    assert_eq!(with(ClusteredForward, Depth, true), ["depth_prepass", "debug_view"]);
    assert_eq!(with(ClusteredDeferred, Depth, true), ["depth_prepass", "debug_view"]);
    assert_eq!(with(NaiveForward, Depth, false), ["depth_prepass", "debug_view"]);
    assert_eq!(with(ClusteredForward, Overflow, true), ["depth_prepass", "cluster_build", "debug_view"]);
    // The seed's bloom: 5 iterations at full resolution.
    let p = Point { lights: true, bloom: true, motion_blur: false, deferred: false, debug: false };
    let mut s = snapshot(p);
    if let Some(c) = s.camera_mut() {
        c.bloom = Some(BloomSettings::full_resolution());
    }
    let names = plan_passes(s).expect("plan");
    assert_eq!(names.iter().filter(|n| n.starts_with("bloom_blur")).count(), 10, "{names:?}");
    assert!(!names.contains(&"bloom_upsample"), "one full-resolution level: {names:?}");
}

fn set_point(app: &mut App, p: Point) {
    let world = app.world_mut();
    world.resource_mut::<RenderSettings>().pipeline = pipeline(p);
    world.resource_mut::<DebugView>().mode = if p.debug { DEBUG_MODE } else { DebugViewMode::None };
    let lights: Vec<Entity> = world.query_filtered::<Entity, With<PointLight>>().iter(world).collect();
    if p.lights && lights.is_empty() {
        for l in &default_scene().lights {
            world.spawn((
                Transform::from_translation(l.position),
                PointLight {
                    color: manylight::app::from_linear_rgb(l.color),
                    intensity: l.intensity,
                    range: l.radius,
                    radius: 0.0,
                    ..Default::default()
                },
            ));
        }
    } else if !p.lights {
        for e in lights {
            world.despawn(e);
        }
    }
    let camera = world.query_filtered::<Entity, With<Camera3d>>().single(world).expect("one camera");
    let mut camera = world.entity_mut(camera);
    if p.bloom {
        camera.insert(Bloom::default());
    } else {
        camera.remove::<Bloom>();
    }
    if p.motion_blur {
        camera.insert(MotionBlur::default());
    } else {
        camera.remove::<MotionBlur>();
    }
}

fn scene_app() -> App {
    let mut app = App::new();
    app.add_plugins(ManyLightPlugin::headless(SIZE)).add_systems(Startup, |mut commands: Commands| {
        spawn_scene(&mut commands, &default_scene(), true, SIZE.x as f32 / SIZE.y as f32);
    });
    app
}

fn last_passes(app: &App) -> Vec<String> {
    app.world().resource::<FrameStats>().pass_names()
}

#[test]
fn rendered_pass_lists_follow_run_time_changes() {
    let _gpu = gpu();
    let mut app = scene_app();
    app.update();
    for p in matrix() {
        set_point(&mut app, p);
        app.update();
        if let Some(e) = &app.world().resource::<manylight::app::RenderFailure>().0 {
            panic!("{p:?}: {e}");
        }
        assert_eq!(last_passes(&app), expected(p), "{p:?}");
    }
}

#[test]
fn removing_bloom_frees_its_textures() {
    let _gpu = gpu();
    let mut app = scene_app();
    app.update();
    let base = Point { lights: true, bloom: false, motion_blur: false, deferred: false, debug: false };
    set_point(&mut app, base);
    app.update();
    let live =
        |app: &App| app.world().resource::<FrameStats>().last.as_ref().expect("report").transient_textures;
    let without = live(&app);
    assert_eq!(without, 3, "hdr + depth + shading distance");
    set_point(&mut app, Point { bloom: true, ..base });
    app.update();
    // Downsampled chain, 5 levels: each level and its horizontal intermediate.
    let with = live(&app);
    assert_eq!(with, without + 2 * BloomSettings::default().iterations);
    set_point(&mut app, base);
    // Kept for reuse while unused for up to TRANSIENT_KEEP_FRAMES frames, then freed.
    let keep = manylight::render::pool::TRANSIENT_KEEP_FRAMES;
    for frame in 1..=keep + 1 {
        app.update();
        assert!(!last_passes(&app).iter().any(|n| n.starts_with("bloom")));
        let expected = if frame <= keep { with } else { without };
        assert_eq!(live(&app), expected, "frame {frame} after removing Bloom");
    }
    // Motion blur: one full-size intermediate, freed the same way.
    set_point(&mut app, Point { motion_blur: true, ..base });
    app.update();
    assert_eq!(live(&app), without + 1);
    set_point(&mut app, base);
    for _ in 0..=keep {
        app.update();
    }
    assert_eq!(live(&app), without);
}

/// A pass of the kind docs/architecture.md walks through: its module (here, this test), its
/// WGSL (below), and one registration line. It adds a constant red to the HDR image.
mod red_tint {
    use manylight::render::graph::{Pass, PassContext, ResourceName};
    use manylight::render::passes::HDR;
    use manylight::render::pipelines::PipelineKey;
    use manylight::render::resources::HDR_FORMAT;
    use manylight::render::{PlanInputs, RenderError};

    /// The pass's WGSL.
    const WGSL: &str = "
        @vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
            let p = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
            return vec4<f32>(p * 2.0 - 1.0, 0.0, 1.0);
        }
        @fragment fn fs() -> @location(0) vec4<f32> { return vec4<f32>(0.25, 0.0, 0.0, 0.0); }
    ";

    /// Its pipeline has one variant.
    #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
    struct RedTintKey;

    impl PipelineKey for RedTintKey {
        type Pipeline = wgpu::RenderPipeline;
    }

    /// Adds red to the HDR image.
    pub struct RedTint;

    /// When it is needed: whenever the image is shown (no debug view).
    pub fn plan(p: &PlanInputs<'_>, out: &mut Vec<Box<dyn Pass>>) {
        if p.shows_image() {
            out.push(Box::new(RedTint));
        }
    }

    fn pipeline(device: &wgpu::Device) -> wgpu::RenderPipeline {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("red_tint"),
            source: wgpu::ShaderSource::Wgsl(WGSL.into()),
        });
        let add = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        };
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("red_tint"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: HDR_FORMAT,
                    blend: Some(wgpu::BlendState { color: add, alpha: add }),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        })
    }

    impl Pass for RedTint {
        fn name(&self) -> &'static str {
            "red_tint"
        }
        fn reads(&self) -> Vec<ResourceName> {
            vec![HDR]
        }
        fn writes(&self) -> Vec<ResourceName> {
            vec![HDR]
        }
        fn record(&self, ctx: &mut PassContext<'_>) -> Result<(), RenderError> {
            let device = &ctx.gpu.device;
            let pipeline =
                ctx.pipelines.get_or_create(RedTintKey, |_| Ok::<_, RenderError>(pipeline(device)))?;
            let view = ctx.texture(HDR)?;
            let timestamps = ctx.render_timestamps(true, true);
            let mut pass = ctx.encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("red_tint"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: timestamps,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&pipeline);
            pass.draw(0..3, 0..1);
            Ok(())
        }
    }
}

#[test]
fn a_pass_added_by_one_registration_line_runs_in_its_place() {
    let _gpu = gpu();
    let point = Point { lights: true, bloom: true, motion_blur: false, deferred: false, debug: false };
    let snapshot = || snapshot(point);
    let mut renderer = manylight::app::render_world::HeadlessRenderer::new().expect("adapter");
    let (plain, plain_image) = renderer.render(snapshot(), true).expect("renders");
    // The one registration line.
    assert_eq!(pipeline(point), PipelineKind::ClusteredForward);
    let shading = "clustered_forward";
    let mut stages = manylight::render::FramePlanner::default();
    stages
        .insert_after::<manylight::render::passes::ClusteredForwardPass>(manylight::render::Stage::new::<
            red_tint::RedTint,
        >(red_tint::plan))
        .expect("a shading stage");
    renderer.render_world.set_stages(&std::sync::Arc::new(stages));
    let (tinted, tinted_image) = renderer.render(snapshot(), true).expect("renders");
    let names = tinted.pass_names();
    let at = |n: &str| names.iter().position(|p| *p == n).unwrap_or_else(|| panic!("{n} missing: {names:?}"));
    assert!(at(shading) < at("red_tint") && at("red_tint") < at("bloom_bright"), "{names:?}");
    assert_eq!(names.len(), plain.pass_names().len() + 1, "{names:?}");
    let mean = |img: &image::RgbaImage, c: usize| {
        img.pixels().map(|p| f64::from(p.0[c])).sum::<f64>() / (img.len() / 4) as f64
    };
    let (plain_image, tinted_image) = (plain_image.expect("image"), tinted_image.expect("image"));
    assert!(mean(&tinted_image, 0) > mean(&plain_image, 0) + 10.0, "red does not rise");
    assert!((mean(&tinted_image, 2) - mean(&plain_image, 2)).abs() < 3.0, "blue changed");
    // A debug view replaces the image: the stage adds nothing then.
    let mut debug = snapshot();
    debug.settings.debug_view = DebugViewMode::Depth;
    let (report, _) = renderer.render(debug, false).expect("renders");
    assert!(!report.pass_names().contains(&"red_tint"), "{:?}", report.pass_names());
}

#[test]
fn the_graph_is_compiled_when_the_plan_changes_not_every_frame() {
    let _gpu = gpu();
    let mut renderer = manylight::app::render_world::HeadlessRenderer::new().expect("adapter");
    let compilations = |r: &manylight::app::render_world::HeadlessRenderer| {
        r.render_world.world.resource::<manylight::app::render_world::FrameGraph>().0.compilations()
    };
    let plain = Point { lights: true, bloom: false, motion_blur: false, deferred: false, debug: false };
    let bloom = Point { bloom: true, ..plain };
    renderer.render(snapshot(plain), false).expect("renders");
    let first = compilations(&renderer);
    for _ in 0..3 {
        renderer.render(snapshot(plain), false).expect("renders");
    }
    assert_eq!(compilations(&renderer), first, "an unchanged plan is not compiled again");
    renderer.render(snapshot(bloom), false).expect("renders");
    assert_eq!(compilations(&renderer), first + 1, "bloom changes the plan");
    renderer.render(snapshot(plain), false).expect("renders");
    renderer.render(snapshot(bloom), false).expect("renders");
    assert_eq!(compilations(&renderer), first + 1, "both plans are kept");
}

/// Blended materials add the transparent pass after shading, in every pipeline (lit through
/// the cluster lists where the view built them); without one there is none, and a debug view
/// that replaces shading draws none either.
#[test]
fn the_transparent_pass_runs_only_for_blended_materials() {
    let blended = |pipeline, lights, debug| {
        let p = Point { lights, bloom: false, motion_blur: false, deferred: false, debug };
        let mut s = snapshot(p);
        s.settings.pipeline = pipeline;
        if !debug {
            s.settings.debug_view = DebugViewMode::None;
        }
        let material = std::sync::Arc::make_mut(&mut s.instances[0].material);
        material.alpha_mode = manylight::math::AlphaMode::Blend;
        plan_passes(s).expect("plan")
    };
    use PipelineKind::*;
    assert_eq!(
        blended(ClusteredForward, true, false),
        ["depth_prepass", "cluster_build", "clustered_forward", "transparent", "tonemap"]
    );
    assert_eq!(
        blended(ClusteredDeferred, true, false),
        ["cluster_build", "gbuffer", "deferred_lighting", "transparent", "tonemap"]
    );
    assert_eq!(blended(NaiveForward, true, false), ["forward", "transparent", "tonemap"]);
    assert_eq!(blended(LightVolumes, true, false), ["gbuffer", "light_volumes", "transparent", "tonemap"]);
    assert_eq!(blended(ClusteredDeferred, false, false), ["forward", "transparent", "tonemap"]);
    assert!(!blended(ClusteredForward, true, true).contains(&"transparent"));
    for p in matrix() {
        assert!(!plan_passes(snapshot(p)).expect("plan").contains(&"transparent"), "{p:?}");
    }
}

/// Refined light lists (`ClusterSettings::refined_lists`) add the `light_refine` pass after the
/// build where every shaded fragment's distance is known before shading (depth pre-pass,
/// G-buffer), and the pre-pass then writes the shading distance; not without lights, with a
/// debug view, in tiled deferred (which cuts its tile lists itself), or in clustered forward
/// without a pre-pass.
#[test]
fn refined_lists_plan_a_refine_pass_where_distances_are_known() {
    use PipelineKind::*;
    let with = |pipeline, lights, debug, depth_bounds, prepass| {
        let p = Point { lights, bloom: false, motion_blur: false, deferred: false, debug };
        let mut s = snapshot(p);
        s.settings.pipeline = pipeline;
        s.settings.render.clusters.refined_lists = true;
        s.settings.render.clusters.depth_bounds = depth_bounds;
        s.settings.render.clusters.depth_prepass = prepass;
        plan_passes(s).expect("plan")
    };
    let forward =
        ["depth_prepass", "cluster_depth", "cluster_build", "light_refine", "clustered_forward", "tonemap"];
    assert_eq!(with(ClusteredForward, true, false, true, true), forward);
    assert_eq!(
        with(ForwardPlus, true, false, false, true),
        ["depth_prepass", "cluster_build", "light_refine", "clustered_forward", "tonemap"]
    );
    assert_eq!(
        with(ClusteredDeferred, true, false, false, true),
        ["cluster_build", "gbuffer", "light_refine", "deferred_lighting", "tonemap"]
    );
    assert_eq!(
        with(ClusteredDeferred, true, false, true, true),
        ["gbuffer", "cluster_depth", "cluster_build", "light_refine", "deferred_lighting", "tonemap"]
    );
    assert_eq!(
        with(TiledDeferred, true, false, false, true),
        ["cluster_build", "gbuffer", "tiled_deferred", "tonemap"]
    );
    assert_eq!(
        with(ClusteredForward, true, false, true, false),
        ["cluster_build", "clustered_forward", "tonemap"]
    );
    assert_eq!(with(ClusteredForward, false, false, true, true), ["forward", "tonemap"]);
    assert_eq!(
        with(ClusteredForward, true, true, true, true),
        ["depth_prepass", "cluster_build", "debug_view"]
    );
}

#[test]
fn the_shadow_pass_runs_only_where_a_light_casts_and_lights_are_shaded() {
    for deferred in [false, true] {
        let p = Point { lights: true, bloom: false, motion_blur: false, deferred, debug: false };
        let casting = || {
            let mut s = snapshot(p);
            s.lights.update(|l| *l = manylight::app::scene::with_shadow(l.clone(), true));
            s
        };
        let mut with_shadows = vec!["shadow_maps"];
        with_shadows.extend(expected(p));
        assert_eq!(plan_passes(casting()).unwrap(), with_shadows, "{p:?}");
        // No light casts: today's list, unchanged.
        assert_eq!(plan_passes(snapshot(p)).unwrap(), expected(p), "{p:?}");
        // Shadows turned off for the view: no shadow pass though the lights cast.
        let mut off = casting();
        off.settings.render.shadows.enabled = false;
        assert_eq!(plan_passes(off).unwrap(), expected(p), "{p:?}");
        // A debug view that replaces shading draws no shadow maps.
        let debug = Point { debug: true, ..p };
        let mut s = snapshot(debug);
        s.lights.update(|l| *l = manylight::app::scene::with_shadow(l.clone(), true));
        assert_eq!(plan_passes(s).unwrap(), expected(debug), "{debug:?}");
        // A casting sun alone (no point light): the shadow pass, then the frame of no lights.
        let unlit = Point { lights: false, ..p };
        let mut sun = snapshot(unlit);
        sun.directional_lights.push(manylight::render::ExtractedDirectionalLight {
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            illuminance: 1.0,
            shadow: Some(manylight::render::DirectionalShadow::default()),
        });
        let mut with_sun = vec!["shadow_maps"];
        with_sun.extend(expected(unlit));
        assert_eq!(plan_passes(sun.clone()).unwrap(), with_sun, "{unlit:?}");
        sun.directional_lights[0].shadow = None;
        assert_eq!(plan_passes(sun).unwrap(), expected(unlit), "{unlit:?}");
    }
}

/// The custom_pass example, headless at 128×64 (two 64×64 cameras side by side), its right
/// camera carrying `vignette` if any: its image and the last frame's report.
fn render_custom_pass(
    vignette: Option<custom_pass::Vignette>,
) -> (image::RgbaImage, manylight::render::FrameReport) {
    let frame = manylight::app::headless::render_headless(UVec2::new(128, 64), 1, move |app| {
        app.add_systems(Startup, move |mut commands: Commands| custom_pass::setup(&mut commands, vignette))
            .add_systems(Update, custom_pass::layout);
        custom_pass::add_vignette(app).expect("tone mapping is a stage");
    })
    .unwrap_or_else(|e| panic!("render failed: {e}"));
    support::assert_finite(&frame);
    (frame.image, frame.stats.last.expect("a report"))
}

/// An app's own pass (the custom_pass example: its WGSL, its camera component, its stage before
/// tone mapping, the HDR image swapped through `post_process_write`) runs only for the camera
/// that carries its component: only that camera's pixels change, darker towards the corners,
/// and the other camera runs exactly the passes it runs without the app's pass.
#[test]
fn an_app_pass_runs_only_for_the_camera_that_carries_its_component() {
    let _gpu = gpu();
    let (plain, plain_report) = render_custom_pass(None);
    let (vignetted, report) = render_custom_pass(Some(custom_pass::Vignette { strength: 1.0, radius: 0.2 }));
    let half =
        |img: &image::RgbaImage, right: u32| image::imageops::crop_imm(img, right * 64, 0, 64, 64).to_image();
    assert_eq!(half(&plain, 0), half(&vignetted, 0), "the camera without a Vignette changed");
    let luma = |img: &image::RgbaImage, x: u32, y: u32| {
        let p = img.get_pixel(x, y).0;
        u32::from(p[0]) + u32::from(p[1]) + u32::from(p[2])
    };
    let corners = |img: &image::RgbaImage| -> u32 {
        [(64, 0), (127, 0), (64, 63), (127, 63)].iter().map(|&(x, y)| luma(img, x, y)).sum()
    };
    assert!(
        corners(&vignetted) * 4 < corners(&plain),
        "corners not darkened: {} against {}",
        corners(&vignetted),
        corners(&plain)
    );
    let centre = |img: &image::RgbaImage| luma(img, 96, 32);
    assert!(centre(&vignetted).abs_diff(centre(&plain)) <= 3, "the centre changed");
    let passes = |r: &manylight::render::FrameReport, view: usize| r.views[view].passes.clone();
    assert_eq!(passes(&report, 0), passes(&plain_report, 0), "the plain camera ran another pass");
    let right = passes(&report, 1);
    let at = |n: &str| right.iter().position(|p| p == n).unwrap_or_else(|| panic!("{n} missing: {right:?}"));
    assert!(at("vignette") + 1 == at("tonemap"), "{right:?}");
    assert_eq!(right.len(), passes(&plain_report, 1).len() + 1, "{right:?}");
}

/// An app's WGSL is composed with the library's includes and validates with naga (no GPU); an
/// include the library does not have is an error naming it.
#[test]
fn an_app_shader_composes_with_the_library_includes_and_validates() {
    let code = manylight::render::shaders::compose_source(
        "custom_pass.wgsl",
        <custom_pass::VignettePass as manylight::render::ext::PostPass>::WGSL,
    )
    .expect("composes");
    let module =
        naga::front::wgsl::parse_str(&code).unwrap_or_else(|e| panic!("{}", e.emit_to_string(&code)));
    naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all())
        .validate(&module)
        .unwrap_or_else(|e| panic!("custom_pass.wgsl: {e:?}"));
    let entries: Vec<&str> = module.entry_points.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(entries, ["fullscreen_vs", "fs_main"]);
    let missing = manylight::render::shaders::compose_source("mine.wgsl", "//!include common/nothing.wgsl\n");
    assert!(
        matches!(&missing, Err(manylight::render::shaders::ShaderError::Unknown(f)) if f == "common/nothing.wgsl"),
        "{missing:?}"
    );
}
