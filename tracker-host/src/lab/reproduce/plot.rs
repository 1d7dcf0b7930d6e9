//! Line charts for the report, written as SVG and PNG with `plotters`.
//!
//! PNG text is drawn with the font [`crate::font`] registers, so the images come out the
//! same on every machine.

use std::path::Path;

use anyhow::{anyhow, Context};
use plotters::coord::Shift;
use plotters::prelude::*;

/// One line of a chart.
pub struct Series {
    /// Legend text.
    pub name: String,
    /// Points (x, y).
    pub points: Vec<(f64, f64)>,
    /// Drawn as dots instead of a line (e.g. noisy observations).
    pub dots: bool,
}

impl Series {
    /// A line.
    pub fn line(name: &str, points: Vec<(f64, f64)>) -> Self {
        Series {
            name: name.into(),
            points,
            dots: false,
        }
    }

    /// Dots.
    pub fn dots(name: &str, points: Vec<(f64, f64)>) -> Self {
        Series {
            name: name.into(),
            points,
            dots: true,
        }
    }
}

/// A chart: title, axis labels, series; `equal_axes` keeps metres square (trajectories).
pub struct Chart<'a> {
    /// Title above the plot.
    pub title: &'a str,
    /// X axis label.
    pub x_label: &'a str,
    /// Y axis label.
    pub y_label: &'a str,
    /// The lines.
    pub series: Vec<Series>,
    /// Same scale on both axes.
    pub equal_axes: bool,
    /// Logarithmic y axis.
    pub log_y: bool,
}

const SIZE: (u32, u32) = (900, 600);
const COLOURS: [RGBColor; 6] = [
    RGBColor(0, 0, 0),
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
];

/// Writes `DIR/NAME.svg` and `DIR/NAME.png`.
///
/// # Errors
/// A file that cannot be written, or the plotting backend failing.
pub fn write(chart: &Chart, dir: &Path, name: &str) -> anyhow::Result<()> {
    crate::font::register();
    let svg = dir.join(format!("{name}.svg"));
    draw(chart, SVGBackend::new(&svg, SIZE).into_drawing_area())
        .with_context(|| format!("plotting {}", svg.display()))?;
    let png = dir.join(format!("{name}.png"));
    draw(chart, BitMapBackend::new(&png, SIZE).into_drawing_area())
        .with_context(|| format!("plotting {}", png.display()))?;
    Ok(())
}

fn bounds(chart: &Chart) -> anyhow::Result<((f64, f64), (f64, f64))> {
    let pts = || chart.series.iter().flat_map(|s| s.points.iter());
    let finite = |v: f64| v.is_finite() && (!chart.log_y || v > 0.0);
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in pts().filter(|p| p.0.is_finite() && finite(p.1)) {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if x0 > x1 || y0 > y1 {
        return Err(anyhow!("chart '{}' has no finite point", chart.title));
    }
    if chart.equal_axes {
        let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
        let half = ((x1 - x0) / 2.0).max((y1 - y0) / 2.0 * 1.5) * 1.05;
        return Ok(((cx - half, cx + half), (cy - half / 1.5, cy + half / 1.5)));
    }
    let pad = |a: f64, b: f64| {
        let p = ((b - a) * 0.05).max(1e-9);
        (a - p, b + p)
    };
    let y = if chart.log_y {
        (y0 / 1.2, y1 * 1.2)
    } else {
        pad(y0, y1)
    };
    Ok((pad(x0, x1), y))
}

fn draw<DB: DrawingBackend>(chart: &Chart, area: DrawingArea<DB, Shift>) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| anyhow!("{e}");
    area.fill(&WHITE).map_err(err)?;
    let ((x0, x1), (y0, y1)) = bounds(chart)?;
    let mut builder = ChartBuilder::on(&area);
    builder
        .caption(chart.title, ("sans-serif", 22))
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(80);
    macro_rules! finish {
        ($ctx:expr) => {{
            let mut ctx = $ctx;
            ctx.configure_mesh()
                .x_desc(chart.x_label)
                .y_desc(chart.y_label)
                .label_style(("sans-serif", 14))
                .draw()
                .map_err(err)?;
            for (i, s) in chart.series.iter().enumerate() {
                let colour = COLOURS[i % COLOURS.len()];
                let pts = s
                    .points
                    .iter()
                    .copied()
                    .filter(|p| p.0.is_finite() && p.1.is_finite());
                let drawn = if s.dots {
                    ctx.draw_series(pts.map(|p| Circle::new(p, 2, colour.filled())))
                        .map_err(err)?
                } else {
                    ctx.draw_series(LineSeries::new(pts, colour.stroke_width(2)))
                        .map_err(err)?
                };
                drawn.label(s.name.as_str()).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(3))
                });
            }
            ctx.configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 14))
                .draw()
                .map_err(err)?;
        }};
    }
    if chart.log_y {
        finish!(builder
            .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
            .map_err(err)?);
    } else {
        finish!(builder.build_cartesian_2d(x0..x1, y0..y1).map_err(err)?);
    }
    area.present().map_err(err)?;
    Ok(())
}
