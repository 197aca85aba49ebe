//! Shadows of point and spot lights: one depth atlas holds a cube of six square face tiles for
//! every casting light, each light's tile edge chosen every frame from the size of its sphere on
//! screen under the atlas's room.
//!
//! Per frame ([`ShadowResources::prepare`], once whatever the views):
//! 1. every valid light with a [`ShadowBias`](crate::snapshot::ShadowBias) asks for a face edge
//!    ([`requested_edge`]): its sphere's projected radius in pixels times
//!    [`ShadowSettings::resolution_scale`], as a power of two in
//!    [`ShadowSettings::min_face_size`]..=[`ShadowSettings::max_face_size`];
//! 2. [`plan_atlas`] packs the blocks (3 × 2 tiles) in rows, largest first; when they do not fit,
//!    every edge halves until they do (the room left goes back to the lights largest on
//!    screen), and at the smallest edge the least important
//!    lights (smallest on screen) go without a shadow: both are counted
//!    ([`ShadowReport::downgraded_lights`], [`ShadowReport::dropped_lights`]), never silent;
//! 3. each opaque instance whose bounds meet a light's sphere is drawn into each face whose
//!    frustum its bounds meet: one instanced draw per mesh for all the pairs
//!    (`passes::shadow_maps`), so a thousand lights are a few dozen draw calls;
//! 4. the shading passes read the light's face at the shaded point with a 2×2 comparison filter
//!    (`shaders/common/shadows.wgsl`).
//!
//! A frame without a casting light has no atlas, no shadow pass and no shadow binding: the
//! shaders are composed without `SHADOWS` ([`crate::shaders::ShaderDefs`]).

use crate::atlas::BlockAllocator;
use crate::context::{GpuContext, RenderError};
use crate::gpu_types::{
    GpuCascade, GpuDirectionalShadow, GpuShadowDraw, GpuShadowFace, GpuShadowLight, MAX_DIRECTIONAL_LIGHTS,
    SHADOW_FACES, SHADOW_TILE_COLUMNS,
};
use crate::lights::{bounding_sphere, viewed_directional_lights};
use crate::pool::GrowableBuffer;
use crate::resources::SceneResources;
use crate::snapshot::{ExtractedCamera, ExtractedDirectionalLight, FrameSnapshot, PointLights};
use glam::{Mat4, UVec2, Vec3, Vec4};
use manylight_core::{Aabb, ProjectionKind};
use std::collections::HashMap;
use std::hash::{DefaultHasher, Hash, Hasher};
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

/// Depth format of the shadow atlas.
pub const SHADOW_ATLAS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Face rows of a light's block of tiles.
pub const SHADOW_TILE_ROWS: u32 = SHADOW_FACES / SHADOW_TILE_COLUMNS;

/// The faces' near plane as a fraction of the light's range (a point nearer the light than
/// that is never shadowed). Reverse depth keeps float precision at every distance, so the
/// near plane can sit this close: 0.1 mm for a range of 10, 10 cm for a range of 10⁴.
pub const SHADOW_NEAR_FRACTION: f32 = 1e-5;

/// The smallest atlas edge: an atlas grows from it in powers of two as the lights ask.
pub const MIN_ATLAS_SIZE: u32 = 256;

pub use crate::settings::{ShadowReport, ShadowSettings};

/// The depth face `f` stores at distance `depth` along its axis: reverse depth, 1 at `near`,
/// 0 at `far`, so a float keeps its precision out to the range (`shadow_face_depth` in
/// `shaders/common/shadows.wgsl`). The atlas is cleared to 0 and keeps the greatest depth
/// (the nearest caster); a point is lit where its depth is at least the stored one.
pub fn face_depth(depth: f32, near: f32, far: f32) -> f32 {
    near * (far - depth) / (depth * (far - near))
}

/// Axis (0 = x) and direction (+1 or -1) face `face` looks along.
pub fn face_axis(face: u32) -> (usize, f32) {
    ((face / 2) as usize % 3, if face.is_multiple_of(2) { 1.0 } else { -1.0 })
}

/// The projection of cube face `face` of a light at `light`: x and y are the coordinates on the
/// next two axes (x on axis + 1, y on axis + 2, modulo 3) over the distance along the face's
/// axis, so the face is x, y ∈ [-w, w]; z / w is [`face_depth`].
pub fn face_clip_from_world(light: Vec3, face: u32, near: f32, far: f32) -> Mat4 {
    let (axis, sign) = face_axis(face);
    let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
    let row = |i: usize, s: f32| (Vec3::AXES[i] * s).extend(-s * light[i]);
    let w = row(axis, sign);
    let k = near / (far - near);
    let z = Vec4::W * (k * far) - w * k;
    Mat4::from_cols(row(a, 1.0), row(b, 1.0), z, w).transpose()
}

/// The atlas transform of a tile at texel (`x`, `y`) with edge `edge` in an atlas `atlas`
/// texels wide: (sx, ox, sy, oy) of [`GpuShadowFace::atlas`].
pub fn tile_transform(x: u32, y: u32, edge: u32, atlas: u32) -> [f32; 4] {
    let (a, e) = (atlas as f32, edge as f32);
    [e / a, (2.0 * x as f32 + e) / a - 1.0, e / a, 1.0 - (2.0 * y as f32 + e) / a]
}

/// The radius in pixels of the sphere (`center`, `radius`) in a view through `camera` of
/// `size` pixels; `None` when it has no bound: no camera, or a camera inside the sphere.
pub fn projected_radius(camera: Option<(&ExtractedCamera, UVec2)>, center: Vec3, radius: f32) -> Option<f32> {
    let (camera, size) = camera?;
    let half_height = size.y.max(1) as f32 * 0.5;
    let projection = camera.projection.sanitized();
    match projection.kind {
        ProjectionKind::Orthographic { height } => Some(radius / (0.5 * height) * half_height),
        ProjectionKind::Perspective => {
            let distance = camera.position().distance(center);
            if distance <= radius {
                return None;
            }
            let tangent = radius / (distance * distance - radius * radius).sqrt();
            Some(tangent / (0.5 * projection.fov_y).tan() * half_height)
        }
    }
}

/// `wanted` texels rounded up to a power of two in `lo..=hi`; `hi` when unbounded (`None`) or
/// not finite.
fn edge_for(wanted: Option<f32>, lo: u32, hi: u32) -> u32 {
    match wanted {
        Some(w) if w.is_finite() && w < hi as f32 => {
            (w.max(1.0).ceil() as u32).next_power_of_two().clamp(lo, hi)
        }
        _ => hi,
    }
}

/// The face edge a light with the sphere (`center`, `radius`) asks for in a view through
/// `camera` of `size` pixels: its projected radius in pixels ([`projected_radius`]) times
/// `resolution_scale`, rounded up to a power of two in the settings' range; the largest for a
/// camera inside the sphere or no camera.
pub fn requested_edge(
    settings: &ShadowSettings,
    camera: Option<(&ExtractedCamera, UVec2)>,
    center: Vec3,
    radius: f32,
) -> u32 {
    let wanted = projected_radius(camera, center, radius).map(|p| p * settings.resolution_scale);
    edge_for(wanted, settings.min_face_size, settings.max_face_size)
}

/// What a shadow map belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ShadowCaster {
    /// A point or spot light, by its index in the light buffer: six cube faces.
    Point(u32),
    /// A directional light, by its index in the view's directional lights: one tile per
    /// cascade.
    Directional(u32),
}

/// One light's request for a shadow map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowRequest {
    /// The light.
    pub caster: ShadowCaster,
    /// Face edge asked for (a power of two).
    pub edge: u32,
    /// Larger is kept first when the atlas is full (the projected size).
    pub importance: f32,
}

/// Where a light's faces lie in the atlas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowPlacement {
    /// The light.
    pub caster: ShadowCaster,
    /// Top-left texel of its block of tiles.
    pub x: u32,
    /// Top-left texel of its block of tiles.
    pub y: u32,
    /// Face edge it got.
    pub edge: u32,
    /// Face edge it asked for.
    pub asked: u32,
}

/// The frame's atlas: every placed light, and what did not fit.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AtlasPlan {
    /// Placed lights, largest faces first (then by light).
    pub placements: Vec<ShadowPlacement>,
    /// Atlas edge in texels.
    pub atlas_size: u32,
    /// Lights placed with a smaller edge than asked.
    pub downgraded: u32,
    /// Lights not placed.
    pub dropped: u32,
}

impl AtlasPlan {
    /// Fraction of the texels of an atlas `atlas` texels wide in a tile (the texture can be
    /// larger than [`AtlasPlan::atlas_size`]: it is never shrunk).
    pub fn occupancy(&self, atlas: u32) -> f32 {
        let used: u64 =
            self.placements.iter().map(|p| u64::from(p.edge).pow(2) * u64::from(SHADOW_FACES)).sum();
        used as f32 / (u64::from(atlas).pow(2)).max(1) as f32
    }
}

/// Packs blocks of `edges` (sorted largest first) in rows of an `atlas` × `atlas` square;
/// `None` when they do not fit. Each row is as tall as its first block.
fn pack_rows(edges: impl Iterator<Item = u32>, atlas: u32) -> Option<Vec<(u32, u32)>> {
    let (mut x, mut y, mut row) = (0u32, 0u32, 0u32);
    let mut out = Vec::new();
    for edge in edges {
        let (w, h) = (SHADOW_TILE_COLUMNS * edge, SHADOW_TILE_ROWS * edge);
        if x + w > atlas {
            (x, y, row) = (0, y + row, 0);
        }
        if w > atlas || y + h > atlas {
            return None;
        }
        out.push((x, y));
        x += w;
        row = row.max(h);
    }
    Some(out)
}

/// Plans the atlas for `requests` (edges are powers of two of at least `min_edge`): the
/// smallest power-of-two atlas from [`MIN_ATLAS_SIZE`] to `max_atlas` that holds every request
/// as asked, or `max_atlas` with every edge halved until they fit (then the room left given
/// back to the most important) and, at `min_edge`,
/// the least important lights left out. Cost: O(n log n) to sort, then O(n) per halving
/// (at most log2 of the largest edge).
pub fn plan_atlas(requests: &[ShadowRequest], max_atlas: u32, min_edge: u32) -> AtlasPlan {
    // Largest first, then by light: a light keeps its block from frame to frame while the
    // lights before it keep their edges, so its map can be cached.
    let mut order: Vec<ShadowRequest> = requests.to_vec();
    order.sort_by(|a, b| b.edge.cmp(&a.edge).then(a.caster.cmp(&b.caster)));
    let placed = |granted: &[u32], order: &[ShadowRequest], atlas: u32, spots: Vec<(u32, u32)>| AtlasPlan {
        placements: order
            .iter()
            .zip(granted)
            .zip(spots)
            .map(|((r, &edge), (x, y))| ShadowPlacement { caster: r.caster, x, y, edge, asked: r.edge })
            .collect(),
        atlas_size: atlas,
        downgraded: order.iter().zip(granted).filter(|(r, g)| **g < r.edge).count() as u32,
        dropped: 0,
    };
    let mut atlas = MIN_ATLAS_SIZE.min(max_atlas);
    loop {
        if let Some(spots) = pack_rows(order.iter().map(|r| r.edge), atlas) {
            let granted: Vec<u32> = order.iter().map(|r| r.edge).collect();
            return placed(&granted, &order, atlas, spots);
        }
        if atlas >= max_atlas {
            break;
        }
        atlas *= 2;
    }
    // Halve every edge (down to the smallest) until the blocks fit: each light keeps its share
    // of the room, where halving only the largest first would take the lights that asked less
    // down with them (docs/benchmarks.md, "Shadows").
    let mut granted: Vec<u32> = order.iter().map(|r| r.edge).collect();
    loop {
        let largest = granted.iter().copied().max().unwrap_or(min_edge);
        if largest <= min_edge {
            break;
        }
        for g in granted.iter_mut().filter(|g| **g > min_edge) {
            *g /= 2;
        }
        // Halving at the smallest edge brings lights of different asks together; re-sort to
        // keep rows largest first.
        let mut paired: Vec<(ShadowRequest, u32)> =
            order.iter().copied().zip(granted.iter().copied()).collect();
        paired.sort_by(|(a, ga), (b, gb)| gb.cmp(ga).then(a.caster.cmp(&b.caster)));
        order = paired.iter().map(|(r, _)| *r).collect();
        granted = paired.iter().map(|(_, g)| *g).collect();
        if pack_rows(granted.iter().copied(), atlas).is_some() {
            let spots = grow_most_important(&mut order, &mut granted, atlas);
            return placed(&granted, &order, atlas, spots);
        }
    }
    // Every light at the smallest edge and still too many: keep the most important ones.
    let per_row = atlas / (SHADOW_TILE_COLUMNS * min_edge);
    let rows = atlas / (SHADOW_TILE_ROWS * min_edge);
    let capacity = (per_row as usize) * (rows as usize);
    order.sort_by(|a, b| b.importance.total_cmp(&a.importance).then(a.caster.cmp(&b.caster)));
    let kept = order.len().min(capacity);
    let dropped = (order.len() - kept) as u32;
    order.truncate(kept);
    order.sort_by_key(|r| r.caster);
    let granted = vec![min_edge; kept];
    let spots = pack_rows(granted.iter().copied(), atlas).unwrap_or_default();
    AtlasPlan { dropped, ..placed(&granted, &order, atlas, spots) }
}

/// Places `target`'s lights (their edges from [`plan_atlas`]) in `alloc`'s atlas so that each
/// keeps its block from the frame before while that block's edge is at most its target and at
/// least half of it; the others (new lights, lights whose edge moved further) get blocks, most
/// important first, at their target edge or, where the atlas has no such block free, the
/// largest free below it (counted as smaller than asked). When a light placed by `target`
/// finds no block at all, every block is given back and all are placed anew, largest first.
/// Lights `target` left out are released. Cost: O(n log n).
pub fn place_stably(
    alloc: &mut BlockAllocator<ShadowCaster>,
    target: &AtlasPlan,
    requests: &[ShadowRequest],
) -> AtlasPlan {
    let importance: HashMap<ShadowCaster, f32> = requests.iter().map(|r| (r.caster, r.importance)).collect();
    let wanted: HashMap<ShadowCaster, u32> = target.placements.iter().map(|p| (p.caster, p.edge)).collect();
    let held: Vec<ShadowCaster> = alloc.keys().collect();
    for caster in held {
        let keep = match (wanted.get(&caster), alloc.block_of(caster)) {
            (Some(&edge), Some(block)) => block.edge <= edge && block.edge * 2 >= edge,
            _ => false,
        };
        if !keep {
            alloc.release(caster);
        }
    }
    let mut order: Vec<&ShadowPlacement> = target.placements.iter().collect();
    order.sort_by(|a, b| {
        let (ia, ib) = (importance.get(&a.caster).unwrap_or(&0.0), importance.get(&b.caster).unwrap_or(&0.0));
        ib.total_cmp(ia).then(a.caster.cmp(&b.caster))
    });
    let place = |alloc: &mut BlockAllocator<ShadowCaster>, p: &ShadowPlacement| {
        let mut edge = p.edge.min(alloc.largest_edge());
        while edge > 0 {
            if alloc.allocate(p.caster, edge).is_some() {
                return true;
            }
            edge /= 2;
        }
        false
    };
    let mut homeless = 0;
    for p in &order {
        if alloc.block_of(p.caster).is_none() && !place(alloc, p) {
            homeless += 1;
        }
    }
    if homeless > 0 {
        // Fragmented: everything anew, largest first (blocks nest, so this packs as tightly as
        // the root blocks allow).
        let held: Vec<ShadowCaster> = alloc.keys().collect();
        for caster in held {
            alloc.release(caster);
        }
        order.sort_by(|a, b| b.edge.cmp(&a.edge).then(a.caster.cmp(&b.caster)));
        homeless = order.iter().filter(|p| !place(alloc, p)).count();
    }
    let placements: Vec<ShadowPlacement> = target
        .placements
        .iter()
        .filter_map(|p| {
            alloc.block_of(p.caster).map(|b| ShadowPlacement { x: b.x, y: b.y, edge: b.edge, ..*p })
        })
        .collect();
    AtlasPlan {
        downgraded: placements.iter().filter(|p| p.edge < p.asked).count() as u32,
        dropped: target.dropped + homeless as u32,
        atlas_size: target.atlas_size.max(alloc.atlas()),
        placements,
    }
}

/// The largest atlas a frame may use: `requested`, or the largest power of two the device's
/// textures (`max_texture` texels) allow when that is smaller, and whether the device limited it.
pub fn atlas_limit(requested: u32, max_texture: u32) -> (u32, bool) {
    let device = 1u32 << (31 - max_texture.max(1).leading_zeros());
    (requested.min(device), device < requested)
}

/// The planes (`n·p + d ≥ 0` inside) of a reverse-Z view frustum `clip_from_world`: left,
/// right, bottom, top and near. The far plane is left out (it may be at infinity), so the
/// volume is conservative.
pub fn frustum_planes(clip_from_world: &Mat4) -> [Vec4; 5] {
    let m = clip_from_world.transpose();
    let (r0, r1, r2, r3) = (m.x_axis, m.y_axis, m.z_axis, m.w_axis);
    [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r3 - r2]
}

/// The frustums of every view of `snapshot` that shows shadows (each at its rectangle's aspect).
pub fn view_frustums(snapshot: &FrameSnapshot) -> Vec<[Vec4; 5]> {
    snapshot
        .views
        .iter()
        .filter(|v| v.shadows)
        .map(|v| {
            let size = v.rect_in(v.target_size(snapshot.viewport)).size.max(UVec2::ONE);
            frustum_planes(&v.camera.clip_from_world(size))
        })
        .collect()
}

/// True when some point of `points` may lie inside `planes` (false only when all of them are
/// outside one plane: conservative).
fn may_meet(planes: &[Vec4; 5], points: &[Vec3]) -> bool {
    planes.iter().all(|p| points.iter().any(|q| p.truncate().dot(*q) + p.w >= 0.0))
}

/// True when the sphere (`center`, `radius`) may be seen through one of `frustums`.
pub fn sphere_in_view(frustums: &[[Vec4; 5]], center: Vec3, radius: f32) -> bool {
    frustums.iter().any(|planes| {
        planes.iter().all(|p| p.truncate().dot(center) + p.w >= -radius * p.truncate().length())
    })
}

/// True when the part of cube face `face` of a light at `light` with range `radius` may be
/// seen through one of `frustums`: that part lies in the pyramid from the light to the face's
/// square at distance `radius`, tested by its five corners. A face no view sees lights no
/// visible pixel, so it is not drawn.
pub fn face_in_view(frustums: &[[Vec4; 5]], light: Vec3, face: u32, radius: f32) -> bool {
    let (axis, sign) = face_axis(face);
    let (a, b) = (Vec3::AXES[(axis + 1) % 3] * radius, Vec3::AXES[(axis + 2) % 3] * radius);
    let end = light + Vec3::AXES[axis] * sign * radius;
    let corners = [light, end + a + b, end + a - b, end - a + b, end - a - b];
    frustums.iter().any(|planes| may_meet(planes, &corners))
}

/// Most rounds of [`grow_most_important`]: each can double a light's edge once, so this many
/// rounds can take a light from a sixteenth of its ask back to all of it.
const GROW_ROUNDS: usize = 4;

/// After halving made every block fit (`granted`, in `order`, fits `atlas`): doubles the edges
/// of the most important lights still below their ask, as many as fit (found by bisection on
/// how many), for up to [`GROW_ROUNDS`] rounds, so the room the last halving freed goes to the
/// lights largest on screen. Leaves `order` and `granted` sorted for packing and returns the
/// blocks' places. Cost: O(n log² n) a round.
fn grow_most_important(
    order: &mut Vec<ShadowRequest>,
    granted: &mut Vec<u32>,
    atlas: u32,
) -> Vec<(u32, u32)> {
    let by_size = |g: &[u32], order: &[ShadowRequest]| {
        let mut idx: Vec<usize> = (0..order.len()).collect();
        idx.sort_by(|&a, &b| g[b].cmp(&g[a]).then(order[a].caster.cmp(&order[b].caster)));
        idx
    };
    for _ in 0..GROW_ROUNDS {
        let mut candidates: Vec<usize> = (0..order.len()).filter(|&i| granted[i] < order[i].edge).collect();
        candidates.sort_by(|&a, &b| {
            order[b].importance.total_cmp(&order[a].importance).then(order[a].caster.cmp(&order[b].caster))
        });
        // The first `k` candidates doubled, sorted for packing, if they fit.
        let grown = |k: usize| {
            let mut g = granted.clone();
            for &i in &candidates[..k] {
                g[i] *= 2;
            }
            let idx = by_size(&g, order);
            pack_rows(idx.iter().map(|&i| g[i]), atlas).map(|_| (idx, g))
        };
        let (mut lo, mut hi) = (0, candidates.len());
        while lo < hi {
            let mid = (lo + hi).div_ceil(2);
            if grown(mid).is_some() { lo = mid } else { hi = mid - 1 }
        }
        let Some((idx, g)) = grown(lo).filter(|_| lo > 0) else { break };
        *order = idx.iter().map(|&i| order[i]).collect();
        *granted = idx.iter().map(|&i| g[i]).collect();
    }
    pack_rows(granted.iter().copied(), atlas).unwrap_or_default()
}

/// True when `bounds` meets the sphere (`center`, `radius`).
fn sphere_meets_box(center: Vec3, radius: f32, bounds: &Aabb) -> bool {
    if bounds.is_empty() {
        return false;
    }
    let nearest = center.clamp(bounds.min, bounds.max);
    nearest.distance_squared(center) <= radius * radius
}

/// True when `bounds` may meet face `face`'s frustum from `light` (a conservative test against
/// the four planes through the light and the half-space in front of it).
pub fn box_meets_face(light: Vec3, face: u32, bounds: &Aabb) -> bool {
    let (axis, sign) = face_axis(face);
    let (a, b) = ((axis + 1) % 3, (axis + 2) % 3);
    let (lo, hi) = (bounds.min - light, bounds.max - light);
    // The largest value of n·p over the box.
    let max_over_box = |n: Vec3| -> f32 { (n * lo).max(n * hi).element_sum() };
    let w = Vec3::AXES[axis] * sign;
    let planes = [w, w - Vec3::AXES[a], w + Vec3::AXES[a], w - Vec3::AXES[b], w + Vec3::AXES[b]];
    planes.iter().all(|&n| max_over_box(n) >= 0.0)
}

/// The atlas texel at the top left of tile `tile` of a placement's block.
fn tile_of(p: &ShadowPlacement, tile: u32) -> (u32, u32) {
    (p.x + (tile % SHADOW_TILE_COLUMNS) * p.edge, p.y + (tile / SHADOW_TILE_COLUMNS) * p.edge)
}

/// A slice of the view between two distances along the camera's axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewSlice {
    /// Nearer distance.
    pub near: f32,
    /// Further distance.
    pub far: f32,
}

/// A cascade fitted to its slice of the view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CascadeFit {
    /// Orthographic along the light: x, y ∈ [-1, 1] over a square that holds the slice's
    /// bounding sphere, z from 1 at the near side (the casters nearest the light, or the
    /// sphere's near side when depth is clamped) to 0 at the sphere's far side (reverse depth,
    /// like the cube faces).
    pub clip_from_world: Mat4,
    /// Width of one of the cascade's texels in world units.
    pub texel: f32,
    /// The depth range in world units.
    pub depth_range: f32,
}

/// Fits a cascade of `edge` texels for light travelling along `direction` to `slice` of the
/// view through `camera` (of aspect `aspect`): the slice's eight corners' bounding sphere, its
/// radius rounded up to 1/16 unit and its centre snapped to whole texels across the light, so
/// the map keeps its size and texel grid as the camera turns and moves (no shimmering edges).
/// Its depth spans the sphere when the shadow pass clamps depth (`casters` is `None`: a caster
/// nearer the light than the sphere is clamped onto its near side and still shadows it, and
/// the depth range stays the sphere's however large the world), else it reaches back to every
/// caster in `casters`.
pub fn fit_cascade(
    camera: &ExtractedCamera,
    aspect: f32,
    slice: ViewSlice,
    direction: Vec3,
    casters: Option<&Aabb>,
    edge: u32,
) -> CascadeFit {
    let projection = camera.projection.sanitized();
    let near = slice.near.max(projection.near);
    let far = slice.far.min(projection.far).max(near);
    let aspect = if aspect.is_finite() && aspect > 0.0 { aspect } else { 1.0 };
    let half_extent = |d: f32| -> (f32, f32) {
        let half_height = match projection.kind {
            ProjectionKind::Perspective => d * (0.5 * projection.fov_y).tan(),
            ProjectionKind::Orthographic { height } => 0.5 * height,
        };
        (half_height * aspect, half_height)
    };
    let mut corners = [Vec3::ZERO; 8];
    for (i, d) in [near, far].into_iter().enumerate() {
        let (w, h) = half_extent(d);
        for (j, (x, y)) in [(-w, -h), (w, -h), (w, h), (-w, h)].into_iter().enumerate() {
            corners[i * 4 + j] = camera.world_from_view.transform_point3(Vec3::new(x, y, -d));
        }
    }
    let center = corners.iter().copied().sum::<Vec3>() / 8.0;
    let radius = corners.iter().map(|c| c.distance(center)).fold(0.0f32, f32::max);
    let radius = ((radius * 16.0).ceil() / 16.0).max(1.0 / 16.0);
    let direction = direction.try_normalize().unwrap_or(Vec3::NEG_Y);
    let up = if direction.y.abs() < 0.99 { Vec3::Y } else { Vec3::X };
    let light_from_world = glam::camera::rh::view::look_to_mat4(Vec3::ZERO, direction, up);
    let texel = 2.0 * radius / edge.max(1) as f32;
    let c = light_from_world.transform_point3(center);
    let (cx, cy) = ((c.x / texel).floor() * texel, (c.y / texel).floor() * texel);
    // Distance along the light is -z in its frame: the sphere spans -c.z ± radius, and the
    // casters nearest the light are at the smallest distance.
    let mut nearest = -c.z - radius;
    if let Some(casters) = casters.filter(|b| !b.is_empty()) {
        let b = casters.transformed(&light_from_world);
        nearest = nearest.min(-b.max.z);
    }
    let farthest = -c.z + radius;
    let range = (farthest - nearest).max(1e-6);
    // Reverse depth: z = (farthest - distance) / range, and distance = -z in the light's frame.
    let scale = Mat4::from_cols(
        Vec4::new(1.0 / radius, 0.0, 0.0, 0.0),
        Vec4::new(0.0, 1.0 / radius, 0.0, 0.0),
        Vec4::new(0.0, 0.0, 1.0 / range, 0.0),
        Vec4::new(-cx / radius, -cy / radius, farthest / range, 1.0),
    );
    CascadeFit { clip_from_world: scale * light_from_world, texel, depth_range: range }
}

/// True when `bounds` may meet the box x, y ∈ [-1, 1], z ∈ [0, 1] of the affine (orthographic)
/// projection `clip_from_world`.
pub fn box_meets_clip(clip_from_world: &Mat4, bounds: &Aabb) -> bool {
    if bounds.is_empty() {
        return false;
    }
    let b = bounds.transformed(clip_from_world);
    b.max.x >= -1.0 && b.min.x <= 1.0 && b.max.y >= -1.0 && b.min.y <= 1.0 && b.max.z >= 0.0 && b.min.z <= 1.0
}

/// A run of the shadow pass's draw instances that share a mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShadowMeshDraws {
    /// Key into `SceneAssets::mesh`.
    pub mesh: usize,
    /// First instance (index into the draw buffer).
    pub first: u32,
    /// Instances.
    pub count: u32,
}

/// What a map in the atlas holds, kept from the frame that drew it.
#[derive(Clone, Copy, Debug, PartialEq)]
struct CachedMap {
    /// Its block's top-left texel: a map is reused only where it lies.
    x: u32,
    y: u32,
    /// Its face edge.
    edge: u32,
    /// Hash of the light and the casters it was drawn from.
    content: u64,
    /// The light table's entry it was drawn with (its origin and depth range).
    light: GpuShadowLight,
}

/// What a placed map gets this frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum MapState {
    /// Drawn (its tiles cleared first when other maps are kept).
    Draw,
    /// Unchanged since the frame before: kept.
    Cached,
    /// Changed, but past the redraw budget: the earlier map is kept.
    Stale,
}

/// An opaque draw as the shadow pass sees it.
struct OpaqueDraw<'a> {
    draw: &'a crate::resources::Draw,
    /// Index of its mesh's list of pairs.
    slot: usize,
    /// Hash of its mesh and transform.
    content: u64,
}

/// A placed map's faces, casters and content, gathered before deciding whether to draw it.
#[derive(Clone, Debug)]
struct MapWork {
    placement: ShadowPlacement,
    content: u64,
    /// The light table's entry (point and spot lights).
    light: GpuShadowLight,
    /// The directional table's entry and its index.
    directional: Option<(u32, GpuDirectionalShadow)>,
    /// Its faces in `ShadowResources::work_faces`.
    faces: Range<usize>,
    /// Its (mesh slot, pair with the face's index within the map) in
    /// `ShadowResources::work_draws`.
    draws: Range<usize>,
    importance: f32,
    state: MapState,
}

/// What gathering a frame's maps reads: its settings, lights, first view and opaque draws.
struct MapInputs<'a> {
    settings: ShadowSettings,
    /// The atlas texture's edge in texels.
    atlas: u32,
    /// Point and spot lights, by their index in the light buffer.
    lights: &'a PointLights,
    /// Directional lights, by their index in the view uniform.
    directional: Vec<&'a ExtractedDirectionalLight>,
    /// The first view's camera and aspect.
    view: Option<(&'a ExtractedCamera, f32)>,
    /// The frustums of the views that show shadows.
    frustums: Vec<[Vec4; 5]>,
    opaque: Vec<OpaqueDraw<'a>>,
    /// What a cascade's depth range must reach back to: every opaque draw.
    casters: Aabb,
    /// Each request's importance, by light.
    importance: HashMap<ShadowCaster, f32>,
}

/// The bounds of every opaque draw: what a cascade's depth range must reach back to.
fn caster_bounds(opaque: &[OpaqueDraw]) -> Aabb {
    let mut casters = Aabb::EMPTY;
    for o in opaque {
        if !o.draw.world_bounds.is_empty() {
            casters.extend(o.draw.world_bounds.min);
            casters.extend(o.draw.world_bounds.max);
        }
    }
    casters
}

/// The shadow atlas and the buffers of its pass, kept across frames.
pub struct ShadowResources {
    /// The atlas (created on the first frame with a casting light, grown when a frame needs a
    /// larger one, never shrunk).
    atlas: Option<wgpu::Texture>,
    atlas_view: Option<wgpu::TextureView>,
    /// The comparison sampler of the shading passes (linear: a 2×2 filter).
    pub sampler: wgpu::Sampler,
    /// [`GpuShadowLight`] per light of the light buffer.
    pub lights: GrowableBuffer,
    /// [`GpuDirectionalShadow`] per entry of the view's directional lights
    /// ([`MAX_DIRECTIONAL_LIGHTS`]; no cascade where a light casts none).
    pub directional: GrowableBuffer,
    /// [`GpuShadowFace`] per placed face.
    pub faces: GrowableBuffer,
    /// [`GpuShadowDraw`] per (instance, face) pair, grouped by mesh.
    pub draws: GrowableBuffer,
    /// The runs of `draws` by mesh, in the scene's draw order.
    pub mesh_draws: Vec<ShadowMeshDraws>,
    /// This frame's plan.
    pub plan: AtlasPlan,
    /// This frame's counters.
    pub report: ShadowReport,
    /// True when the frame has a shadow map to draw and read.
    pub active: bool,
    /// Bumped whenever the atlas or the light table is re-created (the view bind group follows).
    pub generation: u64,
    /// The device draws clip distances (`Features::CLIP_DISTANCES`); otherwise the shadow
    /// pass discards the fragments outside each face's tile.
    pub clip_distances: bool,
    /// The device clamps depth instead of clipping it (`Features::DEPTH_CLIP_CONTROL`): the
    /// shadow pass clamps, so a cascade's depth range is its slice's sphere alone.
    pub clamps_depth: bool,
    /// Some maps of the atlas are kept this frame: the pass loads the atlas and clears the
    /// tiles it draws, instead of clearing the whole atlas.
    pub clears_tiles: bool,
    /// Faces drawn this frame: the first `faces_drawn` of `faces`.
    pub faces_drawn: u32,
    /// Set when a frame has maps to draw, taken by the first view's shadow pass.
    pending_draw: AtomicBool,
    /// Where each light's block lies, kept from frame to frame.
    allocator: BlockAllocator<ShadowCaster>,
    /// The maps the atlas holds, by light.
    cache: HashMap<ShadowCaster, CachedMap>,
    next_cache: HashMap<ShadowCaster, CachedMap>,
    work: Vec<MapWork>,
    work_faces: Vec<GpuShadowFace>,
    work_draws: Vec<(usize, GpuShadowDraw)>,
    max_texture: u32,
    gpu_lights: Vec<GpuShadowLight>,
    gpu_directional: Vec<GpuDirectionalShadow>,
    gpu_faces: Vec<GpuShadowFace>,
    by_mesh: Vec<(usize, Vec<GpuShadowDraw>)>,
    requests: Vec<ShadowRequest>,
}

impl ShadowResources {
    /// Empty buffers and the sampler; no atlas until a light casts.
    pub fn new(gpu: &GpuContext) -> ShadowResources {
        let storage = wgpu::BufferUsages::STORAGE;
        ShadowResources {
            atlas: None,
            atlas_view: None,
            sampler: gpu.device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some("shadow_sampler"),
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                // Reverse depth: lit where the point is at least as near as the stored caster.
                compare: Some(wgpu::CompareFunction::GreaterEqual),
                ..Default::default()
            }),
            lights: GrowableBuffer::new(
                gpu,
                "shadow_lights",
                storage,
                std::mem::size_of::<GpuShadowLight>() as u64,
            ),
            directional: GrowableBuffer::new(
                gpu,
                "shadow_directional",
                storage,
                std::mem::size_of::<GpuDirectionalShadow>() as u64 * u64::from(MAX_DIRECTIONAL_LIGHTS),
            ),
            faces: GrowableBuffer::new(
                gpu,
                "shadow_faces",
                storage,
                std::mem::size_of::<GpuShadowFace>() as u64,
            ),
            draws: GrowableBuffer::new(
                gpu,
                "shadow_draws",
                storage,
                std::mem::size_of::<GpuShadowDraw>() as u64,
            ),
            mesh_draws: Vec::new(),
            plan: AtlasPlan::default(),
            report: ShadowReport::default(),
            active: false,
            generation: 0,
            clip_distances: gpu.device.features().contains(wgpu::Features::CLIP_DISTANCES),
            clamps_depth: gpu.device.features().contains(wgpu::Features::DEPTH_CLIP_CONTROL),
            clears_tiles: false,
            faces_drawn: 0,
            pending_draw: AtomicBool::new(false),
            allocator: BlockAllocator::new(0, 1),
            cache: HashMap::new(),
            next_cache: HashMap::new(),
            work: Vec::new(),
            work_faces: Vec::new(),
            work_draws: Vec::new(),
            max_texture: gpu.max_texture_size(),
            gpu_lights: Vec::new(),
            gpu_directional: vec![GpuDirectionalShadow::default(); MAX_DIRECTIONAL_LIGHTS as usize],
            gpu_faces: Vec::new(),
            by_mesh: Vec::new(),
            requests: Vec::new(),
        }
    }

    /// Caps the atlas at `texels` (rounded down to a power of two) as a device whose textures
    /// are that small would; the device's own limit still applies.
    pub fn limit_texture_size(&mut self, texels: u32) {
        self.max_texture = self.max_texture.min(texels.max(1));
    }

    /// The atlas texture, once a frame had a casting light.
    pub fn atlas(&self) -> Option<&wgpu::Texture> {
        self.atlas.as_ref()
    }

    /// The atlas's view, once a frame had a casting light.
    pub fn atlas_view(&self) -> Option<&wgpu::TextureView> {
        self.atlas_view.as_ref()
    }

    /// What group 0 binds for this frame's shadows; `None` when the frame draws none.
    pub fn bindings(&self) -> Option<crate::resources::ShadowBindings<'_>> {
        let atlas = self.atlas_view.as_ref().filter(|_| self.active)?;
        Some(crate::resources::ShadowBindings {
            atlas,
            sampler: &self.sampler,
            lights: self.lights.buffer(),
            directional: self.directional.buffer(),
            generation: self.generation,
        })
    }

    /// Plans the frame's atlas and uploads its faces, draws and light table (after
    /// [`SceneResources::prepare`], whose lights, instances and draws it reads).
    pub fn prepare(
        &mut self,
        gpu: &GpuContext,
        scene: &SceneResources,
        snapshot: &FrameSnapshot,
    ) -> Result<(), RenderError> {
        let settings = snapshot.settings.shadows;
        self.start_frame();
        if !snapshot.casts_shadows() {
            self.plan = AtlasPlan::default();
            return Ok(());
        }
        let camera = snapshot.views.first().map(|v| (&v.camera, snapshot.viewport));
        let frustums = view_frustums(snapshot);
        self.request_point_maps(snapshot, camera, &frustums);
        // Directional lights, by their index in the view uniform (the first
        // MAX_DIRECTIONAL_LIGHTS valid ones).
        let directional: Vec<&ExtractedDirectionalLight> =
            viewed_directional_lights(&snapshot.directional_lights).map(|(_, l)| l).collect();
        let view = camera.map(|(c, size)| (c, size.x.max(1) as f32 / size.y.max(1) as f32));
        // The largest power of two the device's textures allow.
        let (max_atlas, limited) = atlas_limit(settings.atlas_size, self.max_texture);
        self.request_cascades(&settings, &directional, view.is_some(), max_atlas);
        // Each light's edge from the whole frame's needs, then its place: where it was while
        // its edge holds.
        let min_edge = settings.min_face_size.min(max_atlas / SHADOW_TILE_COLUMNS).max(1);
        let target = plan_atlas(&self.requests, max_atlas, min_edge);
        self.report.casting_lights = self.requests.len() as u32 + self.report.unseen_lights;
        self.report.atlas_limited_by_device = limited;
        if target.placements.is_empty() {
            self.report.dropped_lights = target.dropped;
            self.plan = target;
            return Ok(());
        }
        let atlas = self.place_maps(gpu, &target, min_edge);

        // The light table: every light of the buffer, edge 0 where it has no map.
        self.gpu_lights.clear();
        self.gpu_lights.resize(scene.light_count.max(1) as usize, GpuShadowLight::default());
        let lights = &snapshot.lights;
        self.gpu_faces.clear();
        for list in &mut self.by_mesh {
            list.1.clear();
        }
        let opaque = self.opaque_draws(scene);
        let casters = caster_bounds(&opaque);
        self.gpu_directional.fill(GpuDirectionalShadow::default());
        let importance = self.requests.iter().map(|r| (r.caster, r.importance)).collect();
        let inputs =
            MapInputs { settings, atlas, lights, directional, view, frustums, opaque, casters, importance };

        let mut work = self.gather_work(&inputs);
        self.choose_redraws(&mut work, &settings);
        self.commit_maps(&work);
        self.clears_tiles = work.iter().any(|w| w.state != MapState::Draw);
        self.work = work;
        self.upload(gpu, scene, atlas)
    }

    /// Clears the last frame's counters and draws; forgets the maps of a frame whose views
    /// drew none.
    fn start_frame(&mut self) {
        // Maps planned for a frame whose views drew none (no view shaded lights) are not in
        // the atlas.
        if self.pending_draw.swap(false, Ordering::Relaxed) {
            self.cache.clear();
        }
        self.report = ShadowReport::default();
        self.active = false;
        self.clears_tiles = false;
        self.faces_drawn = 0;
        self.mesh_draws.clear();
    }

    /// Asks for a map for every valid point and spot light with a shadow that one of
    /// `frustums` sees, by the light's index in the light buffer (the valid lights in order),
    /// its edge from its size through `camera`; counts the lights no view sees.
    fn request_point_maps(
        &mut self,
        snapshot: &FrameSnapshot,
        camera: Option<(&ExtractedCamera, UVec2)>,
        frustums: &[[Vec4; 5]],
    ) {
        let settings = snapshot.settings.shadows;
        self.requests.clear();
        // The lights with a shadow, found without visiting the chunks that hold none.
        for (k, light) in snapshot.lights.shadowed().map(|(k, l)| (k as u32, l)) {
            if !light.is_valid() || light.radius <= 0.0 {
                continue;
            }
            let (center, radius) = bounding_sphere(light);
            // A light no view sees lights no visible pixel: no map.
            if !sphere_in_view(frustums, center, radius) {
                self.report.unseen_lights += 1;
                continue;
            }
            // The same rounding as the edge, without its range: lights larger on screen first.
            let wanted = projected_radius(camera, center, radius).map(|p| p * settings.resolution_scale);
            let edge = edge_for(wanted, settings.min_face_size, settings.max_face_size);
            let importance = edge_for(wanted, 1, 1 << 30) as f32;
            self.requests.push(ShadowRequest { caster: ShadowCaster::Point(k), edge, importance });
        }
    }

    /// Asks for the cascades of every casting light of `directional` when the frame has a
    /// view (`has_view`), at their set size (at most a third of `max_atlas`: a block is 3 tiles
    /// wide), kept before any point light when the atlas is full.
    fn request_cascades(
        &mut self,
        settings: &ShadowSettings,
        directional: &[&ExtractedDirectionalLight],
        has_view: bool,
        max_atlas: u32,
    ) {
        let widest = 1u32 << (31 - (max_atlas / SHADOW_TILE_COLUMNS).max(1).leading_zeros());
        for (i, light) in directional.iter().enumerate() {
            if light.shadow.is_some() && has_view {
                let edge = settings.cascade_size.max(settings.min_face_size).min(widest);
                let caster = ShadowCaster::Directional(i as u32);
                self.requests.push(ShadowRequest { caster, edge, importance: f32::MAX });
            }
        }
    }

    /// Places `target`'s maps in the atlas (created or grown to its size first), each where it
    /// was while its edge holds ([`place_stably`]), as the frame's plan; returns the atlas
    /// texture's edge.
    fn place_maps(&mut self, gpu: &GpuContext, target: &AtlasPlan, min_edge: u32) -> u32 {
        self.ensure_atlas(gpu, target.atlas_size);
        let atlas = self.atlas.as_ref().map_or(target.atlas_size, |t| t.width());
        if !self.allocator.serves(atlas, min_edge) {
            self.allocator = BlockAllocator::new(atlas, min_edge);
        }
        self.plan = place_stably(&mut self.allocator, target, &self.requests);
        self.report.downgraded_lights = self.plan.downgraded;
        self.report.dropped_lights = self.plan.dropped;
        atlas
    }

    /// Each opaque draw of `scene` with the slot of its mesh's pairs (a new slot for a new
    /// mesh) and a hash of what it draws (its mesh and transform), found once a frame.
    fn opaque_draws<'a>(&mut self, scene: &'a SceneResources) -> Vec<OpaqueDraw<'a>> {
        let mut opaque = Vec::new();
        for d in scene.draws.iter().filter(|d| !d.variant.blend) {
            let slot = match self.by_mesh.iter().position(|(m, _)| *m == d.mesh) {
                Some(i) => i,
                None => {
                    self.by_mesh.push((d.mesh, Vec::new()));
                    self.by_mesh.len() - 1
                }
            };
            let mut hash = DefaultHasher::new();
            d.mesh.hash(&mut hash);
            d.world_from_local.to_cols_array().map(f32::to_bits).hash(&mut hash);
            opaque.push(OpaqueDraw { draw: d, slot, content: hash.finish() });
        }
        opaque
    }

    /// Each placed map's faces, casters and content, before deciding whether to draw it: the
    /// faces and pairs go to `work_faces` and `work_draws`, each map's ranges of them to the
    /// list returned.
    fn gather_work(&mut self, inputs: &MapInputs) -> Vec<MapWork> {
        let mut work = std::mem::take(&mut self.work);
        work.clear();
        self.work_faces.clear();
        self.work_draws.clear();
        for i in 0..self.plan.placements.len() {
            let p = self.plan.placements[i];
            let (faces, draws) = (self.work_faces.len(), self.work_draws.len());
            let mut content = DefaultHasher::new();
            let mut light_entry = GpuShadowLight::default();
            let mut directional_entry = None;
            match p.caster {
                ShadowCaster::Point(k) => light_entry = self.gather_point_map(inputs, &p, k, &mut content),
                ShadowCaster::Directional(i) => {
                    let Some(gpu) = self.gather_cascades(inputs, &p, i, &mut content) else { continue };
                    directional_entry = Some((i, gpu));
                }
            }
            work.push(MapWork {
                placement: p,
                content: content.finish(),
                light: light_entry,
                directional: directional_entry,
                faces: faces..self.work_faces.len(),
                draws: draws..self.work_draws.len(),
                importance: inputs.importance.get(&p.caster).copied().unwrap_or(0.0),
                state: MapState::Draw,
            });
        }
        work
    }

    /// The six faces of light `k`'s map at `p` and the pairs of each opaque draw in its range
    /// with each face a view sees (the faces no view sees are counted); hashes the light and
    /// its casters into `content` and returns the light table's entry.
    fn gather_point_map(
        &mut self,
        inputs: &MapInputs,
        p: &ShadowPlacement,
        k: u32,
        content: &mut DefaultHasher,
    ) -> GpuShadowLight {
        let light = &inputs.lights[k as usize];
        let bias = light.shadow.unwrap_or_default();
        let far = light.radius;
        let near = far * SHADOW_NEAR_FRACTION;
        let entry = GpuShadowLight {
            tile: [p.x, p.y, p.edge, inputs.settings.filter.gpu_id()],
            params: [near, far, bias.depth, bias.normal],
            origin: light.position.extend(0.0).to_array(),
        };
        for face in 0..SHADOW_FACES {
            let (tx, ty) = tile_of(p, face);
            self.work_faces.push(GpuShadowFace {
                clip_from_world: face_clip_from_world(light.position, face, near, far),
                atlas: tile_transform(tx, ty, p.edge, inputs.atlas),
            });
        }
        let (center, radius) = bounding_sphere(light);
        let seen: Vec<bool> = (0..SHADOW_FACES)
            .map(|face| face_in_view(&inputs.frustums, light.position, face, light.radius))
            .collect();
        self.report.unseen_faces += seen.iter().filter(|s| !**s).count() as u32;
        (light.position.to_array().map(f32::to_bits), far.to_bits(), &seen).hash(content);
        for o in &inputs.opaque {
            if !sphere_meets_box(center, radius, &o.draw.world_bounds) {
                continue;
            }
            for face in 0..SHADOW_FACES {
                if seen[face as usize] && box_meets_face(light.position, face, &o.draw.world_bounds) {
                    let draw = GpuShadowDraw { instance: o.draw.instance, face };
                    self.work_draws.push((o.slot, draw));
                    (o.content, face).hash(content);
                }
            }
        }
        entry
    }

    /// The cascades of directional light `i`'s map at `p`, each fitted to its slice of the
    /// first view, and the pairs of each opaque draw with each cascade it meets; hashes the
    /// cascades and their casters into `content` and returns the directional table's entry.
    /// `None` (nothing gathered) when the light casts none or the frame has no view.
    fn gather_cascades(
        &mut self,
        inputs: &MapInputs,
        p: &ShadowPlacement,
        i: u32,
        content: &mut DefaultHasher,
    ) -> Option<GpuDirectionalShadow> {
        let (Some(light), Some((camera, aspect))) = (inputs.directional.get(i as usize), inputs.view) else {
            return None;
        };
        let shadow = light.shadow?;
        let config = shadow.cascades;
        let bounds = config.far_bounds();
        let mut gpu = GpuDirectionalShadow {
            count: [bounds.len() as u32, 0, 0, 0],
            bias: [shadow.bias.depth, shadow.bias.normal, 0.0, 0.0],
            ..Default::default()
        };
        for (c, &far) in bounds.iter().enumerate() {
            let slice = ViewSlice { near: config.near_bound(c), far };
            let reach = (!self.clamps_depth).then_some(&inputs.casters);
            let fit = fit_cascade(camera, aspect, slice, light.direction, reach, p.edge);
            let (tx, ty) = tile_of(p, c as u32);
            gpu.cascades[c] = GpuCascade {
                clip_from_world: fit.clip_from_world,
                tile: [tx, ty, p.edge, inputs.settings.filter.gpu_id()],
                params: [far, fit.texel, fit.depth_range, 0.0],
            };
            self.work_faces.push(GpuShadowFace {
                clip_from_world: fit.clip_from_world,
                atlas: tile_transform(tx, ty, p.edge, inputs.atlas),
            });
            fit.clip_from_world.to_cols_array().map(f32::to_bits).hash(content);
            for o in &inputs.opaque {
                if box_meets_clip(&fit.clip_from_world, &o.draw.world_bounds) {
                    let draw = GpuShadowDraw { instance: o.draw.instance, face: c as u32 };
                    self.work_draws.push((o.slot, draw));
                    (o.content, c).hash(content);
                }
            }
        }
        Some(gpu)
    }

    /// Which maps to draw: a map whose block and content are unchanged is kept; past the
    /// redraw budget, the changed point and spot light maps least important keep theirs.
    fn choose_redraws(&self, work: &mut [MapWork], settings: &ShadowSettings) {
        let budget = settings.max_redrawn_maps.map_or(usize::MAX, |n| n as usize);
        let mut changed = Vec::new();
        for (i, w) in work.iter_mut().enumerate() {
            let p = w.placement;
            let kept = self.cache.get(&p.caster).filter(|c| (c.x, c.y, c.edge) == (p.x, p.y, p.edge));
            match kept {
                Some(c) if settings.cache_maps && c.content == w.content => w.state = MapState::Cached,
                Some(_) if matches!(p.caster, ShadowCaster::Point(_)) => changed.push(i),
                _ => {}
            }
        }
        if changed.len() > budget {
            changed.sort_by(|&a, &b| {
                work[b]
                    .importance
                    .total_cmp(&work[a].importance)
                    .then(work[a].placement.caster.cmp(&work[b].placement.caster))
            });
            for &i in &changed[budget..] {
                work[i].state = MapState::Stale;
            }
        }
    }

    /// Applies each map's state: a drawn map's faces and pairs join the frame's, a kept or
    /// stale one keeps its tiles; the light tables get each map's entry and the cache the maps
    /// the atlas will hold.
    fn commit_maps(&mut self, work: &[MapWork]) {
        self.next_cache.clear();
        for w in work {
            let p = w.placement;
            let mut entry = w.light;
            match w.state {
                MapState::Draw => {
                    let first_face = self.gpu_faces.len() as u32;
                    self.gpu_faces.extend_from_slice(&self.work_faces[w.faces.clone()]);
                    for &(slot, d) in &self.work_draws[w.draws.clone()] {
                        self.by_mesh[slot]
                            .1
                            .push(GpuShadowDraw { instance: d.instance, face: first_face + d.face });
                    }
                    self.report.maps_rendered += 1;
                    if w.directional.is_some() {
                        self.report.cascades_rendered += w.faces.len() as u32;
                    }
                    let map = CachedMap { x: p.x, y: p.y, edge: p.edge, content: w.content, light: w.light };
                    self.next_cache.insert(p.caster, map);
                }
                MapState::Cached => {
                    self.report.maps_cached += 1;
                    let map = CachedMap { x: p.x, y: p.y, edge: p.edge, content: w.content, light: w.light };
                    self.next_cache.insert(p.caster, map);
                }
                MapState::Stale => {
                    // The map of an earlier frame, tested from where it was drawn with today's
                    // biases.
                    let Some(&map) = self.cache.get(&p.caster) else { continue };
                    self.report.maps_stale += 1;
                    entry = GpuShadowLight {
                        tile: w.light.tile,
                        params: [
                            map.light.params[0],
                            map.light.params[1],
                            w.light.params[2],
                            w.light.params[3],
                        ],
                        origin: map.light.origin,
                    };
                    self.next_cache.insert(p.caster, map);
                }
            }
            if let ShadowCaster::Point(k) = p.caster {
                self.gpu_lights[k as usize] = entry;
            }
            if let Some((i, gpu)) = w.directional {
                self.gpu_directional[i as usize] = gpu;
            }
        }
        std::mem::swap(&mut self.cache, &mut self.next_cache);
    }

    /// Groups the frame's pairs by mesh (meshes no longer drawn leave the list), uploads the
    /// shadow tables, faces and pairs, and marks the frame's maps for drawing in an `atlas`
    /// texels wide atlas.
    fn upload(&mut self, gpu: &GpuContext, scene: &SceneResources, atlas: u32) -> Result<(), RenderError> {
        self.by_mesh.retain(|(mesh, _)| scene.assets.mesh(*mesh).is_some());
        let mut all = Vec::new();
        for (mesh, list) in &self.by_mesh {
            if list.is_empty() {
                continue;
            }
            self.mesh_draws.push(ShadowMeshDraws {
                mesh: *mesh,
                first: all.len() as u32,
                count: list.len() as u32,
            });
            all.extend_from_slice(list);
        }
        let mut grew = self.lights.write(gpu, bytemuck::cast_slice(&self.gpu_lights))?;
        grew |= self.directional.write(gpu, bytemuck::cast_slice(&self.gpu_directional))?;
        if !self.gpu_faces.is_empty() {
            grew |= self.faces.write(gpu, bytemuck::cast_slice(&self.gpu_faces))?;
        }
        if !all.is_empty() {
            grew |= self.draws.write(gpu, bytemuck::cast_slice(&all))?;
        }
        if grew {
            self.generation += 1;
        }
        self.active = true;
        self.faces_drawn = self.gpu_faces.len() as u32;
        self.pending_draw.store(self.faces_drawn > 0, Ordering::Relaxed);
        self.report.instance_faces = all.len() as u32;
        self.report.draw_calls = self.mesh_draws.len() as u32;
        self.report.atlas_size = atlas;
        self.report.atlas_bytes = u64::from(atlas).pow(2) * 4;
        self.report.atlas_occupancy = self.plan.occupancy(atlas);
        Ok(())
    }

    /// True once per frame whose maps need drawing: the first view's shadow pass draws them,
    /// the frame's other views read them.
    pub fn take_pending_draw(&self) -> bool {
        self.pending_draw.swap(false, Ordering::Relaxed)
    }

    /// Creates the atlas, or a larger one, when `size` does not fit the current one.
    fn ensure_atlas(&mut self, gpu: &GpuContext, size: u32) {
        if self.atlas.as_ref().is_some_and(|t| t.width() >= size) {
            return;
        }
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("shadow_atlas"),
            size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: SHADOW_ATLAS_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        self.atlas_view = Some(texture.create_view(&Default::default()));
        self.atlas = Some(texture);
        self.generation += 1;
        // A new texture holds no map.
        self.cache.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::CascadeShadowConfig;

    #[test]
    fn a_face_projects_its_axis_to_the_centre_and_its_edges_to_the_tile() {
        let light = Vec3::new(1.0, 2.0, 3.0);
        let (near, far) = (0.01, 10.0);
        for face in 0..SHADOW_FACES {
            let (axis, sign) = face_axis(face);
            let m = face_clip_from_world(light, face, near, far);
            let ahead = light + Vec3::AXES[axis] * sign * 2.0;
            let c = m * ahead.extend(1.0);
            assert!((c.x / c.w).abs() < 1e-6 && (c.y / c.w).abs() < 1e-6, "face {face}: {c}");
            assert!((c.z / c.w - face_depth(2.0, near, far)).abs() < 1e-6);
            // A point on the next axis at 45° is on the face's edge x = 1.
            let edge = ahead + Vec3::AXES[(axis + 1) % 3] * 2.0;
            let c = m * edge.extend(1.0);
            assert!((c.x / c.w - 1.0).abs() < 1e-6, "face {face}: {c}");
            assert!(box_meets_face(light, face, &Aabb { min: ahead - 0.1, max: ahead + 0.1 }));
            assert!(!box_meets_face(
                light,
                face,
                &Aabb { min: light - ahead + light - 0.1, max: light - ahead + light + 0.1 }
            ));
        }
        assert!((face_depth(near, near, far) - 1.0).abs() < 1e-6);
        assert_eq!(face_depth(far, near, far), 0.0);
    }

    #[test]
    fn tiles_map_the_face_square_onto_their_texels() {
        let [sx, ox, sy, oy] = tile_transform(64, 32, 16, 256);
        // Face corner (-1, 1) (u = 0, top row) lands on texel (64, 32).
        let to_texel = |x: f32| ((x * sx + ox) * 0.5 + 0.5) * 256.0;
        assert!((to_texel(-1.0) - 64.0).abs() < 1e-4);
        assert!((to_texel(1.0) - 80.0).abs() < 1e-4);
        let row = |y: f32| (0.5 - 0.5 * (y * sy + oy)) * 256.0;
        assert!((row(1.0) - 32.0).abs() < 1e-4);
        assert!((row(-1.0) - 48.0).abs() < 1e-4);
    }

    /// A cascade holds its whole slice of the view and every caster between it and the light,
    /// and a camera moved by less than a texel moves the cascade's grid by whole texels.
    #[test]
    fn a_cascade_holds_its_slice_and_its_casters_on_a_stable_grid() {
        let camera = |at: Vec3| ExtractedCamera {
            world_from_view: Mat4::from_translation(at) * Mat4::from_rotation_y(0.4),
            projection: manylight_core::Projection::default(),
            prev_clip_from_world: None,
            bloom: None,
            motion_blur: None,
            exposure: None,
        };
        let direction = Vec3::new(0.3, -1.0, 0.2).normalize();
        let casters = Aabb { min: Vec3::new(-50.0, -1.0, -50.0), max: Vec3::new(50.0, 30.0, 50.0) };
        let slice = ViewSlice { near: 2.0, far: 10.0 };
        let cam = camera(Vec3::new(1.0, 2.0, 3.0));
        let fit = fit_cascade(&cam, 16.0 / 9.0, slice, direction, Some(&casters), 1024);
        let inside = |p: Vec3| {
            let c = fit.clip_from_world.transform_point3(p);
            c.x.abs() <= 1.0 + 1e-4 && c.y.abs() <= 1.0 + 1e-4 && (-1e-4..=1.0 + 1e-4).contains(&c.z)
        };
        let (w, h) = ((0.5f32 * 60f32.to_radians()).tan() * 16.0 / 9.0, (0.5f32 * 60f32.to_radians()).tan());
        for d in [2.0, 6.0, 10.0] {
            for (x, y) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0), (0.0, 0.0)] {
                let p = cam.world_from_view.transform_point3(Vec3::new(x * w * d, y * h * d, -d));
                assert!(inside(p), "slice point {p} at {d}");
            }
        }
        // A caster high above the slice, towards the light, is still in front of the map (z at
        // most 1); with depth clamped it lies beyond the near side, and is clamped onto it.
        let centre = cam.world_from_view.transform_point3(Vec3::new(0.0, 0.0, -6.0));
        let above = centre - direction * ((29.0 - centre.y) / -direction.y);
        assert!(fit.clip_from_world.transform_point3(above).z <= 1.0 + 1e-4);
        let clamped = fit_cascade(&cam, 16.0 / 9.0, slice, direction, None, 1024);
        assert!(clamped.clip_from_world.transform_point3(above).z > 1.0);
        assert!((clamped.clip_from_world.transform_point3(centre).z - 0.5).abs() < 0.2);
        assert!(clamped.depth_range < fit.depth_range);
        assert!(box_meets_clip(&fit.clip_from_world, &Aabb { min: above - 0.1, max: above + 0.1 }));
        assert!(!box_meets_clip(&fit.clip_from_world, &Aabb { min: centre + 100.0, max: centre + 101.0 }));
        assert!((fit.texel - fit.depth_range).abs() > 0.0 && fit.texel > 0.0);
        // Moved by a third of a texel: same size, the grid shifted by whole texels.
        let moved = fit_cascade(
            &camera(Vec3::new(1.0 + fit.texel / 3.0, 2.0, 3.0)),
            16.0 / 9.0,
            slice,
            direction,
            Some(&casters),
            1024,
        );
        assert_eq!(moved.texel, fit.texel);
        let shift = (moved.clip_from_world.w_axis.x - fit.clip_from_world.w_axis.x) / 2.0 * 1024.0;
        assert!((shift - shift.round()).abs() < 1e-2, "a shift of {shift} texels");
    }

    #[test]
    fn a_device_with_small_textures_caps_the_atlas_and_says_so() {
        assert_eq!(atlas_limit(8192, 16384), (8192, false));
        assert_eq!(atlas_limit(8192, 8192), (8192, false));
        assert_eq!(atlas_limit(8192, 4096), (4096, true));
        assert_eq!(atlas_limit(8192, 3000), (2048, true), "a power of two below the limit");
        assert_eq!(atlas_limit(8192, 0), (1, true));
    }

    /// Lights and faces no view sees are found (and nothing a view sees is lost).
    #[test]
    fn unseen_lights_and_faces_are_found_conservatively() {
        // A camera at the origin looking down -Z.
        let clip = manylight_core::Projection::default().matrix(1.0);
        let frustums = [frustum_planes(&clip)];
        assert!(sphere_in_view(&frustums, Vec3::new(0.0, 0.0, -10.0), 1.0));
        assert!(!sphere_in_view(&frustums, Vec3::new(0.0, 0.0, 10.0), 1.0), "behind the camera");
        assert!(sphere_in_view(&frustums, Vec3::new(0.0, 0.0, 0.5), 1.0), "around the camera");
        assert!(!sphere_in_view(&frustums, Vec3::new(30.0, 0.0, -10.0), 1.0), "far to the right");
        assert!(!sphere_in_view(&[], Vec3::ZERO, 1.0), "no view sees anything");
        // A light behind the camera: its -Z face looks into the view, its +Z face away.
        let light = Vec3::new(0.0, 0.0, 3.0);
        assert!(face_in_view(&frustums, light, 5, 5.0), "-Z face");
        assert!(!face_in_view(&frustums, light, 4, 5.0), "+Z face");
        // A light inside the view: every face holds seen points.
        assert!((0..SHADOW_FACES).all(|f| face_in_view(&frustums, Vec3::new(0.0, 0.0, -5.0), f, 2.0)));
        // Beside the view, to its left and level with it: only the +X face looks into it.
        let left = Vec3::new(-20.0, 0.0, -10.0);
        let seen: Vec<u32> = (0..SHADOW_FACES).filter(|&f| face_in_view(&frustums, left, f, 30.0)).collect();
        assert!(seen.contains(&0) && !seen.contains(&1), "{seen:?}");
    }

    #[test]
    fn cascade_bounds_grow_geometrically_as_bevy_builds_them() {
        use crate::settings::{CascadeConfigError, CascadeShadowConfigBuilder};
        let c = CascadeShadowConfig::default();
        assert_eq!(c.count, 4);
        let b = c.far_bounds();
        assert!((b[0] - 5.0).abs() < 1e-5 && (b[3] - 150.0).abs() < 1e-3);
        assert!((b[1] / b[0] - b[2] / b[1]).abs() < 1e-3, "{b:?}");
        assert!((c.near_bound(1) - 4.0).abs() < 1e-5 && c.near_bound(0) == 0.1);
        let one = CascadeShadowConfigBuilder { num_cascades: 1, ..Default::default() }.build().unwrap();
        assert_eq!(one.far_bounds(), &[150.0]);
        let bad = |b: CascadeShadowConfigBuilder| b.build().unwrap_err();
        assert_eq!(
            bad(CascadeShadowConfigBuilder { num_cascades: 5, ..Default::default() }),
            CascadeConfigError::Count(5)
        );
        assert!(matches!(
            bad(CascadeShadowConfigBuilder { first_cascade_far_bound: 200.0, ..Default::default() }),
            CascadeConfigError::Distances { .. }
        ));
        assert!(matches!(
            bad(CascadeShadowConfigBuilder { maximum_distance: f32::NAN, ..Default::default() }),
            CascadeConfigError::Distances { .. }
        ));
        assert_eq!(
            bad(CascadeShadowConfigBuilder { overlap_proportion: 1.0, ..Default::default() }),
            CascadeConfigError::Overlap(1.0)
        );
    }

    fn requests(edges: &[u32]) -> Vec<ShadowRequest> {
        edges
            .iter()
            .enumerate()
            .map(|(i, &edge)| ShadowRequest {
                caster: ShadowCaster::Point(i as u32),
                edge,
                importance: edge as f32 + i as f32 * 1e-3,
            })
            .collect()
    }

    fn no_overlap(plan: &AtlasPlan) {
        let rect = |p: &ShadowPlacement| (p.x, p.y, p.x + 3 * p.edge, p.y + 2 * p.edge);
        for (i, a) in plan.placements.iter().enumerate() {
            let ra = rect(a);
            assert!(ra.2 <= plan.atlas_size && ra.3 <= plan.atlas_size, "{a:?} outside {}", plan.atlas_size);
            for b in &plan.placements[i + 1..] {
                let rb = rect(b);
                let apart = ra.2 <= rb.0 || rb.2 <= ra.0 || ra.3 <= rb.1 || rb.3 <= ra.1;
                assert!(apart, "{a:?} overlaps {b:?}");
            }
        }
    }

    /// A full atlas: 300 lights asking 16 to 256.
    fn crowd(shift: u32) -> Vec<ShadowRequest> {
        requests(&(0..300).map(|i| 16 << ((i * 7 + shift) % 5)).collect::<Vec<u32>>())
    }

    #[test]
    fn lights_keep_their_blocks_while_their_edges_hold() {
        let mut alloc = BlockAllocator::new(2048, 16);
        let first = place_stably(&mut alloc, &plan_atlas(&crowd(0), 2048, 16), &crowd(0));
        no_overlap(&first);
        assert_eq!(first.placements.len() + first.dropped as usize, 300);
        // The same frame again: every light where it was.
        let again = place_stably(&mut alloc, &plan_atlas(&crowd(0), 2048, 16), &crowd(0));
        assert_eq!(first.placements, again.placements);
        // Two lights leave, one arrives and the importances change: the rest stay.
        let mut next = crowd(0);
        next.retain(|r| !matches!(r.caster, ShadowCaster::Point(3 | 150)));
        next.push(ShadowRequest { caster: ShadowCaster::Point(999), edge: 64, importance: 1e6 });
        for (i, r) in next.iter_mut().enumerate() {
            r.importance += (i % 3) as f32;
        }
        let moved = place_stably(&mut alloc, &plan_atlas(&next, 2048, 16), &next);
        no_overlap(&moved);
        let before: HashMap<ShadowCaster, ShadowPlacement> =
            first.placements.iter().map(|p| (p.caster, *p)).collect();
        let stayed = moved.placements.iter().filter(|p| before.get(&p.caster) == Some(p)).count();
        assert!(stayed * 10 >= moved.placements.len() * 9, "{stayed} of {} stayed", moved.placements.len());
        assert!(moved.placements.iter().any(|p| p.caster == ShadowCaster::Point(999)));
    }

    #[test]
    fn the_atlas_grows_to_hold_every_request_as_asked() {
        let plan = plan_atlas(&requests(&[64, 32, 32, 16, 16, 16]), 4096, 16);
        assert_eq!(plan.atlas_size, 256);
        assert_eq!((plan.downgraded, plan.dropped), (0, 0));
        assert_eq!(plan.placements.len(), 6);
        no_overlap(&plan);
        // Blocks of 1536 × 1024: one a row at 2048, two at 4096.
        let plan = plan_atlas(&requests(&[512; 4]), 4096, 16);
        assert_eq!(plan.atlas_size, 4096);
        no_overlap(&plan);
    }

    #[test]
    fn a_full_atlas_halves_the_largest_then_drops_the_least_important_and_counts_both() {
        // 10 lights at 512 need 10 blocks of 1536 × 1024: four fit a 4096 atlas.
        let plan = plan_atlas(&requests(&[512; 10]), 4096, 16);
        assert_eq!(plan.placements.len(), 10);
        no_overlap(&plan);
        // Halved to 256 all ten fill 23 % of the atlas; the room left goes back to the most
        // important (the last requests), as much as fits.
        let at = |edge| plan.placements.iter().filter(|p| p.edge == edge).count();
        assert_eq!(at(512) + at(256), 10, "{plan:?}");
        assert!(at(512) >= 2, "{plan:?}");
        assert_eq!(plan.downgraded as usize, at(256));
        let most = plan.placements.iter().filter(|p| p.edge == 512).map(|p| p.caster).min().unwrap();
        assert!(
            plan.placements.iter().filter(|p| p.edge == 256).all(|p| p.caster < most),
            "the larger faces went to the most important: {plan:?}"
        );
        assert!(plan.occupancy(4096) > 0.4, "{}", plan.occupancy(4096));
        // 100 000 lights at the smallest edge cannot all fit: the most important stay.
        let many = requests(&vec![16; 100_000]);
        let plan = plan_atlas(&many, 1024, 16);
        let capacity = (1024 / 48) * (1024 / 32);
        assert_eq!(plan.placements.len(), capacity as usize);
        assert_eq!(plan.dropped, 100_000 - capacity);
        assert!(
            plan.placements.iter().all(|p| p.caster >= ShadowCaster::Point(100_000 - capacity)),
            "the most important are kept"
        );
        no_overlap(&plan);
    }

    #[test]
    fn requested_edges_follow_the_projected_size() {
        let settings = ShadowSettings::default();
        let camera = ExtractedCamera {
            world_from_view: Mat4::IDENTITY,
            projection: Default::default(),
            prev_clip_from_world: None,
            bloom: None,
            motion_blur: None,
            exposure: None,
        };
        let size = UVec2::new(1280, 720);
        let near = requested_edge(&settings, Some((&camera, size)), Vec3::new(0.0, 0.0, -5.0), 1.0);
        let far = requested_edge(&settings, Some((&camera, size)), Vec3::new(0.0, 0.0, -80.0), 1.0);
        assert!(near > far, "{near} vs {far}");
        assert_eq!(far, 16);
        assert_eq!(requested_edge(&settings, Some((&camera, size)), Vec3::ZERO, 1.0), 512, "camera inside");
        assert!(ShadowSettings { min_face_size: 24, ..settings }.check_values().is_err());
        assert!(ShadowSettings { min_face_size: 1024, ..settings }.check_values().is_err());
        assert!(settings.check_values().is_ok());
    }
}
