//! SVG and PNG plots (plotters, pure Rust: the font is embedded, no system libraries).

use std::path::Path;
use std::sync::Once;

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

/// One labelled curve.
pub struct Series<'a> {
    pub label: String,
    pub points: &'a [(f64, f64)],
}

const COLORS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

fn bounds(series: &[Series<'_>], log: bool) -> Option<((f64, f64), (f64, f64))> {
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

fn draw<DB: DrawingBackend>(
    area: DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    xlabel: &str,
    ylabel: &str,
    series: &[Series<'_>],
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
    let mut builder = ChartBuilder::on(&area);
    builder
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70);
    macro_rules! finish {
        ($chart:expr) => {{
            let mut chart = $chart;
            chart
                .configure_mesh()
                .x_desc(xlabel)
                .y_desc(ylabel)
                .x_labels(7)
                .y_labels(8)
                .x_label_formatter(&|v| format!("{v:.1e}"))
                .y_label_formatter(&|v| format!("{v:.1e}"))
                .draw()
                .map_err(|e| err(&e))?;
            for (i, s) in series.iter().enumerate() {
                let color = COLORS[i % COLORS.len()];
                let pts: Vec<(f64, f64)> = s
                    .points
                    .iter()
                    .copied()
                    .filter(|(x, y)| {
                        x.is_finite() && y.is_finite() && (!log || (*x > 0.0 && *y > 0.0))
                    })
                    .collect();
                chart
                    .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
                    .map_err(|e| err(&e))?
                    .label(s.label.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], color));
                if log {
                    chart
                        .draw_series(pts.iter().map(|p| Circle::new(*p, 3, color.filled())))
                        .map_err(|e| err(&e))?;
                }
            }
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()
                .map_err(|e| err(&e))?;
        }};
    }
    if log {
        finish!(
            builder
                .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
                .map_err(|e| err(&e))?
        );
    } else {
        finish!(
            builder
                .build_cartesian_2d(x0..x1, y0..y1)
                .map_err(|e| err(&e))?
        );
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
    register_font();
    std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    let (w, h) = (900u32, 560u32);
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
        let png = std::fs::read(dir.join("test.png")).unwrap();
        assert_eq!(&png[1..4], b"PNG");
        plot(&dir, "lin", "t", "x", "y", &series, false).unwrap();
        assert!(plot(&dir, "empty", "t", "x", "y", &[], true).is_err());
    }
}
