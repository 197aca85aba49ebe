//! The figure: error against prefilter cost for every GPU setting, each sweep a line, the
//! Pareto front through the settings no other beats in both, and the split-sum with exact
//! factors and the reference's noise as horizontal lines (the floor the GPU's settings
//! approach, and the floor of the measurement).

use super::{GpuRow, Measurement, Sweep};
use crate::plot::{AccuracyPoint, pareto_front};
use anyhow::{Context, Result, anyhow};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Font family of the figure (Hack, embedded, as the other figures use).
const FONT: &str = "sans-serif";

/// One colour per sweep, then the front's.
const COLORS: [RGBColor; 3] = [RGBColor(31, 119, 180), RGBColor(255, 127, 14), RGBColor(44, 160, 44)];

fn drawing<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("drawing the figure: {e}")
}

/// Writes the figure of `m` as PNG at `path`.
pub fn draw(path: &Path, m: &Measurement) -> Result<()> {
    let _ = plotters::style::register_font(FONT, FontStyle::Normal, epaint_default_fonts::HACK_REGULAR);
    let size = (1800u32, 760u32);
    let mut buffer = vec![0u8; size.0 as usize * size.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, size).into_drawing_area();
        root.fill(&WHITE).map_err(drawing)?;
        let title = format!(
            "Split-sum against a Monte-Carlo reference — {}, {}×{}, {}",
            m.environment, m.size.x, m.size.y, m.adapter
        );
        let root = root.titled(&title, (FONT, 26)).map_err(drawing)?;
        let (left, right) = root.split_horizontally(size.0 / 2);
        panel(
            &left,
            m,
            "FLIP mean (tone-mapped)",
            |r| f64::from(r.error.flip.mean),
            |e| f64::from(e.flip.mean),
        )?;
        panel(
            &right,
            m,
            "mean relative luminance error",
            |r| r.error.all().relative(),
            |e| e.all().relative(),
        )?;
        root.present().map_err(drawing)?;
    }
    let image = image::RgbImage::from_raw(size.0, size.1, buffer).context("figure buffer size")?;
    image.save(path).with_context(|| format!("cannot write {}", path.display()))
}

/// One chart: `y` of each GPU setting against its prefilter cost; `floor` of the exact
/// split-sum and of the reference noise as lines.
fn panel(
    area: &DrawingArea<BitMapBackend, Shift>,
    m: &Measurement,
    y_desc: &str,
    y: impl Fn(&GpuRow) -> f64,
    floor: impl Fn(&super::ImageError) -> f64,
) -> Result<()> {
    let x = |r: &GpuRow| r.cost.prefilter_frames().max(1e-3);
    let (exact, noise) = (floor(&m.exact_split_sum), floor(&m.noise));
    let xs = range(m.gpu.iter().map(x));
    let ys = range(m.gpu.iter().map(&y).chain([exact, noise]));
    let mut chart = ChartBuilder::on(area)
        .margin(24)
        .x_label_area_size(64)
        .y_label_area_size(96)
        .build_cartesian_2d(xs.clone().log_scale(), ys.clone().log_scale())
        .map_err(drawing)?;
    let (x_range, y_range) = (xs.clone(), ys.clone());
    chart
        .configure_mesh()
        .x_desc("prefilter time, in frames without the environment")
        .y_desc(y_desc)
        .x_label_formatter(&|v| log_label(*v, &x_range))
        .y_label_formatter(&|v| log_label(*v, &y_range))
        .label_style((FONT, 17))
        .axis_desc_style((FONT, 20))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(drawing)?;
    for (floor, label, dashed) in
        [(exact, "split-sum with exact factors (CPU)", false), (noise, "reference noise (dashed)", true)]
    {
        let grey = RGBColor(110, 110, 110);
        let line: Vec<(f64, f64)> = if dashed {
            // Dashes: every other tenth of the axis, evenly on the log scale.
            let (lo, hi) = (xs.start.ln(), xs.end.ln());
            (0..20).map(|i| ((lo + (hi - lo) * i as f64 / 20.0).exp(), floor)).collect()
        } else {
            vec![(xs.start, floor), (xs.end, floor)]
        };
        let series = if dashed {
            chart.draw_series(line.chunks(2).map(|p| PathElement::new(p.to_vec(), grey.stroke_width(2))))
        } else {
            chart.draw_series(LineSeries::new(line, grey.stroke_width(2)))
        };
        series
            .map_err(drawing)?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], grey.stroke_width(2)));
    }
    // The front of error against prefilter time (`AccuracyPoint` holds it in `frame_ms`).
    let points: Vec<AccuracyPoint> = m
        .gpu
        .iter()
        .map(|r| AccuracyPoint { label: super::label(&r.filter), frame_ms: x(r), flip_mean: y(r) })
        .collect();
    let front = pareto_front(&points);
    // Drawn first and wide, so the sweeps' lines run on top of it.
    let red = RGBColor(214, 39, 40).mix(0.3);
    chart
        .draw_series(LineSeries::new(
            front.iter().map(|&i| (points[i].frame_ms, points[i].flip_mean)),
            red.stroke_width(12),
        ))
        .map_err(drawing)?
        .label("Pareto front")
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], red.stroke_width(12)));
    for (i, sweep) in Sweep::ALL.iter().enumerate() {
        let c = COLORS[i];
        let rows: Vec<&GpuRow> = sweep.filters().iter().filter_map(|f| m.row(f)).collect();
        let mut points: Vec<(f64, f64, u32)> =
            rows.iter().map(|r| (x(r), y(r), sweep.value(&r.filter))).collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        chart
            .draw_series(LineSeries::new(points.iter().map(|p| (p.0, p.1)), c.stroke_width(3)))
            .map_err(drawing)?
            .label(format!("{} sweep", sweep.name()))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(3)));
        // Each point labelled with its value in its sweep's colour: above the line for the
        // first sweep, staggered below it for the others (the cube and table sweeps' points
        // crowd around the middle setting).
        chart
            .draw_series(points.iter().enumerate().map(|(j, &(px, py, value))| {
                let at = if i == 0 { (6, -20) } else { (-30 + 40 * (i as i32 - 1), 8 + 15 * j as i32) };
                EmptyElement::at((px, py))
                    + Circle::new((0, 0), 6, c.filled())
                    + Text::new(value.to_string(), at, (FONT, 15))
            }))
            .map_err(drawing)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .label_font((FONT, 16))
        .position(SeriesLabelPosition::LowerRight)
        .draw()
        .map_err(drawing)
}

/// A log axis's label at `v`: 1, 2 and 5 times a power of ten, nothing between.
fn log_label(v: f64, range: &std::ops::Range<f64>) -> String {
    if v <= 0.0 || !range.contains(&v) {
        return String::new();
    }
    let exponent = v.log10().floor();
    let mantissa = v / 10f64.powf(exponent);
    if ![1.0, 2.0, 5.0].iter().any(|m| (mantissa - m).abs() < 1e-6 * m) {
        return String::new();
    }
    let digits = (-exponent).max(0.0) as usize;
    format!("{v:.digits$}")
}

/// A log axis's range over the positive `values`, padded by a fifth of a decade.
fn range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) =
        values.filter(|v| *v > 0.0).fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !lo.is_finite() {
        return 1.0..10.0;
    }
    let pad = 10f64.powf(0.2);
    (lo / pad)..(hi * pad)
}
