// The shadow test of the shading passes (`shadow_visibility`, common/shadows.wgsl) at given
// surface points, for measuring it against the exact visibility reference (Rust:
// `shadow_probe::probe_shadows`). Not part of a frame.
//!include common/shadows.wgsl

@group(1) @binding(0) var<storage, read> lights: array<GpuPointLight>;
@group(1) @binding(1) var<storage, read> probes: array<GpuShadowProbe>;
@group(1) @binding(2) var<storage, read_write> probed: array<f32>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if i >= arrayLength(&probes) {
        return;
    }
    let probe = probes[i];
    let k = probe.light;
    if k >= arrayLength(&lights) {
        probed[i] = 1.0;
        return;
    }
    probed[i] = shadow_visibility(k, probe.position, probe.normal);
}
