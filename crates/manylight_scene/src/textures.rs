//! Procedural sRGB textures for the default scene (tiles, bricks, stone), generated from a
//! fixed-seed integer hash so every run produces the same bytes.

use glam::Vec3;
use manylight_core::TextureData;

/// A 32-bit integer hash (lowbias32 by Chris Wellons) of a lattice point and a seed.
pub(crate) fn hash3(x: i32, y: i32, seed: u32) -> u32 {
    let mut h = (x as u32).wrapping_mul(0x8da6_b343)
        ^ (y as u32).wrapping_mul(0xd816_3841)
        ^ seed.wrapping_mul(0xcb1a_b31f);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    h
}

/// Hash mapped to [0, 1).
fn hash01(x: i32, y: i32, seed: u32) -> f32 {
    (hash3(x, y, seed) >> 8) as f32 / (1u32 << 24) as f32
}

/// Smooth value noise in [0, 1) with lattice period `period` (tiles seamlessly).
fn value_noise(x: f32, y: f32, period: i32, seed: u32) -> f32 {
    let (xi, yi) = (x.floor(), y.floor());
    let (fx, fy) = (x - xi, y - yi);
    let (sx, sy) = (fx * fx * (3.0 - 2.0 * fx), fy * fy * (3.0 - 2.0 * fy));
    let (x0, y0) = ((xi as i32).rem_euclid(period), (yi as i32).rem_euclid(period));
    let (x1, y1) = ((x0 + 1) % period, (y0 + 1) % period);
    let a = hash01(x0, y0, seed) + (hash01(x1, y0, seed) - hash01(x0, y0, seed)) * sx;
    let b = hash01(x0, y1, seed) + (hash01(x1, y1, seed) - hash01(x0, y1, seed)) * sx;
    a + (b - a) * sy
}

/// Four octaves of tiling value noise at texel (`x`, `y`) of a `size`-texel image.
fn fbm(x: u32, y: u32, size: u32, base_period: i32, seed: u32) -> f32 {
    let mut sum = 0.0;
    let mut amp = 0.5;
    let mut period = base_period;
    for octave in 0..4 {
        let scale = period as f32 / size as f32;
        sum += amp * value_noise(x as f32 * scale, y as f32 * scale, period, seed.wrapping_add(octave));
        amp *= 0.5;
        period *= 2;
    }
    sum / 0.9375
}

/// Builds an sRGB texture from a function returning linear-ish display colour in [0, 1].
fn generate(label: &str, size: u32, f: impl Fn(u32, u32) -> Vec3) -> TextureData {
    let mut rgba8 = Vec::with_capacity((size * size * 4) as usize);
    for y in 0..size {
        for x in 0..size {
            let c = f(x, y).clamp(Vec3::ZERO, Vec3::ONE) * 255.0 + 0.5;
            rgba8.extend_from_slice(&[c.x as u8, c.y as u8, c.z as u8, 255]);
        }
    }
    TextureData { label: label.to_owned(), width: size, height: size, rgba8, srgb: true }
}

/// Polished stone floor tiles: 4 × 4 tiles in two tones with thin grout and veining.
pub(crate) fn floor_tiles(size: u32) -> TextureData {
    let tile = size / 4;
    generate("default_scene/floor_tiles", size, |x, y| {
        let (tx, ty) = (x / tile, y / tile);
        let (lx, ly) = (x % tile, y % tile);
        let grout = lx < 2 || ly < 2;
        let base = if (tx + ty) % 2 == 0 { Vec3::new(0.78, 0.74, 0.66) } else { Vec3::new(0.45, 0.40, 0.36) };
        let n = fbm(x, y, size, 8, 11);
        let vein = (1.0 - (n * 12.0).sin().abs()).powi(8) * 0.15;
        let tint = 0.92 + 0.16 * hash01(tx as i32, ty as i32, 5);
        if grout { Vec3::splat(0.25) } else { base * tint * (0.9 + 0.2 * n) - Vec3::splat(vein) }
    })
}

/// Brick wall: staggered rows of bricks with per-brick tint and mortar joints.
pub(crate) fn bricks(size: u32) -> TextureData {
    let (bw, bh) = (size / 4, size / 8);
    generate("default_scene/bricks", size, |x, y| {
        let row = y / bh;
        let xs = x + if row % 2 == 1 { bw / 2 } else { 0 };
        let (col, lx, ly) = ((xs / bw) % 4, xs % bw, y % bh);
        let mortar = lx < 3 || ly < 3;
        let n = fbm(x, y, size, 16, 23);
        if mortar {
            return Vec3::splat(0.55 + 0.1 * n);
        }
        let h = hash01(col as i32, row as i32, 7);
        let base = Vec3::new(0.62, 0.38, 0.28).lerp(Vec3::new(0.72, 0.55, 0.40), h);
        base * (0.85 + 0.3 * n)
    })
}

/// Weathered sandstone: warm grey with fbm mottling.
pub(crate) fn stone(size: u32) -> TextureData {
    generate("default_scene/stone", size, |x, y| {
        let n = fbm(x, y, size, 4, 41);
        let m = fbm(x, y, size, 16, 43);
        Vec3::new(0.74, 0.68, 0.58) * (0.75 + 0.35 * n) + Vec3::splat((m - 0.5) * 0.08)
    })
}

/// Woven cloth: a fine grey weave meant to be tinted by the material colour.
pub(crate) fn cloth(size: u32) -> TextureData {
    generate("default_scene/cloth", size, |x, y| {
        let weave = if ((x / 2) + (y / 2)) % 2 == 0 { 0.9 } else { 0.75 };
        Vec3::splat(weave * (0.9 + 0.1 * fbm(x, y, size, 8, 59)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn textures_are_deterministic_and_well_formed() {
        for f in [floor_tiles, bricks, stone, cloth] {
            let a = f(128);
            assert_eq!(a.rgba8.len(), 128 * 128 * 4);
            assert!(a.srgb);
            assert_eq!(a, f(128));
        }
    }

    #[test]
    fn noise_is_in_range() {
        for i in 0..1000 {
            let v = fbm(i * 7 % 256, i * 13 % 256, 256, 8, 1);
            assert!((0.0..=1.0).contains(&v), "{v}");
        }
    }
}
