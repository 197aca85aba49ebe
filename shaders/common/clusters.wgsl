// The cluster grid as the shaders see it (Rust: `GpuClusterParams`, `GpuClusterBounds`;
// math mirrored from crates/manylight_core/src/cluster).
struct ClusterParams {
    // x, y, z: grid size; w: cluster count
    dims: vec4<u32>,
    // x, y: viewport size in pixels; z: near; w: far
    viewport: vec4<f32>,
    light_count: u32,
    cap: u32,
    cull_test: u32,
    index_capacity: u32,
    slicing: u32,
    log_far_over_near: f32,
    tile_index_capacity: u32,
    // candidate chunks (TILE_LIGHT_CHUNK each) of level 1 per tile, at least 1: enough for the
    // longest coarse list, or light_chunks without a coarse level
    tile_chunks: u32,
    // coarse tiles across and down (level 0 of the build)
    coarse_dims: vec2<u32>,
    // entries of the coarse-tile lists, after the tile_index_capacity entries of the tile lists
    coarse_index_capacity: u32,
    // tiles per coarse-tile edge; 0: no coarse level (level 1 tests every light)
    coarse_span: u32,
    // 1: the cluster level cuts each cluster to its pixels' depth range (`cluster_depth.wgsl`
    // writes them after the cluster ranges); 0: whole slices
    depth_bounds: u32,
    // blocks across and down of the refined lists (light_refine.wgsl); 0: no refinement
    refine_blocks_x: u32,
    refine_blocks_y: u32,
    // index in the ranges of block 0's refined range; its lists follow `index_capacity` entries
    refined_first: u32,
    // each light's tile rectangle (cluster_build.wgsl, `light_rects`): (tan_x, tan_y, 0,
    // margin) in perspective, (half_x, half_y, 1, margin) orthographic
    frustum: vec4<f32>,
    // chunks (TILE_LIGHT_CHUNK lights each) of level 0 per coarse tile, at least 1
    light_chunks: u32,
    // 1: level 0 runs from the lights' side (cluster_build.wgsl, `light_marks`)
    from_lights: u32,
    // the longest tile list the build loops over in one invocation (lavapipe's loop limit,
    // else 0xffffffff); a cluster whose tile list is longer shades from every light
    loop_limit: u32,
    _pad0: u32,
    // world to view (light_spheres.wgsl)
    view_from_world: mat4x4<f32>,
};

// A u32 that orders as `d` does among floats (sign-magnitude to two's-complement order).
fn order_key(d: f32) -> u32 {
    let b = bitcast<u32>(d);
    return select(b | 0x80000000u, ~b, (b & 0x80000000u) != 0u);
}

fn from_order_key(k: u32) -> f32 {
    return bitcast<f32>(select(~k, k & 0x7fffffffu, (k & 0x80000000u) != 0u));
}

struct GpuClusterBounds {
    aabb_min: vec4<f32>,
    aabb_max: vec4<f32>,
    planes: array<vec4<f32>, 6>,
};

// Depth slice of a positive view distance (ClusterGrid::slice_of_depth).
fn cluster_slice(p: ClusterParams, d: f32) -> u32 {
    let near = p.viewport.z;
    let far = p.viewport.w;
    var s = 0.0;
    if p.slicing == Z_SLICING_LINEAR {
        s = (d - near) / (far - near) * f32(p.dims.z);
    } else {
        s = log(max(d, near) / near) / p.log_far_over_near * f32(p.dims.z);
    }
    // `s >= 0.0` is false for NaN, which lands in slice 0.
    let clamped = select(0.0, min(s, f32(p.dims.z - 1u)), s >= 0.0);
    return u32(clamped);
}

// Tile x, y and slice of a fragment at framebuffer position `frag` (pixels) and view distance
// `d` (ClusterGrid::tile_of_pixel, slice_of_depth).
fn cluster_coords(p: ClusterParams, frag: vec2<f32>, d: f32) -> vec3<u32> {
    let tile_f = floor(frag * vec2<f32>(p.dims.xy) / p.viewport.xy);
    let tile = vec2<u32>(clamp(tile_f, vec2<f32>(0.0), vec2<f32>(p.dims.xy - vec2<u32>(1u))));
    return vec3<u32>(tile, cluster_slice(p, d));
}

// The index of the cluster at tile x, y and slice `c` (ClusterGrid::index).
fn cluster_at(p: ClusterParams, c: vec3<u32>) -> u32 {
    return c.x + c.y * p.dims.x + c.z * p.dims.x * p.dims.y;
}

// Cluster of a fragment at framebuffer position `frag` (pixels) and view distance `d`
// (ClusterGrid::cluster_of).
fn cluster_index(p: ClusterParams, frag: vec2<f32>, d: f32) -> u32 {
    return cluster_at(p, cluster_coords(p, frag, d));
}

// Where refined lists are on (`p.refine_blocks_x` > 0): the index in the ranges buffer of
// pixel block `b`'s range (light_refine.wgsl writes it, the shading passes read it).
fn refined_range_index(p: ClusterParams, b: vec2<u32>) -> u32 {
    return p.refined_first + b.x + b.y * p.refine_blocks_x;
}

// Conservative sphere–box test (manylight_core::cluster::sphere_intersects_aabb): spheres of
// radius <= 0 touch nothing; the radius is inflated by RADIUS_INFLATION.
fn sphere_intersects_aabb(c: vec3<f32>, radius: f32, mn: vec3<f32>, mx: vec3<f32>) -> bool {
    if !(radius > 0.0) {
        return false;
    }
    let r = radius * RADIUS_INFLATION;
    let d = max(max(mn - c, c - mx), vec3<f32>(0.0));
    return dot(d, d) <= r * r;
}

// Conservative sphere–planes test (manylight_core::cluster::sphere_intersects_planes).
// Written without a loop: lavapipe stops a shader invocation after 65 535 loop iterations in
// total, so a 6-iteration loop here would cut the light loops around it to a seventh.
fn sphere_intersects_planes(c: vec3<f32>, radius: f32, b: GpuClusterBounds) -> bool {
    if !(radius > 0.0) {
        return false;
    }
    let r = radius * RADIUS_INFLATION;
    // `< -r` as in Rust, so a NaN distance (overflow) keeps the light.
    let p = b.planes;
    let outside = dot(p[0].xyz, c) + p[0].w < -r || dot(p[1].xyz, c) + p[1].w < -r
        || dot(p[2].xyz, c) + p[2].w < -r || dot(p[3].xyz, c) + p[3].w < -r
        || dot(p[4].xyz, c) + p[4].w < -r || dot(p[5].xyz, c) + p[5].w < -r;
    return !outside;
}
