//! The radar display: a PPI (plan position indicator) with own ship at the centre, range
//! rings, raw plots, track symbols with vectors and past positions, beside the target table
//! and the alarms, in a terminal (ratatui).
//!
//! Keys: `+`/`-` range scale, `v` relative/true vectors, `[`/`]` vector length, `↑`/`↓`
//! select a target, `a` acquire the nearest untracked plot, `c` cancel the selected target,
//! `C` cancel all, `e` radar echoes on/off (a radar source's last rotation, under the plots
//! and tracks), `i` the AIS target table ([`ais_table`]) in the radar targets' place and
//! back, `p` pause (the picture; a live radar is tracked on), `q` quit.
//!
//! [`render`] draws one frame from plain data, so tests drive it headless with ratatui's
//! `TestBackend` and read the screen back. [`plain`] prints the target table as text
//! instead, scan by scan or as progress lines.

pub mod ais_table;
pub mod plain;
mod shown;

use std::collections::{BTreeMap, VecDeque};

use ratatui::layout::{Constraint, Direction, Layout, Rect};
use ratatui::style::{Color, Modifier, Style};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::canvas::{Canvas, Circle, Line as CanvasLine, Points};
use ratatui::widgets::{Block, Borders, Cell, Paragraph, Row, Table};
use ratatui::Frame;
use tracker_core::geo::{self, EastNorth, METRES_PER_NM, MPS_PER_KNOT};
use tracker_core::icd::TrackStatus;
use tracker_core::track::MAX_TRACKS;

use crate::app::run::Run;
use crate::session::ais::AssociatedSymbol;
use crate::session::target::{shown_status, AlarmLimits, TargetData};
use crate::session::ScanReport;
pub use crate::utc::utc_label;

/// Range scales, NM (the short ones for a harbour radar's scales).
pub const RANGE_SCALES_NM: [f32; 9] = [0.125, 0.25, 0.5, 0.75, 1.5, 3.0, 6.0, 12.0, 24.0];

/// The scale the display starts at: 6 NM.
const DEFAULT_SCALE: usize = 6;

/// Vector lengths, minutes.
pub const VECTOR_MINUTES: [f32; 6] = [0.5, 1.0, 3.0, 6.0, 12.0, 30.0];

/// Echoes drawn: cells at or above this fraction of full scale.
pub const ECHO_FRACTION: f32 = 0.25;

/// Past positions kept per track.
const HISTORY: usize = 12;

/// Relative or true vectors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VectorMode {
    /// Motion relative to own ship: where a collision shows as a vector through the centre.
    Relative,
    /// Motion over ground.
    True,
}

/// What a key asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// Nothing for the link.
    None,
    /// Leave.
    Quit,
    /// Start a track on this plot of the last scan.
    Acquire(u16),
    /// Drop this track.
    Cancel(u16),
    /// Drop every track.
    CancelAll,
}

/// The display's own state: scales, modes, selection, trails.
#[derive(Clone, Debug)]
pub struct DisplayState {
    /// Index into [`RANGE_SCALES_NM`].
    pub range_scale: usize,
    /// Vector mode.
    pub vectors: VectorMode,
    /// Index into [`VECTOR_MINUTES`].
    pub vector_length: usize,
    /// Selected track number.
    pub selected: Option<u16>,
    /// Paused: the picture stays until unpaused (a file's scans wait; a live radar's are
    /// tracked on: the `shown` module).
    pub paused: bool,
    /// Scans tracked behind the paused picture (a live radar's).
    pub scans_since_paused: u64,
    /// The source has ended: the last picture stays until the operator quits.
    pub ended: bool,
    /// CPA/TCPA alarm limits.
    pub limits: AlarmLimits,
    /// Link name for the title.
    pub link: String,
    /// The targets are a simulation's (`demo`): the title says `SIM` (as the targets sent
    /// to plotters are named `SIMnn`), so that no one takes the picture for the sea's.
    pub simulated: bool,
    /// The answer to the last operator command (done, or the device's refusal), shown
    /// until the next command.
    pub message: Option<String>,
    /// The scale was fitted to a radar's range (once, at its first picture) or chosen by
    /// the operator.
    scale_chosen: bool,
    /// Draw the radar's echoes under the plots (when the source is a radar).
    pub echoes: bool,
    /// The table lists the AIS targets ([`ais_table`]) instead of the radar targets.
    pub ais_table: bool,
    /// The AIS table's first row shown, nearest first counted from 0 (↑↓ scroll it while
    /// it is shown; held within the targets heard when drawn).
    pub ais_first_row: usize,
    /// The AIS table's rows as last drawn (the pane's height decides them): ↓ stops where
    /// the last target is on the pane's last row.
    ais_rows_drawn: std::cell::Cell<usize>,
    /// The rows the radar targets' table last held ([`table_order`] depends on it, and
    /// ↑↓ step through the targets in the order drawn).
    table_rows_drawn: std::cell::Cell<usize>,
    /// How a ship with a radar target and an AIS target associated is drawn.
    pub associated: AssociatedSymbol,
    /// A live radar silent this long, s (raised after a few antenna periods): the
    /// no-radar-data alarm.
    pub radar_silent_s: Option<u64>,
    trails: BTreeMap<u16, VecDeque<EastNorth>>,
    /// Lost targets not acknowledged yet, oldest first.
    lost: Vec<String>,
    /// The last silence of the radar, not acknowledged yet.
    silence: Option<crate::session::Silence>,
}

/// Lost-target alarms held for acknowledgement, at most (the oldest give way).
const MAX_UNACKNOWLEDGED: usize = 99;

/// The labels of the targets a scan lost (the device says lost, or a silence of the radar
/// cancelled them): the lost-target alarm's. A failed acquisition is not one.
pub(crate) fn lost_targets(view: &ScanReport) -> impl Iterator<Item = String> + '_ {
    view.ended
        .iter()
        .filter(|e| {
            view.silence.is_some()
                || view
                    .tracks
                    .iter()
                    .any(|t| t.track == e.track && t.status == TrackStatus::Lost)
        })
        .map(|e| e.label())
}

impl DisplayState {
    /// 6 NM scale, relative 6-minute vectors.
    pub fn new(link: String) -> Self {
        DisplayState {
            range_scale: DEFAULT_SCALE,
            vectors: VectorMode::Relative,
            vector_length: 3,
            selected: None,
            paused: false,
            scans_since_paused: 0,
            ended: false,
            limits: AlarmLimits::default(),
            link,
            simulated: false,
            message: None,
            scale_chosen: false,
            echoes: true,
            ais_table: false,
            ais_first_row: 0,
            ais_rows_drawn: std::cell::Cell::new(1),
            table_rows_drawn: std::cell::Cell::new(usize::MAX),
            associated: AssociatedSymbol::default(),
            radar_silent_s: None,
            trails: BTreeMap::new(),
            lost: Vec::new(),
            silence: None,
        }
    }

    /// Takes a new scan: extends the trails, notes lost tracks, keeps the selection valid;
    /// at a radar's first picture, fits the scale to its range (the smallest that holds it).
    pub fn observe(&mut self, view: &ScanReport) {
        self.observe_alarms(view);
        self.observe_picture(view);
    }

    /// The lost-target and radar-silence alarms a scan raises (taken from every scan
    /// tracked, the picture paused or not).
    pub fn observe_alarms(&mut self, view: &ScanReport) {
        // Lost tracked targets (the device says lost, or a silence of the radar cancelled
        // them), by their numbers; a failed acquisition is not an alarm. Both alarms stand
        // until the operator acknowledges them (IEC 62388's lost-target alarm): shown for
        // one scan, 2.5 s, they were easily missed.
        for label in lost_targets(view) {
            if !self.lost.contains(&label) {
                if self.lost.len() == MAX_UNACKNOWLEDGED {
                    self.lost.remove(0);
                }
                self.lost.push(label);
            }
        }
        if view.silence.is_some() {
            self.silence = view.silence;
        }
    }

    /// The picture a scan draws: the scale fitted at a radar's first picture, the trails,
    /// the selection kept to targets shown (only from scans drawn: a paused picture's
    /// trails stay as they were).
    pub fn observe_picture(&mut self, view: &ScanReport) {
        if let (false, Some(image)) = (self.scale_chosen, &view.echoes) {
            let nm = image.range_m / METRES_PER_NM;
            if nm > 0.0 {
                self.range_scale = RANGE_SCALES_NM
                    .iter()
                    .position(|s| *s >= nm)
                    .unwrap_or(RANGE_SCALES_NM.len() - 1);
                // A vector a quarter of the scale long at 20 kn, in the lengths offered.
                let minutes = RANGE_SCALES_NM[self.range_scale] / 4.0 / 20.0 * 60.0;
                self.vector_length = VECTOR_MINUTES
                    .iter()
                    .rposition(|m| *m <= minutes)
                    .unwrap_or(0);
                self.scale_chosen = true;
            }
        }
        for t in &view.targets {
            let trail = self.trails.entry(t.track).or_default();
            trail.push_back(t.position_m);
            if trail.len() > HISTORY {
                trail.pop_front();
            }
        }
        self.trails
            .retain(|id, _| view.targets.iter().any(|t| t.track == *id));
        if self
            .selected
            .is_some_and(|id| !view.targets.iter().any(|t| t.track == id))
        {
            self.selected = None;
        }
    }

    /// Applies a key; returns what the link must do.
    pub fn key(&mut self, key: char, view: Option<&ScanReport>) -> Action {
        // The last command's answer stands until this one.
        self.message = None;
        match key {
            'q' => return Action::Quit,
            '+' => {
                self.range_scale = (self.range_scale + 1).min(RANGE_SCALES_NM.len() - 1);
                self.scale_chosen = true;
            }
            '-' => {
                self.range_scale = self.range_scale.saturating_sub(1);
                self.scale_chosen = true;
            }
            'v' => {
                self.vectors = match self.vectors {
                    VectorMode::Relative => VectorMode::True,
                    VectorMode::True => VectorMode::Relative,
                };
                // True vectors add own ship's velocity over ground: without it they stay
                // relative, and the operator is told why rather than see nothing change.
                let unknown = view.map(|v| v.own).filter(|o| !o.quality.motion_known);
                if let (VectorMode::True, Some(own)) = (self.vectors, unknown) {
                    let why = if own.quality.no_fix_yet {
                        "no fix yet"
                    } else if own.position_held() {
                        "position lost"
                    } else {
                        "not yet measured"
                    };
                    self.message = Some(format!(
                        "true vectors need own ship's course and speed over ground ({why}): relative until then"
                    ));
                }
            }
            ']' => self.vector_length = (self.vector_length + 1).min(VECTOR_MINUTES.len() - 1),
            '[' => self.vector_length = self.vector_length.saturating_sub(1),
            'p' => self.paused = !self.paused,
            'e' => {
                self.echoes = !self.echoes;
                self.message = Some(if view.is_some_and(|v| v.echoes.is_none()) {
                    "echoes: this source sends plots, no radar picture".into()
                } else if self.echoes {
                    "echoes shown".into()
                } else {
                    "echoes hidden (e shows them)".into()
                });
            }
            'i' => {
                self.ais_table = !self.ais_table;
                if self.ais_table && view.is_some_and(|v| v.ais.is_empty()) {
                    self.message = Some("AIS table: no AIS target heard yet".into());
                }
            }
            'C' => return Action::CancelAll,
            // Enter: the lost-target and radar-silence alarms acknowledged.
            '\n' => {
                if self.lost.is_empty() && self.silence.is_none() {
                    self.message = Some("no alarm to acknowledge".into());
                }
                self.lost.clear();
                self.silence = None;
            }
            // A command that cannot be done is answered too (the README's promise).
            'c' => {
                if let Some(id) = self.selected {
                    return Action::Cancel(id);
                }
                self.message = Some("cancel: no target selected (↑↓ selects)".into());
            }
            'a' => {
                if let Some(p) = view.and_then(nearest_untracked_plot) {
                    return Action::Acquire(p);
                }
                self.message = Some("acquire: no plot without a track".into());
            }
            // The AIS table, while shown, scrolls; else a radar target is selected.
            '↓' | '↑' if self.ais_table => {
                let heard = view.map_or(0, |v| v.ais.len());
                let last = heard.saturating_sub(self.ais_rows_drawn.get().max(1));
                self.ais_first_row = if key == '↓' {
                    (self.ais_first_row + 1).min(last)
                } else {
                    self.ais_first_row.min(last).saturating_sub(1)
                };
            }
            '↓' | '↑' => {
                if let Some(v) = view {
                    self.select_step(v, if key == '↓' { 1 } else { -1 });
                }
            }
            _ => {}
        }
        Action::None
    }

    /// Told by the AIS table as it is drawn: how many rows its pane holds.
    pub(crate) fn set_ais_rows_drawn(&self, rows: usize) {
        self.ais_rows_drawn.set(rows);
    }

    fn select_step(&mut self, view: &ScanReport, step: isize) {
        let ids: Vec<u16> = table_order(view, &self.limits, self.table_rows_drawn.get())
            .iter()
            .map(|t| t.track)
            .collect();
        if ids.is_empty() {
            self.selected = None;
            return;
        }
        let at = self
            .selected
            .and_then(|id| ids.iter().position(|&x| x == id))
            .map_or(0, |i| {
                (i as isize + step).rem_euclid(ids.len() as isize) as usize
            });
        self.selected = ids.get(at).copied();
    }
}

/// True when an AIS target will pass closer than the alarm limits, as for radar targets
/// (one keeping its range raises none: [`crate::session::target::NO_RELATIVE_MOTION_MPS`]);
/// false while its CPA is not known (own ship's motion unknown).
pub fn ais_dangerous(a: &crate::ais::AisTargetData, limits: &AlarmLimits) -> bool {
    match (a.cpa, a.rel_speed_mps) {
        (Some(c), Some(v)) => limits.within(c, v, 1.0, 0.0),
        _ => false,
    }
}

/// The AIS targets that raise their own CPA/TCPA alarm: activated, dangerous, neither
/// paired with a radar target nor shown by one with their data (such a ship alarms as its
/// radar target, once: [`crate::session::ais::AssociatedData`]).
pub fn ais_alarms<'a>(
    view: &'a ScanReport,
    limits: &'a AlarmLimits,
) -> impl Iterator<Item = &'a crate::ais::AisTargetData> + 'a {
    view.ais.iter().filter(move |a| {
        a.active
            && ais_dangerous(a, limits)
            && !view.paired.iter().any(|p| p.mmsi == a.mmsi)
            && !view.targets.iter().any(|t| t.ais_data == Some(a.mmsi))
    })
}

/// The plot nearest own ship that no confirmed or tentative track is close to (500 m).
pub fn nearest_untracked_plot(view: &ScanReport) -> Option<u16> {
    view.plots_m
        .iter()
        .enumerate()
        .filter(|(_, p)| {
            !view
                .tracks
                .iter()
                .any(|t| libm::hypotf(t.position_m[0] - p[0], t.position_m[1] - p[1]) < 500.0)
        })
        .min_by(|a, b| {
            let d = |p: &EastNorth| {
                libm::hypotf(p[0] - view.own.position_m[0], p[1] - view.own.position_m[1])
            };
            d(a.1).total_cmp(&d(b.1))
        })
        .and_then(|(i, _)| u16::try_from(i).ok())
}

/// An AIS name in a narrow pane's alarm line is cut to this many characters, so that the
/// CPA and TCPA fit ("ALARM AIS " and " 0.83 NM 3.4 min" are 26 of the 42 inside).
const NARROW_AIS_NAME: usize = 14;

/// A pane narrower than this has its alarms in short words ([`alarm_lines`]): "CPA/TCPA
/// ALARM: target 35 CPA 0.83 NM in 3.4 min" is 46 characters with the borders.
const NARROW_ALARM_COLUMNS: u16 = 50;

/// Draws one frame: PPI on the left, header, table and alarms on the right.
pub fn render(frame: &mut Frame, state: &DisplayState, view: &ScanReport) {
    render_paused(frame, state, view, view);
}

/// As [`render`], the picture and the table of `view` (paused) under the alarms of
/// `latest` (the scan tracked last): an alarm raised while the picture is paused is shown
/// at once.
pub fn render_paused(
    frame: &mut Frame,
    state: &DisplayState,
    view: &ScanReport,
    latest: &ScanReport,
) {
    let area = frame.area();
    let columns = Layout::default()
        .direction(Direction::Horizontal)
        .constraints([Constraint::Percentage(45), Constraint::Percentage(55)])
        .split(area);
    render_ppi(frame, columns[0], state, view);
    // A narrow pane's header lines wrap, each onto a second row.
    let header_rows = if columns[1].width < 80 { 7 } else { 5 };
    // Made once: the box's height depends on them. One line an alarm, unless that leaves
    // the table fewer than [`TABLE_MIN_TARGET_ROWS`] targets: then the alarms are listed by
    // target, several to a line (an 80×24 terminal with ten alarms showed 2 of 40 targets).
    let narrow = columns[1].width < NARROW_ALARM_COLUMNS;
    let inner = usize::from(columns[1].width.saturating_sub(2));
    let mut alarms = alarm_lines(state, latest, narrow, None).wrapped(inner);
    if header_rows
        + TABLE_MIN_TARGET_ROWS
        + 3
        + alarm_box_rows(&alarms.lines, state, columns[1].width)
        > columns[1].height
    {
        alarms = alarm_lines(state, latest, narrow, Some(inner)).wrapped(inner);
    }
    let right = Layout::default()
        .direction(Direction::Vertical)
        .constraints([
            Constraint::Length(header_rows),
            Constraint::Min(5),
            Constraint::Length(alarm_box_rows(&alarms.lines, state, columns[1].width)),
        ])
        .split(columns[1]);
    render_header(frame, right[0], state, view);
    render_table(frame, right[1], state, view);
    render_alarms(frame, right[2], state, alarms);
}

fn render_header(frame: &mut Frame, area: Rect, state: &DisplayState, view: &ScanReport) {
    // In a narrow pane (an 80-column terminal's is 44) the words are cut, not the figures.
    let narrow = area.width < 80;
    // A figure and its word are joined by a no-break space where the line wraps, so that a
    // count never starts the next line apart from its word ("trk" / "12" at 80 columns).
    let join = if narrow { "\u{a0}" } else { " " };
    let (gap, link, tracked, acquiring, in_echo) = if narrow {
        (" ", "", "trk", "acq", "held")
    } else {
        (
            "  ",
            "link ",
            "targets tracked",
            "acquiring",
            "held in echoes",
        )
    };
    // The run's state first, where a narrow terminal cannot cut it off.
    let run_state = if state.ended {
        "END OF INPUT: q to quit"
    } else if state.paused && state.scans_since_paused > 0 {
        // A live radar tracked on behind the picture.
        &format!("PAUSED +{}", state.scans_since_paused)
    } else if state.paused {
        "PAUSED"
    } else {
        ""
    };
    let counts = |gap: &str,
                  link: &str,
                  name: &str,
                  tracked: &str,
                  acquiring: &str,
                  in_echo: &str| {
        // Targets held hidden in others' echoes (not drawn), when there are any.
        let held = if view.in_echo.is_empty() {
            String::new()
        } else {
            format!("{gap}{in_echo}{join}{}", view.in_echo.len())
        };
        let link = if name.is_empty() {
            String::new()
        } else {
            format!("{gap}{link}{name}")
        };
        format!(
                "scan{join}{}{gap}{}{link}{gap}plots{join}{}{gap}{tracked}{join}{}{gap}{acquiring}{join}{}{held}",
                view.scan,
                view.time_label(),
                view.plots.len(),
                view.tracked(),
                view.acquiring(),
            )
    };
    let mut first = counts(gap, link, &state.link, tracked, acquiring, in_echo);
    // A wide pane that still cannot hold the line (PAUSED in front of it at about 160
    // columns) takes the short words, so that no count is cut off at its end; and where
    // even they are too long (targets held in echoes, at 80 columns), without the link. (A
    // narrow pane's line wraps.)
    let inner = usize::from(area.width.saturating_sub(2));
    // Set apart from the counts by a bar outside its reverse video: without colours (tmux,
    // a log of the screen) `q to quit scan 5` read as one phrase (a new user's trial).
    let sep = if run_state.is_empty() { "" } else { " | " };
    let title = if state.simulated {
        "ARPA SIM "
    } else {
        "ARPA "
    };
    let fits =
        |line: &str| title.len() + run_state.len() + sep.len() + line.chars().count() <= inner;
    if !fits(&first) {
        first = counts(" ", "", &state.link, "trk", "acq", "held");
    }
    if !narrow && !fits(&first) {
        first = counts(" ", "", "", "trk", "acq", "held");
    }
    let text = vec![
        Line::from(vec![
            Span::styled(title, Style::default().add_modifier(Modifier::BOLD)),
            Span::styled(
                run_state,
                Style::default().add_modifier(Modifier::REVERSED | Modifier::BOLD),
            ),
            Span::raw(sep),
            Span::raw(first),
        ]),
        Line::raw(own_ship_words(&view.own, narrow)),
        // In a narrow pane on one row (at most 40 characters: "48 NM true 30 min alarm
        // 12.00 NM/60 min"), so that the rows above may wrap and the limits still show.
        Line::raw(format!(
            "{}{join}NM{gap}{}{}{join}min{gap}{} {:.2}{join}NM{}{:.0}{join}min",
            RANGE_SCALES_NM[state.range_scale],
            match (vectors_shown(state, view), narrow) {
                (VectorMode::Relative, false) => "relative vectors ",
                (VectorMode::Relative, true) => "rel ",
                (VectorMode::True, false) => "true vectors ",
                (VectorMode::True, true) => "true ",
            },
            VECTOR_MINUTES[state.vector_length],
            if narrow { "alarm" } else { "CPA/TCPA alarm" },
            state.limits.cpa_m / METRES_PER_NM,
            if narrow { "/" } else { " / " },
            state.limits.tcpa_s / 60.0,
        )),
    ];
    frame.render_widget(
        if narrow {
            Paragraph::new(text).wrap(ratatui::widgets::Wrap { trim: true })
        } else {
            Paragraph::new(text)
        }
        .block(Block::default().borders(Borders::ALL)),
        area,
    );
}

/// Own ship as the header shows it: course and speed over ground, heading, and how it is
/// known.
pub fn own_ship_line(own: &crate::own_ship::OwnShip) -> String {
    own_ship_words(own, false)
}

/// [`own_ship_line`], or for a `narrow` pane whose lines wrap, with single spaces between
/// the items and each figure joined to its word and unit by a no-break space.
fn own_ship_words(own: &crate::own_ship::OwnShip, narrow: bool) -> String {
    let (gap, join) = if narrow { (" ", "\u{a0}") } else { ("  ", " ") };
    let q = own.quality;
    // A heading given (`--heading-deg`) is marked as a manual input, not a sensor's.
    let given = if q.heading_given {
        format!("{join}MAN")
    } else {
        String::new()
    };
    let heading = own.heading_rad.map_or("---".to_string(), |h| {
        format!(
            "{:0>5}{given}",
            crate::nmea::angle_360(f64::from(h).to_degrees(), 1)
        )
    });
    // Unknown motion is not a ship stopped, and a ship stopped has no course.
    let sog = own.sog_kn().map_or(format!("----{join}kn"), |kn| {
        let figure = format!("{kn:4.1}");
        let figure = if narrow { figure.trim_start() } else { &figure };
        format!("{figure}{join}kn")
    });
    let cog = own.cog_deg().map_or("---.-".to_string(), |deg| {
        format!("{:0>5}", crate::nmea::angle_360(deg, 1))
    });
    let state = if q.no_fix_yet {
        "NO FIX".to_string()
    } else if q.fixed_position {
        "FIXED".to_string()
    } else if let Some(age) = q.dead_reckoning_s {
        // Past dead reckoning's reach: lost, the alarm says since when (a log of another
        // voyage read to its end showed `DR 47499628 s`).
        if f64::from(age) > crate::own_ship::nav::MAX_DEAD_RECKONING_S {
            "POS LOST".to_string()
        } else {
            format!("DR {age:.0} s")
        }
    } else {
        "fix".to_string()
    };
    format!("OWN{gap}COG{join}{cog}{gap}SOG{join}{sog}{gap}HDG{join}{heading}{gap}{state}")
}

/// The vectors drawn: the operator's choice, relative while own ship's motion over ground is
/// unknown (no fix yet, not yet measured, or dead reckoned past its limit): a true vector
/// would need it, and calling one true then would mislead (a new user's trial read "true
/// vectors" beside `NO FIX`). [`drawn_velocity`] makes the relative one.
fn vectors_shown(state: &DisplayState, view: &ScanReport) -> VectorMode {
    if view.own.quality.motion_known {
        state.vectors
    } else {
        VectorMode::Relative
    }
}

/// The vector drawn for a velocity `v` (m/s, as the session gives it): true, or relative
/// to own ship's. Where own ship's position stands still (stopped at the origin before a
/// fix, held where dead reckoning stopped) a radar target's velocity is already its motion
/// relative to own ship, and own ship's last velocity is not taken off it again
/// ([`OwnShip::track_frame_velocity_mps`]).
///
/// [`OwnShip::track_frame_velocity_mps`]: crate::own_ship::OwnShip::track_frame_velocity_mps
fn drawn_velocity(state: &DisplayState, view: &ScanReport, v: EastNorth) -> EastNorth {
    match vectors_shown(state, view) {
        VectorMode::Relative => geo::relative_velocity(view.own.track_frame_velocity_mps(), v),
        VectorMode::True => v,
    }
}

fn render_ppi(frame: &mut Frame, area: Rect, state: &DisplayState, view: &ScanReport) {
    let scale = f64::from(RANGE_SCALES_NM[state.range_scale]);
    let own = view.own.position_m;
    // Everything in NM relative to own ship; east right, north up.
    let rel = |p: EastNorth| {
        (
            f64::from(p[0] - own[0]) / f64::from(METRES_PER_NM),
            f64::from(p[1] - own[1]) / f64::from(METRES_PER_NM),
        )
    };
    let plots: Vec<(f64, f64)> = view.plots_m.iter().map(|p| rel(*p)).collect();
    // Echoes of a quarter of full scale and more (level 4 of a Navico's 15), within the scale.
    let echoes: Vec<(f64, f64)> = match (&view.echoes, state.echoes) {
        (Some(image), true) => image
            .echoes(ECHO_FRACTION)
            .map(|(b, r, _)| {
                let r = f64::from(r) / f64::from(METRES_PER_NM);
                (r * f64::from(b.sin()), r * f64::from(b.cos()))
            })
            .filter(|(x, y)| x.abs() <= scale && y.abs() <= scale)
            .collect(),
        _ => Vec::new(),
    };
    let trails: Vec<(f64, f64)> = state
        .trails
        .values()
        .flat_map(|t| t.iter().map(|p| rel(*p)))
        .collect();
    let minutes = f64::from(VECTOR_MINUTES[state.vector_length]) * 60.0;
    let canvas = Canvas::default()
        .block(
            Block::default()
                .borders(Borders::ALL)
                .title(format!(" PPI {scale} NM, rings {} NM ", scale / 2.0)),
        )
        .marker(Marker::Braille)
        .x_bounds([-scale, scale])
        .y_bounds([-scale, scale])
        .paint(|ctx| {
            ctx.draw(&Points::new(&echoes, Color::Blue));
            ctx.layer();
            for ring in [scale / 2.0, scale] {
                ctx.draw(&Circle::new(0.0, 0.0, ring, Color::DarkGray));
            }
            ctx.draw(&Points::new(&plots, Color::Yellow));
            ctx.layer();
            ctx.draw(&Points::new(&trails, Color::Gray));
            // Tracks being acquired (a second plot, no number yet): a small grey circle
            // without a vector (IEC 62388: a target in acquisition has none). The header's
            // acquiring count counts them, and nothing on the PPI told them from the plots
            // (two new users' trials).
            for t in &view.acquiring {
                let (x, y) = rel(t.position_m);
                ctx.draw(&Circle::new(x, y, scale / 90.0, Color::Gray));
            }
            for t in view.targets_drawn(state.associated) {
                let (x, y) = rel(t.position_m);
                let v = drawn_velocity(state, view, t.velocity_mps);
                let to = |c: f32| f64::from(c) * minutes / f64::from(METRES_PER_NM);
                let colour = if t.dangerous(&state.limits) {
                    Color::Red
                } else if state.selected == Some(t.track) {
                    Color::Cyan
                } else {
                    Color::Green
                };
                // No vector before the motion's trend is known (IEC 62388: a target in
                // acquisition has none).
                if t.trend_known {
                    ctx.draw(&CanvasLine::new(x, y, x + to(v[0]), y + to(v[1]), colour));
                }
                ctx.draw(&Circle::new(x, y, scale / 60.0, colour));
            }
            // AIS targets (those of associated ships too, with the AIS symbol): a triangle
            // pointing along the heading (else the course), with a vector when activated;
            // an associated ship's takes its radar target's alarm and selection.
            for a in view.ais_drawn(state.associated) {
                let (x, y) = rel(a.position_m);
                if x.abs() > scale || y.abs() > scale {
                    continue;
                }
                let radar = view
                    .associated_track(a.mmsi)
                    .and_then(|track| view.targets.iter().find(|t| t.track == track));
                let colour = if (a.active && ais_dangerous(a, &state.limits))
                    || radar.is_some_and(|t| t.dangerous(&state.limits))
                {
                    Color::Red
                } else if radar.is_some_and(|t| state.selected == Some(t.track)) {
                    Color::Cyan
                } else {
                    Color::Magenta
                };
                let course = a
                    .heading_rad
                    .unwrap_or_else(|| a.velocity_mps[0].atan2(a.velocity_mps[1]));
                let size = scale / 40.0;
                let corner = |angle: f32, length: f64| {
                    (
                        x + length * f64::from(angle.sin()),
                        y + length * f64::from(angle.cos()),
                    )
                };
                let tip = corner(course, size);
                let left = corner(course + 2.5, size * 0.7);
                let right = corner(course - 2.5, size * 0.7);
                for (a0, b0) in [(tip, left), (left, right), (right, tip)] {
                    ctx.draw(&CanvasLine::new(a0.0, a0.1, b0.0, b0.1, colour));
                }
                // An associated ship's vector is its radar target's, drawn at any range; none
                // while own ship's motion is unknown (an AIS velocity is over ground, and its
                // motion relative to own ship is not known, as its CPA is not).
                if (a.active || radar.is_some()) && view.own.quality.motion_known {
                    let to = |c: f32| f64::from(c) * minutes / f64::from(METRES_PER_NM);
                    let v = drawn_velocity(state, view, a.velocity_mps);
                    ctx.draw(&CanvasLine::new(x, y, x + to(v[0]), y + to(v[1]), colour));
                }
            }
            // The selected target, a ring around it in any colour: a target in alarm is
            // drawn red, and its selection was shown nowhere (a new user's trial).
            if let Some(t) =
                (state.selected).and_then(|id| view.targets.iter().find(|t| t.track == id))
            {
                let (x, y) = rel(t.position_m);
                ctx.draw(&Circle::new(x, y, scale / 25.0, Color::Cyan));
            }
            // Own ship's heading line, from own ship to the PPI's edge (IEC 62388: drawn
            // whenever a heading is known), and its vector.
            if let Some(h) = view.own.heading_rad {
                let (sin, cos) = (f64::from(h.sin()), f64::from(h.cos()));
                ctx.draw(&CanvasLine::new(
                    0.0,
                    0.0,
                    scale * sin,
                    scale * cos,
                    Color::White,
                ));
            }
            let hv = view.own.velocity_mps;
            let to = |c: f32| f64::from(c) * minutes / f64::from(METRES_PER_NM);
            ctx.draw(&CanvasLine::new(
                0.0,
                0.0,
                to(hv[0]),
                to(hv[1]),
                Color::White,
            ));
            ctx.print(
                0.0,
                0.0,
                Span::styled("+", Style::default().fg(Color::White)),
            );
        });
    frame.render_widget(canvas, area);
}

/// The table's columns at full width, characters: wider than this (with the borders and a
/// space between columns) it is drawn in full, narrower in its compact form
/// ([`render_table`]).
const TABLE_WIDTHS: [u16; 9] = [5, 9, 7, 7, 7, 7, 7, 9, AIS_COLUMN_WIDTH];

/// The compact table's columns (the AIS name takes what is left): in an 80-column terminal
/// the full table's columns were cut short, `279.` for a course of 279.4° and a target
/// number to one digit at 40 columns.
const COMPACT_WIDTHS: [u16; 8] = [3, 4, 5, 3, 3, 4, 5, 6];

/// The radar targets in the order the table lists them, when it holds `room` rows: nearest
/// first; too short for every target, the targets in alarm first (each group nearest
/// first), so that the alarm box's list of them by number has their figures on screen (at
/// 80×24 a new user's trial saw `soonest first (2): 17 12` over six rows that held
/// neither).
fn table_order<'a>(view: &'a ScanReport, limits: &AlarmLimits, room: usize) -> Vec<&'a TargetData> {
    if view.targets.len() <= room {
        return view.targets.iter().collect();
    }
    let (alarmed, rest): (Vec<&TargetData>, Vec<&TargetData>) =
        view.targets.iter().partition(|t| t.dangerous(limits));
    alarmed.into_iter().chain(rest).collect()
}

/// A target's status in four characters, for the compact table.
fn short_status(t: &TargetData) -> &'static str {
    match shown_status(t) {
        "tracked" => "trk",
        "acquiring" => "acq",
        "coasting" => "cst",
        _ => "LOST",
    }
}

/// The target table: full (units in the header, a decimal of a degree) where the pane is
/// wide enough, else compact (whole degrees, units left to the header's names), so that no
/// figure is ever cut short.
fn render_table(frame: &mut Frame, area: Rect, state: &DisplayState, view: &ScanReport) {
    if state.ais_table {
        return ais_table::render(frame, area, state, view);
    }
    let full: u16 = TABLE_WIDTHS.iter().sum::<u16>() + TABLE_WIDTHS.len() as u16 - 1 + 2;
    let compact = area.width < full;
    // The compact table's AIS column takes what the other columns leave; too narrow for an
    // MMSI and a count, it is left out rather than cut (at 80 columns a new user's trial saw
    // the column's name as `A` and every MMSI as its first digit).
    let ais_room = if compact {
        let others = COMPACT_WIDTHS.iter().sum::<u16>() + COMPACT_WIDTHS.len() as u16 + 2;
        area.width.saturating_sub(others)
    } else {
        AIS_COLUMN_WIDTH
    };
    let show_ais = ais_room >= AIS_COLUMN_MIN_WIDTH;
    // Without own ship's motion over ground the targets' true course and speed are not
    // known: the columns give the relative ones, and say so (a new user's trial read a
    // moored radar's relative motion under `CRS °T` and `SPD kn` without a fix).
    let relative = !view.own.quality.motion_known;
    let (course_name, speed_name) = match (relative, compact) {
        (false, true) => ("CRS", "SPD"),
        (false, false) => ("CRS °T", "SPD kn"),
        (true, true) => ("RCR", "RSPD"),
        (true, false) => ("RCRS °T", "RSPD kn"),
    };
    let names = if compact {
        [
            "TGT",
            "ST",
            "RNG",
            "BRG",
            course_name,
            speed_name,
            "CPA",
            "TCPA",
            "AIS",
        ]
    } else {
        [
            "TGT",
            "STATUS",
            "RNG NM",
            "BRG °T",
            course_name,
            speed_name,
            "CPA NM",
            "TCPA min",
            "AIS",
        ]
    };
    let shown_names = if show_ais {
        &names[..]
    } else {
        &names[..names.len() - 1]
    };
    let header = Row::new(
        shown_names
            .iter()
            .map(|h| Cell::from(*h).style(Style::default().add_modifier(Modifier::BOLD))),
    );
    // Rows that fit under the borders and the header. When fewer than the targets, the
    // nearest are shown, unless the selected target is further down: then the table is
    // scrolled so that it is the last row (a navigator who selects a target sees its data),
    // and the title says which rows these are.
    let room = usize::from(area.height.saturating_sub(3));
    state.table_rows_drawn.set(room);
    let n = view.targets.len();
    let order = table_order(view, &state.limits, room);
    let alarms_first = n > room && view.targets.iter().any(|t| t.dangerous(&state.limits));
    let skip = state
        .selected
        .and_then(|id| order.iter().position(|t| t.track == id))
        .map_or(0, |i| (i + 1).saturating_sub(room));
    let rows = order.iter().skip(skip).map(|t: &&TargetData| {
        let t = *t;
        // Selected: a background (red for a target in alarm, whose row is red anyway).
        let style = match (t.dangerous(&state.limits), state.selected == Some(t.track)) {
            (true, true) => Style::default().fg(Color::White).bg(Color::Red),
            (true, false) => Style::default().fg(Color::Red),
            (false, true) => Style::default().fg(Color::Black).bg(Color::Cyan),
            (false, false) => Style::default(),
        };
        // The motion is `---` until its trend is known.
        let motion = |v: f32, places: usize| {
            if t.trend_known {
                format!("{v:.places$}")
            } else {
                "---".to_string()
            }
        };
        let angle = |deg: f32| table_angle(deg, compact);
        let course = if relative {
            if t.trend_known && !t.keeps_range() {
                angle(t.rel_course_rad.to_degrees())
            } else {
                "---".to_string()
            }
        } else if t.trend_known && t.moving() {
            angle(t.course_rad.to_degrees())
        } else {
            "---".to_string()
        };
        let speed_mps = if relative {
            t.rel_speed_mps
        } else {
            t.speed_mps
        };
        let mut cells = vec![
            t.label(),
            if compact {
                short_status(t).to_string()
            } else {
                shown_status(t).to_string()
            },
            format!("{:.2}", t.range_m / METRES_PER_NM),
            angle(t.bearing_rad.to_degrees()),
            course,
            motion(speed_mps / MPS_PER_KNOT, 1),
            motion(t.cpa_m / METRES_PER_NM, 2),
            if t.trend_known {
                crate::session::target::tcpa_text(t.tcpa_s)
            } else {
                "---".to_string()
            },
        ];
        if show_ais {
            cells.push(ais_column_within(view, t.track, usize::from(ais_room)));
        }
        Row::new(cells).style(style)
    });
    let widths = if compact {
        column_widths(&COMPACT_WIDTHS, show_ais)
    } else {
        column_widths(&TABLE_WIDTHS, false)
    };
    let order_words = if alarms_first {
        "alarms first"
    } else {
        "nearest first"
    };
    let title = if skip > 0 {
        format!(
            " targets, {order_words}: {}–{} of {n} shown ",
            skip + 1,
            skip + room
        )
    } else if n > room {
        format!(" targets, {order_words}: {room} of {n} shown ")
    } else {
        " targets, nearest first ".to_string()
    };
    // Said first where the pane is narrow (at 80 columns the note after the title was
    // cut off, leaving `RCR` and `RSPD` unexplained).
    let title = match (relative, compact) {
        (true, true) => format!(" relative motion:{}", title.trim_start_matches(" targets,")),
        (true, false) => format!("{title}(course and speed relative: own ship's motion unknown) "),
        (false, _) => title,
    };
    draw_table(frame, area, (header, rows), widths, title);
}

/// An angle (degrees) as a table shows it: whole degrees in three digits in a compact
/// table, else tenths; one that rounds to 360 shows as 0 ([`crate::nmea::shown_angle_deg`]).
fn table_angle(deg: f32, compact: bool) -> String {
    let shown = crate::nmea::shown_angle_deg(f64::from(deg), usize::from(!compact)) as f32;
    if compact {
        format!("{shown:03.0}")
    } else {
        format!("{shown:.1}")
    }
}

/// A table's columns of `lengths` characters, and with `rest` one more taking what is left
/// (a compact table's name).
fn column_widths(lengths: &[u16], rest: bool) -> Vec<Constraint> {
    lengths
        .iter()
        .map(|w| Constraint::Length(*w))
        .chain(rest.then_some(Constraint::Min(0)))
        .collect()
}

/// Draws a table of `header` and `rows` in `area`, boxed under `title`.
fn draw_table<'a>(
    frame: &mut Frame,
    area: Rect,
    (header, rows): (Row<'a>, impl IntoIterator<Item = Row<'a>>),
    widths: Vec<Constraint>,
    title: String,
) {
    let table = Table::new(rows, widths)
        .header(header)
        .block(Block::default().borders(Borders::ALL).title(title));
    frame.render_widget(table, area);
}

/// The table's AIS column, characters: an AIS name is at most 20.
pub const AIS_COLUMN_WIDTH: u16 = 20;

/// The narrowest AIS column the compact table draws, characters: an MMSI (9 digits, shown
/// for a ship whose name is not heard) and a count of more ships (`? +99`), never cut.
pub const AIS_COLUMN_MIN_WIDTH: u16 = 14;

/// The table's AIS column, at most [`AIS_COLUMN_WIDTH`] characters: the paired AIS target's
/// name; or, while a radar target is shown as AIS targets (its pair being confirmed, or
/// ships it does not tell apart), the nearest one's name with a `?` and how many more
/// (`+1`), the name cut short to fit.
pub(crate) fn ais_column(view: &ScanReport, track: u16) -> String {
    ais_column_within(view, track, usize::from(AIS_COLUMN_WIDTH))
}

/// [`ais_column`] in at most `width` characters: a name cut short to fit (a word), an MMSI
/// whole (a figure: the caller gives at least [`AIS_COLUMN_MIN_WIDTH`]).
fn ais_column_within(view: &ScanReport, track: u16, width: usize) -> String {
    if let Some(p) = view.paired.iter().find(|p| p.track == track) {
        return fit(&p.label, "", width);
    }
    let Some(x) = view.targets.iter().find(|t| t.track == track) else {
        return String::new();
    };
    let gap = |a: &crate::ais::AisTargetData| {
        libm::hypotf(
            a.hull_centre_m[0] - x.position_m[0],
            a.hull_centre_m[1] - x.position_m[1],
        )
    };
    let shown: Vec<&crate::ais::AisTargetData> = view
        .merged
        .iter()
        .filter(|c| c.track == track)
        .filter_map(|c| view.ais.iter().find(|a| a.mmsi == c.mmsi))
        .collect();
    let Some(nearest) = shown.iter().min_by(|a, b| gap(a).total_cmp(&gap(b))) else {
        return String::new();
    };
    let more = match shown.len() - 1 {
        0 => "?".to_string(),
        n => format!("? +{n}"),
    };
    fit(&nearest.label, &more, width)
}

/// `name` cut short so that it and `suffix` fill at most `width` characters.
fn fit(name: &str, suffix: &str, width: usize) -> String {
    let room = width.saturating_sub(suffix.chars().count());
    let mut out = name
        .chars()
        .take(room)
        .collect::<String>()
        .trim_end()
        .to_string();
    out.push_str(suffix);
    out
}

/// The alarm box's key help, drawn under the alarms while there is room, laid out to the
/// box's width ([`wrap`]: at 80 columns two fixed lines were cut to "… ↑" and "… e echoe",
/// and `p`, `q` and Enter went unlisted).
const KEY_HELP: [&str; 12] = [
    "+/- range",
    "v vectors",
    "[/] vector length",
    "↑↓ select",
    "a acquire",
    "c cancel",
    "C cancel all",
    "e echoes",
    "i AIS table",
    "p pause",
    "q quit",
    "Enter acknowledge",
];

/// `pieces` joined with `separator` into lines of at most `width` characters (a piece
/// longer than that alone on its line, cut by the box).
pub(crate) fn wrap<'a>(
    pieces: impl IntoIterator<Item = &'a str>,
    separator: &str,
    width: usize,
) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for piece in pieces {
        match lines.last_mut() {
            Some(l)
                if l.chars().count() + separator.chars().count() + piece.chars().count()
                    <= width =>
            {
                l.push_str(separator);
                l.push_str(piece);
            }
            _ => lines.push(piece.to_string()),
        }
    }
    lines
}

/// The answer to the operator's last command, in lines of the box's inner `width` (a reply
/// cut at 80 columns read "target 35 cancelled: gone from the next ro").
fn message_lines(state: &DisplayState, width: usize) -> Vec<String> {
    state
        .message
        .as_deref()
        .map_or_else(Vec::new, |m| wrap(m.split_whitespace(), " ", width))
}

/// The alarm box's height in rows (borders included) in a pane `width` columns wide: room
/// for every line and the help, from 7 up to [`ALARM_BOX_MAX_ROWS`].
fn alarm_box_rows(alarms: &[Line], state: &DisplayState, width: u16) -> u16 {
    let inner = usize::from(width.saturating_sub(2));
    let lines = alarms.len().max(1)
        + message_lines(state, inner).len()
        + wrap(KEY_HELP, ", ", inner).len()
        + 2;
    u16::try_from(lines).map_or(ALARM_BOX_MAX_ROWS, |n| n.clamp(7, ALARM_BOX_MAX_ROWS))
}

/// The alarm box never takes more rows than this; what does not fit is counted on its last
/// line.
const ALARM_BOX_MAX_ROWS: u16 = 14;

/// The target table keeps at least this many rows of targets: past it the alarms are
/// listed by target ([`alarm_lines`]' grouped form).
const TABLE_MIN_TARGET_ROWS: u16 = 6;

/// The alarm box's lines, the most urgent first: a live radar gone silent and own ship's
/// sensor alarms, then the CPA/TCPA alarms of radar and AIS targets together, the soonest
/// closest approach first (IEC 62388 has the operator see every alarm; the soonest is the
/// one to act on), lost targets, the track table's capacity, then skipped scans. (The answer
/// to the operator's last command is drawn apart, always: see [`render_alarms`].)
///
/// With `grouped` (the box's inner width, columns), the radar targets' CPA/TCPA alarms and
/// the lost targets are listed by their targets' labels, as many to a line as fit (the CPA
/// and TCPA of each are in the table, its row red); an AIS target's alarm, which has no row
/// there, keeps its line: every alarm is still seen, in fewer rows.
fn alarm_lines(
    state: &DisplayState,
    view: &ScanReport,
    narrow: bool,
    grouped: Option<usize>,
) -> AlarmLines {
    // In a narrow pane the words go, not the figures.
    let head = if narrow { "ALARM" } else { "CPA/TCPA ALARM:" };
    let (of, cpa) = if narrow {
        ("", "")
    } else {
        ("target ", "CPA ")
    };
    // In a narrow pane the figure alone (`-0.3 min` once passed), else the words.
    let when = |tcpa_s: f32| {
        if narrow {
            format!("{} min", crate::session::target::tcpa_text(tcpa_s))
        } else {
            crate::session::target::tcpa_words(tcpa_s)
        }
    };
    let alarm = Style::default().fg(Color::Red).add_modifier(Modifier::BOLD);
    let mut lines: Vec<Line> = state
        .radar_silent_s
        .map(|s| {
            Line::styled(
                if state.paused {
                    format!("NO RADAR DATA for {s} s")
                } else {
                    format!("NO RADAR DATA for {s} s: the picture is the last received")
                },
                alarm,
            )
        })
        .into_iter()
        .collect();
    lines.extend(
        view.own
            .alarms()
            .into_iter()
            .map(|a| Line::styled(a, alarm)),
    );
    // (TCPA, the radar target's label, the alarm's line); an AIS target has no label here.
    let mut approaching: Vec<(f32, Option<String>, String)> = view
        .targets
        .iter()
        .filter(|t| t.dangerous(&state.limits))
        .map(|t| {
            (
                t.tcpa_s,
                Some(t.label()),
                format!(
                    "{head} {of}{} {cpa}{:.2} NM {}",
                    t.label(),
                    t.cpa_m / METRES_PER_NM,
                    when(t.tcpa_s)
                ),
            )
        })
        .collect();
    approaching.extend(ais_alarms(view, &state.limits).filter_map(|a| {
        let c = a.cpa?;
        Some((
            c.tcpa_s,
            None,
            format!(
                "{head} AIS {} {cpa}{:.2} NM {}",
                if narrow {
                    a.label.chars().take(NARROW_AIS_NAME).collect::<String>()
                } else {
                    a.label.clone()
                },
                c.cpa_m / METRES_PER_NM,
                when(c.tcpa_s)
            ),
        ))
    }));
    approaching.sort_by(|a, b| a.0.total_cmp(&b.0));
    // A list by target: its head, then the labels (one word each), wrapped to the box;
    // each line with the number of targets it names.
    let listed = |head: &str, labels: Vec<String>, width: usize| -> Vec<(String, usize)> {
        let head = format!("{head} ({}):", labels.len());
        let head_words = head.split(' ').count();
        wrap(
            std::iter::once(head.as_str()).chain(labels.iter().map(String::as_str)),
            " ",
            width,
        )
        .into_iter()
        .enumerate()
        .map(|(i, l)| {
            let words = l.split(' ').count();
            let n = if i == 0 { words - head_words } else { words };
            (l, n)
        })
        .collect()
    };
    // Lines that name several alarms: (index in `lines`, how many).
    let mut several: Vec<(usize, usize)> = Vec::new();
    // Grouped, the radar targets are listed by label (their CPA and TCPA are in the
    // table); an AIS target, which has no row there, keeps its line.
    let (labels, lines_of): (Vec<String>, Vec<String>) = match grouped {
        Some(_) => {
            let (radar, ais): (Vec<_>, Vec<_>) =
                approaching.into_iter().partition(|(_, l, _)| l.is_some());
            (
                radar.into_iter().filter_map(|(_, l, _)| l).collect(),
                ais.into_iter().map(|(_, _, text)| text).collect(),
            )
        }
        None => (
            Vec::new(),
            approaching.into_iter().map(|(_, _, text)| text).collect(),
        ),
    };
    if let (Some(width), false) = (grouped, labels.is_empty()) {
        for (text, n) in listed("CPA/TCPA ALARM, soonest first", labels, width) {
            several.push((lines.len(), n));
            lines.push(Line::styled(text, alarm));
        }
    }
    lines.extend(lines_of.into_iter().map(|text| Line::styled(text, alarm)));
    if let Some(silence) = &state.silence {
        let text = if narrow {
            silence.short()
        } else {
            silence.to_string()
        };
        lines.push(Line::styled(text, alarm));
    }
    let lost = Style::default().fg(Color::Magenta);
    match grouped {
        Some(width) if !state.lost.is_empty() => {
            let ids = state.lost.iter().map(ToString::to_string).collect();
            for (text, n) in listed("LOST TARGETS", ids, width) {
                several.push((lines.len(), n));
                lines.push(Line::styled(text, lost));
            }
        }
        _ => {
            for id in &state.lost {
                lines.push(Line::styled(format!("LOST TARGET {id}"), lost));
            }
        }
    }
    if view.tracks.len() + 4 >= MAX_TRACKS {
        lines.push(Line::styled(
            format!(
                "CAPACITY: {} of {} tracks in use",
                view.tracks.len(),
                MAX_TRACKS
            ),
            Style::default().fg(Color::Yellow),
        ));
    }
    if let Some(note) = &view.skipped {
        lines.push(Line::styled(
            note.clone(),
            Style::default().fg(Color::Yellow),
        ));
    }
    let mut held = vec![1; lines.len()];
    for (i, n) in several {
        held[i] = n;
    }
    AlarmLines { lines, held }
}

/// The alarm box's lines ([`alarm_lines`]) and how many alarms or notes each holds: one,
/// or a grouped line's targets (what does not fit is counted by them).
struct AlarmLines {
    lines: Vec<Line<'static>>,
    held: Vec<usize>,
}

impl AlarmLines {
    /// Each line wider than `width` wrapped at its spaces onto rows of its own, indented
    /// by two (the last row holds what the line held, the others nothing: an alarm cut
    /// between its rows by the box's `+N more` is counted there as not shown), so that no
    /// figure is cut at the box's edge: at 100 columns the box is 53 characters inside, and
    /// "RADAR SILENT: no scan for 37.6 s (12 rotations missed): 29 targets lost, acquiring
    /// again" lost its targets (a new user's trial).
    fn wrapped(self, width: usize) -> Self {
        let mut out = AlarmLines {
            lines: Vec::with_capacity(self.lines.len()),
            held: Vec::with_capacity(self.held.len()),
        };
        for (line, held) in self.lines.into_iter().zip(self.held) {
            let text = line.to_string();
            if width < 8 || text.chars().count() <= width {
                out.lines.push(line);
                out.held.push(held);
                continue;
            }
            let style = line
                .spans
                .first()
                .map_or(line.style, |s| line.style.patch(s.style));
            let rows = wrap(text.split(' '), " ", width - 2);
            let last = rows.len().saturating_sub(1);
            for (i, row) in rows.into_iter().enumerate() {
                let row = if i == 0 { row } else { format!("  {row}") };
                out.lines.push(Line::styled(row, style));
                out.held.push(if i == last { held } else { 0 });
            }
        }
        out
    }
}

/// Draws the alarm box: `lines` ([`alarm_lines`]), the answer to the operator's last
/// command, and the key help while there is room.
fn render_alarms(frame: &mut Frame, area: Rect, state: &DisplayState, alarms: AlarmLines) {
    let AlarmLines { mut lines, held } = alarms;
    if lines.is_empty() && state.message.is_none() {
        lines.push(Line::raw("no alarms"));
    }
    // Inside the borders, less a row for the answer to the operator's last command (a key
    // just pressed must show its effect, whatever the alarms). Lines that do not fit are
    // never dropped silently: the last row counts them.
    let width = usize::from(area.width.saturating_sub(2));
    let message: Vec<Line> = message_lines(state, width)
        .into_iter()
        .map(|m| Line::styled(m, Style::default().fg(Color::Yellow)))
        .collect();
    let inner = usize::from(area.height.saturating_sub(2));
    let rows = inner.saturating_sub(message.len());
    if lines.len() > rows && rows > 0 {
        // Counted by what the lines hold (a grouped line names several targets).
        let more: usize = held.iter().skip(rows - 1).sum();
        lines.truncate(rows - 1);
        lines.push(Line::styled(
            format!("+{more} more (alarms and notes not shown)"),
            Style::default().fg(Color::Red).add_modifier(Modifier::BOLD),
        ));
    }
    lines.extend(message);
    for help in wrap(KEY_HELP, ", ", width)
        .into_iter()
        .take(inner.saturating_sub(lines.len()))
    {
        lines.push(Line::styled(help, Style::default().fg(Color::DarkGray)));
    }
    frame.render_widget(
        Paragraph::new(lines).block(Block::default().borders(Borders::ALL).title(" alarms ")),
        area,
    );
}

/// Applies an operator key to the display and, for a command, to the device; returns true
/// for quit. A command the device refuses is a message on the display, never an exit.
pub fn key(
    run: &mut Run,
    state: &mut DisplayState,
    key: char,
    drawn: &ScanReport,
    latest: &ScanReport,
) -> bool {
    use tracker_core::icd::TrackCommand;
    // A plot to acquire is one of the scan tracked last; a target is selected among those
    // drawn (a paused picture's).
    let view = if key == 'a' { latest } else { drawn };
    // Past the input's end no rotation comes to act on a command or to pause: said so
    // (a cancel was answered "gone from the next rotation", and `p` not at all).
    if state.ended && matches!(key, 'a' | 'c' | 'C' | 'p') {
        state.message =
            Some("the input has ended: no more scans, the last picture stays (q quits)".into());
        return false;
    }
    let command = match state.key(key, Some(view)) {
        Action::None if key == 'p' && run.is_live() => {
            state.message = state
                .paused
                .then(|| "picture paused: the radar is tracked on, alarms too (p resumes)".into());
            None
        }
        Action::None => None,
        Action::Quit => return true,
        Action::Acquire(plot) => Some(TrackCommand::Acquire { plot }),
        Action::Cancel(track) => Some(TrackCommand::Cancel { track }),
        Action::CancelAll => Some(TrackCommand::CancelAll),
    };
    if let Some(c) = command {
        let gone = if state.paused {
            "gone from the picture when it resumes (p)"
        } else {
            "gone from the next rotation"
        };
        state.message = Some(match run.session_mut().command(c) {
            Err(e) => format!("{e:#}"),
            // Said at once: the picture changes only with the next rotation, which a
            // silent radar may not send for a while.
            Ok(()) => match c {
                TrackCommand::CancelAll => format!("all targets cancelled: {gone}"),
                TrackCommand::Cancel { track } => format!(
                    "target {} cancelled: {gone}",
                    view.targets
                        .iter()
                        .find(|t| t.track == track)
                        .map_or_else(|| format!("(track {track})"), TargetData::label)
                ),
                TrackCommand::Acquire { .. } if state.paused => {
                    "acquiring the nearest plot no track holds in the scan tracked last: shown when the picture resumes (p)".to_string()
                }
                TrackCommand::Acquire { .. } => {
                    "acquiring the nearest plot no track holds: shown as acquiring from its next plot".to_string()
                }
            },
        });
    }
    false
}

/// How long the display waits for a live radar's scan before it answers keys and redraws.
const LIVE_POLL: std::time::Duration = std::time::Duration::from_millis(100);

/// A live radar silent this many antenna periods (and at least [`SILENT_MIN_S`]) raises
/// the display's no-radar-data alarm.
const SILENT_PERIODS: f64 = 3.0;
/// The shortest silence alarmed, s.
const SILENT_MIN_S: f64 = 10.0;

/// The next key pressed within `wait`, as [`key`] takes it (`q` for Esc and Ctrl-C: the
/// terminal is raw, so Ctrl-C comes as a key).
fn next_key(wait: std::time::Duration) -> anyhow::Result<Option<char>> {
    use ratatui::crossterm::event::{self, Event, KeyCode, KeyEventKind, KeyModifiers};
    if !event::poll(wait.max(std::time::Duration::from_millis(1)))? {
        return Ok(None);
    }
    let Event::Key(k) = event::read()? else {
        return Ok(None);
    };
    if k.kind != KeyEventKind::Press {
        return Ok(None);
    }
    Ok(match k.code {
        KeyCode::Char('c') if k.modifiers.contains(KeyModifiers::CONTROL) => Some('q'),
        KeyCode::Char(c) => Some(c),
        KeyCode::Up => Some('↑'),
        KeyCode::Down => Some('↓'),
        KeyCode::Esc => Some('q'),
        KeyCode::Enter => Some('\n'),
        _ => None,
    })
}

/// A key pressed before a live radar's first rotation: the display's own settings (range
/// scale, true or relative vectors, echoes, AIS table, pause) are taken and said so; a
/// command on targets gets its own answer (`acquire: no plot without a track`), any other
/// key that there is nothing to act on yet (a new user's `p` and `-` went unanswered). The
/// vector length is not said to be taken: the first picture sets it with the scale unless
/// `+` or `-` chose one.
fn waiting_key(state: &mut DisplayState, c: char) {
    let settings = |s: &DisplayState| (s.range_scale, s.vectors, s.paused, s.ais_table);
    let before = settings(state);
    // No view: a command on targets (acquire, cancel, select) has nothing to act on.
    let _ = state.key(c, None);
    if state.message.is_some() {
        return;
    }
    let taken = before != settings(state);
    state.message = Some(if taken {
        format!("`{c}` taken: the picture shows it from the radar's first rotation")
    } else {
        format!("`{c}`: no picture yet, nothing to act on until the radar's first rotation")
    });
}

/// The screen before a live radar's first rotation has come.
fn render_waiting(frame: &mut Frame, state: &DisplayState, silent_s: u64) {
    let text = vec![
        Line::styled(
            format!(
                "ARPA  waiting for the radar's first rotation ({silent_s} s)  - link {}",
                state.link
            ),
            Style::default().add_modifier(Modifier::BOLD),
        ),
        Line::raw(""),
        Line::raw(
            "No spokes yet. Is the radar transmitting, and is the interface the one on its network",
        ),
        Line::raw("(--radar navico@ADDR, garmin@ADDR)?"),
        Line::raw(""),
        Line::raw(state.message.clone().unwrap_or_default()),
        Line::styled("q quit", Style::default().fg(Color::DarkGray)),
    ];
    frame.render_widget(
        Paragraph::new(text).block(Block::default().borders(Borders::ALL)),
        frame.area(),
    );
}

/// Runs `run` in the terminal until its source ends or the user quits; returns the scans
/// run. With `speedup`, scans are paced at the source's antenna period divided by it. A
/// live radar is never waited on with the keys unanswered: the display polls it, and says
/// when it has gone silent. The terminal is restored whatever happens.
///
/// # Errors
/// The run failed, or the terminal could not be drawn or read.
pub fn run_tui(
    run: &mut Run,
    state: &mut DisplayState,
    speedup: Option<f64>,
) -> anyhow::Result<u64> {
    use crate::app::run::Polled;
    use std::time::{Duration, Instant};

    // Seconds as a wait, at most a day (a source's period comes from its data: a plots
    // file's scans a century apart would not fit the clock).
    let secs = |s: f64| Duration::try_from_secs_f64(s.clamp(0.0, 86_400.0)).unwrap_or_default();
    let period = run.scan_period_s().unwrap_or(2.5);
    let interval = speedup.map_or(Duration::ZERO, |x| secs(period / x));
    // A live radar's period is known from its data, after its first scans.
    let silent_after = |run: &Run| {
        let period = run.scan_period_s().unwrap_or(2.5);
        secs((SILENT_PERIODS * period).max(SILENT_MIN_S))
    };
    let mut silence_alarm_after = silent_after(run);
    let live = run.is_live();
    let mut terminal = ratatui::init();
    let result = (|| -> anyhow::Result<u64> {
        // The first scan: keys are answered while a live radar is silent.
        let started = Instant::now();
        let view = loop {
            if crate::app::interrupt::interrupted() {
                return Ok(0);
            }
            match run.poll(LIVE_POLL)? {
                Polled::Scan(report) => {
                    // An answer to a key pressed while waiting is not the picture's.
                    state.message = None;
                    break *report;
                }
                Polled::Ended => return Ok(0),
                Polled::Waiting => {}
            }
            let silent_s = started.elapsed().as_secs();
            terminal.draw(|f| render_waiting(f, state, silent_s))?;
            match next_key(Duration::from_millis(1))? {
                Some('q') => return Ok(0),
                Some(c) => waiting_key(state, c),
                None => {}
            }
        };
        let mut shown = shown::Shown::new(state, view);
        let mut done = 1u64;
        let mut next_due = Instant::now() + interval;
        let mut last_scan = Instant::now();
        // A file's scans wait while paused; a live radar's are tracked on.
        let waiting = |state: &DisplayState| state.ended || (state.paused && !live);
        loop {
            // SIGTERM (the terminal's Ctrl-C comes as a key, below).
            if crate::app::interrupt::interrupted() {
                return Ok(done);
            }
            // Silence is a live radar's, and only while scans are wanted.
            if !live || state.ended {
                last_scan = Instant::now();
            }
            let silent = last_scan.elapsed();
            state.radar_silent_s = (silent >= silence_alarm_after).then_some(silent.as_secs());
            state.scans_since_paused = shown.since_paused();
            terminal.draw(|f| render_paused(f, state, shown.view(), shown.latest()))?;
            // Paused or ended, nothing is due: wait for keys without spinning.
            let wait = if waiting(state) {
                Duration::from_millis(200)
            } else {
                next_due.saturating_duration_since(Instant::now())
            };
            if let Some(c) = next_key(wait)? {
                if key(run, state, c, shown.view(), shown.latest()) {
                    return Ok(done);
                }
                shown.follow(state);
                continue;
            }
            if waiting(state) {
                // Scans resume at their pace, not in a burst to catch up.
                next_due = next_due.max(Instant::now());
                continue;
            }
            if Instant::now() < next_due {
                continue;
            }
            match run.poll(LIVE_POLL)? {
                Polled::Scan(next) => {
                    shown.take(state, *next);
                    done += 1;
                    next_due += interval;
                    last_scan = Instant::now();
                    // Measured anew with each scan, not each redraw.
                    silence_alarm_after = silent_after(run);
                }
                Polled::Waiting => {}
                // The last picture stays up to be looked at, as a radar's does.
                Polled::Ended => state.ended = true,
            }
        }
    })();
    ratatui::restore();
    result
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::app::demo::{self, DemoOptions};

    /// Before a live radar's first rotation every key is answered: a setting taken, a
    /// command on targets told there are none yet.
    #[test]
    fn keys_before_the_first_rotation_are_answered() {
        let mut state = DisplayState::new("test".into());
        let scale = state.range_scale;
        waiting_key(&mut state, '-');
        assert_eq!(state.range_scale, scale.saturating_sub(1));
        assert!(
            state.message.as_deref().unwrap().contains("taken"),
            "{:?}",
            state.message
        );
        waiting_key(&mut state, 'p');
        assert!(state.paused && state.message.as_deref().unwrap().contains("taken"));
        waiting_key(&mut state, 'x');
        assert!(state.message.as_deref().unwrap().contains("no picture yet"));
        waiting_key(&mut state, 'a');
        assert!(state.message.as_deref().unwrap().starts_with("acquire:"));
    }

    /// A course or heading a hair under 360° shows as 000.0, not 360.0 (rounded first,
    /// then wrapped, as NMEA out sends it).
    #[test]
    fn own_course_and_heading_never_show_360() {
        let a = (359.97f32).to_radians();
        let mut own = crate::own_ship::OwnShip::at([0.0, 0.0], [5.0 * a.sin(), 5.0 * a.cos()]);
        own.heading_rad = Some(a);
        let line = own_ship_line(&own);
        assert!(
            line.contains("COG 000.0") && line.contains("HDG 000.0"),
            "{line}"
        );
    }
    use crate::link::{Client, InprocTransport};
    use ratatui::backend::TestBackend;
    use ratatui::Terminal;
    use tracker_core::filter::FilterKind;

    pub(crate) fn demo() -> Run {
        let options = DemoOptions::new(
            tracker_core::sim::ScenarioKind::OpenSea,
            12,
            3,
            60.0,
            FilterKind::KalmanCv,
        );
        demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap()
    }

    /// The next scan (the demo runs 24).
    pub(crate) fn step(d: &mut Run) -> ScanReport {
        d.step().unwrap().unwrap()
    }

    fn screen(state: &DisplayState, view: &ScanReport) -> String {
        screen_at(state, view, 160, 40)
    }

    fn screen_at(state: &DisplayState, view: &ScanReport, width: u16, height: u16) -> String {
        let mut terminal = Terminal::new(TestBackend::new(width, height)).unwrap();
        terminal.draw(|f| render(f, state, view)).unwrap();
        let mut text = buffer_rows(terminal.backend().buffer()).join("\n");
        text.push('\n');
        text
    }

    /// A drawn buffer's rows as text.
    fn buffer_rows(buffer: &ratatui::buffer::Buffer) -> Vec<String> {
        (0..buffer.area.height)
            .map(|y| {
                (0..buffer.area.width)
                    .map(|x| buffer[(x, y)].symbol())
                    .collect()
            })
            .collect()
    }

    /// `view` cut to its nearest radar target, with an AIS target on it, paired with it
    /// when `paired`, else the radar target shown as it ([`ScanReport::merged`]).
    pub(crate) fn one_associated_ship(mut view: ScanReport, paired: bool) -> ScanReport {
        let t = view.targets[0];
        view.targets = vec![t];
        view.plots_m.clear();
        view.ais = vec![crate::ais::AisTargetData {
            mmsi: 235_000_001,
            label: "SHIP".into(),
            position_m: t.position_m,
            velocity_mps: t.velocity_mps,
            range_m: t.range_m,
            bearing_rad: t.bearing_rad,
            cpa: Some(tracker_core::geo::Cpa {
                cpa_m: t.cpa_m,
                tcpa_s: t.tcpa_s,
            }),
            rel_speed_mps: Some(t.rel_speed_mps),
            heading_rad: None,
            hull_centre_m: t.position_m,
            hull_centre_unknown_m: 0.0,
            age_s: 0.0,
            active: true,
            motion_reported: true,
        }];
        if paired {
            view.paired = vec![crate::session::ais::Pairing {
                track: t.track,
                number: t.number,
                mmsi: 235_000_001,
                label: "SHIP".into(),
                distance_m: 0.0,
            }];
        } else {
            view.merged = vec![crate::session::ais::Candidate {
                track: t.track,
                mmsi: 235_000_001,
            }];
        }
        view
    }

    /// ↑↓ scroll the AIS table while it shows, by one row, within the targets heard, the
    /// title saying which rows; the radar target's selection stays.
    #[test]
    fn the_ais_table_scrolls_with_the_arrows_while_shown() {
        let mut view = one_associated_ship(eleventh_scan(), true);
        let template = view.ais[0].clone();
        view.ais = (0..60u32)
            .map(|i| {
                let mut a = template.clone();
                a.mmsi = 235_100_000 + i;
                a.label = format!("SHIP{i:02}");
                a.range_m = (1.0 + i as f32 * 0.1) * METRES_PER_NM;
                a
            })
            .collect();
        let mut state = DisplayState::new("inproc".into());
        state.observe(&view);
        let selected = state.selected;
        state.key('i', Some(&view));
        let title = |state: &DisplayState| {
            let text = screen_at(state, &view, 80, 24);
            let line = text
                .lines()
                .find(|l| l.contains("AIS, alarms first"))
                .unwrap_or_else(|| panic!("{text}"))
                .to_string();
            (line, text)
        };
        let (line, text) = title(&state);
        assert!(line.contains(" 1–7 of 60 (↑↓, i)"), "{line}");
        assert!(
            text.contains("SHIP00") && !text.contains("SHIP07"),
            "{text}"
        );
        for _ in 0..5 {
            state.key('↓', Some(&view));
        }
        let (line, text) = title(&state);
        assert!(line.contains(" 6–12 of 60 "), "{line}");
        assert!(
            text.contains("SHIP05") && !text.contains("SHIP04"),
            "{text}"
        );
        // The radar target's selection is not moved by the arrows while the table shows.
        assert_eq!(state.selected, selected);
        for _ in 0..10 {
            state.key('↑', Some(&view));
        }
        assert!(title(&state).0.contains(" 1–"));
        // Past the end: the last rows, a full pane of them.
        for _ in 0..100 {
            state.key('↓', Some(&view));
        }
        let (line, text) = title(&state);
        assert!(line.contains("–60 of 60"), "{line}");
        assert!(text.contains("SHIP59"), "{text}");
        // One ↑ from there moves the rows at once.
        state.key('↑', Some(&view));
        assert!(title(&state).0.contains("–59 of 60"));
    }

    /// An associated ship known by its MMSI alone: at any width the table shows the MMSI
    /// whole or leaves the AIS column out, never a cut figure (at 80 columns a new user's
    /// trial saw the column named `A` and each MMSI as its first digit).
    #[test]
    fn an_mmsi_in_the_table_is_whole_or_not_shown() {
        let mut view = one_associated_ship(eleventh_scan(), true);
        view.paired[0].label = "235000001".into();
        view.ais[0].label = "235000001".into();
        let mut state = DisplayState::new("inproc".into());
        state.observe(&view);
        let mut shown_at = Vec::new();
        for width in (80..=200).step_by(4) {
            let text = screen_at(&state, &view, width, 30);
            let row = text
                .lines()
                .find(|l| l.contains(&format!("│{} ", view.targets[0].label())))
                .unwrap_or_else(|| panic!("no row at {width}: {text}"))
                .to_string();
            if row.contains("235000001") {
                shown_at.push(width);
            } else {
                // Nothing of it: the column is out, its name too.
                assert!(!row.contains("2350"), "cut at {width}: {row}");
                let header = text.lines().find(|l| l.contains("TGT")).unwrap_or("");
                let table_header = header.rsplit("TGT").next().unwrap_or("");
                let last = table_header.trim_end_matches(['│', ' ']);
                assert!(
                    last.ends_with("TCPA") || last.ends_with("TCPA min"),
                    "{width}: {text}"
                );
            }
        }
        assert!(shown_at.contains(&160), "{shown_at:?}");
        assert!(shown_at.len() < 31, "left out somewhere: {shown_at:?}");
    }

    /// `i` shows the AIS targets in the table's place, nearest first, an associated one with
    /// its radar target's number before its name, a sleeping one after, dim; `i` again the
    /// radar targets. At 80 columns the compact columns keep the name and every figure.
    #[test]
    fn the_ais_table_lists_every_ais_target_heard() {
        let view = one_associated_ship(eleventh_scan(), true);
        let t = view.targets[0];
        let mut view = view;
        let mut far = view.ais[0].clone();
        far.mmsi = 235_000_002;
        far.label = "FAR AWAY".into();
        far.range_m = 9.0 * METRES_PER_NM;
        far.velocity_mps = [0.0, 0.0];
        far.cpa = None;
        far.active = false;
        far.motion_reported = false;
        view.ais.insert(0, far);
        let mut state = DisplayState::new("inproc".into());
        state.observe(&view);
        assert!(!screen(&state, &view).contains("AIS targets, alarms then nearest first"));
        assert_eq!(state.key('i', Some(&view)), Action::None);
        let text = screen(&state, &view);
        assert!(
            text.contains("AIS targets, alarms then nearest first"),
            "{text}"
        );
        let row_of = |text: &str, what: &str| -> (usize, String) {
            text.lines()
                .enumerate()
                .find(|(_, l)| l.contains(what))
                .map(|(y, l)| (y, l.to_string()))
                .unwrap_or_else(|| panic!("no {what} in {text}"))
        };
        let (near_y, near) = row_of(&text, &format!("{} SHIP", t.label()));
        let (far_y, far_row) = row_of(&text, "FAR AWAY");
        assert!(near_y < far_y, "{text}");
        // The near one's own figures, in its row.
        for figure in [
            "235000001".to_string(),
            format!("{:.2}", t.range_m / METRES_PER_NM),
            format!("{:.2}", t.cpa_m / METRES_PER_NM),
            format!("{:.1}", t.speed_mps / MPS_PER_KNOT),
        ] {
            assert!(near.contains(&figure), "{figure} not in {near}");
        }
        // Motion not reported: no COG, SOG, CPA or TCPA; sleeping: dim.
        assert!(far_row.contains("9.00"), "{far_row}");
        assert_eq!(far_row.matches("---").count(), 4, "{far_row}");
        let mut terminal = Terminal::new(TestBackend::new(160, 40)).unwrap();
        terminal.draw(|f| render(f, &state, &view)).unwrap();
        let fg_at = |y: usize, what: &str| {
            let buffer = terminal.backend().buffer();
            let line: String = (0..160).map(|x| buffer[(x, y as u16)].symbol()).collect();
            let x = line.find(what).map_or(0, |b| line[..b].chars().count());
            buffer[(x as u16, y as u16)].fg
        };
        assert_eq!(fg_at(far_y, "FAR AWAY"), Color::DarkGray);
        // In alarm as its radar target or itself, as the PPI colours it.
        let dangerous = t.dangerous(&state.limits) || ais_dangerous(&view.ais[1], &state.limits);
        let near_fg = fg_at(near_y, "235000001");
        assert_eq!(near_fg == Color::Red, dangerous, "{near_fg:?}");
        let narrow = screen_at(&state, &view, 80, 24);
        let (_, far_narrow) = row_of(&narrow, "FAR AWAY");
        assert!(far_narrow.contains("9.00"), "{narrow}");
        let (_, near_narrow) = row_of(&narrow, &format!("{} SHIP", t.label()));
        assert!(
            near_narrow.contains(&format!("{:.2}", t.cpa_m / METRES_PER_NM)),
            "{narrow}"
        );
        state.key('i', Some(&view));
        assert!(!screen(&state, &view).contains("AIS targets, alarms then nearest first"));
        // Asked with no AIS heard: answered.
        let mut none = view.clone();
        none.ais.clear();
        state.key('i', Some(&none));
        assert!(
            state
                .message
                .as_deref()
                .is_some_and(|m| m.contains("no AIS target heard")),
            "{:?}",
            state.message
        );
        // … until the next command (it outlived it, a new user's trial).
        state.key('i', Some(&none));
        assert_eq!(state.message, None);
    }

    /// The AIS table lists the targets in CPA/TCPA alarm first, each group nearest first:
    /// a farther ship closing to 0.1 NM in 3 min above a nearer one passing 5 NM off.
    #[test]
    fn the_ais_table_lists_its_targets_in_alarm_first() {
        let mut view = one_associated_ship(eleventh_scan(), true);
        let ship = |mmsi, range_nm, cpa_nm| ais_ship(&view.ais[0], mmsi, range_nm, cpa_nm);
        view.ais = vec![ship(1, 1.0, 5.0), ship(2, 4.0, 0.1), ship(3, 2.0, 4.0)];
        view.paired.clear();
        let state = DisplayState::new("inproc".into());
        let rows = ais_table::rows(&view, &state, 1, 0, 10);
        let order: Vec<(&str, bool)> = rows
            .iter()
            .map(|r| (r.cells[1].as_str(), r.dangerous))
            .collect();
        assert_eq!(order, [("S2", true), ("S1", false), ("S3", false)]);
        // Scrolled past the first: the rest, in that order.
        let rest = ais_table::rows(&view, &state, 1, 1, 10);
        assert_eq!(rest[0].cells[1], "S1");
    }

    /// An activated AIS target `S{mmsi}` like `template`, `range_nm` off, closing to
    /// `cpa_nm` in 3 minutes.
    pub(crate) fn ais_ship(
        template: &crate::ais::AisTargetData,
        mmsi: u32,
        range_nm: f32,
        cpa_nm: f32,
    ) -> crate::ais::AisTargetData {
        let mut a = template.clone();
        a.mmsi = mmsi;
        a.label = format!("S{mmsi}");
        a.range_m = range_nm * METRES_PER_NM;
        a.active = true;
        a.cpa = Some(tracker_core::geo::Cpa {
            cpa_m: cpa_nm * METRES_PER_NM,
            tcpa_s: 180.0,
        });
        a.rel_speed_mps = Some(5.0);
        a
    }

    /// The demo's eleventh scan: targets confirmed, with courses and speeds.
    pub(crate) fn eleventh_scan() -> ScanReport {
        let mut d = demo();
        let mut view = step(&mut d);
        for _ in 0..10 {
            view = step(&mut d);
        }
        view
    }

    /// A display that raises no alarm: radar targets green, AIS targets magenta.
    fn without_alarms() -> DisplayState {
        let mut state = DisplayState::new("inproc".into());
        state.limits = AlarmLimits {
            cpa_m: 0.0,
            tcpa_s: 0.0,
        };
        state
    }

    /// Cells of the PPI (the left half) drawn in `colour`.
    fn ppi_cells(state: &DisplayState, view: &ScanReport, colour: Color) -> usize {
        let mut terminal = Terminal::new(TestBackend::new(160, 40)).unwrap();
        terminal.draw(|f| render(f, state, view)).unwrap();
        let buffer = terminal.backend().buffer();
        (1..39)
            .flat_map(|y| (1..70).map(move |x| (x, y)))
            .filter(|&(x, y)| buffer[(x, y)].fg == colour && buffer[(x, y)].symbol() != " ")
            .count()
    }

    #[test]
    fn an_associated_ship_is_drawn_once_by_the_chosen_symbol() {
        let view = eleventh_scan();
        let mut state = without_alarms();
        assert_eq!(
            state.associated,
            AssociatedSymbol::Ais,
            "IEC 62388's default"
        );
        for paired in [true, false] {
            let view = one_associated_ship(view.clone(), paired);
            state.associated = AssociatedSymbol::Ais;
            let (radar, ais) = (
                ppi_cells(&state, &view, Color::Green),
                ppi_cells(&state, &view, Color::Magenta),
            );
            assert!(radar == 0 && ais > 0, "paired {paired}: {radar} / {ais}");
            state.associated = AssociatedSymbol::Radar;
            let (radar, ais) = (
                ppi_cells(&state, &view, Color::Green),
                ppi_cells(&state, &view, Color::Magenta),
            );
            assert!(radar > 0 && ais == 0, "paired {paired}: {radar} / {ais}");
            // The table names it either way, under the radar target's number.
            let text = screen(&state, &view);
            assert!(text.contains(&view.targets[0].label()), "{text}");
            assert!(text.contains("SHIP"), "{text}");
        }
    }

    /// Own ship's heading line is drawn to the PPI's edge when a heading is known, and not
    /// without one (a new user's trial: no heading line on the terminal PPI or the snapshot).
    #[test]
    fn the_heading_line_is_drawn_when_own_ship_has_a_heading() {
        let mut view = eleventh_scan();
        let state = without_alarms();
        view.own.heading_rad = None;
        let without = ppi_cells(&state, &view, Color::White);
        view.own.heading_rad = Some(core::f32::consts::FRAC_PI_2);
        let with = ppi_cells(&state, &view, Color::White);
        // Own ship to the edge, east: a PPI's half width of cells and more.
        assert!(
            with >= without + 20,
            "{with} white cells with a heading, {without} without"
        );
    }

    #[test]
    fn tracks_being_acquired_are_drawn_without_a_number() {
        let mut view = eleventh_scan();
        let state = without_alarms();
        // Two tracks with a second plot, away from the targets.
        for off in [[2000.0, -3000.0], [-4000.0, 1500.0]] {
            let mut t = view.targets[0];
            let own = view.own.position_m;
            t.position_m = [own[0] + off[0], own[1] + off[1]];
            t.number = None;
            view.acquiring.push(t);
        }
        let with = ppi_cells(&state, &view, Color::Gray);
        view.acquiring.clear();
        let without = ppi_cells(&state, &view, Color::Gray);
        assert!(with > without, "{with} grey cells with, {without} without");
    }

    #[test]
    fn an_associated_ship_keeps_its_vector_beyond_the_ais_activation_range() {
        let view = eleventh_scan();
        let mut state = without_alarms();
        state.vectors = VectorMode::True;
        // A sleeping AIS target (beyond the activation range) is a triangle without a
        // vector; associated with a radar target and drawn as its AIS target, it shows the
        // vector the radar target would.
        let mut associated = one_associated_ship(view, true);
        associated.ais[0].active = false;
        associated.ais[0].velocity_mps = [8.0, 0.0];
        let mut sleeping = associated.clone();
        sleeping.paired.clear();
        let (with, without) = (
            ppi_cells(&state, &associated, Color::Magenta),
            ppi_cells(&state, &sleeping, Color::Magenta),
        );
        assert!(with > without, "associated {with} / sleeping {without}");
    }

    #[test]
    fn the_ais_column_fits_a_radar_target_shown_as_several_ais_targets() {
        let mut view = one_associated_ship(eleventh_scan(), false);
        let track = view.targets[0].track;
        assert_eq!(ais_column(&view, track), "SHIP?");
        // Two more AIS targets on it, farther off, with 20-character names and MMSIs.
        for (mmsi, label, off) in [
            (235_000_002, "235000002", 50.0),
            (235_000_003, "A VERY LONG SHIP NAM", 80.0),
        ] {
            let mut a = view.ais[0].clone();
            a.mmsi = mmsi;
            a.label = label.into();
            a.position_m[0] += off;
            a.hull_centre_m = a.position_m;
            view.ais.push(a);
            view.merged
                .push(crate::session::ais::Candidate { track, mmsi });
        }
        assert_eq!(ais_column(&view, track), "SHIP? +2", "the nearest first");
        // The nearest one with a long name: cut short to fit, the count kept.
        view.ais[0].position_m[0] += 1_000.0;
        view.ais[2].position_m[0] -= 80.0;
        for a in &mut view.ais {
            a.hull_centre_m = a.position_m;
        }
        let column = ais_column(&view, track);
        assert_eq!(column, "A VERY LONG SHIP? +2");
        assert_eq!(column.chars().count(), usize::from(AIS_COLUMN_WIDTH));
        // On the screen: the whole of it, nothing of the next name (no alarm lines).
        let mut state = DisplayState::new("inproc".into());
        state.limits = AlarmLimits {
            cpa_m: 0.0,
            tcpa_s: 0.0,
        };
        let text = screen(&state, &view);
        assert!(text.contains("A VERY LONG SHIP? +2"), "{text}");
        assert!(!text.contains("235000002"), "{text}");
    }

    #[test]
    fn a_radar_picture_sets_the_scale_once_and_e_hides_it() {
        let mut d = demo();
        let mut view = step(&mut d);
        let mut image = crate::radar::EchoImage::default();
        let mut samples = [0u8; 64];
        samples[32] = 15;
        image.add(1.0, 195.0, &samples, 15);
        view.echoes = Some(std::sync::Arc::new(image));
        let mut state = DisplayState::new("inproc".into());
        state.observe(&view);
        // 195 m: the 0.125 NM scale, half-minute vectors.
        assert_eq!(RANGE_SCALES_NM[state.range_scale], 0.125);
        assert_eq!(VECTOR_MINUTES[state.vector_length], 0.5);
        // The operator's choice stands.
        state.key('+', Some(&view));
        state.observe(&view);
        assert_eq!(RANGE_SCALES_NM[state.range_scale], 0.25);
        assert!(state.echoes);
        state.key('e', Some(&view));
        assert!(!state.echoes);
        // Answered, as every command (a new user's trial had none on a capture).
        assert_eq!(
            state.message.as_deref(),
            Some("echoes hidden (e shows them)")
        );
        let text = screen(&state, &view);
        assert!(text.contains("PPI 0.25 NM"), "{text}");
        assert!(text.contains("echoes hidden"), "{text}");
        // The answer stands until the next command.
        state.key('+', Some(&view));
        assert_eq!(state.message, None);
    }

    /// Own ship's position dead reckoned is `DR n s` up to dead reckoning's reach, then
    /// `POS LOST`, its alarm saying since when, in days when days (a log of another voyage
    /// read to its end showed `DR 47499628 s` and `position lost 791660 min ago`).
    #[test]
    fn own_ship_past_dead_reckonings_reach_is_lost() {
        let mut own = crate::own_ship::OwnShip::at([0.0, 0.0], [0.0, 3.0]);
        own.quality.dead_reckoning_s = Some(100.0);
        assert!(
            own_ship_line(&own).contains("DR 100 s"),
            "{}",
            own_ship_line(&own)
        );
        // Motion not measured yet: still dead reckoned (from where it was), not lost.
        own.quality.motion_known = false;
        assert!(
            own_ship_line(&own).contains("DR 100 s"),
            "{}",
            own_ship_line(&own)
        );
        own.quality.dead_reckoning_s = Some(600.0);
        assert!(
            own_ship_line(&own).contains("POS LOST"),
            "{}",
            own_ship_line(&own)
        );
        assert!(own
            .alarms()
            .iter()
            .any(|a| a.contains("position lost 10 min ago")));
        own.quality.dead_reckoning_s = Some(550.0 * 86_400.0);
        assert!(
            own.alarms()
                .iter()
                .any(|a| a.contains("position lost 550 days ago")),
            "{:?}",
            own.alarms()
        );
    }

    #[test]
    fn an_80_by_24_terminal_cuts_words_not_figures() {
        let options = DemoOptions::new(
            tracker_core::sim::ScenarioKind::OpenSea,
            12,
            3,
            200.0,
            FilterKind::KalmanCv,
        );
        let mut d = demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
        let mut state = DisplayState::new("inproc".into());
        let mut view = step(&mut d);
        // By scan 50 the demo's targets' trends are known and some alarm.
        for _ in 0..50 {
            view = step(&mut d);
            state.observe(&view);
        }
        assert!(view.targets.iter().any(|t| t.dangerous(&state.limits)));
        let mut terminal = Terminal::new(TestBackend::new(80, 24)).unwrap();
        terminal.draw(|f| render(f, &state, &view)).unwrap();
        let rows = buffer_rows(terminal.backend().buffer());
        let text = rows.join("\n");
        // The compact table: whole degrees in three digits, every figure whole.
        assert!(text.contains("TGT ST"), "{text}");
        let first = &view.targets[0];
        let row = rows
            .iter()
            .find(|r| r.contains(&format!("│{} ", first.label())))
            .unwrap_or_else(|| panic!("{text}"));
        let bearing = crate::nmea::shown_angle_deg(f64::from(first.bearing_rad.to_degrees()), 0);
        assert!(row.contains(&format!(" {bearing:03.0} ")), "{row}");
        assert!(
            row.contains(&format!("{:.2}", first.range_m / METRES_PER_NM)),
            "{row}"
        );
        // Alarms whole, in short words.
        let alarms: Vec<&String> = rows.iter().filter(|r| r.contains("ALARM")).collect();
        assert!(!alarms.is_empty(), "{text}");
        for a in alarms {
            assert!(a.contains(" min "), "{a}");
        }
        // The header's counts, wrapped rather than cut (each joined to its word by a
        // no-break space).
        assert!(
            text.contains(&format!("acq\u{a0}{}", view.acquiring())),
            "{text}"
        );
        // A table too short for every target says how many it shows.
        let listed = view
            .targets
            .iter()
            .filter(|t| rows.iter().any(|r| r.contains(&format!("│{} ", t.label()))))
            .count();
        let n = view.targets.len();
        assert!(listed < n, "80×24 lists fewer than the demo's {n} targets");
        assert!(text.contains(&format!("{listed} of {n} shown")), "{text}");
        // The targets in alarm come first, their figures on screen (the alarm box lists
        // them by number alone when it is short of room).
        let alarmed: Vec<String> = (view.targets.iter())
            .filter(|t| t.dangerous(&state.limits))
            .map(|t| t.label())
            .collect();
        assert!(
            !alarmed.is_empty() && alarmed.len() <= listed,
            "{alarmed:?}"
        );
        assert!(text.contains("alarms first"), "{text}");
        for label in &alarmed {
            assert!(
                rows.iter().any(|r| r.contains(&format!("│{label} "))),
                "{label}: {text}"
            );
        }
        // ↓ steps through the targets in the order drawn: the first in alarm first.
        let first_alarmed = view.targets.iter().find(|t| t.dangerous(&state.limits));
        assert_eq!(state.selected, None);
        state.key('↓', Some(&view));
        assert_eq!(state.selected, first_alarmed.map(|t| t.track));
        state.selected = None;
        // Selecting the farthest target scrolls the table to it: its row is the last, the
        // nearest is off the table, and the title says which rows are shown.
        let (i, last) = (view.targets.iter().enumerate().rev())
            .find(|(_, t)| t.label() != "--")
            .expect("a numbered target");
        assert!(
            i >= listed,
            "the farthest numbered target is below the fold"
        );
        state.selected = Some(last.track);
        let text = screen_at(&state, &view, 80, 24);
        let shown = |t: &TargetData| text.contains(&format!("│{} ", t.label()));
        assert!(shown(last), "{text}");
        assert!(first.label() == "--" || !shown(first), "{text}");
        let from = i + 2 - listed;
        assert!(
            text.contains(&format!("{from}–{} of {n} shown", i + 1)),
            "{text}"
        );
        // A selected target in alarm is shown selected: its row red behind, not red
        // letters alone as every alarmed row has.
        let alarmed = (view.targets.iter())
            .find(|t| t.dangerous(&state.limits) && t.label() != "--")
            .expect("a numbered target in alarm");
        let background = |state: &DisplayState| {
            let mut terminal = Terminal::new(TestBackend::new(80, 24)).unwrap();
            terminal.draw(|f| render(f, state, &view)).unwrap();
            let buffer = terminal.backend().buffer().clone();
            let label = format!("│{} ", alarmed.label());
            (0..buffer.area.height)
                .find_map(|y| {
                    let row: String = (0..buffer.area.width)
                        .map(|x| buffer[(x, y)].symbol())
                        .collect();
                    let at = row.find(&label)?;
                    let x = row[..at].chars().count() as u16 + 1;
                    Some(buffer[(x, y)].bg)
                })
                .expect("the alarmed target's row")
        };
        state.selected = None;
        assert_ne!(background(&state), Color::Red);
        state.selected = Some(alarmed.track);
        assert_eq!(background(&state), Color::Red);
    }

    #[test]
    fn the_narrow_headers_counts_stay_beside_their_words() {
        // 80 columns: the header wraps in a 44-column pane; a count is never on the line
        // after its word ("trk" at a line's end and "12" at the next's start, a trial).
        let mut d = demo();
        let mut view = step(&mut d);
        for _ in 0..12 {
            view = step(&mut d);
        }
        let state = DisplayState::new("inproc".into());
        let header = |state: &DisplayState, view: &ScanReport| -> Vec<String> {
            screen_at(state, view, 80, 24)
                .lines()
                .take(7)
                .map(|l| {
                    l.rsplit('│')
                        .nth(1)
                        .unwrap_or("")
                        .trim()
                        .replace('\u{a0}', " ")
                })
                .collect()
        };
        let items = [
            format!("scan {}", view.scan),
            format!("plots {}", view.plots.len()),
            format!("trk {}", view.tracked()),
            format!("acq {}", view.acquiring()),
            "1.00 NM/12 min".to_string(),
            "SOG 12.0 kn".to_string(),
        ];
        let all_there = |header: Vec<String>| {
            for item in &items {
                assert!(
                    header.iter().any(|l| l.contains(item.as_str())),
                    "{item}: {header:#?}"
                );
            }
        };
        all_there(header(&state, &view));
        // Paused, own ship dead reckoned: the first two rows wrap, the limits still show
        // (the TCPA limit fell off the box's end, a new user's trial).
        let mut paused = state.clone();
        paused.paused = true;
        let mut reckoned = view.clone();
        reckoned.own.quality.dead_reckoning_s = Some(40.0);
        all_there(header(&paused, &reckoned));
    }

    #[test]
    fn the_key_help_and_a_reply_are_laid_out_to_the_box_not_cut() {
        // 80 columns: the right pane is 44 wide, 42 inside the borders.
        let help = wrap(KEY_HELP, ", ", 42);
        assert!(help.iter().all(|l| l.chars().count() <= 42), "{help:?}");
        assert_eq!(help.join(", "), KEY_HELP.join(", "));
        let mut state = DisplayState::new("inproc".into());
        state.message = Some("target 35 cancelled: gone from the next rotation".into());
        let lines = message_lines(&state, 42);
        assert_eq!(
            lines.join(" "),
            "target 35 cancelled: gone from the next rotation"
        );
        assert!(lines.len() == 2 && lines.iter().all(|l| l.chars().count() <= 42));
        // On the screen, with no alarm to crowd it out: every key listed, the reply whole.
        let mut d = demo();
        let view = step(&mut d);
        let text = screen_at(&state, &view, 80, 24);
        for item in [
            "q quit",
            "Enter acknowledge",
            "p pause",
            "gone from the next",
            "│rotation ",
        ] {
            assert!(text.contains(item), "{item}: {text}");
        }
    }

    #[test]
    fn a_key_that_cannot_act_is_answered() {
        let mut d = demo();
        let mut state = DisplayState::new("inproc".into());
        let view = step(&mut d);
        state.observe(&view);
        for (key, said) in [
            ('c', "no target selected"),
            ('\n', "no alarm to acknowledge"),
            ('e', "no radar picture"),
        ] {
            state.message = None;
            assert!(matches!(state.key(key, Some(&view)), Action::None));
            let m = state.message.clone().unwrap_or_default();
            assert!(m.contains(said), "{key:?}: {m:?}");
        }
    }

    #[test]
    fn the_screen_shows_the_picture_table_and_keys() {
        let mut d = demo();
        let mut state = DisplayState::new("inproc".into());
        let mut view = step(&mut d);
        for _ in 0..20 {
            view = step(&mut d);
            state.observe(&view);
        }
        assert!(!view.targets.is_empty());
        let text = screen(&state, &view);
        assert!(text.contains("PPI 6 NM"), "{text}");
        assert!(
            text.contains("TGT") && text.contains("CPA NM") && text.contains("TCPA min"),
            "{text}"
        );
        assert!(text.contains("relative vectors 6 min"), "{text}");
        let first = view.targets[0].label();
        assert!(text.contains(&first), "{text}");
        assert!(text.contains("q quit"), "{text}");

        // Keys change what is drawn.
        state.key('+', Some(&view));
        state.key('v', Some(&view));
        state.key(']', Some(&view));
        state.key('↓', Some(&view));
        let text = screen(&state, &view);
        assert!(
            text.contains("PPI 12 NM") && text.contains("true vectors 12 min"),
            "{text}"
        );
        // Without own ship's motion the vectors are relative whatever was chosen, and the
        // header says so (a new user's trial read "true vectors" beside `NO FIX`).
        let mut lost = view.clone();
        lost.own.quality.motion_known = false;
        let text = screen(&state, &lost);
        assert!(text.contains("relative vectors 12 min"), "{text}");
        // … and the table's course and speed are the relative ones, named so.
        assert!(
            text.contains("RCRS °T") && text.contains("RSPD kn") && !text.contains(" CRS °T"),
            "{text}"
        );
        assert!(text.contains("course and speed relative"), "{text}");
        let known = screen(&state, &view);
        assert!(
            known.contains(" CRS °T") && !known.contains("RCRS"),
            "{known}"
        );
        // … and `v` asking for true vectors then is told why they stay relative.
        state.key('v', Some(&lost));
        assert!(state.message.is_none(), "{:?}", state.message);
        state.key('v', Some(&lost));
        assert!(
            state
                .message
                .as_deref()
                .unwrap()
                .contains("not yet measured"),
            "{:?}",
            state.message
        );
        let mut no_fix = lost.clone();
        no_fix.own.quality.no_fix_yet = true;
        state.key('v', Some(&no_fix));
        state.key('v', Some(&no_fix));
        assert!(
            state.message.as_deref().unwrap().contains("(no fix yet)"),
            "{:?}",
            state.message
        );
        // … drawn as the tracks' velocities where own ship's position is held (dead
        // reckoning stopped): own ship's last velocity is not taken off them again.
        lost.own.velocity_mps = [3.0, 0.0];
        lost.own.quality.dead_reckoning_s = Some(400.0);
        assert_eq!(drawn_velocity(&state, &lost, [1.0, 2.0]), [1.0, 2.0]);
        // Fixes coming but the motion not yet measured: the position moves with own ship,
        // the tracks are over ground, and own ship's estimate is taken off.
        let mut measuring = lost.clone();
        measuring.own.quality.dead_reckoning_s = None;
        assert_eq!(drawn_velocity(&state, &measuring, [1.0, 2.0]), [-2.0, 2.0]);
        state.vectors = VectorMode::Relative;
        let mut known = lost.clone();
        known.own.quality.motion_known = true;
        known.own.quality.dead_reckoning_s = None;
        assert_eq!(drawn_velocity(&state, &known, [1.0, 2.0]), [-2.0, 2.0]);
        state.vectors = VectorMode::True;
        assert_eq!(state.selected, Some(view.targets[0].track));
        assert_eq!(
            state.key('c', Some(&view)),
            Action::Cancel(view.targets[0].track)
        );
        assert_eq!(state.key('C', Some(&view)), Action::CancelAll);
        assert_eq!(state.key('q', Some(&view)), Action::Quit);
    }

    #[test]
    fn acquire_and_cancel_reach_the_device() {
        let mut d = demo();
        let mut view = step(&mut d);
        for _ in 0..6 {
            view = step(&mut d);
        }
        let before = view.tracks.len();
        let plot = nearest_untracked_plot(&view);
        if let Some(p) = plot {
            d.session_mut()
                .command(tracker_core::icd::TrackCommand::Acquire { plot: p })
                .unwrap();
        }
        d.session_mut()
            .command(tracker_core::icd::TrackCommand::CancelAll)
            .unwrap();
        let view = step(&mut d);
        assert!(
            view.tracks
                .iter()
                .all(|t| t.status == TrackStatus::Tentative),
            "cancel all empties the table; only this scan's new plots start tracks"
        );
        assert!(before > 0);
    }

    /// The demo `scans` scans on, on a display whose every approaching target whose motion is
    /// known raises an alarm.
    fn alarming(scans: usize) -> (DisplayState, ScanReport) {
        let mut d = demo();
        let mut state = DisplayState::new("inproc".into());
        state.limits = AlarmLimits {
            cpa_m: 1e9,
            tcpa_s: 1e9,
        };
        let mut view = step(&mut d);
        for _ in 0..scans {
            view = step(&mut d);
            state.observe(&view);
        }
        (state, view)
    }

    #[test]
    fn alarms_and_lost_targets_are_shown() {
        // 40 m plots: a target's motion is shown (and alarms) from its 14th plot on.
        let (state, view) = alarming(16);
        assert!(view.targets.iter().any(|t| t.trend_known));
        if view
            .targets
            .iter()
            .any(|t| t.trend_known && t.tcpa_s >= 0.0)
        {
            let text = screen(&state, &view);
            assert!(text.contains("CPA/TCPA ALARM"), "{text}");
        }
    }

    #[test]
    fn a_silent_radar_is_the_first_alarm() {
        let (mut state, view) = alarming(16);
        let text = screen(&state, &view);
        assert!(!text.contains("NO RADAR DATA"), "{text}");
        state.radar_silent_s = Some(12);
        let lines = alarm_lines(&state, &view, false, None).lines;
        assert!(
            lines[0].to_string().starts_with("NO RADAR DATA for 12 s"),
            "{lines:?}"
        );
        assert!(screen(&state, &view).contains("NO RADAR DATA for 12 s"));
    }

    #[test]
    fn targets_cancelled_by_a_silence_are_lost_targets_with_its_alarm() {
        let (mut state, mut view) = alarming(16);
        let shown = view.targets.clone();
        assert!(!shown.is_empty());
        // As the session reports a scan after a silence: no tracks, the shown ones ended.
        view.tracks.clear();
        view.targets.clear();
        view.ended = shown.clone();
        view.silence = Some(crate::session::Silence {
            gap_s: 36.1,
            rotations_missed: 13,
            targets_lost: shown.len(),
        });
        state.observe(&view);
        assert_eq!(state.lost.len(), shown.len());
        let text: Vec<String> = alarm_lines(&state, &view, false, None)
            .lines
            .iter()
            .map(|l| l.to_string())
            .collect();
        let said = format!(
            "RADAR SILENT: no scan for 36.1 s (13 rotations missed): {} targets lost",
            shown.len()
        );
        assert!(text.iter().any(|l| l.starts_with(&said)), "{text:?}");
        // At 100 columns the box is 53 wide: the line is wrapped onto a second row, not cut
        // (a new user's trial read "… (12 rotations missed" and no more).
        let wide = screen_at(&state, &view, 100, 30);
        assert!(
            wide.contains(&format!("{} targets lost", shown.len())),
            "{wide}"
        );
        let label = shown[0].label();
        assert!(
            text.iter().any(|l| *l == format!("LOST TARGET {label}")),
            "{text:?}"
        );
        // The plain header says it too (`--plain`, progress lines).
        let header = crate::display::plain::header(&view);
        assert!(
            header.contains(&format!("\n  LOST TARGET {label}")),
            "{header}"
        );
        let narrow: Vec<String> = alarm_lines(&state, &view, true, None)
            .lines
            .iter()
            .map(|l| l.to_string())
            .collect();
        let short = format!("RADAR SILENT 36 s: {} LOST", shown.len());
        assert!(narrow.contains(&short), "{narrow:?}");
        // They stand over the scans after it until acknowledged (Enter).
        view.silence = None;
        view.ended.clear();
        state.observe(&view);
        assert_eq!(state.lost.len(), shown.len());
        assert!(alarm_lines(&state, &view, false, None)
            .lines
            .iter()
            .any(|l| l.to_string().starts_with("RADAR SILENT")));
        assert_eq!(state.key('\n', Some(&view)), Action::None);
        assert!(state.lost.is_empty());
        assert!(!alarm_lines(&state, &view, false, None)
            .lines
            .iter()
            .any(|l| l.to_string().starts_with("RADAR SILENT")));
        // Without a silence, ends the device did not call lost are no alarm.
        view.ended = shown;
        state.observe(&view);
        assert!(state.lost.is_empty());
    }

    /// A live radar that sends nothing: the run waits the time given and goes on; a
    /// recording never waits.
    #[test]
    fn a_silent_live_radar_is_waited_on_for_the_time_given() {
        use crate::app::run::Polled;
        use crate::app::track::{TrackInput, TrackOptions};
        use crate::radar::{RadarKind, RadarSpec};
        let radar = crate::source::radar::RadarOptions::new(RadarSpec::Live {
            kind: RadarKind::Garmin,
            interface: std::net::Ipv4Addr::LOCALHOST,
        });
        let options = TrackOptions {
            input: TrackInput::Radar(radar),
            filter: FilterKind::KalmanCv,
            association: Default::default(),
            alarms: Default::default(),
            own_ship: Default::default(),
            outputs: Default::default(),
        };
        let client = Client::new(Box::new(InprocTransport::new()));
        let mut run = crate::app::track::start(client, &options).unwrap();
        assert!(run.is_live());
        let t = std::time::Instant::now();
        assert!(matches!(
            run.poll(std::time::Duration::from_millis(150)).unwrap(),
            Polled::Waiting
        ));
        assert!(t.elapsed() >= std::time::Duration::from_millis(150));
        let mut recorded = demo();
        assert!(!recorded.is_live());
        assert!(matches!(
            recorded.poll(std::time::Duration::ZERO).unwrap(),
            Polled::Scan(_)
        ));
    }

    /// A grouped list cut short counts the alarms it leaves out, not its lines.
    #[test]
    fn a_grouped_list_cut_short_counts_its_alarms() {
        let (state, view) = alarming(20);
        let dangerous = view
            .targets
            .iter()
            .filter(|t| t.dangerous(&state.limits))
            .count();
        // 12 columns inside: the head on a line of its own, then four labels a line; three
        // rows inside the borders: two lines and the count.
        let alarms = alarm_lines(&state, &view, false, Some(12));
        assert_eq!(alarms.held.len(), alarms.lines.len());
        let lost = state.lost.len();
        assert_eq!(alarms.held.iter().sum::<usize>(), dangerous + lost);
        let mut terminal = Terminal::new(TestBackend::new(14, 5)).unwrap();
        terminal
            .draw(|f| render_alarms(f, f.area(), &state, alarms))
            .unwrap();
        let rows = buffer_rows(terminal.backend().buffer());
        // Shown: the labels on the rows before the count.
        let shown: usize = rows
            .iter()
            .take_while(|r| !r.contains('+'))
            .map(|r| {
                r.trim_matches(|c| c == '│' || c == ' ')
                    .split_whitespace()
                    .filter(|w| w.chars().all(|c| c.is_ascii_digit()) && w.len() == 2)
                    .count()
            })
            .sum();
        let more: usize = rows
            .iter()
            .find_map(|l| l.split_once('+')?.1.split_once(" more")?.0.parse().ok())
            .unwrap_or_else(|| panic!("{rows:#?}"));
        assert!(shown > 0, "{rows:#?}");
        assert_eq!(shown + more, dangerous + lost, "{rows:#?}");
    }

    /// On an 80×24 terminal with many alarms (every target, limits wide open) the alarms
    /// are listed by target and the table keeps its rows: ten one-line alarms showed 2 of
    /// 40 targets in the table.
    #[test]
    fn many_alarms_on_a_small_terminal_are_listed_by_target() {
        let (state, view) = alarming(20);
        let dangerous: Vec<String> = view
            .targets
            .iter()
            .filter(|t| t.dangerous(&state.limits))
            .map(|t| t.label())
            .collect();
        assert!(dangerous.len() >= 6, "{} alarms", dangerous.len());
        let text = screen_at(&state, &view, 80, 24);
        let rows: Vec<&str> = text.lines().collect();
        // The table's rows of targets: a label, then a status.
        let table_rows = rows
            .iter()
            .filter(|r| {
                view.targets
                    .iter()
                    .any(|t| r.contains(&format!("│{} ", t.label())) && r.contains(" trk "))
            })
            .count();
        assert!(
            table_rows >= usize::from(TABLE_MIN_TARGET_ROWS),
            "{table_rows} rows:\n{text}"
        );
        // Every alarm seen: its target's label in the list, soonest first.
        let list: String = rows
            .iter()
            .skip_while(|r| !r.contains("CPA/TCPA ALARM, soonest first"))
            .take_while(|r| !r.contains("LOST") && !r.contains("range,"))
            .map(|r| r.rsplit('│').nth(1).unwrap_or(""))
            .collect::<Vec<_>>()
            .join(" ");
        assert!(
            list.contains(&format!("({}):", dangerous.len())),
            "{list}\n{text}"
        );
        let listed: Vec<&str> = list
            .split_once("):")
            .map(|(_, l)| l.split_whitespace().collect())
            .unwrap_or_default();
        let mut soonest = view
            .targets
            .iter()
            .filter(|t| t.dangerous(&state.limits))
            .collect::<Vec<_>>();
        soonest.sort_by(|a, b| a.tcpa_s.total_cmp(&b.tcpa_s));
        let expected: Vec<String> = soonest.iter().map(|t| t.label()).collect();
        assert_eq!(listed, expected, "{text}");
        // A tall terminal keeps one line an alarm, with its CPA and TCPA.
        let tall = screen_at(&state, &view, 80, 60);
        assert!(!tall.contains("soonest first"), "{tall}");
        assert!(tall.contains(" NM "), "{tall}");
    }

    #[test]
    fn alarms_that_do_not_fit_are_counted_and_the_soonest_come_first() {
        let (mut state, view) = alarming(20);
        let dangerous = view
            .targets
            .iter()
            .filter(|t| t.dangerous(&state.limits))
            .count();
        let total = alarm_lines(&state, &view, false, None).lines.len();
        // A box of 4 rows inside its borders, as on a short terminal.
        let draw = |state: &DisplayState| -> Vec<String> {
            let mut terminal = Terminal::new(TestBackend::new(90, 6)).unwrap();
            terminal
                .draw(|f| render_alarms(f, f.area(), state, alarm_lines(state, &view, false, None)))
                .unwrap();
            buffer_rows(terminal.backend().buffer())
        };
        // The count of what is not shown, from the box's last line.
        let counted = |screen: &[String]| -> usize {
            screen
                .iter()
                .find_map(|l| l.split_once('+')?.1.split_once(" more (")?.0.parse().ok())
                .expect("the count of what is not shown")
        };
        let screen = draw(&state);
        assert!(
            total > 4 && dangerous >= 4,
            "the demo should raise more alarms ({total}) than the box holds"
        );
        let shown: Vec<&String> = screen.iter().filter(|l| l.contains("ALARM")).collect();
        let more = counted(&screen);
        assert_eq!(shown.len() + more, total, "{screen:#?}");
        // The soonest closest approaches first: the minutes shown never decrease.
        let minutes: Vec<f32> = shown
            .iter()
            .filter_map(|l| l.split(" in ").nth(1)?.split(" min").next()?.parse().ok())
            .collect();
        assert_eq!(minutes.len(), shown.len(), "{screen:#?}");
        assert!(minutes.windows(2).all(|w| w[0] <= w[1]), "{minutes:?}");
        let soonest = view
            .targets
            .iter()
            .filter(|t| t.dangerous(&state.limits))
            .map(|t| t.tcpa_s / 60.0)
            .fold(f32::INFINITY, f32::min);
        assert!(
            (minutes[0] - soonest).abs() < 0.051,
            "{minutes:?} {soonest}"
        );
        // The answer to the operator's last key shows whatever the alarms.
        state.message =
            Some("cancel refused: the target is no longer in the device's table".into());
        let screen = draw(&state);
        assert!(
            screen.iter().any(|l| l.contains("cancel refused")),
            "{screen:#?}"
        );
        let shown = screen.iter().filter(|l| l.contains("ALARM")).count();
        let more = counted(&screen);
        assert_eq!(shown + more, total, "{screen:#?}");
    }

    #[test]
    fn the_end_of_input_is_shown_on_a_narrow_terminal_too() {
        let (mut state, view) = alarming(20);
        let header = |state: &DisplayState| -> String {
            let mut terminal = Terminal::new(TestBackend::new(60, 5)).unwrap();
            terminal
                .draw(|f| render_header(f, f.area(), state, &view))
                .unwrap();
            let buffer = terminal.backend().buffer();
            (0..buffer.area.width)
                .map(|x| buffer[(x, 1)].symbol())
                .collect()
        };
        assert!(!header(&state).contains("END OF INPUT"));
        state.ended = true;
        let first = header(&state);
        assert!(
            first.contains("ARPA END OF INPUT: q to quit | scan"),
            "{first}"
        );
        state.ended = false;
        state.paused = true;
        assert!(header(&state).contains("ARPA PAUSED | scan"));
        state.scans_since_paused = 12;
        assert!(header(&state).contains("ARPA PAUSED +12 | scan"));
    }

    #[test]
    fn the_headers_counts_are_never_cut_off_paused_or_ended() {
        let (mut state, quiet) = alarming(20);
        // … and with targets held in others' echoes, whose count ends the line.
        let mut held = quiet.clone();
        held.in_echo = held.targets[..3].to_vec();
        let views = [
            (
                quiet.clone(),
                format!("acq {}", quiet.acquiring()),
                format!("acquiring {}", quiet.acquiring()),
            ),
            (held, "held 3".to_string(), "held in echoes 3".to_string()),
        ];
        // Every pane width from the narrow layout's limit to a wide terminal's.
        for ((view, tail, long_tail), width) in views
            .iter()
            .flat_map(|v| (80..=130u16).map(move |w| (v, w)))
        {
            for (paused, ended) in [(false, false), (true, false), (false, true)] {
                state.paused = paused;
                // A live radar paused for 40 minutes.
                state.scans_since_paused = if paused { 999 } else { 0 };
                state.ended = ended;
                let mut terminal = Terminal::new(TestBackend::new(width, 5)).unwrap();
                terminal
                    .draw(|f| render_header(f, f.area(), &state, view))
                    .unwrap();
                let buffer = terminal.backend().buffer();
                let line: String = (0..width).map(|x| buffer[(x, 1)].symbol()).collect();
                let line = line.trim_end_matches(['│', ' ']);
                assert!(
                    line.ends_with(tail.as_str()) || line.ends_with(long_tail.as_str()),
                    "{width} columns, paused {paused}, ended {ended}: {line}"
                );
            }
        }
    }

    #[test]
    fn refused_commands_are_messages_and_the_run_goes_on() {
        let mut d = demo();
        let mut state = DisplayState::new("inproc".into());
        let mut view = step(&mut d);
        for _ in 0..6 {
            view = step(&mut d);
            state.observe(&view);
        }
        // Select a target, cancel it, and cancel it again within the scan: the second is
        // refused by the device (no such track).
        assert!(!key(&mut d, &mut state, '↓', &view, &view));
        let selected = state.selected.expect("a target selected");
        assert!(!key(&mut d, &mut state, 'c', &view, &view));
        let done = state.message.clone().expect("the cancel answered at once");
        let label = view
            .targets
            .iter()
            .find(|t| t.track == selected)
            .unwrap()
            .label();
        assert_eq!(
            done,
            format!("target {label} cancelled: gone from the next rotation")
        );
        assert!(!key(&mut d, &mut state, 'c', &view, &view));
        let m = state.message.clone().expect("the refusal shown");
        assert!(
            m.contains("cancel refused") && m.contains("no longer"),
            "{m}"
        );
        // The run goes on; the cancelled target is gone.
        let view = step(&mut d);
        assert!(!view.tracks.iter().any(|t| t.track == selected));
        // Cancel all: answered at once, the picture empty from the next scan.
        assert!(!key(&mut d, &mut state, 'C', &view, &view));
        assert_eq!(
            state.message.as_deref(),
            Some("all targets cancelled: gone from the next rotation")
        );
        // Past the input's end no rotation comes: commands and `p` are answered so.
        state.ended = true;
        for k in ['c', 'C', 'a', 'p'] {
            state.message = None;
            assert!(!key(&mut d, &mut state, k, &view, &view));
            assert_eq!(
                state.message.as_deref(),
                Some("the input has ended: no more scans, the last picture stays (q quits)"),
                "{k}"
            );
        }
        assert!(!state.paused);
        assert!(key(&mut d, &mut state, 'q', &view, &view), "q quits");
    }
}
