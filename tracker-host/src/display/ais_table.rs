//! The AIS target table (key `i` on the radar display): every AIS target heard, nearest
//! first, with its MMSI, name, range and bearing, COG and SOG, CPA and TCPA, and the age of
//! its last position (IEC 62388 §11.5's AIS target data, in a list as the radar targets'
//! table is). An AIS target associated with a radar target shows that target's number
//! before its name, as the radar table shows the AIS name beside the number. Without it a
//! navigator could read an AIS target's name and CPA only when it alarmed (a new user's
//! trial).

use ratatui::layout::Rect;
use ratatui::style::{Color, Modifier, Style};
use ratatui::widgets::{Cell, Row};
use ratatui::Frame;
use tracker_core::geo::{self, METRES_PER_NM, MPS_PER_KNOT};

use super::DisplayState;
use crate::ais::AisTargetData;
use crate::session::ScanReport;

/// The full table's columns: MMSI, name (with the radar target's number when associated),
/// range, bearing, COG, SOG, CPA, TCPA, age. As wide as the radar targets' full table.
const WIDTHS: [u16; 9] = [9, 20, 7, 7, 7, 7, 7, 9, 5];

/// The compact table's columns: the name (else the MMSI) cut to 10, range, bearing, COG,
/// SOG, CPA, TCPA; no age. 42 characters with the gaps: an 80-column terminal's pane.
const COMPACT_WIDTHS: [u16; 7] = [10, 5, 3, 3, 4, 5, 6];

/// One AIS target's row: its cells in the full table's column order.
#[derive(Clone, Debug, PartialEq)]
pub struct AisRow {
    /// MMSI, name, range (NM), bearing (°T), COG (°T), SOG (kn), CPA (NM), TCPA (min),
    /// age (s).
    pub cells: [String; 9],
    /// In CPA/TCPA alarm: its own (activated), or its radar target's, as the PPI colours it.
    pub dangerous: bool,
    /// Activated (within the activation range); a sleeping one is drawn dim.
    pub active: bool,
    /// Its radar target is the one selected (↑/↓), whose row is highlighted.
    pub selected: bool,
}

impl AisRow {
    /// The compact table's cells: the name (else the MMSI), range, bearing, COG, SOG, CPA,
    /// TCPA.
    pub fn compact_cells(&self) -> Vec<String> {
        let c = &self.cells;
        let name = if c[1].is_empty() { &c[0] } else { &c[1] };
        std::iter::once(name.clone())
            .chain(c[2..8].iter().cloned())
            .collect()
    }
}

/// The rows of `view`'s AIS targets, those in CPA/TCPA alarm first, then nearest first,
/// from the `first` (counted from 0) and at most `at_most` of them, angles to `places`
/// decimals (0 or 1). Alarms first: with a hundred AIS targets in a harbour, an 80 × 24
/// terminal showed the nearest four and none of those in alarm (a new user's trial).
pub fn rows(
    view: &ScanReport,
    state: &DisplayState,
    places: usize,
    first: usize,
    at_most: usize,
) -> Vec<AisRow> {
    // Without own ship's position (no fix yet, none given) a range and bearing would be
    // measured from the frame's origin, wherever own ship is (a new user's trial: AIS
    // targets 256 NM off, sorted "nearest"): not shown, and the table in MMSI order.
    let placed = !view.own.quality.no_fix_yet;
    // (An MMSI's nine digits are exact in f64, not in f32.)
    let mut targets: Vec<(f64, AisRow)> = view
        .ais
        .iter()
        .map(|a| {
            let key = if placed {
                f64::from(a.range_m)
            } else {
                f64::from(a.mmsi)
            };
            (key, row(view, state, a, places))
        })
        .collect();
    // In alarm first (true before false), then nearest (or by MMSI).
    targets.sort_by(|(ra, a), (rb, b)| b.dangerous.cmp(&a.dangerous).then(ra.total_cmp(rb)));
    targets
        .into_iter()
        .map(|(_, r)| r)
        .skip(first)
        .take(at_most)
        .collect()
}

fn row(view: &ScanReport, state: &DisplayState, a: &AisTargetData, places: usize) -> AisRow {
    let angle = |deg: f32| super::table_angle(deg, places == 0);
    let (course_rad, speed_mps) = geo::course_speed(a.velocity_mps);
    let sog_kn = speed_mps / MPS_PER_KNOT;
    // A speed shown as 0.0 kn has no course, as own ship's; a motion not reported is not
    // a ship stopped.
    let sog = if a.motion_reported {
        format!("{sog_kn:.1}")
    } else {
        "---".to_string()
    };
    let cog = if a.motion_reported && f64::from(sog_kn) >= crate::own_ship::COG_FROM_KN {
        angle(course_rad.to_degrees())
    } else {
        "---".to_string()
    };
    let radar = view
        .associated_track(a.mmsi)
        .and_then(|track| view.targets.iter().find(|t| t.track == track));
    // The label is the MMSI while no name is heard: not said twice.
    let name = if a.label == crate::ais::mmsi_text(a.mmsi) {
        ""
    } else {
        a.label.as_str()
    };
    let name = match radar {
        Some(t) => format!("{} {name}", t.label()),
        None => name.to_string(),
    };
    let (cpa, tcpa) = a.cpa.map_or(("---".to_string(), "---".to_string()), |c| {
        (
            format!("{:.2}", c.cpa_m / METRES_PER_NM),
            crate::session::target::tcpa_text(c.tcpa_s),
        )
    });
    let dangerous = radar.is_some_and(|t| t.dangerous(&state.limits))
        || (a.active && super::ais_dangerous(a, &state.limits));
    AisRow {
        cells: [
            crate::ais::mmsi_text(a.mmsi),
            name,
            if view.own.quality.no_fix_yet {
                "---".to_string()
            } else {
                format!("{:.2}", a.range_m / METRES_PER_NM)
            },
            if view.own.quality.no_fix_yet {
                "---".to_string()
            } else {
                angle(a.bearing_rad.to_degrees())
            },
            cog,
            sog,
            cpa,
            tcpa,
            format!("{:.0}", a.age_s.max(0.0)),
        ],
        dangerous,
        active: a.active,
        selected: radar.is_some_and(|t| state.selected == Some(t.track)),
    }
}

/// Draws the AIS table in `area`: the full columns where they fit, else compact ones (whole
/// degrees, the name last, no age), as the radar targets' table does.
pub fn render(frame: &mut Frame, area: Rect, state: &DisplayState, view: &ScanReport) {
    let full: u16 = WIDTHS.iter().sum::<u16>() + WIDTHS.len() as u16 - 1 + 2;
    let compact = area.width < full;
    let bold = |h: &'static str| Cell::from(h).style(Style::default().add_modifier(Modifier::BOLD));
    let header = if compact {
        Row::new(["NAME", "RNG", "BRG", "COG", "SOG", "CPA", "TCPA"].map(bold))
    } else {
        Row::new(
            [
                "MMSI", "TGT NAME", "RNG NM", "BRG °T", "COG °T", "SOG kn", "CPA NM", "TCPA min",
                "AGE s",
            ]
            .map(bold),
        )
    };
    let room = usize::from(area.height.saturating_sub(3));
    let n = view.ais.len();
    // Scrolled no further than a full pane's last rows.
    let first = state.ais_first_row.min(n.saturating_sub(room));
    state.set_ais_rows_drawn(room);
    let shown = rows(view, state, usize::from(!compact), first, room)
        .into_iter()
        .map(|r| {
            // As the radar targets' table: red in alarm, the selection behind.
            let style = match (r.dangerous, r.selected, r.active) {
                (true, true, _) => Style::default().fg(Color::White).bg(Color::Red),
                (true, false, _) => Style::default().fg(Color::Red),
                (false, true, _) => Style::default().fg(Color::Black).bg(Color::Cyan),
                (false, false, true) => Style::default(),
                (false, false, false) => Style::default().fg(Color::DarkGray),
            };
            let cells = if compact {
                r.compact_cells()
            } else {
                r.cells.to_vec()
            };
            Row::new(cells).style(style)
        });
    let widths = if compact {
        super::column_widths(&COMPACT_WIDTHS, false)
    } else {
        super::column_widths(&WIDTHS, false)
    };
    let (from, to) = (first + 1, (first + room).min(n));
    // Short in a narrow pane, whose title the full words would cut.
    let title = match (n > room, compact) {
        (true, false) => format!(
            " AIS targets, alarms then nearest first: {from}–{to} of {n} shown (↑↓ scroll, i: radar targets) "
        ),
        (true, true) => format!(" AIS, alarms first: {from}–{to} of {n} (↑↓, i) "),
        (false, false) => " AIS targets, alarms then nearest first (i: radar targets) ".to_string(),
        (false, true) => " AIS, alarms first (i: radar targets) ".to_string(),
    };
    super::draw_table(frame, area, (header, shown), widths, title);
}
