// The shadow pass: draws the instances near each casting light into the atlas tiles of its
// cube faces (Rust: `passes::shadow_maps`). One draw per mesh; each of its instances is a
// (scene instance, face) pair. The face's projection puts the face in x, y ∈ [-w, w]; the
// atlas transform then maps that square onto the face's tile. Each triangle is cut to the
// square by clip distances (`CLIP_DISTANCES`) or, on a device without them, its fragments
// outside the square are discarded, so nothing spills into a neighbouring tile.
//!if CLIP_DISTANCES
enable clip_distances;
//!endif
//!include common/mesh.wgsl

// Rust: `GpuShadowFace`.
struct GpuShadowFace {
    clip_from_world: mat4x4<f32>,
    // (sx, ox, sy, oy): atlas clip x = x·sx + w·ox, y = y·sy + w·oy
    atlas: vec4<f32>,
};

// Rust: `GpuShadowDraw`.
struct GpuShadowDraw {
    instance: u32,
    face: u32,
};

@group(0) @binding(0) var<storage, read> shadow_faces: array<GpuShadowFace>;
@group(0) @binding(1) var<storage, read> shadow_draws: array<GpuShadowDraw>;
@group(0) @binding(2) var<storage, read> instances: array<GpuInstance>;

struct ShadowVertex {
    @builtin(position) position: vec4<f32>,
//!if CLIP_DISTANCES
    @builtin(clip_distances) face_bounds: array<f32, 4>,
//!else
    // The face coordinates (x, y, w): the fragment is inside the face where |x|, |y| ≤ w.
    @location(0) face_position: vec3<f32>,
//!endif
};

@vertex
fn vs_main(@location(0) position: vec3<f32>, @builtin(instance_index) draw_index: u32) -> ShadowVertex {
    let draw = shadow_draws[draw_index];
    let face = shadow_faces[draw.face];
    let world = instances[draw.instance].world_from_local * vec4<f32>(position, 1.0);
    let c = face.clip_from_world * world;
    var out: ShadowVertex;
//!if CLIP_DISTANCES
    out.face_bounds = array<f32, 4>(c.w - c.x, c.w + c.x, c.w - c.y, c.w + c.y);
//!else
    out.face_position = c.xyw;
//!endif
    out.position = vec4<f32>(c.x * face.atlas.x + c.w * face.atlas.y, c.y * face.atlas.z + c.w * face.atlas.w, c.z, c.w);
    return out;
}

// Clears face `face_index`'s tile to the far depth (0: reverse depth) before it is drawn
// again while the atlas keeps other maps: two triangles over the face's square.
@vertex
fn vs_clear(@builtin(vertex_index) corner: u32, @builtin(instance_index) face_index: u32) -> @builtin(position) vec4<f32> {
    let corners = array<vec2<f32>, 6>(
        vec2<f32>(-1.0, -1.0), vec2<f32>(1.0, -1.0), vec2<f32>(-1.0, 1.0),
        vec2<f32>(-1.0, 1.0), vec2<f32>(1.0, -1.0), vec2<f32>(1.0, 1.0),
    );
    let c = corners[corner % 6u];
    let atlas = shadow_faces[face_index].atlas;
    return vec4<f32>(c.x * atlas.x + atlas.y, c.y * atlas.z + atlas.w, 0.0, 1.0);
}

//!if CLIP_DISTANCES
//!else
@fragment
fn fs_main(in: ShadowVertex) {
    let p = in.face_position;
    if abs(p.x) > p.z || abs(p.y) > p.z {
        discard;
    }
}
//!endif
