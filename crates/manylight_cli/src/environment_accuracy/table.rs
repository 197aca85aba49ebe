//! The measurement as markdown tables (stdout) and as CSV.

use super::error::{FACING, GRAZING, HIGHLIGHT_FRACTION, ImageError, PerSphere};
use super::spheres::{ROUGHNESS, ROWS};
use super::{GpuRow, Measurement, Sweep};
use anyhow::Result;
use std::fmt::Write as _;

/// A relative error as a percentage.
fn percent(v: f64) -> String {
    format!("{:.2}%", 100.0 * v)
}

/// The markdown tables: a summary per setting, the error per sphere, and where the error is
/// (by `n.v` and on highlights) for the CPU twin and the GPU's middle setting.
pub fn markdown(m: &Measurement) -> String {
    let mut out = String::new();
    let _ = writeln!(
        out,
        "Split-sum against a Monte-Carlo reference: {}, {}x{}, {} reference samples per pixel (two seeds), {} ({} sphere pixels kept of {} covered)\n",
        m.environment, m.size.x, m.size.y, m.reference_samples, m.adapter, m.pixels.0, m.pixels.1
    );
    let _ = writeln!(
        out,
        "| sweep | setting | FLIP mean | FLIP p99 | metal | dielectric | all (signed) | worst sphere | prefilter ms | prefilter ÷ frame | frame with ÷ without |"
    );
    let _ = writeln!(out, "|---|---|---:|---:|---:|---:|---:|---|---:|---:|---:|");
    for (name, error) in cpu_rows(m) {
        summary_line(&mut out, "–", &name, error, None);
    }
    for sweep in Sweep::ALL {
        for filter in sweep.filters() {
            if let Some(row) = m.row(&filter) {
                summary_line(&mut out, sweep.name(), &super::label(&filter), &row.error, Some(row));
            }
        }
    }
    let noise = m.noise.spheres.iter().flatten().map(|s| s.relative()).fold(0.0, f64::max);
    let smallest = cpu_rows(m)
        .into_iter()
        // Past the noise and core's reference: the split-sums only.
        .skip(2)
        .map(|(_, e)| e)
        .chain(m.gpu.iter().map(|r| &r.error))
        .flat_map(|e| e.spheres.iter().flatten().map(|s| s.relative()))
        .fold(f64::INFINITY, f64::min);
    let _ = writeln!(
        out,
        "\nThe reference's noise is at most {} on a sphere; the smallest split-sum error above is {} ({}).",
        percent(noise),
        percent(smallest),
        if noise < smallest {
            "the noise is below every figure"
        } else {
            "NOT below every figure: raise --reference-samples"
        }
    );
    let _ = writeln!(
        out,
        "\nMean relative luminance error per sphere (sum |test - ref| / sum ref), by roughness:\n"
    );
    let header: Vec<String> =
        ROWS.iter().flat_map(|(name, _)| ROUGHNESS.iter().map(move |r| format!("{name} {r}"))).collect();
    let _ = writeln!(out, "| image | {} |", header.join(" | "));
    let _ = writeln!(out, "|---|{}", "---:|".repeat(header.len()));
    for (name, error) in cpu_rows(m) {
        per_sphere_line(&mut out, &name, &error.spheres);
    }
    for sweep in Sweep::ALL {
        for filter in sweep.filters() {
            if let Some(row) = m.row(&filter) {
                per_sphere_line(&mut out, &super::label(&filter), &row.error.spheres);
            }
        }
    }
    where_table(&mut out, "split-sum with exact factors (CPU)", &m.exact_split_sum);
    let middle = Sweep::Samples.filters()[2];
    if let Some(row) = m.row(&middle) {
        where_table(&mut out, &format!("GPU, {}", super::label(&middle)), &row.error);
    }
    out
}

/// The rows that are not GPU settings, named: the reference's noise, core's reference and the
/// two CPU split-sums.
fn cpu_rows(m: &Measurement) -> [(String, &ImageError); 4] {
    [
        ("reference noise (seed against seed)".to_string(), &m.noise),
        ("core reference_radiance (BRDF sampling only)".to_string(), &m.core_reference),
        (format!("core split-sum twin, {} samples", super::TWIN_SAMPLES), &m.twin),
        ("split-sum with exact factors (CPU)".to_string(), &m.exact_split_sum),
    ]
}

fn summary_line(out: &mut String, sweep: &str, setting: &str, e: &ImageError, row: Option<&GpuRow>) {
    let (r, c, worst) = e.worst_sphere();
    let cost = match row {
        Some(row) => format!(
            "{:.0} | {:.0} | {:.2}",
            row.cost.prefilter_ms,
            row.cost.prefilter_frames(),
            row.cost.frame_ratio()
        ),
        None => "– | – | –".to_string(),
    };
    let _ = writeln!(
        out,
        "| {sweep} | {setting} | {:.4} | {:.3} | {} | {} | {} ({:+.2}) | {} {} ({}) | {cost} |",
        e.flip.mean,
        e.flip.p99,
        percent(e.row(0).relative()),
        percent(e.row(1).relative()),
        percent(e.all().relative()),
        100.0 * e.all().bias(),
        ROWS[r].0,
        ROUGHNESS[c],
        percent(worst),
    );
}

fn per_sphere_line(out: &mut String, name: &str, sums: &PerSphere) {
    let cells: Vec<String> = sums.iter().flat_map(|row| row.iter().map(|s| percent(s.relative()))).collect();
    let _ = writeln!(out, "| {name} | {} |", cells.join(" | "));
}

/// Error and bias (signed error) of each sphere on all its pixels, grazing ones, facing ones
/// and its highlights.
fn where_table(out: &mut String, name: &str, e: &ImageError) {
    let _ = writeln!(
        out,
        "\nWhere the error is, {name}: mean relative error (signed: + too bright) on all pixels, n.v < {GRAZING}, n.v >= {FACING}, and the brightest {:.0}% of each sphere in the reference:\n",
        100.0 * HIGHLIGHT_FRACTION
    );
    let _ = writeln!(out, "| sphere | all | n.v < {GRAZING} | n.v ≥ {FACING} | highlights |");
    let _ = writeln!(out, "|---|---:|---:|---:|---:|");
    for (r, (row, _)) in ROWS.iter().enumerate() {
        for (c, roughness) in ROUGHNESS.iter().enumerate() {
            let cell = |s: &PerSphere| {
                let s = s[r][c];
                format!("{} ({:+.1})", percent(s.relative()), 100.0 * s.bias())
            };
            let _ = writeln!(
                out,
                "| {row} {roughness} | {} | {} | {} | {} |",
                cell(&e.spheres),
                cell(&e.grazing),
                cell(&e.facing),
                cell(&e.highlights)
            );
        }
    }
}

/// The CSV: one row per image (reference noise, CPU twin, each GPU setting of each sweep),
/// relative errors as fractions, times in ms.
pub fn csv(m: &Measurement) -> Result<String> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header: Vec<String> = [
        "environment",
        "width",
        "height",
        "adapter",
        "reference_samples",
        "image",
        "sweep",
        "cube_size",
        "samples",
        "irradiance_size",
        "lut_size",
        "flip_mean",
        "flip_p99",
        "rel_metal",
        "rel_dielectric",
        "rel_all",
    ]
    .map(String::from)
    .to_vec();
    for (name, _) in ROWS {
        for r in ROUGHNESS {
            header.push(format!("rel_{name}_{r}"));
        }
    }
    header.extend(
        ["prefilter_ms", "prefilter_cpu_ms", "frame_ms", "plain_frame_ms", "prefilter_frames", "frame_ratio"]
            .map(String::from),
    );
    w.write_record(&header)?;
    let mut record = |image: &str, sweep: &str, e: &ImageError, row: Option<&GpuRow>| -> Result<()> {
        let mut r = vec![
            m.environment.clone(),
            m.size.x.to_string(),
            m.size.y.to_string(),
            m.adapter.clone(),
            m.reference_samples.to_string(),
            image.to_string(),
            sweep.to_string(),
        ];
        match row {
            Some(row) => r.extend(
                [row.filter.cube_size, row.filter.samples, row.filter.irradiance_size, row.filter.lut_size]
                    .map(|v| v.to_string()),
            ),
            None => r.extend(std::iter::repeat_n(String::new(), 4)),
        }
        r.extend([e.flip.mean as f64, e.flip.p99 as f64].map(|v| format!("{v:.5}")));
        r.extend([e.row(0), e.row(1), e.all()].map(|s| format!("{:.5}", s.relative())));
        r.extend(e.spheres.iter().flat_map(|row| row.iter().map(|s| format!("{:.5}", s.relative()))));
        match row {
            Some(row) => r.extend(
                [
                    row.cost.prefilter_ms,
                    row.cost.prefilter_cpu_ms,
                    row.cost.frame_ms,
                    row.cost.plain_frame_ms,
                    row.cost.prefilter_frames(),
                    row.cost.frame_ratio(),
                ]
                .map(|v| format!("{v:.3}")),
            ),
            None => r.extend(std::iter::repeat_n(String::new(), 6)),
        }
        w.write_record(&r)?;
        Ok(())
    };
    for (name, error) in cpu_rows(m) {
        record(&name, "", error, None)?;
    }
    for sweep in Sweep::ALL {
        for filter in sweep.filters() {
            if let Some(row) = m.row(&filter) {
                record("GPU", sweep.name(), &row.error, Some(row))?;
            }
        }
    }
    Ok(String::from_utf8(w.into_inner()?)?)
}
