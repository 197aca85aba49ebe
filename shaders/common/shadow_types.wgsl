// The shadow tables' structs (Rust: `GpuShadowLight`, `GpuCascade`, `GpuDirectionalShadow`)
// and the probes' pairs (`GpuShadowProbe`), apart from their bindings: the shading passes bind them in group 0 (common/shadows.wgsl),
// the debug views in their own group.

// Rust: `GpuShadowLight`.
struct GpuShadowLight {
    // xy: top-left atlas texel of the light's block of face tiles (SHADOW_TILE_COLUMNS per
    // row); z: a face tile's edge in texels, 0 when the light has no shadow map; w: the filter
    // (0: hardware 2×2, 1: Gaussian 3×3)
    tile: vec4<u32>,
    // x: near plane, y: far plane (the light's range), z: depth bias (world units),
    // w: normal bias (face texels)
    params: vec4<f32>,
    // xyz: where the light was when its map was drawn (the test's origin; an earlier frame's
    // position for a map kept past the frame's redraw budget), w: 0
    origin: vec4<f32>,
};

// Rust: `GpuCascade`.
struct GpuCascade {
    // x, y ∈ [-1, 1] across the cascade's square, z ∈ [0, 1] through its depth range
    clip_from_world: mat4x4<f32>,
    // xy: top-left atlas texel of the tile, z: its edge in texels, w: the filter (as above)
    tile: vec4<u32>,
    // x: far bound (view distance), y: a texel's width (world), z: depth range (world), w: 0
    params: vec4<f32>,
};

// Rust: `GpuDirectionalShadow`.
struct GpuDirectionalShadow {
    cascades: array<GpuCascade, MAX_CASCADES>,
    // x: cascades in use (0: no shadow)
    count: vec4<u32>,
    // x: depth bias (world units), y: normal bias (texels of the cascade)
    bias: vec4<f32>,
};

// One light-point pair whose shadow test a probe reads back (Rust: `GpuShadowProbe`;
// shadow_probe.wgsl for the maps, ray_probe.wgsl for the rays).
struct GpuShadowProbe {
    // The surface point (world).
    position: vec3<f32>,
    // The light's index in the light buffer.
    light: u32,
    // The surface's normal (any length).
    normal: vec3<f32>,
    pad: f32,
};
