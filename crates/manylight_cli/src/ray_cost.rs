//! What tracing shadow rays through the scene's two-level BVH costs (`manylight shadow-rays`):
//! building each level (time, bytes, depth), and rays per second on the GPU
//! (`shaders/common/ray_bvh.wgsl`), on the CPU twin of that traversal and on the CPU oracle
//! (`obvhs`), for the rays a frame would trace: from each pixel's surface to `k` of the lights
//! that reach it.
//!
//! 1. Each pixel's surface is the first hit of its camera ray in the scene's opaque triangles.
//! 2. The lights are the animated rig of `bench` (`light_rig` over the scene's bounds), where
//!    they are at time 0. A light reaches a surface when the surface lies inside its range and
//!    in front of the surface; a uniform grid of cells the size of the lights' diameter finds
//!    them.
//! 3. Each pixel traces `k` of those lights' segments, picked by a hash of the pixel and the
//!    sample (all of them when fewer reach it): the segments of `ShadowQuery::segment`, as the
//!    oracle casts them.

use crate::bench::median;
use crate::shadow_error::{occluders, pixel_surface};
use anyhow::{Context, Result, bail};
use glam::{IVec3, Mat4, UVec2, Vec3};
use manylight_core::ray_bvh::{self, MeshSlot, RayOutcome, Traced};
use manylight_core::shadow_oracle::{LightSource, OccluderSet, ShadowQuery, SurfaceHit};
use manylight_render::GpuContext;
use manylight_render::ray_geometry::{RayGeometry, RayGeometryReport, RaySegment, trace_segments};
use manylight_scene::{Scene, SplitMix64, light_rig};
use rayon::prelude::*;
use std::collections::HashMap;
use std::time::Instant;

/// What to measure.
pub struct Options {
    /// The scene (`default`, `sphere-shell` or a glTF path).
    pub scene: String,
    /// Rig lights.
    pub lights: usize,
    /// Pixels across and down.
    pub size: UVec2,
    /// Rays a pixel, one row each.
    pub rays_per_pixel: Vec<u32>,
    /// Seed of the light rig.
    pub seed: u64,
    /// Timed repetitions of each GPU trace and of each instance-level build (medians).
    pub repeats: u32,
}

/// One row: the rays of `k` a pixel.
pub struct Row {
    /// Rays a pixel asked for.
    pub rays_per_pixel: u32,
    /// Segments traced (pixels with fewer reaching lights trace fewer).
    pub segments: usize,
    /// Median wall time of the GPU trace, ms.
    pub gpu_ms: f64,
    /// CPU twin's time on every core, ms.
    pub twin_ms: f64,
    /// The oracle's time on every core, ms.
    pub oracle_ms: f64,
    /// Mean and largest steps a GPU ray took.
    pub mean_steps: f64,
    /// Largest steps.
    pub max_steps: u32,
    /// Rays that stopped before an answer (step budget or stack).
    pub stopped: usize,
    /// Rays blocked.
    pub blocked: usize,
    /// Rays whose GPU answer differs from the oracle's.
    pub oracle_disagreements: usize,
}

/// The whole measurement.
pub struct Measurement {
    /// The scene's name.
    pub scene: String,
    /// The adapter.
    pub adapter: String,
    /// Both levels' sizes and build times.
    pub geometry: RayGeometryReport,
    /// Median time of building the instance level again (what a frame with moved instances pays).
    pub instance_rebuild_ms: f64,
    /// Pixels with a surface.
    pub surfaces: usize,
    /// Mean lights reaching a surface.
    pub mean_reaching: f64,
    /// One row a rays-per-pixel setting.
    pub rows: Vec<Row>,
}

/// Runs the measurement (see the module's steps).
pub fn measure(options: &Options) -> Result<Measurement> {
    if options.size.x == 0 || options.size.y == 0 {
        bail!("--size {}x{} has no pixel", options.size.x, options.size.y);
    }
    if options.rays_per_pixel.is_empty() || options.rays_per_pixel.contains(&0) {
        bail!("--rays-per-pixel needs one or more counts of at least 1");
    }
    let scene = manylight_scene::load_scene(&options.scene, &Default::default())
        .with_context(|| format!("cannot load scene {}", options.scene))?;
    let gpu = GpuContext::headless().context("no GPU adapter")?;
    let occluders = occluders(&scene);
    let surfaces = pixel_surfaces(&scene, options.size, &occluders);
    let rig = light_rig(options.lights, scene.bounds(), options.seed)?;
    let lights: Vec<(Vec3, f32)> = rig.iter().map(|l| (l.position_at(0.0), l.radius)).collect();
    let grid = LightGrid::new(&lights);
    let reaching: Vec<Vec<u32>> =
        surfaces.par_iter().map(|s| s.map(|s| grid.reaching(&lights, &s)).unwrap_or_default()).collect();
    let with_surface = surfaces.iter().filter(|s| s.is_some()).count();
    let mean_reaching = reaching.iter().map(Vec::len).sum::<usize>() as f64 / with_surface.max(1) as f64;

    let (mut geometry, slots) = build_geometry(&scene);
    let placed = placement(&scene, &slots);
    geometry.place(placed.iter().copied());
    geometry.upload(&gpu);
    let rebuilds: Vec<f64> = (0..options.repeats.max(1))
        .map(|_| {
            geometry.place(placed.iter().copied());
            geometry.report().instance_build_ms
        })
        .collect();
    let instance_rebuild_ms = median(&rebuilds);
    let mut nodes = Vec::new();
    let mut rows = Vec::new();
    for &k in &options.rays_per_pixel {
        let queries = pixel_queries(&surfaces, &reaching, &lights, k);
        let segments: Vec<RaySegment> = queries
            .iter()
            .filter_map(|q| q.segment())
            .map(|(origin, direction, t_max)| RaySegment { origin, direction, t_max })
            .collect();
        let mut times = Vec::new();
        let mut traced = Vec::new();
        for _ in 0..options.repeats.max(1) {
            let run = trace_segments(&gpu, &geometry, &segments)?;
            times.push(run.gpu_time.as_secs_f64() * 1e3);
            traced = run.traced;
        }
        let cpu = geometry.cpu_scene(&mut nodes);
        let start = Instant::now();
        let twin: Vec<Traced> =
            segments.par_iter().map(|s| ray_bvh::trace(&cpu, s.origin, s.direction, s.t_max)).collect();
        let twin_ms = start.elapsed().as_secs_f64() * 1e3;
        let with_segment: Vec<ShadowQuery> = queries.into_iter().filter(|q| q.segment().is_some()).collect();
        let start = Instant::now();
        let exact = occluders.visibility(&with_segment);
        let oracle_ms = start.elapsed().as_secs_f64() * 1e3;
        debug_assert_eq!(twin.len(), traced.len());
        rows.push(Row {
            rays_per_pixel: k,
            segments: segments.len(),
            gpu_ms: median(&times),
            twin_ms,
            oracle_ms,
            mean_steps: traced.iter().map(|t| f64::from(t.steps)).sum::<f64>() / traced.len().max(1) as f64,
            max_steps: traced.iter().map(|t| t.steps).max().unwrap_or(0),
            stopped: traced
                .iter()
                .filter(|t| !matches!(t.outcome, RayOutcome::Visible | RayOutcome::Blocked))
                .count(),
            blocked: traced.iter().filter(|t| t.outcome == RayOutcome::Blocked).count(),
            oracle_disagreements: traced.iter().zip(&exact).filter(|(t, v)| t.outcome.lit() != **v).count(),
        });
    }
    Ok(Measurement {
        scene: scene.name.clone(),
        adapter: gpu.info.name.clone(),
        geometry: geometry.report(),
        instance_rebuild_ms,
        surfaces: with_surface,
        mean_reaching,
        rows,
    })
}

/// The geometry of every mesh of `scene`, and each mesh's slot.
fn build_geometry(scene: &Scene) -> (RayGeometry, Vec<MeshSlot>) {
    let mut geometry = RayGeometry::new();
    let slots = scene.meshes.iter().map(|m| geometry.add_mesh(m)).collect();
    (geometry, slots)
}

/// The opaque instances (what casts shadows) as slots and transforms.
fn placement(scene: &Scene, slots: &[MeshSlot]) -> Vec<(MeshSlot, Mat4)> {
    scene
        .instances
        .iter()
        .filter(|i| {
            scene.materials.get(i.material).is_none_or(|m| m.alpha_mode != manylight_core::AlphaMode::Blend)
        })
        .filter_map(|i| Some((*slots.get(i.mesh)?, i.transform)))
        .collect()
}

/// The surface under each pixel's centre (`None` where the camera ray meets nothing).
fn pixel_surfaces(scene: &Scene, size: UVec2, occluders: &OccluderSet) -> Vec<Option<SurfaceHit>> {
    let aspect = size.x as f32 / size.y as f32;
    let camera = scene.camera_or_fit(aspect);
    let world_from_clip = camera.transform * camera.projection.matrix(aspect).inverse();
    (0..size.x * size.y)
        .into_par_iter()
        .map(|i| pixel_surface(&world_from_clip, size, i, occluders))
        .collect()
}

/// Light–surface pairs: `k` of each pixel's reaching lights, picked by a hash of the pixel and
/// the sample.
fn pixel_queries(
    surfaces: &[Option<SurfaceHit>],
    reaching: &[Vec<u32>],
    lights: &[(Vec3, f32)],
    k: u32,
) -> Vec<ShadowQuery> {
    let mut out = Vec::new();
    for (pixel, (surface, list)) in surfaces.iter().zip(reaching).enumerate() {
        let Some(surface) = surface else { continue };
        if list.is_empty() {
            continue;
        }
        let picks = (k as usize).min(list.len());
        for sample in 0..picks {
            let index = if picks == list.len() {
                sample
            } else {
                (SplitMix64((pixel as u64) << 8 | sample as u64).next_u64() % list.len() as u64) as usize
            };
            let (position, _) = lights[list[index] as usize];
            out.push(ShadowQuery {
                point: surface.point,
                normal: surface.normal,
                light: LightSource::At(position),
            });
        }
    }
    out
}

/// Lights in a uniform grid of cells one largest diameter wide: a light's sphere touches at
/// most the eight cells around its centre's nearest cell corner.
struct LightGrid {
    cell: f32,
    cells: HashMap<IVec3, Vec<u32>>,
}

impl LightGrid {
    fn new(lights: &[(Vec3, f32)]) -> LightGrid {
        let cell = lights.iter().map(|l| l.1 * 2.0).fold(1e-3f32, f32::max);
        let mut cells: HashMap<IVec3, Vec<u32>> = HashMap::new();
        for (i, &(p, r)) in lights.iter().enumerate() {
            let lo = ((p - r) / cell).floor().as_ivec3();
            let hi = ((p + r) / cell).floor().as_ivec3();
            for x in lo.x..=hi.x {
                for y in lo.y..=hi.y {
                    for z in lo.z..=hi.z {
                        cells.entry(IVec3::new(x, y, z)).or_default().push(i as u32);
                    }
                }
            }
        }
        LightGrid { cell, cells }
    }

    /// Lights whose range holds the surface point, in front of the surface.
    fn reaching(&self, lights: &[(Vec3, f32)], surface: &SurfaceHit) -> Vec<u32> {
        let key = (surface.point / self.cell).floor().as_ivec3();
        let Some(candidates) = self.cells.get(&key) else { return Vec::new() };
        candidates
            .iter()
            .copied()
            .filter(|&i| {
                let (p, r) = lights[i as usize];
                let to = p - surface.point;
                to.length_squared() < r * r && to.dot(surface.normal) > 0.0
            })
            .collect()
    }
}

/// The measurement as markdown: the geometry, then one row a rays-per-pixel setting.
pub fn markdown(m: &Measurement) -> String {
    let g = &m.geometry;
    let mut s = format!(
        "Scene `{}` on {}: {} surfaces, {:.1} lights reaching each on average.\n\n\
         | level | count | triangles | build ms | bytes | depth |\n|---|---:|---:|---:|---:|---:|\n\
         | meshes | {} | {} | {:.1} | {} | |\n\
         | instances | {} | | {:.2} (again: {:.2}) | {} | {} (stack {} of {}) |\n\n",
        m.scene,
        m.adapter,
        m.surfaces,
        m.mean_reaching,
        g.meshes,
        g.triangles,
        g.mesh_build_ms,
        g.mesh_level_bytes,
        g.instances,
        g.instance_build_ms,
        m.instance_rebuild_ms,
        g.instance_level_bytes,
        g.instance_depth,
        g.stack_needed,
        ray_bvh::RAY_STACK_SIZE,
    );
    s.push_str(
        "| rays a pixel | segments | GPU ms | GPU Mrays/s | CPU twin Mrays/s | oracle Mrays/s | mean steps | max steps | stopped | blocked | ≠ oracle |\n\
         |---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let rate = |n: usize, ms: f64| if ms > 0.0 { n as f64 / ms / 1e3 } else { 0.0 };
    for r in &m.rows {
        s.push_str(&format!(
            "| {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {} | {} | {:.1} % | {} |\n",
            r.rays_per_pixel,
            r.segments,
            r.gpu_ms,
            rate(r.segments, r.gpu_ms),
            rate(r.segments, r.twin_ms),
            rate(r.segments, r.oracle_ms),
            r.mean_steps,
            r.max_steps,
            r.stopped,
            100.0 * r.blocked as f64 / r.segments.max(1) as f64,
            r.oracle_disagreements,
        ));
    }
    s
}
