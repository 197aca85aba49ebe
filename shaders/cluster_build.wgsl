// Cluster light assignment on the GPU, in three dispatches of one compute pass:
// 1. `count`: one invocation per cluster tests every light's view-space sphere against the
//    cluster's bounds, stores the count (capped if a cap is set) and updates the counters;
// 2. `scan`: one workgroup turns the counts into offsets (exclusive prefix sum) and writes
//    the total the index list needs;
// 3. `fill`: one invocation per cluster tests the lights again in ascending order and writes
//    the first `count` hits at its offset (skipped if the list is too small: the renderer
//    reads the total back, grows the list and renders the frame again, so nothing is lost).
// The result is the same compacted structure as manylight_core::cluster::assign_lights.
//!include common/clusters.wgsl

struct ClusterCounters {
    total_entries: atomic<u32>,
    dropped_pairs: atomic<u32>,
    clusters_overflowed: atomic<u32>,
    max_count: atomic<u32>,
    non_empty: atomic<u32>,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
};

@group(0) @binding(0) var<uniform> params: ClusterParams;
@group(0) @binding(1) var<storage, read> bounds: array<GpuClusterBounds>;
@group(0) @binding(2) var<storage, read> spheres: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> ranges: array<vec2<u32>>;
@group(0) @binding(4) var<storage, read_write> indices: array<u32>;
@group(0) @binding(5) var<storage, read_write> counters: ClusterCounters;

override WORKGROUP_SIZE: u32 = 64u;

fn touches(cluster: u32, light: u32) -> bool {
    let s = spheres[light];
    let b = bounds[cluster];
    if params.cull_test == CULL_AABB {
        return sphere_intersects_aabb(s.xyz, s.w, b.aabb_min.xyz, b.aabb_max.xyz);
    }
    if params.cull_test == CULL_PLANES {
        return sphere_intersects_planes(s.xyz, s.w, b);
    }
    return sphere_intersects_aabb(s.xyz, s.w, b.aabb_min.xyz, b.aabb_max.xyz) && sphere_intersects_planes(s.xyz, s.w, b);
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn count(@builtin(global_invocation_id) id: vec3<u32>) {
    let cluster = id.x;
    if cluster >= params.dims.w {
        return;
    }
    var n = 0u;
    for (var l = 0u; l < params.light_count; l++) {
        if touches(cluster, l) {
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

@compute @workgroup_size(SCAN_WORKGROUP_SIZE)
fn scan(@builtin(local_invocation_index) t: u32) {
    let total_clusters = params.dims.w;
    let chunk = (total_clusters + SCAN_WORKGROUP_SIZE - 1u) / SCAN_WORKGROUP_SIZE;
    let begin = min(t * chunk, total_clusters);
    let end = min(begin + chunk, total_clusters);
    var sum = 0u;
    for (var c = begin; c < end; c++) {
        sum += ranges[c].y;
    }
    partial_sums[t] = sum;
    workgroupBarrier();
    if t == 0u {
        var running = 0u;
        for (var i = 0u; i < SCAN_WORKGROUP_SIZE; i++) {
            let v = partial_sums[i];
            partial_sums[i] = running;
            running += v;
        }
        atomicStore(&counters.total_entries, running);
    }
    workgroupBarrier();
    var offset = partial_sums[t];
    for (var c = begin; c < end; c++) {
        let n = ranges[c].y;
        ranges[c].x = offset;
        offset += n;
    }
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn fill(@builtin(global_invocation_id) id: vec3<u32>) {
    let cluster = id.x;
    if cluster >= params.dims.w {
        return;
    }
    let range = ranges[cluster];
    if range.x + range.y > params.index_capacity {
        return; // the list is too small this frame; the renderer grows it and renders again
    }
    var k = 0u;
    for (var l = 0u; l < params.light_count && k < range.y; l++) {
        if touches(cluster, l) {
            indices[range.x + k] = l;
            k += 1u;
        }
    }
}
