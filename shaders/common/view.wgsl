// Per-view constants (Rust: `ViewUniform` in crates/manylight_render/src/gpu_types.rs).
struct ViewUniform {
    clip_from_world: mat4x4<f32>,
    view_from_world: mat4x4<f32>,
    clip_from_view: mat4x4<f32>,
    world_from_clip: mat4x4<f32>,
    prev_clip_from_world: mat4x4<f32>,
    // xyz: camera position in world space, w: unused
    camera_position: vec4<f32>,
    // x, y: viewport size in pixels, z, w: 1 / size
    viewport: vec4<f32>,
    // x: near, y: far, z: exposure, w: ambient intensity
    params: vec4<f32>,
    light_count: u32,
    shading_model: u32,
    _pad0: u32,
    _pad1: u32,
};
