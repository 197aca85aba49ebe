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
    _pad: u32,
};

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
};
