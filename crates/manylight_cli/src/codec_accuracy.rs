//! `manylight codec-accuracy`: the worst and mean angular error of every normal codec over the
//! whole sphere (Fibonacci points, hard points and a local search around the worst), as the
//! markdown table of `docs/accuracy.md`. CPU only.

use manylight_core::codec::{CodecError, NormalCodec, SphereRegion, measure_error, measure_error_in};
use std::fmt::Write as _;

/// `v` with four significant digits, in plain decimal.
fn significant(v: f64) -> String {
    let decimals = if v > 0.0 { (3 - v.log10().floor() as i32).max(1) } else { 1 };
    format!("{v:.*}", decimals as usize)
}

/// Measures every codec with `samples` Fibonacci points and returns the markdown table.
/// `progress` is called with each row's label when it is done.
pub fn table(samples: usize, mut progress: impl FnMut(&str)) -> String {
    let mut table = format!(
        "{samples} Fibonacci samples over the sphere, plus hard points and a local search:\n\n\
         | codec | bits per normal | worst ° | mean ° | worst at |\n|---|---|---|---|---|\n"
    );
    let mut row = |label: &str, bits: u32, e: CodecError| {
        let at = e.worst_at.normalize_or_zero();
        let _ = writeln!(
            table,
            "| {label} | {bits} | {} | {} | ({:.4}, {:.4}, {:.4}) |",
            significant(e.worst_deg),
            significant(e.mean_deg),
            at.x,
            at.y,
            at.z
        );
        progress(label);
    };
    for codec in NormalCodec::ALL {
        row(codec.name(), codec.bits_per_normal(), measure_error(codec, samples));
    }
    for (label, region) in
        [("xyz, z ≥ 0 only", SphereRegion::FrontFacing), ("xyz, z < 0 only", SphereRegion::BackFacing)]
    {
        row(label, 64, measure_error_in(NormalCodec::Xyz, samples, region));
    }
    table
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_table_has_a_row_per_codec_and_region() {
        let mut done = Vec::new();
        let t = super::table(2000, |label| done.push(label.to_string()));
        assert_eq!(done.len(), manylight_core::codec::NormalCodec::ALL.len() + 2);
        assert_eq!(t.lines().filter(|l| l.starts_with("| ")).count(), done.len() + 1, "{t}");
        assert!(!t.contains("NaN"), "{t}");
    }
}
