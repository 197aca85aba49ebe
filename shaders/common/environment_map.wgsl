// Directions of environment maps, shared by the shading passes, the skybox and the prefilter
// passes (Rust twin: `manylight_core::environment::{equirect_uv, equirect_direction}`).

const ENV_PI: f32 = 3.14159265358979;

// Where unit direction `d` lands in an equirectangular image: u from left to right (0.5 looks
// along -Z, 0.75 along +X), v from the zenith down.
fn equirect_uv(d: vec3<f32>) -> vec2<f32> {
    let u = 0.5 + atan2(d.x, -d.z) / (2.0 * ENV_PI);
    let v = acos(clamp(d.y, -1.0, 1.0)) / ENV_PI;
    return vec2<f32>(u, v);
}

// The direction through texel centre `uv` (0..1 across the face, v down) of cube face `face`
// (+X, -X, +Y, -Y, +Z, -Z), as a cube texture is sampled (the face's major axis, then the
// WebGPU/Vulkan rule for its s and t axes): the prefilter passes write each texel with the
// environment in this direction, so sampling the cube with a direction reads it there.
fn cube_face_direction(face: u32, uv: vec2<f32>) -> vec3<f32> {
    let a = uv * 2.0 - 1.0;
    var d: vec3<f32>;
    switch face {
        case 0u: { d = vec3<f32>(1.0, -a.y, -a.x); }
        case 1u: { d = vec3<f32>(-1.0, -a.y, a.x); }
        case 2u: { d = vec3<f32>(a.x, 1.0, a.y); }
        case 3u: { d = vec3<f32>(a.x, -1.0, -a.y); }
        case 4u: { d = vec3<f32>(a.x, -a.y, 1.0); }
        default: { d = vec3<f32>(-a.x, -a.y, -1.0); }
    }
    return normalize(d);
}
