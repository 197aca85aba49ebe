// Vertex transform and surface parameters shared by every pass that shades meshes.
//!include common/mesh.wgsl
//!include common/brdf.wgsl

struct SurfaceVertexOut {
    @invariant @builtin(position) clip_position: vec4<f32>,
    @location(0) world_position: vec3<f32>,
    @location(1) world_normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
};

fn surface_vertex(v: VertexIn, inst: GpuInstance, clip_from_world: mat4x4<f32>) -> SurfaceVertexOut {
    let world = inst.world_from_local * vec4<f32>(v.position, 1.0);
    var out: SurfaceVertexOut;
    out.clip_position = clip_from_world * world;
    out.world_position = world.xyz;
    out.world_normal = (inst.normal_from_local * vec4<f32>(v.normal, 0.0)).xyz;
    out.uv = v.uv;
    return out;
}

// Sampled always and chosen by select, never behind a branch on the material: lavapipe (Mesa
// 22.3) compiles a shader again at every draw when it can fold a uniform-buffer branch away, and
// keeps every copy (about 9 MB per frame in the Packed and Compact G-buffer passes).
fn surface_albedo(m: GpuMaterial, t: texture_2d<f32>, smp: sampler, uv: vec2<f32>) -> vec4<f32> {
    return m.base_color * select(vec4<f32>(1.0), textureSample(t, smp, uv), m.has_texture != 0u);
}

fn surface_params(m: GpuMaterial, global_model: u32, albedo: vec3<f32>, normal: vec3<f32>, front_facing: bool) -> SurfaceParams {
    let len = length(normal);
    var n = select(vec3<f32>(0.0, 1.0, 0.0), normal / len, len > 1e-8);
    // Two-sided lighting: shade the face the camera sees.
    n = select(-n, n, front_facing);
    var s: SurfaceParams;
    s.albedo = albedo;
    s.normal = n;
    s.shininess = m.shininess;
    s.specular = m.specular;
    s.model = select(m.shading_model, global_model, m.shading_model == SHADING_GLOBAL);
    return s;
}
