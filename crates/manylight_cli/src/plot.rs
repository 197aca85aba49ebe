//! Figures of the measuring commands (`bench`, `report`, `post`): PNGs drawn with plotters
//! from the CSV text the command wrote, so a figure shows exactly what its CSV says.
//!
//! Every figure's title names the scene, the image size and the adapter (columns `scene`,
//! `width`, `height`, `adapter` of the CSV). Columns named `<pass>_gpu_ms` are per-pass GPU
//! times; `transient_mib` and `cluster_buffer_mib` are memory; `frame_ms_median` is the frame
//! time.

use anyhow::{Context, Result, anyhow, bail};
use plotters::coord::Shift;
use plotters::coord::ranged1d::ValueFormatter;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
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

/// A CSV file as read back: its header and its rows of fields.
#[derive(Clone, Debug)]
pub struct Table {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// Parses CSV text with a header line.
    pub fn parse(text: &str) -> Result<Table> {
        let mut reader = csv::ReaderBuilder::new().from_reader(text.as_bytes());
        let header = reader.headers().context("CSV header")?.iter().map(str::to_string).collect();
        let rows = reader
            .records()
            .map(|r| r.map(|r| r.iter().map(str::to_string).collect()))
            .collect::<Result<Vec<Vec<String>>, _>>()
            .context("CSV rows")?;
        Ok(Table { header, rows })
    }

    fn column(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    /// The text of `row`'s field `name` (empty when the column is absent).
    fn text<'a>(&self, row: &'a [String], name: &str) -> &'a str {
        self.column(name).and_then(|c| row.get(c)).map_or("", String::as_str)
    }

    /// The number in `row`'s field `name` (`None` when absent, empty or not a finite number).
    fn number(&self, row: &[String], name: &str) -> Option<f64> {
        self.text(row, name).parse::<f64>().ok().filter(|v| v.is_finite())
    }

    /// Per-pass GPU time columns: (column index, pass name), in column order.
    fn pass_columns(&self) -> Vec<(usize, String)> {
        self.header
            .iter()
            .enumerate()
            .filter_map(|(i, h)| h.strip_suffix("_gpu_ms").map(|p| (i, p.to_string())))
            .collect()
    }

    /// "scene, W×H, adapter" from the first row.
    fn setting(&self) -> String {
        let Some(row) = self.rows.first() else { return String::new() };
        format!(
            "{}, {}×{}, {}",
            self.text(row, "scene"),
            self.text(row, "width"),
            self.text(row, "height"),
            self.text(row, "adapter")
        )
    }

    /// The label of a row: its `configuration` column, else pipeline and G-buffer layout.
    fn label(&self, row: &[String]) -> String {
        let configuration = self.text(row, "configuration");
        if !configuration.is_empty() {
            return configuration.to_string();
        }
        match self.text(row, "gbuffer") {
            "" => self.text(row, "pipeline").to_string(),
            g => format!("{}, {g} G-buffer", self.text(row, "pipeline")),
        }
    }
}

/// Points of a line chart: one series per label, in order of first appearance.
pub type Series = Vec<(String, Vec<(f64, f64)>)>;

/// The spread of a measured point: its lowest and highest value around the plotted one (drawn
/// as a bar between them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpreadPoint {
    /// Where it is on the x axis.
    pub x: f64,
    /// The lowest value.
    pub lo: f64,
    /// The plotted value (the median).
    pub mid: f64,
    /// The highest value.
    pub hi: f64,
}

/// Spreads of a line chart's points, by series label.
pub type Spread = Vec<(String, Vec<SpreadPoint>)>;

/// The spread of `mid` between the columns `lo` and `hi` over `lights`, one series per
/// configuration, where a row has all three and more than one frame (a one-frame row has no
/// spread to show).
pub fn spread_over_lights(table: &Table, mid: &str, lo: &str, hi: &str) -> Spread {
    by_configuration(table, |row| {
        let x = table.number(row, "lights")?;
        let (lo, mid, hi) = (table.number(row, lo)?, table.number(row, mid)?, table.number(row, hi)?);
        let several = table.number(row, "frames").is_none_or(|f| f >= 2.0);
        (x > 0.0 && lo > 0.0 && several).then_some(SpreadPoint { x, lo, mid, hi })
    })
}

/// The points `point` takes from the rows, one series per configuration label, in order of
/// first appearance (rows it returns `None` for are left out).
fn by_configuration<T>(table: &Table, point: impl Fn(&[String]) -> Option<T>) -> Vec<(String, Vec<T>)> {
    let mut series: Vec<(String, Vec<T>)> = Vec::new();
    for row in &table.rows {
        let Some(p) = point(row) else { continue };
        let label = table.label(row);
        match series.iter_mut().find(|(l, _)| *l == label) {
            Some((_, points)) => points.push(p),
            None => series.push((label, vec![p])),
        }
    }
    series
}

/// One horizontal stacked bar: its label and its segments (name, value).
pub type Bar = (String, Vec<(String, f64)>);

/// `y` against `lights`, one series per configuration (rows without a positive `y` or light
/// count are left out, so a log axis can show them).
pub fn series_over_lights(table: &Table, y: &str) -> Series {
    let mut series = by_configuration(table, |row| {
        let (x, v) = (table.number(row, "lights")?, table.number(row, y)?);
        (x > 0.0 && v > 0.0).then_some((x, v))
    });
    for (_, points) in &mut series {
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
    }
    series
}

/// Rows to show as bars: every row, or for a sweep over light counts only the rows at the
/// largest count (returned too).
fn bar_rows(table: &Table) -> (Vec<&Vec<String>>, Option<f64>) {
    let lights = table
        .rows
        .iter()
        .filter_map(|r| table.number(r, "lights"))
        .fold(None, |m: Option<f64>, v| Some(m.map_or(v, |m| m.max(v))));
    match lights {
        Some(max) if table.column("configuration").is_none() => {
            (table.rows.iter().filter(|r| table.number(r, "lights") == Some(max)).collect(), Some(max))
        }
        _ => (table.rows.iter().collect(), None),
    }
}

/// Per-pass GPU time of each configuration (passes without a time are left out).
pub fn pass_bars(table: &Table) -> Vec<Bar> {
    let passes = table.pass_columns();
    bar_rows(table)
        .0
        .into_iter()
        .map(|row| {
            let segments = passes
                .iter()
                .filter_map(|(c, name)| {
                    row.get(*c)
                        .and_then(|v| v.parse::<f64>().ok())
                        .filter(|v| v.is_finite())
                        .map(|v| (name.clone(), v))
                })
                .collect();
            (table.label(row), segments)
        })
        .collect()
}

/// The bars without those more than 10× the median total (the naive reference beside the
/// fast pipelines would flatten every other bar), and "label: total" of each one left out.
pub fn without_outliers(bars: Vec<Bar>) -> (Vec<Bar>, Vec<String>) {
    let total = |b: &Bar| b.1.iter().map(|(_, v)| v.max(0.0)).sum::<f64>();
    let mut totals: Vec<f64> = bars.iter().map(total).collect();
    totals.sort_by(f64::total_cmp);
    let median = totals.get(totals.len() / 2).copied().unwrap_or(0.0);
    if median <= 0.0 {
        return (bars, Vec::new());
    }
    let (kept, out): (Vec<Bar>, Vec<Bar>) = bars.into_iter().partition(|b| total(b) <= 10.0 * median);
    (kept, out.iter().map(|b| format!("{} {:.0} ms", b.0, total(b))).collect())
}

/// Frame textures and cluster buffers of each configuration, MiB.
pub fn memory_bars(table: &Table) -> Vec<Bar> {
    bar_rows(table)
        .0
        .into_iter()
        .map(|row| {
            let segments = [("frame textures", "transient_mib"), ("cluster buffers", "cluster_buffer_mib")]
                .into_iter()
                .filter_map(|(name, column)| table.number(row, column).map(|v| (name.to_string(), v)))
                .collect();
            (table.label(row), segments)
        })
        .collect()
}

/// A configuration of the accuracy-versus-time figure.
#[derive(Clone, Debug, PartialEq)]
pub struct AccuracyPoint {
    /// The configuration.
    pub label: String,
    /// Median frame time, ms.
    pub frame_ms: f64,
    /// Mean FLIP error against the reference.
    pub flip_mean: f64,
}

/// FLIP mean against frame time of each configuration of a `report` CSV.
pub fn accuracy_points(table: &Table) -> Vec<AccuracyPoint> {
    table
        .rows
        .iter()
        .filter_map(|row| {
            Some(AccuracyPoint {
                label: table.label(row),
                frame_ms: table.number(row, "frame_ms_median")?,
                flip_mean: table.number(row, "flip_mean")?,
            })
        })
        .collect()
}

/// True for the oracle rows of `manylight report`: drawn as the floor, never on the front (their
/// lists are built on the CPU outside the timed frame, so no renderer can choose them).
pub fn is_oracle(point: &AccuracyPoint) -> bool {
    point.label.starts_with("oracle")
}

/// Indices of the Pareto front (no other point is both faster and more accurate), fastest
/// first; oracle rows ([`is_oracle`]) are left out.
pub fn pareto_front(points: &[AccuracyPoint]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).filter(|&i| !is_oracle(&points[i])).collect();
    order.sort_by(|&a, &b| {
        points[a]
            .frame_ms
            .total_cmp(&points[b].frame_ms)
            .then(points[a].flip_mean.total_cmp(&points[b].flip_mean))
    });
    let mut front = Vec::new();
    let mut best = f64::INFINITY;
    for i in order {
        if points[i].flip_mean < best {
            best = points[i].flip_mean;
            front.push(i);
        }
    }
    front
}

/// Tallest figure drawn, in pixels: a 1900-pixel-wide RGB buffer of this height takes 93 MB.
pub const MAX_FIGURE_HEIGHT: u32 = 16_384;

/// Height of a figure with `rows` rows of `per_row` pixels under a `base` of titles and axes,
/// at least `min`; refused, naming the row count, past [`MAX_FIGURE_HEIGHT`].
fn figure_height(base: u32, per_row: u32, rows: usize, min: u32) -> Result<u32> {
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
fn line_chart(
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
fn stacked_bars(path: &Path, title: &str, x_desc: &str, bars: &[Bar], note: Option<&str>) -> Result<()> {
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
fn accuracy_chart(path: &Path, title: &str, points: &[AccuracyPoint]) -> Result<()> {
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
mod tests {
    use super::*;

    const BENCH: &str = "adapter,scene,pipeline,gbuffer,lights,width,height,frame_ms_median,forward_gpu_ms,\
        cluster_build_gpu_ms,cluster_build_gpu_trusted,culling_ratio,transient_mib,cluster_buffer_mib\n\
        \"llvmpipe (LLVM 15, 256 bits)\",default,naive,,16,96,64,40.5,38.0,,,,0.07,\n\
        \"llvmpipe (LLVM 15, 256 bits)\",default,clustered-forward,,16,96,64,12.0,,0.02,false,1.4,0.07,0.50\n\
        \"llvmpipe (LLVM 15, 256 bits)\",default,clustered-deferred,full,16,96,64,14.0,,0.02,false,1.5,0.20,0.50\n\
        \"llvmpipe (LLVM 15, 256 bits)\",default,clustered-forward,,64,96,64,20.0,,0.03,false,1.2,0.07,0.60\n";

    #[test]
    fn series_follow_the_csv() {
        let t = Table::parse(BENCH).expect("parses");
        let s = series_over_lights(&t, "frame_ms_median");
        assert_eq!(s.len(), 3);
        assert_eq!(s[0], ("naive".to_string(), vec![(16.0, 40.5)]));
        assert_eq!(s[1], ("clustered-forward".to_string(), vec![(16.0, 12.0), (64.0, 20.0)]));
        assert_eq!(s[2].0, "clustered-deferred, full G-buffer");
        let culling = series_over_lights(&t, "culling_ratio");
        assert_eq!(culling[0], ("clustered-forward".to_string(), vec![(16.0, 1.4), (64.0, 1.2)]));
        // Bars show the largest light count only.
        let bars = pass_bars(&t);
        assert_eq!(bars, vec![("clustered-forward".to_string(), vec![("cluster_build".to_string(), 0.03)])]);
        let memory = memory_bars(&t);
        assert_eq!(
            memory[0].1,
            vec![("frame textures".to_string(), 0.07), ("cluster buffers".to_string(), 0.60)]
        );
        assert_eq!(t.setting(), "default, 96×64, llvmpipe (LLVM 15, 256 bits)");
    }

    /// A CSV of 200 000 configurations at one light count would ask for a figure 8.8 million
    /// pixels tall (and, with `u32` sizes, wrap past 2^32 at larger counts): refused, naming
    /// the limit, before any buffer is allocated.
    #[test]
    fn log_axes_label_decades_and_minor_ticks_only_where_they_fit() {
        let wide = 10.0..200_000.0;
        let labels: Vec<String> = [10.0, 20.0, 60.0, 100.0, 1000.0, 5000.0, 100_000.0, 1e6]
            .iter()
            .map(|&v| log_label(v, &wide))
            .collect();
        assert_eq!(labels, ["10", "", "", "100", "1000", "", "100000", "1e6"]);
        let narrow = 10.0..300.0;
        let labels: Vec<String> = [20.0, 50.0, 60.0, 0.02].iter().map(|&v| log_label(v, &narrow)).collect();
        assert_eq!(labels, ["20", "50", "", "0.02"]);
    }

    #[test]
    fn the_spread_comes_from_rows_of_several_frames() {
        let csv = "pipeline,lights,frames,frame_ms_median,frame_ms_min,frame_ms_max\n\
                   naive,16,5,10,9,12\nnaive,64,1,20,20,20\nforward-plus,16,5,8,7,9\n";
        let t = Table::parse(csv).expect("table");
        let s = spread_over_lights(&t, "frame_ms_median", "frame_ms_min", "frame_ms_max");
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].1, vec![SpreadPoint { x: 16.0, lo: 9.0, mid: 10.0, hi: 12.0 }]);
    }

    #[test]
    fn figures_too_tall_for_their_rows_are_refused() {
        let mut csv = BENCH.lines().next().expect("header").to_string();
        for i in 0..200_000 {
            csv.push_str(&format!(
                "\n\"llvmpipe\",default,clustered-forward-{i},,64,96,64,20.0,,0.03,false,1.2,0.07,0.60"
            ));
        }
        let dir = std::env::temp_dir().join(format!("manylight_plot_rows_{}", std::process::id()));
        let error = figures(&csv, &dir).expect_err("too many rows for one figure");
        let _ = std::fs::remove_dir_all(&dir);
        assert!(format!("{error:#}").contains("MAX_FIGURE_HEIGHT"), "{error:#}");
        assert!(figure_height(200, 44, usize::MAX, 450).is_err());
        assert!(figure_height(200, 26, (u32::MAX / 26) as usize + 1, 800).is_err());
        assert_eq!(figure_height(200, 44, 1, 450).expect("fits"), 450);
    }

    #[test]
    fn pareto_front_keeps_points_no_other_beats() {
        let p = |label: &str, frame_ms, flip_mean| AccuracyPoint { label: label.into(), frame_ms, flip_mean };
        let points = [
            p("reference", 8000.0, 0.0),
            p("fast exact", 170.0, 0.0001),
            p("faster", 160.0, 0.004),
            p("worse", 200.0, 0.01),
            p("oracle, forward (exact per-pixel lists)", 150.0, 0.0),
        ];
        // The reference is exact: nothing beats its error, so it ends the front; the oracle
        // beats everything but is not a configuration, so it is not on the front.
        assert_eq!(pareto_front(&points), vec![2, 1, 0]);
    }

    #[test]
    fn figures_are_written_as_png() {
        let dir = std::env::temp_dir().join(format!("manylight-plot-test-{}", std::process::id()));
        let files = figures(BENCH, &dir).expect("figures");
        let names: Vec<String> =
            files.iter().map(|f| f.file_name().and_then(|n| n.to_str()).unwrap_or("").to_string()).collect();
        assert_eq!(
            names,
            ["bench_frame_time.png", "bench_culling_ratio.png", "bench_passes.png", "bench_memory.png"]
        );
        for f in &files {
            let img = image::open(f).expect("a PNG").to_rgb8();
            // Something besides the white background was drawn.
            assert!(img.pixels().filter(|p| p.0 != [255, 255, 255]).count() > 1000, "{}", f.display());
        }
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_csv_of_another_kind_is_refused() {
        let err = figures("a,b\n1,2\n", Path::new("/nonexistent")).expect_err("refused");
        assert!(err.to_string().contains("not a CSV"), "{err}");
    }
}
