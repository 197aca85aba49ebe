//! What the soak run measures and how it decides: resident memory, the transient pool, errors
//! and non-finite pixels, and the pass criterion over them. Pure code, tested without a window.
//!
//! The pool's `transient_allocations` is a counter of textures created since start-up. It
//! cannot stay within 5 % of its warm-up value, and should not: a texture unused for
//! [`TRANSIENT_KEEP_FRAMES`] frames is freed, so a window size seen again after a resize is
//! allocated again. What must hold is that the pool reuses: once a configuration (size and
//! pass list) has rendered, the next frame of the same configuration allocates nothing, and a
//! configuration that has run long enough for the pool to hold only its own textures always
//! holds the same number of them, with the same bytes.

use manylight_render::FrameReport;
use manylight_render::pool::TRANSIENT_KEEP_FRAMES;
use std::collections::HashMap;

/// Resident memory of this process in KiB (`VmRSS` of `/proc/self/status`).
pub fn resident_kib() -> Result<u64, String> {
    let status = std::fs::read_to_string("/proc/self/status")
        .map_err(|e| format!("cannot read resident memory from /proc/self/status: {e}"))?;
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .ok_or_else(|| "/proc/self/status has no readable VmRSS line".to_string())
}

/// The state after `frame` frames: one row of the CSV, one field a column (over 15: the soak's
/// CSV has that many columns).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sample {
    /// Frames (app updates) done.
    pub frame: u64,
    /// Seconds since the first frame.
    pub seconds: f64,
    /// Mean wall time per frame since the previous sample, in ms.
    pub frame_ms: f64,
    /// Resident memory in KiB.
    pub rss_kib: u64,
    /// Size of the last frame seen.
    pub width: u32,
    /// Size of the last frame seen.
    pub height: u32,
    /// Lights the last frame rendered.
    pub lights: u32,
    /// Bloom on the camera now.
    pub bloom: bool,
    /// Motion blur on the camera now.
    pub motion_blur: bool,
    /// The debug view now.
    pub debug_view: &'static str,
    /// Transient textures alive after the last frame.
    pub transient_textures: u32,
    /// Bytes of the transient textures the last frame used.
    pub transient_bytes: u64,
    /// Transient textures created since start-up.
    pub transient_allocations: u64,
    /// Of those, created in a frame of the same configuration as the frame before.
    pub repeat_allocations: u64,
    /// Frame reports seen so far.
    pub reports: u64,
    /// Non-finite pixels counted so far.
    pub nonfinite_pixels: u64,
}

/// What decides whether a frame can reuse the last one's textures: its size and passes.
type ConfigKey = (u32, u32, Vec<String>);

/// Follows the frame reports and checks that the transient pool reuses its textures.
#[derive(Debug, Default)]
pub struct PoolCheck {
    last: Option<(u64, ConfigKey, u64)>,
    /// Consecutive reports with the same configuration, this one included.
    run: u64,
    /// Live textures and bytes of each configuration once the pool holds only its textures.
    settled: HashMap<ConfigKey, (u32, u64)>,
    /// Allocations in frames whose configuration equals the previous frame's, after warm-up.
    pub repeat_allocations: u64,
    /// The same during warm-up (not judged).
    pub warmup_repeat_allocations: u64,
    /// Settled frames whose live textures or bytes differ from the first settled frame of the
    /// same configuration.
    pub settled_mismatches: u64,
    /// The first such difference, described.
    pub first_mismatch: Option<String>,
    /// Settled frames checked.
    pub settled_frames: u64,
    /// Configurations seen settled.
    pub configurations: usize,
}

impl PoolCheck {
    /// Takes the next report the app saw (`after_warmup`: it counts towards the verdict).
    pub fn observe(&mut self, report: &FrameReport, after_warmup: bool) {
        let key: ConfigKey =
            (report.width, report.height, report.passes.iter().map(|p| p.name.clone()).collect());
        let allocations = report.transient_allocations;
        let follows = self
            .last
            .as_ref()
            .is_some_and(|(index, last_key, _)| report.frame_index == index + 1 && *last_key == key);
        if follows {
            self.run += 1;
            let before = self.last.as_ref().map_or(allocations, |l| l.2);
            let new = allocations.saturating_sub(before);
            match after_warmup {
                true => self.repeat_allocations += new,
                false => self.warmup_repeat_allocations += new,
            }
        } else {
            self.run = 1;
        }
        // After KEEP + 1 frames of one configuration every other texture has been freed.
        if self.run > TRANSIENT_KEEP_FRAMES && !report.passes.is_empty() {
            self.settled_frames += 1;
            let now = (report.transient_textures, report.transient_bytes);
            let first = *self.settled.entry(key.clone()).or_insert(now);
            self.configurations = self.settled.len();
            if first != now {
                self.settled_mismatches += 1;
                self.first_mismatch.get_or_insert_with(|| {
                    format!(
                        "frame {} at {}x{} ({}): {} textures / {} bytes, first seen with {} / {}",
                        report.frame_index,
                        key.0,
                        key.1,
                        key.2.join(","),
                        now.0,
                        now.1,
                        first.0,
                        first.1
                    )
                });
            }
        }
        self.last = Some((report.frame_index, key, allocations));
    }
}

/// Everything the run saw, judged by [`verdict`].
#[derive(Debug, Default)]
pub struct Outcome {
    /// Frames (app updates) asked for.
    pub frames: u64,
    /// Frames the renderer really rendered.
    pub frames_rendered: u64,
    /// Frames counted as warm-up.
    pub warmup: u64,
    /// Wall time of the run in seconds.
    pub seconds: f64,
    /// The samples, in order.
    pub samples: Vec<Sample>,
    /// The pool's reuse check.
    pub pool: PoolCheck,
    /// Render errors (the first message), including a failed exit of the app.
    pub error: Option<String>,
    /// Reports seen.
    pub reports: u64,
    /// Non-finite pixels over all reports seen.
    pub nonfinite_pixels: u64,
    /// Reports with at least one non-finite pixel.
    pub nonfinite_frames: u64,
    /// Allowed growth of resident memory after warm-up, in percent.
    pub max_growth_percent: f64,
}

/// The decision and its one-line summary.
#[derive(Debug, PartialEq)]
pub struct Verdict {
    /// All criteria hold.
    pub pass: bool,
    /// One line with every figure.
    pub summary: String,
    /// What failed, one item per criterion.
    pub failures: Vec<String>,
}

fn mib(kib: u64) -> f64 {
    kib as f64 / 1024.0
}

/// Applies the pass criterion:
/// - no render error;
/// - no non-finite pixel in any report;
/// - resident memory: the highest sample after warm-up is at most `max_growth_percent` above
///   the sample at the end of warm-up;
/// - the pool: no allocation after warm-up in a frame of the same configuration as the frame
///   before, and every settled frame of a configuration holds what its first settled frame held.
pub fn verdict(o: &Outcome) -> Verdict {
    let mut failures = Vec::new();
    if let Some(e) = &o.error {
        failures.push(format!("render error: {e}"));
    }
    if o.nonfinite_pixels > 0 {
        failures.push(format!("{} non-finite pixels in {} frames", o.nonfinite_pixels, o.nonfinite_frames));
    }
    let baseline = o.samples.iter().find(|s| s.frame >= o.warmup);
    let after: Vec<&Sample> = o.samples.iter().filter(|s| s.frame > o.warmup).collect();
    let rss = match (baseline, after.iter().max_by_key(|s| s.rss_kib)) {
        (Some(b), Some(max)) if b.rss_kib > 0 => {
            let growth = 100.0 * (max.rss_kib as f64 - b.rss_kib as f64) / b.rss_kib as f64;
            if growth > o.max_growth_percent {
                failures.push(format!(
                    "resident memory grew {growth:.1} % after warm-up (limit {} %)",
                    o.max_growth_percent
                ));
            }
            format!(
                "RSS {:.1} MiB at frame {}, max {:.1} MiB after (frame {}, {growth:+.1} %, limit {} %)",
                mib(b.rss_kib),
                b.frame,
                mib(max.rss_kib),
                max.frame,
                o.max_growth_percent
            )
        }
        _ => {
            failures.push(format!("no memory sample after the {} warm-up frames", o.warmup));
            "RSS not measured after warm-up".to_string()
        }
    };
    if o.pool.repeat_allocations > 0 {
        failures.push(format!(
            "the transient pool allocated {} textures after warm-up in frames that repeated the \
             previous frame's configuration",
            o.pool.repeat_allocations
        ));
    }
    if let Some(m) = &o.pool.first_mismatch {
        failures.push(format!(
            "the transient pool held different textures for one configuration {} times; first: {m}",
            o.pool.settled_mismatches
        ));
    }
    let live_max = |warm: bool| {
        o.samples
            .iter()
            .filter(|s| (s.frame <= o.warmup) == warm)
            .map(|s| (s.transient_textures, s.transient_bytes))
            .fold((0, 0), |a, b| (a.0.max(b.0), a.1.max(b.1)))
    };
    let (warm_live, after_live) = (live_max(true), live_max(false));
    let allocations_at =
        |frame: u64| o.samples.iter().rev().find(|s| s.frame <= frame).map_or(0, |s| s.transient_allocations);
    let total_allocations = o.samples.last().map_or(0, |s| s.transient_allocations);
    let after_allocations = total_allocations.saturating_sub(allocations_at(o.warmup));
    let summary = format!(
        "soak {}: {} frames ({} rendered, {} reports) in {:.0} s; {rss}; transient pool: {} \
         allocations ({} after warm-up, {} of them in repeated configurations), at most {} textures / \
         {:.2} MiB live after warm-up ({} / {:.2} MiB during), {} of {} settled frames differ over {} \
         configurations; {} render errors; {} non-finite pixels",
        if failures.is_empty() { "PASS" } else { "FAIL" },
        o.frames,
        o.frames_rendered,
        o.reports,
        o.seconds,
        total_allocations,
        after_allocations,
        o.pool.repeat_allocations,
        after_live.0,
        after_live.1 as f64 / (1024.0 * 1024.0),
        warm_live.0,
        warm_live.1 as f64 / (1024.0 * 1024.0),
        o.pool.settled_mismatches,
        o.pool.settled_frames,
        o.pool.configurations,
        u32::from(o.error.is_some()),
        o.nonfinite_pixels,
    );
    Verdict { pass: failures.is_empty(), summary, failures }
}

/// The samples as CSV, one row per sample.
pub fn csv(samples: &[Sample]) -> anyhow::Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "frame",
        "seconds",
        "frame_ms",
        "rss_kib",
        "width",
        "height",
        "lights",
        "bloom",
        "motion_blur",
        "debug_view",
        "transient_textures",
        "transient_bytes",
        "transient_allocations",
        "repeat_allocations",
        "reports",
        "nonfinite_pixels",
    ])?;
    for s in samples {
        w.write_record([
            s.frame.to_string(),
            format!("{:.3}", s.seconds),
            format!("{:.3}", s.frame_ms),
            s.rss_kib.to_string(),
            s.width.to_string(),
            s.height.to_string(),
            s.lights.to_string(),
            s.bloom.to_string(),
            s.motion_blur.to_string(),
            s.debug_view.to_string(),
            s.transient_textures.to_string(),
            s.transient_bytes.to_string(),
            s.transient_allocations.to_string(),
            s.repeat_allocations.to_string(),
            s.reports.to_string(),
            s.nonfinite_pixels.to_string(),
        ])?;
    }
    Ok(String::from_utf8(w.into_inner().map_err(|e| anyhow::anyhow!("{e}"))?)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use manylight_render::PassTiming;

    fn report(index: u64, width: u32, passes: &[&str], live: u32, allocations: u64) -> FrameReport {
        FrameReport {
            frame_index: index,
            width,
            height: 100,
            passes: passes
                .iter()
                .map(|p| PassTiming { name: p.to_string(), ..PassTiming::default() })
                .collect(),
            transient_textures: live,
            transient_bytes: u64::from(live) * 1000,
            transient_allocations: allocations,
            ..FrameReport::default()
        }
    }

    #[test]
    fn reuse_is_judged_only_within_one_configuration() {
        let mut pool = PoolCheck::default();
        // A resize allocates (not a repeat), the next frames reuse, then one frame allocates.
        pool.observe(&report(0, 100, &["forward", "tonemap"], 2, 2), true);
        pool.observe(&report(1, 200, &["forward", "tonemap"], 4, 4), true);
        assert_eq!(pool.repeat_allocations, 0);
        for i in 2..8 {
            pool.observe(&report(i, 200, &["forward", "tonemap"], 2, 4), true);
        }
        assert_eq!((pool.repeat_allocations, pool.settled_mismatches), (0, 0));
        assert_eq!(pool.settled_frames, 4, "frames 4 to 7 are settled (KEEP + 1 = 4 in a row)");
        pool.observe(&report(8, 200, &["forward", "tonemap"], 3, 5), true);
        assert_eq!((pool.repeat_allocations, pool.settled_mismatches), (1, 1));
        assert!(pool.first_mismatch.as_deref().is_some_and(|m| m.contains("frame 8")));
    }

    #[test]
    fn a_gap_in_the_reports_is_not_a_repeat() {
        let mut pool = PoolCheck::default();
        pool.observe(&report(0, 100, &["forward"], 1, 1), true);
        pool.observe(&report(2, 100, &["forward"], 1, 2), true);
        assert_eq!(pool.repeat_allocations, 0);
        pool.observe(&report(3, 100, &["forward"], 1, 3), false);
        assert_eq!((pool.repeat_allocations, pool.warmup_repeat_allocations), (0, 1));
    }

    fn sample(frame: u64, rss_kib: u64) -> Sample {
        Sample { frame, rss_kib, ..Sample::default() }
    }

    fn outcome(rss: &[u64]) -> Outcome {
        Outcome {
            frames: 100 * rss.len() as u64,
            warmup: 200,
            samples: rss.iter().enumerate().map(|(i, &r)| sample(100 * (i as u64 + 1), r)).collect(),
            max_growth_percent: 5.0,
            ..Outcome::default()
        }
    }

    #[test]
    fn memory_growth_is_measured_from_the_end_of_warm_up() {
        // Growth during warm-up does not count; 5 % after it does not fail, 6 % does.
        let v = verdict(&outcome(&[100, 1000, 1050, 1020]));
        assert!(v.pass, "{v:?}");
        assert!(v.summary.contains("+5.0 %"), "{}", v.summary);
        let v = verdict(&outcome(&[100, 1000, 1010, 1060]));
        assert!(!v.pass);
        assert!(v.failures[0].contains("6.0 %"), "{:?}", v.failures);
        assert!(v.summary.starts_with("soak FAIL"));
    }

    #[test]
    fn errors_nan_pixels_and_missing_samples_fail() {
        let v = verdict(&Outcome { error: Some("device lost".into()), ..outcome(&[1, 1, 1]) });
        assert!(!v.pass && v.failures[0].contains("device lost"));
        let v = verdict(&Outcome { nonfinite_pixels: 3, nonfinite_frames: 1, ..outcome(&[1, 1, 1]) });
        assert!(!v.pass && v.failures[0].contains("3 non-finite"));
        let v = verdict(&outcome(&[1, 1]));
        assert!(!v.pass && v.failures[0].contains("no memory sample"));
    }

    #[test]
    fn csv_has_a_row_per_sample() {
        let text = csv(&[sample(100, 1), sample(200, 2)]).expect("csv");
        assert_eq!(text.lines().count(), 3);
        assert!(text.starts_with("frame,seconds,frame_ms,rss_kib,"));
    }

    #[test]
    fn resident_memory_is_readable_here() {
        if cfg!(target_os = "linux") {
            assert!(resident_kib().is_ok_and(|k| k > 0));
        }
    }
}
