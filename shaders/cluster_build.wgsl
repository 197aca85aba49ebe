// Cluster light assignment on the GPU, in three levels of three or four dispatches each, in one
// compute pass. Level 0 builds a list per coarse tile (span × span tiles); level 1 a list per screen
// tile (the column of clusters behind it) from its coarse tile's list; level 2 each cluster's
// list from its tile's list. So no level tests every light against every tile: at 100 000
// lights on 40 × 23 tiles, level 1 alone used to run 92 million sphere tests twice.
// 0. Level 0, per coarse tile, in one of two ways with the same lists:
//    - from the lights' side, where its bits fit (ClusterResources::coarse_bits): `light_marks`
//      runs one invocation per light, makes the light's rectangle of tiles (`light_rect`, a
//      superset of the tiles whose column accepts it: manylight_core::cluster::RectGrid::light_tile_rect,
//      checked on the CPU by crates/manylight_core/tests/tile_prefilter.rs) and sets the light's
//      bit in each coarse tile of the rectangle that `touches_coarse`; `coarse_count_bits`
//      counts, and `coarse_fill_bits` writes, the set bits of one (coarse tile, chunk of
//      TILE_LIGHT_CHUNK lights) each, in ascending light order. Each light loops over its few
//      coarse tiles, not each coarse tile over every light;
//    - otherwise `coarse_count` and `coarse_fill`: one invocation per (coarse tile, chunk of
//      TILE_LIGHT_CHUNK lights) counts, then writes, the chunk's lights that `touches_coarse`.
//    `touches_coarse` accepts a superset of what any of its columns accepts
//    (manylight_core::cluster::coarse_tile_accepts; checked by tile_prefilter.rs too), and
//    `coarse_scan` makes the lists' offsets. Without a coarse level (`coarse_span` 0: the
//    planes test, which is not monotone in the tile, or a span below 2) these steps are not
//    dispatched and level 1 takes every light as a candidate;
// 1. `tile_count`: one invocation per (tile, chunk of TILE_LIGHT_CHUNK candidates of its coarse
//    tile's list; `tile_chunk`: `tile_chunks` chunks per tile, enough for the longest coarse
//    list there can be; chunks past a tile's list return at once) counts the
//    chunk's lights whose sphere passes the chosen test against the tile's whole column,
//    radius inflated a little more: the column's box contains each cluster's box and its
//    planes are each cluster's side planes moved outwards, so this is a superset of what any
//    cluster of the column accepts (checked on the CPU by
//    crates/manylight_core/tests/tile_prefilter.rs). Chunks keep every invocation's loop short:
//    lavapipe stops an invocation after 65 535 loop iterations (gpu_types::TILE_LIGHT_CHUNK).
//    With level 0's bits, level 1 runs from the coarse lists' side instead: `tile_marks` takes
//    one invocation per position of the coarse lists and tests its light only against the tiles
//    of its coarse tile inside its rectangle, marking a bit per (tile, position) where the
//    column accepts it; `tile_count_bits` and `tile_fill_bits` then count and write the set
//    bits of each (tile, chunk), in ascending position, so the same lists in the same order;
// 2. `tile_scan`: one workgroup turns the (tile, chunk) counts, tile-major, into offsets
//    (exclusive prefix sum), so a tile's chunks lie one after another;
// 3. `tile_fill`: each (tile, chunk) writes its lights in ascending order, so each tile's
//    list is in ascending light order (the coarse lists are, chunk after chunk);
// 4. `count`: one invocation per cluster tests its tile's lights against the cluster's bounds,
//    stores the count (capped if a cap is set) and updates the counters;
// 5. `scan`: prefix sum of the cluster counts, and the total the index list needs;
// 6. `fill`: writes the first `count` hits, in ascending light order, at the cluster's offset.
// Levels 0 and 1 share buffers (a device binds 8 storage buffers per stage): the coarse
// tiles' bounds follow the tiles' in `tile_bounds`, their (coarse tile, chunk) ranges follow
// the (tile, chunk) ranges in `tile_ranges`, and their lists follow the `tile_index_capacity`
// entries of the tile lists in `tile_indices`.
// Sums and offsets saturate at 2^32 - 1 instead of wrapping (`add_saturating`), so a frame
// with more pairs than a u32 counts is seen as too large (PAIR_COUNT_SATURATED) rather than as
// a small total whose lists would silently miss lights.
// The lists are sized from the counters of earlier frames, read back without waiting: no
// bound is computed on the CPU. A fill whose list does not fit is skipped, and a cluster
// whose list is missing or incomplete for that (its coarse tile's list, its tile's list or its
// own did not fit, or its tile list is longer than the loop limit) gets the range
// (0, LIST_EVERY_LIGHT): its pixels shade from every light that frame, exact and slower,
// `fallback_clusters` counts it, and the renderer grows the lists for the next frames. No
// frame is rendered twice and no light is lost. The result is otherwise the same compacted
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
    coarse_entries: atomic<u32>,
    fallback_clusters: atomic<u32>,
};

@group(0) @binding(0) var<uniform> params: ClusterParams;
@group(0) @binding(1) var<storage, read> bounds: array<GpuClusterBounds>;
// The lights' view-space spheres (centre, radius; light_spheres.wgsl writes them first).
@group(0) @binding(2) var<storage, read> spheres: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> ranges: array<vec2<u32>>;
@group(0) @binding(4) var<storage, read_write> indices: array<u32>;
// The counters, then, where levels 0 and 1 run from the lights' side, their bits (the build's
// 8 storage bindings are taken, and atomics need an atomic binding): level 0's first
// (`light_marks`: bit `e % 32` of word `c * coarse_words + e / 32` of `coarse_bits` is set when
// coarse tile `c` keeps light `e`, `coarse_words` being `light_chunks * CHUNK_WORDS`, a chunk
// of TILE_LIGHT_CHUNK lights being CHUNK_WORDS words), then level
// 1's (`tile_marks`, `tile_bits_first`). The renderer clears the bits before the build.
struct ClusterBuildState {
    counters: ClusterCounters,
    coarse_bits: array<atomic<u32>>,
};

@group(0) @binding(5) var<storage, read_write> build: ClusterBuildState;
@group(0) @binding(6) var<storage, read> tile_bounds: array<GpuClusterBounds>;
@group(0) @binding(7) var<storage, read_write> tile_ranges: array<vec2<u32>>;
@group(0) @binding(8) var<storage, read_write> tile_indices: array<u32>;

// TILE_PREFILTER_INFLATION (from Rust, manylight_core::cluster::TILE_PREFILTER_INFLATION): extra
// inflation of the tile prefilter, so float rounding can never make it reject a light a cluster
// of the column would accept.

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

// Entries of `tile_ranges` for level 1: one per (tile, chunk), tile-major.
fn tile_entry_total() -> u32 {
    return tile_count_total() * params.tile_chunks;
}

fn coarse_count_total() -> u32 {
    return params.coarse_dims.x * params.coarse_dims.y;
}

// Entries of `tile_ranges` for level 0, after level 1's: one per (coarse tile, chunk).
fn coarse_entry_total() -> u32 {
    return select(0u, coarse_count_total() * params.light_chunks, params.coarse_span > 0u);
}

// The positions [first, end) of chunk `chunk` in a list of `n` candidates.
fn chunk_range(chunk: u32, n: u32) -> vec2<u32> {
    let first = chunk * TILE_LIGHT_CHUNK;
    return vec2<u32>(first, min(first + TILE_LIGHT_CHUNK, n));
}

// Invocation `e` of levels 0 and 1 handles chunk `e / tiles` of tile `e % tiles` (of `tiles`
// tiles or coarse tiles): neighbouring invocations, which run side by side in a SIMD group and
// wait for its longest loop, take the same chunk of different tiles, so a group is either all
// at work or all past the end of its lists. Returns (tile, chunk, entry): `entry` indexes the
// tile-major ranges, where a tile's chunks lie one after another.
fn chunk_of(e: u32, tiles: u32, chunks: u32) -> vec3<u32> {
    let tile = e % tiles;
    let chunk = e / tiles;
    return vec3<u32>(tile, chunk, tile * chunks + chunk);
}

// Invocation `e` of level 0: (coarse tile, chunk of its `light_chunks` chunks of candidates,
// entry).
fn coarse_chunk(e: u32) -> vec3<u32> {
    return chunk_of(e, coarse_count_total(), params.light_chunks);
}

// Invocation `e` of level 1: (tile, chunk of `tile_chunks` chunks of its candidates, entry).
fn tile_chunk(e: u32) -> vec3<u32> {
    return chunk_of(e, tile_count_total(), params.tile_chunks);
}

// The list (offset, count) made of the `chunks` consecutive entries from `first` of
// `tile_ranges`.
fn chunked_range(first: u32, chunks: u32) -> vec2<u32> {
    let a = tile_ranges[first];
    let z = tile_ranges[first + chunks - 1u];
    return vec2<u32>(a.x, add_saturating(z.x, z.y) - a.x);
}

// `chunked_range`, or empty when it does not fit in `capacity` entries this frame: its fill
// skipped it, and the clusters below it shade from every light (`fill`).
fn chunked_list(first: u32, chunks: u32, capacity: u32) -> vec2<u32> {
    let range = chunked_range(first, chunks);
    return select(vec2<u32>(0u), range, fits(range, capacity));
}

const RECT_NONE = vec2<u32>(0xffffu, 0xffffu);

// Tiles `k` whose span [k, k + 1] (tile units) meets [lo, hi] padded by RECT_PAD, as (first,
// last); `first > last` when none does, the whole axis for NaN (RectGrid::light_tile_rect's `tile_span`).
fn rect_span(lo: f32, hi: f32, n: u32) -> vec2<u32> {
    let last = f32(n - 1u);
    let first = ceil(lo - RECT_PAD) - 1.0;
    let end = floor(hi + RECT_PAD);
    if first > last || end < 0.0 || first > end {
        return vec2<u32>(0xffffu, 0u);
    }
    // NaN compares false both ways: the whole axis.
    let a = select(0.0, min(first, last), first >= 0.0);
    let b = select(last, max(end, 0.0), end <= last);
    return vec2<u32>(u32(a), u32(b));
}

// Slopes a column's edges must reach for its box over depths [near, far] to meet [a - big,
// a + big] (RectGrid::light_tile_rect's `box_slopes`).
fn box_slopes(a: f32, big: f32, near: f32, far: f32) -> vec2<f32> {
    let lo = a - big;
    let hi = a + big;
    return vec2<f32>(lo / select(far, near, lo <= 0.0), hi / select(far, near, hi >= 0.0));
}

// Slopes of the two lines through the eye tangent to the circle of radius `big` around (a, d),
// den = (d - big)(d + big) > 0 (RectGrid::light_tile_rect's `tangent_slopes`).
fn tangent_slopes(a: f32, d: f32, big: f32, den: f32) -> vec2<f32> {
    let root = big * sqrt(a * a + den);
    return vec2<f32>((a * d - root) / den, (a * d + root) / den);
}

// Whether some pair of tile edges in [-tan, tan] can have the sphere within reach of both side
// planes (RectGrid::light_tile_rect's `within_side_planes`).
fn within_side_planes(a: f32, d: f32, big: f32, tan: f32) -> bool {
    return abs(a) <= abs(tan * d) + big * sqrt(1.0 + tan * tan);
}

// The tile rectangle of sphere `s` (manylight_core::cluster::RectGrid::light_tile_rect, step for step),
// packed as (x0 | x1 << 16, y0 | y1 << 16), inclusive tile coordinates (a grid has at most 4096
// tiles across); RECT_NONE when no tile can accept the light.
fn light_rect(s: vec4<f32>) -> vec2<u32> {
    let tiles = params.dims.xy;
    let everything = vec2<u32>(((tiles.x - 1u) << 16u), ((tiles.y - 1u) << 16u));
    // 1. `>` is false for NaN.
    if !(s.w > 0.0) {
        return RECT_NONE;
    }
    // 2. `<` is false for NaN and infinities.
    let size = abs(s.x) + abs(s.y) + abs(s.z) + s.w;
    if !(size < RECT_MAGNITUDE) {
        return everything;
    }
    // 3.
    let f = params.frustum;
    let near = params.viewport.z;
    let far = params.viewport.w;
    let r = s.w * (TILE_PREFILTER_INFLATION * TILE_PREFILTER_INFLATION * RADIUS_INFLATION);
    let big = r + 4.0 * f.w + RECT_SLACK * size;
    // 4.
    let d = -s.z;
    if d + big < near || d - big > far {
        return RECT_NONE;
    }
    // 5. Slope ranges in NDC units.
    var x = vec2<f32>(s.x - big, s.x + big) / f.x;
    var y = vec2<f32>(s.y - big, s.y + big) / f.y;
    if f.z <= 0.5 {
        let planes_only = params.cull_test == CULL_PLANES;
        x = select(box_slopes(s.x, big, near, far), vec2<f32>(-3.0e38, 3.0e38), planes_only);
        y = select(box_slopes(s.y, big, near, far), vec2<f32>(-3.0e38, 3.0e38), planes_only);
        let den = (d - big) * (d + big);
        if params.cull_test != CULL_AABB && d > 2.0 * big && den > 1e-30 {
            let tx = tangent_slopes(s.x, d, big, den);
            let ty = tangent_slopes(s.y, d, big, den);
            x = vec2<f32>(max(x.x, tx.x), min(x.y, tx.y));
            y = vec2<f32>(max(y.x, ty.x), min(y.y, ty.y));
        } else if params.cull_test != CULL_AABB
            && !(within_side_planes(s.x, d, big, f.x) && within_side_planes(s.y, d, big, f.y)) {
            return RECT_NONE;
        }
        x /= f.x;
        y /= f.y;
    }
    // 6. Tile x spans NDC [-1 + 2k/X, ...]; tile row 0 is at the top.
    let n = vec2<f32>(tiles);
    let xs = rect_span((x.x + 1.0) * 0.5 * n.x, (x.y + 1.0) * 0.5 * n.x, tiles.x);
    let ys = rect_span((1.0 - y.y) * 0.5 * n.y, (1.0 - y.x) * 0.5 * n.y, tiles.y);
    if xs.x > xs.y || ys.x > ys.y {
        return RECT_NONE;
    }
    return vec2<u32>(xs.x | (xs.y << 16u), ys.x | (ys.y << 16u));
}

// The first (x0, y0) and last (x1, y1) tile of a rectangle from `light_rect`.
fn rect_first(rect: vec2<u32>) -> vec2<u32> {
    return rect & vec2<u32>(0xffffu);
}

fn rect_last(rect: vec2<u32>) -> vec2<u32> {
    return rect >> vec2<u32>(16u);
}

// Level 0's test (manylight_core::cluster::coarse_tile_accepts, where the proof is): the
// sphere, radius inflated as for level 1, must reach the hull of the coarse tile's columns'
// AABBs, and, unless the AABB test is chosen, its planes with the radius inflated once more,
// when the sphere lies in front of the eye by more than twice the column margin (`aabb_min.w`).
fn touches_coarse(b: GpuClusterBounds, light: u32) -> bool {
    let s = spheres[light];
    let r = s.w * TILE_PREFILTER_INFLATION;
    if !sphere_intersects_aabb(s.xyz, r, b.aabb_min.xyz, b.aabb_max.xyz) {
        return false;
    }
    if params.cull_test == CULL_AABB {
        return true;
    }
    let wide = r * TILE_PREFILTER_INFLATION;
    let in_front = -s.z > wide * RADIUS_INFLATION + 2.0 * b.aabb_min.w;
    return !in_front || sphere_intersects_planes(s.xyz, wide, b);
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn coarse_count(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = linear_index(id, groups);
    if e >= coarse_entry_total() {
        return;
    }
    let c = coarse_chunk(e);
    let b = tile_bounds[tile_count_total() + c.x];
    let lights = chunk_range(c.y, params.light_count);
    var n = 0u;
    for (var l = lights.x; l < lights.y; l++) {
        if touches_coarse(b, l) {
            n += 1u;
        }
    }
    tile_ranges[tile_entry_total() + c.z] = vec2<u32>(0u, n);
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn coarse_fill(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = linear_index(id, groups);
    if e >= coarse_entry_total() {
        return;
    }
    let c = coarse_chunk(e);
    let range = tile_ranges[tile_entry_total() + c.z];
    if !fits(range, params.coarse_index_capacity) {
        return;
    }
    let b = tile_bounds[tile_count_total() + c.x];
    let lights = chunk_range(c.y, params.light_count);
    let base = params.tile_index_capacity + range.x;
    var k = 0u;
    for (var l = lights.x; l < lights.y && k < range.y; l++) {
        if touches_coarse(b, l) {
            tile_indices[base + k] = l;
            k += 1u;
        }
    }
}

// Words of `coarse_bits` per chunk of TILE_LIGHT_CHUNK lights.
const CHUNK_WORDS: u32 = TILE_LIGHT_CHUNK / 32u;

// The first word of coarse tile `c`'s chunk `chunk` in `coarse_bits`.
fn coarse_word(c: u32, chunk: u32) -> u32 {
    return (c * params.light_chunks + chunk) * CHUNK_WORDS;
}

// Word `w` of the bits from `row` (level 0's of a coarse tile, or level 1's of a tile), with
// only the bits of positions [first, end) kept.
fn bits_between(row: u32, w: u32, first: u32, end: u32) -> u32 {
    var bits = atomicLoad(&build.coarse_bits[row + w]);
    let base = w * 32u;
    if first > base {
        bits &= ~0u << (first - base);
    }
    if end < base + 32u {
        bits &= (1u << (end - base)) - 1u;
    }
    return bits;
}

// The set bits of positions [first, end) of the bits from `row`.
fn count_bits(row: u32, first: u32, end: u32) -> u32 {
    var n = 0u;
    if first < end {
        for (var w = first / 32u; w <= (end - 1u) / 32u; w++) {
            n += countOneBits(bits_between(row, w, first, end));
        }
    }
    return n;
}

// Level 0 from the lights' side (where the coarse bits fit, `ClusterResources`): one invocation
// per light makes its rectangle (`light_rect`) and sets its bit in each coarse tile of the
// rectangle that `touches_coarse`. The loops run over the rectangle, at most
// COARSE_SCATTER_TILES coarse tiles, not over the lights; a light that no tile can list (an
// empty rectangle: behind the camera, outside the frustum) returns at once.
@compute @workgroup_size(WORKGROUP_SIZE)
fn light_marks(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = linear_index(id, groups);
    if e >= params.light_count {
        return;
    }
    let l = e;
    let rect = light_rect(spheres[l]);
    let span = params.coarse_span;
    let lo = rect_first(rect) / span;
    let hi = rect_last(rect) / span;
    let word = e / 32u;
    let bit = 1u << (e % 32u);
    for (var y = lo.y; y <= hi.y; y++) {
        for (var x = lo.x; x <= hi.x; x++) {
            let c = x + y * params.coarse_dims.x;
            if touches_coarse(tile_bounds[tile_count_total() + c], l) {
                atomicOr(&build.coarse_bits[coarse_word(c, 0u) + word], bit);
            }
        }
    }
}

// `coarse_count` from the bits: the chunk's lights are the set bits of its CHUNK_WORDS words.
@compute @workgroup_size(WORKGROUP_SIZE)
fn coarse_count_bits(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = linear_index(id, groups);
    if e >= coarse_entry_total() {
        return;
    }
    let c = coarse_chunk(e);
    let lights = chunk_range(c.y, params.light_count);
    tile_ranges[tile_entry_total() + c.z] = vec2<u32>(0u, count_bits(coarse_word(c.x, 0u), lights.x, lights.y));
}

// `coarse_fill` from the bits: the set bits in ascending order, so the coarse lists are in
// ascending light order as before.
@compute @workgroup_size(WORKGROUP_SIZE)
fn coarse_fill_bits(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = linear_index(id, groups);
    if e >= coarse_entry_total() {
        return;
    }
    let c = coarse_chunk(e);
    let range = tile_ranges[tile_entry_total() + c.z];
    if !fits(range, params.coarse_index_capacity) {
        return;
    }
    let first = coarse_word(c.x, c.y);
    let base = params.tile_index_capacity + range.x;
    var k = 0u;
    for (var i = 0u; i < CHUNK_WORDS; i++) {
        var bits = atomicLoad(&build.coarse_bits[first + i]);
        let first_light = (c.y * CHUNK_WORDS + i) * 32u;
        // One iteration per set bit; at most TILE_LIGHT_CHUNK in all.
        while bits != 0u && k < range.y {
            tile_indices[base + k] = first_light + firstTrailingBit(bits);
            k += 1u;
            bits &= bits - 1u;
        }
    }
}

// The first entry of `tile_ranges` of the coarse tile that holds tile `t`.
fn coarse_entry_of_tile(t: u32) -> u32 {
    let x = (t % params.dims.x) / params.coarse_span;
    let y = (t / params.dims.x) / params.coarse_span;
    return tile_entry_total() + (x + y * params.coarse_dims.x) * params.light_chunks;
}

// Level 1's candidates for tile `t`: its coarse tile's list (offset, count into the coarse
// lists), or, without a coarse level, every light.
fn tile_candidates(t: u32) -> vec2<u32> {
    if params.coarse_span == 0u {
        return vec2<u32>(0u, params.light_count);
    }
    return chunked_list(coarse_entry_of_tile(t), params.light_chunks, params.coarse_index_capacity);
}

// True when tile `t`'s candidates are all its coarse tile's lights: there is no coarse level,
// or its coarse tile's list fit this frame's coarse lists and level 1's `tile_chunks` chunks.
fn candidates_complete(t: u32) -> bool {
    if params.coarse_span == 0u {
        return true;
    }
    let list = chunked_range(coarse_entry_of_tile(t), params.light_chunks);
    return fits(list, params.coarse_index_capacity) && list.y <= params.tile_chunks * TILE_LIGHT_CHUNK;
}

// Candidate `i` of a list from `tile_candidates`.
fn candidate(list: vec2<u32>, i: u32) -> u32 {
    if params.coarse_span == 0u {
        return i;
    }
    return tile_indices[params.tile_index_capacity + list.x + i];
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn tile_count(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = linear_index(id, groups);
    if e >= tile_entry_total() {
        return;
    }
    let t = tile_chunk(e);
    let b = tile_bounds[t.x];
    let list = tile_candidates(t.x);
    let part = chunk_range(t.y, list.y);
    var n = 0u;
    for (var i = part.x; i < part.y; i++) {
        if touches_tile(b, candidate(list, i)) {
            n += 1u;
        }
    }
    tile_ranges[t.z] = vec2<u32>(0u, n);
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn tile_fill(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = linear_index(id, groups);
    if e >= tile_entry_total() {
        return;
    }
    let t = tile_chunk(e);
    let range = tile_ranges[t.z];
    if !fits(range, params.tile_index_capacity) {
        return;
    }
    let b = tile_bounds[t.x];
    let list = tile_candidates(t.x);
    let part = chunk_range(t.y, list.y);
    var k = 0u;
    for (var i = part.x; i < part.y && k < range.y; i++) {
        let l = candidate(list, i);
        if touches_tile(b, l) {
            tile_indices[range.x + k] = l;
            k += 1u;
        }
    }
}

// Level 1 from the coarse lists' side (with level 0's bits), after level 0's bits in
// `coarse_bits`: bit `p % 32` of word `tile_bits_first() + k * tile_bit_words() + p / 32` is set
// when the k-th tile of its coarse tile (`local_tile`) keeps the light at position `p` of the
// coarse lists.
fn tile_bits_first() -> u32 {
    return coarse_count_total() * params.light_chunks * CHUNK_WORDS;
}

fn tile_bit_words() -> u32 {
    return (params.coarse_index_capacity + 31u) / 32u;
}

// The index of tile (x, y) among the span × span tiles of its coarse tile.
fn local_tile(x: u32, y: u32) -> u32 {
    let span = params.coarse_span;
    return x % span + (y % span) * span;
}

// The (coarse tile, chunk) entry of level 0's ranges whose list holds position `p` of the coarse
// lists: the last entry whose offset is at most `p` (offsets grow entry by entry, and an entry
// with the offset of the next one is empty).
fn coarse_entry_of(p: u32) -> u32 {
    var lo = 0u;
    var hi = coarse_entry_total();
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if tile_ranges[tile_entry_total() + mid].x <= p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// One invocation per position of the coarse lists: the light there is tested against the tiles
// of its coarse tile that lie in its rectangle (the others cannot accept it), and marked in
// those whose column accepts it. Each entry loops over at most span × span tiles.
@compute @workgroup_size(WORKGROUP_SIZE)
fn tile_marks(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let p = linear_index(id, groups);
    if p >= min(atomicLoad(&build.counters.coarse_entries), params.coarse_index_capacity) {
        return;
    }
    let c = coarse_entry_of(p) / params.light_chunks;
    let l = tile_indices[params.tile_index_capacity + p];
    let rect = light_rect(spheres[l]);
    let span = params.coarse_span;
    let origin = vec2<u32>(c % params.coarse_dims.x, c / params.coarse_dims.x) * span;
    let lo = max(rect_first(rect), origin);
    let hi = min(rect_last(rect), min(origin + vec2<u32>(span - 1u), params.dims.xy - vec2<u32>(1u)));
    let word = tile_bits_first() + p / 32u;
    let bit = 1u << (p % 32u);
    for (var y = lo.y; y <= hi.y; y++) {
        for (var x = lo.x; x <= hi.x; x++) {
            if touches_tile(tile_bounds[x + y * params.dims.x], l) {
                atomicOr(&build.coarse_bits[word + local_tile(x, y) * tile_bit_words()], bit);
            }
        }
    }
}

// A (tile, chunk)'s row of tile bits and its positions [first, end) in the coarse lists.
fn tile_bit_span(t: vec3<u32>) -> vec3<u32> {
    let list = tile_candidates(t.x);
    let part = chunk_range(t.y, list.y);
    let row = tile_bits_first() + local_tile(t.x % params.dims.x, t.x / params.dims.x) * tile_bit_words();
    return vec3<u32>(row, list.x + part.x, list.x + max(part.x, part.y));
}

// `tile_count` from the bits: the chunk's lights are the set bits of its positions.
@compute @workgroup_size(WORKGROUP_SIZE)
fn tile_count_bits(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = linear_index(id, groups);
    if e >= tile_entry_total() {
        return;
    }
    let t = tile_chunk(e);
    let b = tile_bit_span(t);
    tile_ranges[t.z] = vec2<u32>(0u, count_bits(b.x, b.y, b.z));
}

// `tile_fill` from the bits, in ascending position, so in ascending light order.
@compute @workgroup_size(WORKGROUP_SIZE)
fn tile_fill_bits(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let e = linear_index(id, groups);
    if e >= tile_entry_total() {
        return;
    }
    let t = tile_chunk(e);
    let range = tile_ranges[t.z];
    if !fits(range, params.tile_index_capacity) {
        return;
    }
    let b = tile_bit_span(t);
    var k = 0u;
    if b.y < b.z {
        for (var w = b.y / 32u; w <= (b.z - 1u) / 32u; w++) {
            var bits = bits_between(b.x, w, b.y, b.z);
            // One iteration per set bit; at most TILE_LIGHT_CHUNK in all.
            while bits != 0u && k < range.y {
                let p = w * 32u + firstTrailingBit(bits);
                tile_indices[range.x + k] = tile_indices[params.tile_index_capacity + p];
                k += 1u;
                bits &= bits - 1u;
            }
        }
    }
}

// The lights of a cluster's tile (`range`: offset, count into `tile_indices`, from its first and
// last chunk's ranges), and whether they are every light of the tile's column the build can
// loop over: its coarse tile's list and its own fit this frame's lists, and it is no longer
// than `loop_limit`. When not (`exact` false), the range is empty and the cluster shades from
// every light (`fill`).
struct TileLights {
    range: vec2<u32>,
    exact: bool,
};

fn tile_lights(cluster: u32) -> TileLights {
    let t = cluster % tile_count_total();
    let chunks = params.tile_chunks;
    let range = chunked_range(t * chunks, chunks);
    let exact = candidates_complete(t) && fits(range, params.tile_index_capacity) && range.y <= params.loop_limit;
    return TileLights(select(vec2<u32>(0u), range, exact), exact);
}

// The coordinate (x for planes 0 and 1, y for 2 and 3: `along` is the plane's normal along
// that axis) where side plane `p` of a tile column (normal (nx, ny, nz), through the eye or
// axis-parallel) crosses view depth `d`: x = (nz d - w) / nx. A column's extent between two
// depths lies between its side planes' crossings at those depths (linear in the depth).
fn plane_crossing(p: vec4<f32>, along: f32, d: f32) -> f32 {
    return (p.z * d - p.w) / along;
}

// The x (planes 0 and 1) or y (2 and 3) extent of the column between depths `near` and `far`,
// widened for rounding; the whole axis when a normal has no component along it.
fn column_extent(a: vec4<f32>, b: vec4<f32>, along_a: f32, along_b: f32, near: f32, far: f32) -> vec2<f32> {
    let c = vec4<f32>(
        plane_crossing(a, along_a, near),
        plane_crossing(a, along_a, far),
        plane_crossing(b, along_b, near),
        plane_crossing(b, along_b, far),
    );
    let lo = min(min(c.x, c.y), min(c.z, c.w));
    let hi = max(max(c.x, c.y), max(c.z, c.w));
    let widen = 1e-5 * (max(abs(lo), abs(hi)) + far);
    // `>=` is false for NaN (a zero normal component): then the whole axis.
    if abs(along_a) >= 1e-6 && abs(along_b) >= 1e-6 && hi >= lo {
        return vec2<f32>(lo - widen, hi + widen);
    }
    return vec2<f32>(-3.0e38, 3.0e38);
}

// With depth bounds: true when no pixel falls in the cluster (its depth range, kept after the
// cluster ranges by `cluster_depth.wgsl`, is still zero), so it keeps no light.
fn cluster_without_pixels(cluster: u32) -> bool {
    return params.depth_bounds != 0u && ranges[params.dims.w + cluster].y == 0u;
}

// The cluster's bounds for level 2: with depth bounds, cut to the depth range of the pixels in it
// (order keys after the cluster ranges: the complement of the nearest, the farthest).
fn level2_bounds(cluster: u32) -> GpuClusterBounds {
    var b = bounds[cluster];
    if params.depth_bounds != 0u {
        let r = ranges[params.dims.w + cluster];
        let near = from_order_key(~r.x);
        let far = from_order_key(r.y);
        // Planes 4 and 5 are the slice's near (0, 0, -1, -d0) and far (0, 0, 1, d1) planes.
        b.planes[4].w = min(b.planes[4].w, -near);
        b.planes[5].w = min(b.planes[5].w, far);
        b.aabb_min.z = max(b.aabb_min.z, -far);
        b.aabb_max.z = min(b.aabb_max.z, -near);
        let p = b.planes;
        let x = column_extent(p[0], p[1], p[0].x, p[1].x, near, far);
        let y = column_extent(p[2], p[3], p[2].y, p[3].y, near, far);
        b.aabb_min.x = max(b.aabb_min.x, x.x);
        b.aabb_max.x = min(b.aabb_max.x, x.y);
        b.aabb_min.y = max(b.aabb_min.y, y.x);
        b.aabb_max.y = min(b.aabb_max.y, y.y);
    }
    return b;
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn count(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let cluster = linear_index(id, groups);
    if cluster >= params.dims.w {
        return;
    }
    let b = level2_bounds(cluster);
    let lights = tile_lights(cluster);
    var tile = lights.range;
    if cluster_without_pixels(cluster) {
        tile.y = 0u;
    }
    // The longest tile list the loops below run over (lavapipe ends an invocation after
    // LAVAPIPE_LOOP_LIMIT iterations: a longer list is not looped over, `loop_limit`).
    atomicMax(&build.counters.max_tile_lights, tile.y);
    var n = 0u;
    for (var i = 0u; i < tile.y; i++) {
        if touches(b, tile_indices[tile.x + i]) {
            n += 1u;
        }
    }
    let kept = min(n, params.cap);
    ranges[cluster] = vec2<u32>(0u, kept);
    if n > kept {
        atomicAdd(&build.counters.dropped_pairs, n - kept);
        atomicAdd(&build.counters.clusters_overflowed, 1u);
    }
    if n > 0u {
        atomicAdd(&build.counters.non_empty, 1u);
    }
    atomicMax(&build.counters.max_count, n);
}

var<workgroup> partial_sums: array<u32, SCAN_WORKGROUP_SIZE>;
var<workgroup> scan_total: u32;

// Exclusive prefix sum of the counts (`.y`) of `count` entries from `first` of `ranges`
// (`clusters`) or `tile_ranges` into their offsets (`.x`); returns the total. One workgroup:
// each invocation sums a chunk, invocation 0 scans the chunk sums, each invocation then writes
// its chunk's offsets.
fn scan_ranges(clusters: bool, first: u32, count: u32, t: u32) -> u32 {
    let chunk = (count + SCAN_WORKGROUP_SIZE - 1u) / SCAN_WORKGROUP_SIZE;
    let begin = first + min(t * chunk, count);
    let end = min(begin + chunk, first + count);
    var sum = 0u;
    for (var c = begin; c < end; c++) {
        sum = add_saturating(sum, select(tile_ranges[c].y, ranges[c].y, clusters));
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
        if clusters {
            let n = ranges[c].y;
            ranges[c].x = offset;
            offset = add_saturating(offset, n);
        } else {
            let n = tile_ranges[c].y;
            tile_ranges[c].x = offset;
            offset = add_saturating(offset, n);
        }
    }
    return scan_total;
}

@compute @workgroup_size(SCAN_WORKGROUP_SIZE)
fn coarse_scan(@builtin(local_invocation_index) t: u32) {
    let total = scan_ranges(false, tile_entry_total(), coarse_entry_total(), t);
    if t == 0u {
        atomicStore(&build.counters.coarse_entries, total);
    }
}

@compute @workgroup_size(SCAN_WORKGROUP_SIZE)
fn tile_scan(@builtin(local_invocation_index) t: u32) {
    let total = scan_ranges(false, 0u, tile_entry_total(), t);
    if t == 0u {
        atomicStore(&build.counters.tile_entries, total);
    }
}

@compute @workgroup_size(SCAN_WORKGROUP_SIZE)
fn scan(@builtin(local_invocation_index) t: u32) {
    let total = scan_ranges(true, 0u, params.dims.w, t);
    if t == 0u {
        atomicStore(&build.counters.total_entries, total);
    }
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn fill(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    let cluster = linear_index(id, groups);
    if cluster >= params.dims.w {
        return;
    }
    if cluster_without_pixels(cluster) {
        return; // no pixel shades from it: its list stays empty
    }
    let range = ranges[cluster];
    let lights = tile_lights(cluster);
    if !lights.exact || !fits(range, params.index_capacity) {
        // This frame's lists cannot hold the cluster's list: its pixels shade from every light
        // (exact, slower), and the lists grow for the following frames from the counters.
        ranges[cluster] = vec2<u32>(0u, LIST_EVERY_LIGHT);
        atomicAdd(&build.counters.fallback_clusters, 1u);
        return;
    }
    let b = level2_bounds(cluster);
    let tile = lights.range;
    var k = 0u;
    for (var i = 0u; i < tile.y && k < range.y; i++) {
        let l = tile_indices[tile.x + i];
        if touches(b, l) {
            indices[range.x + k] = l;
            k += 1u;
        }
    }
}
