//! SVG and PNG plots (plotters, pure Rust: the font is embedded, no system libraries).
//!
//! Conventions of every plot: ticks at 1, 2, 5 × 10^k (log axes at decades when they span
//! three or more), labels written as plain decimals between 10⁻³ and 10⁴ and as `m×10ᵏ`
//! outside; the legend in a panel right of the data, never over it; a series whose label
//! starts with a backend name (`fem`, `fdm`, `modal`, `reference`) always takes that
//! backend's colour, so the same backend looks the same on every page.

use std::path::Path;
use std::sync::Once;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

static FONT: Once = Once::new();

fn register_font() {
    FONT.call_once(|| {
        // The bitmap backend panics when it has to draw text without a font: register one
        // embedded in the binary so plots work on any machine.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            include_bytes!("../assets/DejaVuSans.ttf"),
        );
    });
}

/// One labelled curve, drawn as a line (with markers on log axes).
pub struct Series<'a> {
    pub label: String,
    pub points: &'a [(f64, f64)],
}

/// How a [`StyledSeries`] is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mark {
    /// A line through the points, with markers on log axes.
    Line,
    /// Markers only (a scatter of measurements).
    Points,
    /// A thick dark staircase line (a Pareto front): no markers.
    Front,
}

/// A curve with an explicit drawing style.
pub struct StyledSeries<'a> {
    pub label: String,
    pub points: &'a [(f64, f64)],
    pub mark: Mark,
}

/// Colours of the backends (the same on every plot) and of other series, in order.
const BACKEND_COLORS: [(&str, RGBColor); 4] = [
    ("fem", RGBColor(31, 119, 180)),
    ("fdm", RGBColor(214, 39, 40)),
    ("modal", RGBColor(44, 160, 44)),
    ("reference", RGBColor(110, 110, 110)),
];
const OTHER_COLORS: [RGBColor; 5] = [
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
];

/// The colour of the backend a label names (`fem`, `fem (order 4.00)`, `modal(modes=8)`).
pub fn backend_color(label: &str) -> Option<RGBColor> {
    BACKEND_COLORS.iter().find_map(|(name, c)| {
        let rest = label.strip_prefix(name)?;
        (rest.is_empty() || rest.starts_with([' ', '(', ':', ','])).then_some(*c)
    })
}

/// `#rrggbb` of a backend's colour, for the HTML pages.
pub fn backend_css_color(name: &str) -> Option<String> {
    backend_color(name).map(|c| format!("#{:02x}{:02x}{:02x}", c.0, c.1, c.2))
}

fn series_colors(series: &[StyledSeries<'_>]) -> Vec<RGBColor> {
    let mut others = OTHER_COLORS.iter().cycle();
    series
        .iter()
        .map(|s| match s.mark {
            Mark::Front => RGBColor(30, 30, 30),
            _ => backend_color(&s.label).unwrap_or_else(|| *others.next().expect("cycle")),
        })
        .collect()
}

/// Ticks at multiples of 1, 2 or 5 × 10^k covering [lo, hi] with about `target` ticks.
pub fn linear_ticks(lo: f64, hi: f64, target: usize) -> Vec<f64> {
    if hi <= lo || !lo.is_finite() || !hi.is_finite() {
        return vec![lo];
    }
    let raw = (hi - lo) / target.max(2) as f64;
    let k = raw.log10().floor();
    let base = 10f64.powf(k);
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * base)
        .find(|s| *s >= raw * (1.0 - 1e-12))
        .unwrap_or(10.0 * base);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last)
        .map(|i| {
            let v = i as f64 * step;
            // Snap round-off (0.30000000000000004) to the decimal the step implies.
            if v.abs() < step * 1e-9 { 0.0 } else { v }
        })
        .collect()
}

/// Ticks of a log axis on [lo, hi] (lo > 0): decades when three or more fall inside, else
/// 1, 2, 5 × 10^k, else linear 1-2-5 ticks (a range narrower than a factor 2.5).
pub fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    if hi <= lo || lo <= 0.0 || !hi.is_finite() {
        return vec![lo];
    }
    let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let inside = |v: &f64| *v >= lo * (1.0 - 1e-12) && *v <= hi * (1.0 + 1e-12);
    let decades: Vec<f64> = (k0..=k1).map(|k| 10f64.powi(k)).filter(inside).collect();
    if decades.len() >= 3 {
        // Keep at most about eight labels: every n-th decade.
        let every = decades.len().div_ceil(8);
        return decades
            .into_iter()
            .enumerate()
            .filter(|(i, _)| i % every == 0)
            .map(|(_, v)| v)
            .collect();
    }
    let fine: Vec<f64> = (k0..=k1)
        .flat_map(|k| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(k)))
        .filter(inside)
        .collect();
    if fine.len() >= 2 {
        fine
    } else {
        linear_ticks(lo, hi, 4)
            .into_iter()
            .filter(|v| *v > 0.0)
            .collect()
    }
}

fn superscript(n: i32) -> String {
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::new();
    if n < 0 {
        s.push('⁻');
    }
    for c in n.unsigned_abs().to_string().chars() {
        s.push(DIGITS[c.to_digit(10).expect("digit") as usize]);
    }
    s
}

/// Shortest decimal of `v` with at most `max_decimals` decimals (trailing zeros cut).
fn decimal(v: f64, max_decimals: usize) -> String {
    let s = format!("{v:.max_decimals$}");
    let s = if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    };
    if s == "-0" { "0".into() } else { s }
}

/// Whether an axis with these ticks labels them as powers of ten: when any non-zero tick lies
/// outside 10⁻³ ≤ |v| < 10⁴ (one style per axis, never `0.001` beside `10⁻⁴`).
fn powers_of_ten(ticks: &[f64]) -> bool {
    ticks
        .iter()
        .any(|v| *v != 0.0 && (v.abs() < 1e-3 * (1.0 - 1e-12) || v.abs() >= 1e4))
}

/// A tick label in the axis' style: a plain decimal (`0.002`, `50`, `1.5`) or a power of ten
/// (`2×10⁻⁵`, `10⁶`).
pub fn axis_tick_label(v: f64, powers: bool) -> String {
    if v == 0.0 || !v.is_finite() {
        return "0".into();
    }
    let e = exponent(v);
    if !powers {
        // Ticks are multiples of 1, 2 or 5 × 10^k: three significant digits are plenty.
        return decimal(v, (2 - e).max(0) as usize);
    }
    let m = v / 10f64.powi(e);
    let mant = decimal(m, 2);
    match mant.as_str() {
        "1" => format!("10{}", superscript(e)),
        "-1" => format!("-10{}", superscript(e)),
        _ => format!("{mant}×10{}", superscript(e)),
    }
}

/// The decimal exponent of |v| (exact for powers of ten).
fn exponent(v: f64) -> i32 {
    let e = v.abs().log10().floor() as i32;
    // Guard against 9.999… for an exact power of ten.
    if 10f64.powi(e + 1) <= v.abs() * (1.0 + 1e-12) {
        e + 1
    } else {
        e
    }
}

/// A tick label: `0.002`, `50`, `1.5`, or `2×10⁻⁵`, `10⁶` outside 10⁻³ ≤ |v| < 10⁴.
pub fn tick_label(v: f64) -> String {
    axis_tick_label(v, powers_of_ten(&[v]))
}

fn bounds(series: &[StyledSeries<'_>], log: bool) -> Option<((f64, f64), (f64, f64))> {
    let pts = series
        .iter()
        .flat_map(|s| s.points.iter())
        .filter(|(x, y)| x.is_finite() && y.is_finite() && (!log || (*x > 0.0 && *y > 0.0)));
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    let mut any = false;
    for &(x, y) in pts {
        any = true;
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if !any {
        return None;
    }
    if log {
        Some(((x0 / 1.5, x1 * 1.5), (y0 / 2.0, y1 * 2.0)))
    } else {
        let pad = |a: f64, b: f64| {
            let d = if b > a {
                0.05 * (b - a)
            } else {
                a.abs().max(1.0) * 0.05
            };
            (a - d, b + d)
        };
        Some((pad(x0, x1), pad(y0, y1)))
    }
}

/// An axis with the given tick positions (plotters' own `WithKeyPoints` carries no default
/// label formatting, which the mesh needs).
struct Ticked<R: Ranged<ValueType = f64>> {
    inner: R,
    ticks: Vec<f64>,
}

impl<R: Ranged<ValueType = f64>> Ranged for Ticked<R> {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<Hint: plotters::coord::ranged1d::KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        // Bold points (labels and grid) only: no light grid between ticks.
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }
}

/// Width of the legend panel right of the chart, pixels.
const LEGEND_WIDTH: u32 = 230;

/// Cuts a legend label to what fits the panel.
fn legend_text(label: &str) -> String {
    const MAX: usize = 30;
    if label.chars().count() <= MAX {
        label.to_string()
    } else {
        let mut s: String = label.chars().take(MAX - 1).collect();
        s.push('…');
        s
    }
}

fn draw<DB: DrawingBackend>(
    area: DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    xlabel: &str,
    ylabel: &str,
    series: &[StyledSeries<'_>],
    log: bool,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: &dyn std::fmt::Display| e.to_string();
    area.fill(&WHITE).map_err(|e| err(&e))?;
    let Some(((x0, x1), (y0, y1))) = bounds(series, log) else {
        return Err("nothing to plot".into());
    };
    let area = area
        .titled(title, ("sans-serif", 19))
        .map_err(|e| err(&e))?;
    let (w, _) = area.dim_in_pixel();
    let (chart_area, legend_area) = area.split_horizontally(w.saturating_sub(LEGEND_WIDTH));
    let colors = series_colors(series);
    let mut builder = ChartBuilder::on(&chart_area);
    builder
        .margin(12)
        .x_label_area_size(48)
        .y_label_area_size(78);
    macro_rules! finish {
        ($chart:expr, $x_ticks:expr, $y_ticks:expr) => {{
            let (x_powers, y_powers) = (powers_of_ten($x_ticks), powers_of_ten($y_ticks));
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_desc(xlabel)
                .y_desc(ylabel)
                .label_style(("sans-serif", 17))
                .axis_desc_style(("sans-serif", 17))
                .bold_line_style(RGBColor(225, 225, 225))
                .x_label_formatter(&|v| axis_tick_label(*v, x_powers))
                .y_label_formatter(&|v| axis_tick_label(*v, y_powers))
                .draw()
                .map_err(|e| err(&e))?;
            for (i, (s, color)) in series.iter().zip(&colors).enumerate() {
                let color = *color;
                // The first curve wide and pale, later ones narrow on top of it: curves that
                // agree stay visible both.
                let line = if i == 0 && series.len() > 1 {
                    color.mix(0.5).stroke_width(5)
                } else {
                    color.stroke_width(2)
                };
                let pts: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|(x, y)| {
                        x.is_finite() && y.is_finite() && (!log || (*x > 0.0 && *y > 0.0))
                    })
                    .collect();
                match s.mark {
                    Mark::Line => {
                        chart
                            .draw_series(LineSeries::new(pts.clone(), line))
                            .map_err(|e| err(&e))?;
                        if log {
                            chart
                                .draw_series(pts.iter().map(|p| Circle::new(*p, 3, color.filled())))
                                .map_err(|e| err(&e))?;
                        }
                    }
                    Mark::Points => {
                        chart
                            .draw_series(pts.iter().map(|p| Circle::new(*p, 4, color.filled())))
                            .map_err(|e| err(&e))?;
                    }
                    Mark::Front => {
                        // A staircase: cost is paid before the error drops.
                        let mut stairs = Vec::new();
                        for (i, p) in pts.iter().enumerate() {
                            if i > 0 {
                                stairs.push((p.0, pts[i - 1].1));
                            }
                            stairs.push(*p);
                        }
                        chart
                            .draw_series(LineSeries::new(stairs, color.stroke_width(2)))
                            .map_err(|e| err(&e))?;
                    }
                }
            }
        }};
    }
    if log {
        let (xt, yt) = (log_ticks(x0, x1), log_ticks(y0, y1));
        let x = Ticked {
            inner: LogCoord::from((x0..x1).log_scale()),
            ticks: xt.clone(),
        };
        let y = Ticked {
            inner: LogCoord::from((y0..y1).log_scale()),
            ticks: yt.clone(),
        };
        finish!(
            builder.build_cartesian_2d(x, y).map_err(|e| err(&e))?,
            &xt,
            &yt
        );
    } else {
        let (xt, yt) = (linear_ticks(x0, x1, 7), linear_ticks(y0, y1, 7));
        let x = Ticked {
            inner: RangedCoordf64::from(x0..x1),
            ticks: xt.clone(),
        };
        let y = Ticked {
            inner: RangedCoordf64::from(y0..y1),
            ticks: yt.clone(),
        };
        finish!(
            builder.build_cartesian_2d(x, y).map_err(|e| err(&e))?,
            &xt,
            &yt
        );
    }
    // The legend, in its own panel right of the chart.
    let font = ("sans-serif", 17).into_font().color(&BLACK);
    for (i, (s, color)) in series.iter().zip(&colors).enumerate() {
        let y = 24 + 26 * i as i32;
        let color = *color;
        match s.mark {
            Mark::Points => legend_area.draw(&Circle::new((22, y), 4, color.filled())),
            Mark::Line if i == 0 && series.len() > 1 => legend_area.draw(&PathElement::new(
                vec![(8, y), (34, y)],
                color.mix(0.5).stroke_width(5),
            )),
            _ => legend_area.draw(&PathElement::new(
                vec![(8, y), (34, y)],
                color.stroke_width(2),
            )),
        }
        .map_err(|e| err(&e))?;
        legend_area
            .draw(&Text::new(legend_text(&s.label), (42, y - 8), font.clone()))
            .map_err(|e| err(&e))?;
    }
    area.present().map_err(|e| err(&e))?;
    Ok(())
}

/// Writes `<stem>.svg` and `<stem>.png` into `dir` (each atomically).
pub fn plot(
    dir: &Path,
    stem: &str,
    title: &str,
    xlabel: &str,
    ylabel: &str,
    series: &[Series<'_>],
    log: bool,
) -> Result<(), String> {
    let styled: Vec<StyledSeries<'_>> = series
        .iter()
        .map(|s| StyledSeries {
            label: s.label.clone(),
            points: s.points,
            mark: Mark::Line,
        })
        .collect();
    plot_styled(dir, stem, title, xlabel, ylabel, &styled, log)
}

/// [`plot`] with a drawing style per series.
pub fn plot_styled(
    dir: &Path,
    stem: &str,
    title: &str,
    xlabel: &str,
    ylabel: &str,
    series: &[StyledSeries<'_>],
    log: bool,
) -> Result<(), String> {
    register_font();
    std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    let (w, h) = (900u32, 500u32);
    let mut svg = String::new();
    {
        let area = SVGBackend::with_string(&mut svg, (w, h)).into_drawing_area();
        draw(area, title, xlabel, ylabel, series, log)?;
    }
    crate::output::write_atomic(dir, &format!("{stem}.svg"), svg.as_bytes())
        .map_err(|e| e.to_string())?;
    // The bitmap backend encodes PNG by file extension on `present`: draw into a temporary
    // .png and rename it, so readers never see a half-written image.
    let tmp = dir.join(format!(".{stem}.{}.tmp.png", std::process::id()));
    {
        let area = BitMapBackend::new(&tmp, (w, h)).into_drawing_area();
        draw(area, title, xlabel, ylabel, series, log)?;
    }
    std::fs::rename(&tmp, dir.join(format!("{stem}.png"))).map_err(|e| e.to_string())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plot_writes_svg_and_png_with_text() {
        let dir = std::env::temp_dir().join(format!("flexverify-plot-{}", std::process::id()));
        let pts: Vec<(f64, f64)> = (1..20).map(|k| (k as f64, (k as f64).powi(-2))).collect();
        let series = [Series {
            label: "h^-2".into(),
            points: &pts,
        }];
        plot(&dir, "test", "title", "x", "y", &series, true).unwrap();
        let svg = std::fs::read_to_string(dir.join("test.svg")).unwrap();
        assert!(svg.contains("<svg") && svg.contains("title"));
        assert!(
            !svg.contains("e0<") && !svg.contains(".0e"),
            "scientific tick labels"
        );
        let png = std::fs::read(dir.join("test.png")).unwrap();
        assert_eq!(&png[1..4], b"PNG");
        plot(&dir, "lin", "t", "x", "y", &series, false).unwrap();
        assert!(plot(&dir, "empty", "t", "x", "y", &[], true).is_err());
    }

    #[test]
    fn ticks_are_one_two_five_times_powers_of_ten() {
        let is_125 = |v: f64| {
            let e = v.abs().log10().floor();
            let m = v.abs() / 10f64.powf(e);
            [1.0, 2.0, 5.0, 10.0].iter().any(|n| (m - n).abs() < 1e-9)
        };
        // Linear: the step is 1, 2 or 5 × 10^k; every tick a multiple of it.
        for (lo, hi) in [(0.0, 10.0), (-0.37, 0.81), (3.2e-5, 9.1e-5), (0.0, 15.0)] {
            let t = linear_ticks(lo, hi, 7);
            assert!(t.len() >= 3 && t.len() <= 11, "{lo}..{hi}: {t:?}");
            assert!(is_125(t[1] - t[0]), "{lo}..{hi}: step {}", t[1] - t[0]);
            assert!(t.iter().all(|v| *v >= lo && *v <= hi));
        }
        // Log: decades over a wide range, 1-2-5 over a narrow one.
        assert_eq!(
            log_ticks(3e-9, 2e-3),
            vec![1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3]
        );
        let narrow = log_ticks(1.5e-4, 2.1e-3);
        assert!(
            narrow.len() >= 3 && narrow.iter().all(|v| is_125(*v)),
            "{narrow:?}"
        );
    }

    #[test]
    fn tick_labels_read_as_numbers() {
        assert_eq!(tick_label(5.0), "5");
        assert_eq!(tick_label(10.0), "10");
        assert_eq!(tick_label(0.002), "0.002");
        assert_eq!(tick_label(1.5), "1.5");
        assert_eq!(tick_label(-0.25), "-0.25");
        assert_eq!(tick_label(1e-5), "10⁻⁵");
        assert_eq!(tick_label(2e-5), "2×10⁻⁵");
        assert_eq!(tick_label(1e6), "10⁶");
        assert_eq!(tick_label(0.0), "0");
        // One style per axis.
        let ticks = log_ticks(2e-5, 3e-3);
        let powers = powers_of_ten(&ticks);
        assert!(powers);
        assert_eq!(axis_tick_label(1e-3, powers), "10⁻³");
        assert_eq!(axis_tick_label(0.5, powers_of_ten(&[0.0, 0.5, 1.0])), "0.5");
    }

    #[test]
    fn backends_keep_their_colour() {
        assert_eq!(backend_color("fem"), backend_color("fem (order 4.00)"));
        assert_eq!(backend_color("modal"), backend_color("modal(modes=8)"));
        assert_ne!(backend_color("fem"), backend_color("fdm"));
        assert_eq!(backend_color("femur"), None);
        assert_eq!(backend_css_color("fdm").as_deref(), Some("#d62728"));
    }
}
