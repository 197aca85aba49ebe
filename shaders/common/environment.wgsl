// The light of the view's environment map (split-sum image-based lighting), for the passes
// that shade surfaces: forward passes add it to the fragment, the G-buffer pass to the emissive
// target, so every pipeline adds the same term. Composed with ENVIRONMENT, the prefiltered maps
// are bound in group 0 (Rust: `ENVIRONMENT_BINDINGS`); without it `environment_light` is 0 and
// nothing is bound.
//!include common/brdf.wgsl
//!include common/view_binding.wgsl
//!include common/environment_map.wgsl

//!if ENVIRONMENT
// The specular cube: mip m is the environment prefiltered with GGX at perceptual roughness
// (m / (mips - 1))^2 (Rust: `EnvironmentFilter::specular_mip_roughness`; view.environment.y
// is mips - 1), read at `environment_specular_lod`.
@group(0) @binding(7) var env_specular: texture_cube<f32>;
// The diffuse irradiance cube: (1 / pi) x the cosine-weighted integral of the environment.
@group(0) @binding(8) var env_irradiance: texture_cube<f32>;
// The split-sum lookup table: (scale, bias) of F0 at (n.v, roughness), and the diffuse lobe's
// Fresnel weight at n.v.
@group(0) @binding(9) var env_brdf_lut: texture_2d<f32>;
@group(0) @binding(10) var env_sampler: sampler;

// The environment's direction for world direction `d` (its rotation).
fn environment_direction(d: vec3<f32>) -> vec3<f32> {
    return (view.env_from_world * vec4<f32>(d, 0.0)).xyz;
}

fn environment_irradiance(n: vec3<f32>) -> vec3<f32> {
    return textureSampleLevel(env_irradiance, env_sampler, environment_direction(n), 0.0).rgb;
}

// The specular mip of perceptual `roughness`: sqrt(roughness) x (mips - 1), the inverse of the
// prefilter's (m / (mips - 1))^2 (Rust: `EnvironmentFilter::specular_lod` and
// `specular_mip_roughness`, which set each mip's roughness for `cs_specular`).
fn environment_specular_lod(roughness: f32) -> f32 {
    return sqrt(clamp(roughness, 0.0, 1.0)) * view.environment.y;
}

fn environment_specular(r: vec3<f32>, roughness: f32) -> vec3<f32> {
    let lod = environment_specular_lod(roughness);
    return textureSampleLevel(env_specular, env_sampler, environment_direction(r), lod).rgb;
}

// The split-sum (scale, bias) of F0 at `n_dot_v` and perceptual `roughness`, and the diffuse
// lobe's Fresnel weight at `n_dot_v`.
fn environment_brdf(n_dot_v: f32, roughness: f32) -> vec3<f32> {
    return textureSampleLevel(env_brdf_lut, env_sampler, vec2<f32>(n_dot_v, roughness), 0.0).rgb;
}

// The Blinn-Phong exponent's GGX perceptual roughness: the Beckmann slope sqrt(2 / (n + 2)) of
// the same lobe width, whose square root is the perceptual roughness.
fn environment_blinn_phong_roughness(shininess: f32) -> f32 {
    return clamp(pow(2.0 / (max(shininess, 0.0) + 2.0), 0.25), PBR_MIN_ROUGHNESS, 1.0);
}

// What the environment sends towards `view_dir` (unit, towards the eye) from a surface, with the
// material's `occlusion`, in each shading model's own way:
// - PBR: split-sum; specular = prefiltered radiance at the mirror direction x (F0 scale + bias),
//   diffuse = c_diff (1 - F0) x the diffuse lobe's Fresnel weight x irradiance (the lights'
//   (1 - F) c_diff / pi, integrated over a constant environment);
// - Lambert: albedo x irradiance;
// - Blinn-Phong: albedo x irradiance, plus the specular strength x the radiance prefiltered at
//   the roughness of its exponent;
// - toon: albedo x irradiance (its bands and rim come from its lights).
fn environment_light(s: SurfaceParams, view_dir: vec3<f32>, occlusion: f32) -> vec3<f32> {
    let intensity = view.environment.x * occlusion;
    let irradiance = environment_irradiance(s.normal);
    let n_dot_v = max(dot(s.normal, view_dir), PBR_MIN_N_DOT_V);
    let r = reflect(-view_dir, s.normal);
    if s.model == SHADING_PBR {
        let metallic = clamp(s.metallic, 0.0, 1.0);
        let roughness = clamp(s.roughness, PBR_MIN_ROUGHNESS, 1.0);
        let f0 = mix(vec3<f32>(PBR_DIELECTRIC_F0), s.albedo, metallic);
        let lut = environment_brdf(n_dot_v, roughness);
        let c_diff = s.albedo * (1.0 - metallic);
        let specular = environment_specular(r, roughness) * (f0 * lut.x + vec3<f32>(lut.y));
        let diffuse = c_diff * (vec3<f32>(1.0) - f0) * (lut.z * irradiance);
        return (diffuse + specular) * intensity;
    }
    var result = s.albedo * irradiance;
    if s.model == SHADING_BLINN_PHONG {
        result += s.specular * environment_specular(r, environment_blinn_phong_roughness(s.shininess));
    }
    return result * intensity;
}
//!else
fn environment_light(s: SurfaceParams, view_dir: vec3<f32>, occlusion: f32) -> vec3<f32> {
    return vec3<f32>(0.0);
}
//!endif
