//! Figures of the measuring commands (`bench`, `report`, `post`): PNGs drawn with plotters
//! from the CSV text the command wrote, so a figure shows exactly what its CSV says.
//!
//! Every figure's title names the scene, the image size and the adapter (columns `scene`,
//! `width`, `height`, `adapter` of the CSV). Columns named `<pass>_gpu_ms` are per-pass GPU
//! times; `transient_mib` and `cluster_buffer_mib` are memory; `frame_ms_median` is the frame
//! time.
//!
//! - [`table`]: the CSV read back, and the series, bars and points each figure shows;
//! - [`draw`]: the charts (line, spread, stacked bars, accuracy against time) and their style.

mod draw;
mod table;

#[cfg(test)]
use draw::log_label;
use draw::{accuracy_chart, figure_height, line_chart, stacked_bars};
pub use table::*;

use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};

/// Which command's CSV a table is, from its columns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `manylight bench`: pipelines × light counts.
    Bench,
    /// `manylight report`: accuracy against time.
    Report,
    /// `manylight post`: post stages.
    Post,
}

impl Kind {
    /// The kind of `table`, or an error naming what is missing.
    pub fn of(table: &Table) -> Result<Kind> {
        if table.column("flip_mean").is_some() {
            Ok(Kind::Report)
        } else if table.column("lights").is_some() && table.column("pipeline").is_some() {
            Ok(Kind::Bench)
        } else if table.column("configuration").is_some() {
            Ok(Kind::Post)
        } else {
            bail!(
                "not a CSV of manylight bench, report or post (no lights/pipeline, flip_mean or configuration column)"
            )
        }
    }

    fn prefix(self) -> &'static str {
        match self {
            Kind::Bench => "bench",
            Kind::Report => "report",
            Kind::Post => "post",
        }
    }
}

/// Draws every figure `csv` (the text a command wrote) calls for into `dir` and returns the
/// files written: frame time and culling ratio against light count (bench), accuracy against
/// time (report), per-pass GPU time and memory per configuration (all three). The files are
/// named after the kind of CSV (`bench_frame_time.png`, `report_accuracy_vs_time.png`, …).
pub fn figures(csv: &str, dir: &Path) -> Result<Vec<PathBuf>> {
    figures_named(csv, dir, None)
}

/// [`figures`], the files named `{prefix}_…` instead of after the kind of CSV.
pub fn figures_named(csv: &str, dir: &Path, prefix: Option<&str>) -> Result<Vec<PathBuf>> {
    let table = Table::parse(csv)?;
    if table.rows.is_empty() {
        bail!("the CSV has no rows to plot");
    }
    let kind = Kind::of(&table)?;
    let prefix = prefix.unwrap_or(kind.prefix());
    // The tallest figures grow with the rows they show (one bar per configuration, one key
    // line per point): checked before anything is drawn.
    figure_height(200, 44, bar_rows(&table).0.len(), 450)?;
    if kind == Kind::Report {
        figure_height(200, 26, table.rows.len(), 800)?;
    }
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let setting = table.setting();
    let file = |name: &str| dir.join(format!("{prefix}_{name}.png"));
    let mut written = Vec::new();
    if kind == Kind::Bench {
        let path = file("frame_time");
        let series = series_over_lights(&table, "frame_ms_median");
        let spread = spread_over_lights(&table, "frame_ms_median", "frame_ms_min", "frame_ms_max");
        line_chart(
            &path,
            &format!("Frame time vs lights — {setting}"),
            "lights",
            if spread.is_empty() {
                "frame time (ms, median)"
            } else {
                "frame time (ms, median; bars: min–max)"
            },
            (&series, &spread),
            true,
        )?;
        written.push(path);
        let culling = series_over_lights(&table, "culling_ratio");
        if !culling.is_empty() {
            let path = file("culling_ratio");
            line_chart(
                &path,
                &format!("Culling ratio vs lights — {setting}"),
                "lights",
                "light–pixel pairs evaluated ÷ contributing",
                (&culling, &Vec::new()),
                false,
            )?;
            written.push(path);
        }
    }
    if kind == Kind::Report {
        let path = file("accuracy_vs_time");
        accuracy_chart(&path, &format!("Accuracy vs time — {setting}"), &accuracy_points(&table))?;
        written.push(path);
    }
    let at = match bar_rows(&table).1 {
        Some(lights) => format!(" at {lights} lights"),
        None => String::new(),
    };
    let (passes, left_out) = without_outliers(pass_bars(&table));
    if passes.iter().any(|(_, s)| !s.is_empty()) {
        let path = file("passes");
        let untrusted = table.rows.iter().any(|r| table.text(r, "cluster_build_gpu_trusted") == "false")
            || table.rows.iter().any(|r| !table.text(r, "untrusted_passes").is_empty());
        let x_desc = if untrusted {
            "GPU ms per pass (compute timestamps are unreliable on this adapter)"
        } else {
            "GPU ms per pass"
        };
        let note =
            (!left_out.is_empty()).then(|| format!("Not drawn (off the scale): {}", left_out.join(", ")));
        stacked_bars(&path, &format!("GPU time per pass{at} — {setting}"), x_desc, &passes, note.as_deref())?;
        written.push(path);
    }
    let memory = memory_bars(&table);
    if memory.iter().any(|(_, s)| !s.is_empty()) {
        let path = file("memory");
        stacked_bars(&path, &format!("Memory per configuration{at} — {setting}"), "MiB", &memory, None)?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests;
