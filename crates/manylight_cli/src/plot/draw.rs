//! The charts the figures are made of, drawn with plotters: line and spread charts over light
//! counts (log axes), stacked bars per configuration, accuracy against time; one font and one
//! colour order for all.

use super::table::*;
use anyhow::{Context, Result, anyhow, bail};
use plotters::coord::Shift;
use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// Font family every figure uses (Hack, embedded, so no system fonts are needed; its letters
/// stay distinct at small sizes, where a light sans font merges "cl" into "d").
const FONT: &str = "sans-serif";

/// Series colours: distinguishable on white, in a fixed order.
const COLORS: [RGBColor; 12] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(0, 0, 128),
    RGBColor(128, 64, 0),
];

fn color(i: usize) -> RGBColor {
    COLORS[i % COLORS.len()]
}

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The embedded font is valid; an error here would leave text undrawn, not crash.
        let _ = plotters::style::register_font(FONT, FontStyle::Normal, epaint_default_fonts::HACK_REGULAR);
    });
}

/// Plotters' errors carry the backend's error type; they become plain messages here.
fn drawing<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow!("drawing a figure: {e}")
}

/// Tallest figure drawn, in pixels: a 1900-pixel-wide RGB buffer of this height takes 93 MB.
pub const MAX_FIGURE_HEIGHT: u32 = 16_384;

/// Height of a figure with `rows` rows of `per_row` pixels under a `base` of titles and axes,
/// at least `min`; refused, naming the row count, past [`MAX_FIGURE_HEIGHT`].
pub(super) fn figure_height(base: u32, per_row: u32, rows: usize, min: u32) -> Result<u32> {
    let height = u32::try_from(rows)
        .ok()
        .and_then(|rows| rows.checked_mul(per_row))
        .and_then(|h| h.checked_add(base))
        .filter(|&h| h <= MAX_FIGURE_HEIGHT);
    match height {
        Some(h) => Ok(h.max(min)),
        None => bail!(
            "{rows} rows would make a figure more than MAX_FIGURE_HEIGHT ({MAX_FIGURE_HEIGHT} px) tall: at most {} rows fit",
            (MAX_FIGURE_HEIGHT - base) / per_row
        ),
    }
}

/// Renders into an RGB buffer of `size` and saves it as PNG at `path`.
fn save(
    path: &Path,
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend, Shift>) -> Result<()>,
) -> Result<()> {
    register_font();
    let mut buffer = vec![0u8; size.0 as usize * size.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, size).into_drawing_area();
        root.fill(&WHITE).map_err(drawing)?;
        draw(&root)?;
        root.present().map_err(drawing)?;
    }
    let image = image::RgbImage::from_raw(size.0, size.1, buffer).context("figure buffer size")?;
    image.save(path).with_context(|| format!("cannot write {}", path.display()))
}

/// Range of positive values for a log axis, padded by a quarter of a decade on each side.
fn log_range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) =
        values.filter(|v| *v > 0.0).fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !lo.is_finite() {
        return 1.0..10.0;
    }
    let pad = 10f64.powf(0.25);
    (lo / pad)..(hi * pad)
}

/// A line chart of `series` over a log x axis (and a log or linear y axis), with each point's
/// spread in `spread` (by series label) drawn as a bar from its lowest to its highest value.
pub(super) fn line_chart(
    path: &Path,
    title: &str,
    x_desc: &str,
    y_desc: &str,
    (series, spread): (&Series, &Spread),
    log_y: bool,
) -> Result<()> {
    save(path, (1280, 800), |root| {
        let xs = log_range(series.iter().flat_map(|(_, p)| p.iter().map(|p| p.0)));
        let mut ys: Vec<f64> = series.iter().flat_map(|(_, p)| p.iter().map(|p| p.1)).collect();
        ys.extend(spread.iter().flat_map(|(_, p)| p.iter().flat_map(|s| [s.lo, s.hi])));
        let mut chart = ChartBuilder::on(root);
        chart.caption(title, (FONT, 28)).margin(24).x_label_area_size(70).y_label_area_size(100);
        // Values within one decade read better on a linear axis: a log axis labels too few.
        let (lo, hi) = ys
            .iter()
            .filter(|v| **v > 0.0)
            .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(*v), hi.max(*v)));
        if log_y && hi > 10.0 * lo {
            let y_range = log_range(ys.into_iter());
            let axes = Axes { x_log: Some(xs.clone()), y_log: Some(y_range.clone()) };
            let mut chart = chart.build_cartesian_2d(xs.log_scale(), y_range.log_scale()).map_err(drawing)?;
            mesh(&mut chart, x_desc, y_desc, axes)?;
            draw_spread(&mut chart, series, spread)?;
            draw_lines(&mut chart, series)
        } else {
            let top = ys.iter().fold(0.0f64, |m, v| m.max(*v)) * 1.1;
            let axes = Axes { x_log: Some(xs.clone()), y_log: None };
            let mut chart = chart.build_cartesian_2d(xs.log_scale(), 0.0..top.max(1.0)).map_err(drawing)?;
            mesh(&mut chart, x_desc, y_desc, axes)?;
            draw_spread(&mut chart, series, spread)?;
            draw_lines(&mut chart, series)
        }
    })
}

/// Draws each point's spread as a vertical bar in its series' colour.
fn draw_spread<'a, X, Y>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, Cartesian2d<X, Y>>,
    series: &Series,
    spread: &Spread,
) -> Result<()>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    for (label, points) in spread {
        let Some(i) = series.iter().position(|(l, _)| l == label) else { continue };
        let c = color(i);
        chart
            .draw_series(
                points.iter().map(|p| PathElement::new(vec![(p.x, p.lo), (p.x, p.hi)], c.stroke_width(2))),
            )
            .map_err(drawing)?;
    }
    Ok(())
}

/// Draws each series as a line with dots, and the legend.
fn draw_lines<'a, X, Y>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, Cartesian2d<X, Y>>,
    series: &Series,
) -> Result<()>
where
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    for (i, (label, points)) in series.iter().enumerate() {
        let c = color(i);
        // A series equal to an earlier one (pipelines sharing one light list) hides under
        // it; the legend says so.
        let twin = series[..i].iter().find(|(_, p)| p == points).map(|(l, _)| l.as_str());
        let label = match twin {
            Some(t) => format!("{label} (same as {t})"),
            None => label.clone(),
        };
        chart
            .draw_series(LineSeries::new(points.iter().copied(), c.stroke_width(3)))
            .map_err(drawing)?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], c.stroke_width(3)));
        chart.draw_series(points.iter().map(|&p| Circle::new(p, 5, c.filled()))).map_err(drawing)?;
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font((FONT, 18))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(drawing)
}

/// A log axis's label at `v` over `range`: decades always; 2 and 5 between them only where the
/// axis spans at most two decades (more would collide); nothing elsewhere. Values are written
/// as plain numbers (1000, 0.01) and as powers of ten past six digits (1e5).
pub fn log_label(v: f64, range: &std::ops::Range<f64>) -> String {
    if v.is_nan() || v <= 0.0 {
        return String::new();
    }
    let exponent = v.log10().floor();
    let mantissa = v / 10f64.powf(exponent);
    let near = |m: f64| (mantissa - m).abs() < 1e-6 * m || (mantissa - 10.0 * m).abs() < 1e-5 * m;
    let decades = (range.end / range.start.max(f64::MIN_POSITIVE)).log10();
    let shown = near(1.0) || (decades <= 2.0 && (near(2.0) || near(5.0)));
    if !shown {
        return String::new();
    }
    let rounded = 10f64.powf(exponent) * mantissa.round();
    if !(1e-4..1e6).contains(&rounded) {
        format!("{}e{}", mantissa.round() as u32, exponent as i32)
    } else if rounded >= 1.0 {
        format!("{}", rounded.round() as u64)
    } else {
        format!("{}", (rounded * 1e4).round() / 1e4)
    }
}

/// Axis ranges of a chart, for [`mesh`]: `Some` marks a log axis (its labels from
/// [`log_label`]).
struct Axes {
    x_log: Option<std::ops::Range<f64>>,
    y_log: Option<std::ops::Range<f64>>,
}

fn mesh<'a, X, Y>(
    chart: &mut ChartContext<'a, BitMapBackend<'a>, Cartesian2d<X, Y>>,
    x_desc: &str,
    y_desc: &str,
    axes: Axes,
) -> Result<()>
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let x_format = |v: &f64| match &axes.x_log {
        Some(r) => log_label(*v, r),
        None => X::format(v),
    };
    let y_format = |v: &f64| match &axes.y_log {
        Some(r) => log_label(*v, r),
        None => Y::format(v),
    };
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&x_format)
        .y_label_formatter(&y_format)
        .label_style((FONT, 18))
        .axis_desc_style((FONT, 22))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(drawing)
}

/// Horizontal stacked bars, first bar at the top, one colour per segment name; `note` is
/// written under the chart.
pub(super) fn stacked_bars(
    path: &Path,
    title: &str,
    x_desc: &str,
    bars: &[Bar],
    note: Option<&str>,
) -> Result<()> {
    let n = bars.len().max(1);
    let height = figure_height(200, 44, n, 450)?;
    save(path, (1400, height), |root| {
        if let Some(note) = note {
            root.draw(&Text::new(note.to_string(), (20, height as i32 - 28), (FONT, 16).into_font()))
                .map_err(drawing)?;
        }
        let mut names: Vec<&str> = Vec::new();
        for (_, segments) in bars {
            for (name, _) in segments {
                if !names.contains(&name.as_str()) {
                    names.push(name);
                }
            }
        }
        let widest =
            bars.iter().map(|(_, s)| s.iter().map(|(_, v)| v.max(0.0)).sum::<f64>()).fold(0.0, f64::max);
        let labels: Vec<String> = bars.iter().map(|(l, _)| l.clone()).collect();
        let label_width = labels.iter().map(|l| l.chars().count()).max().unwrap_or(10) as u32 * 10 + 24;
        let mut chart = ChartBuilder::on(root)
            .caption(title, (FONT, 26))
            .margin(20)
            .margin_bottom(44)
            .x_label_area_size(60)
            .y_label_area_size(label_width.min(640))
            .build_cartesian_2d(0.0..(widest * 1.6).max(1e-3), (0..n as i32 - 1).into_segmented())
            .map_err(drawing)?;
        let row_of = |i: usize| (n - 1 - i) as i32;
        chart
            .configure_mesh()
            .disable_y_mesh()
            .y_labels(n)
            .y_label_formatter(&|v| match v {
                SegmentValue::CenterOf(i) if (0..n as i32).contains(i) => {
                    labels.get(n - 1 - *i as usize).cloned().unwrap_or_default()
                }
                _ => String::new(),
            })
            .x_desc(x_desc)
            .label_style((FONT, 17))
            .axis_desc_style((FONT, 21))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(drawing)?;
        for (k, name) in names.iter().enumerate() {
            let c = color(k);
            let rects: Vec<Rectangle<(f64, SegmentValue<i32>)>> = bars
                .iter()
                .enumerate()
                .filter_map(|(i, (_, segments))| {
                    let start: f64 =
                        segments.iter().take_while(|(s, _)| s != name).map(|(_, v)| v.max(0.0)).sum();
                    let value = segments.iter().find(|(s, _)| s == name)?.1.max(0.0);
                    let y = row_of(i);
                    let mut r = Rectangle::new(
                        [(start, SegmentValue::Exact(y)), (start + value, SegmentValue::Exact(y + 1))],
                        c.filled(),
                    );
                    r.set_margin(6, 6, 0, 0);
                    Some(r)
                })
                .collect();
            chart
                .draw_series(rects)
                .map_err(drawing)?
                .label(*name)
                .legend(move |(x, y)| Rectangle::new([(x, y - 7), (x + 18, y + 7)], c.filled()));
        }
        // Each bar's total at its end.
        chart
            .draw_series(bars.iter().enumerate().map(|(i, (_, segments))| {
                let total: f64 = segments.iter().map(|(_, v)| v.max(0.0)).sum();
                Text::new(format!(" {total:.1}"), (total, SegmentValue::CenterOf(row_of(i))), (FONT, 16))
            }))
            .map_err(drawing)?;
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font((FONT, 17))
            .position(SeriesLabelPosition::LowerRight)
            .draw()
            .map_err(drawing)
    })
}

/// FLIP mean against frame time, each configuration a numbered point with a key beside the
/// chart, the Pareto front drawn through the points no other beats in both.
pub(super) fn accuracy_chart(path: &Path, title: &str, points: &[AccuracyPoint]) -> Result<()> {
    // A zero error (the reference itself) is drawn on the bottom of the log axis.
    const FLOOR: f64 = 1e-5;
    let height = figure_height(200, 26, points.len(), 800)?;
    save(path, (1900, height), |root| {
        let (left, right) = root.split_horizontally(1000);
        let xs = log_range(points.iter().map(|p| p.frame_ms));
        let ys = log_range(points.iter().map(|p| p.flip_mean.max(FLOOR)));
        let mut chart = ChartBuilder::on(&left)
            .caption(title, (FONT, 24))
            .margin(20)
            .x_label_area_size(70)
            .y_label_area_size(100)
            .build_cartesian_2d(xs.clone().log_scale(), (ys.start.min(FLOOR * 0.7)..ys.end).log_scale())
            .map_err(drawing)?;
        let axes = Axes { x_log: Some(xs.clone()), y_log: Some(ys.start.min(FLOOR * 0.7)..ys.end) };
        mesh(&mut chart, "frame time (ms, median)", "FLIP mean vs reference (0 drawn at 1e-5)", axes)?;
        let front = pareto_front(points);
        let at = |p: &AccuracyPoint| (p.frame_ms, p.flip_mean.max(FLOOR));
        chart
            .draw_series(LineSeries::new(front.iter().map(|&i| at(&points[i])), RED.stroke_width(2)))
            .map_err(drawing)?
            .label("Pareto front")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], RED.stroke_width(2)));
        for (i, p) in points.iter().enumerate() {
            let c = color(i);
            let on_front = front.contains(&i);
            let marker = if on_front { c.filled() } else { c.stroke_width(2) };
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at(at(p))
                        + Circle::new((0, 0), 7, marker)
                        + Text::new(
                            format!("{}", i + 1),
                            if i % 2 == 0 { (8, -20) } else { (-18, 8) },
                            (FONT, 16),
                        ),
                ))
                .map_err(drawing)?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font((FONT, 17))
            .position(SeriesLabelPosition::UpperRight)
            .draw()
            .map_err(drawing)?;
        // The key: number, configuration, figures; Pareto-optimal ones marked.
        let style = TextStyle::from((FONT, 16).into_font()).color(&BLACK);
        let heading = "configuration (* on the Pareto front): frame ms, FLIP mean";
        right.draw(&Text::new(heading, (10, 40), (FONT, 17).into_font())).map_err(drawing)?;
        for (i, p) in points.iter().enumerate() {
            let mark = if front.contains(&i) { "*" } else { " " };
            let line = format!("{mark}{:>2} {}: {:.0} ms, {:.4}", i + 1, p.label, p.frame_ms, p.flip_mean);
            right.draw(&Text::new(line, (10, 72 + 26 * i as i32), style.clone())).map_err(drawing)?;
        }
        Ok(())
    })
}
