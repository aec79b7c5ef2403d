//! Log-log plots of error against time (plotters, PNG), with the Monte
//! Carlo slope of -1/2 drawn through the first point for comparison.
use std::path::Path;

use anyhow::{anyhow, bail, Context, Result};
use plotters::prelude::*;

/// Registers the embedded DejaVu Sans as "sans-serif" once (plotters draws
/// text with it; no system fonts are needed).
fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular());
    });
}

/// Axis numbers: plain where that is short, scientific otherwise.
fn short(v: f64) -> String {
    if (0.01..10_000.0).contains(&v.abs()) {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.1e}")
    }
}

/// One curve: a label and its (time in s, error) points.
pub struct Series {
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

/// Writes a log-log plot of error against time to `path` (PNG), with the
/// Monte Carlo slope (error ∝ time^-1/2) drawn through the first point.
pub fn error_vs_time(path: &Path, title: &str, y_label: &str, series: &[Series]) -> Result<()> {
    let positive = |p: &&(f64, f64)| p.0 > 0.0 && p.1 > 0.0;
    let count = series.iter().flat_map(|s| s.points.iter()).filter(positive).count();
    if count < 2 {
        bail!("not enough positive points to plot ({count})");
    }
    let x1 = series.iter().flat_map(|s| s.points.iter()).filter(positive).fold(0.0f64, |a, p| a.max(p.0));
    let mut all: Vec<Series> = series.iter().map(|s| Series { label: s.label.clone(), points: s.points.clone() }).collect();
    if let Some(&(tx, ty)) = series.first().and_then(|s| s.points.iter().find(positive)) {
        all.push(Series { label: "slope -1/2".into(), points: vec![(tx, ty), (x1, ty * (x1 / tx).powf(-0.5))] });
    }
    let c = Chart { title, x_label: "time (s)", y_label, log_x: true, log_y: true, scatter: false };
    chart(path, &c, &all)
}

/// How [`chart`] draws a figure.
pub struct Chart<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub log_x: bool,
    pub log_y: bool,
    /// Points only, each labelled with its series (a Pareto plot), instead of lines.
    pub scatter: bool,
}

/// Writes a plot of `series` (x, y) to `path` (PNG): lines with markers, or
/// labelled points; log axes where asked (non-positive values are dropped there).
pub fn chart(path: &Path, c: &Chart, series: &[Series]) -> Result<()> {
    // Drawn into memory and written by `image` (plotters' own PNG writer
    // would build a second, older `image` crate: 12% of a cold build's CPU
    // time went to such duplicates).
    let (width, height) = (1000u32, 650u32);
    let mut pixels = vec![0u8; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (width, height)).into_drawing_area();
        draw_chart(&root, path, c, series)?;
        root.present().map_err(|e| anyhow!("plotting {}: {e}", path.display()))?;
    }
    let image = image::RgbImage::from_raw(width, height, pixels).expect("a buffer of the chart's size");
    image.save(path).with_context(|| format!("writing {}", path.display()))
}

/// Draws [`chart`]'s figure on `root` (`path` names it in errors).
fn draw_chart(root: &DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>, path: &Path, c: &Chart, series: &[Series]) -> Result<()> {
    register_font();
    let keep = |&(x, y): &(f64, f64)| x.is_finite() && y.is_finite() && (!c.log_x || x > 0.0) && (!c.log_y || y > 0.0);
    let all: Vec<(f64, f64)> = series.iter().flat_map(|s| s.points.iter().copied()).filter(keep).collect();
    if all.is_empty() {
        bail!("nothing to plot in {}", path.display());
    }
    let (x0, x1) = all.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.0), b.max(p.0)));
    let (y0, y1) = all.iter().fold((f64::MAX, f64::MIN), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let range = |lo: f64, hi: f64, log: bool| {
        if log {
            (lo / 1.5, hi * 1.5)
        } else {
            let pad = ((hi - lo) * 0.08).max(hi.abs() * 0.02).max(1e-9);
            (lo - pad, hi + pad)
        }
    };
    let ((mut xa, mut xb), (ya, yb)) = (range(x0, x1, c.log_x), range(y0, y1, c.log_y));
    if c.scatter {
        // Room on the right for the points' labels.
        (xa, xb) = if c.log_x { (xa, xb * 4.0) } else { (xa, xb + (xb - xa) * 0.3) };
    }
    let err = |e: &dyn std::fmt::Display| anyhow!("plotting {}: {e}", path.display());
    root.fill(&WHITE).map_err(|e| err(&e))?;
    // Fourteen distinguishable colours (figures compare up to that many series).
    let colors = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(255, 127, 14),
        RGBColor(148, 103, 189),
        RGBColor(140, 86, 75),
        RGBColor(227, 119, 194),
        RGBColor(90, 90, 90),
        RGBColor(188, 189, 34),
        RGBColor(23, 190, 207),
        RGBColor(0, 0, 128),
        RGBColor(0, 128, 128),
        RGBColor(128, 0, 0),
        RGBColor(0, 0, 0),
    ];
    // The four axis combinations are four chart types in plotters.
    macro_rules! draw {
        ($x:expr, $y:expr) => {{
            let mut chart = ChartBuilder::on(root)
                .caption(c.title, ("sans-serif", 22))
                .margin(15)
                .x_label_area_size(45)
                .y_label_area_size(80)
                .build_cartesian_2d($x, $y)
                .map_err(|e| err(&e))?;
            chart
                .configure_mesh()
                .x_desc(c.x_label)
                .y_desc(c.y_label)
                .x_label_formatter(&|v| short(*v))
                .y_label_formatter(&|v| short(*v))
                .label_style(("sans-serif", 15))
                .draw()
                .map_err(|e| err(&e))?;
            for (i, s) in series.iter().enumerate() {
                let color = colors[i % colors.len()];
                let pts: Vec<_> = s.points.iter().copied().filter(keep).collect();
                if c.scatter {
                    // Each point carries its label: no legend to cover them.
                    let label = s.label.clone();
                    chart.draw_series(pts.iter().map(|&p| Circle::new(p, 6, color.filled()))).map_err(|e| err(&e))?;
                    chart
                        .draw_series(pts.iter().map(|&p| {
                            EmptyElement::at(p)
                                + Text::new(label.clone(), (8, -6), ("sans-serif", 13).into_font().color(&color))
                        }))
                        .map_err(|e| err(&e))?;
                } else {
                    chart
                        .draw_series(LineSeries::new(pts.clone(), color.stroke_width(2)))
                        .map_err(|e| err(&e))?
                        .label(&s.label)
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2)));
                    chart.draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled()))).map_err(|e| err(&e))?;
                }
            }
            if c.scatter {
                return Ok(());
            }
            // The legend goes to the upper corner the curves leave free.
            let (left, right) = first_and_last_mean(series);
            let corner = if left < right { SeriesLabelPosition::UpperLeft } else { SeriesLabelPosition::UpperRight };
            chart
                .configure_series_labels()
                .position(corner)
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .label_font(("sans-serif", 15))
                .draw()
                .map_err(|e| err(&e))?;
        }};
    }
    match (c.log_x, c.log_y) {
        (true, true) => draw!((xa..xb).log_scale(), (ya..yb).log_scale()),
        (true, false) => draw!((xa..xb).log_scale(), ya..yb),
        (false, true) => draw!(xa..xb, (ya..yb).log_scale()),
        (false, false) => draw!(xa..xb, ya..yb),
    }
    Ok(())
}

/// Mean y of the points at the smallest and at the largest x of each series
/// (of their first and last points): which side of a chart the curves rise on.
fn first_and_last_mean(series: &[Series]) -> (f64, f64) {
    let (mut a, mut b, mut n) = (0.0, 0.0, 0.0);
    for s in series {
        if let (Some(f), Some(l)) = (s.points.first(), s.points.last()) {
            a += f.1;
            b += l.1;
            n += 1.0;
        }
    }
    if n > 0.0 {
        (a / n, b / n)
    } else {
        (0.0, 0.0)
    }
}
