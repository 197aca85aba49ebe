// Shadows of point and spot lights: each casting light's six cube faces are tiles of one
// depth atlas (Rust: `crate::shadows`), drawn by `shadow_maps.wgsl`. Bound in group 0 of
// every shading pass only when the frame has a casting light (`//!if SHADOWS`).
//!include common/lights.wgsl

// Rust: `GpuShadowLight`.
struct GpuShadowLight {
    // xy: top-left atlas texel of the light's block of face tiles (SHADOW_TILE_COLUMNS per
    // row); z: a face tile's edge in texels, 0 when the light has no shadow map; w: 0
    tile: vec4<u32>,
    // x: near plane, y: far plane (the light's range), z: depth bias (world units),
    // w: normal bias (face texels)
    params: vec4<f32>,
};

@group(0) @binding(3) var shadow_atlas: texture_depth_2d;
@group(0) @binding(4) var shadow_sampler: sampler_comparison;
@group(0) @binding(5) var<storage, read> shadow_lights: array<GpuShadowLight>;

// The depth a face stores for a point `depth` along its axis: a perspective depth, 0 at the
// near plane and 1 at the far one (Rust: `shadows::face_depth`).
fn shadow_face_depth(depth: f32, near: f32, far: f32) -> f32 {
    return far * (depth - near) / (depth * (far - near));
}

// How much of light `k` (at `light_position`) reaches `position` past the shadow casters, in
// [0, 1]: its shadow map's 2×2 comparison-filtered test, or 1 when it has none. `normal` is
// the surface's; the test is made from a point pushed off the surface towards the light by
// the normal bias (in face texels at this distance) and moved the depth bias nearer to it,
// so a surface does not shadow itself.
fn shadow_visibility(k: u32, light_position: vec3<f32>, position: vec3<f32>, normal: vec3<f32>) -> f32 {
    let shadow = shadow_lights[k];
    let size = shadow.tile.z;
    if size == 0u {
        return 1.0;
    }
    let edge = f32(size);
    let to_light = light_position - position;
    // A face spans 90°: at distance d one of its texels is 2·d / edge wide.
    let texel = 2.0 * length(to_light) / edge;
    let facing = select(-normal, normal, dot(normal, to_light) >= 0.0);
    let v = position + facing * (shadow.params.w * texel) - light_position;
    let a = abs(v);
    var axis = 2u;
    if a.x >= a.y && a.x >= a.z {
        axis = 0u;
    } else if a.y >= a.z {
        axis = 1u;
    }
    let depth = max(a[axis], 1e-30);
    let face = 2u * axis + select(1u, 0u, v[axis] >= 0.0);
    let uv = vec2<f32>(v[(axis + 1u) % 3u], v[(axis + 2u) % 3u]) / depth;
    let origin = vec2<f32>(
        f32(shadow.tile.x + (face % SHADOW_TILE_COLUMNS) * size),
        f32(shadow.tile.y + (face / SHADOW_TILE_COLUMNS) * size),
    );
    // u to the right, v up; tile rows run down. The filter's 2×2 texels stay in the tile.
    let local = clamp(vec2<f32>(0.5 + 0.5 * uv.x, 0.5 - 0.5 * uv.y) * edge, vec2<f32>(0.5), vec2<f32>(edge - 0.5));
    let atlas_uv = (origin + local) / vec2<f32>(textureDimensions(shadow_atlas));
    let near = shadow.params.x;
    let reference = shadow_face_depth(max(depth - shadow.params.z, near), near, shadow.params.y);
    return textureSampleCompareLevel(shadow_atlas, shadow_sampler, atlas_uv, reference);
}
