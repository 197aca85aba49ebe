// Recording per-cluster depth bounds (Olsson et al. 2012; cluster_depth.wgsl): each pixel marks
// the cluster it is shaded in with its view distance; the cluster build then cuts each cluster
// to the depth range of its pixels (`level2_bounds` in cluster_build.wgsl), and clusters no
// pixel falls in keep no light.
// Two order keys per cluster that zero means "no pixel" for: the complement of the nearest
// distance, and the farthest (copied after the cluster ranges, where the build reads them).
// A pixel marks [d - s, d + s] (s = CLUSTER_DEPTH_SLACK * d) in the clusters of both ends: the
// shading pass computes its distance again from the same surface data, which agrees to
// rounding.
// Group 2 (Rust: `ClusterResources::depth_layout`).
//!include common/clusters.wgsl

// A storage binding of the params uniform's buffer: lavapipe (Mesa 22.3) compiles a new
// variant of a small shader that reads a uniform buffer whenever the uniform's contents change
// (its inlined uniforms), which grew the process by about 0.3 MB a frame here.
@group(2) @binding(0) var<storage, read> cluster_params: ClusterParams;
@group(2) @binding(1) var<storage, read_write> cluster_depths: array<atomic<u32>>;

fn mark_cluster(cluster: u32, near: f32, far: f32) {
    let at = cluster * 2u;
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
        far = bitcast<f32>(0x7f800000u);
    }
    let first = cluster_index(cluster_params, frag, near);
    let last = cluster_index(cluster_params, frag, far);
    mark_cluster(first, near, far);
    if last != first {
        mark_cluster(last, near, far);
    }
}
