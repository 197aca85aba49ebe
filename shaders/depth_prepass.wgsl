// Depth pre-pass: depth only, so the lighting pass shades each pixel once. Opaque surfaces run
// no fragment stage; alpha-masked ones (`fs_mask`) discard where the base colour's alpha is below
// the material's cutoff, as the shading passes do.
//!include common/mesh_pass.wgsl

@fragment
fn fs_mask(in: SurfaceVertexOut) {
    let uv = texture_uv(material, TEXTURE_SLOT_BASE_COLOR, in.uv);
    alpha_test(surface_albedo(material, base_color_texture, base_color_sampler, uv));
}
