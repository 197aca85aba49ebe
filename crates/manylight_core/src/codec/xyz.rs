//! The naive view-space codec: keep `x, y`, rebuild `z = sqrt(max(0, 1 - x² - y²))`.
//!
//! It assumes view-space normals face the camera (`z ≥ 0`). A normal with `z < 0` (a
//! back-facing or bent normal, common with normal maps and at silhouettes) decodes mirrored
//! to `+|z|`: the error is `2·asin(|z|)`, 180° at `-Z`. Near the silhouette (`z → 0`) the
//! rebuilt `z` also suffers cancellation in `1 - x² - y²`: its f32 rounding error of a few
//! `2^-24` becomes a `z` error of its square root (measured worst 0.033° on `z ≥ 0`), so this
//! codec is not exact even with two f32.

use super::{non_finite, sanitize_normal};
use glam::Vec3;

/// `(x, y)` of `n` (any vector, sanitised first). The G-buffer chooses the storage precision;
/// [`crate::codec::encode`] keeps the f32 bits. WGSL `xyz_encode`.
pub fn encode_xy(n: Vec3) -> [f32; 2] {
    let n = sanitize_normal(n);
    [n.x, n.y]
}

/// `(x, y, +sqrt(max(0, 1 - x² - y²)))`, normalised. Any input: NaN or infinite components
/// give `+Z`; `x² + y² > 1` gives a vector in the `z = 0` plane. WGSL `xyz_decode`.
pub fn decode_xy(e: [f32; 2]) -> Vec3 {
    let [x, y] = e;
    if non_finite(x) || non_finite(y) {
        return Vec3::Z;
    }
    let z = (1.0 - x * x - y * y).max(0.0).sqrt();
    sanitize_normal(Vec3::new(x, y, z))
}
