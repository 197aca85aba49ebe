//! A measuring command's CSV read back, and what each figure shows of it: series over light
//! counts, per-pass and memory bars, accuracy points and their Pareto front.

use anyhow::{Context, Result};

/// A CSV file as read back: its header and its rows of fields.
#[derive(Clone, Debug)]
pub struct Table {
    pub(super) header: Vec<String>,
    pub(super) rows: Vec<Vec<String>>,
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

    pub(super) fn column(&self, name: &str) -> Option<usize> {
        self.header.iter().position(|h| h == name)
    }

    /// The text of `row`'s field `name` (empty when the column is absent).
    pub(super) fn text<'a>(&self, row: &'a [String], name: &str) -> &'a str {
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
    pub(super) fn setting(&self) -> String {
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
pub(super) fn bar_rows(table: &Table) -> (Vec<&Vec<String>>, Option<f64>) {
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
