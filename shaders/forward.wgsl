// Naive forward: every fragment evaluates every light.
//!include common/mesh_pass.wgsl
//!include common/brdf.wgsl

@fragment
fn fs_main(in: SurfaceVertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let p = surface_point(view, in.clip_position.xy, in.camera_offset);
    let m = sample_material(in, front_facing);
    let s = m.params;
    alpha_test(m.base_color);
    let view_dir = direction_to_eye(view, p.world_position);
    var color = surface_base_radiance(s.albedo, view.params.w, m.occlusion, m.emissive);
    color += shade_directional_lights(view, s, view_dir);
    // Four lights per iteration, added in order: lavapipe stops an invocation after 65 535 loop
    // iterations, which would drop every light past the 65 535th of the reference.
    let n = view.light_count;
    var i = 0u;
    for (; i + 4u <= n; i += 4u) {
        color += shade_point_light(s, p.world_position, view_dir, lights[i]);
        color += shade_point_light(s, p.world_position, view_dir, lights[i + 1u]);
        color += shade_point_light(s, p.world_position, view_dir, lights[i + 2u]);
        color += shade_point_light(s, p.world_position, view_dir, lights[i + 3u]);
    }
    for (; i < n; i++) {
        color += shade_point_light(s, p.world_position, view_dir, lights[i]);
    }
    return vec4<f32>(color, 1.0);
}
