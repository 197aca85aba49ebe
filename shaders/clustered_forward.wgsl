// Clustered (and tiled, Z = 1) forward shading: each fragment finds its cluster and evaluates
// only the lights in that cluster's list.
//!include common/light_lists.wgsl

@fragment
fn fs_main(in: SurfaceVertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    return vec4<f32>(add_cluster_lights(environment_fragment(in, front_facing), in.clip_position.xy), 1.0);
}
