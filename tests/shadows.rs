//! Shadows: a plate over a floor shadows the floor where the exact visibility oracle
//! (`manylight_core::shadow_oracle`) says, for a point, a spot and a directional light, with
//! shadow maps and with shadow rays; every pipeline gives naive forward's shadowed image;
//! lights that do not cast change nothing; the hard cases hold for maps and rays.

mod support;

use glam::Mat4;
use manylight::app::headless::{HeadlessFrame, render_headless};
use manylight::math::LightShape;
use manylight::math::shadow_oracle::{LightSource, OccluderSet, ShadowQuery};
use manylight::prelude::*;
use manylight::render::{ShadowFilteringMethod, ShadowMethod};
use manylight::scene::shapes::cuboid;
use manylight::scene::{SceneCamera, SceneInstance, camera_looking_at};
use std::sync::Arc;
use support::{COMPACT, STRICT, assert_similar, gpu};

const SIZE: UVec2 = UVec2::new(160, 120);
const LIGHT: Vec3 = Vec3::new(0.0, 2.0, 0.0);
const EYE: Vec3 = Vec3::new(0.0, 5.0, 5.0);
/// Half the floor's edge.
const FLOOR: f32 = 4.0;

/// A floor (top at y = 0), a 1 × 1 plate at y = 1 and the camera looking down at them.
fn plate_scene() -> Scene {
    let white = MaterialData { base_color: Color::linear_rgb(0.8, 0.8, 0.8), ..MaterialData::default() };
    Scene {
        name: "plate".into(),
        meshes: vec![
            Arc::new(cuboid("floor", Vec3::new(2.0 * FLOOR, 0.2, 2.0 * FLOOR), 1.0)),
            Arc::new(cuboid("plate", Vec3::new(1.0, 0.05, 1.0), 1.0)),
        ],
        materials: vec![Arc::new(white)],
        instances: vec![
            SceneInstance {
                mesh: 0,
                material: 0,
                transform: Mat4::from_translation(Vec3::new(0.0, -0.1, 0.0)),
            },
            SceneInstance {
                mesh: 1,
                material: 0,
                transform: Mat4::from_translation(Vec3::new(0.0, 1.0, 0.0)),
            },
        ],
        cameras: vec![SceneCamera {
            transform: camera_looking_at(EYE, Vec3::ZERO),
            projection: Default::default(),
        }],
        ..Scene::default()
    }
}

/// Which light lights the plate scene.
#[derive(Clone, Copy, Debug)]
enum Kind {
    Point,
    Spot,
    /// Light travelling along [`SUN`].
    Directional,
}

/// Where the directional light travels: down and towards +x, so the plate's shadow (its own
/// size, 1 × 1) falls beside it where the camera sees it.
const SUN: Vec3 = Vec3::new(1.0, -1.0, 0.2);

impl Kind {
    /// The light as the oracle sees it.
    fn source(self) -> LightSource {
        match self {
            Kind::Point | Kind::Spot => LightSource::At(LIGHT),
            Kind::Directional => LightSource::Travelling(SUN),
        }
    }
}

fn render(kind: Kind, shadows: bool, settings: RenderSettings) -> HeadlessFrame {
    render_scene(&plate_scene(), kind.spawn(), shadows, settings)
}

/// Spawns a light, casting or not.
type SpawnLight = fn(&mut Commands, bool);

impl Kind {
    /// The plate scene's light of this kind: at [`LIGHT`], or travelling along [`SUN`].
    fn spawn(self) -> SpawnLight {
        match self {
            Kind::Point => |c, shadows| point_at(c, LIGHT, 8.0, shadows),
            Kind::Spot => |c, shadows| {
                let light = SpotLight {
                    intensity: 150.0,
                    range: 8.0,
                    inner_angle: 0.9,
                    outer_angle: 1.2,
                    shadows_enabled: shadows,
                    ..Default::default()
                };
                c.spawn((Transform::from_translation(LIGHT).looking_to(Vec3::NEG_Y, Vec3::Z), light));
            },
            Kind::Directional => |c, shadows| {
                let light =
                    DirectionalLight { illuminance: 3.0, shadows_enabled: shadows, ..Default::default() };
                c.spawn((Transform::default().looking_to(SUN, Vec3::Z), light));
            },
        }
    }
}

/// `scene` with the light `spawn` makes, through `settings`.
fn render_scene(scene: &Scene, spawn: SpawnLight, shadows: bool, settings: RenderSettings) -> HeadlessFrame {
    let scene = scene.clone();
    let frame = render_headless(SIZE, 1, move |app| {
        app.insert_resource(settings).add_systems(Startup, move |mut commands: Commands| {
            spawn_scene(&mut commands, &scene, true, SIZE.x as f32 / SIZE.y as f32);
            spawn(&mut commands, shadows);
        });
    })
    .unwrap_or_else(|e| panic!("render failed: {e}"));
    support::assert_finite(&frame);
    frame
}

fn luminance(p: &image::Rgba<u8>) -> f32 {
    (0.2126 * p[0] as f32 + 0.7152 * p[1] as f32 + 0.0722 * p[2] as f32) / 255.0
}

/// The floor point each pixel shows (`None` where it shows no floor, or the plate hides it).
fn floor_points(scene: &Scene, occluders: &OccluderSet) -> Vec<Option<(u32, u32, Vec3)>> {
    let camera = scene.cameras[0];
    let clip_from_world =
        camera.projection.matrix(SIZE.x as f32 / SIZE.y as f32) * camera.transform.inverse();
    let world_from_clip = clip_from_world.inverse();
    let mut out = Vec::new();
    for y in 0..SIZE.y {
        for x in 0..SIZE.x {
            let ndc = Vec2::new(
                (x as f32 + 0.5) / SIZE.x as f32 * 2.0 - 1.0,
                1.0 - (y as f32 + 0.5) / SIZE.y as f32 * 2.0,
            );
            let far = world_from_clip.project_point3(ndc.extend(0.5));
            let dir = (far - EYE).normalize();
            let t = -EYE.y / dir.y;
            let p = EYE + dir * t;
            let on_floor = t > 0.0 && p.x.abs() < FLOOR && p.z.abs() < FLOOR;
            // The camera sees the floor there unless the plate is in between.
            let seen = on_floor
                && occluders.visible(&ShadowQuery { point: p, normal: Vec3::Y, light: LightSource::At(EYE) });
            out.push(seen.then_some((x, y, p)));
        }
    }
    out
}

/// Floor pixels where a light adds enough to tell lit from shadowed, against the oracle.
#[derive(Clone, Copy, Debug)]
struct Measured {
    /// Floor pixels the light reaches (unshadowed) by more than 0.05 of luminance.
    pairs: u32,
    /// Of those, the ones the oracle finds blocked.
    blocked: u32,
    /// Of those, the ones whose shadowed image is on the wrong side of half the light.
    wrong: u32,
}

impl Measured {
    fn error(&self) -> f32 {
        self.wrong as f32 / self.pairs.max(1) as f32
    }
}

/// Compares each floor pixel's shadow with the oracle through `scene`'s triangles: shadowed
/// (less than half of the unshadowed light over the ambient) where `source` reaches the point,
/// or lit where it is blocked.
fn measure(
    scene: &Scene,
    source: LightSource,
    shadowed: &HeadlessFrame,
    unshadowed: &HeadlessFrame,
    ambient: &HeadlessFrame,
) -> Measured {
    let occluders = OccluderSet::from_instances(
        scene.instances.iter().map(|i| (scene.meshes[i.mesh].as_ref(), i.transform)),
    );
    let mut m = Measured { pairs: 0, blocked: 0, wrong: 0 };
    for (x, y, p) in floor_points(scene, &occluders).into_iter().flatten() {
        let base = luminance(ambient.image.get_pixel(x, y));
        let light = luminance(unshadowed.image.get_pixel(x, y)) - base;
        if light < 0.05 {
            continue; // the light does not reach the point enough to tell
        }
        let visible = occluders.visible(&ShadowQuery { point: p, normal: Vec3::Y, light: source });
        let got = luminance(shadowed.image.get_pixel(x, y)) - base;
        let lit = got > 0.5 * light;
        m.pairs += 1;
        m.blocked += u32::from(!visible);
        m.wrong += u32::from(lit != visible);
    }
    m
}

/// [`measure`] for the plate scene lit by `kind`, with its umbra checked to be there.
fn visibility_error(
    kind: Kind,
    shadowed: &HeadlessFrame,
    unshadowed: &HeadlessFrame,
    ambient: &HeadlessFrame,
) -> f32 {
    let m = measure(&plate_scene(), kind.source(), shadowed, unshadowed, ambient);
    assert!(m.pairs > 2000, "{kind:?}: too few lit floor pixels ({})", m.pairs);
    // A point light 1 above the plate projects it at twice its size; the sun at its own size.
    let umbra = if let Kind::Directional = kind { 100 } else { 200 };
    assert!(m.blocked > umbra, "{kind:?}: the plate blocks the light from few pixels ({})", m.blocked);
    m.error()
}

#[test]
fn a_plate_shadows_the_floor_where_the_oracle_says_for_every_light_kind() {
    let _gpu = gpu();
    let naive = RenderSettings { pipeline: PipelineKind::NaiveForward, ..RenderSettings::default() };
    let ambient = render_scene(&plate_scene(), |_, _| {}, false, naive);
    for kind in [Kind::Point, Kind::Spot, Kind::Directional] {
        let on = render(kind, true, naive);
        let off = render(kind, false, naive);
        // One light with the largest tile: at most 0.5 % of the pairs on the wrong side.
        let error = visibility_error(kind, &on, &off, &ambient);
        eprintln!("{kind:?}: visibility error {:.3} %", error * 100.0);
        assert!(
            error < 0.005,
            "{kind:?}: {:.2} % of the floor's pixels disagree with the oracle",
            error * 100.0
        );
        // The wider filter softens the edge by a texel: it stays within the same bound.
        let mut gaussian = naive;
        gaussian.shadows.filter = ShadowFilteringMethod::Gaussian;
        let soft = render(kind, true, gaussian);
        let soft_error = visibility_error(kind, &soft, &off, &ambient);
        eprintln!("{kind:?}, Gaussian filter: visibility error {:.3} %", soft_error * 100.0);
        assert!(soft_error < 0.005, "{kind:?}, Gaussian filter: {:.2} % disagree", soft_error * 100.0);
        assert_ne!(soft.image, on.image, "{kind:?}: the filter changes nothing");
        let report = on.stats.last.as_ref().and_then(|r| r.shadows).expect("a shadow report");
        assert_eq!((report.casting_lights, report.maps_rendered, report.dropped_lights), (1, 1, 0));
        let cascades = if let Kind::Directional = kind { 4 } else { 0 };
        assert_eq!(report.cascades_rendered, cascades, "{kind:?}");
        assert!(report.instance_faces >= 2, "the floor and the plate are drawn: {report:?}");
        // Unshadowed, the frame has no shadow pass and no report.
        assert!(off.stats.last.as_ref().is_some_and(|r| r.shadows.is_none()));
        // Rays: exact visibility, hard edges; no shadow pass and no atlas.
        let mut rays = naive;
        rays.shadows.method = ShadowMethod::Rays;
        let traced = render(kind, true, rays);
        let ray_error = visibility_error(kind, &traced, &off, &ambient);
        eprintln!("{kind:?}, rays: visibility error {:.3} %", ray_error * 100.0);
        assert!(ray_error < 0.002, "{kind:?}, rays: {:.2} % disagree", ray_error * 100.0);
        let report = traced.stats.last.as_ref().expect("a report");
        assert!(
            report.shadows.is_none() && !report.passes.iter().any(|p| p.name == "shadow_maps"),
            "{kind:?}"
        );
    }
}

#[test]
fn every_pipeline_gives_naive_forwards_shadowed_image() {
    let _gpu = gpu();
    for method in ShadowMethod::ALL {
        let settings = |pipeline| {
            let mut s = RenderSettings { pipeline, ..RenderSettings::default() };
            s.shadows.method = method;
            s
        };
        let naive = render(Kind::Point, true, settings(PipelineKind::NaiveForward));
        for (name, s) in support::pipelines_besides_naive(&format!("shadows {}", method.name()), settings) {
            let frame = render(Kind::Point, true, s);
            let tolerance = if name.ends_with("compact") { COMPACT } else { STRICT };
            assert_similar(&name, &naive.image, &frame.image, tolerance);
        }
    }
}

#[test]
fn disabled_shadows_give_the_unshadowed_image() {
    let _gpu = gpu();
    let off = render(Kind::Point, false, RenderSettings::default());
    let mut settings = RenderSettings::default();
    settings.shadows.enabled = false;
    let disabled = render(Kind::Point, true, settings);
    assert_eq!(off.image, disabled.image, "a casting light with shadows disabled lights through the plate");
    assert!(disabled.stats.last.as_ref().is_some_and(|r| !r.passes.iter().any(|p| p.name == "shadow_maps")));
}

/// One renderer whose light starts and stops casting between frames: every pass keeps working
/// (the passes sharing the view's bind group follow its layout), and the last frame is the
/// frame a renderer that always cast would give.
#[test]
fn a_light_that_starts_and_stops_casting_renders_every_frame() {
    let _gpu = gpu();
    let scene = plate_scene();
    let settings = RenderSettings::default();
    // Frames: off (spawned), on, off, on.
    let toggled = render_headless(SIZE, 4, move |app| {
        app.insert_resource(settings)
            .add_systems(Startup, move |mut commands: Commands| {
                spawn_scene(&mut commands, &scene, true, SIZE.x as f32 / SIZE.y as f32);
                let light = PointLight { intensity: 150.0, range: 8.0, ..Default::default() };
                commands.spawn((Transform::from_translation(LIGHT), light));
            })
            .add_systems(Update, |mut lights: Query<&mut PointLight>, mut frame: Local<u32>| {
                *frame += 1;
                for mut light in &mut lights {
                    light.shadows_enabled = frame.is_multiple_of(2);
                }
            });
    })
    .unwrap_or_else(|e| panic!("toggling shadows failed: {e}"));
    assert_eq!(toggled.stats.frames_rendered, 4);
    let always = render(Kind::Point, true, settings);
    assert_similar("toggled shadows", &always.image, &toggled.image, STRICT);
}

/// `scene` with the light `spawn` makes, through naive forward, its shadows found by `method`.
fn render_case(scene: &Scene, spawn: SpawnLight, shadows: bool, method: ShadowMethod) -> HeadlessFrame {
    let mut naive = RenderSettings { pipeline: PipelineKind::NaiveForward, ..RenderSettings::default() };
    naive.shadows.method = method;
    render_scene(scene, spawn, shadows, naive)
}

/// A light where shadow maps usually break, checked against the oracle.
struct HardCase {
    name: &'static str,
    scene: Scene,
    spawn: SpawnLight,
    source: LightSource,
    /// The oracle must find at least this many floor pixels blocked (the case has a shadow).
    min_blocked: u32,
    /// Largest fraction of the floor's lit pixels on the wrong side, with shadow maps (rays
    /// are held to [`RAY_MAX_ERROR`]).
    max_error: f32,
}

/// Largest fraction of the floor's lit pixels on the wrong side with shadow rays in any case:
/// the pixels whose segment grazes an edge within rounding.
const RAY_MAX_ERROR: f32 = 0.002;

fn check(case: HardCase) {
    let ambient = render_case(&case.scene, |_, _| {}, false, ShadowMethod::Maps);
    let off = render_case(&case.scene, case.spawn, false, ShadowMethod::Maps);
    for method in ShadowMethod::ALL {
        let on = render_case(&case.scene, case.spawn, true, method);
        let m = measure(&case.scene, case.source, &on, &off, &ambient);
        let name = format!("{}, {}", case.name, method.name());
        eprintln!("{name}: {m:?}, error {:.3} %", m.error() * 100.0);
        assert!(m.pairs > 500, "{name}: the light reaches few floor pixels ({m:?})");
        assert!(m.blocked >= case.min_blocked, "{name}: no shadow to test ({m:?})");
        let max_error = if method == ShadowMethod::Rays { RAY_MAX_ERROR } else { case.max_error };
        assert!(
            m.error() <= max_error,
            "{name}: {:.2} % of the floor's lit pixels disagree with the oracle ({m:?})",
            m.error() * 100.0
        );
    }
}

/// The plate scene with one more instance.
fn plate_scene_with(mesh: MeshData, at: Vec3) -> Scene {
    let mut scene = plate_scene();
    scene.meshes.push(Arc::new(mesh));
    scene.instances.push(SceneInstance {
        mesh: scene.meshes.len() - 1,
        material: 0,
        transform: Mat4::from_translation(at),
    });
    scene
}

fn point_at(commands: &mut Commands, at: Vec3, range: f32, shadows: bool) {
    let light = PointLight { intensity: 150.0, range, shadows_enabled: shadows, ..Default::default() };
    commands.spawn((Transform::from_translation(at), light));
}

#[test]
fn a_light_of_huge_range_keeps_its_shadow() {
    let _gpu = gpu();
    check(HardCase {
        name: "range 10^4",
        scene: plate_scene(),
        spawn: |c, s| point_at(c, LIGHT, 1e4, s),
        source: LightSource::At(LIGHT),
        min_blocked: 200,
        max_error: 0.005,
    });
}

#[test]
fn a_light_inside_a_closed_box_lights_nothing_outside() {
    let _gpu = gpu();
    check(HardCase {
        name: "inside a box",
        scene: plate_scene_with(cuboid("box", Vec3::splat(0.6), 1.0), LIGHT),
        spawn: |c, s| point_at(c, LIGHT, 8.0, s),
        source: LightSource::At(LIGHT),
        min_blocked: 2000,
        max_error: 0.005,
    });
}

#[test]
fn a_light_touching_the_floor_has_neither_acne_nor_detached_shadows() {
    let _gpu = gpu();
    // 2 cm above the floor, a block beside it: the floor is lit at grazing angles and the
    // block's shadow starts at its foot.
    const LOW: Vec3 = Vec3::new(-1.0, 0.02, 0.5);
    check(HardCase {
        name: "touching the floor",
        scene: plate_scene_with(cuboid("block", Vec3::splat(0.3), 1.0), Vec3::new(-0.4, 0.15, 0.5)),
        spawn: |c, s| point_at(c, LOW, 8.0, s),
        source: LightSource::At(LOW),
        min_blocked: 50,
        max_error: 0.02,
    });
}

#[test]
fn a_thin_pole_casts_its_thin_shadow() {
    let _gpu = gpu();
    // A pole 4 cm thick and 1.5 tall beside the plate, lit from above and to the side: its
    // shadow on the floor is a few pixels wide.
    const SIDE: Vec3 = Vec3::new(-2.0, 2.5, 0.5);
    check(HardCase {
        name: "thin pole",
        scene: plate_scene_with(cuboid("pole", Vec3::new(0.04, 1.5, 0.04), 1.0), Vec3::new(-1.2, 0.75, 0.5)),
        spawn: |c, s| point_at(c, SIDE, 10.0, s),
        source: LightSource::At(SIDE),
        min_blocked: 20,
        max_error: 0.01,
    });
}

#[test]
fn a_spot_light_of_nearly_a_hemisphere_shadows_like_a_point_light() {
    let _gpu = gpu();
    check(HardCase {
        name: "spot outer angle 1.55",
        scene: plate_scene(),
        spawn: |c, s| {
            let light = SpotLight {
                intensity: 150.0,
                range: 8.0,
                inner_angle: 1.2,
                outer_angle: 1.55,
                shadows_enabled: s,
                ..Default::default()
            };
            c.spawn((Transform::from_translation(LIGHT).looking_to(Vec3::NEG_Y, Vec3::Z), light));
        },
        source: LightSource::At(LIGHT),
        min_blocked: 200,
        max_error: 0.005,
    });
}

#[test]
fn a_light_at_the_camera_hides_its_shadow_behind_the_plate() {
    let _gpu = gpu();
    check(HardCase {
        name: "light at the camera",
        scene: plate_scene(),
        spawn: |c, s| point_at(c, EYE, 12.0, s),
        source: LightSource::At(EYE),
        min_blocked: 0,
        max_error: 0.005,
    });
}

/// The scene's floor widened to 10⁷ by four slabs around the measured one: the scene's bounds,
/// and with them the depth a cascade would need to reach every caster, grow a million times,
/// while the plate's shadow stays 1 wide. (One triangle 10⁷ wide is a different matter: its
/// depth, interpolated in floats between corners 5·10⁶ away, is off by tenths of a unit in
/// any rasterised shadow map.)
#[test]
fn a_sun_over_a_floor_ten_million_wide_keeps_the_plate_shadow() {
    let _gpu = gpu();
    let mut scene = plate_scene();
    let (half, inner) = (5e6f32, FLOOR);
    let slabs = [
        (Vec3::new(0.0, 0.0, (half + inner) * 0.5), Vec3::new(2.0 * half, 0.2, half - inner)),
        (Vec3::new(0.0, 0.0, -(half + inner) * 0.5), Vec3::new(2.0 * half, 0.2, half - inner)),
        (Vec3::new((half + inner) * 0.5, 0.0, 0.0), Vec3::new(half - inner, 0.2, 2.0 * inner)),
        (Vec3::new(-(half + inner) * 0.5, 0.0, 0.0), Vec3::new(half - inner, 0.2, 2.0 * inner)),
    ];
    for (centre, size) in slabs {
        scene.meshes.push(Arc::new(cuboid("slab", size, 1.0)));
        let mesh = scene.meshes.len() - 1;
        let transform = Mat4::from_translation(centre - Vec3::new(0.0, 0.1, 0.0));
        scene.instances.push(SceneInstance { mesh, material: 0, transform });
    }
    check(HardCase {
        name: "sun over 10^7",
        scene,
        spawn: |c, s| {
            let light = DirectionalLight { illuminance: 3.0, shadows_enabled: s, ..Default::default() };
            c.spawn((Transform::default().looking_to(SUN, Vec3::Z), light));
        },
        source: LightSource::Travelling(SUN),
        min_blocked: 100,
        max_error: 0.005,
    });
}

/// 300 casting lights over the floor (a grid 1 apart, range 3).
fn many_casting_lights() -> Vec<manylight::render::ExtractedPointLight> {
    (0..300)
        .map(|i| manylight::render::ExtractedPointLight {
            position: Vec3::new(
                (i % 20) as f32 * 0.4 - 3.8,
                1.5 + (i / 100) as f32 * 0.3,
                (i / 20 % 5) as f32 - 2.0,
            ),
            color: Vec3::ONE,
            intensity: 1.0,
            radius: 3.0,
            shape: LightShape::Point,
            shadow: Some(manylight::render::ShadowBias::POINT),
            animation: None,
        })
        .collect()
}

/// An atlas too small for the lights: resolutions fall and, at the smallest, lights go without
/// a map — every one counted. A device whose textures are smaller than the atlas asked for
/// caps it, and says so.
#[test]
fn a_full_atlas_and_a_small_device_lower_resolutions_and_count_every_light() {
    let _gpu = gpu();
    let scene = plate_scene();
    let mut settings = manylight::render::FrameSettings::default();
    settings.render.shadows.atlas_size = 256;
    let snapshot = manylight::app::scene::scene_snapshot(&scene, many_casting_lights(), SIZE, settings, 0);
    let mut renderer = manylight::app::render_world::HeadlessRenderer::new().expect("a GPU");
    let (report, image) = renderer.render(snapshot, true).expect("the frame renders");
    let s = report.shadows.expect("a shadow report");
    assert_eq!(s.casting_lights, 300);
    assert_eq!(s.maps_rendered + s.dropped_lights + s.unseen_lights, 300, "{s:?}");
    assert!(s.dropped_lights > 0 && s.maps_rendered > 0, "{s:?}");
    assert_eq!((s.atlas_size, s.atlas_limited_by_device), (256, false), "{s:?}");
    assert!(image.is_some());

    let mut renderer = manylight::app::render_world::HeadlessRenderer::new().expect("a GPU");
    renderer.render_world.renderer_mut().shadows.limit_texture_size(700);
    let snapshot = manylight::app::scene::scene_snapshot(
        &scene,
        many_casting_lights(),
        SIZE,
        manylight::render::FrameSettings::default(),
        0,
    );
    let (report, _) = renderer.render(snapshot, false).expect("the frame renders");
    let s = report.shadows.expect("a shadow report");
    assert_eq!((s.atlas_size, s.atlas_limited_by_device), (512, true), "{s:?}");
    assert_eq!(s.maps_rendered + s.dropped_lights + s.unseen_lights, 300, "{s:?}");
    assert!(s.downgraded_lights > 0, "{s:?}");
}

/// The plate scene's point light through a debug view.
fn debug_frame(mode: DebugViewMode, shadows: bool) -> HeadlessFrame {
    let scene = plate_scene();
    render_headless(SIZE, 1, move |app| {
        app.insert_resource(DebugView::new(mode)).add_systems(Startup, move |mut commands: Commands| {
            spawn_scene(&mut commands, &scene, true, SIZE.x as f32 / SIZE.y as f32);
            point_at(&mut commands, LIGHT, 8.0, shadows);
        });
    })
    .unwrap_or_else(|e| panic!("{mode:?}: {e}"))
}

/// The shadow views show the atlas (its drawn tiles brighter than the cleared rest) and the
/// face edge of the lights reaching each pixel (one light of 512 texels: the hottest colour
/// wherever it reaches); without a map, the background alone.
#[test]
fn the_shadow_debug_views_show_the_atlas_and_the_resolution() {
    let _gpu = gpu();
    let atlas = debug_frame(DebugViewMode::ShadowAtlas, true);
    let bright = atlas.image.pixels().filter(|p| p[0] > 100).count();
    assert!(bright > 100, "the atlas view shows few drawn texels ({bright})");
    let lod = debug_frame(DebugViewMode::ShadowLod, true);
    let red = lod.image.pixels().filter(|p| p[0] > 200 && p[1] < 80 && p[2] < 80).count();
    assert!(red > 2000, "few pixels show the light's 512-texel faces ({red})");
    for mode in [DebugViewMode::ShadowAtlas, DebugViewMode::ShadowLod] {
        let none = debug_frame(mode, false);
        let first = *none.image.get_pixel(0, 0);
        assert!(none.image.pixels().all(|p| *p == first), "{mode:?} without shadows is not the background");
    }
}

/// Three casting lights over the plate scene, each moved `shift` along x: one above the plate
/// (its map holds the plate) and two in far corners whose spheres miss it.
fn three_lights(shift: f32) -> Vec<manylight::render::ExtractedPointLight> {
    [Vec3::new(0.0, 2.0, 0.0), Vec3::new(-3.0, 0.5, -3.0), Vec3::new(3.0, 0.5, -3.0)]
        .into_iter()
        .map(|at| manylight::render::ExtractedPointLight {
            position: at + Vec3::X * shift,
            color: Vec3::ONE,
            intensity: 4.0,
            radius: if at.y > 1.0 { 3.0 } else { 1.0 },
            shape: LightShape::Point,
            shadow: Some(manylight::render::ShadowBias::POINT),
            animation: None,
        })
        .collect()
}

/// One frame of `scene` lit by `lights` on `renderer`: its shadow report and image.
fn frame_of(
    renderer: &mut manylight::app::render_world::HeadlessRenderer,
    scene: &Scene,
    lights: Vec<manylight::render::ExtractedPointLight>,
    settings: manylight::render::FrameSettings,
    frame: u64,
) -> (manylight::render::ShadowReport, image::RgbaImage) {
    let snapshot = manylight::app::scene::scene_snapshot(scene, lights, SIZE, settings, frame);
    let (report, image) = renderer.render(snapshot, true).expect("the frame renders");
    (report.shadows.expect("a shadow report"), image.expect("the image"))
}

/// The image of `scene` lit by `lights` from a renderer of its own, every map drawn.
fn drawn_anew(scene: &Scene, lights: Vec<manylight::render::ExtractedPointLight>) -> image::RgbaImage {
    let mut renderer = manylight::app::render_world::HeadlessRenderer::new().expect("a GPU");
    let mut settings = manylight::render::FrameSettings::default();
    settings.render.shadows.cache_maps = false;
    frame_of(&mut renderer, scene, lights, settings, 0).1
}

/// Still lights keep their maps (no draw, the same image); a caster that moves draws again only
/// the map it is in, and the frame is the one every map drawn anew gives.
#[test]
fn still_lights_keep_their_maps_and_a_moving_caster_redraws_only_its_light() {
    let _gpu = gpu();
    let scene = plate_scene();
    let settings = manylight::render::FrameSettings::default();
    let mut renderer = manylight::app::render_world::HeadlessRenderer::new().expect("a GPU");
    let (first, first_image) = frame_of(&mut renderer, &scene, three_lights(0.0), settings, 0);
    assert_eq!((first.maps_rendered, first.maps_cached, first.unseen_lights), (3, 0, 0), "{first:?}");
    let (second, second_image) = frame_of(&mut renderer, &scene, three_lights(0.0), settings, 1);
    assert_eq!((second.maps_rendered, second.maps_cached, second.instance_faces), (0, 3, 0), "{second:?}");
    assert_eq!(first_image, second_image, "cached maps change the image");

    let mut moved = scene.clone();
    moved.instances[1].transform = Mat4::from_translation(Vec3::new(0.3, 1.0, 0.0));
    let (third, third_image) = frame_of(&mut renderer, &moved, three_lights(0.0), settings, 2);
    assert_eq!((third.maps_rendered, third.maps_cached, third.maps_stale), (1, 2, 0), "{third:?}");
    assert_similar("cached_maps_moved_plate", &drawn_anew(&moved, three_lights(0.0)), &third_image, STRICT);
}

/// Past the redraw budget, changed maps keep an earlier frame's map, counted (new lights are
/// drawn whatever the budget); once the lights stop, every map is drawn again within as many
/// frames as it takes, and the frame is the one every map drawn anew gives.
#[test]
fn a_redraw_budget_keeps_the_rest_stale_and_catches_up() {
    let _gpu = gpu();
    let scene = plate_scene();
    let mut settings = manylight::render::FrameSettings::default();
    settings.render.shadows.max_redrawn_maps = Some(1);
    let mut renderer = manylight::app::render_world::HeadlessRenderer::new().expect("a GPU");
    let counts = |s: manylight::render::ShadowReport| (s.maps_rendered, s.maps_cached, s.maps_stale);
    let mut frame = |shift: f32, f: u64| frame_of(&mut renderer, &scene, three_lights(shift), settings, f);
    assert_eq!(counts(frame(0.0, 0).0), (3, 0, 0));
    assert_eq!(counts(frame(0.1, 1).0), (1, 0, 2));
    assert_eq!(counts(frame(0.1, 2).0), (1, 1, 1));
    assert_eq!(counts(frame(0.1, 3).0), (1, 2, 0));
    let (last, image) = frame(0.1, 4);
    assert_eq!(counts(last), (0, 3, 0));
    assert_similar("redraw_budget_caught_up", &drawn_anew(&scene, three_lights(0.1)), &image, STRICT);
}

/// The plate scene seen by two cameras side by side (the same camera, each half the width),
/// lit by the casting point light, each camera with its shadows checkbox as given.
fn two_cameras(left: bool, right: bool) -> HeadlessFrame {
    let half = UVec2::new(SIZE.x / 2, SIZE.y);
    let frame = render_headless(SIZE, 1, move |app| {
        app.add_systems(Startup, move |mut commands: Commands| {
            spawn_scene(&mut commands, &plate_scene(), false, 1.0);
            point_at(&mut commands, LIGHT, 8.0, true);
            for (x, shadows) in [(0, left), (half.x, right)] {
                let viewport = Viewport { physical_position: UVec2::new(x, 0), physical_size: half };
                commands.spawn((
                    Transform::from_matrix(camera_looking_at(EYE, Vec3::ZERO)),
                    Camera3d,
                    Camera { viewport: Some(viewport), order: x as isize, ..default() },
                    CameraShadows { enabled: shadows },
                ));
            }
        });
    })
    .unwrap_or_else(|e| panic!("render failed: {e}"));
    support::assert_finite(&frame);
    frame
}

/// Each camera has its own shadows checkbox: the camera whose box is off shades unshadowed and
/// the other keeps its shadows (the maps drawn once for the frame); with every box off the
/// frame draws no map.
#[test]
fn each_camera_has_its_own_shadows_checkbox() {
    let _gpu = gpu();
    let half = |frame: &HeadlessFrame, right: bool| {
        let x = if right { SIZE.x / 2 } else { 0 };
        image::imageops::crop_imm(&frame.image, x, 0, SIZE.x / 2, SIZE.y).to_image()
    };
    let both = two_cameras(true, true);
    let mixed = two_cameras(true, false);
    let none = two_cameras(false, false);
    assert_eq!(half(&both, false), half(&both, true), "the two cameras see the same image");
    assert_eq!(half(&mixed, false), half(&both, false), "the camera with shadows lost them");
    assert_eq!(half(&mixed, true), half(&none, true), "the camera without shadows shades with them");
    assert_ne!(half(&mixed, true), half(&mixed, false), "the plate casts no shadow");
    let report = |f: &HeadlessFrame| f.stats.last.clone().expect("a report");
    let mixed_shadows = report(&mixed).shadows.expect("a shadow report");
    assert_eq!(mixed_shadows.maps_rendered, 1, "{mixed_shadows:?}");
    assert!(report(&none).shadows.is_none() && !report(&none).passes.iter().any(|p| p.name == "shadow_maps"));
}

/// A thousand casting lights moving every frame: every light is counted every frame (drawn,
/// kept, kept stale, left out or unseen), the redraw budget holds, and the frame stays close to
/// the one every map drawn anew gives.
#[test]
fn a_thousand_moving_shadowed_lights_are_all_accounted_for() {
    let _gpu = gpu();
    let scene = plate_scene();
    let lights = |shift: f32| -> Vec<manylight::render::ExtractedPointLight> {
        (0..1000)
            .map(|i| manylight::render::ExtractedPointLight {
                position: Vec3::new(
                    (i % 40) as f32 * 0.2 - 3.9 + shift,
                    1.3 + (i / 400) as f32 * 0.4,
                    (i / 40 % 10) as f32 * 0.8 - 3.6,
                ),
                color: Vec3::ONE,
                intensity: 0.05,
                radius: 2.0,
                shape: LightShape::Point,
                shadow: Some(manylight::render::ShadowBias::POINT),
                animation: None,
            })
            .collect()
    };
    let settings = manylight::render::FrameSettings::default();
    let budget = settings.render.shadows.max_redrawn_maps.expect("a default budget");
    let mut renderer = manylight::app::render_world::HeadlessRenderer::new().expect("a GPU");
    let mut last = None;
    for f in 0..4u64 {
        let (s, image) = frame_of(&mut renderer, &scene, lights(f as f32 * 0.02), settings, f);
        let counted = s.maps_rendered + s.maps_cached + s.maps_stale + s.dropped_lights + s.unseen_lights;
        assert_eq!((s.casting_lights, counted), (1000, 1000), "frame {f}: {s:?}");
        // Past the first frame the budget's maps are drawn, and the few lights whose block
        // changed with their size (they have no map to keep).
        if f > 0 {
            assert!(s.maps_rendered >= budget && s.maps_rendered < budget + 50, "frame {f}: {s:?}");
            assert!(s.maps_stale > 0, "frame {f}: {s:?}");
        }
        last = Some(image);
    }
    let fresh = drawn_anew(&scene, lights(0.06));
    assert_similar("thousand_moving_lights", &fresh, &last.expect("frames"), COMPACT);
}
