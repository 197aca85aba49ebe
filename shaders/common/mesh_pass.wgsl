// What every pass drawing the scene's meshes with surface shading shares (forward, clustered
// forward, G-buffer): group 0 (Rust: `SceneResources::view_layout`), group 1 (the material,
// `SceneResources::material_layout`) and the vertex stage.
//!include common/view.wgsl
//!include common/lights.wgsl
//!include common/mesh.wgsl
//!include common/surface.wgsl

@group(0) @binding(0) var<uniform> view: ViewUniform;
@group(0) @binding(1) var<storage, read> lights: array<GpuPointLight>;
@group(0) @binding(2) var<storage, read> instances: array<GpuInstance>;

@group(1) @binding(0) var<uniform> material: GpuMaterial;
@group(1) @binding(1) var base_color_texture: texture_2d<f32>;
@group(1) @binding(2) var base_color_sampler: sampler;
// glTF metallic-roughness: blue = metalness, green = roughness (linear)
@group(1) @binding(3) var metallic_roughness_texture: texture_2d<f32>;

@vertex
fn vs_main(v: VertexIn, @builtin(instance_index) instance_index: u32) -> SurfaceVertexOut {
    return surface_vertex(v, instances[instance_index], view.clip_from_world, view.camera_position.xyz);
}
