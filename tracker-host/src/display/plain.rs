//! The target table as plain text, for a terminal that is not one (a pipe, a log) or when
//! `--plain` asks for it: every scan's table, or a progress line a minute.

use std::io::Write;

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
}

impl Plain {
    /// Prints in `mode` with alarms at `limits`.
    pub fn new(mode: PlainMode, limits: AlarmLimits) -> Self {
        Plain {
            mode,
            limits,
            closed: false,
            simulated: false,
        }
    }

    /// With `simulated`, each header starts `SIM` (`demo`'s picture is a simulation's).
    pub fn with_simulated(mut self, simulated: bool) -> Self {
        self.simulated = simulated;
        self
    }
}

/// The scan header: scan, UTC, counts, own ship, and own ship's alarms.
pub fn header(r: &ScanReport) -> String {
    let mut s = format!(
        "scan {:>4}  {}  plots {:>3}  targets tracked {:>3}  acquiring {:>3}  {}",
        r.scan,
        r.time_label(),
        r.plots.len(),
        r.tracked(),
        r.acquiring(),
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
        // The targets and those being acquired (tentative tracks with a second plot, no
        // number yet: `--`), nearest first: every one the header counts.
        let mut rows: Vec<TargetData> = r.targets.iter().chain(&r.acquiring).cloned().collect();
        rows.sort_by(|a, b| a.range_m.total_cmp(&b.range_m));
        if r.ais.is_empty() {
            return table_with_ais(&rows, &self.limits, None);
        }
        let column = |track: u16| crate::display::ais_column(r, track);
        let mut s = table_with_ais(&rows, &self.limits, Some(&column));
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
}

impl ScanSink for Plain {
    fn scan(&mut self, _: &SourceScan, r: &ScanReport) -> anyhow::Result<()> {
        if self.closed {
            return Ok(());
        }
        let sim = if self.simulated { "SIM " } else { "" };
        let text = match self.mode {
            PlainMode::Table => format!("{sim}{}\n{}", header(r), self.table(r)),
            // A silence of the radar is told when it ends, whatever the scan's number.
            PlainMode::Progress { every }
                if r.scan.is_multiple_of(every.max(1)) || r.silence.is_some() =>
            {
                format!("{sim}{}\n", header(r))
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
    use crate::display::tests::{demo, step};

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
}
