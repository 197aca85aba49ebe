// Naive forward: every fragment evaluates every light.
//!include common/view.wgsl
//!include common/lights.wgsl
//!include common/brdf.wgsl
//!include common/mesh.wgsl

@group(0) @binding(0) var<uniform> view: ViewUniform;
@group(0) @binding(1) var<storage, read> lights: array<GpuPointLight>;
@group(0) @binding(2) var<storage, read> instances: array<GpuInstance>;

@group(1) @binding(0) var<uniform> material: GpuMaterial;
@group(1) @binding(1) var base_color_texture: texture_2d<f32>;
@group(1) @binding(2) var base_color_sampler: sampler;

struct VertexOut {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) world_position: vec3<f32>,
    @location(1) world_normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
};

@vertex
fn vs_main(v: VertexIn, @builtin(instance_index) instance_index: u32) -> VertexOut {
    let inst = instances[instance_index];
    let world = inst.world_from_local * vec4<f32>(v.position, 1.0);
    var out: VertexOut;
    out.clip_position = view.clip_from_world * world;
    out.world_position = world.xyz;
    out.world_normal = (inst.normal_from_local * vec4<f32>(v.normal, 0.0)).xyz;
    out.uv = v.uv;
    return out;
}

@fragment
fn fs_main(in: VertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<f32> {
    var albedo = material.base_color;
    if material.has_texture != 0u {
        albedo *= textureSample(base_color_texture, base_color_sampler, in.uv);
    }
    var n = in.world_normal;
    let len = length(n);
    n = select(vec3<f32>(0.0, 1.0, 0.0), n / len, len > 1e-8);
    // Two-sided lighting: shade the face the camera sees.
    n = select(-n, n, front_facing);

    var s: SurfaceParams;
    s.albedo = albedo.rgb;
    s.normal = n;
    s.shininess = material.shininess;
    s.specular = material.specular;
    s.model = select(material.shading_model, view.shading_model, material.shading_model == SHADING_GLOBAL);

    let view_dir = normalize(view.camera_position.xyz - in.world_position);
    var color = albedo.rgb * view.params.w;
    for (var i = 0u; i < view.light_count; i++) {
        color += shade_point_light(s, in.world_position, view_dir, lights[i]);
    }
    return vec4<f32>(color, 1.0);
}
