//! `--snapshot PATH`: a PNG of the run's last scan as a radar display would show it, north
//! up, own ship at the centre: the rotation's echoes (a radar source's; green, brighter for
//! stronger), the extracted plots (yellow), the targets with their numbers and true vectors
//! (cyan, red when dangerous; as long as the time in the caption, which grows with the
//! range), AIS targets not paired with a target (magenta triangles), range rings. For a
//! person to check the extraction and the tracking by eye.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::Context;
use plotters::prelude::*;

use crate::ais::AisTargetData;
use crate::radar::EchoImage;
use crate::session::target::{AlarmLimits, TargetData};
use crate::session::ScanReport;
use crate::sink::ScanSink;
use crate::source::SourceScan;

const SIZE: u32 = 1000;

#[derive(Clone, Debug)]
struct Last {
    scan: u32,
    echoes: Option<Arc<EchoImage>>,
    plots_m: Vec<[f32; 2]>,
    own_m: [f32; 2],
    targets: Vec<TargetData>,
    ais: Vec<AisTargetData>,
    paired: Vec<u32>,
}

/// Keeps the last scan and draws it when the run ends.
pub struct Snapshot {
    path: PathBuf,
    limits: AlarmLimits,
    last: Option<Last>,
}

impl Snapshot {
    /// A snapshot to be written to `path` (PNG).
    pub fn new(path: PathBuf, limits: AlarmLimits) -> Self {
        Snapshot {
            path,
            limits,
            last: None,
        }
    }
}

impl ScanSink for Snapshot {
    fn scan(&mut self, scan: &SourceScan, report: &ScanReport) -> anyhow::Result<()> {
        self.last = Some(Last {
            scan: report.scan,
            echoes: scan.echoes.clone(),
            plots_m: report.plots_m.clone(),
            own_m: report.own.position_m,
            targets: report.targets_shown_apart().cloned().collect(),
            ais: report.ais.clone(),
            paired: report.paired.iter().map(|p| p.mmsi).collect(),
        });
        Ok(())
    }

    fn finish(&mut self) -> anyhow::Result<()> {
        let Some(last) = &self.last else {
            return Ok(());
        };
        draw(&self.path, last, &self.limits)
            .with_context(|| format!("writing the snapshot {}", self.path.display()))
    }
}

fn draw(path: &std::path::Path, last: &Last, limits: &AlarmLimits) -> anyhow::Result<()> {
    crate::font::register();
    let root = BitMapBackend::new(path, (SIZE, SIZE)).into_drawing_area();
    root.fill(&BLACK)?;
    // The scale: the radar's range, else the farthest plot or target.
    let rel = |p: [f32; 2]| {
        (
            f64::from(p[0] - last.own_m[0]),
            f64::from(p[1] - last.own_m[1]),
        )
    };
    let farthest = last
        .plots_m
        .iter()
        .chain(last.targets.iter().map(|t| &t.position_m))
        .map(|p| {
            let (x, y) = rel(*p);
            x.hypot(y)
        })
        .fold(500.0, f64::max);
    let r = last
        .echoes
        .as_ref()
        .map_or(farthest, |e| f64::from(e.range_m).max(1.0));
    // A 20 kn ship's vector reaches a quarter of the range: 30 s to 12 min.
    let vector_s = (r / (4.0 * 10.3)).clamp(30.0, 720.0) as f32;
    let mut chart = ChartBuilder::on(&root)
        .margin(10)
        .caption(
            format!(
                "scan {}, range {:.0} m, north up, true vectors {:.1} min",
                last.scan,
                r,
                vector_s / 60.0
            ),
            ("sans-serif", 22).into_font().color(&WHITE),
        )
        .build_cartesian_2d(-r..r, -r..r)?;
    if let Some(e) = &last.echoes {
        chart.draw_series(e.echoes(0.1).map(|(b, range, level)| {
            let (x, y) = (f64::from(range * b.sin()), f64::from(range * b.cos()));
            let g = (60.0 + 195.0 * level.min(1.0)) as u8;
            Circle::new((x, y), 2, RGBColor(0, g, 0).filled())
        }))?;
    }
    for ring in [0.25, 0.5, 0.75, 1.0] {
        chart.draw_series(std::iter::once(PathElement::new(
            (0..=72)
                .map(|i| {
                    let a = f64::from(i) * std::f64::consts::TAU / 72.0;
                    (r * ring * a.sin(), r * ring * a.cos())
                })
                .collect::<Vec<_>>(),
            RGBColor(90, 90, 90),
        )))?;
    }
    chart.draw_series(
        last.plots_m
            .iter()
            .map(|p| Circle::new(rel(*p), 4, YELLOW.stroke_width(2))),
    )?;
    for a in last.ais.iter().filter(|a| !last.paired.contains(&a.mmsi)) {
        let (x, y) = rel(a.position_m);
        let c = a
            .heading_rad
            .unwrap_or_else(|| a.velocity_mps[0].atan2(a.velocity_mps[1]));
        let s = r / 60.0;
        let corner = |angle: f32, k: f64| {
            (
                x + k * s * f64::from(angle.sin()),
                y + k * s * f64::from(angle.cos()),
            )
        };
        let tri = vec![
            corner(c, 1.0),
            corner(c + 2.5, 0.7),
            corner(c - 2.5, 0.7),
            corner(c, 1.0),
        ];
        chart.draw_series(std::iter::once(PathElement::new(
            tri,
            MAGENTA.stroke_width(2),
        )))?;
    }
    for t in &last.targets {
        let colour = if t.dangerous(limits) { RED } else { CYAN };
        let (x, y) = rel(t.position_m);
        let v = t.velocity_mps;
        chart.draw_series(std::iter::once(PathElement::new(
            vec![
                (x, y),
                (
                    x + f64::from(v[0] * vector_s),
                    y + f64::from(v[1] * vector_s),
                ),
            ],
            colour.stroke_width(2),
        )))?;
        chart.draw_series(std::iter::once(Circle::new(
            (x, y),
            7,
            colour.stroke_width(2),
        )))?;
        chart.draw_series(std::iter::once(Text::new(
            t.label(),
            (x + r / 80.0, y + r / 80.0),
            ("sans-serif", 16).into_font().color(&colour),
        )))?;
    }
    chart.draw_series(std::iter::once(Cross::new(
        (0.0, 0.0),
        8,
        WHITE.stroke_width(2),
    )))?;
    root.present()?;
    Ok(())
}
