// G-buffer pass of the deferred pipelines: writes the surface at each pixel, in one of three
// layouts (Rust: `GBufferLayout`); the normal codec of Packed and Compact is the override
// constant NORMAL_CODEC (common/gbuffer_codec.wgsl):
// - Full (3 targets): position rgba32f (xyz, w = shading model), normal rgba16f (xyz, w =
//   shininess or roughness), albedo rgba16f (rgb, a = specular or metallic);
// - Packed (2 x rgba32f): (albedo.rgb + material parameters in the integer parts, n.a) and
//   (position.xyz, n.b);
// - Compact (1 x rgba32uint): x = albedo rgb8 (sRGB-encoded, so dark colours keep their
//   precision) with the shading model in the top byte, y = the normal codec's word,
//   z = the two material parameters as f16 (`material_slots`: shininess | specular, or
//   roughness | metallic for PBR), w = the reverse-Z depth of the shading position
//   (f32 bits); the lighting pass rebuilds the position from that depth.
// Every layout adds an rgba16f target: the emitted radiance plus, with ENVIRONMENT, the light
// of the view's environment (rgb, clamped to f16's largest value; the environment is summed
// here, as forward passes sum it per fragment, so the G-buffer stores no more for it) and the
// ambient occlusion (a).
// Every layout stores the shading position of `surface_point` (common/surface.wgsl), not the
// rasteriser's interpolation or depth, which drift on triangles much larger than their
// distance from the camera.
//!include common/mesh_pass.wgsl
//!include common/gbuffer_codec.wgsl
//!include common/environment.wgsl

// The fragment stage writes the layout the shader is composed for (the define GBUFFER_FULL,
// GBUFFER_PACKED or GBUFFER_COMPACT): one `GBufferOut` and one `fs_main`.

// The emissive target's texel at shading point `p`: emitted radiance with the environment's
// light, and occlusion.
fn emissive_texel(m: MaterialSample, p: SurfacePoint) -> vec4<f32> {
    let view_dir = direction_to_eye(view, p.world_position);
    let radiance = m.emissive + environment_light(m.params, view_dir, m.occlusion);
    return vec4<f32>(min(radiance, vec3<f32>(65504.0)), m.occlusion);
}

//!if GBUFFER_FULL
struct GBufferOut {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) albedo: vec4<f32>,
    @location(3) emissive: vec4<f32>,
};

@fragment
fn fs_main(in: SurfaceVertexOut, @builtin(front_facing) front_facing: bool) -> GBufferOut {
    let p = surface_point(view, in.clip_position.xy, in.camera_offset);
    let m = sample_material(in, front_facing);
    alpha_test(m.base_color);
    let s = m.params;
    var out: GBufferOut;
    out.position = vec4<f32>(p.world_position, f32(s.model));
    let slots = material_slots(s);
    out.normal = vec4<f32>(s.normal, slots.x);
    out.albedo = vec4<f32>(s.albedo, saturate(slots.y));
    out.emissive = emissive_texel(m, p);
    return out;
}
//!endif

//!if GBUFFER_PACKED
struct GBufferOut {
    @location(0) albedo: vec4<f32>,
    @location(1) position: vec4<f32>,
    @location(2) emissive: vec4<f32>,
};

@fragment
fn fs_main(in: SurfaceVertexOut, @builtin(front_facing) front_facing: bool) -> GBufferOut {
    let p = surface_point(view, in.clip_position.xy, in.camera_offset);
    let m = sample_material(in, front_facing);
    alpha_test(m.base_color);
    let s = m.params;
    let n = gbuffer_encode_components(s.normal, view.view_from_world);
    var out: GBufferOut;
    out.albedo = vec4<f32>(gbuffer_pack_albedo_params(s), n.x);
    out.position = vec4<f32>(p.world_position, n.y);
    out.emissive = emissive_texel(m, p);
    return out;
}
//!endif

//!if GBUFFER_COMPACT
struct GBufferOut {
    @location(0) surface: vec4<u32>,
    @location(1) emissive: vec4<f32>,
};

@fragment
fn fs_main(in: SurfaceVertexOut, @builtin(front_facing) front_facing: bool) -> GBufferOut {
    let p = surface_point(view, in.clip_position.xy, in.camera_offset);
    let m = sample_material(in, front_facing);
    alpha_test(m.base_color);
    let s = m.params;
    let clip = view.clip_from_world * vec4<f32>(p.world_position, 1.0);
    var out: GBufferOut;
    out.surface = vec4<u32>(
        gbuffer_pack_albedo_model(s.albedo, s.model),
        gbuffer_encode_word(s.normal),
        pack2x16float(material_slots(s)),
        bitcast<u32>(clip.z / clip.w),
    );
    out.emissive = emissive_texel(m, p);
    return out;
}
//!endif
