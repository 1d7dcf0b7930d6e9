//! The same AIS message heard from two sources taken once: a radar capture's recorded AIS
//! and the same recording on `--nmea-in` (a new user's trial counted every sentence twice).
//! (Several `--nmea-in` sources are one source here: an AIS stream heard on two of them is
//! still taken twice.) A message from one source equal in every field the table keeps,
//! the position's UTC second included ([`AisReport::utc_second`]), to one the other source
//! gave within [`DUPLICATE_WINDOW_S`] is the same transmission (a ship's reports differ in
//! time stamp from one to the next, under a minute apart), and is counted, not taken again.

use std::collections::VecDeque;

use super::AisReport;

/// How far apart in time two sources may hear one message, s.
pub const DUPLICATE_WINDOW_S: f64 = 30.0;

/// Messages remembered at most (a flood of them forgets the oldest first): 30 s of a busy
/// strait's 100 messages a second, with room.
pub const MAX_REMEMBERED: usize = 8_000;

/// Which source a report came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AisSource {
    /// The plot source (a radar capture's own AIS).
    Plots,
    /// The own-ship source (`--nmea-in`).
    OwnShip,
}

/// The messages heard lately, by source.
#[derive(Clone, Debug, Default)]
pub struct AisDuplicates {
    recent: VecDeque<(f64, AisSource, AisReport)>,
    /// Messages heard from both sources and taken once.
    pub duplicates: u64,
}

impl AisDuplicates {
    /// Both sources' reports of one scan (heard time s, report), each source's in the
    /// order heard, less those the other source gave already: the reports to take.
    pub fn merge(
        &mut self,
        plots: Vec<(f64, AisReport)>,
        own_ship: Vec<(f64, AisReport)>,
    ) -> Vec<(f64, AisReport)> {
        let mut out = Vec::with_capacity(plots.len() + own_ship.len());
        for (t, r) in plots {
            if self.is_new(t, AisSource::Plots, &r) {
                out.push((t, r));
            }
        }
        for (t, r) in own_ship {
            if self.is_new(t, AisSource::OwnShip, &r) {
                out.push((t, r));
            }
        }
        out.sort_by(|a, b| a.0.total_cmp(&b.0));
        out
    }

    /// True unless the other source gave `r` within the window (then counted); remembers it.
    fn is_new(&mut self, t: f64, source: AisSource, r: &AisReport) -> bool {
        while self
            .recent
            .front()
            .is_some_and(|(at, _, _)| t - at > DUPLICATE_WINDOW_S)
        {
            self.recent.pop_front();
        }
        let heard = self
            .recent
            .iter()
            .position(|(at, s, x)| *s != source && (t - at).abs() <= DUPLICATE_WINDOW_S && x == r);
        if let Some(i) = heard {
            // Taken once: the other source's next hearing of it is new again.
            self.recent.remove(i);
            self.duplicates += 1;
            return false;
        }
        if self.recent.len() == MAX_REMEMBERED {
            self.recent.pop_front();
        }
        self.recent.push_back((t, source, r.clone()));
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(mmsi: u32, lat: f64) -> AisReport {
        AisReport {
            msg_type: 1,
            mmsi,
            position_deg: Some((lat, -1.0)),
            sog_kn: Some(10.0),
            ..AisReport::default()
        }
    }

    #[test]
    fn a_message_heard_from_both_sources_is_taken_once() {
        let mut d = AisDuplicates::default();
        // The capture's AIS and the same log on --nmea-in, a second apart.
        let taken = d.merge(
            vec![(100.0, report(1, 50.0)), (101.0, report(2, 50.0))],
            vec![(101.5, report(1, 50.0))],
        );
        assert_eq!(taken.len(), 2);
        assert_eq!(d.duplicates, 1);
        // The other half a scan later.
        let taken = d.merge(Vec::new(), vec![(103.0, report(2, 50.0))]);
        assert!(taken.is_empty());
        assert_eq!(d.duplicates, 2);
        // A new position from either source is taken; one source's repeats are its own.
        let taken = d.merge(vec![(110.0, report(1, 50.01))], Vec::new());
        assert_eq!(taken.len(), 1);
        let taken = d.merge(vec![(111.0, report(1, 50.01))], Vec::new());
        assert_eq!(taken.len(), 1);
        // Out of the window: the same content is a new report (a moored ship's).
        let taken = d.merge(Vec::new(), vec![(150.0, report(2, 50.0))]);
        assert_eq!(taken.len(), 1);
        assert_eq!(d.duplicates, 2);
    }

    /// A ship standing still reports the same fields every 10 s, each with its own time
    /// stamp: a report one source missed is new when the other gives it.
    #[test]
    fn a_ship_standing_still_is_told_apart_by_its_time_stamp() {
        let mut d = AisDuplicates::default();
        let at = |second| AisReport {
            utc_second: Some(second),
            ..report(7, 50.0)
        };
        let taken = d.merge(vec![(100.0, at(40))], vec![(100.5, at(40))]);
        assert_eq!((taken.len(), d.duplicates), (1, 1));
        // The capture missed the next; --nmea-in's is new, and so is the one after.
        let taken = d.merge(vec![(120.0, at(0))], vec![(110.0, at(50)), (120.2, at(0))]);
        assert_eq!((taken.len(), d.duplicates), (2, 2));
    }

    #[test]
    fn a_flood_is_bounded() {
        let mut d = AisDuplicates::default();
        for m in 0..10_000 {
            d.merge(vec![(1.0, report(m, 50.0))], Vec::new());
        }
        assert_eq!(d.recent.len(), MAX_REMEMBERED);
        assert_eq!(d.duplicates, 0);
    }
}
