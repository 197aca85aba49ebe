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
    if s.model == SHADING_TOON {
        return toon_point_light(s, n_dot_l, view_dir, l) * light.color.rgb * att;
    }
    var result = s.albedo * n_dot_l;
    if s.model == SHADING_BLINN_PHONG && n_dot_l > 0.0 {
        let h = normalize(l + view_dir);
        let n_dot_h = max(dot(s.normal, h), 0.0);
        result += vec3<f32>(s.specular * pow(n_dot_h, s.shininess) * n_dot_l);
    }
    return result * light.color.rgb * att;
}

// Toon (cel) shading of one light: the diffuse term in TOON_BANDS flat bands (the light's
// attenuation stays smooth, so many overlapping lights do not stack into hard rings), plus a rim
// on silhouettes where the light reaches the surface or grazes it from behind.
fn toon_point_light(s: SurfaceParams, n_dot_l: f32, view_dir: vec3<f32>, l: vec3<f32>) -> vec3<f32> {
    let bands = f32(TOON_BANDS);
    // n_dot_l rounded to the nearest band (halves upwards): 0 up to 1/6, then 1/3, 2/3, 1.
    let band = ceil(n_dot_l * bands - 0.5) / bands;
    let n_dot_v = max(dot(s.normal, view_dir), 0.0);
    let rim = pow(1.0 - n_dot_v, 4.0) * smoothstep(-0.2, 0.1, dot(s.normal, l));
    return s.albedo * band + s.albedo * (TOON_RIM_STRENGTH * rim);
}
