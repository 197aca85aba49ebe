//! How far a frame's shadows are from exact visibility (`render --shadow-oracle`,
//! `bench --shadow-oracle`).
//!
//! 1. The frame's exact per-pixel light lists come from the light-list oracle
//!    ([`oracle_snapshot`]), whose render also leaves the frame's shadow atlas on the renderer.
//! 2. Each pixel's surface is found by casting its camera ray into the scene's triangles
//!    ([`OccluderSet::first_hit`]): a point and a geometric normal facing the camera.
//! 3. For each light of the pixel's list, the ray-cast oracle decides whether anything blocks
//!    the segment to the light ([`OccluderSet::visibility`]), and the GPU evaluates the
//!    shading passes' own shadow test there ([`manylight_render::Renderer::probe_shadows`]).
//! 4. The **visibility error** is the mean of `|test − exact|` over the contributing pairs (the
//!    light reaches the point: inside its range, in front of the surface, inside a spot's
//!    cone): a filtered test half-lit at a lit pair counts one half.
//! 5. The **shadow reference image** is the light-list oracle with every blocked pair removed
//!    from its lists and no point or spot light's shadow map: naive forward's image with exact
//!    visibility. The frame is compared with it by FLIP. Directional lights are not measured:
//!    the reference keeps the frame's cascades, and a scene lit only by directional lights
//!    has no pairs to measure (its error is 0 over 0 pairs).
//! 6. The **light error** is `Σ |shadowed − reference| / Σ unshadowed` over the pixels' Rec. 709
//!    luminance in HDR (linear radiance before exposure and tone mapping;
//!    [`manylight_core::image_metrics::light_error`]): the measured frame, the shadow
//!    reference, and the frame with shadows disabled (the render the oracle's lists come from).
//!    Unlike the visibility error it weighs each pair by the light it carries and needs nothing
//!    of the technique but its image, so it measures any shadow technique alike.
//! 7. The **flicker** is the renderer's next frame of the same still scene (camera, lights and
//!    the animation clock unchanged, the frame index one on) against the measured frame:
//!    `mean |next − measured| / mean next` of their HDR luminance
//!    ([`manylight_core::image_metrics::flicker`]). Shadow maps are deterministic (0); a
//!    stochastic technique's noise that changes from frame to frame shows here.

use crate::direct::oracle_snapshot;
use anyhow::{Context, Result};
use glam::{Mat4, UVec2, Vec2};
use manylight_app::render_world::HeadlessRenderer;
use manylight_core::AlphaMode;
use manylight_core::cluster::ClusterAssignment;
use manylight_core::image_metrics::{FlipStats, flicker, flip_compare, light_error, luminance_rgba_f16};
use manylight_core::shadow_oracle::{LightSource, OccluderSet, ShadowQuery, SurfaceHit};
use manylight_render::shadow_probe::ShadowProbe;
use manylight_render::{ExtractedPointLight, FrameSnapshot};
use manylight_scene::Scene;
use rayon::prelude::*;
use std::sync::Arc;

/// A frame's shadows measured against exact visibility.
pub struct ShadowAccuracy {
    /// Light–pixel pairs where the light reaches the surface (the error's denominator).
    pub contributing_pairs: u64,
    /// Of those, the pairs the oracle finds blocked.
    pub blocked_pairs: u64,
    /// Mean `|shadow test − exact visibility|` over the contributing pairs, in [0, 1].
    pub visibility_error: f64,
    /// Contributing pairs whose test is on the wrong side of one half.
    pub wrong_pairs: u64,
    /// Segments the oracle cast (every listed pair with a surface, reached or not).
    pub rays: u64,
    /// Wall time of casting them against the BVH on every core: what ray-traced shadows
    /// would cost this frame on this CPU.
    pub ray_cast_ms: f64,
    /// The part of `visibility_error` from pairs the light reaches but the test shadows
    /// (acne, over-wide filtering), over all contributing pairs.
    pub false_shadow: f64,
    /// The part of `visibility_error` from blocked pairs the test lights (light leaks,
    /// peter-panning, lights without a map).
    pub light_leak: f64,
    /// FLIP of the frame against the shadow reference.
    pub flip: FlipStats,
    /// `Σ |shadowed − reference| / Σ unshadowed` of the HDR luminance (see the module's
    /// step 6): 0 is exact visibility; infinite only when the unshadowed frame is black and the
    /// frame is not.
    pub light_error: f64,
    /// `mean |next frame − frame| / mean next frame` of the HDR luminance with nothing moving
    /// (step 7): 0 for a deterministic technique.
    pub flicker: f64,
    /// The shadow reference image.
    pub reference: image::RgbaImage,
}

/// The opaque triangles of `scene` in world space: what casts shadows (blended materials cast
/// none, as in the shadow pass).
pub fn occluders(scene: &Scene) -> OccluderSet {
    OccluderSet::from_instances(
        scene
            .instances
            .iter()
            .filter(|i| scene.materials.get(i.material).is_none_or(|m| m.alpha_mode != AlphaMode::Blend))
            .map(|i| (scene.meshes[i.mesh].as_ref(), i.transform)),
    )
}

/// Measures `snapshot`'s frame (a snapshot of `scene`, as rendered by its pipeline and shadow
/// settings) against exact visibility through `occluders` (see the module's steps).
pub fn measure_shadows(
    renderer: &mut HeadlessRenderer,
    snapshot: FrameSnapshot,
    occluders: &OccluderSet,
) -> Result<ShadowAccuracy> {
    // The measuring frames keep their HDR images readable; the renderer's frames after them
    // are ordinary again, whether the measurement succeeded or not.
    renderer.render_world.renderer_mut().set_hdr_readback(true);
    let measured = measure_with_hdr(renderer, snapshot, occluders);
    renderer.render_world.renderer_mut().set_hdr_readback(false);
    measured
}

/// The per-pixel HDR luminance of the renderer's last frame (rendered with its HDR read-back
/// on).
fn hdr_luminance(renderer: &HeadlessRenderer, what: &str) -> Result<Vec<f32>> {
    let (_, _, rgba) = renderer
        .render_world
        .renderer()
        .read_hdr()?
        .with_context(|| format!("the {what} has no HDR image to measure"))?;
    Ok(luminance_rgba_f16(&rgba)?)
}

/// [`measure_shadows`] on a renderer whose frames keep their HDR images readable.
fn measure_with_hdr(
    renderer: &mut HeadlessRenderer,
    snapshot: FrameSnapshot,
    occluders: &OccluderSet,
) -> Result<ShadowAccuracy> {
    let camera = *snapshot.camera().context("the frame has no camera to measure")?;
    let size = snapshot.viewport.max(UVec2::ONE);
    // The oracle's lists come from a render without shadows (its depth is the same), so the
    // atlas and light table the probes read are the measured frame's: the frame after the
    // renderer's last one, as the caching and the redraw budget left it.
    let mut unshadowed = snapshot.clone();
    unshadowed.settings.shadows.enabled = false;
    // `oracle_snapshot` renders the unshadowed frame (by the oracle's pipeline: clustered
    // forward or deferred) when it has a point or spot light to list; without one it renders
    // nothing, and the unshadowed frame is rendered here.
    let lists_rendered = manylight_render::lights::buffered_lights(&unshadowed.lights).next().is_some();
    let (oracle, _) = oracle_snapshot(renderer, unshadowed.clone())?;
    if !lists_rendered {
        renderer.render(unshadowed, false)?;
    }
    let unshadowed_light = hdr_luminance(renderer, "unshadowed frame")?;
    let (_, frame) = renderer.render(snapshot.clone(), true)?;
    let image = frame.context("the frame was not read back")?;
    let shadowed_light = hdr_luminance(renderer, "frame")?;
    let lists = oracle.pixel_light_lists.clone().context("the oracle made no lists")?;
    let lights: Vec<&ExtractedPointLight> =
        manylight_render::lights::buffered_lights(&snapshot.lights).map(|(_, l)| l).collect();

    let world_from_clip =
        camera.world_from_view * camera.projection.matrix(size.x as f32 / size.y as f32).inverse();
    let surfaces = pixel_surfaces(&world_from_clip, size, &lists, occluders);
    let pairs = light_pairs(&surfaces, &lists, &lights);
    let cast = std::time::Instant::now();
    let visible = occluders.visibility(&pairs.queries);
    let ray_cast_ms = cast.elapsed().as_secs_f64() * 1e3;
    let probe_inputs: Vec<ShadowProbe> = (pairs.entries.iter())
        .zip(&pairs.queries)
        .filter(|((_, reaches), _)| *reaches)
        .map(|((entry, _), q)| ShadowProbe {
            position: q.point,
            normal: q.normal,
            light: lists.indices[*entry as usize],
        })
        .collect();
    let tested = renderer.render_world.renderer().probe_shadows(&probe_inputs)?;
    // The renderer's next frame, right after the measured one (the probes above read the
    // measured frame's atlas): the same still scene, the animation clock unchanged.
    let mut next = snapshot.clone();
    next.frame_index += 1;
    renderer.render(next, false)?;
    let flicker = flicker(&hdr_luminance(renderer, "next frame")?, &shadowed_light)?;
    let exact: Vec<bool> =
        pairs.entries.iter().zip(&visible).filter(|((_, reaches), _)| *reaches).map(|(_, &v)| v).collect();
    let errors = test_errors(&tested, &exact);
    let contributing_pairs = exact.len() as u64;
    let blocked_pairs = exact.iter().filter(|&&v| !v).count() as u64;

    let reference =
        shadow_reference(renderer, oracle, snapshot.settings.shadows, &lists, &pairs.entries, &visible)?;
    let light_error =
        light_error(&shadowed_light, &hdr_luminance(renderer, "shadow reference")?, &unshadowed_light)?;
    let (flip, _) =
        flip_compare(reference.dimensions(), reference.as_raw(), image.dimensions(), image.as_raw())?;
    let per_pair = |sum: f64| if contributing_pairs == 0 { 0.0 } else { sum / contributing_pairs as f64 };
    Ok(ShadowAccuracy {
        contributing_pairs,
        blocked_pairs,
        visibility_error: per_pair(errors.false_shadow + errors.light_leak),
        wrong_pairs: errors.wrong,
        rays: pairs.queries.len() as u64,
        ray_cast_ms,
        false_shadow: per_pair(errors.false_shadow),
        light_leak: per_pair(errors.light_leak),
        flip,
        light_error,
        flicker,
        reference,
    })
}

/// The surface under each pixel of a `size` frame whose list in `lists` is not empty: the
/// first hit of its camera ray (through `world_from_clip`) in `occluders`.
fn pixel_surfaces(
    world_from_clip: &Mat4,
    size: UVec2,
    lists: &ClusterAssignment,
    occluders: &OccluderSet,
) -> Vec<Option<SurfaceHit>> {
    (0..size.x * size.y)
        .into_par_iter()
        .map(|i| {
            let [_, count] = lists.ranges.get(i as usize).copied().unwrap_or_default();
            if count == 0 {
                return None;
            }
            pixel_surface(world_from_clip, size, i, occluders)
        })
        .collect()
}

/// The surface under pixel `i` (row-major) of a `size` frame: the first hit of the camera ray
/// through its centre (through `world_from_clip`) in `occluders`.
pub(crate) fn pixel_surface(
    world_from_clip: &Mat4,
    size: UVec2,
    i: u32,
    occluders: &OccluderSet,
) -> Option<SurfaceHit> {
    let (x, y) = (i % size.x, i / size.x);
    let ndc =
        Vec2::new((x as f32 + 0.5) / size.x as f32 * 2.0 - 1.0, 1.0 - (y as f32 + 0.5) / size.y as f32 * 2.0);
    // Reverse-Z: 1 is the near plane.
    let near = world_from_clip.project_point3(ndc.extend(1.0));
    let further = world_from_clip.project_point3(ndc.extend(0.5));
    occluders.first_hit(near, further - near)
}

/// The (pixel, light) entries of the oracle's lists whose pixel has a surface.
struct LightPairs {
    /// Each entry's index into the lists' `indices`, and whether its light reaches the surface
    /// ([`reaches`]).
    entries: Vec<(u32, bool)>,
    /// The segment from each entry's surface to its light.
    queries: Vec<ShadowQuery>,
}

/// Every (pixel, light) entry of `lists` with a surface in `surfaces` (`lights` by their
/// index in the light buffer), and whether the light reaches it.
fn light_pairs(
    surfaces: &[Option<SurfaceHit>],
    lists: &ClusterAssignment,
    lights: &[&ExtractedPointLight],
) -> LightPairs {
    let mut entries = Vec::new();
    let mut queries = Vec::new();
    for (pixel, surface) in surfaces.iter().enumerate() {
        let Some(s) = surface else { continue };
        let [offset, count] = lists.ranges[pixel];
        for entry in offset..offset + count {
            let k = lists.indices[entry as usize];
            let Some(light) = lights.get(k as usize) else { continue };
            entries.push((entry, reaches(light, s)));
            queries.push(ShadowQuery {
                point: s.point,
                normal: s.normal,
                light: LightSource::At(light.position),
            });
        }
    }
    LightPairs { entries, queries }
}

/// How far the shadow tests are from exact visibility, summed over the contributing pairs.
struct TestErrors {
    /// `1 - test` over the pairs the light reaches.
    false_shadow: f64,
    /// `test` over the blocked pairs.
    light_leak: f64,
    /// Pairs whose test is on the wrong side of one half.
    wrong: u64,
}

/// The errors of the shadow tests `tested` (1: lit) against `exact` visibility, pair by pair.
fn test_errors(tested: &[f32], exact: &[bool]) -> TestErrors {
    let (mut false_shadow, mut light_leak, mut wrong) = (0.0f64, 0.0f64, 0u64);
    for (&test, &lit) in tested.iter().zip(exact) {
        let e = if lit { 1.0 - f64::from(test) } else { f64::from(test) };
        if lit {
            false_shadow += e;
        } else {
            light_leak += e;
        }
        wrong += u64::from(e > 0.5);
    }
    TestErrors { false_shadow, light_leak, wrong }
}

/// Renders the shadow reference: the `oracle` snapshot's `lists` without the blocked pairs
/// (`entries` whose segment is not `visible`) and no point or spot light's shadow map.
/// Directional lights keep the measured frame's cascades (`shadows`): the oracle measures
/// point and spot lights, so the reference differs from the frame only in their shadows.
fn shadow_reference(
    renderer: &mut HeadlessRenderer,
    oracle: FrameSnapshot,
    shadows: manylight_render::ShadowSettings,
    lists: &ClusterAssignment,
    entries: &[(u32, bool)],
    visible: &[bool],
) -> Result<image::RgbaImage> {
    let blocked: Vec<u32> =
        entries.iter().zip(visible).filter(|(_, v)| !**v).map(|((entry, _), _)| *entry).collect();
    let mut reference_snapshot = oracle;
    reference_snapshot.settings.shadows = shadows;
    reference_snapshot
        .lights
        .update(|light| *light = manylight_app::scene::with_shadow(light.clone(), false));
    reference_snapshot.pixel_light_lists = Some(Arc::new(without_entries(lists, &blocked)));
    let (_, reference) = renderer.render(reference_snapshot, true)?;
    reference.context("the reference was not read back")
}

/// True when `light` sends light to the surface at `s`: in front of it and, for a spot light,
/// inside its cone (the lists hold only lights whose range reaches the point).
fn reaches(light: &ExtractedPointLight, s: &SurfaceHit) -> bool {
    let to_light = light.position - s.point;
    if to_light.dot(s.normal) <= 0.0 {
        return false;
    }
    light.shape.attenuation(-to_light) > 0.0
}

/// `lists` without the entries (indices into `lists.indices`, ascending) in `removed`.
fn without_entries(lists: &ClusterAssignment, removed: &[u32]) -> ClusterAssignment {
    let mut ranges = Vec::with_capacity(lists.ranges.len());
    let mut indices = Vec::with_capacity(lists.indices.len() - removed.len().min(lists.indices.len()));
    let mut next = removed.iter().peekable();
    for &[offset, count] in &lists.ranges {
        let start = indices.len() as u32;
        for entry in offset..offset + count {
            if next.peek() == Some(&&entry) {
                next.next();
                continue;
            }
            indices.push(lists.indices[entry as usize]);
        }
        ranges.push([start, indices.len() as u32 - start]);
    }
    ClusterAssignment { ranges, indices, dropped_pairs: 0, clusters_overflowed: 0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat4, UVec2, Vec3};
    use manylight_render::{ExtractedPointLight, FrameSettings, PipelineKind, ShadowBias};
    use manylight_scene::{SceneCamera, SceneInstance, camera_looking_at, shapes::cuboid};

    /// A floor under a camera and four lights above it: nothing stands between a light and a
    /// surface.
    fn open_floor() -> (Scene, Vec<ExtractedPointLight>) {
        let grey = manylight_core::MaterialData {
            base_color: manylight_core::Color::linear_rgb(0.7, 0.7, 0.7),
            ..Default::default()
        };
        let scene = Scene {
            name: "floor".into(),
            meshes: vec![std::sync::Arc::new(cuboid("floor", Vec3::new(8.0, 0.2, 8.0), 1.0))],
            materials: vec![std::sync::Arc::new(grey)],
            instances: vec![SceneInstance {
                mesh: 0,
                material: 0,
                transform: Mat4::from_translation(Vec3::new(0.0, -0.1, 0.0)),
            }],
            cameras: vec![SceneCamera {
                transform: camera_looking_at(Vec3::new(0.0, 4.0, 4.0), Vec3::ZERO),
                projection: Default::default(),
            }],
            ..Scene::default()
        };
        let lights = [(-1.5, -1.0), (1.5, -1.0), (0.0, 1.0), (0.5, 0.0)]
            .map(|(x, z)| ExtractedPointLight {
                position: Vec3::new(x, 1.0, z),
                color: Vec3::ONE,
                intensity: 2.0,
                radius: 4.0,
                shape: manylight_core::LightShape::Point,
                shadow: Some(ShadowBias::POINT),
                animation: None,
            })
            .to_vec();
        (scene, lights)
    }

    /// Where nothing occludes, the shadow reference is naive forward's image, shadow maps make
    /// no pair wrong, and nothing is blocked.
    #[test]
    fn the_shadow_reference_equals_naive_forward_where_nothing_occludes() {
        let (scene, lights) = open_floor();
        let occluders = occluders(&scene);
        let mut settings = FrameSettings::default();
        settings.render.pipeline = PipelineKind::NaiveForward;
        let size = UVec2::new(128, 96);
        let mut renderer = HeadlessRenderer::new().expect("a GPU adapter (lavapipe in CI)");
        for shadows in [false, true] {
            settings.render.shadows.enabled = shadows;
            let snapshot = manylight_app::scene::scene_snapshot(&scene, lights.clone(), size, settings, 0);
            let a = measure_shadows(&mut renderer, snapshot, &occluders).expect("measured");
            assert!(a.contributing_pairs > 10_000, "{}", a.contributing_pairs);
            assert_eq!(a.blocked_pairs, 0, "shadows {shadows}");
            assert!(a.visibility_error < 1e-3, "shadows {shadows}: {}", a.visibility_error);
            assert!(a.flip.mean < 0.002, "shadows {shadows}: FLIP {}", a.flip.mean);
            assert!(a.light_error < 1e-3, "shadows {shadows}: light error {}", a.light_error);
            // Deterministic frames (0 on lavapipe); light lists in another order on another
            // device round sums differently, far below this.
            assert!(a.flicker < 1e-4, "shadows {shadows}: flicker {}", a.flicker);
        }
    }

    /// The HDR image the measures read is the one the tone map shows: tone mapped on the CPU
    /// it is the read-back frame within the rounding of the sRGB encoding; an ordinary frame's
    /// HDR image cannot be read.
    #[test]
    fn the_hdr_read_back_is_what_the_tone_map_shows() {
        let (scene, lights) = open_floor();
        let size = UVec2::new(128, 96);
        let snapshot =
            manylight_app::scene::scene_snapshot(&scene, lights, size, FrameSettings::default(), 0);
        let exposure = snapshot.render_view(0).exposure();
        let mut renderer = HeadlessRenderer::new().expect("a GPU adapter (lavapipe in CI)");
        renderer.render_world.renderer_mut().set_hdr_readback(true);
        let (_, image) = renderer.render(snapshot.clone(), true).expect("rendered");
        let image = image.expect("read back");
        let (w, h, rgba) = renderer.render_world.renderer().read_hdr().expect("read").expect("an HDR image");
        assert_eq!((w, h), size.into());
        let mut worst = 0u8;
        for (hdr, ldr) in rgba.chunks_exact(4).zip(image.pixels()) {
            let [r, g, b, _] =
                [hdr[0], hdr[1], hdr[2], hdr[3]].map(manylight_core::image_metrics::f16_to_f32);
            let shown = manylight_core::tonemap::tonemap_to_srgb8(Vec3::new(r, g, b), exposure);
            for c in 0..3 {
                worst = worst.max(shown[c].abs_diff(ldr[c]));
            }
        }
        assert!(worst <= 1, "the CPU tone map of the HDR image is {worst} steps from the frame");
        let lit = luminance_rgba_f16(&rgba).expect("RGBA").iter().filter(|&&l| l > 0.01).count();
        assert!(lit > (w * h / 2) as usize, "{lit} lit pixels of {}", w * h);

        renderer.render_world.renderer_mut().set_hdr_readback(false);
        renderer.render(snapshot, false).expect("rendered");
        assert!(renderer.render_world.renderer().read_hdr().is_err(), "an ordinary frame's HDR image");
    }

    #[test]
    fn removing_entries_keeps_the_others_in_order() {
        let lists = ClusterAssignment {
            ranges: vec![[0, 2], [2, 0], [2, 3]],
            indices: vec![7, 8, 1, 2, 3],
            dropped_pairs: 0,
            clusters_overflowed: 0,
        };
        let cut = without_entries(&lists, &[1, 3]);
        assert_eq!(cut.ranges, vec![[0, 1], [1, 0], [1, 2]]);
        assert_eq!(cut.indices, vec![7, 1, 3]);
        assert_eq!(without_entries(&lists, &[]).indices, lists.indices);
    }
}
