// The skybox: behind the geometry (where the depth buffer holds the reverse-Z far plane, 0),
// the environment the pixel's ray looks at, times the skybox's brightness. A full-screen
// triangle at depth 0 with the test "greater or equal" touches only those pixels.
//!include common/view.wgsl
//!include common/fullscreen.wgsl
//!include common/environment_map.wgsl

@group(0) @binding(0) var<uniform> view: ViewUniform;
@group(0) @binding(1) var sky: texture_cube<f32>;
@group(0) @binding(2) var sky_sampler: sampler;

@fragment
fn fs_main(in: FullscreenOut) -> @location(0) vec4<f32> {
    let ray = view_ray(view, in.position.xy);
    let d = (view.sky_from_world * vec4<f32>(normalize(ray), 0.0)).xyz;
    let radiance = textureSampleLevel(sky, sky_sampler, d, 0.0).rgb * view.environment.z;
    return vec4<f32>(radiance, 1.0);
}
