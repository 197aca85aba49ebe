// What the passes that shade meshes forward share (naive, tiled and clustered forward, and the
// transparent pass): the fragment's surface with its ambient, emission and directional lights,
// then the point and spot lights it sums, either every light or its cluster's list.
//!include common/mesh_pass.wgsl
//!include common/brdf.wgsl
//!include common/directional_lights.wgsl
// The light lists (group 2), bound only by the pipelines whose entry point calls
// `add_cluster_lights`.
//!include common/cluster_lists.wgsl

struct ForwardFragment {
    p: SurfacePoint,
    m: MaterialSample,
    view_dir: vec3<f32>,
    // the radiance so far: ambient (with occlusion), emission and the directional lights
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

// `f.color` plus every point and spot light, added in order.
fn add_every_light(f: ForwardFragment) -> vec3<f32> {
    return add_every_light_to(f.color, f.m.params, f.p.world_position, f.view_dir, view.light_count);
}

// `f.color` plus the lights of the list of the fragment at `frag` (pixel coordinates): its
// block's refined list or its cluster's, or every light where the cluster's list did not fit.
fn add_cluster_lights(f: ForwardFragment, frag: vec2<f32>) -> vec3<f32> {
    let range = light_list_range(frag, f.p.view_depth);
    if range.y == LIST_EVERY_LIGHT {
        return add_every_light(f);
    }
    var color = f.color;
    for (var i = 0u; i < range.y; i++) {
        color += shade_light(f.m.params, f.p.world_position, f.view_dir, cluster_indices[range.x + i]);
    }
    return color;
}
