// What a forward fragment sums before its point and spot lights: the surface with its
// ambient, emission and directional lights. No storage binding (`common/light_lists.wgsl` adds
// the light lists of the storage-buffer passes, `texture_lists.wgsl` its textures).
//!include common/mesh_material.wgsl
//!include common/brdf.wgsl
//!include common/directional_lights.wgsl

struct ForwardFragment {
    p: SurfacePoint,
    m: MaterialSample,
    view_dir: vec3<f32>,
    // the radiance so far: ambient (with occlusion), emission and the directional lights
    // (and the environment, `common/light_lists.wgsl`'s `environment_fragment`)
    color: vec3<f32>,
};

// Samples the material (discarding below an alpha mask's cutoff) and sums what every light
// list starts from.
fn forward_fragment(in: SurfaceVertexOut, front_facing: bool) -> ForwardFragment {
    let p = surface_point(view, in.clip_position.xy, in.camera_offset);
    let m = sample_material(in, front_facing);
    alpha_test(m.base_color);
    let view_dir = direction_to_eye(view, p.world_position);
    var color = surface_base_radiance(m.params.albedo, view.params.w, m.occlusion, m.emissive);
    color += shade_directional_lights(m.params, p.world_position, view_dir);
    return ForwardFragment(p, m, view_dir, color);
}
