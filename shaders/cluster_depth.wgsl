// Per-cluster depth bounds: one compute pass after the depth pre-pass (forward pipelines) or
// the G-buffer pass (deferred ones) and before the cluster build marks every pixel's cluster
// with the pixel's view distance (common/cluster_depth.wgsl), one invocation per pixel. The
// distance is the one the shading pass computes, not the depth buffer's (which drifts from the
// shading position on triangles much larger than their distance from the camera, as a floor
// seen from close by): forward shading's `surface_point` distance, which the depth pre-pass
// writes to `shading_distance`, or that of the position the G-buffer stores, as deferred
// lighting reads it.
//!include common/view.wgsl
//!include common/lights.wgsl
//!include common/brdf.wgsl
//!include common/cluster_depth.wgsl

// group 0, binding 0: `view`, declared in common/gbuffer_read.wgsl; group 1: the G-buffer
//!include common/gbuffer_read.wgsl

// Forward pipelines: the depth pre-pass's shading distances (0: background).
@group(1) @binding(9) var shading_distance: texture_2d<f32>;

@compute @workgroup_size(8, 8)
fn cs_forward(@builtin(global_invocation_id) id: vec3<u32>) {
    if any(id.xy >= textureDimensions(shading_distance)) {
        return;
    }
    let d = textureLoad(shading_distance, vec2<i32>(id.xy), 0).r;
    if d > 0.0 || !(abs(d) <= 3.0e38) {
        mark_cluster_depth(vec2<f32>(id.xy) + 0.5, d);
    }
}

// The view distance deferred lighting computes for a stored position.
fn stored_distance(g: GSurface) -> f32 {
    return -(view.view_from_world * vec4<f32>(g.world_position, 1.0)).z;
}

@compute @workgroup_size(8, 8)
fn cs_full(@builtin(global_invocation_id) id: vec3<u32>) {
    let px = vec2<i32>(id.xy);
    if all(id.xy < textureDimensions(gb_depth)) && gbuffer_depth(px) > 0.0 {
        mark_cluster_depth(vec2<f32>(id.xy) + 0.5, stored_distance(gbuffer_read_full(px)));
    }
}

@compute @workgroup_size(8, 8)
fn cs_packed(@builtin(global_invocation_id) id: vec3<u32>) {
    let px = vec2<i32>(id.xy);
    if all(id.xy < textureDimensions(gb_depth)) && gbuffer_depth(px) > 0.0 {
        mark_cluster_depth(vec2<f32>(id.xy) + 0.5, stored_distance(gbuffer_read_packed(px)));
    }
}

@compute @workgroup_size(8, 8)
fn cs_compact(@builtin(global_invocation_id) id: vec3<u32>) {
    let px = vec2<i32>(id.xy);
    if all(id.xy < textureDimensions(gb_depth)) && gbuffer_depth(px) > 0.0 {
        mark_cluster_depth(vec2<f32>(id.xy) + 0.5, stored_distance(gbuffer_read_compact(px)));
    }
}
