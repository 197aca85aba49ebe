// Shadows: each casting point or spot light's six cube faces, and each casting directional
// light's cascades, are tiles of one depth atlas (Rust: `crate::shadows`), drawn by
// `shadow_maps.wgsl`. Bound in group 0 of every shading pass only when the frame has a casting
// light (`//!if SHADOWS`).
//!include common/lights.wgsl

//!include common/shadow_types.wgsl

@group(0) @binding(3) var shadow_atlas: texture_depth_2d;
@group(0) @binding(4) var shadow_sampler: sampler_comparison;
@group(0) @binding(5) var<storage, read> shadow_lights: array<GpuShadowLight>;
@group(0) @binding(6) var<storage, read> directional_shadows: array<GpuDirectionalShadow>;

// The comparison-filtered test of the tile whose top-left atlas texel is `origin` and edge
// `edge`, at `local` texels from its corner: one bilinear comparison (`method` 0, 2×2 texels)
// or four half a texel apart (`method` 1, a 3×3 tent). Samples stay inside the tile.
fn shadow_compare(origin: vec2<f32>, edge: f32, local: vec2<f32>, reference: f32, method: u32) -> f32 {
    let size = vec2<f32>(textureDimensions(shadow_atlas));
    let lo = vec2<f32>(0.5);
    let hi = vec2<f32>(edge - 0.5);
    if method == 0u {
        return textureSampleCompareLevel(shadow_atlas, shadow_sampler, (origin + clamp(local, lo, hi)) / size, reference);
    }
    var sum = 0.0;
    for (var i = 0u; i < 4u; i++) {
        let offset = vec2<f32>(f32(i & 1u) - 0.5, f32(i >> 1u) - 0.5);
        sum += textureSampleCompareLevel(shadow_atlas, shadow_sampler, (origin + clamp(local + offset, lo, hi)) / size, reference);
    }
    return 0.25 * sum;
}

// The depth a face stores for a point `depth` along its axis: a reverse perspective depth, 1
// at the near plane and 0 at the far one (Rust: `shadows::face_depth`); the comparison
// sampler passes where the point's depth is at least the stored (nearest) caster's.
fn shadow_face_depth(depth: f32, near: f32, far: f32) -> f32 {
    return near * (far - depth) / (depth * (far - near));
}

// How much of light `k` reaches `position` past the shadow casters, in [0, 1]: its shadow
// map's comparison-filtered test (`shadow_compare`), or 1 when it has none. The test looks from where the
// light was when its map was drawn (`origin`: the light's position unless the map was kept
// past the frame's redraw budget). `normal` is the surface's; the test is made from a point
// pushed off the surface towards the light by the normal bias (in face texels at this
// distance) and moved the depth bias nearer to it, so a surface does not shadow itself.
fn shadow_visibility(k: u32, position: vec3<f32>, normal: vec3<f32>) -> f32 {
    let shadow = shadow_lights[k];
    let size = shadow.tile.z;
    if size == 0u {
        return 1.0;
    }
    let light_position = shadow.origin.xyz;
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
    // u to the right, v up; tile rows run down.
    let local = vec2<f32>(0.5 + 0.5 * uv.x, 0.5 - 0.5 * uv.y) * edge;
    let near = shadow.params.x;
    let reference = shadow_face_depth(max(depth - shadow.params.z, near), near, shadow.params.y);
    return shadow_compare(origin, edge, local, reference, shadow.tile.w);
}

// How much of directional light `i` (travelling along the unit `direction`) reaches
// `position`, `view_distance` from the camera along its axis: the comparison-filtered test
// of the first cascade whose far bound lies beyond the point, or 1 past the last cascade or
// when the light casts no shadow. The biases work as for point lights, in the cascade's
// texels and along the light's direction.
fn directional_shadow_visibility(
    i: u32,
    direction: vec3<f32>,
    position: vec3<f32>,
    normal: vec3<f32>,
    view_distance: f32,
) -> f32 {
    let count = min(directional_shadows[i].count.x, MAX_CASCADES);
    var c = 0u;
    loop {
        if c >= count || view_distance <= directional_shadows[i].cascades[c].params.x {
            break;
        }
        c++;
    }
    if c >= count {
        return 1.0;
    }
    let cascade = directional_shadows[i].cascades[c];
    let bias = directional_shadows[i].bias;
    let to_light = -direction;
    let facing = select(-normal, normal, dot(normal, to_light) >= 0.0);
    let p = position + facing * (bias.y * cascade.params.y) + to_light * bias.x;
    let clip = cascade.clip_from_world * vec4<f32>(p, 1.0);
    let edge = f32(cascade.tile.z);
    let local = vec2<f32>(0.5 + 0.5 * clip.x, 0.5 - 0.5 * clip.y) * edge;
    return shadow_compare(vec2<f32>(cascade.tile.xy), edge, local, saturate(clip.z), cascade.tile.w);
}
