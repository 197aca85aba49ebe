// Depth pre-pass: depth only, so the lighting pass shades each pixel once.
//!include common/view.wgsl
//!include common/mesh.wgsl

@group(0) @binding(0) var<uniform> view: ViewUniform;
@group(0) @binding(2) var<storage, read> instances: array<GpuInstance>;

@vertex
fn vs_main(v: VertexIn, @builtin(instance_index) instance_index: u32) -> @invariant @builtin(position) vec4<f32> {
    let world = instances[instance_index].world_from_local * vec4<f32>(v.position, 1.0);
    return view.clip_from_world * world;
}
