//! How many lights may be created: checked before anything is allocated.
//!
//! A light count comes from a user (`--lights`, `spawn_light_rig`, a glTF file). It is checked,
//! in this order, against [`MAX_LIGHTS`] (what the renderer can index), the device's light
//! buffer limit where one is known ([`LightLimit`]) and the memory the lights would take, so a
//! count of 4 294 967 295 is refused at once instead of aborting on a 240 GB allocation.

use thiserror::Error;

/// Most lights the renderer can index: light indices and counts are 32-bit on the GPU.
pub const MAX_LIGHTS: usize = u32::MAX as usize;

/// Main-memory bytes one light of an app takes, an upper estimate: its ECS entity and
/// components (`Transform`, `GlobalTransform`, the light, its animation, visibility), the
/// extracted copy (and its slot) and the packed GPU copy. The light rig's
/// 10 000 000 lights reached 2.9 GB while spawning, about 290 bytes a light.
pub const APP_BYTES_PER_LIGHT: u64 = 512;

/// The largest light count a consumer of lights accepts, and where that limit comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LightLimit {
    /// Most lights.
    pub max_lights: usize,
    /// What sets it, for messages: `MAX_LIGHTS` or the device limit's name.
    pub name: &'static str,
}

impl LightLimit {
    /// The renderer's own limit, [`MAX_LIGHTS`], for callers that know no device.
    pub const INDICES: LightLimit =
        LightLimit { max_lights: MAX_LIGHTS, name: "MAX_LIGHTS (32-bit light indices)" };

    /// The limit of a light buffer of at most `max_buffer_bytes` bytes (a device's largest
    /// storage binding) holding `bytes_per_light` bytes a light, never above [`MAX_LIGHTS`].
    pub fn from_buffer(max_buffer_bytes: u64, bytes_per_light: u64, name: &'static str) -> LightLimit {
        let max_lights = (max_buffer_bytes / bytes_per_light.max(1)).min(MAX_LIGHTS as u64) as usize;
        LightLimit { max_lights, name }
    }
}

/// A light count refused before anything was allocated.
#[derive(Clone, Debug, Error, PartialEq, Eq)]
pub enum LightCountError {
    /// More lights than a limit allows.
    #[error("{count} lights are more than the {limit} that {name} allows")]
    TooMany {
        /// Lights asked for.
        count: usize,
        /// The limit.
        limit: usize,
        /// What sets the limit.
        name: &'static str,
    },
    /// More memory than the system has available.
    #[error(
        "{count} lights need about {needed} bytes of memory ({per_light} bytes a light), more than the {available} bytes available"
    )]
    OutOfMemory {
        /// Lights asked for.
        count: usize,
        /// Bytes they would take.
        needed: u64,
        /// Bytes a light takes.
        per_light: u64,
        /// Bytes the system has available.
        available: u64,
    },
}

/// Checks that `count` lights fit `limit` and, at `bytes_per_light` bytes each, the memory
/// available now ([`available_memory`]; not checked where the system does not say).
pub fn check_light_count(
    count: usize,
    limit: LightLimit,
    bytes_per_light: u64,
) -> Result<(), LightCountError> {
    check_light_count_within(count, limit, bytes_per_light, available_memory())
}

/// The check for lights an app spawns before any device is known: [`LightLimit::INDICES`] and
/// the memory available at [`APP_BYTES_PER_LIGHT`] a light.
pub fn check_app_lights(count: usize) -> Result<(), LightCountError> {
    check_light_count(count, LightLimit::INDICES, APP_BYTES_PER_LIGHT)
}

/// [`check_light_count`] against `available` bytes of memory (`None`: unknown, not checked).
// Where `usize` is 32 bits (WebAssembly) every count is within `MAX_LIGHTS` and the `min` does
// nothing; on 64-bit targets it caps the limit.
#[cfg_attr(target_pointer_width = "32", allow(clippy::unnecessary_min_or_max))]
pub fn check_light_count_within(
    count: usize,
    limit: LightLimit,
    bytes_per_light: u64,
    available: Option<u64>,
) -> Result<(), LightCountError> {
    let limit = LightLimit { max_lights: limit.max_lights.min(MAX_LIGHTS), ..limit };
    if count > limit.max_lights {
        return Err(LightCountError::TooMany { count, limit: limit.max_lights, name: limit.name });
    }
    let needed = (count as u64).saturating_mul(bytes_per_light);
    match available {
        Some(available) if needed > available => {
            Err(LightCountError::OutOfMemory { count, needed, per_light: bytes_per_light, available })
        }
        _ => Ok(()),
    }
}

/// Bytes of memory the system can give a process now without swapping (Linux: `MemAvailable`
/// in `/proc/meminfo`); `None` where it cannot be read.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    parse_mem_available(&text)
}

/// The `MemAvailable` line of a `/proc/meminfo` text, in bytes.
fn parse_mem_available(meminfo: &str) -> Option<u64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let mut words = line.split_whitespace().skip(1);
    let value: u64 = words.next()?.parse().ok()?;
    match words.next() {
        Some("kB") => value.checked_mul(1024),
        None => Some(value),
        Some(_) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_past_a_limit_are_refused_naming_it() {
        let device = LightLimit::from_buffer(128 << 20, 48, "max_storage_buffer_binding_size");
        assert_eq!(device.max_lights, 2_796_202);
        assert_eq!(check_light_count_within(2_796_202, device, 48, None), Ok(()));
        let e = check_light_count_within(2_796_203, device, 48, None).unwrap_err();
        assert!(e.to_string().contains("max_storage_buffer_binding_size"), "{e}");
        for count in [u32::MAX as usize + 1, usize::MAX] {
            let e = check_light_count_within(count, LightLimit::INDICES, 48, None).unwrap_err();
            assert!(matches!(e, LightCountError::TooMany { limit: MAX_LIGHTS, .. }), "{e}");
        }
        // A device limit above the renderer's own is capped by it.
        let huge = LightLimit::from_buffer(u64::MAX, 1, "test");
        assert_eq!(huge.max_lights, MAX_LIGHTS);
    }

    #[test]
    fn counts_past_the_available_memory_are_refused() {
        let e = check_light_count_within(
            u32::MAX as usize,
            LightLimit::INDICES,
            APP_BYTES_PER_LIGHT,
            Some(24 << 30),
        )
        .unwrap_err();
        assert!(matches!(e, LightCountError::OutOfMemory { .. }), "{e}");
        assert!(e.to_string().contains("bytes available"), "{e}");
        assert_eq!(
            check_light_count_within(1000, LightLimit::INDICES, APP_BYTES_PER_LIGHT, Some(1 << 20)),
            Ok(())
        );
    }

    #[test]
    fn mem_available_is_read_in_bytes() {
        let text = "MemTotal:       24000000 kB\nMemFree:  100 kB\nMemAvailable:   20000000 kB\n";
        assert_eq!(parse_mem_available(text), Some(20_000_000 * 1024));
        assert_eq!(parse_mem_available("MemTotal: 1 kB\n"), None);
        assert_eq!(parse_mem_available("MemAvailable: x kB\n"), None);
    }
}
