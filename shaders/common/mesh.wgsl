// Per-instance data (Rust: `GpuInstance`) and per-material constants (Rust: `GpuMaterial`).
struct GpuInstance {
    world_from_local: mat4x4<f32>,
    // inverse transpose of the upper 3x3, stored as columns of a mat4 for alignment
    normal_from_local: mat4x4<f32>,
};

// Which uv set a material texture reads (row0.w: 1 = TEXCOORD_1) and its affine uv transform
// (rows xyz). Rust: `GpuTextureUv`.
struct GpuTextureUv {
    row0: vec4<f32>,
    row1: vec4<f32>,
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
    // indexed by TEXTURE_SLOT_*
    texture_uv: array<GpuTextureUv, MATERIAL_TEXTURE_SLOTS>,
};

// The uv texture slot `slot` samples at, from the vertex's two uv sets (xy: TEXCOORD_0,
// zw: TEXCOORD_1).
fn texture_uv(m: GpuMaterial, slot: u32, uvs: vec4<f32>) -> vec2<f32> {
    let t = m.texture_uv[slot];
    let uv = vec3<f32>(select(uvs.xy, uvs.zw, t.row0.w != 0.0), 1.0);
    return vec2<f32>(dot(t.row0.xyz, uv), dot(t.row1.xyz, uv));
}

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    // xyz along +u, w = bitangent handedness (all zero: no tangent frame)
    @location(3) tangent: vec4<f32>,
    // TEXCOORD_1 (zero when the mesh has none)
    @location(4) uv1: vec2<f32>,
};
