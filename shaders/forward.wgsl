// Naive forward: every fragment evaluates every light.
//!include common/view.wgsl
//!include common/lights.wgsl
//!include common/brdf.wgsl
//!include common/mesh.wgsl
//!include common/surface.wgsl

@group(0) @binding(0) var<uniform> view: ViewUniform;
@group(0) @binding(1) var<storage, read> lights: array<GpuPointLight>;
@group(0) @binding(2) var<storage, read> instances: array<GpuInstance>;

@group(1) @binding(0) var<uniform> material: GpuMaterial;
@group(1) @binding(1) var base_color_texture: texture_2d<f32>;
@group(1) @binding(2) var base_color_sampler: sampler;

@vertex
fn vs_main(v: VertexIn, @builtin(instance_index) instance_index: u32) -> SurfaceVertexOut {
    return surface_vertex(v, instances[instance_index], view.clip_from_world);
}

@fragment
fn fs_main(in: SurfaceVertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    let albedo = surface_albedo(material, base_color_texture, base_color_sampler, in.uv);
    let s = surface_params(material, view.shading_model, albedo.rgb, in.world_normal, front_facing);
    let view_dir = normalize(view.camera_position.xyz - in.world_position);
    var color = albedo.rgb * view.params.w;
    // Four lights per iteration, added in order: lavapipe stops an invocation after 65 535 loop
    // iterations, which would drop every light past the 65 535th of the reference.
    let n = view.light_count;
    var i = 0u;
    for (; i + 4u <= n; i += 4u) {
        color += shade_point_light(s, in.world_position, view_dir, lights[i]);
        color += shade_point_light(s, in.world_position, view_dir, lights[i + 1u]);
        color += shade_point_light(s, in.world_position, view_dir, lights[i + 2u]);
        color += shade_point_light(s, in.world_position, view_dir, lights[i + 3u]);
    }
    for (; i < n; i++) {
        color += shade_point_light(s, in.world_position, view_dir, lights[i]);
    }
    return vec4<f32>(color, 1.0);
}
