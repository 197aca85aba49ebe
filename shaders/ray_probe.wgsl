// Shadow rays through the scene's two-level BVH, read back (Rust: `ray_geometry`); not part of
// a frame:
// - main: given segments (`ray_trace`, common/ray_bvh.wgsl): how each ended and the steps it
//   took, for testing the traversal against its CPU twin and measuring rays per second;
// - probe_lights: the shading passes' own ray test (`ray_light_visibility`,
//   common/ray_shadows.wgsl) at light-point pairs, for measuring it against the visibility
//   oracle (`render --shadow-oracle`).
//!include common/ray_shadows.wgsl
//!include common/lights.wgsl
//!include common/shadow_types.wgsl

// Rust: `GpuRaySegment`.
struct GpuRaySegment {
    origin: vec3<f32>,
    t_max: f32,
    direction: vec3<f32>,
    pad: f32,
};

// Rust: `GpuRayProbeParams`.
struct GpuRayProbeParams {
    // As the view uniform's `rays`: the instance level's root (RAY_NO_NODE: nothing placed),
    // where the instances and the casting lights' bits start in `ray_prims`.
    geometry: vec4<u32>,
    // Segments or pairs to trace.
    count: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
};

@group(1) @binding(0) var<uniform> params: GpuRayProbeParams;
@group(1) @binding(1) var<storage, read> segments: array<GpuRaySegment>;
@group(1) @binding(2) var<storage, read_write> traced: array<vec2<u32>>;
@group(1) @binding(3) var<storage, read> lights: array<GpuPointLight>;
@group(1) @binding(4) var<storage, read> probes: array<GpuShadowProbe>;
@group(1) @binding(5) var<storage, read_write> probed: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= params.count {
        return;
    }
    let s = segments[i];
    let result = ray_trace(params.geometry, s.origin, s.direction, s.t_max);
    traced[i] = vec2<u32>(result.outcome, result.steps);
}

@compute @workgroup_size(64)
fn probe_lights(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= params.count {
        return;
    }
    let probe = probes[i];
    let k = probe.light;
    if k >= arrayLength(&lights) {
        probed[i] = 1.0;
        return;
    }
    probed[i] = ray_light_visibility(params.geometry, k, lights[k].position_radius.xyz, probe.position, probe.normal);
}
