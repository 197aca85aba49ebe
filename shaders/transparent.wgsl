// Blended surfaces (glTF alphaMode BLEND), drawn after the opaque ones, back to front, over
// the shaded image: lit as forward shading lights them, through the cluster lists where the
// view has them (`fs_clusters`), else by every light (`fs_every_light`). The pipeline blends
// the colour over the target by the base colour's alpha.
//!include common/light_lists.wgsl

@fragment
fn fs_every_light(in: SurfaceVertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let f = environment_fragment(in, front_facing);
    return vec4<f32>(add_every_light(f), saturate(f.m.base_color.a));
}

@fragment
fn fs_clusters(in: SurfaceVertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let f = environment_fragment(in, front_facing);
    return vec4<f32>(add_cluster_lights(f, in.clip_position.xy), saturate(f.m.base_color.a));
}
