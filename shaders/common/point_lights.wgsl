// The point and spot lights of a shading pass (group 0, binding 1 of Rust's
// `SceneResources::view_layout`) and the shading of one of them by index.
//!include common/lights.wgsl
//!include common/brdf.wgsl
//!if SHADOWS
//!include common/shadows.wgsl
//!endif
//!if RAYS
//!include common/view_binding.wgsl
//!include common/ray_shadows.wgsl
//!endif

@group(0) @binding(1) var<storage, read> lights: array<GpuPointLight>;

// Radiance light `k` adds at `position` seen from `view_dir`, reading its colour and spot
// fields only when it reaches `position`: on a CPU rasteriser each field read is a gather over
// the invocations, and most lights of a light list end at the range test (what it saves is in
// docs/benchmarks.md).
fn shade_light(s: SurfaceParams, position: vec3<f32>, view_dir: vec3<f32>, k: u32) -> vec3<f32> {
    let reach = light_reach(lights[k].position_radius, position);
    if reach.attenuation <= 0.0 {
        return vec3<f32>(0.0);
    }
    let radiance = shade_reached_light(s, reach, view_dir, lights[k].color, lights[k].spot);
//!if SHADOWS
    // Only a light that adds something (in front of the surface, inside its cone) pays for the
    // map lookup.
    if any(radiance > vec3<f32>(0.0)) {
        return radiance * shadow_visibility(k, position, s.normal);
    }
//!endif
//!if RAYS
    // Only a light that adds something pays for its ray.
    if any(radiance > vec3<f32>(0.0)) {
        return radiance * ray_light_visibility(view.rays, k, lights[k].position_radius.xyz, position, s.normal);
    }
//!endif
    return radiance;
}

// `base` plus the radiance every point and spot light (`n` of them) adds at `position`, added in
// light order as a light list adds its lights: naive forward, and a cluster whose list did not
// fit the frame's lists (LIST_EVERY_LIGHT). Four lights per iteration: lavapipe stops an
// invocation after 65 535 loop iterations, which would drop every light past the 65 535th.
fn add_every_light_to(base: vec3<f32>, s: SurfaceParams, position: vec3<f32>, view_dir: vec3<f32>, n: u32) -> vec3<f32> {
    var color = base;
    var i = 0u;
    for (; i + 4u <= n; i += 4u) {
        color += shade_light(s, position, view_dir, i);
        color += shade_light(s, position, view_dir, i + 1u);
        color += shade_light(s, position, view_dir, i + 2u);
        color += shade_light(s, position, view_dir, i + 3u);
    }
    for (; i < n; i++) {
        color += shade_light(s, position, view_dir, i);
    }
    return color;
}
