// The view's directional lights (`ViewUniform::directional`; not clustered: each reaches every
// pixel), read from the pass's view uniform in place.
//!include common/view_binding.wgsl
//!include common/brdf.wgsl
//!if SHADOWS
//!include common/shadows.wgsl
//!endif
//!if RAYS
//!include common/ray_shadows.wgsl
//!endif

// Radiance the view's directional lights add to a surface at `position` seen from
// `view_dir` (each times its shadow test where it casts one).
//
// It indexes the uniform buffer itself rather than a `ViewUniform` passed by value: lavapipe
// copies a struct argument, array and all, into every invocation before a dynamic index can
// read it, which made this loop about 40 % of the sphere-shell scene's shading at 1 024
// lights, a scene with no directional light at all (docs/benchmarks.md, "Per-pixel cost").
fn shade_directional_lights(s: SurfaceParams, position: vec3<f32>, view_dir: vec3<f32>) -> vec3<f32> {
    var color = vec3<f32>(0.0);
//!if SHADOWS
    let view_distance = -(view.view_from_world * vec4<f32>(position, 1.0)).z;
//!endif
    for (var i = 0u; i < min(view.directional_count, MAX_DIRECTIONAL_LIGHTS); i++) {
        let light = view.directional[i];
        var radiance = reflected(s, -light.direction.xyz, view_dir) * light.color.rgb;
//!if SHADOWS
        if any(radiance > vec3<f32>(0.0)) {
            radiance *= directional_shadow_visibility(i, light.direction.xyz, position, s.normal, view_distance);
        }
//!endif
//!if RAYS
        if any(radiance > vec3<f32>(0.0)) {
            radiance *= ray_directional_visibility(view.rays, light.direction, position, s.normal);
        }
//!endif
        color += radiance;
    }
    return color;
}
