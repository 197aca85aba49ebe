//! The metallic-roughness model on the GPU against its CPU twin: a grid of spheres of known
//! metallic and roughness under point lights, a spot light and a directional light, rendered by naive forward and by a CPU ray
//! caster that shades with `manylight_core::brdf` and tone-maps with
//! `manylight_core::tonemap`; then every other pipeline and G-buffer layout against naive
//! forward on the same spheres.

mod support;

use glam::Vec3;
use image::RgbaImage;
use manylight::app::RenderSettings;
use manylight::math::LightShape;
use manylight::math::brdf::{PointLightSample, SurfaceParams, shade_directional_light, shade_point_light};
use manylight::math::tonemap::tonemap_to_srgb8;
use manylight::math::{Projection, ShadingModel, SpotCone};
use manylight::prelude::*;
use manylight::scene::shapes::SphereGrid;
use manylight::scene::{SceneCamera, SceneDirectionalLight, SceneLight, camera_looking_at};
use support::{STRICT, Tolerance, assert_similar, gpu, render_scene};

const SIZE: UVec2 = UVec2::new(256, 128);
const SPHERE_RADIUS: f32 = 0.42;
const ROUGHNESS: [f32; 5] = [0.08, 0.25, 0.5, 0.75, 1.0];
const METALLIC: [f32; 2] = [1.0, 0.0];
const BASE_COLOR: Vec3 = Vec3::new(0.95, 0.64, 0.32);
const AMBIENT: f32 = 0.03;
const EYE: Vec3 = Vec3::new(0.0, 0.0, 7.0);
const FOV_Y: f32 = 0.5;

/// The tolerance of the GPU image against the CPU twin (the mean is the acceptance figure;
/// the 99th percentile allows the sphere outlines, where the mesh's polygon meets the exact
/// circle).
const TWIN: Tolerance = Tolerance { mean: 0.01, p99: 0.05 };

fn grid() -> SphereGrid {
    SphereGrid {
        radius: SPHERE_RADIUS,
        rings: 96,
        segments: 192,
        albedo: BASE_COLOR,
        metallic: METALLIC.to_vec(),
        roughness: ROUGHNESS.to_vec(),
    }
}

fn centre(row: usize, column: usize) -> Vec3 {
    grid().centre(row, column)
}

fn lights() -> Vec<SceneLight> {
    vec![
        SceneLight {
            position: Vec3::new(2.5, 2.0, 3.5),
            color: Vec3::ONE,
            intensity: 30.0,
            radius: 40.0,
            shape: LightShape::Point,
        },
        SceneLight {
            position: Vec3::new(-3.0, 1.0, 3.0),
            color: Vec3::new(1.0, 0.7, 0.4),
            intensity: 15.0,
            radius: 40.0,
            shape: LightShape::Point,
        },
        // A spot from below and to the left, its cone's edge falling across the middle of
        // the grid, so both the full-strength core and the falloff show.
        SceneLight {
            position: Vec3::new(-1.0, -2.5, 2.0),
            color: Vec3::new(0.4, 0.6, 1.0),
            intensity: 40.0,
            radius: 40.0,
            shape: LightShape::Spot(SpotCone {
                direction: (Vec3::new(-1.0, 0.0, 0.0) - Vec3::new(-1.0, -2.5, 2.0)).normalize(),
                inner_angle: 0.25,
                outer_angle: 0.45,
            }),
        },
    ]
}

/// A directional light from the upper right, behind the camera.
fn sun() -> SceneDirectionalLight {
    SceneDirectionalLight {
        direction: Vec3::new(-0.4, -0.6, -1.0).normalize(),
        color: Vec3::new(1.0, 0.95, 0.85),
        illuminance: 1.5,
    }
}

/// Ten spheres: metals on the top row, dielectrics below, roughness rising to the right.
fn spheres() -> Scene {
    let mut scene = grid().scene("pbr spheres");
    scene.lights = lights();
    scene.directional_lights = vec![sun()];
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
        ambient: AMBIENT,
        clear_color: [0.0; 3],
        exposure: 1.0,
        ..RenderSettings::default()
    }
}

/// The spheres ray-cast at each pixel centre and shaded by the CPU twin.
fn cpu_twin(scene_lights: &[SceneLight]) -> RgbaImage {
    let aspect = SIZE.x as f32 / SIZE.y as f32;
    let clip_from_world = Projection::perspective(FOV_Y, 0.1, 100.0).matrix(aspect)
        * camera_looking_at(EYE, Vec3::ZERO).inverse();
    let world_from_clip = clip_from_world.inverse();
    let unproject = |ndc: Vec3| {
        let p = world_from_clip * ndc.extend(1.0);
        p.truncate() / p.w
    };
    let lights: Vec<PointLightSample> = scene_lights
        .iter()
        .map(|l| match &l.shape {
            LightShape::Spot(cone) => {
                PointLightSample::spot(l.position, l.radius, l.color * l.intensity, cone)
            }
            LightShape::Point => PointLightSample::point(l.position, l.radius, l.color * l.intensity),
        })
        .collect();
    let spheres = grid();
    RgbaImage::from_fn(SIZE.x, SIZE.y, |x, y| {
        let ndc = Vec3::new(
            (x as f32 + 0.5) / SIZE.x as f32 * 2.0 - 1.0,
            1.0 - (y as f32 + 0.5) / SIZE.y as f32 * 2.0,
            0.5,
        );
        let dir = (unproject(ndc) - EYE).normalize();
        let hit = spheres.hit(EYE, dir);
        let hdr = match hit {
            None => Vec3::ZERO,
            Some((t, row, column)) => {
                let p = EYE + dir * t;
                let s = SurfaceParams {
                    albedo: BASE_COLOR,
                    normal: (p - centre(row, column)).normalize(),
                    shininess: 32.0,
                    specular: 0.25,
                    metallic: METALLIC[row],
                    roughness: ROUGHNESS[column],
                    model: ShadingModel::Pbr,
                };
                let view_dir = (EYE - p).normalize();
                let mut c = BASE_COLOR * AMBIENT;
                let sun = sun();
                c += shade_directional_light(&s, sun.direction, view_dir, sun.color * sun.illuminance);
                for l in &lights {
                    c += shade_point_light(&s, p, view_dir, l);
                }
                c
            }
        };
        image::Rgba(tonemap_to_srgb8(hdr, 1.0))
    })
}

/// Naive forward's metallic-roughness spheres equal the CPU twin's (FLIP mean <= 0.01), and
/// the image shows what the parameters mean: metals take the base colour into their
/// highlights, rough surfaces spread them.
#[test]
fn pbr_spheres_match_the_cpu_twin() {
    let _gpu = gpu();
    let frame = render_scene(spheres(), SIZE, 0, settings(PipelineKind::NaiveForward));
    let twin = cpu_twin(&lights());
    // The spot's cone shows: the same light shining in every direction gives another image.
    let unbounded: Vec<SceneLight> =
        lights().into_iter().map(|l| SceneLight { shape: LightShape::Point, ..l }).collect();
    let cone = support::flip(&twin, &cpu_twin(&unbounded));
    assert!(cone.mean > 0.01, "the spot light's cone changes little: {cone:?}");
    let _ = frame.image.save(support::output_dir().join("pbr_spheres.png"));
    let stats = assert_similar("pbr_spheres_cpu_twin", &twin, &frame.image, TWIN);
    eprintln!("pbr spheres against the CPU twin: {stats:?}");
    // Not a flat image: the smooth metal's highlight is far brighter than the rough one's.
    let peak = |column: usize| {
        let c = centre(0, column);
        let half = (SPHERE_RADIUS * SIZE.y as f32 / (2.0 * EYE.z * (FOV_Y * 0.5).tan())) as i32;
        let cx = ((c.x / (EYE.z * (FOV_Y * 0.5).tan() * 2.0)) * SIZE.y as f32 + SIZE.x as f32 * 0.5) as i32;
        let cy = (SIZE.y as f32 * 0.5 - c.y / (EYE.z * (FOV_Y * 0.5).tan() * 2.0) * SIZE.y as f32) as i32;
        let mut best = 0u8;
        for y in (cy - half).max(0)..(cy + half).min(SIZE.y as i32) {
            for x in (cx - half).max(0)..(cx + half).min(SIZE.x as i32) {
                best = best.max(frame.image.get_pixel(x as u32, y as u32)[1]);
            }
        }
        best
    };
    assert!(peak(0) > peak(4).saturating_add(40), "smooth metal peak {} vs rough {}", peak(0), peak(4));
}

/// Every pipeline and G-buffer layout shades the metallic-roughness spheres as naive forward.
#[test]
fn every_pipeline_matches_naive_forward_with_pbr() {
    let _gpu = gpu();
    let naive = render_scene(spheres(), SIZE, 0, settings(PipelineKind::NaiveForward));
    let variants = support::pipelines_besides_naive("pbr", settings);
    for (name, s) in variants {
        let frame = render_scene(spheres(), SIZE, 0, s);
        let stats = assert_similar(&name, &naive.image, &frame.image, STRICT);
        eprintln!("{name}: {stats:?}");
    }
}
