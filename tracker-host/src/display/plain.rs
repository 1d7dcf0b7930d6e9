//! The target table as plain text, for a terminal that is not one (a pipe, a log) or when
//! `--plain` asks for it: every scan's table, or a progress line a minute.

use std::io::Write;

use crate::display::{ais_table, DisplayState};
use crate::session::target::{table_with_ais, AlarmLimits, TargetData};
use crate::session::ScanReport;
use crate::sink::ScanSink;
use crate::source::SourceScan;

/// What the plain display prints.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlainMode {
    /// A header and the target table every scan.
    Table,
    /// A header line every `every` scans.
    Progress {
        /// Scans between lines.
        every: u32,
    },
}

/// Prints scans to standard output. A closed pipe (`| head`) ends the printing quietly,
/// not the run.
pub struct Plain {
    mode: PlainMode,
    limits: AlarmLimits,
    closed: bool,
    simulated: bool,
    radar: bool,
}

impl Plain {
    /// Prints in `mode` with alarms at `limits`.
    pub fn new(mode: PlainMode, limits: AlarmLimits) -> Self {
        Plain {
            mode,
            limits,
            closed: false,
            simulated: false,
            radar: true,
        }
    }

    /// With `radar` false (`track --nmea-in` alone), no radar table and no radar counts in
    /// the header: the AIS targets are the picture.
    pub fn with_radar(mut self, radar: bool) -> Self {
        self.radar = radar;
        self
    }

    /// With `simulated`, each header starts `SIM` (`demo`'s picture is a simulation's).
    pub fn with_simulated(mut self, simulated: bool) -> Self {
        self.simulated = simulated;
        self
    }
}

/// The scan header: scan, UTC, counts, own ship, and own ship's alarms.
pub fn header(r: &ScanReport) -> String {
    header_with(r, true)
}

/// [`header`], without the radar's counts when there is no `radar` (they would read as
/// a radar seeing nothing).
fn header_with(r: &ScanReport, radar: bool) -> String {
    let counts = if radar {
        format!(
            "plots {:>3}  targets tracked {:>3}  acquiring {:>3}",
            r.plots.len(),
            r.tracked(),
            r.acquiring()
        )
    } else {
        "no radar".to_string()
    };
    let mut s = format!(
        "scan {:>4}  {}  {counts}  {}",
        r.scan,
        r.time_label(),
        crate::display::own_ship_line(&r.own)
    );
    if !r.in_echo.is_empty() {
        // Held, not drawn: their targets are in other targets' echoes.
        s += &format!("  held in echoes {}", r.in_echo.len());
    }
    if !r.ais.is_empty() {
        s += &format!("  AIS {}", r.ais.len());
    }
    for a in r.own.alarms() {
        s += &format!("\n  {a}");
    }
    for label in crate::display::lost_targets(r) {
        s += &format!("\n  LOST TARGET {label}");
    }
    if let Some(silence) = &r.silence {
        s += &format!("\n  {silence}");
    }
    if let Some(note) = &r.skipped {
        s += &format!("\n  {note}");
    }
    s
}

impl Plain {
    /// The target table; with AIS heard, its AIS column and the CPA/TCPA alarms of the AIS
    /// targets no radar target is paired with (as on the radar display).
    fn table(&self, r: &ScanReport) -> String {
        // Without a radar (`track --nmea-in` alone) no empty radar table every scan: the
        // AIS table is the picture.
        let mut s = if self.radar {
            // The targets and those being acquired (tentative tracks with a second plot, no
            // number yet: `--`), nearest first: every one the header counts.
            let mut rows: Vec<TargetData> = r.targets.iter().chain(&r.acquiring).cloned().collect();
            rows.sort_by(|a, b| a.range_m.total_cmp(&b.range_m));
            let column = |track: u16| crate::display::ais_column(r, track);
            let column: Option<&dyn Fn(u16) -> String> = (!r.ais.is_empty()).then_some(&column);
            table_with_ais(&rows, &self.limits, column)
        } else if r.ais.is_empty() {
            "no AIS target heard yet\n".to_string()
        } else {
            String::new()
        };
        if r.ais.is_empty() {
            return s;
        }
        s += &self.ais_table(r);
        // The soonest closest approach first, as on the radar display.
        let mut alarms: Vec<_> = crate::display::ais_alarms(r, &self.limits)
            .filter_map(|a| Some((a, a.cpa?)))
            .collect();
        alarms.sort_by(|x, y| x.1.tcpa_s.total_cmp(&y.1.tcpa_s));
        for (a, c) in alarms {
            s += &format!(
                "  AIS {} CPA {:.2} NM {}  ALARM CPA/TCPA\n",
                a.label,
                c.cpa_m / tracker_core::geo::METRES_PER_NM,
                crate::session::target::tcpa_words(c.tcpa_s)
            );
        }
        s
    }

    /// Every AIS target heard, in CPA/TCPA alarm first, then nearest (the display's AIS
    /// table, key `i`): MMSI, name (after its radar target's number when associated),
    /// range, bearing, COG, SOG, CPA, TCPA, the age of its last position, and `ALARM` or
    /// `sleeping` (outside the activation range). Before, `--plain` gave only the AIS
    /// targets' count and alarms: a navigator using the product as an AIS CPA alarm without
    /// a radar read no target at all in a log (a new user's trial).
    fn ais_table(&self, r: &ScanReport) -> String {
        let mut state = DisplayState::new(String::new());
        state.limits = self.limits;
        let line = |c: [&str; 9]| {
            format!(
                "{:<9} {:<20} {:>7} {:>7} {:>7} {:>7} {:>7} {:>9} {:>6}",
                c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7], c[8]
            )
        };
        let mut s = line([
            "AIS MMSI", "TGT NAME", "RNG NM", "BRG °T", "COG °T", "SOG kn", "CPA NM", "TCPA min",
            "AGE s",
        ]) + "\n";
        for row in ais_table::rows(r, &state, 1, 0, usize::MAX) {
            let c = &row.cells;
            // The radar target's number and the name, cut to the column.
            let name: String = c[1].chars().take(20).collect();
            let flag = if row.dangerous {
                "  ALARM"
            } else if !row.active {
                "  sleeping"
            } else {
                ""
            };
            s += &line([
                &c[0], &name, &c[2], &c[3], &c[4], &c[5], &c[6], &c[7], &c[8],
            ]);
            s += flag;
            s.push('\n');
        }
        s
    }
}

impl ScanSink for Plain {
    fn scan(&mut self, _: &SourceScan, r: &ScanReport) -> anyhow::Result<()> {
        if self.closed {
            return Ok(());
        }
        let sim = if self.simulated { "SIM " } else { "" };
        let text = match self.mode {
            PlainMode::Table => {
                format!("{sim}{}\n{}", header_with(r, self.radar), self.table(r))
            }
            // A silence of the radar is told when it ends, whatever the scan's number.
            PlainMode::Progress { every }
                if r.scan.is_multiple_of(every.max(1)) || r.silence.is_some() =>
            {
                format!("{sim}{}\n", header_with(r, self.radar))
            }
            PlainMode::Progress { .. } => return Ok(()),
        };
        let mut out = std::io::stdout().lock();
        if out
            .write_all(text.as_bytes())
            .and_then(|()| out.flush())
            .is_err()
        {
            self.closed = true;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::display::tests::{ais_ship, demo, eleventh_scan, one_associated_ship, step};

    /// Every target the header counts (tracked, and acquiring with or without a number) is a
    /// row of the table.
    #[test]
    fn the_table_lists_every_target_the_header_counts() {
        let mut d = demo();
        let plain = Plain::new(PlainMode::Table, AlarmLimits::default());
        let mut tentative_listed = 0;
        for _ in 0..12 {
            let r = step(&mut d);
            let rows = plain.table(&r).lines().count() - 1;
            assert_eq!(rows, r.tracked() + r.acquiring(), "scan {}", r.scan);
            tentative_listed += r.acquiring.len();
        }
        assert!(tentative_listed > 0, "the demo's first scans acquire");
    }

    /// Every AIS target is a row, in alarm first, with its name and `ALARM` or `sleeping`,
    /// under the radar table; without a radar, the AIS table alone.
    #[test]
    fn the_ais_targets_are_listed_in_alarm_first() {
        let mut view = one_associated_ship(eleventh_scan(), true);
        let ship = |mmsi, range_nm, cpa_nm, active| crate::ais::AisTargetData {
            active,
            ..ais_ship(&view.ais[0], mmsi, range_nm, cpa_nm)
        };
        view.ais = vec![
            ship(211000001, 1.0, 5.0, true),
            ship(211000002, 4.0, 0.1, true),
            ship(211000003, 11.0, 4.0, false),
        ];
        view.ais[2].label = "A SHIP WITH A VERY LONG NAME".into();
        view.paired.clear();
        let plain = Plain::new(PlainMode::Table, AlarmLimits::default());
        let text = plain.table(&view);
        let ais: Vec<&str> = text
            .lines()
            .skip_while(|l| !l.starts_with("AIS MMSI"))
            .skip(1)
            .take_while(|l| l.starts_with("211"))
            .collect();
        assert_eq!(ais.len(), 3, "{text}");
        assert!(
            ais[0].starts_with("211000002 S211000002") && ais[0].ends_with("  ALARM"),
            "{text}"
        );
        assert!(ais[1].starts_with("211000001") && !ais[1].contains("ALARM"));
        assert!(ais[2].starts_with("211000003") && ais[2].ends_with("  sleeping"));
        assert!(
            text.contains(" TGT STATUS"),
            "radar targets: their table too"
        );

        // No radar: no radar table even with radar targets.
        let plain = plain.with_radar(false);
        let text = plain.table(&view);
        assert!(!text.contains(" TGT STATUS"), "{text}");
        assert!(text.starts_with("AIS MMSI"), "{text}");
        // The columns under their headings (a name past 20 characters cut): each row as
        // long as the heading line (the alarm lines follow the table).
        let lines: Vec<&str> = text.lines().collect();
        let width = lines[0].chars().count();
        for l in lines[1..].iter().take_while(|l| !l.starts_with("  AIS ")) {
            let l = l.trim_end_matches("  ALARM").trim_end_matches("  sleeping");
            assert_eq!(l.chars().count(), width, "{l:?}");
        }

        // Without own ship's position (no fix yet): no range or bearing (they would be from
        // the frame's origin), and in MMSI order after the alarms, not "nearest".
        let mut unplaced = view.clone();
        unplaced.own.quality.no_fix_yet = true;
        unplaced.ais[0].range_m = 20.0 * 1852.0;
        // In the table's order before: 211000003 before 211000001 (MMSIs 2 apart: the same
        // in f32).
        unplaced.ais.swap(0, 2);
        let text = plain.table(&unplaced);
        let rows: Vec<&str> = text
            .lines()
            .skip(1)
            .take_while(|l| l.starts_with("211"))
            .collect();
        let order: Vec<&str> = rows.iter().map(|l| &l[..9]).collect();
        assert_eq!(order, ["211000002", "211000001", "211000003"], "{text}");
        assert!(
            rows.iter()
                .all(|l| !l.contains("20.00") && l.matches("---").count() >= 2),
            "{text}"
        );

        // A note until AIS is heard, and a header without the radar's counts.
        view.ais.clear();
        assert_eq!(plain.table(&view), "no AIS target heard yet\n");
        let h = header_with(&view, false);
        assert!(h.contains("  no radar  ") && !h.contains("plots"), "{h}");
    }
}
