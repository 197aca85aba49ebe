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
// Every layout stores the shading position of `surface_point` (common/surface.wgsl), not the
// rasteriser's interpolation or depth, which drift on triangles much larger than their
// distance from the camera.
//!include common/mesh_pass.wgsl
//!include common/gbuffer_codec.wgsl

struct FullOut {
    @location(0) position: vec4<f32>,
    @location(1) normal: vec4<f32>,
    @location(2) albedo: vec4<f32>,
};

fn surface_of(in: SurfaceVertexOut, front_facing: bool) -> SurfaceParams {
    let albedo = surface_albedo(material, base_color_texture, base_color_sampler, in.uv);
    let metal_rough = surface_metal_rough(material, metallic_roughness_texture, base_color_sampler, in.uv);
    return surface_params(material, view.shading_model, albedo.rgb, metal_rough, in.world_normal, front_facing);
}

@fragment
fn fs_full(in: SurfaceVertexOut, @builtin(front_facing) front_facing: bool) -> FullOut {
    let p = surface_point(view, in.clip_position.xy, in.camera_offset);
    let s = surface_of(in, front_facing);
    var out: FullOut;
    out.position = vec4<f32>(p.world_position, f32(s.model));
    let slots = material_slots(s);
    out.normal = vec4<f32>(s.normal, slots.x);
    out.albedo = vec4<f32>(s.albedo, saturate(slots.y));
    return out;
}

struct PackedOut {
    @location(0) albedo: vec4<f32>,
    @location(1) position: vec4<f32>,
};

@fragment
fn fs_packed(in: SurfaceVertexOut, @builtin(front_facing) front_facing: bool) -> PackedOut {
    let p = surface_point(view, in.clip_position.xy, in.camera_offset);
    let s = surface_of(in, front_facing);
    let n = gbuffer_encode_components(s.normal, view.view_from_world);
    var out: PackedOut;
    out.albedo = vec4<f32>(gbuffer_pack_albedo_params(s), n.x);
    out.position = vec4<f32>(p.world_position, n.y);
    return out;
}

@fragment
fn fs_compact(in: SurfaceVertexOut, @builtin(front_facing) front_facing: bool) -> @location(0) vec4<u32> {
    let p = surface_point(view, in.clip_position.xy, in.camera_offset);
    let s = surface_of(in, front_facing);
    let clip = view.clip_from_world * vec4<f32>(p.world_position, 1.0);
    return vec4<u32>(
        gbuffer_pack_albedo_model(s.albedo, s.model),
        gbuffer_encode_word(s.normal),
        pack2x16float(material_slots(s)),
        bitcast<u32>(clip.z / clip.w),
    );
}
