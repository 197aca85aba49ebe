// Clustered deferred lighting: one full-screen pass reads the G-buffer (any layout, see
// gbuffer.wgsl and common/gbuffer_read.wgsl) and walks the pixel's light list (its cluster's,
// or its block's refined list), with the same shading code as the forward pipelines.
//!include common/view.wgsl
//!include common/lights.wgsl
//!include common/brdf.wgsl
//!include common/clusters.wgsl
//!include common/fullscreen.wgsl

// group 0, binding 0: `view` (common/view_binding.wgsl, through common/gbuffer_read.wgsl)
//!include common/point_lights.wgsl

//!include common/gbuffer_read.wgsl

// group 2: the light lists
//!include common/cluster_lists.wgsl

fn shade(g: GSurface, frag: vec2<f32>) -> vec4<f32> {
    let view_dir = direction_to_eye(view, g.world_position);
    let range = light_list_range(frag, gbuffer_view_distance(g.world_position));
    var color = gbuffer_base_radiance(g) + shade_directional_lights(g.params, g.world_position, view_dir);
    if range.y == LIST_EVERY_LIGHT {
        let n = cluster_params.light_count;
        return vec4<f32>(add_every_light_to(color, g.params, g.world_position, view_dir, n), 1.0);
    }
    for (var i = 0u; i < range.y; i++) {
        color += shade_light(g.params, g.world_position, view_dir, cluster_indices[range.x + i]);
    }
    return vec4<f32>(color, 1.0);
}

// Composed for the pipeline's G-buffer layout (`gbuffer_read`, common/gbuffer_read.wgsl).
//!if GBUFFER
@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let px = vec2<i32>(in.position.xy);
    if gbuffer_depth(px) <= 0.0 {
        return clear_color; // background (reverse-Z: cleared to 0)
    }
    return shade(gbuffer_read(px), in.position.xy);
}
//!endif
