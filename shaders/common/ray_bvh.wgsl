// Shadow rays through the scene's two-level BVH: the twin of `manylight_core::ray_bvh::trace`,
// step for step (that module says how the levels, the stack and the step budget work).
//
// The geometry is in group 0 (Rust: `RAY_GEOMETRY_BINDINGS`, filled by
// `ray_geometry::RayGeometry`).

// Rust: `manylight_core::ray_bvh::BvhNode`. count == 0: inner node, children at first and
// first + 1; count > 0: a leaf of triangles (mesh level) or of one instance (instance level).
struct RayNode {
    min: vec3<f32>,
    count: u32,
    max: vec3<f32>,
    first: u32,
};

// Rust: `manylight_core::ray_bvh::RayTriangle`: a corner and the two edges from it, in the
// mesh's space.
struct RayTriangle {
    v0: vec4<f32>,
    e1: vec4<f32>,
    e2: vec4<f32>,
};

// Rust: `manylight_core::ray_bvh::RayInstance`: rows of the local-from-world transform and the
// mesh's root node.
struct RayInstance {
    local_from_world: array<vec4<f32>, 3>,
    root: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
};

// The mesh level's nodes, then the instance level's.
@group(0) @binding(11) var<storage, read> ray_nodes: array<RayNode>;
// The mesh level's triangles (three entries each: `RayTriangle`), then from the view's
// `rays.y` the instances (four each: `RayInstance`), then from `rays.z` the casting lights'
// bits (four words an entry); bit patterns, read as floats where they are floats.
@group(0) @binding(12) var<storage, read> ray_prims: array<vec4<u32>>;

fn ray_triangle(i: u32) -> RayTriangle {
    let at = 3u * i;
    return RayTriangle(
        bitcast<vec4<f32>>(ray_prims[at]),
        bitcast<vec4<f32>>(ray_prims[at + 1u]),
        bitcast<vec4<f32>>(ray_prims[at + 2u]),
    );
}

fn ray_instance(base: u32, j: u32) -> RayInstance {
    let at = base + 4u * j;
    let tail = ray_prims[at + 3u];
    return RayInstance(
        array<vec4<f32>, 3>(
            bitcast<vec4<f32>>(ray_prims[at]),
            bitcast<vec4<f32>>(ray_prims[at + 1u]),
            bitcast<vec4<f32>>(ray_prims[at + 2u]),
        ),
        tail.x,
        tail.y,
        tail.z,
        tail.w,
    );
}

// How a ray ended (`RayOutcome::code`: RAY_VISIBLE, RAY_BLOCKED, RAY_EXHAUSTED,
// RAY_STACK_FULL) and the steps it took.
struct RayTrace {
    outcome: u32,
    steps: u32,
};

struct TraversalRay {
    origin: vec3<f32>,
    direction: vec3<f32>,
    inverse: vec3<f32>,
};

// A zero direction component becomes a tiny one of the same sign: no 0 * inf in the box test.
fn ray_traversal(origin: vec3<f32>, direction: vec3<f32>) -> TraversalRay {
    let tiny = select(vec3<f32>(-1e-30), vec3<f32>(1e-30), direction >= vec3<f32>(0.0));
    let safe = select(direction, tiny, abs(direction) < vec3<f32>(1e-30));
    return TraversalRay(origin, direction, vec3<f32>(1.0) / safe);
}

// Where the ray enters the node's box within [0, t_max]; RAY_MISS when it misses.
fn ray_box_entry(node: RayNode, ray: TraversalRay, t_max: f32) -> f32 {
    let t1 = (node.min - ray.origin) * ray.inverse;
    let t2 = (node.max - ray.origin) * ray.inverse;
    let lo = min(t1, t2);
    let hi = max(t1, t2);
    let near = max(max(max(lo.x, lo.y), lo.z), 0.0);
    let far = min(min(min(hi.x, hi.y), hi.z), t_max);
    return select(RAY_MISS, near, near <= far);
}

// The segment crosses the triangle (either side, edges included by RAY_EDGE_TOLERANCE) within
// [0, t_max] (Moller-Trumbore).
fn ray_triangle_hit(tri: RayTriangle, ray: TraversalRay, t_max: f32) -> bool {
    let e1 = tri.e1.xyz;
    let e2 = tri.e2.xyz;
    let p = cross(ray.direction, e2);
    let det = dot(e1, p);
    if !(abs(det) > 0.0 && abs(det) <= RAY_MISS) {
        return false;
    }
    let inv = 1.0 / det;
    let s = ray.origin - tri.v0.xyz;
    let u = dot(s, p) * inv;
    let q = cross(s, e1);
    let v = dot(ray.direction, q) * inv;
    let t = dot(e2, q) * inv;
    return u >= -RAY_EDGE_TOLERANCE && v >= -RAY_EDGE_TOLERANCE && u + v <= 1.0 + RAY_EDGE_TOLERANCE
        && t >= 0.0 && t <= t_max;
}

// Traces the segment from `origin` along `direction` for t in [0, t_max] through `geometry`
// (the view's `rays`: x the instance level's root, RAY_NO_NODE when nothing is placed; y where
// the instances start in `ray_prims`).
fn ray_trace(geometry: vec4<u32>, origin: vec3<f32>, direction: vec3<f32>, t_max_in: f32) -> RayTrace {
    var steps = 0u;
    let root = geometry.x;
    if root == RAY_NO_NODE {
        return RayTrace(RAY_VISIBLE, steps);
    }
    let t_max = min(t_max_in, RAY_FAR);
    let world = ray_traversal(origin, direction);
    var ray = world;
    var stack: array<u32, RAY_STACK_SIZE>;
    var depth = 0u;
    var node = root;
    var in_mesh = false;
    var mesh_base = 0u;
    loop {
        if steps >= RAY_MAX_STEPS {
            return RayTrace(RAY_EXHAUSTED, steps);
        }
        steps += 1u;
        let n = ray_nodes[node];
        if n.count == 0u {
            let a = n.first;
            let b = n.first + 1u;
            let ta = ray_box_entry(ray_nodes[a], ray, t_max);
            let tb = ray_box_entry(ray_nodes[b], ray, t_max);
            let a_first = ta <= tb;
            let near = select(b, a, a_first);
            let far = select(a, b, a_first);
            let t_near = select(tb, ta, a_first);
            let t_far = select(ta, tb, a_first);
            if t_near < RAY_MISS {
                node = near;
                if t_far < RAY_MISS {
                    if depth == RAY_STACK_SIZE {
                        return RayTrace(RAY_STACK_FULL, steps);
                    }
                    stack[depth] = far;
                    depth += 1u;
                }
                continue;
            }
        } else if !in_mesh {
            let instance = ray_instance(geometry.y, n.first);
            let o = vec4<f32>(origin, 1.0);
            let d = vec4<f32>(direction, 0.0);
            let m = instance.local_from_world;
            ray = ray_traversal(
                vec3<f32>(dot(m[0], o), dot(m[1], o), dot(m[2], o)),
                vec3<f32>(dot(m[0], d), dot(m[1], d), dot(m[2], d)),
            );
            in_mesh = true;
            mesh_base = depth;
            node = instance.root;
            continue;
        } else {
            for (var i = n.first; i < n.first + n.count; i += 1u) {
                steps += 1u;
                if ray_triangle_hit(ray_triangle(i), ray, t_max) {
                    return RayTrace(RAY_BLOCKED, steps);
                }
            }
        }
        if in_mesh && depth == mesh_base {
            in_mesh = false;
            ray = world;
        }
        if depth == 0u {
            return RayTrace(RAY_VISIBLE, steps);
        }
        depth -= 1u;
        node = stack[depth];
    }
    return RayTrace(RAY_VISIBLE, steps);
}
