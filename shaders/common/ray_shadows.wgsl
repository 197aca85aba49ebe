// Shadows found with rays (`//!if RAYS`, Rust `ShadowMethod::Rays`): each casting light's
// visibility at a shaded point is one ray through the scene's BVH (`ray_trace`,
// common/ray_bvh.wgsl), along the segment `manylight_core::shadow_oracle::ShadowQuery::segment`
// defines, so the shading agrees with the visibility oracle pair for pair.
//!include common/ray_bvh.wgsl

// How far a ray starts off the surface at `p`, and ends before a point light:
// `manylight_core::shadow_oracle::surface_offset`.
fn ray_surface_offset(p: vec3<f32>) -> f32 {
    let a = abs(p);
    return RAY_SURFACE_OFFSET * max(max(max(a.x, a.y), a.z), 1.0);
}

// 1 when nothing blocks the segment from `position` (off the surface along `normal`) along
// the unit `direction` for `span`, else 0; `geometry` is the view uniform's `rays`.
fn ray_segment_visibility(geometry: vec4<u32>, position: vec3<f32>, normal: vec3<f32>, direction: vec3<f32>, span: f32) -> f32 {
    let offset = ray_surface_offset(position);
    let n_len = length(normal);
    let n = select(vec3<f32>(0.0), normal / n_len, n_len > 0.0);
    let traced = ray_trace(geometry, position + n * offset, direction, span);
    return select(1.0, 0.0, traced.outcome == RAY_BLOCKED);
}

// Visibility of point or spot light `k` at `light_position` from the surface at `position`.
fn ray_light_visibility(geometry: vec4<u32>, k: u32, light_position: vec3<f32>, position: vec3<f32>, normal: vec3<f32>) -> f32 {
    // Bit k % 32 of word k / 32 of the casting lights' bits, from `ray_prims` entry `geometry.z`.
    let word = k / 32u;
    if (ray_prims[geometry.z + word / 4u][word % 4u] & (1u << (k % 32u))) == 0u {
        return 1.0;
    }
    let to_light = light_position - position;
    let distance = length(to_light);
    let span = distance - ray_surface_offset(position);
    if !(span > 0.0) {
        return 1.0;
    }
    return ray_segment_visibility(geometry, position, normal, to_light / distance, span);
}

// Visibility of a directional light travelling along `direction` (xyz; w: 1 when it casts).
fn ray_directional_visibility(geometry: vec4<u32>, direction: vec4<f32>, position: vec3<f32>, normal: vec3<f32>) -> f32 {
    if direction.w == 0.0 {
        return 1.0;
    }
    return ray_segment_visibility(geometry, position, normal, -normalize(direction.xyz), RAY_FAR);
}
