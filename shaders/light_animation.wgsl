// Light animation: one invocation per light of the light buffer writes an animated light's
// position and colour at the frame's time, before any view reads the lights. The WGSL twin of
// `AnimatedLight::position_from` and `color_from` (crates/manylight_core/src/animation.rs): the
// CPU takes each light's five angles once, at an epoch, in f64 (`lights::gpu_light_motion`), and
// this pass adds `speed × (t − epoch)`, which the renderer keeps small
// (`animation::EPOCH_SPAN_SECS`), so f32 keeps its precision for any time. A light whose motion
// is not `animated` keeps what the CPU uploaded.
//!include common/lights.wgsl

struct GpuLightMotion {
    center: vec3<f32>,
    orbit_radius: f32,
    color: vec3<f32>,
    bob_amplitude: f32,
    // Radians per second of the orbit, the bob, the hue drift and the first flicker wave.
    speeds: vec4<f32>,
    // Those four angles at `epoch`.
    angles: vec4<f32>,
    flicker2_speed: f32,
    flicker2_angle: f32,
    epoch: f32,
    intensity: f32,
    animated: u32,
};

struct LightAnimationParams {
    elapsed_secs: f32,
    light_count: u32,
    pad: vec2<u32>,
};

@group(0) @binding(0) var<storage, read> params: LightAnimationParams;
@group(0) @binding(1) var<storage, read> motions: array<GpuLightMotion>;
@group(0) @binding(2) var<storage, read_write> lights: array<GpuPointLight>;

override WORKGROUP_SIZE: u32 = 64u;

const ANIMATION_TAU: f32 = 6.2831855f;

// Finite (neither NaN nor infinite).
fn finite1(x: f32) -> bool {
    return abs(x) <= 3.40282346e38f;
}

fn finite3(v: vec3<f32>) -> bool {
    return finite1(v.x) && finite1(v.y) && finite1(v.z);
}

// The angles at `dt` seconds past the epoch, wrapped to [0, 2π); 0 where not finite (as the
// CPU's `AngleRate::at`).
fn angles_after(angles: vec4<f32>, speeds: vec4<f32>, dt: f32) -> vec4<f32> {
    let a = angles + speeds * dt;
    let wrapped = a - floor(a / ANIMATION_TAU) * ANIMATION_TAU;
    let ok = vec4<bool>(finite1(wrapped.x), finite1(wrapped.y), finite1(wrapped.z), finite1(wrapped.w));
    return select(vec4<f32>(0.0), wrapped, ok);
}

fn angle_after(angle: f32, speed: f32, dt: f32) -> f32 {
    return angles_after(vec4<f32>(angle), vec4<f32>(speed), dt).x;
}

// `AnimatedLight::position_from`.
fn position_from(m: GpuLightMotion, orbit: f32, bob: f32) -> vec3<f32> {
    let p = m.center + vec3<f32>(m.orbit_radius * cos(orbit), m.bob_amplitude * sin(bob), m.orbit_radius * sin(orbit));
    if finite3(p) {
        return p;
    }
    if finite3(m.center) {
        return m.center;
    }
    return vec3<f32>(0.0);
}

// A hue shift: `color` turned by `theta` about the grey axis, clamped to >= 0.
fn hue_rotate(c: vec3<f32>, theta: f32) -> vec3<f32> {
    let k = normalize(vec3<f32>(1.0));
    let s = sin(theta);
    let co = cos(theta);
    return max(c * co + cross(k, c) * s + k * dot(k, c) * (1.0 - co), vec3<f32>(0.0));
}

// `AnimatedLight::color_from`.
fn color_from(m: GpuLightMotion, drift_angle: f32, flicker: f32, flicker2: f32) -> vec3<f32> {
    let drift = sin(drift_angle) * 0.35;
    let scale = 0.85 + 0.15 * (0.6 * sin(flicker) + 0.4 * sin(flicker2));
    let c = hue_rotate(max(m.color, vec3<f32>(0.0)), drift) * scale;
    return select(vec3<f32>(0.0), c, finite3(c));
}

@compute @workgroup_size(WORKGROUP_SIZE)
fn main(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    // Rows of workgroups past the device's limit per dimension (`cluster_build::dispatch_size`).
    let l = id.x + id.y * groups.x * WORKGROUP_SIZE;
    if l >= params.light_count {
        return;
    }
    let m = motions[l];
    if m.animated == 0u {
        return;
    }
    let dt = params.elapsed_secs - m.epoch;
    let a = angles_after(m.angles, m.speeds, dt);
    let flicker2 = angle_after(m.flicker2_angle, m.flicker2_speed, dt);
    lights[l].position_radius = vec4<f32>(position_from(m, a.x, a.y), lights[l].position_radius.w);
    lights[l].color = vec4<f32>(color_from(m, a.z, a.w, flicker2) * m.intensity, lights[l].color.a);
}
