// The material of a mesh pass (group 1; Rust: `SceneAssets::material_layout`) and what a
// fragment reads of it. No storage binding: the passes for devices without storage buffers
// (`texture_lists.wgsl`, WebGL2) include it as the storage-buffer passes do through
// `common/mesh_pass.wgsl`.
//!include common/view.wgsl
//!include common/mesh.wgsl
//!include common/surface.wgsl
//!include common/view_binding.wgsl

@group(1) @binding(0) var<uniform> material: GpuMaterial;
// Each texture is followed by its own sampler (glTF wrap and filter modes).
// base colour (sRGB)
@group(1) @binding(1) var base_color_texture: texture_2d<f32>;
@group(1) @binding(2) var base_color_sampler: sampler;
// glTF metallic-roughness: blue = metalness, green = roughness (linear)
@group(1) @binding(3) var metallic_roughness_texture: texture_2d<f32>;
@group(1) @binding(4) var metallic_roughness_sampler: sampler;
// tangent-space normal map (linear, xyz * 0.5 + 0.5)
@group(1) @binding(5) var normal_texture: texture_2d<f32>;
@group(1) @binding(6) var normal_sampler: sampler;
// ambient occlusion (linear, red)
@group(1) @binding(7) var occlusion_texture: texture_2d<f32>;
@group(1) @binding(8) var occlusion_sampler: sampler;
// emitted colour (sRGB)
@group(1) @binding(9) var emissive_texture: texture_2d<f32>;
@group(1) @binding(10) var emissive_sampler: sampler;

// Everything a shading pass needs of the material at a fragment.
struct MaterialSample {
    params: SurfaceParams,
    // linear RGBA base colour (alpha for the mask test)
    base_color: vec4<f32>,
    emissive: vec3<f32>,
    occlusion: f32,
};

// The base colour texture's texel at the fragment, 1 where the pipeline does not sample it.
fn base_color_texel(in: SurfaceVertexOut) -> vec4<f32> {
    var texel = vec4<f32>(1.0);
    if BASE_COLOR_TEXTURE {
        let uv = texture_uv(material, TEXTURE_SLOT_BASE_COLOR, in.uv);
        texel = textureSample(base_color_texture, base_color_sampler, uv);
    }
    return texel;
}

// Samples the textures of the material that the pipeline samples (the `*_TEXTURE` override
// constants; their branches are uniform and fold away when the pipeline is made) and builds
// the surface: normal map, occlusion, emissive, and the normal turned towards the viewer on
// the back faces of double-sided materials.
fn sample_material(in: SurfaceVertexOut, front_facing: bool) -> MaterialSample {
    var out: MaterialSample;
    out.base_color = surface_albedo(material, base_color_texel(in));
    var metal_rough_texel = vec4<f32>(1.0);
    if METALLIC_ROUGHNESS_TEXTURE {
        let uv = texture_uv(material, TEXTURE_SLOT_METALLIC_ROUGHNESS, in.uv);
        metal_rough_texel = textureSample(metallic_roughness_texture, metallic_roughness_sampler, uv);
    }
    let metal_rough = surface_metal_rough(material, metal_rough_texel);
    // a flat normal where the pipeline has no normal map
    var normal_texel = vec3<f32>(0.5, 0.5, 1.0);
    if NORMAL_TEXTURE {
        let uv = texture_uv(material, TEXTURE_SLOT_NORMAL, in.uv);
        normal_texel = textureSample(normal_texture, normal_sampler, uv).xyz;
    }
    let n = surface_normal(material, normal_texel, in, front_facing);
    out.params = surface_params(material, view.shading_model, out.base_color.rgb, metal_rough, n);
    var occlusion_texel = 1.0;
    if OCCLUSION_TEXTURE {
        let uv = texture_uv(material, TEXTURE_SLOT_OCCLUSION, in.uv);
        occlusion_texel = textureSample(occlusion_texture, occlusion_sampler, uv).r;
    }
    out.occlusion = surface_occlusion(material, occlusion_texel);
    var emissive_texel = vec3<f32>(1.0);
    if EMISSIVE_TEXTURE {
        let uv = texture_uv(material, TEXTURE_SLOT_EMISSIVE, in.uv);
        emissive_texel = textureSample(emissive_texture, emissive_sampler, uv).rgb;
    }
    out.emissive = material.emissive * select(vec3<f32>(1.0), emissive_texel, material.has_emissive_texture != 0u);
    return out;
}

// Discards the fragment in the ALPHA_MASK pipelines when its alpha is below the cutoff. Call
// it after every derivative and texture sample of the fragment.
fn alpha_test(base_color: vec4<f32>) {
    if ALPHA_MASK && base_color.a < material.alpha_cutoff {
        discard;
    }
}
