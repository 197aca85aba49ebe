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
    // x: near, y: near / far (0 without a far plane), z: exposure, w: ambient intensity
    params: vec4<f32>,
    light_count: u32,
    shading_model: u32,
    _pad0: u32,
    _pad1: u32,
};

// Direction of the ray through the framebuffer position `frag` (pixel centres at .5), in world
// axes but relative to the camera, scaled so that its view-space z is -1: the point
// `camera + t * ray` lies at view depth t. Built from the projection's scale terms and the
// inverse of the view's 3x3 part (cofactors, so a scaled camera works too); no world
// coordinate enters it, so it is as exact far from the world origin as near it.
fn view_ray(v: ViewUniform, frag: vec2<f32>) -> vec3<f32> {
    let ndc = vec2<f32>(frag.x * v.viewport.z * 2.0 - 1.0, 1.0 - frag.y * v.viewport.w * 2.0);
    let dir_view = vec3<f32>(ndc.x / v.clip_from_view[0][0], ndc.y / v.clip_from_view[1][1], -1.0);
    let c0 = v.view_from_world[0].xyz;
    let c1 = v.view_from_world[1].xyz;
    let c2 = v.view_from_world[2].xyz;
    let r0 = cross(c1, c2);
    let r1 = cross(c2, c0);
    let r2 = cross(c0, c1);
    return vec3<f32>(dot(r0, dir_view), dot(r1, dir_view), dot(r2, dir_view)) / dot(c0, r0);
}
