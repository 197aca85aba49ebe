// Vertex transform, shading position and surface parameters shared by every pass that shades
// meshes.
//!include common/view.wgsl
//!include common/mesh.wgsl
//!include common/brdf.wgsl

struct SurfaceVertexOut {
    @invariant @builtin(position) clip_position: vec4<f32>,
    // World position minus the camera position (camera-relative: interpolated values near the
    // camera are small, whatever the distance from the world origin).
    @location(0) camera_offset: vec3<f32>,
    @location(1) world_normal: vec3<f32>,
    // xy: TEXCOORD_0, zw: TEXCOORD_1 (`texture_uv` picks and transforms a texture's).
    @location(2) uv: vec4<f32>,
    // World tangent (xyz, transformed like positions) and the bitangent's handedness in world
    // space (w: the vertex's times the sign of the instance's determinant; 0 without tangent).
    @location(3) world_tangent: vec4<f32>,
};

// True in the pipelines of alpha-masked materials (Rust: `SurfaceVariant::alpha_mask`).
override ALPHA_MASK: bool = false;

// The texture slots the pipeline samples (Rust: `SurfaceVariant::textures`): each material's
// draws use the pipeline of its own slots, and a slot left out costs nothing. A branch on the
// material's flag would not do: lavapipe runs both sides of it, so every pixel paid for all
// five samples (a quarter of the untextured sphere-shell scene's shading). True by default,
// so a pipeline that sets none samples every slot its material flags.
override BASE_COLOR_TEXTURE: bool = true;
override METALLIC_ROUGHNESS_TEXTURE: bool = true;
override NORMAL_TEXTURE: bool = true;
override OCCLUSION_TEXTURE: bool = true;
override EMISSIVE_TEXTURE: bool = true;

// The shading model of the pipeline's draws (Rust: `SurfaceVariant::shading`, resolved against
// the view's), or SHADING_GLOBAL where each fragment reads its material's and the view's. A
// constant model leaves the other models' code out of the loop over lights, which lavapipe
// would run for every light whatever the branch decided.
override SHADING_MODEL: u32 = SHADING_GLOBAL;

fn surface_vertex(v: VertexIn, inst: GpuInstance, clip_from_world: mat4x4<f32>, camera: vec3<f32>) -> SurfaceVertexOut {
    let world = inst.world_from_local * vec4<f32>(v.position, 1.0);
    let m = mat3x3<f32>(inst.world_from_local[0].xyz, inst.world_from_local[1].xyz, inst.world_from_local[2].xyz);
    // A mirrored instance (negative determinant) flips the bitangent's handedness too.
    let mirror = select(1.0, -1.0, determinant(m) < 0.0);
    var out: SurfaceVertexOut;
    out.clip_position = clip_from_world * world;
    out.camera_offset = world.xyz - camera;
    out.world_normal = (inst.normal_from_local * vec4<f32>(v.normal, 0.0)).xyz;
    out.uv = vec4<f32>(v.uv, v.uv1);
    out.world_tangent = vec4<f32>(m * v.tangent.xyz, v.tangent.w * mirror);
    return out;
}

// The material's base colour times its texture's `texel` where it has one. The texels reach
// these functions already sampled (`sample_material`, 1 where the pipeline does not sample the
// slot) and are chosen by select, never by a branch on the material: lavapipe (Mesa 22.3)
// compiles a shader again at every draw when it can fold a uniform-buffer branch away, and
// keeps every copy (about 9 MB per frame in the Packed and Compact G-buffer passes).
fn surface_albedo(m: GpuMaterial, texel: vec4<f32>) -> vec4<f32> {
    return m.base_color * select(vec4<f32>(1.0), texel, m.has_texture != 0u);
}

// Metalness and roughness of the material (factors times the texture `texel`'s blue and green).
fn surface_metal_rough(m: GpuMaterial, texel: vec4<f32>) -> vec2<f32> {
    let t = select(vec4<f32>(1.0), texel, m.has_metallic_roughness_texture != 0u);
    return vec2<f32>(m.metallic * t.b, m.roughness * t.g);
}

// The shading normal of a fragment: the interpolated normal, turned to the side the camera
// sees (the back faces of single-sided materials are culled before they get here; a mirrored
// instance's pipeline takes clockwise triangles as front, so `front_facing` is the face's own
// side whatever the instance's handedness), then
// perturbed by the tangent-space normal map `texel` (0..1 per channel) when the material has
// one and the vertex a tangent frame (glTF: bitangent = w * cross(normal, tangent), the map's
// +y along it). On a back face the whole frame turns, as MikkTSpace bakers expect.
fn surface_normal(m: GpuMaterial, texel: vec3<f32>, in: SurfaceVertexOut, front_facing: bool) -> vec3<f32> {
    let len = length(in.world_normal);
    let n0 = select(vec3<f32>(0.0, 1.0, 0.0), in.world_normal / len, len > 1e-8);
    let side = select(-1.0, 1.0, front_facing);
    let n = n0 * side;
    let t = in.world_tangent.xyz * side;
    let b = cross(n0, in.world_tangent.xyz) * (in.world_tangent.w * side);
    let tn = vec3<f32>((texel.xy * 2.0 - 1.0) * m.normal_scale, texel.z * 2.0 - 1.0);
    let mapped = tn.x * t + tn.y * b + tn.z * n;
    let mapped_len = length(mapped);
    let usable = m.has_normal_texture != 0u && in.world_tangent.w != 0.0 && mapped_len > 1e-8;
    return select(n, mapped / mapped_len, usable);
}

// Ambient occlusion of the material for the occlusion texture's red channel `texel`.
fn surface_occlusion(m: GpuMaterial, texel: f32) -> f32 {
    let strength = saturate(m.occlusion_strength);
    return select(1.0, 1.0 + strength * (texel - 1.0), m.has_occlusion_texture != 0u);
}

// Radiance a surface sends back whatever the point lights: the ambient term (darkened by
// occlusion) plus what it emits.
fn surface_base_radiance(albedo: vec3<f32>, ambient: f32, occlusion: f32, emissive: vec3<f32>) -> vec3<f32> {
    return albedo * ambient * occlusion + emissive;
}

// The surface parameters of a fragment whose shading normal `n` is unit length and oriented.
fn surface_params(m: GpuMaterial, global_model: u32, albedo: vec3<f32>, metal_rough: vec2<f32>, n: vec3<f32>) -> SurfaceParams {
    var s: SurfaceParams;
    s.albedo = albedo;
    s.normal = n;
    s.shininess = m.shininess;
    s.specular = m.specular;
    s.metallic = saturate(metal_rough.x);
    s.roughness = clamp(metal_rough.y, PBR_MIN_ROUGHNESS, 1.0);
    s.model = select(m.shading_model, global_model, m.shading_model == SHADING_GLOBAL);
    if SHADING_MODEL != SHADING_GLOBAL {
        s.model = SHADING_MODEL;
    }
    return s;
}

// Where a fragment is shaded.
struct SurfacePoint {
    world_position: vec3<f32>,
    // Distance from the camera along the view direction (view-space -z).
    view_depth: f32,
};

// The cosine between the pixel's ray and its triangle below which `surface_point` keeps the
// interpolated position (the ray runs within 0.06 degrees of the plane: the intersection
// would amplify any error of the plane).
const SURFACE_POINT_MIN_COSINE: f32 = 1e-3;

// The shading position of a fragment: the pixel's ray (`view_ray`) intersected with the plane
// of its triangle, which passes through the interpolated camera-relative position `offset`
// with the normal cross(dpdx, dpdy) of it. Interpolation across a triangle whose vertices lie
// far beyond the pixel (a floor 1e7 wide seen from 2 units) is off by about |vertex| * 2^-24,
// and clipping such a triangle at the near plane puts the rasteriser's depth off as well; the
// error lies within the triangle's plane for an axis-aligned surface, so the intersection
// removes it, and for a small triangle it changes the interpolated point by rounding only.
// Uses derivatives: call it in uniform control flow.
fn surface_point(v: ViewUniform, frag: vec2<f32>, offset: vec3<f32>) -> SurfacePoint {
    let g = cross(dpdx(offset), dpdy(offset));
    let ray = view_ray(v, frag);
    let origin = view_ray_origin(v, frag);
    let denom = dot(ray, g);
    let t = dot(offset - origin, g) / denom;
    let camera = v.camera_position.xyz;
    var p: SurfacePoint;
    // NaN (a degenerate derivative) fails every comparison and falls back.
    if abs(denom) > SURFACE_POINT_MIN_COSINE * length(ray) * length(g) && t > 0.0 && t < 3.4e38 {
        p.world_position = camera + origin + ray * t;
        p.view_depth = t;
    } else {
        p.world_position = camera + offset;
        p.view_depth = -(v.view_from_world * vec4<f32>(p.world_position, 1.0)).z;
    }
    return p;
}
