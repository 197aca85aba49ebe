// Prefiltering an environment for split-sum image-based lighting, once when it is loaded
// (Rust: `environment::EnvironmentMaps`), in compute:
// - cs_from_equirect: the equirectangular panorama into mip 0 of the source cube, each texel
//   the mean of supersample x supersample bilinear reads, so a panorama finer than the cube
//   does not alias;
// - cs_downsample: each further mip of the source cube, the mean of the four texels below it
//   (one bilinear read at their shared corner);
// - cs_specular: one mip of the specular cube, the source convolved with GGX at that mip's
//   roughness (params.roughness), with n = v = r (Karis 2013), importance sampled; each sample reads the source's
//   mip whose texels cover the sample's solid angle (filtered importance sampling, Colbert and
//   Krivanek 2007), so a few hundred samples do not sparkle;
// - cs_irradiance: the irradiance cube, (1 / pi) x the cosine-weighted integral, cosine
//   sampled the same way;
// - cs_brdf_lut: the split-sum table of GGX with the separable Smith visibility the lights are
//   shaded with: (scale, bias) of F0 at (n.v, roughness), and the Fresnel weight of the
//   diffuse lobe at n.v, as the shading passes read them (`common/environment.wgsl`).
// Rust twins of the estimators: `manylight_core::environment`.
//!include common/environment_map.wgsl

// Rust: `GpuEnvironmentFilter`.
struct GpuEnvironmentFilter {
    // face size (or table size) of what the dispatch writes, in texels
    size: u32,
    // samples per texel (cs_specular, cs_irradiance, cs_brdf_lut) or reads per axis
    // (cs_from_equirect)
    samples: u32,
    // GGX perceptual roughness of the mip cs_specular writes: (mip / (mips - 1))^2 (Rust:
    // `EnvironmentFilter::specular_mip_roughness`), which `environment_specular_lod` in
    // `common/environment.wgsl` maps back to the mip
    roughness: f32,
    // the source cube's mip-0 face size in texels
    source_size: f32,
    // the source cube's largest mip level
    source_max_lod: f32,
    // the equirectangular image's width and height (cs_from_equirect)
    equirect_width: u32,
    equirect_height: u32,
    _pad: u32,
};

@group(0) @binding(0) var<uniform> params: GpuEnvironmentFilter;
@group(0) @binding(1) var equirect: texture_2d<f32>;
@group(0) @binding(2) var source: texture_cube<f32>;
@group(0) @binding(3) var out_cube: texture_storage_2d_array<rgba16float, write>;
@group(0) @binding(4) var source_sampler: sampler;
@group(0) @binding(5) var out_lut: texture_storage_2d<rgba16float, write>;

// The largest finite f16: radiance is clamped to it so the cube holds no infinity.
const ENV_F16_MAX: f32 = 65504.0;

fn store_cube(id: vec3<u32>, value: vec3<f32>) {
    textureStore(out_cube, id.xy, id.z, vec4<f32>(min(value, vec3<f32>(ENV_F16_MAX)), 1.0));
}

// A texel of the panorama, wrapping horizontally and clamping at the poles.
fn equirect_texel(x: i32, y: i32) -> vec3<f32> {
    let w = i32(params.equirect_width);
    let h = i32(params.equirect_height);
    let xx = ((x % w) + w) % w;
    return textureLoad(equirect, vec2<i32>(xx, clamp(y, 0, h - 1)), 0).rgb;
}

// The panorama at `uv`, bilinear between texel centres (the float texture is not filterable).
fn equirect_bilinear(uv: vec2<f32>) -> vec3<f32> {
    let size = vec2<f32>(f32(params.equirect_width), f32(params.equirect_height));
    let p = uv * size - 0.5;
    let base = floor(p);
    let f = p - base;
    let x = i32(base.x);
    let y = i32(base.y);
    let top = mix(equirect_texel(x, y), equirect_texel(x + 1, y), f.x);
    let bottom = mix(equirect_texel(x, y + 1), equirect_texel(x + 1, y + 1), f.x);
    return mix(top, bottom, f.y);
}

@compute @workgroup_size(8, 8, 1)
fn cs_from_equirect(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.size || id.y >= params.size {
        return;
    }
    let n = max(params.samples, 1u);
    var sum = vec3<f32>(0.0);
    for (var j = 0u; j < n; j++) {
        for (var i = 0u; i < n; i++) {
            let sub = (vec2<f32>(f32(i), f32(j)) + 0.5) / f32(n);
            let uv = (vec2<f32>(id.xy) + sub) / f32(params.size);
            sum += equirect_bilinear(equirect_uv(cube_face_direction(id.z, uv)));
        }
    }
    store_cube(id, sum / f32(n * n));
}

fn texel_direction(id: vec3<u32>) -> vec3<f32> {
    let uv = (vec2<f32>(id.xy) + 0.5) / f32(params.size);
    return cube_face_direction(id.z, uv);
}

@compute @workgroup_size(8, 8, 1)
fn cs_downsample(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.size || id.y >= params.size {
        return;
    }
    // The source view holds only the mip above: its bilinear read at the corner the four
    // texels share is their mean.
    store_cube(id, textureSampleLevel(source, source_sampler, texel_direction(id), 0.0).rgb);
}

// The i-th of n points of the Hammersley set in [0, 1)^2.
fn hammersley(i: u32, n: u32) -> vec2<f32> {
    return vec2<f32>((f32(i) + 0.5) / f32(n), f32(reverseBits(i)) * 2.3283064365386963e-10);
}

// An orthonormal basis around unit `n` (Duff et al. 2017).
fn basis(n: vec3<f32>) -> mat3x3<f32> {
    let s = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (s + n.z);
    let b = n.x * n.y * a;
    let t = vec3<f32>(1.0 + s * n.x * n.x * a, s * b, -s * n.x);
    let bt = vec3<f32>(b, s + n.y * n.y * a, -n.y);
    return mat3x3<f32>(t, bt, n);
}

// A half vector about +Z distributed as GGX D(h) (n.h) for alpha = roughness^2.
fn ggx_half_vector(xi: vec2<f32>, alpha: f32) -> vec3<f32> {
    let a2 = alpha * alpha;
    let cos_theta = sqrt((1.0 - xi.y) / (1.0 + (a2 - 1.0) * xi.y));
    let sin_theta = sqrt(max(1.0 - cos_theta * cos_theta, 0.0));
    let phi = 2.0 * ENV_PI * xi.x;
    return vec3<f32>(sin_theta * cos(phi), sin_theta * sin(phi), cos_theta);
}

fn ggx_distribution(n_dot_h: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    return a2 / (ENV_PI * d * d);
}

// The source mip whose texels cover the solid angle of one of `n` samples of density `pdf`
// (per steradian), one level blurrier (Colbert and Krivanek's bias).
fn sample_lod(pdf: f32, n: u32) -> f32 {
    let texel = 4.0 * ENV_PI / (6.0 * params.source_size * params.source_size);
    let sample = 1.0 / (f32(n) * max(pdf, 1e-8));
    return clamp(0.5 * log2(sample / texel) + 1.0, 0.0, params.source_max_lod);
}

@compute @workgroup_size(8, 8, 1)
fn cs_specular(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.size || id.y >= params.size {
        return;
    }
    let n = texel_direction(id);
    let alpha = params.roughness * params.roughness;
    let frame = basis(n);
    let count = max(params.samples, 1u);
    var sum = vec3<f32>(0.0);
    var weight = 0.0;
    for (var i = 0u; i < count; i++) {
        let h_local = ggx_half_vector(hammersley(i, count), alpha);
        let h = frame * h_local;
        // v = n: the light direction mirrors n about h.
        let l = 2.0 * dot(n, h) * h - n;
        let n_dot_l = dot(n, l);
        if n_dot_l > 0.0 {
            // pdf of l: D(h) (n.h) / (4 v.h), and v.h = n.h here.
            let pdf = ggx_distribution(h_local.z, alpha) * 0.25;
            let lod = sample_lod(pdf, count);
            sum += textureSampleLevel(source, source_sampler, l, lod).rgb * n_dot_l;
            weight += n_dot_l;
        }
    }
    store_cube(id, sum / max(weight, 1e-6));
}

@compute @workgroup_size(8, 8, 1)
fn cs_irradiance(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.size || id.y >= params.size {
        return;
    }
    let n = texel_direction(id);
    let frame = basis(n);
    let count = max(params.samples, 1u);
    var sum = vec3<f32>(0.0);
    for (var i = 0u; i < count; i++) {
        let xi = hammersley(i, count);
        // Cosine-weighted: pdf = cos(theta) / pi, and the estimate of (1 / pi) x the integral
        // of L cos(theta) is the mean of L.
        let r = sqrt(xi.y);
        let phi = 2.0 * ENV_PI * xi.x;
        let cos_theta = sqrt(max(1.0 - xi.y, 0.0));
        let l = frame * vec3<f32>(r * cos(phi), r * sin(phi), cos_theta);
        let lod = sample_lod(cos_theta / ENV_PI, count);
        sum += textureSampleLevel(source, source_sampler, l, lod).rgb;
    }
    store_cube(id, sum / f32(count));
}

// Smith visibility V = G1(l) G1(v) / (4 n.l n.v) (the separable form), as `common/brdf.wgsl`
// shades lights.
fn smith_visibility(n_dot_l: f32, n_dot_v: f32, alpha: f32) -> f32 {
    let a2 = alpha * alpha;
    let vis_l = n_dot_l + sqrt(a2 + (1.0 - a2) * n_dot_l * n_dot_l);
    let vis_v = n_dot_v + sqrt(a2 + (1.0 - a2) * n_dot_v * n_dot_v);
    return 1.0 / (vis_l * vis_v);
}

@compute @workgroup_size(8, 8, 1)
fn cs_brdf_lut(@builtin(global_invocation_id) id: vec3<u32>) {
    if id.x >= params.size || id.y >= params.size {
        return;
    }
    // Texel centres: n.v from left to right, roughness from top to bottom.
    let n_dot_v = max((f32(id.x) + 0.5) / f32(params.size), 1e-4);
    let roughness = (f32(id.y) + 0.5) / f32(params.size);
    let alpha = roughness * roughness;
    let v = vec3<f32>(sqrt(1.0 - n_dot_v * n_dot_v), 0.0, n_dot_v);
    let count = max(params.samples, 1u);
    var scale = 0.0;
    var bias = 0.0;
    for (var i = 0u; i < count; i++) {
        let h = ggx_half_vector(hammersley(i, count), alpha);
        let l = 2.0 * dot(v, h) * h - v;
        let n_dot_l = l.z;
        let v_dot_h = max(dot(v, h), 0.0);
        if n_dot_l > 0.0 && v_dot_h > 0.0 {
            // f (n.l) / pdf with pdf = D (n.h) / (4 v.h): F x V x 4 (n.l) (v.h) / (n.h).
            let g = smith_visibility(n_dot_l, n_dot_v, alpha) * 4.0 * n_dot_l * v_dot_h / max(h.z, 1e-6);
            let x = 1.0 - v_dot_h;
            let fc = x * x * x * x * x;
            scale += (1.0 - fc) * g;
            bias += fc * g;
        }
    }
    // The diffuse lobe (1 - F) c_diff / pi = (1 - f0) c_diff / pi x (1 - (1 - v.h)^5): its
    // Fresnel factor averaged over cosine-distributed light, so the diffuse term is
    // c_diff (1 - f0) x this x the irradiance.
    var diffuse = 0.0;
    for (var i = 0u; i < count; i++) {
        let xi = hammersley(i, count);
        let r = sqrt(xi.y);
        let phi = 2.0 * ENV_PI * xi.x;
        let l = vec3<f32>(r * cos(phi), r * sin(phi), sqrt(max(1.0 - xi.y, 0.0)));
        let h = normalize(v + l);
        let x = 1.0 - clamp(dot(v, h), 0.0, 1.0);
        diffuse += 1.0 - x * x * x * x * x;
    }
    textureStore(out_lut, id.xy, vec4<f32>(scale / f32(count), bias / f32(count), diffuse / f32(count), 1.0));
}
