// Point and spot lights (Rust: `GpuPointLight`) and the attenuation shared with
// crates/manylight_core/src/attenuation.rs: saturate(1 - (d/r)^4)^2 / max(d^2, LIGHT_MIN_DISTANCE^2),
// exactly 0 at r; times a light's intensity (candela) it is the illuminance (lux) facing it.
struct GpuPointLight {
    // xyz: world position, w: radius
    position_radius: vec4<f32>,
    // rgb: colour * intensity (linear, candela), a: the spot falloff's offset (1 for a point light)
    color: vec4<f32>,
    // xyz: a spot light's unit direction (0 for a point light), w: the falloff's scale (0)
    spot: vec4<f32>,
};

// A spot light's angular falloff (crates/manylight_core/src/spot.rs): saturate(cos * scale +
// offset)^2; 1 for a point light's (scale 0, offset 1).
fn spot_attenuation(cos_angle: f32, scale: f32, offset: f32) -> f32 {
    let t = saturate(cos_angle * scale + offset);
    return t * t;
}

// The sphere (xyz: centre, w: radius) holding every point `light` reaches (Rust:
// `lights::bounding_sphere`): its range's sphere, or for a spot light the smaller sphere around
// its cone. The cone's outer cosine is where the falloff reaches 0 (-offset / scale); the
// radius is widened by one part in 10⁴ for the rounding of that quotient.
fn light_bounds(light: GpuPointLight) -> vec4<f32> {
    let range = light.position_radius.w;
    let scale = light.spot.w;
    if !(scale > 0.0) {
        return light.position_radius;
    }
    let cos_outer = clamp(-light.color.a / scale, 0.0, 1.0);
    var along = range * cos_outer;
    var radius = range * sqrt(max(1.0 - cos_outer * cos_outer, 0.0));
    if cos_outer >= 0.70710678 {
        along = range / (2.0 * cos_outer);
        radius = along;
    }
    if radius * (1.0 + 1e-4) >= range {
        return light.position_radius;
    }
    return vec4<f32>(light.position_radius.xyz + light.spot.xyz * along, radius * (1.0 + 1e-4));
}

fn attenuation(distance: f32, radius: f32) -> f32 {
    if !(radius > 0.0) || distance >= radius {
        return 0.0;
    }
    let ratio = distance / radius;
    let ratio2 = ratio * ratio;
    let window = saturate(1.0 - ratio2 * ratio2);
    return window * window / max(distance * distance, LIGHT_MIN_DISTANCE * LIGHT_MIN_DISTANCE);
}
