//! What the soak run asks of each frame: window size, post stages, debug view and light count,
//! as a pure function of the frame number (so the schedule is tested without a window).

use glam::UVec2;
use manylight_render::DebugViewMode;

/// How often each setting changes, and the values it cycles through.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// Window sizes, one after the other, each for `resize_every` frames.
    pub sizes: Vec<UVec2>,
    /// Light counts, one after the other, each for `lights_every` frames.
    pub light_counts: Vec<usize>,
    /// Frames between resizes.
    pub resize_every: u64,
    /// Frames between steps of the post stages (none, bloom, motion blur, both).
    pub post_every: u64,
    /// Frames between switching the debug view on (the next view of the cycle) or off; the
    /// switches fall half a period after the post steps.
    pub debug_every: u64,
    /// Frames between light-count changes.
    pub lights_every: u64,
}

/// The settings of one frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameConfig {
    /// Window inner size.
    pub size: UVec2,
    /// `Bloom` on the camera.
    pub bloom: bool,
    /// `MotionBlur` on the camera.
    pub motion_blur: bool,
    /// The debug view (`None` shows the tone-mapped image with its post stages).
    pub debug: DebugViewMode,
    /// Animated lights alive.
    pub lights: usize,
}

/// The `k`-th debug view of the cycle that `DebugViewMode::next` walks, skipping `None`
/// (`k` = 0 is the first view after `None`).
fn debug_view(k: u64) -> DebugViewMode {
    let views = DebugViewMode::ALL.len() as u64 - 1;
    let mut mode = DebugViewMode::None;
    for _ in 0..=(k % views.max(1)) {
        mode = mode.next();
        if mode == DebugViewMode::None {
            mode = mode.next();
        }
    }
    mode
}

/// `values[(frame / every) % len]`; the first value when `values` is empty is the caller's
/// problem, so `Plan::validate` refuses that.
fn cycle<T: Copy>(values: &[T], frame: u64, every: u64) -> T {
    let i = (frame / every.max(1)) % values.len().max(1) as u64;
    values[i as usize]
}

impl Plan {
    /// Refuses an empty list, a zero period or a light count that cannot fit, naming the option.
    pub fn validate(&self) -> Result<(), String> {
        if self.sizes.is_empty() {
            return Err("--sizes: give at least one size".into());
        }
        if self.light_counts.is_empty() {
            return Err("--lights: give at least one light count".into());
        }
        for &count in &self.light_counts {
            manylight_core::light_count::check_app_lights(count).map_err(|e| format!("--lights: {e}"))?;
        }
        for (name, every) in [
            ("--resize-every", self.resize_every),
            ("--post-every", self.post_every),
            ("--debug-every", self.debug_every),
            ("--lights-every", self.lights_every),
        ] {
            if every == 0 {
                return Err(format!("{name}: must be at least 1"));
            }
        }
        Ok(())
    }

    /// The settings of frame `frame` (0-based). Call [`Plan::validate`] first.
    pub fn at(&self, frame: u64) -> FrameConfig {
        let post = frame / self.post_every;
        // Off for half a period, then on for one, off for one, ...: the debug view replaces
        // the post stages, so they show between its periods.
        let debug_period = (frame + self.debug_every / 2) / self.debug_every;
        FrameConfig {
            size: cycle(&self.sizes, frame, self.resize_every),
            bloom: post % 4 == 1 || post % 4 == 3,
            motion_blur: post % 4 >= 2,
            debug: if debug_period % 2 == 1 { debug_view(debug_period / 2) } else { DebugViewMode::None },
            lights: cycle(&self.light_counts, frame, self.lights_every),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plan() -> Plan {
        Plan {
            sizes: vec![UVec2::new(320, 180), UVec2::new(256, 256), UVec2::new(200, 120)],
            light_counts: vec![4096, 2048],
            resize_every: 50,
            post_every: 100,
            debug_every: 100,
            lights_every: 500,
        }
    }

    #[test]
    fn every_setting_changes_on_its_period() {
        let p = plan();
        assert_eq!(
            p.at(0),
            FrameConfig {
                size: UVec2::new(320, 180),
                bloom: false,
                motion_blur: false,
                debug: DebugViewMode::None,
                lights: 4096,
            }
        );
        assert_eq!(p.at(49).size, UVec2::new(320, 180));
        assert_eq!(p.at(50).size, UVec2::new(256, 256));
        assert_eq!(p.at(100).size, UVec2::new(200, 120));
        assert_eq!(p.at(150).size, UVec2::new(320, 180));
        let post: Vec<(bool, bool)> =
            (0..5).map(|k| (p.at(k * 100).bloom, p.at(k * 100).motion_blur)).collect();
        assert_eq!(post, [(false, false), (true, false), (false, true), (true, true), (false, false)]);
        assert_eq!(p.at(49).debug, DebugViewMode::None);
        assert_ne!(p.at(50).debug, DebugViewMode::None);
        assert_eq!(p.at(149).debug, p.at(50).debug);
        assert_eq!(p.at(150).debug, DebugViewMode::None);
        assert_eq!(p.at(499).lights, 4096);
        assert_eq!(p.at(500).lights, 2048);
        assert_eq!(p.at(1000).lights, 4096);
    }

    #[test]
    fn the_debug_view_cycle_shows_every_view() {
        let p = plan();
        let count = DebugViewMode::ALL.len() as u64 - 1;
        let views: Vec<DebugViewMode> = (0..count).map(|k| p.at(50 + 200 * k).debug).collect();
        for mode in DebugViewMode::ALL.into_iter().filter(|&m| m != DebugViewMode::None) {
            assert!(views.contains(&mode), "{mode:?} never shown: {views:?}");
        }
        assert_eq!(p.at(50 + 200 * count).debug, views[0], "the cycle wraps");
    }

    #[test]
    fn empty_lists_and_zero_periods_are_refused() {
        assert!(plan().validate().is_ok());
        assert!(Plan { sizes: vec![], ..plan() }.validate().is_err());
        assert!(Plan { light_counts: vec![], ..plan() }.validate().is_err());
        let e = Plan { lights_every: 0, ..plan() }.validate();
        assert!(e.is_err_and(|e| e.contains("--lights-every")));
    }
}
