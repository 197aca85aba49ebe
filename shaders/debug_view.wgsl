// Debug views that replace tone mapping (Rust: crates/manylight_render/src/passes/debug_view.rs):
// - fs_clusters: per-pixel light count of the pixel's cluster as a heatmap (with a legend bar
//   along the bottom edge), the cluster x / y / z index as alternating colours, or overflow
//   (clusters whose list hit the cap in red, the others green by how full they are);
// - fs_depth: the linearised view distance (near white, far black; log scale so both near
//   and far detail show);
// - fs_surface: albedo, world-space normal (n * 0.5 + 0.5), metallic, roughness (PBR surfaces;
//   others black), emitted radiance (clamped to 1) or ambient occlusion, from the Full G-buffer;
// - fs_shadow_atlas: the shadow atlas fitted to the view (white near a light, grey at its range,
//   black where nothing was drawn);
// - fs_shadow_lod: the face edge the casting lights reaching each pixel got, as a heatmap.
//!include common/view.wgsl
//!include common/clusters.wgsl
//!include common/fullscreen.wgsl
//!include common/lights.wgsl
//!include common/shadow_types.wgsl

struct DebugParams {
    mode: u32,
    // light count shown as the hottest colour
    scale_max: u32,
    // far end of the depth view's scale: the far plane, or without one the cluster grid's far
    // (the farthest light's reach)
    depth_far: f32,
    _pad0: u32,
};

@group(0) @binding(0) var<uniform> view: ViewUniform;
@group(0) @binding(1) var depth: texture_depth_2d;
@group(0) @binding(2) var<uniform> cluster_params: ClusterParams;
@group(0) @binding(3) var<storage, read> cluster_ranges: array<vec2<u32>>;
@group(0) @binding(4) var<uniform> debug: DebugParams;
@group(0) @binding(5) var gbuffer_albedo: texture_2d<f32>;
@group(0) @binding(6) var gbuffer_normal: texture_2d<f32>;
@group(0) @binding(7) var gbuffer_emissive: texture_2d<f32>;
@group(0) @binding(8) var gbuffer_position: texture_2d<f32>;
@group(0) @binding(10) var<storage, read> debug_lights: array<GpuPointLight>;
@group(0) @binding(11) var<storage, read> debug_shadow_lights: array<GpuShadowLight>;
@group(0) @binding(12) var debug_shadow_atlas: texture_depth_2d;

const BACKGROUND = vec4<f32>(0.02, 0.02, 0.02, 1.0);

// Blue -> cyan -> green -> yellow -> red, t in [0, 1].
fn heat(t: f32) -> vec3<f32> {
    let x = clamp(t, 0.0, 1.0) * 4.0;
    let r = clamp(x - 2.0, 0.0, 1.0);
    let g = select(clamp(x, 0.0, 1.0), clamp(4.0 - x, 0.0, 1.0), x > 3.0);
    let b = clamp(2.0 - x, 0.0, 1.0);
    return vec3<f32>(r, g, b);
}

fn index_color(i: u32) -> vec3<f32> {
    let h = f32((i * 7u) % 12u) / 12.0;
    let k = vec3<f32>(0.0, 2.0 / 3.0, 1.0 / 3.0);
    return clamp(abs(fract(vec3<f32>(h) + k) * 6.0 - 3.0) - 1.0, vec3<f32>(0.0), vec3<f32>(1.0)) * select(0.55, 0.95, i % 2u == 0u);
}

// Lights cluster `cluster` shades from: its list's, or every light where its list did not fit.
fn list_length(cluster: u32) -> u32 {
    let n = cluster_ranges[cluster].y;
    return select(n, cluster_params.light_count, n == LIST_EVERY_LIGHT);
}

@fragment
fn fs_clusters(in: FullscreenOut) -> @location(0) vec4<f32> {
    let px = vec2<i32>(in.position.xy);
    let size = vec2<f32>(cluster_params.viewport.xy);
    // Legend: a bar of the heat scale along the bottom 4% with ticks every 1/8 of the scale.
    let legend_top = size.y * 0.96;
    if debug.mode == DEBUG_LIGHT_COUNT && in.position.y >= legend_top {
        let t = in.position.x / size.x;
        let tick = abs(fract(t * 8.0 + 0.5) - 0.5) * size.x / 8.0 < 1.0;
        return vec4<f32>(select(heat(t), vec3<f32>(1.0), tick), 1.0);
    }
    let z = textureLoad(depth, px, 0);
    if z <= 0.0 {
        return BACKGROUND; // reverse-Z: cleared to 0
    }
    let clip = vec4<f32>(in.uv.x * 2.0 - 1.0, 1.0 - in.uv.y * 2.0, z, 1.0);
    let world = view.world_from_clip * clip;
    let world_pos = world.xyz / world.w;
    let view_distance = -(view.view_from_world * vec4<f32>(world_pos, 1.0)).z;
    let cluster = cluster_index(cluster_params, in.position.xy, view_distance);
    let dims = cluster_params.dims;
    var color = vec3<f32>(0.0);
    if debug.mode == DEBUG_LIGHT_COUNT {
        let n = list_length(cluster);
        color = select(heat(f32(n) / f32(max(debug.scale_max, 1u))), vec3<f32>(0.0), n == 0u);
    } else if debug.mode == DEBUG_OVERFLOW {
        // The stored count is capped, so a cluster at the cap is one that overflowed (or was
        // exactly full); without a cap nothing overflows and the green shows the fill.
        let n = list_length(cluster);
        let capped = cluster_params.cap != CLUSTER_NO_CAP;
        let full = select(max(debug.scale_max, 1u), max(cluster_params.cap, 1u), capped);
        if capped && n >= cluster_params.cap {
            color = vec3<f32>(1.0, 0.05, 0.05);
        } else {
            color = vec3<f32>(0.0, 0.1 + 0.7 * clamp(f32(n) / f32(full), 0.0, 1.0), 0.05);
        }
    } else if debug.mode == DEBUG_SLICE_X {
        color = index_color(cluster % dims.x);
    } else if debug.mode == DEBUG_SLICE_Y {
        color = index_color((cluster / dims.x) % dims.y);
    } else {
        color = index_color(cluster / (dims.x * dims.y));
    }
    return vec4<f32>(color, 1.0);
}

@fragment
fn fs_depth(in: FullscreenOut) -> @location(0) vec4<f32> {
    let z = textureLoad(depth, vec2<i32>(in.position.xy), 0);
    if z <= 0.0 {
        return BACKGROUND;
    }
    let near = view.params.x;
    let far = debug.depth_far;
    let d = view_distance_of_depth(view, z);
    // Log scale in perspective; orthographic depth is linear, and so is its scale.
    var t = clamp(log(d / near) / log(far / near), 0.0, 1.0);
    if is_orthographic(view) {
        t = clamp((d - near) / (far - near), 0.0, 1.0);
    }
    return vec4<f32>(vec3<f32>(1.0 - t), 1.0);
}

@fragment
fn fs_surface(in: FullscreenOut) -> @location(0) vec4<f32> {
    let px = vec2<i32>(in.position.xy);
    if textureLoad(depth, px, 0) <= 0.0 {
        return BACKGROUND;
    }
    let albedo = textureLoad(gbuffer_albedo, px, 0);
    let normal = textureLoad(gbuffer_normal, px, 0);
    let emissive = textureLoad(gbuffer_emissive, px, 0);
    // The Full layout's material slots hold roughness (normal.w) and metallic (albedo.a) for PBR.
    let pbr = u32(textureLoad(gbuffer_position, px, 0).w + 0.5) == SHADING_PBR;
    var color = saturate(normal.xyz * 0.5 + 0.5);
    if debug.mode == DEBUG_ALBEDO {
        color = saturate(albedo.rgb);
    } else if debug.mode == DEBUG_METALLIC {
        color = vec3<f32>(select(0.0, saturate(albedo.a), pbr));
    } else if debug.mode == DEBUG_ROUGHNESS {
        color = vec3<f32>(select(0.0, saturate(normal.w), pbr));
    } else if debug.mode == DEBUG_EMISSIVE {
        color = saturate(emissive.rgb);
    } else if debug.mode == DEBUG_OCCLUSION {
        color = vec3<f32>(saturate(emissive.a));
    }
    return vec4<f32>(color, 1.0);
}

@fragment
fn fs_shadow_atlas(in: FullscreenOut) -> @location(0) vec4<f32> {
    // The square atlas, as large as the view allows, centred.
    let size = view.viewport.xy;
    let side = min(size.x, size.y);
    let local = (in.position.xy - 0.5 * (size - vec2<f32>(side))) / side;
    if any(local < vec2<f32>(0.0)) || any(local >= vec2<f32>(1.0)) {
        return BACKGROUND;
    }
    let dims = textureDimensions(debug_shadow_atlas);
    let texel = min(vec2<u32>(local * vec2<f32>(dims)), dims - vec2<u32>(1u));
    let d = textureLoad(debug_shadow_atlas, texel, 0);
    if d <= 0.0 {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0); // nothing drawn
    }
    // Reverse depth is about near / distance: five decades from the near plane (white) to the
    // range (grey).
    let t = saturate(-log2(d) / (5.0 * log2(10.0)));
    return vec4<f32>(vec3<f32>(1.0 - 0.8 * t), 1.0);
}

@fragment
fn fs_shadow_lod(in: FullscreenOut) -> @location(0) vec4<f32> {
    let px = vec2<i32>(in.position.xy);
    let z = textureLoad(depth, px, 0);
    if z <= 0.0 {
        return BACKGROUND;
    }
    let clip = vec4<f32>(in.uv.x * 2.0 - 1.0, 1.0 - in.uv.y * 2.0, z, 1.0);
    let world = view.world_from_clip * clip;
    let position = world.xyz / world.w;
    // Every light (a debug view: no lists), those with a map that reach the point.
    var sum = 0.0;
    var casting = 0u;
    for (var k = 0u; k < min(view.light_count, arrayLength(&debug_lights)); k++) {
        let light = debug_lights[k].position_radius;
        if attenuation(distance(light.xyz, position), light.w) <= 0.0 || k >= arrayLength(&debug_shadow_lights) {
            continue;
        }
        // Edge 0: the light has no map this frame (it does not cast, or was dropped: counted
        // in the frame's shadow report).
        let shadow = debug_shadow_lights[k];
        if shadow.tile.z == 0u {
            continue;
        }
        sum += log2(max(f32(shadow.tile.z), 1.0));
        casting++;
    }
    if casting == 0u {
        return vec4<f32>(0.12, 0.12, 0.12, 1.0);
    }
    // log2 16 = 4 (blue) to log2 512 = 9 (red).
    return vec4<f32>(heat((sum / f32(casting) - 4.0) / 5.0), 1.0);
}
