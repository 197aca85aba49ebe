//! Scene geometry as a two-level bounding volume hierarchy laid out for tracing shadow rays in a
//! compute or fragment shader, and the CPU twin of that shader's traversal.
//!
//! - **Mesh level.** Each mesh's triangles, in the mesh's own space, get one binary BVH
//!   (`obvhs`'s PLOC builder with reinsertion), built once when the mesh is first traced and
//!   appended to [`MeshLevel`]'s arrays.
//! - **Instance level.** One binary BVH over the instances' world-space boxes, one instance a
//!   leaf ([`InstanceLevel`]), built again when an instance moves: a few hundred boxes cost
//!   far less than refitting or rebuilding any mesh.
//! - **Traversal** ([`trace`], mirrored by `shaders/common/ray_bvh.wgsl`): one loop and one
//!   short stack for both levels. A leaf of the instance level moves the ray into the mesh's
//!   space (the segment's parameter `t` is the same in both, so its end stays put) and
//!   continues in the mesh's tree; when the stack drops back to where the mesh was entered, the
//!   world ray returns. Near child first, the far one pushed; any hit ends the ray (a shadow
//!   ray needs no closest hit).
//! - **Bounded cost.** Every loop iteration (a node, or a triangle of a leaf) is a step; a ray
//!   that would take more than [`RAY_MAX_STEPS`] stops there ([`RayOutcome::Exhausted`]), as
//!   does one whose stack would grow past [`RAY_STACK_SIZE`] ([`RayOutcome::StackFull`]). Both
//!   are counted and lit (a missed shadow, never a hang): lavapipe ends an invocation silently
//!   after 65 535 loop iterations in all, so a shading invocation that traces a few rays must
//!   know each ray's most. [`InstanceLevel::stack_needed`] says beforehand whether the stack
//!   can run out.
//!
//! Decisions match the visibility oracle ([`crate::shadow_oracle`]): the same segment
//! ([`ShadowQuery::segment`]) and the same edge-inclusive triangle test, so the two disagree
//! only where a segment passes within rounding of an edge or an end.

use crate::mesh::MeshData;
use crate::shadow_oracle::{EDGE_TOLERANCE, ShadowQuery};
use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3, Vec3A, Vec4};
use obvhs::BvhBuildParams;
use obvhs::aabb::Aabb as BuildBox;
use obvhs::bvh2::Bvh2;
use obvhs::bvh2::builder::{build_bvh2, build_bvh2_from_tris};
use obvhs::triangle::Triangle;

/// Entries of a ray's traversal stack (`array<u32, RAY_STACK_SIZE>` in WGSL): far children
/// waiting while the near one is visited, across both levels.
pub const RAY_STACK_SIZE: u32 = 32;
/// Most steps (nodes visited plus triangles tested) one ray takes before it stops
/// ([`RayOutcome::Exhausted`]). Eight rays of a pixel stay far inside lavapipe's 65 535 loop
/// iterations an invocation.
pub const RAY_MAX_STEPS: u32 = 4096;
/// Most triangles a mesh-level leaf holds: a leaf's triangle loop is part of a step budget.
pub const RAY_LEAF_TRIANGLES: u32 = 4;
/// [`InstanceLevel::root`] value meaning "no node": nothing to trace.
pub const RAY_NO_NODE: u32 = u32::MAX;
/// What the box test returns for a box the ray misses: far past [`RAY_FAR`], and written as a
/// literal every WGSL compiler takes (shaders have no infinity, and Tint refuses `f32::MAX`'s
/// shortest decimal, 3.4028235e38, which lies just above it).
pub const RAY_MISS: f32 = 1e38;
/// Where every segment ends at the latest: a directional light's (infinite) segment is traced
/// this far.
pub const RAY_FAR: f32 = 1e30;

/// One node of either level (`RayNode` in `shaders/common/ray_bvh.wgsl`), 32 bytes.
///
/// `count == 0`: an inner node whose children are `nodes[first]` and `nodes[first + 1]`.
/// `count > 0`: a leaf: at the mesh level triangles `first .. first + count`, at the instance
/// level the instance `first` (`count` is 1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct BvhNode {
    /// Minimum corner of the node's box (widened a little past its contents, so rounding in the
    /// box test never misses what it holds).
    pub min: [f32; 3],
    /// Triangles or instances in a leaf; 0 for an inner node.
    pub count: u32,
    /// Maximum corner of the node's box.
    pub max: [f32; 3],
    /// First child, first triangle or the instance, by `count`.
    pub first: u32,
}

/// One triangle of a mesh, in the mesh's space, as the edge test reads it
/// (`RayTriangle` in `shaders/common/ray_bvh.wgsl`), 48 bytes: a corner and the two edges from
/// it (`w` unused).
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct RayTriangle {
    /// First corner.
    pub v0: [f32; 4],
    /// Second corner minus the first.
    pub e1: [f32; 4],
    /// Third corner minus the first.
    pub e2: [f32; 4],
}

/// One placed mesh of the instance level (`RayInstance` in `shaders/common/ray_bvh.wgsl`),
/// 64 bytes: the rows of its local-from-world transform (an affine 3 × 4) and its mesh's root
/// node.
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct RayInstance {
    /// Rows of the local-from-world transform: `local = (dot(r0, (p, 1)), dot(r1, …), dot(r2, …))`.
    pub local_from_world: [[f32; 4]; 3],
    /// Root node of the instance's mesh (an index into the mesh level's nodes).
    pub root: u32,
    /// Padding to 16 bytes.
    pub pad: [u32; 3],
}

/// How a traced ray ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RayOutcome {
    /// Nothing blocks the segment.
    Visible,
    /// A triangle blocks it.
    Blocked,
    /// It took [`RAY_MAX_STEPS`] steps without an answer: lit, and counted.
    Exhausted,
    /// Its stack would have grown past [`RAY_STACK_SIZE`]: lit, and counted.
    StackFull,
}

impl RayOutcome {
    /// The code a shader writes for it (`RAY_VISIBLE` … in `shaders/common/ray_bvh.wgsl`).
    pub fn code(self) -> u32 {
        match self {
            RayOutcome::Visible => 0,
            RayOutcome::Blocked => 1,
            RayOutcome::Exhausted => 2,
            RayOutcome::StackFull => 3,
        }
    }

    /// The outcome of a shader's code; `None` for a code no shader writes.
    pub fn from_code(code: u32) -> Option<RayOutcome> {
        [RayOutcome::Visible, RayOutcome::Blocked, RayOutcome::Exhausted, RayOutcome::StackFull]
            .into_iter()
            .find(|o| o.code() == code)
    }

    /// True when the light is treated as reaching the point.
    pub fn lit(self) -> bool {
        self != RayOutcome::Blocked
    }
}

/// A traced ray: how it ended and the steps it took.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Traced {
    /// How it ended.
    pub outcome: RayOutcome,
    /// Nodes visited plus triangles tested.
    pub steps: u32,
}

/// Where one mesh's tree lies in [`MeshLevel`]'s arrays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeshSlot {
    /// Root node; [`RAY_NO_NODE`] for a mesh with no triangle that can be hit.
    pub root: u32,
    /// Levels of the tree (1: the root is a leaf; 0: empty).
    pub depth: u32,
    /// The mesh's box in its own space (unwidened; empty for an empty mesh).
    pub bounds: crate::Aabb,
    /// Triangles kept (those with finite corners).
    pub triangles: u32,
}

/// The mesh level: every traced mesh's tree and triangles, appended as meshes arrive, so what
/// is on the GPU already never moves.
#[derive(Clone, Debug, Default)]
pub struct MeshLevel {
    /// Nodes of all meshes' trees.
    pub nodes: Vec<BvhNode>,
    /// Triangles of all meshes, each mesh's in its tree's leaf order.
    pub triangles: Vec<RayTriangle>,
}

impl MeshLevel {
    /// Appends `mesh`'s tree (its triangles with a non-finite corner are left out, degenerate
    /// ones kept: they are never hit) and says where it went.
    pub fn add_mesh(&mut self, mesh: &MeshData) -> MeshSlot {
        let corner = |i: u32| mesh.vertices.get(i as usize).map(|v| Vec3::from(v.position));
        let triangles =
            mesh.indices.chunks_exact(3).filter_map(|t| Some([corner(t[0])?, corner(t[1])?, corner(t[2])?]));
        self.add_triangles(triangles)
    }

    /// [`MeshLevel::add_mesh`] for loose triangles in one space.
    pub fn add_triangles(&mut self, triangles: impl IntoIterator<Item = [Vec3; 3]>) -> MeshSlot {
        let triangles: Vec<Triangle> = triangles
            .into_iter()
            .filter(|t| t.iter().all(|v| v.is_finite()))
            .map(|[a, b, c]| Triangle { v0: a.into(), v1: b.into(), v2: c.into() })
            .collect();
        let mut bounds = crate::Aabb::EMPTY;
        for t in &triangles {
            for v in [t.v0, t.v1, t.v2] {
                bounds.extend(v.into());
            }
        }
        if triangles.is_empty() {
            return MeshSlot { root: RAY_NO_NODE, depth: 0, bounds, triangles: 0 };
        }
        let params =
            BvhBuildParams { max_prims_per_leaf: RAY_LEAF_TRIANGLES, ..BvhBuildParams::medium_build() };
        let bvh = build_bvh2_from_tris(&triangles, params, &mut std::time::Duration::default());
        let node_base = self.nodes.len() as u32;
        let triangle_base = self.triangles.len() as u32;
        self.triangles.extend(bvh.primitive_indices.iter().map(|&i| {
            let t = &triangles[i as usize];
            let w = |v: Vec3A| [v.x, v.y, v.z, 0.0];
            RayTriangle { v0: w(t.v0), e1: w(t.v1 - t.v0), e2: w(t.v2 - t.v0) }
        }));
        self.nodes.extend(flatten(&bvh, node_base, triangle_base));
        MeshSlot { root: node_base, depth: depth(&bvh), bounds, triangles: triangles.len() as u32 }
    }

    /// Bytes of the nodes and triangles (what the GPU holds of this level).
    pub fn bytes(&self) -> u64 {
        (self.nodes.len() * size_of::<BvhNode>() + self.triangles.len() * size_of::<RayTriangle>()) as u64
    }
}

/// The instance level of one frame: a tree over the placed meshes' world boxes.
#[derive(Clone, Debug, Default)]
pub struct InstanceLevel {
    /// Nodes, their child indices already offset past the mesh level's nodes (both levels
    /// share one node array: the mesh level's, then these).
    pub nodes: Vec<BvhNode>,
    /// The placed meshes, in the order the leaves name them.
    pub instances: Vec<RayInstance>,
    /// Root node (an index into the shared node array); [`RAY_NO_NODE`] when nothing is placed.
    pub root: u32,
    /// Levels of the tree (0: empty).
    pub depth: u32,
    /// Most stack entries a ray can need: this level's depth plus its deepest placed mesh's,
    /// less one for each (a root is never pushed). Over [`RAY_STACK_SIZE`], some rays end
    /// [`RayOutcome::StackFull`].
    pub stack_needed: u32,
}

impl InstanceLevel {
    /// Builds the level over `placed` meshes (a slot from `meshes` and a world-from-local
    /// transform each), its nodes numbered after `meshes`'s. Empty meshes and transforms that
    /// cannot be inverted (a zero scale: nothing to hit) are left out.
    pub fn build(meshes: &MeshLevel, placed: impl IntoIterator<Item = (MeshSlot, Mat4)>) -> InstanceLevel {
        let mut boxes = Vec::new();
        let mut instances = Vec::new();
        let mut mesh_depth = 0;
        for (slot, world_from_local) in placed {
            if slot.root == RAY_NO_NODE || !world_from_local.is_finite() {
                continue;
            }
            let local_from_world = world_from_local.inverse();
            if !local_from_world.is_finite() || world_from_local.determinant() == 0.0 {
                continue;
            }
            let world = slot.bounds.transformed(&world_from_local);
            if !(world.min.is_finite() && world.max.is_finite()) {
                continue;
            }
            let rows = local_from_world.transpose();
            instances.push(RayInstance {
                local_from_world: [rows.x_axis.into(), rows.y_axis.into(), rows.z_axis.into()],
                root: slot.root,
                pad: [0; 3],
            });
            boxes.push(BuildBox { min: world.min.into(), max: world.max.into() });
            mesh_depth = mesh_depth.max(slot.depth);
        }
        if boxes.is_empty() {
            return InstanceLevel { root: RAY_NO_NODE, ..InstanceLevel::default() };
        }
        let params = BvhBuildParams { max_prims_per_leaf: 1, ..BvhBuildParams::medium_build() };
        let bvh = build_bvh2(&boxes, params, &mut std::time::Duration::default());
        let node_base = meshes.nodes.len() as u32;
        // One instance a leaf: the leaf names its instance directly.
        let instances = bvh.primitive_indices.iter().map(|&i| instances[i as usize]).collect();
        let nodes = flatten(&bvh, node_base, 0);
        let depth = depth(&bvh);
        InstanceLevel {
            nodes,
            instances,
            root: node_base,
            depth,
            stack_needed: depth.saturating_sub(1) + mesh_depth.saturating_sub(1),
        }
    }

    /// Bytes of the nodes and instances (what the GPU holds of this level).
    pub fn bytes(&self) -> u64 {
        (self.nodes.len() * size_of::<BvhNode>() + self.instances.len() * size_of::<RayInstance>()) as u64
    }
}

/// Both levels of a frame's geometry as the traversal reads them: the node array is the mesh
/// level's nodes followed by the instance level's.
#[derive(Clone, Copy, Debug)]
pub struct RayScene<'a> {
    /// Mesh-level nodes, then instance-level nodes.
    pub nodes: &'a [BvhNode],
    /// The mesh level's triangles.
    pub triangles: &'a [RayTriangle],
    /// The instance level's instances.
    pub instances: &'a [RayInstance],
    /// The instance level's root ([`RAY_NO_NODE`]: nothing to hit).
    pub root: u32,
}

/// A ray as the traversal holds it: origin, direction and the reciprocal direction for the
/// box test (a zero component replaced by a tiny one of the same sign, so no 0 · ∞ appears).
#[derive(Clone, Copy, Debug)]
struct TraversalRay {
    origin: Vec3,
    direction: Vec3,
    inverse: Vec3,
}

impl TraversalRay {
    fn new(origin: Vec3, direction: Vec3) -> TraversalRay {
        let safe = |d: f32| if d.abs() < 1e-30 { 1e-30f32.copysign(d) } else { d };
        let inverse = Vec3::ONE / Vec3::new(safe(direction.x), safe(direction.y), safe(direction.z));
        TraversalRay { origin, direction, inverse }
    }
}

/// Traces the segment from `origin` along `direction` (any length, not zero) for
/// `t ∈ [0, t_max]` through `scene`, as `shaders/common/ray_bvh.wgsl`'s `ray_trace` does,
/// step for step (see the module's steps).
pub fn trace(scene: &RayScene, origin: Vec3, direction: Vec3, t_max: f32) -> Traced {
    let mut steps = 0u32;
    if scene.root == RAY_NO_NODE {
        return Traced { outcome: RayOutcome::Visible, steps };
    }
    let t_max = t_max.min(RAY_FAR);
    let world = TraversalRay::new(origin, direction);
    let mut ray = world;
    let mut stack = [0u32; RAY_STACK_SIZE as usize];
    let mut depth = 0u32;
    let mut node = scene.root;
    let mut in_mesh = false;
    let mut mesh_base = 0u32;
    loop {
        if steps >= RAY_MAX_STEPS {
            return Traced { outcome: RayOutcome::Exhausted, steps };
        }
        steps += 1;
        let n = scene.nodes[node as usize];
        if n.count == 0 {
            let (a, b) = (n.first, n.first + 1);
            let ta = box_entry(&scene.nodes[a as usize], &ray, t_max);
            let tb = box_entry(&scene.nodes[b as usize], &ray, t_max);
            let (near, far, t_near, t_far) = if ta <= tb { (a, b, ta, tb) } else { (b, a, tb, ta) };
            if t_near < RAY_MISS {
                node = near;
                if t_far < RAY_MISS {
                    if depth == RAY_STACK_SIZE {
                        return Traced { outcome: RayOutcome::StackFull, steps };
                    }
                    stack[depth as usize] = far;
                    depth += 1;
                }
                continue;
            }
        } else if !in_mesh {
            let instance = &scene.instances[n.first as usize];
            let [r0, r1, r2] = instance.local_from_world.map(Vec4::from);
            let (o, d) = (origin.extend(1.0), direction.extend(0.0));
            ray = TraversalRay::new(
                Vec3::new(r0.dot(o), r1.dot(o), r2.dot(o)),
                Vec3::new(r0.dot(d), r1.dot(d), r2.dot(d)),
            );
            in_mesh = true;
            mesh_base = depth;
            node = instance.root;
            continue;
        } else {
            for i in n.first..n.first + n.count {
                steps += 1;
                if triangle_hit(&scene.triangles[i as usize], &ray, t_max) {
                    return Traced { outcome: RayOutcome::Blocked, steps };
                }
            }
        }
        if in_mesh && depth == mesh_base {
            in_mesh = false;
            ray = world;
        }
        if depth == 0 {
            return Traced { outcome: RayOutcome::Visible, steps };
        }
        depth -= 1;
        node = stack[depth as usize];
    }
}

/// [`trace`] for a light–point pair: the oracle's segment ([`ShadowQuery::segment`]); a pair
/// with no segment (the point on the light, a non-finite input) is visible.
pub fn trace_query(scene: &RayScene, query: &ShadowQuery) -> Traced {
    match query.segment() {
        Some((origin, direction, length)) => trace(scene, origin, direction, length),
        None => Traced { outcome: RayOutcome::Visible, steps: 0 },
    }
}

/// Where the ray enters `node`'s box within `[0, t_max]`; [`RAY_MISS`] when it misses.
fn box_entry(node: &BvhNode, ray: &TraversalRay, t_max: f32) -> f32 {
    let t1 = (Vec3::from(node.min) - ray.origin) * ray.inverse;
    let t2 = (Vec3::from(node.max) - ray.origin) * ray.inverse;
    let near = t1.min(t2).max_element().max(0.0);
    let far = t1.max(t2).min_element().min(t_max);
    if near <= far { near } else { RAY_MISS }
}

/// True when the segment crosses `tri` (either side, edges included as the oracle's test
/// includes them) within `[0, t_max]` (Möller–Trumbore).
fn triangle_hit(tri: &RayTriangle, ray: &TraversalRay, t_max: f32) -> bool {
    let (v0, e1, e2) =
        (Vec4::from(tri.v0).truncate(), Vec4::from(tri.e1).truncate(), Vec4::from(tri.e2).truncate());
    let p = ray.direction.cross(e2);
    let det = e1.dot(p);
    if !(det.abs() > 0.0 && det.abs() <= RAY_MISS) {
        return false; // parallel, degenerate, or past RAY_MISS (not finite)
    }
    let inv = 1.0 / det;
    let s = ray.origin - v0;
    let u = s.dot(p) * inv;
    let q = s.cross(e1);
    let v = ray.direction.dot(q) * inv;
    let t = e2.dot(q) * inv;
    u >= -EDGE_TOLERANCE && v >= -EDGE_TOLERANCE && u + v <= 1.0 + EDGE_TOLERANCE && t >= 0.0 && t <= t_max
}

/// A box grown on every side by a little more than rounding can lose (relative to its size and
/// position), so a segment that touches a flat mesh's zero-thickness box is never culled by it.
fn widen(min: Vec3A, max: Vec3A) -> ([f32; 3], [f32; 3]) {
    let scale = (max - min).max_element().max(min.abs().max_element()).max(max.abs().max_element());
    let pad = Vec3A::splat(scale * 1e-5 + 1e-30);
    ((min - pad).into(), (max + pad).into())
}

/// The nodes of `bvh` in our layout, node and primitive indices offset by the bases.
fn flatten(bvh: &Bvh2, node_base: u32, primitive_base: u32) -> Vec<BvhNode> {
    bvh.nodes
        .iter()
        .map(|n| {
            let (min, max) = widen(n.aabb.min, n.aabb.max);
            let leaf = n.prim_count > 0;
            BvhNode {
                min,
                count: n.prim_count,
                max,
                first: n.first_index + if leaf { primitive_base } else { node_base },
            }
        })
        .collect()
}

/// Levels of `bvh` from its root (0 when it has no node).
fn depth(bvh: &Bvh2) -> u32 {
    let mut deepest = 0;
    let mut pending = if bvh.nodes.is_empty() { vec![] } else { vec![(0usize, 1u32)] };
    while let Some((i, level)) = pending.pop() {
        deepest = deepest.max(level);
        let n = &bvh.nodes[i];
        if n.prim_count == 0 {
            let first = n.first_index as usize;
            pending.extend([(first, level + 1), (first + 1, level + 1)]);
        }
    }
    deepest
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shadow_oracle::{LightSource, OccluderSet};
    use proptest::prelude::*;

    /// A unit cube's twelve triangles, centred on the origin.
    fn cube() -> Vec<[Vec3; 3]> {
        let mut tris = Vec::new();
        for axis in 0..3 {
            for side in [-0.5f32, 0.5] {
                let corner = |a: f32, b: f32| {
                    let mut p = [0.0; 3];
                    p[axis] = side;
                    p[(axis + 1) % 3] = a;
                    p[(axis + 2) % 3] = b;
                    Vec3::from(p)
                };
                let (c00, c10, c11, c01) =
                    (corner(-0.5, -0.5), corner(0.5, -0.5), corner(0.5, 0.5), corner(-0.5, 0.5));
                tris.push([c00, c10, c11]);
                tris.push([c00, c11, c01]);
            }
        }
        tris
    }

    struct Built {
        meshes: MeshLevel,
        level: InstanceLevel,
        nodes: Vec<BvhNode>,
    }

    impl Built {
        fn new(meshes: MeshLevel, placed: Vec<(MeshSlot, Mat4)>) -> Built {
            let level = InstanceLevel::build(&meshes, placed);
            let nodes = [meshes.nodes.clone(), level.nodes.clone()].concat();
            Built { meshes, level, nodes }
        }

        fn scene(&self) -> RayScene<'_> {
            RayScene {
                nodes: &self.nodes,
                triangles: &self.meshes.triangles,
                instances: &self.level.instances,
                root: self.level.root,
            }
        }
    }

    fn cubes(transforms: &[Mat4]) -> (Built, OccluderSet) {
        let mut meshes = MeshLevel::default();
        let slot = meshes.add_triangles(cube());
        let placed = transforms.iter().map(|&t| (slot, t)).collect();
        let world = transforms
            .iter()
            .flat_map(|t| cube().into_iter().map(move |tri| tri.map(|p| t.transform_point3(p))));
        (Built::new(meshes, placed), OccluderSet::new(world))
    }

    #[test]
    fn a_cube_blocks_the_segment_through_it_and_not_one_beside_it() {
        let (built, _) = cubes(&[Mat4::IDENTITY]);
        let through = trace(&built.scene(), Vec3::new(-2.0, 0.1, 0.2), Vec3::X, 4.0);
        assert_eq!(through.outcome, RayOutcome::Blocked);
        let beside = trace(&built.scene(), Vec3::new(-2.0, 0.7, 0.2), Vec3::X, 4.0);
        assert_eq!(beside.outcome, RayOutcome::Visible);
        let short = trace(&built.scene(), Vec3::new(-2.0, 0.1, 0.2), Vec3::X, 1.4);
        assert_eq!(short.outcome, RayOutcome::Visible, "the segment ends before the cube");
    }

    #[test]
    fn an_instance_is_traced_where_its_transform_puts_it() {
        let moved = Mat4::from_scale_rotation_translation(
            Vec3::new(2.0, 0.5, 1.0),
            glam::Quat::from_rotation_y(0.7),
            Vec3::new(5.0, 0.0, 0.0),
        );
        let (built, _) = cubes(&[moved]);
        let at_origin = trace(&built.scene(), Vec3::new(0.0, -3.0, 0.0), Vec3::Y, 6.0);
        assert_eq!(at_origin.outcome, RayOutcome::Visible);
        let at_instance = trace(&built.scene(), Vec3::new(5.0, -3.0, 0.0), Vec3::Y, 6.0);
        assert_eq!(at_instance.outcome, RayOutcome::Blocked);
    }

    #[test]
    fn nothing_placed_is_visible_in_no_steps() {
        let meshes = MeshLevel::default();
        let built = Built::new(meshes, vec![]);
        let traced = trace(&built.scene(), Vec3::ZERO, Vec3::X, 10.0);
        assert_eq!(traced, Traced { outcome: RayOutcome::Visible, steps: 0 });
    }

    #[test]
    fn an_empty_mesh_or_a_zero_scale_places_nothing() {
        let mut meshes = MeshLevel::default();
        let empty = meshes.add_triangles([[Vec3::NAN, Vec3::ZERO, Vec3::X]]);
        assert_eq!(empty.root, RAY_NO_NODE);
        let cube = meshes.add_triangles(cube());
        let level = InstanceLevel::build(
            &meshes,
            [(empty, Mat4::IDENTITY), (cube, Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0)))],
        );
        assert_eq!(level.root, RAY_NO_NODE);
        assert!(level.instances.is_empty());
    }

    #[test]
    fn a_light_inside_a_closed_box_lights_nothing_outside() {
        let (built, oracle) = cubes(&[Mat4::from_scale(Vec3::splat(4.0))]);
        let light = LightSource::At(Vec3::new(0.3, -0.2, 0.1));
        for i in 0..500 {
            let a = i as f32 * 2.399;
            let dir = Vec3::new(a.cos(), (i as f32 / 250.0) - 1.0, a.sin()).normalize();
            let query = ShadowQuery { point: dir * 6.0, normal: dir, light };
            assert_eq!(trace_query(&built.scene(), &query).outcome, RayOutcome::Blocked, "{dir}");
            assert!(!oracle.visible(&query));
        }
    }

    #[test]
    fn a_point_on_a_face_sees_a_light_in_front_and_not_one_behind() {
        let (built, _) = cubes(&[Mat4::IDENTITY]);
        let point = Vec3::new(0.5, 0.1, -0.2);
        let front =
            ShadowQuery { point, normal: Vec3::X, light: LightSource::At(Vec3::new(0.55, 0.1, -0.2)) };
        assert_eq!(
            trace_query(&built.scene(), &front).outcome,
            RayOutcome::Visible,
            "a light 5 cm off the face"
        );
        let behind =
            ShadowQuery { point, normal: Vec3::X, light: LightSource::At(Vec3::new(-2.0, 0.0, 0.0)) };
        assert_eq!(trace_query(&built.scene(), &behind).outcome, RayOutcome::Blocked);
    }

    #[test]
    fn the_stack_holds_for_a_large_scene() {
        // 4 096 cubes on a grid: a deep instance level over a twelve-triangle mesh.
        let transforms: Vec<Mat4> = (0..4096)
            .map(|i| Mat4::from_translation(Vec3::new((i % 64) as f32 * 1.5, 0.0, (i / 64) as f32 * 1.5)))
            .collect();
        let (built, oracle) = cubes(&transforms);
        assert!(built.level.stack_needed <= RAY_STACK_SIZE, "stack {}", built.level.stack_needed);
        for i in 0..2000 {
            let f = i as f32;
            let point = Vec3::new((f * 7.31) % 96.0 + 0.013, 3.0, (f * 3.17) % 96.0 + 0.029);
            let light = LightSource::At(Vec3::new(
                (f * 1.91) % 96.0 + 0.017,
                -0.2 + (f % 3.0) * 0.1,
                (f * 5.3) % 96.0 + 0.023,
            ));
            let query = ShadowQuery { point, normal: Vec3::ZERO, light };
            let traced = trace_query(&built.scene(), &query);
            assert!(matches!(traced.outcome, RayOutcome::Visible | RayOutcome::Blocked), "{traced:?}");
            assert_eq!(traced.outcome.lit(), oracle.visible(&query), "pair {i}");
        }
    }

    #[test]
    fn a_ray_past_its_step_budget_stops_lit() {
        // 20 000 half-squares across the ray's path, each missing it through the half its box
        // holds but the triangle does not: every box is entered, no triangle is hit.
        let mut meshes = MeshLevel::default();
        let slot = meshes.add_triangles((0..20_000).map(|i| {
            let x = i as f32 * 0.01;
            [Vec3::new(x, -1.0, -1.0), Vec3::new(x, 1.0, -1.0), Vec3::new(x, -1.0, 1.0)]
        }));
        let built = Built::new(meshes, vec![(slot, Mat4::IDENTITY)]);
        let traced = trace(&built.scene(), Vec3::new(-1.0, 0.5, 0.5), Vec3::X, 1000.0);
        assert_eq!(traced.outcome, RayOutcome::Exhausted);
        assert!(traced.steps <= RAY_MAX_STEPS + RAY_LEAF_TRIANGLES, "{traced:?}");
        assert!(traced.outcome.lit());
    }

    #[test]
    fn outcome_codes_round_trip() {
        for o in [RayOutcome::Visible, RayOutcome::Blocked, RayOutcome::Exhausted, RayOutcome::StackFull] {
            assert_eq!(RayOutcome::from_code(o.code()), Some(o));
        }
        assert_eq!(RayOutcome::from_code(7), None);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]

        /// Random boxes placed at random, random segments: the traversal agrees with the
        /// oracle except within rounding of an edge (at most 1 pair in 200).
        #[test]
        fn agrees_with_the_oracle(
            seeds in proptest::collection::vec((-4.0f32..4.0, -4.0f32..4.0, -4.0f32..4.0, 0.1f32..2.0, 0.0f32..6.0), 1..24),
            rays in proptest::collection::vec((-6.0f32..6.0, -6.0f32..6.0, -6.0f32..6.0, -6.0f32..6.0, -6.0f32..6.0, -6.0f32..6.0), 200),
        ) {
            let transforms: Vec<Mat4> = seeds
                .iter()
                .map(|&(x, y, z, s, a)| Mat4::from_scale_rotation_translation(
                    Vec3::new(s, s * 0.5, s * 1.5),
                    glam::Quat::from_rotation_y(a) * glam::Quat::from_rotation_x(a * 0.5),
                    Vec3::new(x, y, z),
                ))
                .collect();
            let (built, oracle) = cubes(&transforms);
            let mut disagree = 0;
            for &(px, py, pz, lx, ly, lz) in &rays {
                let query = ShadowQuery {
                    point: Vec3::new(px, py, pz),
                    normal: Vec3::ZERO,
                    light: LightSource::At(Vec3::new(lx, ly, lz)),
                };
                let traced = trace_query(&built.scene(), &query);
                prop_assert!(matches!(traced.outcome, RayOutcome::Visible | RayOutcome::Blocked));
                if traced.outcome.lit() != oracle.visible(&query) {
                    disagree += 1;
                }
            }
            prop_assert!(disagree <= 1, "{disagree} of {} pairs disagree", rays.len());
        }
    }
}
