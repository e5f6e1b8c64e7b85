//! Charts for benchmarks and sweeps, drawn by `plotters` into SVG and rasterised to PNG by
//! [`svg_to_png`](super::svg_to_png) with the bundled font.
//!
//! - [`Scatter`]: labelled point series on linear or log axes, optionally joined by lines, with
//!   the Pareto front (both axes minimised) drawn over them;
//! - [`HeatMap`]: a grid of values with a colour scale and the value printed in each cell.
//!
//! Log axes are drawn in log10 space with `10^k` tick labels, so one coordinate type serves both.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

const FONT: &str = super::svg::FONT_FAMILY;

/// Colours for series, in order (Tableau 10).
const PALETTE: [RGBColor; 10] = [
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
];

/// The `k`-th series colour as RGB.
pub fn color(k: usize) -> (u8, u8, u8) {
    let c = PALETTE[k % PALETTE.len()];
    (c.0, c.1, c.2)
}

/// One named set of points.
#[derive(Clone, Debug, Default)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// `(x, y)` points; non-finite points (and non-positive ones on a log axis) are skipped.
    pub points: Vec<(f64, f64)>,
    /// Draw the points as rings instead of dots (`bench` marks refined methods so).
    pub hollow: bool,
}

/// A scatter (or line) chart.
#[derive(Clone, Debug, Default)]
pub struct Scatter {
    /// Title above the plot.
    pub title: String,
    /// X axis caption.
    pub x_label: String,
    /// Y axis caption.
    pub y_label: String,
    /// Log-scaled x axis.
    pub log_x: bool,
    /// Log-scaled y axis.
    pub log_y: bool,
    /// Join each series' points in order.
    pub lines: bool,
    /// Draw the Pareto front of all points (lower x and lower y are better).
    pub pareto: bool,
    /// The series.
    pub series: Vec<Series>,
}

/// Indices of the points not dominated by another (a point dominates when it is ≤ in both
/// coordinates and < in one), sorted by x. Non-finite points are never on the front.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let mut idx: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].0.is_finite() && points[i].1.is_finite())
        .collect();
    idx.sort_by(|&a, &b| {
        let (pa, pb) = (points[a], points[b]);
        pa.0.total_cmp(&pb.0).then(pa.1.total_cmp(&pb.1))
    });
    let mut front = Vec::new();
    let mut best_y = f64::INFINITY;
    for i in idx {
        if points[i].1 < best_y {
            best_y = points[i].1;
            front.push(i);
        }
    }
    front
}

fn axis(v: f64, log: bool) -> Option<f64> {
    match (v.is_finite(), log) {
        (false, _) => None,
        (true, true) => (v > 0.0).then(|| v.log10()),
        (true, false) => Some(v),
    }
}

fn range(values: impl Iterator<Item = f64>) -> std::ops::Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
        (lo.min(v), hi.max(v))
    });
    if !lo.is_finite() {
        return 0.0..1.0;
    }
    let pad = ((hi - lo) * 0.08).max(1e-9 * hi.abs().max(1.0)).max(0.05);
    (lo - pad)..(hi + pad)
}

/// The corner of the plot for the legend of `rows` lines that covers the fewest of the points
/// `all` (in axis coordinates over the ranges `xr`, `yr`); the upper right on a tie.
fn legend_corner(
    all: &[(f64, f64)],
    xr: &std::ops::Range<f64>,
    yr: &std::ops::Range<f64>,
    rows: usize,
) -> SeriesLabelPosition {
    // The box's share of the plot: about 40 % of the width, 4.5 % of the height a line.
    let (w, h) = (0.4, (0.045 * (rows as f64 + 1.0)).min(0.9));
    let t = |v: f64, r: &std::ops::Range<f64>| (v - r.start) / (r.end - r.start);
    let covered = |right: bool, upper: bool| {
        all.iter()
            .filter(|&&(x, y)| {
                let (u, v) = (t(x, xr), t(y, yr));
                (if right { u >= 1.0 - w } else { u <= w })
                    && (if upper { v >= 1.0 - h } else { v <= h })
            })
            .count()
    };
    [
        (true, true, SeriesLabelPosition::UpperRight),
        (false, true, SeriesLabelPosition::UpperLeft),
        (true, false, SeriesLabelPosition::LowerRight),
        (false, false, SeriesLabelPosition::LowerLeft),
    ]
    .into_iter()
    .min_by_key(|&(right, upper, _)| covered(right, upper))
    .map_or(SeriesLabelPosition::UpperRight, |c| c.2)
}

fn tick(v: f64, log: bool) -> String {
    let x = if log { 10f64.powf(v) } else { v };
    let a = x.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        // Three significant digits, so that close ticks (1.05e5, 1.1e5) stay apart.
        let e = format!("{x:.2e}");
        let (m, exp) = e.split_once('e').expect("{:e} has an exponent");
        format!("{}e{exp}", m.trim_end_matches('0').trim_end_matches('.'))
    } else if a >= 100.0 {
        format!("{x:.0}")
    } else if a >= 1.0 {
        format!("{x:.2}")
    } else if a == 0.0 {
        "0".to_string()
    } else {
        // Three significant digits here too (0.00112, not 0.001), trailing zeros dropped.
        let digits = (2.0 - a.log10().floor()) as usize;
        let f = format!("{x:.digits$}");
        f.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

fn err(e: impl std::fmt::Display) -> String {
    format!("chart: {e}")
}

impl Scatter {
    /// Draws the chart as an SVG document of `width` × `height` pixels.
    pub fn to_svg(&self, width: u32, height: u32) -> Result<String, String> {
        let mapped: Vec<Vec<(f64, f64)>> = self
            .series
            .iter()
            .map(|s| {
                s.points
                    .iter()
                    .filter_map(|&(x, y)| Some((axis(x, self.log_x)?, axis(y, self.log_y)?)))
                    .collect()
            })
            .collect();
        let all: Vec<(f64, f64)> = mapped.iter().flatten().copied().collect();
        let xr = range(all.iter().map(|p| p.0));
        let yr = range(all.iter().map(|p| p.1));
        let rows = self.series.len() + usize::from(self.pareto && all.len() > 1);
        let corner = legend_corner(&all, &xr, &yr, rows);
        let mut buf = String::new();
        {
            let root = SVGBackend::with_string(&mut buf, (width, height)).into_drawing_area();
            root.fill(&WHITE).map_err(err)?;
            let mut chart = ChartBuilder::on(&root)
                .caption(&self.title, (FONT, 18))
                .margin(12)
                .x_label_area_size(44)
                .y_label_area_size(64)
                .build_cartesian_2d(xr, yr)
                .map_err(err)?;
            let (lx, ly) = (self.log_x, self.log_y);
            chart
                .configure_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .label_style((FONT, 12))
                .axis_desc_style((FONT, 14))
                .x_label_formatter(&|v| tick(*v, lx))
                .y_label_formatter(&|v| tick(*v, ly))
                .light_line_style(RGBColor(235, 235, 235))
                .draw()
                .map_err(err)?;
            for (k, pts) in mapped.iter().enumerate() {
                let c = PALETTE[k % PALETTE.len()];
                if self.lines && pts.len() > 1 {
                    chart
                        .draw_series(LineSeries::new(pts.iter().copied(), c.stroke_width(2)))
                        .map_err(err)?;
                }
                let style = if self.series[k].hollow {
                    c.stroke_width(2)
                } else {
                    c.filled()
                };
                chart
                    .draw_series(pts.iter().map(|&p| Circle::new(p, 4, style)))
                    .map_err(err)?
                    .label(&self.series[k].label)
                    .legend(move |(x, y)| Circle::new((x + 8, y), 4, style));
            }
            if self.pareto && all.len() > 1 {
                let front: Vec<(f64, f64)> =
                    pareto_front(&all).into_iter().map(|i| all[i]).collect();
                chart
                    .draw_series(LineSeries::new(
                        front.iter().copied(),
                        BLACK.mix(0.7).stroke_width(1),
                    ))
                    .map_err(err)?
                    .label("Pareto front")
                    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 16, y)], BLACK));
                chart
                    .draw_series(
                        front
                            .iter()
                            .map(|&p| Circle::new(p, 7, BLACK.stroke_width(1))),
                    )
                    .map_err(err)?;
            }
            if !self.series.is_empty() {
                chart
                    .configure_series_labels()
                    .position(corner)
                    .label_font((FONT, 12))
                    .background_style(WHITE.mix(0.85))
                    .border_style(RGBColor(160, 160, 160))
                    .draw()
                    .map_err(err)?;
            }
            root.present().map_err(err)?;
        }
        Ok(buf)
    }
}

/// A grid of values, one coloured cell each (low = light, high = dark; on a log scale when the
/// positive values span more than a decade).
#[derive(Clone, Debug, Default)]
pub struct HeatMap {
    /// Title above the grid.
    pub title: String,
    /// Caption under the columns.
    pub x_label: String,
    /// Caption beside the rows.
    pub y_label: String,
    /// Column labels.
    pub x_ticks: Vec<String>,
    /// Row labels (row 0 is drawn at the top).
    pub y_ticks: Vec<String>,
    /// `values[row][col]`; non-finite cells are grey.
    pub values: Vec<Vec<f64>>,
}

fn shade(t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0);
    let lerp = |a: f64, b: f64| (a + (b - a) * t).round() as u8;
    RGBColor(lerp(255.0, 8.0), lerp(245.0, 48.0), lerp(235.0, 107.0))
}

impl HeatMap {
    /// Draws the heat map as an SVG document of `width` × `height` pixels.
    pub fn to_svg(&self, width: u32, height: u32) -> Result<String, String> {
        let rows = self.y_ticks.len().max(1);
        let cols = self.x_ticks.len().max(1);
        let finite = self
            .values
            .iter()
            .flatten()
            .copied()
            .filter(|v| v.is_finite());
        let (lo, hi) = finite.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
        // Colour by log value when positive values span more than a decade.
        let log = lo > 0.0 && hi / lo > 10.0;
        let level = |v: f64| match (hi > lo, log) {
            (false, _) => 0.5,
            (true, true) => (v / lo).ln() / (hi / lo).ln(),
            (true, false) => (v - lo) / (hi - lo),
        };
        let mut buf = String::new();
        {
            let root = SVGBackend::with_string(&mut buf, (width, height)).into_drawing_area();
            root.fill(&WHITE).map_err(err)?;
            let mut chart = ChartBuilder::on(&root)
                .caption(&self.title, (FONT, 16))
                .margin(10)
                .x_label_area_size(40)
                .y_label_area_size(70)
                .build_cartesian_2d(0.0..cols as f64, 0.0..rows as f64)
                .map_err(err)?;
            let (xt, yt) = (&self.x_ticks, &self.y_ticks);
            let label = |ticks: &Vec<String>, v: f64| {
                let i = v.floor() as usize;
                if (v - i as f64 - 0.5).abs() < 1e-6 {
                    ticks.get(i).cloned().unwrap_or_default()
                } else {
                    String::new()
                }
            };
            chart
                .configure_mesh()
                .disable_mesh()
                .x_desc(&self.x_label)
                .y_desc(&self.y_label)
                .label_style((FONT, 12))
                .axis_desc_style((FONT, 13))
                .x_labels(cols * 2 + 1)
                .y_labels(rows * 2 + 1)
                .x_label_formatter(&|v| label(xt, *v))
                .y_label_formatter(&|v| label(yt, rows as f64 - 1.0 - 2.0 * v.floor() + v))
                .draw()
                .map_err(err)?;
            for (r, row) in self.values.iter().enumerate() {
                let y0 = (rows - 1 - r) as f64;
                for (c, &v) in row.iter().enumerate() {
                    let fill = if v.is_finite() {
                        shade(level(v))
                    } else {
                        RGBColor(200, 200, 200)
                    };
                    let cell = [(c as f64, y0), (c as f64 + 1.0, y0 + 1.0)];
                    chart
                        .draw_series([Rectangle::new(cell, fill.filled())])
                        .map_err(err)?;
                    let text_colour = if v.is_finite() && level(v) > 0.55 {
                        WHITE
                    } else {
                        BLACK
                    };
                    let style = TextStyle::from((FONT, 12).into_font())
                        .color(&text_colour)
                        .pos(Pos::new(HPos::Center, VPos::Center));
                    let text = if v.is_finite() {
                        tick(v, false)
                    } else {
                        "–".into()
                    };
                    chart
                        .draw_series([Text::new(text, (c as f64 + 0.5, y0 + 0.5), style)])
                        .map_err(err)?;
                }
            }
            root.present().map_err(err)?;
        }
        Ok(buf)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_legend_goes_where_it_hides_no_point() {
        let (xr, yr) = (0.0..10.0, 0.0..10.0);
        // A point in the upper right (a slow, costly builder): the legend moves left.
        let pts = [(9.5, 9.5), (1.0, 5.0), (5.0, 1.0)];
        let c = legend_corner(&pts, &xr, &yr, 5);
        assert!(matches!(c, SeriesLabelPosition::UpperLeft), "{c:?}");
        // Points in both upper corners: a lower one.
        let pts = [(9.5, 9.5), (0.5, 9.5), (5.0, 5.0)];
        let c = legend_corner(&pts, &xr, &yr, 5);
        assert!(matches!(c, SeriesLabelPosition::LowerRight), "{c:?}");
        // Nothing in the way: the upper right, as before.
        let c = legend_corner(&[(5.0, 5.0)], &xr, &yr, 5);
        assert!(matches!(c, SeriesLabelPosition::UpperRight), "{c:?}");
    }

    #[test]
    fn pareto_front_keeps_only_undominated_points() {
        let pts = [
            (1.0, 5.0),
            (2.0, 3.0),
            (2.5, 4.0),
            (3.0, 1.0),
            (f64::NAN, 0.0),
            (3.0, 1.0),
        ];
        assert_eq!(pareto_front(&pts), vec![0, 1, 3]);
    }

    #[test]
    fn close_large_ticks_get_distinct_labels() {
        assert_eq!(tick(1.05e5, false), "1.05e5");
        assert_eq!(tick(1.1e5, false), "1.1e5");
        assert_eq!(tick(2e6, false), "2e6");
        assert_eq!(tick(2.0, true), "100");
        assert_eq!(tick(0.0005, false), "5e-4");
        // Log ticks a few per cent apart below 1 (build times of about a millisecond).
        assert_eq!(tick(0.00112f64.log10(), true), "0.00112");
        assert_eq!(tick(0.00125f64.log10(), true), "0.00125");
        assert_eq!(tick(0.5, false), "0.5");
        assert_eq!(tick(0.0, false), "0");
    }

    #[test]
    fn charts_render_to_png() {
        let s = Scatter {
            title: "t".into(),
            log_x: true,
            pareto: true,
            series: vec![Series {
                label: "a".into(),
                points: vec![(1e-3, 2.0), (1e-1, 1.0), (0.0, 1.0)],
                hollow: false,
            }],
            ..Scatter::default()
        };
        let svg = s.to_svg(400, 300).unwrap();
        assert!(svg.contains("Pareto front"));
        assert!(
            crate::render::svg_to_png(&svg)
                .unwrap()
                .starts_with(b"\x89PNG")
        );
        let h = HeatMap {
            x_ticks: vec!["0".into(), "1".into()],
            y_ticks: vec!["a".into()],
            values: vec![vec![1.0, f64::NAN]],
            ..HeatMap::default()
        };
        let svg = h.to_svg(300, 200).unwrap();
        assert!(svg.contains("\na\n"), "{svg}");
    }
}
