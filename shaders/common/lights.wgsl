// Point lights (Rust: `GpuPointLight`) and the attenuation shared with
// crates/manylight_core/src/attenuation.rs: saturate(1 - (d/r)^4)^2 / (d^2 + 1), exactly 0 at r.
struct GpuPointLight {
    // xyz: world position, w: radius
    position_radius: vec4<f32>,
    // rgb: colour * intensity (linear), a: unused
    color: vec4<f32>,
};

fn attenuation(distance: f32, radius: f32) -> f32 {
    if !(radius > 0.0) || distance >= radius {
        return 0.0;
    }
    let ratio = distance / radius;
    let ratio2 = ratio * ratio;
    let window = saturate(1.0 - ratio2 * ratio2);
    return window * window / (distance * distance + 1.0);
}
