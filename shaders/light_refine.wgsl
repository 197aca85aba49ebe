// Refined light lists: one compute pass after the cluster build, one invocation per group of
// REFINE_GROUP_EDGE × REFINE_GROUP_EDGE blocks of REFINE_EDGE × REFINE_EDGE pixels. A cluster
// is a whole tile deep in a depth slice; the lights of a tile that reach a block's few surface
// points are far fewer when lights are small (a light a few pixels wide on a 16-pixel tile).
// Each block:
// 1. reads its pixels' shading distances (the depth pre-pass's `shading_distance`, or the
//    G-buffer's stored position as deferred lighting reads it) and makes the view-space box
//    around their surface positions, widened on every axis by REFINE_SLACK × (distance +
//    the camera's distance from the origin) (the shading pass computes each position again,
//    in world space, from the same data, which agrees to rounding), and the box of the
//    clusters those widened distances fall in;
// 2. keeps the lights of those clusters' lists whose sphere reaches the box (the cluster
//    test's `sphere_intersects_aabb`), each once (a light in several of the clusters' lists,
//    all in ascending light order, is kept from the first), in cluster order, in its
//    REFINED_LIST_SLOTS slots after the cluster lists;
// 3. writes its range after the cluster ranges: (offset, count), or a count of
//    REFINED_FALLBACK when its pixels are to shade from their cluster lists: more than
//    REFINED_LIST_SLOTS lights kept, more than REFINE_MAX_CLUSTERS clusters or
//    REFINE_CANDIDATE_LIMIT list entries to test (which keeps the invocation far inside
//    lavapipe's loop limit; a cluster that shades from every light, LIST_EVERY_LIGHT, has more),
//    or a distance that is not finite.
// When every block of the group that has surface points falls in one and the same cluster
// (most groups at 16-px tiles), step 2 reads that cluster's list once for all of them and tests
// each light against each block's box, which gives each block the list it would get alone; the
// other groups refine their blocks one after the other within one budget of
// REFINE_CANDIDATE_LIMIT × REFINE_MAX_CLUSTERS list entries × clusters, a block past it
// shading from its cluster lists. The budget keeps the invocation inside lavapipe's loop
// limit: a block's lists hold at most 1 024 entries, so a duplicate check is a binary search of
// at most 11 steps, and an entry of a block spanning n clusters costs at most 1 + 11 (n - 1)
// iterations; 4 096 entries × clusters make at most 45 056, with the 64 pixels and the counts.
// Exact as the cluster lists are: a light that lights a pixel reaches the pixel's position,
// which lies in the block's box, and is in the list of the pixel's cluster.
//!include common/view.wgsl
//!include common/lights.wgsl
//!include common/brdf.wgsl
//!include common/clusters.wgsl

// group 0, binding 0: `view` (common/view_binding.wgsl, through common/gbuffer_read.wgsl); group 1: the G-buffer
//!include common/gbuffer_read.wgsl

// Storage, not uniform: see cluster_depth.wgsl (lavapipe recompiles small shaders whose
// uniforms change).
@group(2) @binding(0) var<storage, read> cluster_params: ClusterParams;
@group(2) @binding(1) var<storage, read> spheres: array<vec4<f32>>;
@group(2) @binding(2) var<storage, read_write> ranges: array<vec2<u32>>;
@group(2) @binding(3) var<storage, read_write> indices: array<u32>;

// Forward pipelines: the depth pre-pass's shading distances (0: background).
@group(1) @binding(9) var shading_distance: texture_2d<f32>;

// The block being refined: the box around its pixels' positions, the first and last of its
// covered pixels along x and y, and the box of clusters they fall in (`find_clusters`).
var<private> box_min: vec3<f32>;
var<private> box_max: vec3<f32>;
var<private> pixels_min: vec2<u32>;
var<private> pixels_max: vec2<u32>;
var<private> clusters_min: vec3<u32>;
var<private> clusters_max: vec3<u32>;
var<private> covered: bool;
var<private> unbounded: bool;
// The largest view distance of the block's pixels.
var<private> farthest: f32;

// A block of the group, once its pixels are read (`close_block`).
const BLOCK_OUTSIDE: u32 = 0u; // past the image's blocks
const BLOCK_EMPTY: u32 = 1u; // no surface: an empty list
const BLOCK_UNBOUNDED: u32 = 2u; // a distance that is not finite: shades from its clusters
const BLOCK_OPEN: u32 = 3u; // its box and cluster box are known
struct GroupBlock {
    box_min: vec3<f32>,
    box_max: vec3<f32>,
    clusters_min: vec3<u32>,
    clusters_max: vec3<u32>,
    state: u32,
};
const GROUP_BLOCKS: u32 = REFINE_GROUP_EDGE * REFINE_GROUP_EDGE;
var<private> group: array<GroupBlock, GROUP_BLOCKS>;

fn begin_block() {
    box_min = vec3<f32>(3.0e38);
    box_max = vec3<f32>(-3.0e38);
    pixels_min = vec2<u32>(0xffffffffu);
    pixels_max = vec2<u32>(0u);
    covered = false;
    unbounded = false;
    farthest = 0.0;
}

// Pixel `i` (row-major) of block `b`.
fn block_pixel(b: vec2<u32>, i: u32) -> vec2<u32> {
    return b * REFINE_EDGE + vec2<u32>(i % REFINE_EDGE, i / REFINE_EDGE);
}

// Adds the pixel `px` whose surface lies at view-space `q`.
fn add_pixel(px: vec2<u32>, q: vec3<f32>) {
    if !all(abs(q) <= vec3<f32>(3.0e38)) {
        unbounded = true;
        return;
    }
    box_min = min(box_min, q);
    box_max = max(box_max, q);
    farthest = max(farthest, abs(q.z));
    pixels_min = min(pixels_min, px);
    pixels_max = max(pixels_max, px);
    covered = true;
}

// Widens the box around the block's surface positions by REFINE_SLACK × (distance + the
// camera's distance from the origin) on every side, with the block's largest distance: at
// least each pixel's own widening, once per block rather than per pixel.
fn widen_box() {
    let s = REFINE_SLACK * (farthest + length(view.camera_position.xyz));
    box_min -= vec3<f32>(s);
    box_max += vec3<f32>(s);
}

// The box of clusters the block's pixels fall in with their widened distances: tiles grow with
// the pixel position and slices with the distance, so the clusters of the first pixel at the
// nearest widened distance and of the last at the farthest (the box's z: -(d + s) at its min,
// -(d - s) at its max) bound those of every pixel.
fn find_clusters() {
    let first = vec2<f32>(pixels_min) + 0.5;
    let last = vec2<f32>(pixels_max) + 0.5;
    clusters_min = cluster_coords(cluster_params, first, max(-box_max.z, 0.0));
    clusters_max = cluster_coords(cluster_params, last, -box_min.z);
}

// The linear index of the `k`-th cluster of the block's cluster box.
fn box_cluster(k: u32) -> u32 {
    let n = clusters_max - clusters_min + 1u;
    return cluster_at(cluster_params, clusters_min + vec3<u32>(k % n.x, (k / n.x) % n.y, k / (n.x * n.y)));
}

// True when light `l` is in the (ascending) list `r`.
fn list_holds(r: vec2<u32>, l: u32) -> bool {
    var lo = 0u;
    var hi = r.y;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        let v = indices[r.x + mid];
        if v == l {
            return true;
        }
        if v < l {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return false;
}

// The list (steps 2 and 3 above) of the open block whose box and cluster box are in
// `box_min`.. `clusters_max`, written at `slot`: its range. Takes its list entries × clusters
// from `budget`.
fn refine_lights(slot: u32, budget: ptr<function, u32>) -> vec2<u32> {
    let fallback = vec2<u32>(0u, REFINED_FALLBACK);
    let n3 = clusters_max - clusters_min + 1u;
    let n = n3.x * n3.y * n3.z;
    if n > REFINE_MAX_CLUSTERS {
        return fallback;
    }
    var candidates = 0u;
    for (var k = 0u; k < n; k++) {
        candidates += min(ranges[box_cluster(k)].y, REFINE_CANDIDATE_LIMIT + 1u);
    }
    if candidates > REFINE_CANDIDATE_LIMIT || candidates * n > *budget {
        return fallback;
    }
    *budget -= candidates * n;
    var count = 0u;
    for (var k = 0u; k < n; k++) {
        let r = ranges[box_cluster(k)];
        for (var j = 0u; j < r.y; j++) {
            let l = indices[r.x + j];
            let s = spheres[l];
            if !sphere_intersects_aabb(s.xyz, s.w, box_min, box_max) {
                continue;
            }
            var seen = false;
            for (var e = 0u; e < k && !seen; e++) {
                seen = list_holds(ranges[box_cluster(e)], l);
            }
            if seen {
                continue;
            }
            if count == REFINED_LIST_SLOTS {
                return fallback;
            }
            indices[slot + count] = l;
            count += 1u;
        }
    }
    return vec2<u32>(slot, count);
}

fn in_blocks(b: vec2<u32>) -> bool {
    return b.x < cluster_params.refine_blocks_x && b.y < cluster_params.refine_blocks_y;
}

// Block `q` (row-major) of the group `g`.
fn group_block(g: vec2<u32>, q: u32) -> vec2<u32> {
    return g * REFINE_GROUP_EDGE + vec2<u32>(q % REFINE_GROUP_EDGE, q / REFINE_GROUP_EDGE);
}

// Keeps block `q` of the group from the pixels added since `begin_block` (`inside`: the block
// is one of the image's).
fn close_block(q: u32, inside: bool) {
    var state = BLOCK_OPEN;
    if !inside {
        state = BLOCK_OUTSIDE;
    } else if unbounded {
        state = BLOCK_UNBOUNDED;
    } else if !covered {
        state = BLOCK_EMPTY;
    } else {
        widen_box();
        find_clusters();
    }
    group[q] = GroupBlock(box_min, box_max, clusters_min, clusters_max, state);
}

// Where block `b`'s range and list slots are.
fn range_at(b: vec2<u32>) -> u32 {
    return refined_range_index(cluster_params, b);
}

fn slot_of(at: u32) -> u32 {
    return cluster_params.index_capacity + (at - cluster_params.refined_first) * REFINED_LIST_SLOTS;
}

// The one cluster every open block of the group falls in, or 0xffffffff when they fall in
// more than one (or none is open).
fn shared_cluster() -> u32 {
    var lead = 0xffffffffu;
    var one = true;
    for (var q = 0u; q < GROUP_BLOCKS; q++) {
        let blk = group[q];
        if blk.state == BLOCK_OPEN {
            let c = cluster_at(cluster_params, blk.clusters_min);
            one = one && all(blk.clusters_min == blk.clusters_max) && (lead == 0xffffffffu || c == lead);
            lead = c;
        }
    }
    return select(0xffffffffu, lead, one);
}

// Writes the ranges of the group `g`'s blocks (closed with `close_block`).
fn finish_group(g: vec2<u32>) {
    let fallback = vec2<u32>(0u, REFINED_FALLBACK);
    let lead = shared_cluster();
    if lead != 0xffffffffu {
        // Step 2 once for the group: the shared cluster's list against every open block's box.
        let r = ranges[lead];
        var counts = array<u32, GROUP_BLOCKS>();
        if r.y <= REFINE_CANDIDATE_LIMIT {
            for (var j = 0u; j < r.y; j++) {
                let l = indices[r.x + j];
                let s = spheres[l];
                for (var q = 0u; q < GROUP_BLOCKS; q++) {
                    let blk = group[q];
                    if blk.state == BLOCK_OPEN && sphere_intersects_aabb(s.xyz, s.w, blk.box_min, blk.box_max) {
                        if counts[q] < REFINED_LIST_SLOTS {
                            indices[slot_of(range_at(group_block(g, q))) + counts[q]] = l;
                        }
                        counts[q] += 1u;
                    }
                }
            }
        }
        for (var q = 0u; q < GROUP_BLOCKS; q++) {
            let blk = group[q];
            let at = range_at(group_block(g, q));
            if blk.state == BLOCK_OPEN {
                let fits = r.y <= REFINE_CANDIDATE_LIMIT && counts[q] <= REFINED_LIST_SLOTS;
                ranges[at] = select(fallback, vec2<u32>(slot_of(at), counts[q]), fits);
            } else if blk.state != BLOCK_OUTSIDE {
                ranges[at] = select(fallback, vec2<u32>(slot_of(at), 0u), blk.state == BLOCK_EMPTY);
            }
        }
        return;
    }
    var budget = REFINE_CANDIDATE_LIMIT * REFINE_MAX_CLUSTERS;
    for (var q = 0u; q < GROUP_BLOCKS; q++) {
        let blk = group[q];
        let at = range_at(group_block(g, q));
        if blk.state == BLOCK_OPEN {
            box_min = blk.box_min;
            box_max = blk.box_max;
            clusters_min = blk.clusters_min;
            clusters_max = blk.clusters_max;
            ranges[at] = refine_lights(slot_of(at), &budget);
        } else if blk.state != BLOCK_OUTSIDE {
            ranges[at] = select(fallback, vec2<u32>(slot_of(at), 0u), blk.state == BLOCK_EMPTY);
        }
    }
}

// The view-space position forward shading computes for a pixel at view distance `d`
// (common/surface.wgsl's `surface_point`: on the ray through the pixel centre).
fn forward_position(px: vec2<u32>, d: f32) -> vec3<f32> {
    let ndc = frag_ndc(view, vec2<f32>(px) + 0.5);
    let across = ndc / vec2<f32>(view.clip_from_view[0][0], view.clip_from_view[1][1]);
    return vec3<f32>(across * select(d, 1.0, is_orthographic(view)), -d);
}

fn gbuffer_position(p: vec3<f32>) -> vec3<f32> {
    return (view.view_from_world * vec4<f32>(p, 1.0)).xyz;
}

@compute @workgroup_size(8, 8)
fn cs_forward(@builtin(global_invocation_id) id: vec3<u32>) {
    // A pixel past the image's edge reads the edge's (in the same block) instead.
    let last = textureDimensions(shading_distance) - 1u;
    for (var q = 0u; q < GROUP_BLOCKS; q++) {
        let b = group_block(id.xy, q);
        begin_block();
        if in_blocks(b) {
            for (var i = 0u; i < REFINE_EDGE * REFINE_EDGE; i++) {
                let px = min(block_pixel(b, i), last);
                let d = textureLoad(shading_distance, vec2<i32>(px), 0).r;
                if d > 0.0 || !(abs(d) <= 3.0e38) {
                    add_pixel(px, forward_position(px, d));
                }
            }
        }
        close_block(q, in_blocks(b));
    }
    finish_group(id.xy);
}

// From the G-buffer of the layout the shader is composed for (`gbuffer_read`).
//!if GBUFFER
@compute @workgroup_size(8, 8)
fn cs_gbuffer(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(gb_depth);
    for (var q = 0u; q < GROUP_BLOCKS; q++) {
        let b = group_block(id.xy, q);
        begin_block();
        for (var i = 0u; i < REFINE_EDGE * REFINE_EDGE && in_blocks(b); i++) {
            let px = block_pixel(b, i);
            if all(px < size) && gbuffer_depth(vec2<i32>(px)) > 0.0 {
                add_pixel(px, gbuffer_position(gbuffer_read(vec2<i32>(px)).world_position));
            }
        }
        close_block(q, in_blocks(b));
    }
    finish_group(id.xy);
}
//!endif
