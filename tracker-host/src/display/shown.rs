//! The scan on the screen, and what pausing does to it.
//!
//! A file's scans wait while the display is paused. A live radar's do not: an ARPA goes on
//! tracking while its operator reads the table, so every scan is still tracked and its
//! alarms (a lost target, a radar gone silent) still raised, while the picture stays as it
//! was paused. Resuming shows the latest scan. Before, pausing a live radar stopped reading
//! it: its queue overflowed after a few seconds (about 7 s of the Garmin xHD), and on
//! resuming the gap read as a radar silence that lost every target.

use crate::session::ScanReport;

use super::DisplayState;

/// The scan drawn and, while the picture is paused, the latest scan tracked.
#[derive(Debug)]
pub struct Shown {
    view: ScanReport,
    latest: Option<Box<ScanReport>>,
    since_paused: u64,
}

impl Shown {
    /// The first scan, observed by `state` (trails, alarms, the scale) and drawn.
    pub fn new(state: &mut DisplayState, first: ScanReport) -> Self {
        state.observe(&first);
        Shown {
            view: first,
            latest: None,
            since_paused: 0,
        }
    }

    /// The scan drawn.
    pub fn view(&self) -> &ScanReport {
        &self.view
    }

    /// The latest scan tracked, which the operator's commands act on (a plot to acquire is
    /// one of its plots; the frozen picture's may be gone).
    pub fn latest(&self) -> &ScanReport {
        self.latest.as_deref().unwrap_or(&self.view)
    }

    /// Scans tracked since the picture was paused.
    pub fn since_paused(&self) -> u64 {
        self.since_paused
    }

    /// A scan tracked: observed by `state` whatever the picture does (so that its alarms
    /// are raised), and drawn unless the picture is paused.
    pub fn take(&mut self, state: &mut DisplayState, report: ScanReport) {
        state.observe(&report);
        if state.paused {
            self.latest = Some(Box::new(report));
            self.since_paused += 1;
        } else {
            self.view = report;
            self.latest = None;
            self.since_paused = 0;
        }
    }

    /// After a key: a picture no longer paused shows the latest scan.
    pub fn follow(&mut self, state: &DisplayState) {
        if !state.paused {
            if let Some(latest) = self.latest.take() {
                self.view = *latest;
            }
            self.since_paused = 0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{demo, step};
    use super::*;

    /// Scans taken while paused are observed (their alarms raised) but not drawn, and
    /// resuming draws the latest.
    #[test]
    fn a_paused_picture_stays_while_scans_are_tracked_and_resumes_at_the_latest() {
        let mut run = demo();
        let mut state = DisplayState::new("inproc".into());
        let mut shown = Shown::new(&mut state, step(&mut run));
        let first = shown.view().scan;
        state.key('p', None);
        for _ in 0..3 {
            shown.take(&mut state, step(&mut run));
        }
        assert_eq!(shown.view().scan, first, "the picture stays while paused");
        assert_eq!(
            shown.latest().scan,
            first + 3,
            "commands act on the latest scan"
        );
        assert_eq!(shown.since_paused(), 3);
        // A silence told while paused is an alarm at once, not when the picture resumes.
        let mut silent = step(&mut run);
        silent.silence = Some(crate::session::Silence {
            gap_s: 30.0,
            rotations_missed: 12,
            targets_lost: 2,
        });
        shown.take(&mut state, silent);
        assert!(state.silence.is_some());
        let first = shown.view().scan;
        state.key('p', None);
        shown.follow(&state);
        assert_eq!(shown.view().scan, first + 4, "resumed at the latest scan");
        assert_eq!(shown.since_paused(), 0);
        shown.take(&mut state, step(&mut run));
        assert_eq!(shown.view().scan, first + 5);
    }
}
