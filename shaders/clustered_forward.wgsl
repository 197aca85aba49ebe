// Clustered (and tiled, Z = 1) forward shading: each fragment finds its cluster and evaluates
// only the lights in that cluster's list.
//!include common/mesh_pass.wgsl
//!include common/brdf.wgsl
//!include common/clusters.wgsl

@group(2) @binding(0) var<uniform> cluster_params: ClusterParams;
@group(2) @binding(1) var<storage, read> cluster_ranges: array<vec2<u32>>;
@group(2) @binding(2) var<storage, read> cluster_indices: array<u32>;

@fragment
fn fs_main(in: SurfaceVertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let p = surface_point(view, in.clip_position.xy, in.camera_offset);
    let m = sample_material(in, front_facing);
    let s = m.params;
    alpha_test(m.base_color);
    let view_dir = direction_to_eye(view, p.world_position);
    let cluster = cluster_index(cluster_params, in.clip_position.xy, p.view_depth);
    let range = cluster_ranges[cluster];
    var color = surface_base_radiance(s.albedo, view.params.w, m.occlusion, m.emissive);
    color += shade_directional_lights(view, s, view_dir);
    for (var i = 0u; i < range.y; i++) {
        color += shade_point_light(s, p.world_position, view_dir, lights[cluster_indices[range.x + i]]);
    }
    return vec4<f32>(color, 1.0);
}
