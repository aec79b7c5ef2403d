//! What a figure of `treelet bench` is: its points and JSON document, the
//! device it runs on, its table and plot.
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use indicatif::{ProgressBar, ProgressStyle};
use serde::{Deserialize, Serialize};
use treelet::internals::plot::{chart, Chart, Series};

use super::measure::median;
use treelet::runtime::device::DeviceChoice;

/// The file name of `bench error`'s second figure, against kernel time.
pub(crate) const ERROR_KERNEL: &str = "error-kernel";

/// The figures: the seed's five, then three it lacks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Figure {
    /// Graph 1: render time against samples per pixel, GPU and CPU runner (cornell).
    #[value(name = "graph1")]
    Graph1,
    /// Graph 2: render time against scene size, linear scan against BVHs.
    #[value(name = "graph2")]
    Graph2,
    /// Graph 2.5: BVH build time against size (LBVH on the device; CPU builders, peers).
    #[value(name = "graph2.5")]
    Graph25,
    /// Graph 3: render time against size, LBVH against the optimized BVHs.
    #[value(name = "graph3")]
    Graph3,
    /// Graph 3.5: treelet-optimization time against size.
    #[value(name = "graph3.5")]
    Graph35,
    /// RMSE against wall and kernel time for each integrator (and Mitsuba 3).
    #[value(name = "error")]
    Error,
    /// SAH cost against build time for every builder (Pareto plot).
    #[value(name = "pareto")]
    Pareto,
    /// Primary and diffuse rays per second through each tree.
    #[value(name = "rays")]
    Rays,
    /// Every figure, then RESULTS.md.
    #[value(name = "all")]
    All,
}

impl Figure {
    pub(crate) const EACH: [Figure; 8] = [
        Figure::Graph1,
        Figure::Graph2,
        Figure::Graph25,
        Figure::Graph3,
        Figure::Graph35,
        Figure::Error,
        Figure::Pareto,
        Figure::Rays,
    ];

    /// File names of the figures, in order (`error` makes two).
    pub fn names() -> impl Iterator<Item = &'static str> {
        Self::EACH.into_iter().flat_map(|f| match f {
            Figure::Error => vec![f.name(), ERROR_KERNEL],
            _ => vec![f.name()],
        })
    }

    pub(crate) fn name(self) -> &'static str {
        match self {
            Figure::Graph1 => "graph1",
            Figure::Graph2 => "graph2",
            Figure::Graph25 => "graph2.5",
            Figure::Graph3 => "graph3",
            Figure::Graph35 => "graph3.5",
            Figure::Error => "error",
            Figure::Pareto => "pareto",
            Figure::Rays => "rays",
            Figure::All => "all",
        }
    }
}

/// One measurement: a point of one series.
#[derive(Clone, Serialize, Deserialize)]
pub struct Point {
    pub series: String,
    pub x: f64,
    pub median: f64,
    pub min: f64,
    pub max: f64,
    pub repeats: usize,
}

impl Point {
    pub(crate) fn of(series: impl Into<String>, x: f64, samples: &[f64]) -> Point {
        Point {
            series: series.into(),
            x,
            median: median(samples.to_vec()),
            min: samples.iter().copied().fold(f64::MAX, f64::min),
            max: samples.iter().copied().fold(f64::MIN, f64::max),
            repeats: samples.len(),
        }
    }

    pub(crate) fn once(series: impl Into<String>, x: f64, y: f64) -> Point {
        Point::of(series, x, &[y])
    }
}

/// Everything a figure's JSON holds.
#[derive(Serialize, Deserialize)]
pub struct FigureDoc {
    pub figure: String,
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub log_x: bool,
    pub log_y: bool,
    pub scatter: bool,
    pub device: String,
    pub adapter: String,
    pub date: String,
    pub command: String,
    pub quick: bool,
    pub parameters: serde_json::Value,
    pub notes: Vec<String>,
    pub points: Vec<Point>,
}

/// What every figure runs on.
pub struct Suite {
    pub device: DeviceChoice,
    pub quick: bool,
    pub out: PathBuf,
    pub repeats: usize,
    /// Mitsuba 3's images of the disk-lit room (`bench error --mitsuba`).
    pub mitsuba: Option<PathBuf>,
}


pub(crate) fn write_figure(dir: &Path, doc: &FigureDoc) -> Result<()> {
    let json = dir.join(format!("{}.json", doc.figure));
    std::fs::write(&json, serde_json::to_string_pretty(doc)?).with_context(|| format!("writing {}", json.display()))?;
    plot_figure(dir, doc)
}

/// `dir/<figure>.png` from the figure's points (medians).
pub fn plot_figure(dir: &Path, doc: &FigureDoc) -> Result<()> {
    let mut names: Vec<&str> = Vec::new();
    for p in &doc.points {
        if !names.contains(&p.series.as_str()) {
            names.push(&p.series);
        }
    }
    let series: Vec<Series> = names
        .iter()
        .map(|n| Series {
            label: n.to_string(),
            points: doc.points.iter().filter(|p| p.series == *n).map(|p| (p.x, p.median)).collect(),
        })
        .collect();
    let c = Chart {
        title: &doc.title,
        x_label: &doc.x_label,
        y_label: &doc.y_label,
        log_x: doc.log_x,
        log_y: doc.log_y,
        scatter: doc.scatter,
    };
    chart(&dir.join(format!("{}.png", doc.figure)), &c, &series)
}

/// The figure as a table: header and rows. Rows are x values and columns
/// series (medians) where the series share their x values; otherwise (a
/// Pareto plot, error against time) one row per point.
pub fn table(doc: &FigureDoc) -> (Vec<String>, Vec<Vec<String>>) {
    let mut names: Vec<String> = Vec::new();
    let mut xs: Vec<f64> = Vec::new();
    for p in &doc.points {
        if !names.contains(&p.series) {
            names.push(p.series.clone());
        }
        if !xs.contains(&p.x) {
            xs.push(p.x);
        }
    }
    let x_name = doc.x_label.clone();
    if doc.scatter || xs.len() * 2 > doc.points.len() + 1 {
        let header = vec!["series".to_string(), x_name, doc.y_label.clone()];
        let rows = doc.points.iter().map(|p| vec![p.series.clone(), fmt(p.x), fmt(p.median)]).collect();
        return (header, rows);
    }
    xs.sort_by(f64::total_cmp);
    let mut header = vec![x_name];
    header.extend(names.iter().cloned());
    let rows = xs
        .iter()
        .map(|&x| {
            let mut row = vec![fmt(x)];
            for n in &names {
                row.push(match doc.points.iter().find(|p| p.series == *n && p.x == x) {
                    Some(p) => fmt(p.median),
                    None => String::new(),
                });
            }
            row
        })
        .collect();
    (header, rows)
}

pub fn fmt(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.fract() == 0.0 && v.abs() < 1e9 {
        format!("{v:.0}")
    } else if v.abs() >= 1e5 || v.abs() < 1e-3 {
        format!("{v:.3e}")
    } else if v.abs() >= 100.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.4}")
    }
}

pub(crate) fn print_table(doc: &FigureDoc) {
    println!("{} — {} ({})", doc.figure, doc.title, doc.adapter);
    println!("y: {}", doc.y_label);
    let (header, rows) = table(doc);
    let widths: Vec<usize> = (0..header.len())
        .map(|i| rows.iter().map(|r| r[i].len()).chain([header[i].len()]).max().unwrap_or(0) + 2)
        .collect();
    for (h, w) in header.iter().zip(&widths) {
        print!("{h:>w$}");
    }
    println!();
    for r in rows {
        for (c, w) in r.iter().zip(&widths) {
            print!("{c:>w$}");
        }
        println!();
    }
    for n in &doc.notes {
        println!("note: {n}");
    }
}

pub(crate) fn bar(len: usize, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len as u64);
    bar.set_style(ProgressStyle::with_template(&format!("{{bar:40}} {{pos}}/{{len}} {what} {{msg}}")).unwrap());
    bar
}

pub(crate) fn doc(figure: Figure, title: &str, x: &str, y: &str, (log_x, log_y): (bool, bool)) -> FigureDoc {
    FigureDoc {
        figure: figure.name().into(),
        title: title.into(),
        x_label: x.into(),
        y_label: y.into(),
        log_x,
        log_y,
        scatter: false,
        device: String::new(),
        adapter: String::new(),
        date: String::new(),
        command: String::new(),
        quick: false,
        parameters: serde_json::Value::Null,
        notes: Vec::new(),
        points: Vec::new(),
    }
}
