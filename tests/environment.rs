//! Image-based lighting: every pipeline and G-buffer layout adds the same environment term as
//! naive forward, each shading model takes it without a NaN, the skybox fills what no surface
//! covers, and a camera without an environment runs no environment pass.

mod support;

use glam::Vec3;
use manylight::app::RenderSettings;
use manylight::app::headless::{HeadlessFrame, render_headless};
use manylight::math::environment::EquirectImage;
use manylight::math::{Projection, ShadingModel};
use manylight::prelude::*;
use manylight::render::EnvironmentFilter;
use manylight::scene::shapes::SphereGrid;
use manylight::scene::{SceneCamera, SceneLight, camera_looking_at};
use support::{STRICT, assert_finite, assert_similar, gpu};

const SIZE: UVec2 = UVec2::new(192, 96);
const ROUGHNESS: [f32; 4] = [0.05, 0.3, 0.6, 1.0];
const METALLIC: [f32; 2] = [1.0, 0.0];

/// A small filter keeps the tests quick on a CPU rasteriser; the accuracy of the full one is
/// `manylight report`'s.
const FILTER: EnvironmentFilter =
    EnvironmentFilter { cube_size: 64, samples: 64, irradiance_size: 16, lut_size: 32 };

/// A panorama with features a reflection shows: a blue sky brightening to the horizon, a
/// brown ground, a small bright sun and a red band on one side.
fn panorama() -> EquirectImage {
    let (width, height) = (128u32, 64u32);
    let mut texels = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let v = (y as f32 + 0.5) / height as f32;
            let u = (x as f32 + 0.5) / width as f32;
            let mut c = if v < 0.5 {
                let t = v * 2.0;
                [0.2 + 0.6 * t, 0.4 + 0.5 * t, 1.0]
            } else {
                [0.35, 0.22, 0.1]
            };
            if (0.6..0.66).contains(&u) {
                c = [2.0, 0.1, 0.1];
            }
            if (0.28..0.31).contains(&u) && (0.2..0.25).contains(&v) {
                c = [60.0, 55.0, 45.0];
            }
            texels.push(c);
        }
    }
    EquirectImage { width, height, texels }
}

const RADIUS: f32 = 0.42;
const EYE: Vec3 = Vec3::new(0.0, 0.0, 6.0);
const FOV_Y: f32 = 0.5;
const ALBEDO: Vec3 = Vec3::new(0.9, 0.7, 0.5);

fn grid() -> SphereGrid {
    SphereGrid {
        radius: RADIUS,
        rings: 48,
        segments: 96,
        albedo: ALBEDO,
        metallic: METALLIC.to_vec(),
        roughness: ROUGHNESS.to_vec(),
    }
}

fn centre(row: usize, column: usize) -> Vec3 {
    grid().centre(row, column)
}

/// A panorama of broad features only (sky gradient, ground, coloured quadrants), so the
/// split-sum's GPU and CPU estimates agree texel for texel without a sharp feature that
/// sampling resolves differently.
fn smooth_panorama() -> EquirectImage {
    EquirectImage::from_fn(128, 64, |d| {
        let sky = 0.3 + 0.7 * d.y.max(0.0);
        let side = if d.x > 0.0 { [1.0, 0.6, 0.3] } else { [0.3, 0.6, 1.0] };
        let front = if d.z < 0.0 { 1.0 } else { 0.5 };
        if d.y >= 0.0 {
            [sky * side[0] * front, sky * side[1] * front, sky * side[2] * front]
        } else {
            [0.3 * front, 0.2 * front, 0.1]
        }
    })
}

/// Eight spheres: metals on the top row, dielectrics below, roughness rising to the right,
/// one weak point light, nothing else.
fn spheres() -> Scene {
    let mut scene = grid().scene("environment spheres");
    scene.lights.push(SceneLight {
        position: Vec3::new(2.0, 2.0, 3.0),
        color: Vec3::ONE,
        intensity: 5.0,
        radius: 30.0,
        shape: manylight::math::LightShape::Point,
    });
    scene.cameras.push(SceneCamera {
        transform: camera_looking_at(EYE, Vec3::ZERO),
        projection: Projection::perspective(FOV_Y, 0.1, 100.0),
    });
    scene
}

fn settings(pipeline: PipelineKind) -> RenderSettings {
    RenderSettings {
        pipeline,
        shading: ShadingModel::Pbr,
        ambient: 0.0,
        clear_color: [0.0; 3],
        environment_filter: FILTER,
        ..RenderSettings::default()
    }
}

/// What the camera carries.
#[derive(Clone, Copy, PartialEq)]
enum Environment {
    None,
    Light,
    LightAndSkybox,
}

/// Renders the spheres with the panorama on the camera as `environment` says.
fn render(settings: RenderSettings, environment: Environment) -> HeadlessFrame {
    render_with(spheres(), panorama(), settings, environment)
}

fn render_with(
    scene: Scene,
    panorama: EquirectImage,
    settings: RenderSettings,
    environment: Environment,
) -> HeadlessFrame {
    let mut images = EnvironmentImages::default();
    let image = images.add(panorama);
    render_camera(scene, images, settings, move |camera| {
        if environment != Environment::None {
            camera.insert(EnvironmentMapLight::new(image));
        }
        if environment == Environment::LightAndSkybox {
            camera.insert(Skybox::new(image));
        }
    })
}

/// Renders `scene` through its camera, with `images` as the app's panoramas and what `camera`
/// puts on the camera entity; panics on failure or a NaN pixel.
fn render_camera(
    scene: Scene,
    images: EnvironmentImages,
    settings: RenderSettings,
    camera: impl Fn(&mut EntityCommands) + Send + Sync + 'static,
) -> HeadlessFrame {
    let aspect = SIZE.x as f32 / SIZE.y as f32;
    let frame = render_headless(SIZE, 1, move |app| {
        app.insert_resource(images).insert_resource(settings).add_systems(
            Startup,
            move |mut commands: Commands| {
                spawn_scene(&mut commands, &scene, true, aspect);
            },
        );
        app.add_systems(
            PostStartup,
            move |mut commands: Commands, cameras: Query<Entity, With<Camera3d>>| {
                for entity in &cameras {
                    camera(&mut commands.entity(entity));
                }
            },
        );
    })
    .unwrap_or_else(|e| panic!("render failed: {e}"));
    assert_finite(&frame);
    frame
}

fn pass_names(frame: &HeadlessFrame) -> Vec<String> {
    frame.stats.last.as_ref().expect("a report").passes.iter().map(|p| p.name.clone()).collect()
}

/// Every pipeline and G-buffer layout adds the environment as naive forward does (the same
/// thresholds as without one), and the environment shows: the image is not the one without it.
#[test]
fn every_pipeline_matches_naive_forward_with_an_environment() {
    let _gpu = gpu();
    let naive = render(settings(PipelineKind::NaiveForward), Environment::LightAndSkybox);
    let _ = naive.image.save(support::output_dir().join("environment_spheres.png"));
    let plain = render(settings(PipelineKind::NaiveForward), Environment::None);
    let shown = support::flip(&plain.image, &naive.image);
    assert!(shown.mean > 0.05, "the environment changes little: {shown:?}");
    for (name, s) in support::pipelines_besides_naive("environment", settings) {
        let frame = render(s, Environment::LightAndSkybox);
        let stats = assert_similar(&name, &naive.image, &frame.image, STRICT);
        eprintln!("{name}: {stats:?}");
    }
}

/// Lambert, Blinn-Phong and toon take the environment in their own way in forward and deferred
/// alike, with no NaN.
#[test]
fn every_shading_model_takes_the_environment() {
    let _gpu = gpu();
    for shading in [ShadingModel::Lambert, ShadingModel::BlinnPhong, ShadingModel::Toon] {
        let with = |pipeline| RenderSettings { shading, ..settings(pipeline) };
        let naive = render(with(PipelineKind::NaiveForward), Environment::Light);
        let plain = render(with(PipelineKind::NaiveForward), Environment::None);
        let shown = support::flip(&plain.image, &naive.image);
        assert!(shown.mean > 0.02, "{shading:?}: the environment changes little: {shown:?}");
        let deferred = render(with(PipelineKind::ClusteredDeferred), Environment::Light);
        let name = format!("environment_{}_deferred", shading.name());
        assert_similar(&name, &naive.image, &deferred.image, STRICT);
    }
}

/// The environment's passes and bindings come only with a camera that names one: without,
/// the pass list is today's; a skybox adds its one pass.
#[test]
fn only_a_camera_with_an_environment_gets_its_passes() {
    let _gpu = gpu();
    let plain = render(settings(PipelineKind::ClusteredForward), Environment::None);
    let light = render(settings(PipelineKind::ClusteredForward), Environment::Light);
    let sky = render(settings(PipelineKind::ClusteredForward), Environment::LightAndSkybox);
    assert_eq!(pass_names(&plain), pass_names(&light));
    let report = |f: &HeadlessFrame| f.stats.last.as_ref().expect("a report").environment;
    assert_eq!(report(&plain), None, "a frame without an environment reports none");
    let named = report(&light).expect("the environment's report");
    assert_eq!((named.prefiltered, named.missing, named.resident), (1, 0, 1));
    let skybox = "skybox".to_string();
    assert!(!pass_names(&light).contains(&skybox));
    let with_sky: Vec<_> = pass_names(&sky).into_iter().filter(|p| *p != skybox).collect();
    assert_eq!(with_sky, pass_names(&plain));
    assert!(pass_names(&sky).contains(&skybox));
    // The skybox fills the background: the corner shows the panorama's sky, not black.
    let corner = sky.image.get_pixel(2, 2);
    assert!(corner[2] > 100, "the skybox's corner is {corner:?}");
    assert_eq!(plain.image.get_pixel(2, 2)[2], 0);
}

/// The spheres ray-cast at each pixel centre, lit by the panorama through the CPU twin of the
/// split-sum (`manylight::math::environment::split_sum`), the background the panorama itself.
fn split_sum_twin(panorama: &EquirectImage) -> image::RgbaImage {
    use manylight::math::environment::split_sum::{SplitSumSamples, split_sum_radiance};
    use manylight::math::environment::{PbrSurface, sample_equirect};
    let aspect = SIZE.x as f32 / SIZE.y as f32;
    let world_from_clip = (Projection::perspective(FOV_Y, 0.1, 100.0).matrix(aspect)
        * camera_looking_at(EYE, Vec3::ZERO).inverse())
    .inverse();
    let samples = SplitSumSamples { lut: 256, specular: 256, irradiance: 256 };
    let spheres = grid();
    image::RgbaImage::from_fn(SIZE.x, SIZE.y, |x, y| {
        let ndc = Vec3::new(
            (x as f32 + 0.5) / SIZE.x as f32 * 2.0 - 1.0,
            1.0 - (y as f32 + 0.5) / SIZE.y as f32 * 2.0,
            0.5,
        );
        let p = world_from_clip * ndc.extend(1.0);
        let dir = (p.truncate() / p.w - EYE).normalize();
        let hit = spheres.hit(EYE, dir);
        let hdr = match hit {
            None => sample_equirect(panorama, dir),
            Some((t, row, column)) => {
                let p = EYE + dir * t;
                let n = (p - centre(row, column)).normalize();
                let surface =
                    PbrSurface { albedo: ALBEDO, metallic: METALLIC[row], roughness: ROUGHNESS[column] };
                split_sum_radiance(panorama, n, -dir, &surface, samples)
            }
        };
        image::Rgba(manylight::math::tonemap::tonemap_to_srgb8(hdr, 1.0))
    })
}

/// The GPU's prefiltered cubes and lookup table give what the CPU twin integrates from the
/// panorama directly: the cube faces, the panorama's mapping and the table's axes are where
/// the twin puts them (mean FLIP <= 0.02; the 99th percentile allows the sphere outlines).
#[test]
fn gpu_split_sum_matches_its_cpu_twin() {
    let _gpu = gpu();
    let mut scene = spheres();
    scene.lights.clear();
    let filter = EnvironmentFilter { cube_size: 128, samples: 256, irradiance_size: 32, lut_size: 64 };
    let s = RenderSettings { environment_filter: filter, ..settings(PipelineKind::NaiveForward) };
    let frame = render_with(scene, smooth_panorama(), s, Environment::LightAndSkybox);
    let twin = split_sum_twin(&smooth_panorama());
    let _ = twin.save(support::output_dir().join("environment_split_sum_twin.png"));
    let stats = assert_similar(
        "environment_split_sum_twin",
        &twin,
        &frame.image,
        support::Tolerance { mean: 0.02, p99: 0.15 },
    );
    eprintln!("split-sum against its CPU twin: {stats:?}");
}

/// A camera naming a panorama no `EnvironmentImages` holds (removed, or never added) draws
/// without it, and the frame counts it: no error, no NaN.
#[test]
fn a_missing_panorama_is_counted_and_drawn_without() {
    let _gpu = gpu();
    let mut images = EnvironmentImages::default();
    let gone = images.add(panorama());
    images.remove(gone);
    let frame = render_camera(spheres(), images, settings(PipelineKind::ClusteredDeferred), move |camera| {
        camera.insert((EnvironmentMapLight::new(gone), Skybox::new(gone)));
    });
    let report = frame.stats.last.as_ref().expect("a report").environment.expect("the environment's report");
    assert_eq!((report.prefiltered, report.resident), (0, 0));
    assert!(report.missing >= 1, "{report:?}");
}
