// Cluster light assignment on the GPU, in two levels of three dispatches each, in one compute
// pass. Level 1 builds a list per screen tile (the column of clusters behind it); level 2
// builds each cluster's list from its tile's list instead of from every light:
// 1. `tile_count`: one invocation per (tile, chunk of TILE_LIGHT_CHUNK lights) counts the
//    chunk's lights whose sphere passes the chosen test against the tile's whole column,
//    radius inflated a little more: the column's box contains each cluster's box and its
//    planes are each cluster's side planes moved outwards, so this is a superset of what any
//    cluster of the column accepts (checked on the CPU by
//    crates/manylight_core/tests/tile_prefilter.rs). Chunks keep every invocation's loop short:
//    lavapipe stops an invocation after 65 535 loop iterations (gpu_types::TILE_LIGHT_CHUNK);
// 2. `tile_scan`: one workgroup turns the (tile, chunk) counts, tile-major, into offsets
//    (exclusive prefix sum), so a tile's chunks lie one after another;
// 3. `tile_fill`: each (tile, chunk) writes its lights in ascending order, so each tile's
//    list is in ascending light order;
// 4. `count`: one invocation per cluster tests its tile's lights against the cluster's bounds,
//    stores the count (capped if a cap is set) and updates the counters;
// 5. `scan`: prefix sum of the cluster counts, and the total the index list needs;
// 6. `fill`: writes the first `count` hits, in ascending light order, at the cluster's offset.
// Sums and offsets saturate at 2^32 - 1 instead of wrapping (`add_saturating`), so a frame
// with more pairs than a u32 counts is seen as too large (PAIR_COUNT_SATURATED) rather than as
// a small total whose lists would silently miss lights.
// A fill whose list is too small is skipped; the renderer reads the totals back, grows the
// lists and renders the frame again, so nothing is lost. The result is the same compacted
// structure as manylight_core::cluster::assign_lights.
//!include common/clusters.wgsl

struct ClusterCounters {
    total_entries: atomic<u32>,
    dropped_pairs: atomic<u32>,
    clusters_overflowed: atomic<u32>,
    max_count: atomic<u32>,
    non_empty: atomic<u32>,
    tile_entries: atomic<u32>,
    max_tile_lights: atomic<u32>,
    _pad: u32,
};

@group(0) @binding(0) var<uniform> params: ClusterParams;
@group(0) @binding(1) var<storage, read> bounds: array<GpuClusterBounds>;
@group(0) @binding(2) var<storage, read> spheres: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> ranges: array<vec2<u32>>;
@group(0) @binding(4) var<storage, read_write> indices: array<u32>;
@group(0) @binding(5) var<storage, read_write> counters: ClusterCounters;
@group(0) @binding(6) var<storage, read> tile_bounds: array<GpuClusterBounds>;
@group(0) @binding(7) var<storage, read_write> tile_ranges: array<vec2<u32>>;
@group(0) @binding(8) var<storage, read_write> tile_indices: array<u32>;

// TILE_PREFILTER_INFLATION (from Rust, manylight_core::cluster::TILE_PREFILTER_INFLATION): extra
// inflation of the tile prefilter, so float rounding can never make it reject a light a cluster
// of the column would accept; the CPU bound of the tile list (cluster::list_bounds) uses it too.

override WORKGROUP_SIZE: u32 = 64u;

// The linear index of an invocation. Dispatches wider than the device's workgroups per
// dimension (65 535 by default) are split into rows: x runs over at most that many workgroups,
// y counts the rows (Rust: `cluster_build::dispatch_size`).
fn linear_index(id: vec3<u32>, groups: vec3<u32>) -> u32 {
    return id.x + id.y * groups.x * WORKGROUP_SIZE;
}

// a + b, or PAIR_COUNT_SATURATED when the sum does not fit in a u32.
fn add_saturating(a: u32, b: u32) -> u32 {
    let sum = a + b;
    return select(sum, PAIR_COUNT_SATURATED, sum < a);
}

// True when the list `range` (offset, count) lies within `capacity` entries, without the
// wrap-around of `range.x + range.y`.
fn fits(range: vec2<u32>, capacity: u32) -> bool {
    return range.y <= capacity && range.x <= capacity - range.y;
}

// The cluster's bounds are loaded once per invocation (`b`), not once per light.
fn touches(b: GpuClusterBounds, light: u32) -> bool {
    return touches_sphere(b, spheres[light]);
}

// The chosen sphere test (CULL_AABB, CULL_PLANES or CULL_BOTH).
fn touches_sphere(b: GpuClusterBounds, s: vec4<f32>) -> bool {
    if params.cull_test == CULL_AABB {
        return sphere_intersects_aabb(s.xyz, s.w, b.aabb_min.xyz, b.aabb_max.xyz);
    }
    if params.cull_test == CULL_PLANES {
        return sphere_intersects_planes(s.xyz, s.w, b);
    }
    return sphere_intersects_aabb(s.xyz, s.w, b.aabb_min.xyz, b.aabb_max.xyz) && sphere_intersects_planes(s.xyz, s.w, b);
}

fn touches_tile(b: GpuClusterBounds, light: u32) -> bool {
    let s = spheres[light];
    return touches_sphere(b, vec4<f32>(s.xyz, s.w * TILE_PREFILTER_INFLATION));
}

fn tile_count_total() -> u32 {
    return params.dims.x * params.dims.y;
}

// Entries of `tile_ranges`: one per (tile, chunk), tile-major.
fn tile_entry_total() -> u32 {
    return tile_count_total() * params.tile_chunks;
}

// The lights [first, end) of entry `e`'s chunk.
fn chunk_lights(e: u32) -> vec2<u32> {
    let first = (e % params.tile_chunks) * TILE_LIGHT_CHUNK;
    return vec2<u32>(first, min(first + TILE_LIGHT_CHUNK, params.light_count));
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn tile_count(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = linear_index(id, groups);
    if e >= tile_entry_total() {
        return;
    }
    let b = tile_bounds[e / params.tile_chunks];
    let lights = chunk_lights(e);
    var n = 0u;
    for (var l = lights.x; l < lights.y; l++) {
        if touches_tile(b, l) {
            n += 1u;
        }
    }
    tile_ranges[e] = vec2<u32>(0u, n);
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn tile_fill(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = linear_index(id, groups);
    if e >= tile_entry_total() {
        return;
    }
    let range = tile_ranges[e];
    if !fits(range, params.tile_index_capacity) {
        return;
    }
    let b = tile_bounds[e / params.tile_chunks];
    let lights = chunk_lights(e);
    var k = 0u;
    for (var l = lights.x; l < lights.y && k < range.y; l++) {
        if touches_tile(b, l) {
            tile_indices[range.x + k] = l;
            k += 1u;
        }
    }
}

// The lights of the cluster's tile: (offset, count) into `tile_indices`, from its first and
// last chunk's ranges.
fn tile_lights(cluster: u32) -> vec2<u32> {
    let first = (cluster % tile_count_total()) * params.tile_chunks;
    let a = tile_ranges[first];
    let z = tile_ranges[first + params.tile_chunks - 1u];
    let range = vec2<u32>(a.x, add_saturating(z.x, z.y) - a.x);
    // A tile list that did not fit this frame is empty; the frame is rendered again.
    return select(vec2<u32>(0u), range, fits(range, params.tile_index_capacity));
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn count(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let cluster = linear_index(id, groups);
    if cluster >= params.dims.w {
        return;
    }
    let b = bounds[cluster];
    let tile = tile_lights(cluster);
    // The longest tile list: the loops below run that often (lavapipe ends an invocation
    // after LAVAPIPE_LOOP_LIMIT iterations, so the renderer refuses longer lists there).
    atomicMax(&counters.max_tile_lights, tile.y);
    var n = 0u;
    for (var i = 0u; i < tile.y; i++) {
        if touches(b, tile_indices[tile.x + i]) {
            n += 1u;
        }
    }
    let kept = min(n, params.cap);
    ranges[cluster] = vec2<u32>(0u, kept);
    if n > kept {
        atomicAdd(&counters.dropped_pairs, n - kept);
        atomicAdd(&counters.clusters_overflowed, 1u);
    }
    if n > 0u {
        atomicAdd(&counters.non_empty, 1u);
    }
    atomicMax(&counters.max_count, n);
}

var<workgroup> partial_sums: array<u32, SCAN_WORKGROUP_SIZE>;

// Exclusive prefix sum of the counts (`.y`) of `tiles ? tile_ranges : ranges` into their
// offsets (`.x`); returns the total. One workgroup: each invocation sums a chunk, invocation
// 0 scans the chunk sums, each invocation then writes its chunk's offsets.
fn scan_ranges(tiles: bool, t: u32) -> u32 {
    let total_entries = select(params.dims.w, tile_entry_total(), tiles);
    let chunk = (total_entries + SCAN_WORKGROUP_SIZE - 1u) / SCAN_WORKGROUP_SIZE;
    let begin = min(t * chunk, total_entries);
    let end = min(begin + chunk, total_entries);
    var sum = 0u;
    for (var c = begin; c < end; c++) {
        sum = add_saturating(sum, select(ranges[c].y, tile_ranges[c].y, tiles));
    }
    partial_sums[t] = sum;
    workgroupBarrier();
    if t == 0u {
        var running = 0u;
        for (var i = 0u; i < SCAN_WORKGROUP_SIZE; i++) {
            let v = partial_sums[i];
            partial_sums[i] = running;
            running = add_saturating(running, v);
        }
        // The total goes where every invocation can read it after the barrier.
        scan_total = running;
    }
    workgroupBarrier();
    var offset = partial_sums[t];
    for (var c = begin; c < end; c++) {
        if tiles {
            let n = tile_ranges[c].y;
            tile_ranges[c].x = offset;
            offset = add_saturating(offset, n);
        } else {
            let n = ranges[c].y;
            ranges[c].x = offset;
            offset = add_saturating(offset, n);
        }
    }
    return scan_total;
}

var<workgroup> scan_total: u32;

@compute @workgroup_size(SCAN_WORKGROUP_SIZE)
fn tile_scan(@builtin(local_invocation_index) t: u32) {
    let total = scan_ranges(true, t);
    if t == 0u {
        atomicStore(&counters.tile_entries, total);
    }
}

@compute @workgroup_size(SCAN_WORKGROUP_SIZE)
fn scan(@builtin(local_invocation_index) t: u32) {
    let total = scan_ranges(false, t);
    if t == 0u {
        atomicStore(&counters.total_entries, total);
    }
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn fill(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let cluster = linear_index(id, groups);
    if cluster >= params.dims.w {
        return;
    }
    let range = ranges[cluster];
    if !fits(range, params.index_capacity) {
        return; // the list is too small this frame; the renderer grows it and renders again
    }
    let b = bounds[cluster];
    let tile = tile_lights(cluster);
    var k = 0u;
    for (var i = 0u; i < tile.y && k < range.y; i++) {
        let l = tile_indices[tile.x + i];
        if touches(b, l) {
            indices[range.x + k] = l;
            k += 1u;
        }
    }
}
