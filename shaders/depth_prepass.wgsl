// Depth pre-pass: depth only, so the lighting pass shades each pixel once. Opaque surfaces run
// no fragment stage; alpha-masked ones (`fs_mask`) discard where the base colour's alpha is below
// the material's cutoff, as the shading passes do. With per-cluster depth bounds or refined
// light lists it also writes the view distance clustered forward shades each pixel at
// (`fs_distance`, `fs_mask_distance`, r32float), which cluster_depth.wgsl and light_refine.wgsl
// read.
//!include common/mesh_pass.wgsl

@fragment
fn fs_mask(in: SurfaceVertexOut) {
    alpha_test(surface_albedo(material, base_color_texel(in)));
}

@fragment
fn fs_distance(in: SurfaceVertexOut) -> @location(0) f32 {
    return surface_point(view, in.clip_position.xy, in.camera_offset).view_depth;
}

@fragment
fn fs_mask_distance(in: SurfaceVertexOut) -> @location(0) f32 {
    let p = surface_point(view, in.clip_position.xy, in.camera_offset);
    alpha_test(surface_albedo(material, base_color_texel(in)));
    return p.view_depth;
}
