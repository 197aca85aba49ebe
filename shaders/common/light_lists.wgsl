// What the passes that shade meshes forward share (naive, tiled and clustered forward, and the
// transparent pass): the fragment's surface with its ambient, emission, environment and
// directional lights, then the point and spot lights it sums, either every light or its
// cluster's list.
//!include common/mesh_pass.wgsl
//!include common/brdf.wgsl
//!include common/directional_lights.wgsl
// The light lists (group 2), bound only by the pipelines whose entry point calls
// `add_cluster_lights`.
//!include common/cluster_lists.wgsl
//!include common/forward_fragment.wgsl
//!include common/environment.wgsl

// `forward_fragment` with the light of the view's environment added (with ENVIRONMENT; the
// G-buffer pass adds the same term to its emissive target).
fn environment_fragment(in: SurfaceVertexOut, front_facing: bool) -> ForwardFragment {
    var f = forward_fragment(in, front_facing);
    f.color += environment_light(f.m.params, f.view_dir, f.m.occlusion);
    return f;
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
