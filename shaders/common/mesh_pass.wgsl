// What every pass drawing the scene's meshes with surface shading shares (forward, clustered
// forward, G-buffer): group 0 (Rust: `SceneResources::view_layout`), group 1 (the material,
// `common/mesh_material.wgsl`) and the vertex stage, which reads its instance from a storage
// buffer.
//!include common/view.wgsl
//!include common/lights.wgsl
//!include common/mesh.wgsl
//!include common/surface.wgsl
//!include common/view_binding.wgsl

//!include common/point_lights.wgsl
@group(0) @binding(2) var<storage, read> instances: array<GpuInstance>;

//!include common/mesh_material.wgsl

@vertex
fn vs_main(v: VertexIn, @builtin(instance_index) instance_index: u32) -> SurfaceVertexOut {
    return surface_vertex(v, instances[instance_index], view.clip_from_world, view.camera_position.xyz);
}
