//! The page's camera: drag with the mouse to look around, W/A/S/D or the arrow keys to move,
//! Q/E to go down and up, Shift to move faster. The page gathers its input from the DOM
//! (`page.rs`); this module turns one update's input into a camera move, with no browser in it.

use glam::EulerRot;
use manylight::prelude::*;

/// Metres a second the camera moves (times [`FAST`] with Shift).
pub const SPEED: f32 = 4.0;
/// Speed factor while Shift is held.
pub const FAST: f32 = 4.0;
/// Radians the camera turns per pixel the mouse is dragged.
pub const RADIANS_PER_PIXEL: f32 = 0.004;
/// The steepest the camera looks up or down, short of straight (where yaw is undefined).
const MAX_PITCH: f32 = 1.5;

/// What the user did since the last update.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FlyInput {
    /// Held direction keys, in the camera's frame: x right, y up, z backwards (each -1, 0 or 1).
    pub direction: Vec3,
    /// Shift is held.
    pub fast: bool,
    /// Pixels dragged with a mouse button held (x right, y down).
    pub drag: Vec2,
}

impl FlyInput {
    /// The direction the held keys name (`KeyboardEvent.code` values).
    pub fn direction_of<'a>(codes: impl IntoIterator<Item = &'a str>) -> Vec3 {
        let mut d = Vec3::ZERO;
        for code in codes {
            match code {
                "KeyW" | "ArrowUp" => d.z -= 1.0,
                "KeyS" | "ArrowDown" => d.z += 1.0,
                "KeyA" | "ArrowLeft" => d.x -= 1.0,
                "KeyD" | "ArrowRight" => d.x += 1.0,
                "KeyE" => d.y += 1.0,
                "KeyQ" => d.y -= 1.0,
                _ => {}
            }
        }
        d.clamp(Vec3::NEG_ONE, Vec3::ONE)
    }
}

/// Moves and turns `transform` by `input` over `seconds`: yaw about the world's up axis, pitch
/// about the camera's right axis (kept short of straight up or down), then a move along the
/// camera's axes, horizontal keys in the camera's heading.
pub fn fly(transform: &mut Transform, input: &FlyInput, seconds: f32) {
    let (yaw, pitch, _) = transform.rotation.to_euler(EulerRot::YXZ);
    let yaw = yaw - input.drag.x * RADIANS_PER_PIXEL;
    let pitch = (pitch - input.drag.y * RADIANS_PER_PIXEL).clamp(-MAX_PITCH, MAX_PITCH);
    transform.rotation = Quat::from_euler(EulerRot::YXZ, yaw, pitch, 0.0);
    let step = input.direction.normalize_or_zero() * SPEED * if input.fast { FAST } else { 1.0 } * seconds;
    if step != Vec3::ZERO && step.is_finite() {
        let heading = Quat::from_rotation_y(yaw);
        transform.translation += heading * Vec3::new(step.x, 0.0, step.z) + Vec3::Y * step.y;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_name_directions() {
        assert_eq!(FlyInput::direction_of(["KeyW", "KeyD"]), Vec3::new(1.0, 0.0, -1.0));
        assert_eq!(FlyInput::direction_of(["KeyW", "ArrowUp"]), Vec3::new(0.0, 0.0, -1.0));
        assert_eq!(FlyInput::direction_of(["KeyW", "KeyS", "KeyX"]), Vec3::ZERO);
        assert_eq!(FlyInput::direction_of(["KeyE"]), Vec3::Y);
    }

    #[test]
    fn forward_follows_the_heading_and_stays_level() {
        let mut t = Transform::from_rotation(Quat::from_euler(EulerRot::YXZ, 0.5, -0.3, 0.0));
        let input = FlyInput { direction: Vec3::NEG_Z, ..FlyInput::default() };
        fly(&mut t, &input, 1.0);
        let expected = Quat::from_rotation_y(0.5) * Vec3::NEG_Z * SPEED;
        assert!(t.translation.abs_diff_eq(expected, 1e-5), "{}", t.translation);
        let fast = FlyInput { fast: true, ..input };
        let mut t2 = Transform::IDENTITY;
        fly(&mut t2, &fast, 0.5);
        assert!((t2.translation.length() - SPEED * FAST * 0.5).abs() < 1e-4);
    }

    #[test]
    fn dragging_turns_and_pitch_stops_short_of_vertical() {
        let mut t = Transform::IDENTITY;
        fly(&mut t, &FlyInput { drag: Vec2::new(100.0, 0.0), ..FlyInput::default() }, 0.016);
        let (yaw, _, _) = t.rotation.to_euler(EulerRot::YXZ);
        assert!((yaw + 100.0 * RADIANS_PER_PIXEL).abs() < 1e-5);
        fly(&mut t, &FlyInput { drag: Vec2::new(0.0, -1e6), ..FlyInput::default() }, 0.016);
        let (_, pitch, roll) = t.rotation.to_euler(EulerRot::YXZ);
        assert!((pitch - MAX_PITCH).abs() < 1e-4 && roll.abs() < 1e-5);
        assert_eq!(t.translation, Vec3::ZERO);
    }
}
