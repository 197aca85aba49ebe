// Shading models (ids: SHADING_* constants, generated from Rust `ShadingModel::gpu_id`).
//!include common/lights.wgsl
//!include common/view.wgsl
// Rust twin: `manylight_core::brdf` (same operations, same order).
struct SurfaceParams {
    albedo: vec3<f32>,
    normal: vec3<f32>,
    // Blinn-Phong exponent and strength (Blinn-Phong, toon)
    shininess: f32,
    specular: f32,
    // metalness 0..1 and perceptual roughness PBR_MIN_ROUGHNESS..1 (PBR)
    metallic: f32,
    roughness: f32,
    model: u32,
};

// The two material parameters the surface's model reads, as the G-buffers store them:
// (shininess, specular) for Blinn-Phong and toon, (roughness, metallic) for PBR.
fn material_slots(s: SurfaceParams) -> vec2<f32> {
    return select(vec2<f32>(s.shininess, s.specular), vec2<f32>(s.roughness, s.metallic), s.model == SHADING_PBR);
}

// `s` with the parameters of `material_slots` read back (each model reads only its own pair).
fn with_material_slots(s: SurfaceParams, slots: vec2<f32>) -> SurfaceParams {
    var out = s;
    out.shininess = slots.x;
    out.specular = slots.y;
    out.roughness = slots.x;
    out.metallic = slots.y;
    return out;
}

// How a light (`position_radius`: `GpuPointLight::position_radius`) reaches `position`: the
// vector to it, its distance and the distance attenuation (0: the light adds nothing).
struct LightReach {
    to_light: vec3<f32>,
    distance: f32,
    attenuation: f32,
};

fn light_reach(position_radius: vec4<f32>, position: vec3<f32>) -> LightReach {
    let to_light = position_radius.xyz - position;
    let distance = length(to_light);
    return LightReach(to_light, distance, attenuation(distance, position_radius.w));
}

// Radiance a point or spot light that reaches the point (`reach`, attenuation above 0) adds,
// seen from `view_dir` (unit, towards the eye), with the light's `color` and `spot` fields
// (`shade_light` in `point_lights.wgsl` reads those two only here: on a CPU rasteriser every
// field read is a gather, and most listed lights end at the range test).
fn shade_reached_light(s: SurfaceParams, reach: LightReach, view_dir: vec3<f32>, color: vec4<f32>, spot: vec4<f32>) -> vec3<f32> {
    let l = reach.to_light / max(reach.distance, 1e-6);
    let cone = spot_attenuation(dot(spot.xyz, -l), spot.w, color.a);
    return reflected(s, l, view_dir) * color.rgb * (reach.attenuation * cone);
}

// What a surface reflects towards `view_dir` of unit light arriving from unit direction `l`
// (towards the light): the model's BRDF times n.l. Point, spot and directional lights multiply
// it by their colour and falloff (in that order: a huge colour overflows to infinity there,
// and the tone map counts it).
fn reflected(s: SurfaceParams, l: vec3<f32>, view_dir: vec3<f32>) -> vec3<f32> {
    let n_dot_l = max(dot(s.normal, l), 0.0);
    if s.model == SHADING_TOON {
        return toon_point_light(s, n_dot_l, view_dir, l);
    }
    if s.model == SHADING_PBR {
        if n_dot_l <= 0.0 {
            return vec3<f32>(0.0);
        }
        return pbr_point_light(s, n_dot_l, view_dir, l);
    }
    var result = s.albedo * n_dot_l;
    if s.model == SHADING_BLINN_PHONG && n_dot_l > 0.0 {
        let h = normalize(l + view_dir);
        let n_dot_h = max(dot(s.normal, h), 0.0);
        result += vec3<f32>(s.specular * pow(n_dot_h, s.shininess) * n_dot_l);
    }
    return result;
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

// glTF 2.0 metallic-roughness (Appendix B) times n.l, for a light in direction `l` with
// n_dot_l > 0: GGX distribution, separable Smith visibility, Schlick Fresnel, Lambert
// diffuse, split by metallic.
fn pbr_point_light(s: SurfaceParams, n_dot_l: f32, view_dir: vec3<f32>, l: vec3<f32>) -> vec3<f32> {
    let metallic = clamp(s.metallic, 0.0, 1.0);
    let roughness = clamp(s.roughness, PBR_MIN_ROUGHNESS, 1.0);
    let a = roughness * roughness;
    let a2 = a * a;
    let hv = l + view_dir;
    let hl = length(hv);
    let h = select(s.normal, hv / hl, hl > 0.0);
    let n_dot_v = max(dot(s.normal, view_dir), PBR_MIN_N_DOT_V);
    let n_dot_h = max(dot(s.normal, h), 0.0);
    let v_dot_h = clamp(dot(view_dir, h), 0.0, 1.0);
    let f0 = mix(vec3<f32>(PBR_DIELECTRIC_F0), s.albedo, metallic);
    let c_diff = s.albedo * (1.0 - metallic);
    let x = 1.0 - v_dot_h;
    let x2 = x * x;
    let fresnel = f0 + (vec3<f32>(1.0) - f0) * (x2 * x2 * x);
    let d_denom = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    let d = a2 / (BRDF_PI * d_denom * d_denom);
    let vis_l = n_dot_l + sqrt(a2 + (1.0 - a2) * n_dot_l * n_dot_l);
    let vis_v = n_dot_v + sqrt(a2 + (1.0 - a2) * n_dot_v * n_dot_v);
    let vis = 1.0 / (vis_l * vis_v);
    let diffuse = (vec3<f32>(1.0) - fresnel) * c_diff * BRDF_FRAC_1_PI;
    let specular = fresnel * (d * vis);
    return (diffuse + specular) * n_dot_l;
}
