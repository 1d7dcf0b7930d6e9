//! `--snapshot PATH`: a PNG of the run's last scan as a radar display would show it, north
//! up, own ship at the centre: the rotation's echoes (a radar source's; green, brighter for
//! stronger), the extracted plots (yellow), the targets with their numbers and true vectors
//! (cyan, red when dangerous; as long as the time in the caption, which grows with the
//! range), AIS targets (magenta triangles, with their vectors when activated; an
//! associated ship's with its radar target's number, or drawn as the radar target instead:
//! [`AssociatedSymbol`]), range rings, and own ship's alarms in red (no heading for a
//! head-up radar: no echoes placed). For a person to check the extraction and the
//! tracking by eye.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::Context;
use plotters::prelude::*;
use plotters_bitmap::BitMapBackendError;

use crate::ais::AisTargetData;
use crate::radar::EchoImage;
use crate::session::ais::AssociatedSymbol;
use crate::session::target::{AlarmLimits, TargetData};
use crate::session::ScanReport;
use crate::sink::ScanSink;
use crate::source::SourceScan;

const SIZE: u32 = 1000;

/// A track being acquired: light grey (the range rings are darker).
const ACQUIRING: RGBColor = RGBColor(170, 170, 170);

/// The file name extensions the snapshot can be written as: the image formats plotters'
/// bitmap backend encodes as built here (`image` with `png`, `jpeg`, `bmp`).
pub const EXTENSIONS: [&str; 4] = ["png", "jpg", "jpeg", "bmp"];

/// Checks, before a run, that a snapshot can be written to `path`: its extension names a
/// format the drawing writes ([`EXTENSIONS`], any case) and the file can be made there.
///
/// # Errors
/// Another extension or none, or as [`super::check_writable`].
pub fn check_path(path: &std::path::Path) -> anyhow::Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !ext.is_some_and(|e| EXTENSIONS.contains(&e.as_str())) {
        anyhow::bail!(
            "{}: the snapshot is a PNG image, the name must end in .png (or .jpg, .jpeg, .bmp)",
            path.display()
        );
    }
    super::check_writable(path)
}

#[derive(Clone, Debug)]
struct Last {
    scan: u32,
    echoes: Option<Arc<EchoImage>>,
    plots_m: Vec<[f32; 2]>,
    own_m: [f32; 2],
    /// Own ship's heading, rad true: its heading line.
    heading_rad: Option<f32>,
    /// The radar targets drawn as radar targets.
    targets: Vec<TargetData>,
    /// Where the tracks being acquired are (a second plot, no number yet), local m.
    acquiring_m: Vec<[f32; 2]>,
    /// The AIS targets drawn, each with the radar target of its ship when associated.
    ais: Vec<(AisTargetData, Option<TargetData>)>,
    /// Own ship's alarms ([`crate::own_ship::OwnShip::alarms`]): why the picture may be
    /// empty (no heading for a head-up radar) or off, written on it.
    own_alarms: Vec<String>,
    /// Own ship's motion over ground is known: the targets' vectors are true; without it
    /// the radar targets' are relative to own ship, titled so, and the AIS targets' are not
    /// drawn.
    motion_known: bool,
    /// Taken off a radar target's velocity for its relative vector while own ship's motion
    /// is unknown, m/s: own ship's velocity where its position moves with it, none where it
    /// stands (the tracks are relative already; [`crate::own_ship::OwnShip::track_frame_velocity_mps`]).
    frame_velocity_mps: [f32; 2],
    /// The picture is a simulation's (`demo`): its title says so.
    simulated: bool,
}

impl Last {
    fn of(scan: &SourceScan, report: &ScanReport, symbol: AssociatedSymbol) -> Self {
        Last {
            scan: report.scan,
            echoes: scan.echoes.clone(),
            plots_m: report.plots_m.clone(),
            own_m: report.own.position_m,
            heading_rad: report.own.heading_rad,
            targets: report.targets_drawn(symbol).copied().collect(),
            acquiring_m: report.acquiring.iter().map(|t| t.position_m).collect(),
            ais: report
                .ais_drawn(symbol)
                .map(|a| {
                    let radar = report
                        .associated_track(a.mmsi)
                        .and_then(|track| report.targets.iter().find(|t| t.track == track));
                    (a.clone(), radar.copied())
                })
                .collect(),
            own_alarms: report.own.alarms(),
            motion_known: report.own.quality.motion_known,
            frame_velocity_mps: report.own.track_frame_velocity_mps(),
            simulated: false,
        }
    }
}

/// Keeps the last scan and draws it when the run ends.
pub struct Snapshot {
    path: PathBuf,
    limits: AlarmLimits,
    symbol: AssociatedSymbol,
    /// The range drawn, NM, when the operator chose one.
    range_nm: Option<f64>,
    last: Option<Last>,
    simulated: bool,
}

impl Snapshot {
    /// A snapshot to be written to `path` (PNG), associated ships drawn by `symbol`.
    pub fn new(path: PathBuf, limits: AlarmLimits, symbol: AssociatedSymbol) -> Self {
        Snapshot {
            path,
            limits,
            symbol,
            range_nm: None,
            last: None,
            simulated: false,
        }
    }

    /// With `simulated`, the picture is a simulation's (`demo`), titled `SIMULATION`.
    pub fn with_simulated(mut self, simulated: bool) -> Self {
        self.simulated = simulated;
        self
    }

    /// Drawn to `range_nm` (NM, own ship to the edge) rather than the automatic scale.
    pub fn with_range_nm(mut self, range_nm: Option<f64>) -> Self {
        self.range_nm = range_nm;
        self
    }
}

impl ScanSink for Snapshot {
    fn scan(&mut self, scan: &SourceScan, report: &ScanReport) -> anyhow::Result<()> {
        let mut last = Last::of(scan, report, self.symbol);
        last.simulated = self.simulated;
        self.last = Some(last);
        Ok(())
    }

    fn finish(&mut self) -> anyhow::Result<()> {
        let Some(last) = &self.last else {
            return Ok(());
        };
        draw(&self.path, last, &self.limits, self.range_nm)
            .map_err(plain)
            .with_context(|| format!("writing the snapshot {}", self.path.display()))
    }
}

/// A true vector from `at` (chart metres) for `velocity_mps` over `vector_s` seconds.
fn vector(at: (f64, f64), velocity_mps: [f32; 2], vector_s: f32) -> Vec<(f64, f64)> {
    let (x, y) = at;
    vec![
        (x, y),
        (
            x + f64::from(velocity_mps[0] * vector_s),
            y + f64::from(velocity_mps[1] * vector_s),
        ),
    ]
}

/// A drawing error in words: plotters' bitmap errors show themselves as `Debug` structs
/// (`ImageError(IoError(Os { … }))`); the image or I/O error inside says it plainly.
fn plain(e: DrawingAreaErrorKind<BitMapBackendError>) -> anyhow::Error {
    use plotters_backend::DrawingErrorKind;
    match e {
        DrawingAreaErrorKind::BackendError(DrawingErrorKind::DrawingError(b)) => match b {
            BitMapBackendError::IOError(io) => anyhow::anyhow!(io),
            BitMapBackendError::ImageError(image) => anyhow::anyhow!("{image}"),
            other => anyhow::anyhow!("{other}"),
        },
        other => anyhow::anyhow!("{other}"),
    }
}

fn draw(
    path: &std::path::Path,
    last: &Last,
    limits: &AlarmLimits,
    range_nm: Option<f64>,
) -> Result<(), DrawingAreaErrorKind<BitMapBackendError>> {
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
        .chain(
            last.ais
                .iter()
                .filter(|(_, t)| t.is_some())
                .map(|(a, _)| &a.position_m),
        )
        .map(|p| {
            let (x, y) = rel(*p);
            x.hypot(y)
        })
        .fold(500.0, f64::max);
    // (An image nothing was painted on, for want of a heading, has no range.)
    let reach = last
        .echoes
        .as_ref()
        .filter(|e| e.range_m > 1.0)
        .map_or(farthest, |e| f64::from(e.range_m));
    // On the display's range scale that holds it (a radar's scales), in NM.
    let scale_nm = range_nm.unwrap_or_else(|| scale_holding_nm(reach));
    let r = scale_nm * f64::from(tracker_core::geo::METRES_PER_NM);
    // A 20 kn ship's vector reaches about a quarter of the range: the display's vector
    // length nearest that.
    let vector_min = vector_minutes_for(r);
    let vector_s = vector_min * 60.0;
    let mut chart = ChartBuilder::on(&root)
        .margin(10)
        .caption(
            caption(last, scale_nm, vector_min),
            ("sans-serif", 22).into_font().color(&WHITE),
        )
        .build_cartesian_2d(-r..r, -r..r)?;
    // Nothing beyond the range is drawn, as on a radar display (plotters would put it on
    // the frame's edge; a range the operator chose may be short of the radar's).
    let within = |(x, y): (f64, f64)| x.hypot(y) <= r;
    if let Some(e) = &last.echoes {
        let inside = move |&(_, range, _): &(f32, f32, f32)| f64::from(range) <= r;
        chart.draw_series(e.echoes(0.1).filter(inside).map(|(b, range, level)| {
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
            .map(|p| rel(*p))
            .filter(|p| within(*p))
            .map(|p| Circle::new(p, 4, YELLOW.stroke_width(2))),
    )?;
    for (a, radar) in &last.ais {
        let (x, y) = rel(a.position_m);
        // Off the range scale: not drawn (AIS is heard far beyond a harbour radar's range).
        if !within((x, y)) {
            continue;
        }
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
        // Red as on the display: its radar target's alarm, or its own when activated.
        let colour = if radar.is_some_and(|t| t.dangerous(limits))
            || (a.active && crate::display::ais_dangerous(a, limits))
        {
            RED
        } else {
            MAGENTA
        };
        chart.draw_series(std::iter::once(PathElement::new(
            tri,
            colour.stroke_width(2),
        )))?;
        // Its true vector when activated or associated, as the display draws it: an
        // associated ship drawn as its AIS target shows where it is going, at any range.
        // None while own ship's motion is unknown, as on the display.
        if (a.active || radar.is_some()) && last.motion_known {
            chart.draw_series(std::iter::once(PathElement::new(
                vector((x, y), a.velocity_mps, vector_s),
                colour.stroke_width(1),
            )))?;
        }
        // An associated ship drawn as its AIS target keeps its radar target's number, as
        // the table and `TTM` do.
        if let Some(t) = radar {
            chart.draw_series(std::iter::once(Text::new(
                t.label(),
                (x + r / 80.0, y + r / 80.0),
                ("sans-serif", 16).into_font().color(&colour),
            )))?;
        }
    }
    // Tracks being acquired: a small grey circle, no number, no vector (IEC 62388), as the
    // display draws them.
    for &p in &last.acquiring_m {
        let (x, y) = rel(p);
        if within((x, y)) {
            chart.draw_series(std::iter::once(Circle::new(
                (x, y),
                11,
                ACQUIRING.stroke_width(1),
            )))?;
        }
    }
    for t in &last.targets {
        let colour = if t.dangerous(limits) { RED } else { CYAN };
        let (x, y) = rel(t.position_m);
        if !within((x, y)) {
            continue;
        }
        // No vector before the motion's trend is known, as on the display.
        if t.trend_known {
            let v = if last.motion_known {
                t.velocity_mps
            } else {
                tracker_core::geo::relative_velocity(last.frame_velocity_mps, t.velocity_mps)
            };
            chart.draw_series(std::iter::once(PathElement::new(
                vector((x, y), v, vector_s),
                colour.stroke_width(2),
            )))?;
        }
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
    // Own ship's heading line, to the range's edge, whenever a heading is known.
    if let Some(h) = last.heading_rad {
        let (sin, cos) = (f64::from(h.sin()), f64::from(h.cos()));
        chart.draw_series(std::iter::once(PathElement::new(
            vec![(0.0, 0.0), (r * sin, r * cos)],
            WHITE.stroke_width(1),
        )))?;
    }
    chart.draw_series(std::iter::once(Cross::new(
        (0.0, 0.0),
        8,
        WHITE.stroke_width(2),
    )))?;
    let alarm_font = ("sans-serif", 18).into_font().color(&RED);
    let lines = last
        .own_alarms
        .iter()
        .flat_map(|a| wrapped(a, NOTE_COLUMNS));
    for (i, line) in lines.enumerate() {
        let y = 45 + 22 * i32::try_from(i).unwrap_or(i32::MAX / 32);
        root.draw(&Text::new(line, (20, y), alarm_font.clone()))?;
    }
    root.present()?;
    Ok(())
}

/// The picture's title: scan, range scale, orientation and the vectors drawn (true, or
/// relative while own ship's motion is unknown, as the display's header says).
fn caption(last: &Last, scale_nm: f64, vector_min: f32) -> String {
    let vectors = if last.motion_known {
        "true"
    } else {
        "relative"
    };
    // The rings at quarters of the range (a new user's trial read "range 24 NM" over four
    // rings and could not tell their spacing).
    format!(
        "{}scan {}, range {scale_nm} NM, rings {} NM, north up, {vectors} vectors {vector_min} min",
        if last.simulated { "SIMULATION, " } else { "" },
        last.scan,
        (scale_nm / 4.0 * 1000.0).round() / 1000.0
    )
}

/// Characters a line of own ship's alarms on the picture holds at its font.
const NOTE_COLUMNS: usize = 95;

/// `text` cut at spaces into lines of at most `columns` characters (a longer word alone).
fn wrapped(text: &str, columns: usize) -> Vec<String> {
    crate::display::wrap(text.split_whitespace(), " ", columns)
}

/// The smallest of the display's range scales that holds `reach_m`, NM; past the largest,
/// whole NM.
fn scale_holding_nm(reach_m: f64) -> f64 {
    let nm = reach_m / f64::from(tracker_core::geo::METRES_PER_NM);
    crate::display::RANGE_SCALES_NM
        .iter()
        .map(|&s| f64::from(s))
        .find(|&s| s >= nm * 0.999)
        .unwrap_or_else(|| nm.ceil())
}

/// The display's vector length nearest the time a 20 kn ship takes to cross a quarter of
/// a range of `range_m`, min.
fn vector_minutes_for(range_m: f64) -> f32 {
    let want_min = (range_m / (4.0 * 10.3) / 60.0) as f32;
    crate::display::VECTOR_MINUTES
        .iter()
        .copied()
        .min_by(|a, b| (a - want_min).abs().total_cmp(&(b - want_min).abs()))
        .unwrap_or(6.0)
}

#[cfg(test)]
mod tests {
    #[test]
    fn own_ship_alarms_are_cut_into_lines_that_fit_the_picture() {
        let text = "OWN SHIP: no heading: the head-up radar's plots are not placed";
        let lines = super::wrapped(text, 24);
        assert_eq!(
            lines,
            [
                "OWN SHIP: no heading:",
                "the head-up radar's",
                "plots are not placed"
            ]
        );
        assert!(lines.iter().all(|l| l.chars().count() <= 24));
        assert_eq!(super::wrapped(text, 1_000), [text]);
        assert!(super::wrapped("", 10).is_empty());
    }

    #[test]
    fn a_snapshot_takes_a_radar_range_scale_and_a_display_vector_length() {
        assert_eq!(super::scale_holding_nm(25_465.0), 24.0);
        assert_eq!(super::scale_holding_nm(50_000.0), 27.0);
        assert_eq!(super::scale_holding_nm(1_312.0), 0.75);
        assert_eq!(super::scale_holding_nm(195.0), 0.125);
        assert_eq!(super::vector_minutes_for(24.0 * 1852.0), 12.0);
        assert_eq!(super::vector_minutes_for(0.75 * 1852.0), 0.5);
        assert_eq!(super::vector_minutes_for(6.0 * 1852.0), 3.0);
        assert_eq!(super::vector_minutes_for(0.125 * 1852.0), 0.5);
    }

    use super::*;
    use crate::app::demo::{self, DemoOptions};
    use crate::display::tests::one_associated_ship;
    use crate::link::{Client, InprocTransport};

    #[test]
    fn the_snapshot_draws_an_associated_ship_by_the_chosen_symbol() {
        let options = DemoOptions::new(
            tracker_core::sim::ScenarioKind::OpenSea,
            12,
            3,
            60.0,
            tracker_core::filter::FilterKind::KalmanCv,
        );
        let mut d = demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
        let mut view = d.step().unwrap().unwrap();
        for _ in 0..10 {
            view = d.step().unwrap().unwrap();
        }
        let scan = SourceScan::default();
        for paired in [true, false] {
            let view = one_associated_ship(view.clone(), paired);
            let track = view.targets[0].track;
            let ais = Last::of(&scan, &view, AssociatedSymbol::Ais);
            assert!(ais.targets.is_empty(), "paired {paired}");
            assert_eq!(ais.ais.len(), 1);
            assert_eq!(
                ais.ais[0].1.map(|t| t.track),
                Some(track),
                "its number kept"
            );
            let radar = Last::of(&scan, &view, AssociatedSymbol::Radar);
            assert_eq!(radar.targets.len(), 1, "paired {paired}");
            assert!(radar.ais.is_empty(), "paired {paired}");
            // Both draw.
            let dir = tempfile::tempdir().unwrap();
            for (last, name) in [(&ais, "ais.png"), (&radar, "radar.png")] {
                let path = dir.path().join(name);
                draw(&path, last, &AlarmLimits::default(), None).unwrap();
                assert!(std::fs::metadata(&path).unwrap().len() > 0);
            }
        }
    }

    /// `--snapshot-range-nm` shorter than the farthest plot: the plot beyond it is not
    /// drawn (the first version drew it on the frame's edge, as plotters clamps points).
    #[test]
    fn a_chosen_range_draws_nothing_beyond_it() {
        // 0.5 NM and 1.6 NM east of own ship.
        let last = with_plots(vec![[926.0, 0.0], [3000.0, 0.0]]);
        // Yellow pixels (the plots' circles; BGR) of the picture drawn to `range_nm`.
        let yellow =
            |range_nm: f64| -> usize { pixels(&last, range_nm, |_, _, bgr| bgr == [0, 255, 255]) };
        let both = yellow(2.0);
        let near_only = yellow(1.0);
        assert!(near_only > 0, "the near plot drawn");
        assert!(
            2 * near_only < both + both / 4,
            "{near_only} yellow pixels at 1 NM against {both} at 2 NM"
        );
    }

    /// Scan 1 with `plots_m` (m east and north of own ship at the origin), nothing else,
    /// own ship's motion known.
    fn with_plots(plots_m: Vec<[f32; 2]>) -> Last {
        Last {
            scan: 1,
            echoes: None,
            plots_m,
            own_m: [0.0, 0.0],
            heading_rad: None,
            targets: Vec::new(),
            acquiring_m: Vec::new(),
            ais: Vec::new(),
            own_alarms: Vec::new(),
            motion_known: true,
            frame_velocity_mps: [0.0, 0.0],
            simulated: false,
        }
    }

    /// The pixels of `last` drawn to `range_nm` for which `f(x, y, [b, g, r])` holds (x
    /// right, y up from the picture's bottom row), read from an uncompressed 24-bit BMP:
    /// pixels from the offset at byte 10, rows padded to 4.
    fn pixels(last: &Last, range_nm: f64, f: impl Fn(usize, usize, [u8; 3]) -> bool) -> usize {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.bmp");
        draw(&path, last, &AlarmLimits::default(), Some(range_nm)).unwrap();
        let b = std::fs::read(&path).unwrap();
        let u32_at = |i: usize| u32::from_le_bytes(b[i..i + 4].try_into().unwrap()) as usize;
        let (start, width, height) = (u32_at(10), u32_at(18), u32_at(22));
        let row = (width * 3).div_ceil(4) * 4;
        (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                let i = start + y * row + x * 3;
                f(x, y, [b[i], b[i + 1], b[i + 2]])
            })
            .count()
    }

    /// Own ship's heading line: drawn from own ship to the edge when a heading is known.
    #[test]
    fn the_heading_line_is_drawn_when_own_ship_has_a_heading() {
        let mut last = with_plots(Vec::new());
        // White pixels in a band about the centre row, right of own ship's cross.
        let east = |last: &Last| {
            let half = SIZE as usize / 2;
            pixels(last, 1.0, |x, y, bgr| {
                bgr == [255, 255, 255] && x > half + 20 && y.abs_diff(half) < 20
            })
        };
        let without = east(&last);
        last.heading_rad = Some(core::f32::consts::FRAC_PI_2);
        let with = east(&last);
        assert!(
            with > without + 100,
            "{with} white pixels east with a heading, {without} without"
        );
    }

    #[test]
    fn tracks_being_acquired_are_drawn_without_a_number() {
        // Grey lighter than the range rings' (90), however the ring's edge is shaded.
        let grey = |last: &Last| {
            pixels(last, 1.0, |_, _, [b, g, r]| {
                b == g && g == r && (120..=200).contains(&r)
            })
        };
        let mut last = with_plots(Vec::new());
        let without = grey(&last);
        last.acquiring_m = vec![[300.0, 400.0], [-600.0, 100.0]];
        let with = grey(&last);
        assert!(
            with >= without + 16,
            "{with} grey pixels with, {without} without"
        );
    }

    #[test]
    fn every_extension_allowed_draws_and_a_late_failure_is_told_in_words() {
        let last = Last {
            own_alarms: vec!["OWN SHIP: no heading: a note long enough to take two lines on the picture at its font, so that the wrapping is drawn too".to_string()],
            ..with_plots(vec![[100.0, 200.0]])
        };
        // The title says which vectors are drawn: relative without own ship's motion (a new
        // user's trial read "true vectors" on a capture with no fix).
        assert!(caption(&last, 0.5, 0.5).contains("true vectors 0.5 min"));
        assert!(caption(&last, 24.0, 6.0).contains("range 24 NM, rings 6 NM"));
        let simulated = Last {
            simulated: true,
            ..with_plots(Vec::new())
        };
        assert!(caption(&simulated, 6.0, 3.0).starts_with("SIMULATION, scan 1,"));
        let unknown = Last {
            motion_known: false,
            ..last.clone()
        };
        assert!(caption(&unknown, 0.5, 0.5).contains("relative vectors 0.5 min"));
        let dir = tempfile::tempdir().unwrap();
        for ext in EXTENSIONS.iter().chain(&["PNG"]) {
            let path = dir.path().join(format!("s.{ext}"));
            check_path(&path).unwrap();
            draw(&path, &last, &AlarmLimits::default(), None).unwrap();
            assert!(std::fs::metadata(&path).unwrap().len() > 0, "{ext}");
        }
        for name in ["s.txt", "s.svg", "s"] {
            let e = format!("{:#}", check_path(&dir.path().join(name)).unwrap_err());
            assert!(e.contains("must end in .png"), "{e}");
        }
        // The directory gone by the end of the run: the system's words, no Debug struct.
        let mut sink = Snapshot::new(
            dir.path().join("gone").join("s.png"),
            AlarmLimits::default(),
            AssociatedSymbol::Ais,
        );
        sink.last = Some(last);
        let e = format!("{:#}", sink.finish().unwrap_err());
        assert!(e.contains("No such file or directory"), "{e}");
        assert!(!e.contains("IoError") && !e.contains("Os {"), "{e}");
    }
}
