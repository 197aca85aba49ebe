// Naive forward: every fragment evaluates every light.
//!include common/light_lists.wgsl

@fragment
fn fs_main(in: SurfaceVertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    return vec4<f32>(add_every_light(environment_fragment(in, front_facing)), 1.0);
}
