// Tiled deferred lighting in compute: one workgroup per screen tile of the light grid (the grid
// has one depth slice here, so a cluster is a tile and its list holds the lights whose sphere
// reaches the tile's column). The workgroup
//   1. finds the depth range of its pixels (view distance of the positions it will shade) and
//      a mask of which of TILED_DEPTH_CELLS equal cells of that range hold a pixel (2.5D
//      culling, Harada 2012),
//   2. keeps the column's lights whose depth interval meets an occupied cell, in workgroup
//      memory (TILED_LIST_CAPACITY entries; a longer list shades from the column's list),
//   3. shades each pixel from that shared list, with the same shading code as the other
//      pipelines, into the HDR image.
// Both tests are exact for a pixel: a light reaches a pixel only within its radius, so its view
// distance differs from the pixel's by at most the radius (times the view's z-row scale); the
// cell of a distance is one monotone float expression, so a pixel in the interval lies in a
// cell the interval covers.
//!include common/view.wgsl
//!include common/lights.wgsl
//!include common/brdf.wgsl
//!include common/clusters.wgsl

// group 0, binding 0: `view` (common/view_binding.wgsl, through common/gbuffer_read.wgsl)
//!include common/point_lights.wgsl

//!include common/gbuffer_read.wgsl

@group(2) @binding(0) var<uniform> cluster_params: ClusterParams;
@group(2) @binding(1) var<storage, read> cluster_ranges: array<vec2<u32>>;
@group(2) @binding(2) var<storage, read> cluster_indices: array<u32>;

@group(3) @binding(0) var hdr_out: texture_storage_2d<rgba16float, write>;

// Smallest and largest view distance of the tile's pixels, as order-preserving u32 keys.
var<workgroup> depth_lo: atomic<u32>;
var<workgroup> depth_hi: atomic<u32>;
// 1 when a pixel's distance is not finite: the tile keeps its whole column list.
var<workgroup> depth_unbounded: atomic<u32>;
// Bit c: a pixel lies in depth cell c of [lo, hi].
var<workgroup> depth_mask: atomic<u32>;
// Lights kept (may exceed TILED_LIST_CAPACITY: then the tile shades from its column list).
var<workgroup> list_count: atomic<u32>;
var<workgroup> tile_list: array<u32, TILED_LIST_CAPACITY>;

const PHASE_BOUNDS: u32 = 0u;
const PHASE_MASK: u32 = 1u;
const PHASE_SHADE: u32 = 2u;

// Tile of pixel `px` along an axis of `n` tiles over `size` pixels: `cluster_index`'s expression
// at the pixel centre.
fn tile_of_pixel(px: u32, n: u32, size: f32) -> u32 {
    let t = floor((f32(px) + 0.5) * f32(n) / size);
    return u32(clamp(t, 0.0, f32(n - 1u)));
}

// First pixel of tile `t` along that axis (`size_px` pixels): the guess from the tile width
// sits at most two pixels before it.
fn first_pixel(t: u32, n: u32, size: f32, size_px: u32) -> u32 {
    if t == 0u {
        return 0u;
    }
    if t >= n {
        return size_px;
    }
    var p = u32(max(floor(f32(t) * size / f32(n)) - 2.0, 0.0));
    // Unrolled: lavapipe counts every loop iteration of an invocation against one limit.
    p += u32(p < size_px && tile_of_pixel(p, n, size) < t);
    p += u32(p < size_px && tile_of_pixel(p, n, size) < t);
    p += u32(p < size_px && tile_of_pixel(p, n, size) < t);
    p += u32(p < size_px && tile_of_pixel(p, n, size) < t);
    return p;
}

// The tile's pixels: x0, y0, x1, y1 (end exclusive).
fn tile_rect(tile: vec2<u32>) -> vec4<u32> {
    let size = textureDimensions(hdr_out);
    let n = cluster_params.dims.xy;
    let v = cluster_params.viewport.xy;
    return vec4<u32>(
        first_pixel(tile.x, n.x, v.x, size.x),
        first_pixel(tile.y, n.y, v.y, size.y),
        first_pixel(tile.x + 1u, n.x, v.x, size.x),
        first_pixel(tile.y + 1u, n.y, v.y, size.y),
    );
}

fn begin_tile(li: u32) {
    if li == 0u {
        atomicStore(&depth_lo, 0xffffffffu);
        atomicStore(&depth_hi, 0u);
        atomicStore(&depth_unbounded, 0u);
        atomicStore(&depth_mask, 0u);
        atomicStore(&list_count, 0u);
    }
    workgroupBarrier();
}

// The tile's depth range: (lo, hi); lo > hi when no pixel is covered.
fn tile_depths() -> vec2<f32> {
    return vec2<f32>(from_order_key(atomicLoad(&depth_lo)), from_order_key(atomicLoad(&depth_hi)));
}

// Depth cell of distance `d` in the range `r` (lo, hi): one monotone expression.
fn depth_cell(d: f32, r: vec2<f32>) -> u32 {
    let cells = f32(TILED_DEPTH_CELLS);
    let c = floor((d - r.x) * (cells / max(r.y - r.x, 1e-30)));
    return u32(clamp(c, 0.0, cells - 1.0));
}

// True unless the light's depth interval misses every occupied cell of the tile.
fn light_reaches_tile(light: GpuPointLight, r: vec2<f32>, mask: u32) -> bool {
    let bounds = light_bounds(light);
    let p = bounds.xyz;
    let z_row = vec3<f32>(view.view_from_world[0].z, view.view_from_world[1].z, view.view_from_world[2].z);
    let d = gbuffer_view_distance(p);
    // Reach along the view axis, widened by the radius inflation of the cluster tests and by
    // a bound on the rounding of both view distances (their terms' magnitudes times 1e-5).
    let magnitude = dot(abs(z_row), abs(p)) + abs(view.view_from_world[3].z);
    let reach = bounds.w * length(z_row) * RADIUS_INFLATION + 1e-5 * (magnitude + abs(d));
    let lo = d - reach;
    let hi = d + reach;
    // Written as "not outside" so that a NaN keeps the light.
    if hi < r.x || lo > r.y {
        return false;
    }
    let first = depth_cell(lo, r);
    let last = depth_cell(hi, r);
    let span = (0xffffffffu >> (31u - last)) & (0xffffffffu << first);
    return (span & mask) != 0u;
}

// Phase 2: the tile's lights that reach its pixels' depths, into `tile_list`.
fn cull_tile(tile: vec2<u32>, li: u32) {
    let range = cluster_ranges[tile.x + tile.y * cluster_params.dims.x];
    let r = tile_depths();
    let mask = atomicLoad(&depth_mask);
    let bounded = atomicLoad(&depth_unbounded) == 0u;
    // A column whose list did not fit the frame's lists (LIST_EVERY_LIGHT) culls every light.
    let every = range.y == LIST_EVERY_LIGHT;
    let n = select(range.y, cluster_params.light_count, every);
    if r.x <= r.y {
        for (var i = li; i < n; i += TILED_EDGE * TILED_EDGE) {
            let index = select(cluster_indices[range.x + i], i, every);
            if !bounded || light_reaches_tile(lights[index], r, mask) {
                let slot = atomicAdd(&list_count, 1u);
                if slot < TILED_LIST_CAPACITY {
                    tile_list[slot] = index;
                }
            }
        }
    }
    workgroupBarrier();
}

fn shade(g: GSurface, tile: vec2<u32>) -> vec4<f32> {
    let view_dir = direction_to_eye(view, g.world_position);
    var color = gbuffer_base_radiance(g) + shade_directional_lights(g.params, g.world_position, view_dir);
    let count = atomicLoad(&list_count);
    if count <= TILED_LIST_CAPACITY {
        for (var i = 0u; i < count; i++) {
            color += shade_light(g.params, g.world_position, view_dir, tile_list[i]);
        }
    } else {
        // More lights than workgroup memory holds: the column's whole list, or every light.
        let range = cluster_ranges[tile.x + tile.y * cluster_params.dims.x];
        if range.y == LIST_EVERY_LIGHT {
            let n = cluster_params.light_count;
            return vec4<f32>(add_every_light_to(color, g.params, g.world_position, view_dir, n), 1.0);
        }
        for (var i = 0u; i < range.y; i++) {
            color += shade_light(g.params, g.world_position, view_dir, cluster_indices[range.x + i]);
        }
    }
    return vec4<f32>(color, 1.0);
}

// One pixel's work in `phase`; `depth` is its reverse-Z depth (0: background).
fn tile_pixel(phase: u32, px: vec2<i32>, depth: f32, g: GSurface, tile: vec2<u32>) {
    let covered = depth > 0.0;
    if phase == PHASE_BOUNDS {
        if covered {
            let d = gbuffer_view_distance(g.world_position);
            if abs(d) <= 3.0e38 {
                atomicMin(&depth_lo, order_key(d));
                atomicMax(&depth_hi, order_key(d));
            } else {
                atomicStore(&depth_unbounded, 1u);
            }
        }
    } else if phase == PHASE_MASK {
        if covered {
            atomicOr(&depth_mask, 1u << depth_cell(gbuffer_view_distance(g.world_position), tile_depths()));
        }
    } else if covered {
        textureStore(hdr_out, px, shade(g, tile));
    } else {
        textureStore(hdr_out, px, clear_color);
    }
}

// A tile of at most TILED_EDGE × TILED_EDGE pixels (the default grid's): each invocation reads
// its pixel's surface once and keeps it through the three phases.
fn tile_fits(rect: vec4<u32>) -> bool {
    return rect.z - rect.x <= TILED_EDGE && rect.w - rect.y <= TILED_EDGE;
}

// The pixel of invocation `lid` in a tile that fits, clamped into the tile, and whether it is
// the invocation's own (invocations past the tile's edge only take part in the barriers).
fn own_pixel(rect: vec4<u32>, lid: vec2<u32>) -> vec3<i32> {
    let p = rect.xy + lid;
    let inside = all(p < rect.zw);
    return vec3<i32>(vec2<i32>(min(p, rect.zw - vec2<u32>(1u))), i32(inside));
}

// The three phases for a tile that fits: the pixel's depth and surface were read once.
fn light_own_pixel(own: vec3<i32>, depth: f32, g: GSurface, tile: vec2<u32>, li: u32) {
    let d = select(0.0, depth, own.z != 0);
    tile_pixel(PHASE_BOUNDS, own.xy, d, g, tile);
    workgroupBarrier();
    tile_pixel(PHASE_MASK, own.xy, d, g, tile);
    workgroupBarrier();
    cull_tile(tile, li);
    if own.z != 0 {
        tile_pixel(PHASE_SHADE, own.xy, d, g, tile);
    }
}

//!if GBUFFER
// A larger tile (a grid of wider tiles) is visited once per phase, TILED_EDGE pixels apart,
// reading the surfaces again each time (from the G-buffer of the layout the shader is composed
// for: `gbuffer_read`).
fn pixels(phase: u32, tile: vec2<u32>, rect: vec4<u32>, lid: vec2<u32>) {
    for (var y = rect.y + lid.y; y < rect.w; y += TILED_EDGE) {
        for (var x = rect.x + lid.x; x < rect.z; x += TILED_EDGE) {
            let px = vec2<i32>(vec2<u32>(x, y));
            tile_pixel(phase, px, gbuffer_depth(px), gbuffer_read(px), tile);
        }
    }
}

@compute @workgroup_size(TILED_EDGE, TILED_EDGE)
fn cs_main(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>, @builtin(local_invocation_index) li: u32) {
    let rect = tile_rect(wg.xy);
    begin_tile(li);
    if tile_fits(rect) {
        let own = own_pixel(rect, lid.xy);
        light_own_pixel(own, gbuffer_depth(own.xy), gbuffer_read(own.xy), wg.xy, li);
    } else {
        pixels(PHASE_BOUNDS, wg.xy, rect, lid.xy);
        workgroupBarrier();
        pixels(PHASE_MASK, wg.xy, rect, lid.xy);
        workgroupBarrier();
        cull_tile(wg.xy, li);
        pixels(PHASE_SHADE, wg.xy, rect, lid.xy);
    }
}
//!endif
