// Shading models (ids: SHADING_* constants, generated from Rust `ShadingModel::gpu_id`).
//!include common/lights.wgsl
struct SurfaceParams {
    albedo: vec3<f32>,
    normal: vec3<f32>,
    shininess: f32,
    specular: f32,
    model: u32,
};

// Radiance a point light adds at `position` seen from `view_dir` (unit, towards the eye).
fn shade_point_light(s: SurfaceParams, position: vec3<f32>, view_dir: vec3<f32>, light: GpuPointLight) -> vec3<f32> {
    let to_light = light.position_radius.xyz - position;
    let distance = length(to_light);
    let att = attenuation(distance, light.position_radius.w);
    if att <= 0.0 {
        return vec3<f32>(0.0);
    }
    let l = to_light / max(distance, 1e-6);
    let n_dot_l = max(dot(s.normal, l), 0.0);
    var result = s.albedo * n_dot_l;
    if s.model == SHADING_BLINN_PHONG && n_dot_l > 0.0 {
        let h = normalize(l + view_dir);
        let n_dot_h = max(dot(s.normal, h), 0.0);
        result += vec3<f32>(s.specular * pow(n_dot_h, s.shininess) * n_dot_l);
    }
    return result * light.color.rgb * att;
}
