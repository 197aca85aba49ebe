// Per-cluster depth bounds (Olsson et al. 2012): one compute pass after the depth pre-pass
// (forward pipelines) or the G-buffer pass (deferred ones) and before the cluster build marks
// every pixel's cluster with the pixel's view distance, one invocation per pixel; the build then
// cuts each cluster to the depth range of its pixels (`level2_bounds` in cluster_build.wgsl), and
// clusters no pixel falls in keep no light.
// The ranges lie after the cluster ranges in the same buffer, as two order keys per cluster
// that zero means "no pixel" for: the complement of the nearest distance, and the farthest.
// A pixel marks [d - s, d + s] (s = CLUSTER_DEPTH_SLACK * d) in the clusters of both ends: the
// shading pass computes its distance again from the same surface data, which agrees to
// rounding.
// The distance is the one the shading pass computes, not the depth buffer's (which drifts from the
// shading position on triangles much larger than their distance from the camera, as a floor
// seen from close by): forward shading's `surface_point` distance, which the depth pre-pass
// writes to `shading_distance`, or that of the position the G-buffer stores, as deferred
// lighting reads it.
//!include common/view.wgsl
//!include common/lights.wgsl
//!include common/brdf.wgsl
//!include common/clusters.wgsl

// group 0, binding 0: `view` (common/view_binding.wgsl, through common/gbuffer_read.wgsl); group 1: the G-buffer
//!include common/gbuffer_read.wgsl

// A storage binding of the params uniform's buffer: lavapipe (Mesa 22.3) compiles a new
// variant of a small shader that reads a uniform buffer whenever the uniform's contents change
// (its inlined uniforms), which grew the process by about 0.3 MB a frame here.
@group(2) @binding(0) var<storage, read> cluster_params: ClusterParams;
@group(2) @binding(1) var<storage, read_write> cluster_depths: array<atomic<u32>>;

fn mark_cluster(cluster: u32, near: f32, far: f32) {
    let at = (cluster_params.dims.w + cluster) * 2u;
    atomicMax(&cluster_depths[at], ~order_key(near));
    atomicMax(&cluster_depths[at + 1u], order_key(far));
}

// Marks the clusters a pixel at framebuffer position `frag` and view distance `d` is shaded in.
fn mark_cluster_depth(frag: vec2<f32>, d: f32) {
    var near = max(d - CLUSTER_DEPTH_SLACK * abs(d), 0.0);
    var far = d + CLUSTER_DEPTH_SLACK * abs(d);
    // A distance that is not finite bounds nothing: its cluster keeps every light.
    if !(abs(d) <= 3.0e38) {
        near = 0.0;
        // +infinity, made from `d` at run time: WGSL refuses an infinite constant (Tint, in
        // browsers, rejects `bitcast<f32>(0x7f800000u)`), and naga accepts either.
        far = bitcast<f32>((bitcast<u32>(d) & 0u) | 0x7f800000u);
    }
    let first = cluster_index(cluster_params, frag, near);
    let last = cluster_index(cluster_params, frag, far);
    mark_cluster(first, near, far);
    if last != first {
        mark_cluster(last, near, far);
    }
}

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

// From the G-buffer of the layout the shader is composed for (`gbuffer_read`).
//!if GBUFFER
@compute @workgroup_size(8, 8)
fn cs_gbuffer(@builtin(global_invocation_id) id: vec3<u32>) {
    let px = vec2<i32>(id.xy);
    if all(id.xy < textureDimensions(gb_depth)) && gbuffer_depth(px) > 0.0 {
        mark_cluster_depth(vec2<f32>(id.xy) + 0.5, gbuffer_view_distance(gbuffer_read(px).world_position));
    }
}
//!endif
