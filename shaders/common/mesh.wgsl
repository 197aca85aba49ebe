// Per-instance data (Rust: `GpuInstance`) and per-material constants (Rust: `GpuMaterial`).
struct GpuInstance {
    world_from_local: mat4x4<f32>,
    // inverse transpose of the upper 3x3, stored as columns of a mat4 for alignment
    normal_from_local: mat4x4<f32>,
};

struct GpuMaterial {
    base_color: vec4<f32>,
    shininess: f32,
    specular: f32,
    // SHADING_* id, or SHADING_GLOBAL to use the view's model
    shading_model: u32,
    has_texture: u32,
    metallic: f32,
    roughness: f32,
    has_metallic_roughness_texture: u32,
    normal_scale: f32,
    // linear emitted radiance (factor times KHR_materials_emissive_strength)
    emissive: vec3<f32>,
    occlusion_strength: f32,
    has_normal_texture: u32,
    has_occlusion_texture: u32,
    has_emissive_texture: u32,
    // fragments below it are discarded by the ALPHA_MASK pipelines
    alpha_cutoff: f32,
};

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    // xyz along +u, w = bitangent handedness (all zero: no tangent frame)
    @location(3) tangent: vec4<f32>,
};
