//! Tangent generation with a bounded cost: MikkTSpace where its cost on the mesh is bounded,
//! per-vertex UV derivatives elsewhere.
//!
//! `bevy_mikktspace` (with its default features, byte-compatible with the C MikkTSpace) does
//! work that grows faster than the mesh in five places, all driven by topology rather than
//! size:
//! 1. Welding (`weld_vertices_legacy.rs`): corners are bucketed along the bounding box's
//!    longest axis and split recursively at the midpoint of each part's box; a part whose box
//!    can no longer be split (all its positions equal, or a float apart) compares every
//!    corner with the ones before it until it finds an equal (position, normal, uv): quadratic
//!    in the corners of one position when they are not all equal.
//! 2. Neighbour pairing (`build_neighbors`): corners sharing the same welded edge are matched
//!    by scanning every later one for an unpaired edge of opposite winding: quadratic in the
//!    triangles on one edge (one triangle repeated n times: n² per edge).
//! 3. Grouping (`assign_to_group_recursive`): the triangles around a welded vertex are
//!    collected by a recursion one call deep per triangle: n triangles around one vertex
//!    overflow the stack.
//! 4. Sub-groups (`generate_tangent_spaces`): for every triangle of a group, every other
//!    triangle of the group is tested and the result sorted and compared with the sub-groups
//!    found so far: quadratic in the triangles around a vertex, cubic when many of them have
//!    opposite tangent directions (which split the group into many sub-groups).
//! 5. Degenerate triangles (`generate_tangent_spaces_for_degenerate_triangles`): each corner
//!    of a zero-area triangle searches the corners of all good triangles for its welded vertex.
//!
//! `plan` bounds each of these from the mesh in O(n log n) time and memory (welding by the
//! same rule, with the same splits), without running MikkTSpace; `run_mikktspace` then runs it,
//! on a thread whose stack fits the recursions when they are deep. A mesh whose work is over
//! [`work_limit`] gets `uv_derivative_tangents` instead.
//!
//! The welded edges are sorted with the standard library's sort (the crate's
//! `corrected-edge-sorting` feature, set in the workspace): the C code's quicksort, with its
//! fixed pivot sequence, could be made quadratic and deeply recursive by a crafted face order.

use super::{MeshData, sanitize_tangent};
use glam::{DVec2, DVec3, Vec3, Vec4};
use std::fmt;

/// How [`MeshData::generate_tangents`] made the tangents.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TangentMethod {
    /// MikkTSpace (`bevy_mikktspace`), the basis the glTF specification asks for.
    MikkTSpace,
    /// Per-vertex UV derivatives, because MikkTSpace could not run in bounded time on this
    /// mesh; the reason says why.
    UvDerivatives(TangentFallback),
}

/// Why [`MeshData::generate_tangents`] did not use MikkTSpace.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TangentFallback {
    /// An index is out of range, an attribute is NaN or infinite, or a coordinate's magnitude
    /// is over [`MAX_COORDINATE`] (MikkTSpace's welding would overflow).
    UnusableData,
    /// MikkTSpace's work beyond its linear part, estimated from the topology, is over the
    /// bound ([`work_limit`]).
    TooCostly {
        /// Estimated work units (a lower bound when the estimate stopped at the limit).
        estimated: u64,
        /// The bound for this mesh.
        limit: u64,
    },
    /// The thread that runs MikkTSpace with the stack it needs could not be started.
    NoThread,
    /// MikkTSpace panicked.
    Panicked,
}

impl fmt::Display for TangentFallback {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::UnusableData => {
                write!(f, "an index is out of range or an attribute is non-finite or too large")
            }
            Self::TooCostly { estimated, limit } => write!(
                f,
                "MikkTSpace's work on this topology is estimated at {estimated} units or more, \
                 over the bound of {limit} (many triangles around one vertex or on one edge, \
                 many corners at one position, or many degenerate triangles)"
            ),
            Self::NoThread => write!(f, "the thread to run MikkTSpace on could not be started"),
            Self::Panicked => write!(f, "MikkTSpace panicked"),
        }
    }
}

/// Largest coordinate magnitude MikkTSpace is run on: its welding adds two coordinates, which
/// must not overflow `f32`.
pub const MAX_COORDINATE: f32 = 1e30;

/// Work units MikkTSpace may spend per corner (3 per triangle) on top of [`WORK_BASE`].
///
/// One unit is about one inner-loop step (a comparison, a projection, a swap). Ordinary meshes
/// (valence around 6, vertices shared by up to a few dozen triangles) estimate at 100 to 300
/// units per corner; the bound leaves a wide margin for them and keeps the worst accepted mesh
/// within a small multiple of MikkTSpace's time on an ordinary mesh of the same size.
pub const WORK_PER_CORNER: u64 = 1024;

/// Work units any mesh may use, however small (about the cost of starting a thread). Kept
/// small so that splitting a hostile mesh into many small ones gains nothing: the bound
/// grows with the corners, not with the number of meshes.
pub const WORK_BASE: u64 = 1 << 16;

/// The work bound for a mesh of `corners` corners: [`WORK_BASE`] + [`WORK_PER_CORNER`] per corner.
pub fn work_limit(corners: u64) -> u64 {
    WORK_BASE.saturating_add(WORK_PER_CORNER.saturating_mul(corners))
}

/// Units per corner of a welding split (bounding box and partition).
const WELD_SPLIT_UNITS: u64 = 2;
/// Units per comparison of two corners in a welding leaf (four attribute reads).
const WELD_COMPARE_UNITS: u64 = 4;
/// Units per step of an edge-pairing scan (it finds the edge in both triangles).
const EDGE_SCAN_UNITS: u64 = 12;
/// Units per corner a degenerate triangle's corner scans.
const DEGENERATE_SCAN_UNITS: u64 = 4;
/// Units per pair of triangles in a group's sub-group test (two projections and two dots).
const GROUP_PAIR_UNITS: u64 = 12;

/// Stack the MikkTSpace thread gets beyond its recursions.
const STACK_BASE: usize = 256 << 10;
/// Stack allowed per recursion level: generous, the grouping recursion's frames are about
/// 150 bytes in an optimised build.
const FRAME: usize = 1 << 10;
/// Recursions estimated to need at most this much stack run on the caller's thread; deeper
/// ones on a thread of their own.
const INLINE_STACK: usize = 128 << 10;

/// What [`plan`] found: MikkTSpace runs within its bounds on this mesh.
#[derive(Debug)]
pub(super) struct Plan {
    /// Estimated work units beyond the linear part (the tests check its margin).
    #[cfg_attr(not(test), allow(dead_code))]
    pub work: u64,
    /// Deepest recursion MikkTSpace may reach: welding splits, triangles around one vertex
    /// (grouping), and an allowance for its edge quicksort.
    pub levels: usize,
}

/// Dense ids (0, 1, ...) for `keys`: equal keys get equal ids. Returns the ids and how many
/// distinct keys there are. O(n log n).
fn dense_ids<K: Ord + Copy>(keys: impl Iterator<Item = K>) -> (Vec<u32>, usize) {
    let mut order: Vec<(K, u32)> = keys.zip(0..).collect();
    order.sort_unstable();
    let mut ids = vec![0u32; order.len()];
    let mut next = 0u32;
    for k in 0..order.len() {
        if k > 0 && order[k - 1].0 != order[k].0 {
            next += 1;
        }
        ids[order[k].1 as usize] = next;
    }
    let distinct = if order.is_empty() { 0 } else { next as usize + 1 };
    (ids, distinct)
}

/// The bits of `x` with -0 made +0, so that equal bits mean `==` (for finite values).
fn canonical(x: f32) -> u32 {
    (x + 0.0).to_bits()
}

/// A running work estimate that stops at its limit.
struct Work {
    used: u64,
    limit: u64,
}

impl Work {
    /// Adds `units`; an error once the total is over the limit.
    fn add(&mut self, units: u64) -> Result<(), TangentFallback> {
        self.used = self.used.saturating_add(units);
        if self.used > self.limit {
            return Err(TangentFallback::TooCostly { estimated: self.used, limit: self.limit });
        }
        Ok(())
    }
}

/// A distinct corner position for the welding estimate.
#[derive(Clone, Copy)]
struct Point {
    p: [f32; 3],
    /// Corners at this position.
    corners: u64,
    /// Distinct (position, normal, uv) among them.
    classes: u64,
}

/// The axis MikkTSpace's welder splits along for a box of extent `d` (the longest, ties to
/// x then z, as it breaks them).
fn split_axis(d: [f32; 3]) -> usize {
    if d[1] > d[0] && d[1] > d[2] {
        1
    } else if d[2] > d[0] {
        2
    } else {
        0
    }
}

/// Bounding box of points.
fn bounds(points: &[Point]) -> ([f32; 3], [f32; 3]) {
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for q in points {
        for c in 0..3 {
            min[c] = min[c].min(q.p[c]);
            max[c] = max[c].max(q.p[c]);
        }
    }
    (min, max)
}

/// The welding's work and recursion depth: the same bucketing (2 048 slabs along the longest
/// axis) and the same midpoint splits as `bevy_mikktspace`'s welder, on distinct positions
/// weighted by their corners (equal positions always end in the same part, so the parts
/// depend only on the set of positions). Work per split is its corners; a leaf costs its
/// corners when they are all one (position, normal, uv), else one comparison per pair.
fn weld_work(points: &mut [Point], work: &mut Work) -> Result<usize, TangentFallback> {
    const GROUPS: u16 = 2048;
    if points.is_empty() {
        return Ok(0);
    }
    let (min, max) = bounds(points);
    let d = [max[0] - min[0], max[1] - min[1], max[2] - min[2]];
    let c = split_axis(d);
    let bucket = |q: &Point| {
        let t = (q.p[c] - min[c]) / d[c];
        let group = (GROUPS as f32 * t.clamp(0.0, 1.0)) as u16;
        group.clamp(0, GROUPS - 1)
    };
    points.sort_unstable_by_key(bucket);
    let mut depth_max = 0;
    let mut stack: Vec<(usize, usize, usize)> = Vec::new();
    let mut start = 0;
    while start < points.len() {
        let b = bucket(&points[start]);
        let end = start + points[start..].iter().take_while(|q| bucket(q) == b).count();
        stack.push((start, end, 1));
        while let Some((s, e, depth)) = stack.pop() {
            let part = &mut points[s..e];
            let corners: u64 = part.iter().map(|q| q.corners).sum();
            if corners < 2 {
                continue;
            }
            depth_max = depth_max.max(depth);
            let (min, max) = bounds(part);
            let d = [max[0] - min[0], max[1] - min[1], max[2] - min[2]];
            let c = split_axis(d);
            let sep = 0.5f32 * (max[c] + min[c]);
            if !sep.is_finite() {
                return Err(TangentFallback::UnusableData);
            }
            if !(min[c] < sep && sep < max[c]) {
                let classes: u64 = part.iter().map(|q| q.classes).sum();
                let pairs = corners.saturating_mul(corners - 1) / 2;
                work.add(if classes <= 1 { corners } else { pairs.saturating_mul(WELD_COMPARE_UNITS) })?;
                continue;
            }
            work.add(corners.saturating_mul(WELD_SPLIT_UNITS))?;
            // Both sides are non-empty: `sep` lies strictly inside the box along `c`.
            let mut left = 0;
            for k in 0..part.len() {
                if part[k].p[c] < sep {
                    part.swap(left, k);
                    left += 1;
                }
            }
            stack.push((s, s + left, depth + 1));
            stack.push((s + left, e, depth + 1));
        }
        start = end;
    }
    Ok(depth_max)
}

/// The tangent directions MikkTSpace's sub-group test compares for triangle `tri` at a vertex
/// of normal `n`, as angles in the tangent plane (`basis`); `None` when the triangle takes no
/// part in the test (zero uv area: it joins any group), `Some(None)` when its directions are
/// numerically unreliable (they may compare as opposite to anything).
fn tangent_angles(
    mesh: &MeshData,
    tri: [u32; 3],
    n: DVec3,
    basis: (DVec3, DVec3),
) -> Option<Option<[f64; 2]>> {
    let v = tri.map(|i| &mesh.vertices[i as usize]);
    // The same f32 arithmetic as MikkTSpace, so the zero-area decision is the same.
    let d_tx = [1, 2].map(|k| [0, 1].map(|i| v[k].uv[i] - v[0].uv[i]));
    let d_v = [1, 2].map(|k| [0, 1, 2].map(|i| v[k].position[i] - v[0].position[i]));
    let signed_area = d_tx[0][0] * d_tx[1][1] - d_tx[0][1] * d_tx[1][0];
    if signed_area.abs() <= f32::MIN_POSITIVE {
        return None;
    }
    let sign = if signed_area > 0.0 { 1.0 } else { -1.0 };
    let dv = d_v.map(|d| DVec3::new(d[0].into(), d[1].into(), d[2].into()));
    let (a, b) = (dv[0] * f64::from(d_tx[1][1]), dv[1] * f64::from(d_tx[0][1]));
    let (c, d) = (dv[0] * -f64::from(d_tx[1][0]), dv[1] * -f64::from(d_tx[0][0]));
    let mut out = [0.0; 2];
    // The tangent a - b and the bitangent c - d, as MikkTSpace forms them.
    for (k, (x, y)) in [(a, b), (c, d)].into_iter().enumerate() {
        let s = (x - y) * sign;
        let len = s.length();
        // Cancellation, or lengths whose f32 squares under- or overflow: the f32 direction
        // MikkTSpace computes may point anywhere.
        if !(len > 1e-3 * (x.length() + y.length()) && (1e-15..1e15).contains(&len)) {
            return Some(None);
        }
        let s = s / len;
        let projected = s - n * n.dot(s);
        if projected.length() < 1e-3 {
            return Some(None);
        }
        out[k] = projected.dot(basis.1).atan2(projected.dot(basis.0));
    }
    Some(Some(out))
}

/// Angle bins around the circle for the opposite-direction test.
const ANGLE_BINS: i64 = 4096;

/// Buffers [`split_candidates`] reuses from one vertex to the next.
#[derive(Default)]
struct SplitScratch {
    angles: Vec<[f64; 2]>,
    bins: [Vec<i64>; 2],
}

/// Groups of at most this many triangles are not tested for sub-group splits: every triangle
/// is counted as one (a cost of at most this many cubed per vertex).
const SPLIT_TEST_MIN: usize = 9;

/// How many of the triangles `tris` around a vertex of normal `normal` may end up in a
/// sub-group of their own: MikkTSpace splits a group where two triangles' tangent (or
/// bitangent) directions, projected on the vertex's tangent plane, are exactly opposite.
/// Directions within two bins (about 0.2°) of opposite count, and when any direction is
/// unreliable all of them do.
fn split_candidates(mesh: &MeshData, tris: &[u32], normal: [f32; 3], scratch: &mut SplitScratch) -> u64 {
    let all = tris.len() as u64;
    let n = Vec3::from(normal).as_dvec3();
    if tris.len() < SPLIT_TEST_MIN || (n.length_squared() - 1.0).abs() > 1e-3 {
        return all;
    }
    let basis = n.any_orthonormal_pair();
    let angles = &mut scratch.angles;
    angles.clear();
    for &f in tris {
        let tri = [0, 1, 2].map(|k| mesh.indices[f as usize * 3 + k]);
        match tangent_angles(mesh, tri, n, basis) {
            None => {}
            Some(None) => return all,
            Some(Some(a)) => angles.push(a),
        }
    }
    let bin =
        |a: f64| ((a + std::f64::consts::PI) / std::f64::consts::TAU * ANGLE_BINS as f64).floor() as i64;
    for (k, bins) in scratch.bins.iter_mut().enumerate() {
        bins.clear();
        bins.extend(angles.iter().map(|a| bin(a[k]).rem_euclid(ANGLE_BINS)));
        bins.sort_unstable();
        bins.dedup();
    }
    let bins = &scratch.bins;
    let opposed = |k: usize, a: f64| {
        let b = bin(a) + ANGLE_BINS / 2;
        (-2..=2).any(|o| bins[k].binary_search(&(b + o).rem_euclid(ANGLE_BINS)).is_ok())
    };
    angles.iter().filter(|a| opposed(0, a[0]) || opposed(1, a[1])).count() as u64
}

/// Checks that MikkTSpace runs on `mesh` within [`work_limit`] and finds the stack it needs.
pub(super) fn plan(mesh: &MeshData) -> Result<Plan, TangentFallback> {
    let faces = mesh.indices.len() / 3;
    let tris = &mesh.indices[..faces * 3];
    check_usable(&mesh.vertices, tris)?;
    let corners = tris.len() as u64;
    let mut work = Work { used: 0, limit: work_limit(corners) };

    // Welded vertices: MikkTSpace welds corners with equal position, normal and uv.
    let (pos_id, positions) = dense_ids(mesh.vertices.iter().map(|v| v.position.map(canonical)));
    let (class_id, classes) = dense_ids(mesh.vertices.iter().zip(&pos_id).map(|(v, &p)| {
        let [nx, ny, nz] = v.normal.map(canonical);
        let [u, w] = v.uv.map(canonical);
        [p, nx, ny, nz, u, w]
    }));
    let welded = Welded { tris, class_id, classes };

    let mut points = weld_points(&mesh.vertices, &welded, &pos_id, positions);
    let weld_depth = weld_work(&mut points, &mut work)?;
    drop(points);

    // Good triangles: no two corners at the same position (the others are "degenerate").
    let good: Vec<u32> = (0..faces as u32)
        .filter(|&f| {
            let p = [0, 1, 2].map(|k| pos_id[tris[f as usize * 3 + k] as usize]);
            p[0] != p[1] && p[1] != p[2] && p[0] != p[2]
        })
        .collect();
    drop(pos_id);

    pairing_work(&welded, &good, &mut work)?;
    let valence_max = group_work(mesh, &welded, &good, &mut work)?;
    if good.len() < faces {
        degenerate_work(&welded, &good, faces, &mut work)?;
    }

    let sort_levels = 4 * (corners.max(2).ilog2() as usize);
    Ok(Plan { work: work.used, levels: weld_depth + valence_max + sort_levels })
}

/// Refuses a mesh `plan` cannot estimate or MikkTSpace cannot run on: more vertices or
/// corners than `u32` ids hold, an index out of range, or a non-finite or too large attribute.
fn check_usable(vertices: &[super::Vertex], tris: &[u32]) -> Result<(), TangentFallback> {
    // Ids and offsets below are u32, as indices are.
    let too_many = vertices.len() > u32::MAX as usize || tris.len() > u32::MAX as usize;
    if too_many || tris.iter().any(|&i| i as usize >= vertices.len()) {
        return Err(TangentFallback::UnusableData);
    }
    let usable = |v: &super::Vertex| {
        v.position.iter().all(|x| x.is_finite() && x.abs() <= MAX_COORDINATE)
            && v.normal.iter().chain(&v.uv).all(|x| x.is_finite())
    };
    if !vertices.iter().all(usable) {
        return Err(TangentFallback::UnusableData);
    }
    Ok(())
}

/// The welded vertex of each corner: its (position, normal, uv) class.
struct Welded<'a> {
    /// The mesh's whole triangles' indices.
    tris: &'a [u32],
    /// Class of each vertex (dense ids).
    class_id: Vec<u32>,
    /// Number of classes.
    classes: usize,
}

impl Welded<'_> {
    /// The class of corner `corner` (an index into `tris`).
    fn of(&self, corner: usize) -> usize {
        self.class_id[self.tris[corner] as usize] as usize
    }
}

/// The distinct positions the triangles use (`pos_id`: each vertex's position id, of
/// `positions` ids), each with its corners and its welded classes, for [`weld_work`].
fn weld_points(vertices: &[super::Vertex], welded: &Welded, pos_id: &[u32], positions: usize) -> Vec<Point> {
    let (tris, class_id, classes) = (welded.tris, &welded.class_id, welded.classes);
    let mut pos_corners = vec![0u64; positions];
    let mut class_corners = vec![0u64; classes];
    for &i in tris {
        pos_corners[pos_id[i as usize] as usize] += 1;
        class_corners[class_id[i as usize] as usize] += 1;
    }
    let mut pos_vertex = vec![0u32; positions];
    let mut class_pos = vec![0u32; classes];
    for i in 0..vertices.len() {
        pos_vertex[pos_id[i] as usize] = i as u32;
        class_pos[class_id[i] as usize] = pos_id[i];
    }
    let mut pos_classes = vec![0u64; positions];
    for c in (0..classes).filter(|&c| class_corners[c] > 0) {
        pos_classes[class_pos[c] as usize] += 1;
    }
    (0..positions)
        .filter(|&p| pos_corners[p] > 0)
        .map(|p| Point {
            p: vertices[pos_vertex[p] as usize].position,
            corners: pos_corners[p],
            classes: pos_classes[p],
        })
        .collect()
}

/// Neighbour pairing: each corner of an edge shared by k of the `good` triangles scans the
/// others.
fn pairing_work(welded: &Welded, good: &[u32], work: &mut Work) -> Result<(), TangentFallback> {
    let mut edges: Vec<u64> = Vec::with_capacity(good.len() * 3);
    for &f in good {
        let c = [0, 1, 2].map(|k| welded.of(f as usize * 3 + k) as u64);
        for (a, b) in [(c[0], c[1]), (c[1], c[2]), (c[2], c[0])] {
            edges.push(a.min(b) << 32 | a.max(b));
        }
    }
    edges.sort_unstable();
    for run in edges.chunk_by(|a, b| a == b) {
        let k = run.len() as u64;
        work.add((k.saturating_mul(k - 1) / 2).saturating_mul(EDGE_SCAN_UNITS))?;
    }
    Ok(())
}

/// Groups: the `good` triangles around each welded vertex, each pair tested, and the
/// sub-group splits among them. Returns the most triangles around one vertex.
fn group_work(
    mesh: &MeshData,
    welded: &Welded,
    good: &[u32],
    work: &mut Work,
) -> Result<usize, TangentFallback> {
    let classes = welded.classes;
    let mut class_vertex = vec![0u32; classes];
    for (i, &c) in welded.class_id.iter().enumerate() {
        class_vertex[c as usize] = i as u32;
    }
    let mut offsets = vec![0u32; classes + 1];
    for &f in good {
        for k in 0..3 {
            offsets[welded.of(f as usize * 3 + k) + 1] += 1;
        }
    }
    for c in 0..classes {
        offsets[c + 1] += offsets[c];
    }
    let mut around = vec![0u32; good.len() * 3];
    let mut fill = offsets.clone();
    for &f in good {
        for k in 0..3 {
            let c = welded.of(f as usize * 3 + k);
            around[fill[c] as usize] = f;
            fill[c] += 1;
        }
    }
    drop(fill);
    let mut valence_max = 0;
    let mut scratch = SplitScratch::default();
    for c in 0..classes {
        let tris_around = &around[offsets[c] as usize..offsets[c + 1] as usize];
        let g = tris_around.len() as u64;
        valence_max = valence_max.max(tris_around.len());
        if g < 2 {
            continue;
        }
        // Before the (O(g log g)) split test: the quadratic part alone may be over the limit.
        let pairs = g.saturating_mul(g);
        work.add(pairs.saturating_mul(GROUP_PAIR_UNITS + u64::from(g.ilog2())))?;
        let normal = mesh.vertices[class_vertex[c] as usize].normal;
        let split = split_candidates(mesh, tris_around, normal, &mut scratch);
        work.add(pairs.saturating_mul(split))?;
    }
    Ok(valence_max)
}

/// Degenerate triangles (those of the `faces` not in `good`): each corner scans the good
/// triangles' corners, in face order, up to the first of its welded vertex (or all of them).
fn degenerate_work(
    welded: &Welded,
    good: &[u32],
    faces: usize,
    work: &mut Work,
) -> Result<(), TangentFallback> {
    let mut first = vec![u64::MAX; welded.classes];
    for (rank, &f) in good.iter().enumerate() {
        for k in 0..3 {
            let c = welded.of(f as usize * 3 + k);
            first[c] = first[c].min(rank as u64 * 3 + k as u64);
        }
    }
    let good_corners = good.len() as u64 * 3;
    let mut is_good = vec![false; faces];
    for &f in good {
        is_good[f as usize] = true;
    }
    for f in (0..faces).filter(|&f| !is_good[f]) {
        for k in 0..3 {
            let c = welded.of(f * 3 + k);
            let scanned = if first[c] == u64::MAX { good_corners } else { first[c] + 1 };
            work.add(scanned.saturating_mul(DEGENERATE_SCAN_UNITS))?;
        }
    }
    Ok(())
}

/// `bevy_mikktspace`'s view of a mesh: one face per index triple.
struct Geometry<'a>(&'a mut MeshData);

impl bevy_mikktspace::Geometry for Geometry<'_> {
    fn num_faces(&self) -> usize {
        self.0.indices.len() / 3
    }
    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }
    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.0.vertices[self.0.indices[face * 3 + vert] as usize].position
    }
    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.0.vertices[self.0.indices[face * 3 + vert] as usize].normal
    }
    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.0.vertices[self.0.indices[face * 3 + vert] as usize].uv
    }
    fn set_tangent(
        &mut self,
        tangent_space: Option<bevy_mikktspace::TangentSpace>,
        face: usize,
        vert: usize,
    ) {
        let i = self.0.indices[face * 3 + vert] as usize;
        self.0.vertices[i].tangent =
            tangent_space.map_or([0.0; 4], |t| sanitize_tangent(Vec4::from(t.tangent_encoded())));
    }
}

/// Runs MikkTSpace on `mesh` (whose tangents are all zero): on the caller's thread when the
/// recursion `plan` found is shallow, else on a thread with a stack that fits it.
pub(super) fn run_mikktspace(mesh: &mut MeshData, plan: &Plan) -> Result<(), TangentFallback> {
    let run = |mesh: &mut MeshData| {
        // The error type has no variants: generation cannot fail.
        let _ = bevy_mikktspace::generate_tangents(&mut Geometry(mesh));
    };
    let recursion = plan.levels.saturating_mul(FRAME);
    if recursion <= INLINE_STACK {
        return std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| run(mesh)))
            .map_err(|_| TangentFallback::Panicked);
    }
    std::thread::scope(|scope| {
        let thread = std::thread::Builder::new()
            .name("mikktspace".into())
            .stack_size(STACK_BASE.saturating_add(recursion))
            .spawn_scoped(scope, || run(mesh))
            .map_err(|_| TangentFallback::NoThread)?;
        thread.join().map_err(|_| TangentFallback::Panicked)
    })
}

/// Per-vertex tangents from UV derivatives (Lengyel's method), in O(n): each triangle's
/// derivatives of position along u and v, weighted by its UV area, are summed at its
/// vertices; the sum along u is made orthogonal to the normal (Gram-Schmidt) and normalised,
/// and the handedness is the sign of the summed v derivative along `cross(normal, tangent)`.
/// Triangles with zero UV area, or out-of-range indices, add nothing; a vertex with no usable
/// frame gets an all-zero tangent. Computed in f64, so no intermediate overflows.
pub(super) fn uv_derivative_tangents(mesh: &mut MeshData) {
    let n = mesh.vertices.len();
    let mut along_u = vec![DVec3::ZERO; n];
    let mut along_v = vec![DVec3::ZERO; n];
    for tri in mesh.indices.chunks_exact(3) {
        if tri.iter().any(|&i| i as usize >= n) {
            continue;
        }
        let v = [0, 1, 2].map(|k| &mesh.vertices[tri[k] as usize]);
        let p = v.map(|v| Vec3::from(v.position).as_dvec3());
        let uv = v.map(|v| DVec2::new(v.uv[0].into(), v.uv[1].into()));
        let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
        let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
        let det = d1.x * d2.y - d2.x * d1.y;
        if det == 0.0 || !det.is_finite() {
            continue;
        }
        // (e1 d2.y - e2 d1.y) / det is dP/du; times |det| it is weighted by the UV area.
        let sign = det.signum();
        let du = (e1 * d2.y - e2 * d1.y) * sign;
        let dv = (e2 * d1.x - e1 * d2.x) * sign;
        if !(du.is_finite() && dv.is_finite()) {
            continue;
        }
        for &i in tri {
            along_u[i as usize] += du;
            along_v[i as usize] += dv;
        }
    }
    for (vertex, (u, v)) in mesh.vertices.iter_mut().zip(along_u.into_iter().zip(along_v)) {
        let normal = Vec3::from(vertex.normal).as_dvec3();
        let t = u - normal * normal.dot(u);
        vertex.tangent = match t.try_normalize() {
            Some(t) if u.is_finite() && v.is_finite() => {
                let w = if normal.cross(t).dot(v) < 0.0 { -1.0 } else { 1.0 };
                sanitize_tangent(t.as_vec3().extend(w))
            }
            _ => [0.0; 4],
        };
    }
}

#[cfg(test)]
mod tests;
