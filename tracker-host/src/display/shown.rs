//! The scan on the screen, and what pausing does to it.
//!
//! A file's scans wait while the display is paused. A live radar's do not: an ARPA goes on
//! tracking while its operator reads the table, so every scan is still tracked and its
//! alarms (a lost target, a radar gone silent, a CPA/TCPA alarm: the alarm box is the latest
//! scan's) still raised, while the picture, the table and the trails stay as they were
//! paused. Resuming shows the latest scan. Before, pausing a live radar stopped reading
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

    /// A scan tracked: its alarms raised whatever the picture does, and drawn (with its
    /// trails) unless the picture is paused.
    pub fn take(&mut self, state: &mut DisplayState, report: ScanReport) {
        state.observe_alarms(&report);
        if state.paused {
            self.latest = Some(Box::new(report));
            self.since_paused += 1;
        } else {
            state.observe_picture(&report);
            self.view = report;
            self.latest = None;
            self.since_paused = 0;
        }
    }

    /// After a key: a picture no longer paused shows the latest scan, its trails started
    /// again.
    pub fn follow(&mut self, state: &mut DisplayState) {
        if !state.paused {
            if let Some(latest) = self.latest.take() {
                // The trails start again: one point after the pause would draw a straight
                // line across whatever the targets did meanwhile.
                state.trails.clear();
                state.observe_picture(&latest);
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
        shown.follow(&mut state);
        assert_eq!(shown.view().scan, first + 4, "resumed at the latest scan");
        assert_eq!(shown.since_paused(), 0);
        shown.take(&mut state, step(&mut run));
        assert_eq!(shown.view().scan, first + 5);
    }

    /// While paused, a CPA/TCPA alarm of a scan tracked behind the picture is shown at
    /// once, and the paused picture's trails do not grow; on resuming they start again.
    #[test]
    fn a_paused_picture_shows_the_latest_scans_alarms_and_keeps_its_trails() {
        use ratatui::backend::TestBackend;
        use ratatui::Terminal;
        let screen = |state: &DisplayState, shown: &Shown| {
            let mut terminal = Terminal::new(TestBackend::new(160, 40)).unwrap();
            terminal
                .draw(|f| super::super::render_paused(f, state, shown.view(), shown.latest()))
                .unwrap();
            let buffer = terminal.backend().buffer().clone();
            (0..buffer.area.height)
                .flat_map(|y| (0..buffer.area.width).map(move |x| (x, y)))
                .map(|(x, y)| buffer[(x, y)].symbol().to_string())
                .collect::<String>()
        };
        let mut run = demo();
        let mut state = DisplayState::new("inproc".into());
        let mut shown = Shown::new(&mut state, step(&mut run));
        for _ in 0..6 {
            shown.take(&mut state, step(&mut run));
        }
        let track = shown.view().targets[0].track;
        let trail = |state: &DisplayState| state.trails.get(&track).map_or(0, |t| t.len());
        let before = trail(&state);
        assert!(!screen(&state, &shown).contains("CPA/TCPA ALARM"));
        state.key('p', None);
        for _ in 0..3 {
            shown.take(&mut state, step(&mut run));
        }
        assert_eq!(trail(&state), before, "a paused picture's trails stay");
        // The next scan tracked has a target closing on own ship.
        let mut closing = step(&mut run);
        let t = &mut closing.targets[0];
        (t.cpa_m, t.tcpa_s, t.trend_known) = (100.0, 120.0, true);
        shown.take(&mut state, closing);
        assert!(screen(&state, &shown).contains("CPA/TCPA ALARM"));
        assert_eq!(shown.view().scan + 4, shown.latest().scan);
        state.key('p', None);
        shown.follow(&mut state);
        assert!(before > 1);
        assert_eq!(trail(&state), 1, "resumed: the trails start again");
    }
}
