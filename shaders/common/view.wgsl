// A directional light (Rust: `GpuDirectionalLight`): light travelling along `direction`
// everywhere, not clustered.
struct GpuDirectionalLight {
    // xyz: unit direction the light travels (from the light into the scene), w: unused
    direction: vec4<f32>,
    // rgb: colour x illuminance (linear), a: unused
    color: vec4<f32>,
};

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
    // the environment's axes from world axes (`common/environment.wgsl`)
    env_from_world: mat4x4<f32>,
    // the skybox's axes from world axes (`skybox.wgsl`)
    sky_from_world: mat4x4<f32>,
    // x: environment intensity, y: the specular cube's largest mip level, z: skybox
    // brightness, w: unused
    environment: vec4<f32>,
    // the shadow rays' geometry (`common/ray_bvh.wgsl`): x the instance level's root
    // (RAY_NO_NODE: no ray), y the first `ray_prims` entry of the instances, z that of the
    // casting lights' bits
    rays: vec4<u32>,
    light_count: u32,
    shading_model: u32,
    directional_count: u32,
    _pad0: u32,
    directional: array<GpuDirectionalLight, MAX_DIRECTIONAL_LIGHTS>,
};

// True for an orthographic projection: its matrix has w = 1 for every point (a perspective
// one has w = -z).
fn is_orthographic(v: ViewUniform) -> bool {
    return v.clip_from_view[3][3] == 1.0;
}

// A view-space vector in world axes, through the inverse of the view's 3x3 part (cofactors,
// so a scaled camera works too); no world coordinate enters it, so it is as exact far from the
// world origin as near it.
fn view_to_world_vector(v: ViewUniform, d: vec3<f32>) -> vec3<f32> {
    let c0 = v.view_from_world[0].xyz;
    let c1 = v.view_from_world[1].xyz;
    let c2 = v.view_from_world[2].xyz;
    let r0 = cross(c1, c2);
    let r1 = cross(c2, c0);
    let r2 = cross(c0, c1);
    return vec3<f32>(dot(r0, d), dot(r1, d), dot(r2, d)) / dot(c0, r0);
}

// NDC of the framebuffer position `frag` (pixel centres at .5).
fn frag_ndc(v: ViewUniform, frag: vec2<f32>) -> vec2<f32> {
    return vec2<f32>(frag.x * v.viewport.z * 2.0 - 1.0, 1.0 - frag.y * v.viewport.w * 2.0);
}

// x and y of the view-space point at z = -1 (perspective) or 0 (orthographic) that the
// framebuffer position `frag` sees.
fn frag_view_xy(v: ViewUniform, frag: vec2<f32>) -> vec2<f32> {
    let ndc = frag_ndc(v, frag);
    return vec2<f32>(ndc.x / v.clip_from_view[0][0], ndc.y / v.clip_from_view[1][1]);
}

// The functions below choose between perspective and orthographic with `select`, never a
// branch: lavapipe (Mesa 22.3) folds a branch that depends only on a uniform buffer into a
// copy of the shader compiled at draw time, and never frees it (the Compact G-buffer pass grew
// by about 15 MB a frame through `surface_point`; docs/reliability.md).

// Direction of the ray through the framebuffer position `frag`, in world axes, scaled so that
// its view-space z is -1: the point `camera + view_ray_origin + t * ray` lies at view depth t.
// Perspective rays leave the camera; orthographic rays are parallel.
fn view_ray(v: ViewUniform, frag: vec2<f32>) -> vec3<f32> {
    let xy = select(frag_view_xy(v, frag), vec2<f32>(0.0), is_orthographic(v));
    return view_to_world_vector(v, vec3<f32>(xy, -1.0));
}

// Where the ray through `frag` starts, relative to the camera position: 0 in perspective; on
// the camera's plane, beside it, in orthographic.
fn view_ray_origin(v: ViewUniform, frag: vec2<f32>) -> vec3<f32> {
    let xy = select(vec2<f32>(0.0), frag_view_xy(v, frag), is_orthographic(v));
    return view_to_world_vector(v, vec3<f32>(xy, 0.0));
}

// Unit direction from the surface point `p` (world) towards the eye: to the camera position in
// perspective, against the view direction in orthographic.
fn direction_to_eye(v: ViewUniform, p: vec3<f32>) -> vec3<f32> {
    let orthographic = normalize(view_to_world_vector(v, vec3<f32>(0.0, 0.0, 1.0)));
    return select(normalize(v.camera_position.xyz - p), orthographic, is_orthographic(v));
}

// View distance (positive) of a reverse-Z depth value, through the projection's depth terms
// (depth = (A z + B) / w): perspective `B / (depth + A)` with w = -z, orthographic
// `(B - depth) / A` with w = 1 (manylight_core::Projection::linearize_depth).
fn view_distance_of_depth(v: ViewUniform, depth: f32) -> f32 {
    let a = v.clip_from_view[2][2];
    let b = v.clip_from_view[3][2];
    let near = v.params.x;
    let near_over_far = v.params.y;
    let perspective = near / (depth * (1.0 - near_over_far) + near_over_far);
    return select(perspective, (b - depth) / a, is_orthographic(v));
}
