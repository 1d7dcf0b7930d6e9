//! Radar/AIS pairing scored against the truth, when the truth's target ids are the ships'
//! MMSIs (real traffic, `demo --ais-truth`): each scan, each pair (track, MMSI) is *correct*
//! when the scorer matched the track to that ship or that ship is the one nearest the track
//! (two ships in one resolution cell share a track, and the scorer keeps to the one it
//! matched first), *wrong* otherwise; a ship with a confirmed track drawn apart (neither
//! paired nor shown as an AIS target) and an AIS target held is *shown twice* that scan:
//! its radar target and its AIS triangle. The time to pair is from the scan a track drawn
//! as a target was first matched to it (a firm track whose acquisition failed is not drawn:
//! [`crate::session::numbers::ACQUISITION_MISSES`]) to the scan it was first paired
//! correctly.

use std::collections::{BTreeMap, BTreeSet};

use serde::Serialize;

/// What pairing came to.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PairingScores {
    /// Pair-scans whose track followed the ship of the MMSI.
    pub pairs_correct: u64,
    /// Pair-scans whose track followed another ship.
    pub pairs_wrong: u64,
    /// Pair-scans whose track followed no ship (a false or lost track).
    pub pairs_unverified: u64,
    /// Scans a radar target was merged into AIS targets' symbols ([`crate::session::ais::Candidate`])
    /// and followed one of those ships (or one of them was the ship nearest it).
    pub merged_correct: u64,
    /// … and followed another ship.
    pub merged_wrong: u64,
    /// … and followed no ship.
    pub merged_unverified: u64,
    /// Ship-scans with a matched track merged into other ships' AIS symbols and no AIS
    /// target of its own: the ship not shown at all.
    pub ships_hidden: u64,
    /// Ship-scans with a matched track drawn as a radar target of its own (neither paired
    /// nor shown as an AIS target) while the ship's AIS target is held (drawn, by itself
    /// or on another track): the ship shown twice.
    pub ships_unpaired: u64,
    /// … of those, later than [`PAIRING_ALLOWANCE_SCANS`] after the track was matched.
    pub ships_unpaired_late: u64,
    /// Ship-scans with a matched track held but not drawn, its target hidden in another
    /// track's plot ([`crate::session::ScanReport::in_echo`]), no AIS target held and no
    /// other track drawn on it: the ship shown only as the echo it shares.
    pub ships_in_echo_only: u64,
    /// Ships with a matched track drawn as a target and AIS, at some scan.
    pub ships_with_track_and_ais: usize,
    /// … of those paired correctly at some scan.
    pub ships_paired: usize,
    /// … paired correctly within [`PAIRING_ALLOWANCE_SCANS`] of their track being matched.
    pub ships_paired_in_time: usize,
    /// Mean time from a track matched to its correct pair, s.
    pub time_to_pair_mean_s: f64,
    /// The longest, s.
    pub time_to_pair_max_s: f64,
    /// 95 % of the ships with a track and AIS were paired within this, s (`None` when
    /// fewer than 95 % were paired at all).
    pub time_to_pair_p95_s: Option<f64>,
    /// Ships with a track and AIS whose track was, at some scan, paired with their AIS
    /// target or shown as it (merged, [`crate::session::ais::Candidate`]): associated.
    pub ships_associated: usize,
    /// Mean time from a track matched to its first association, s.
    pub time_to_associate_mean_s: f64,
    /// 95 % of the ships with a track and AIS were associated within this, s (`None` when
    /// fewer than 95 % were at all).
    pub time_to_associate_p95_s: Option<f64>,
}

/// The time a pair may take to form after the track is matched, scans: the pairing's own
/// three scans in a row, and as many again for a track's first velocities to settle.
pub const PAIRING_ALLOWANCE_SCANS: u32 = 6;

/// What the session showed in a scan, as the pairing scorer reads it.
#[derive(Clone, Copy, Debug)]
pub struct Picture<'a> {
    /// The session's pairs (track, MMSI).
    pub pairs: &'a [(u16, u32)],
    /// Its radar targets shown as AIS targets (track, MMSI).
    pub merged: &'a [(u16, u32)],
    /// The MMSIs of the AIS targets held.
    pub ais: &'a [u32],
    /// The tracks drawn as targets (a firm track whose acquisition failed is not:
    /// [`crate::session::numbers::ACQUISITION_MISSES`]).
    pub drawn: &'a [u16],
    /// The tracks held but not drawn, their target hidden in another's plot.
    pub in_echo: &'a [u16],
}

/// The tally.
#[derive(Clone, Debug, Default)]
pub struct PairingScorer {
    scores: PairingScores,
    /// Per ship: the scan its track was first matched, and first correctly paired.
    first_matched: BTreeMap<u32, u32>,
    first_paired: BTreeMap<u32, u32>,
    first_associated: BTreeMap<u32, u32>,
}

impl PairingScorer {
    /// One scan: `matched` maps each confirmed track to the ship (MMSI) the scorer matched
    /// it to, `nearest` to the ship nearest it; `picture` is what the session showed.
    pub fn scan(
        &mut self,
        scan: u32,
        matched: &BTreeMap<u16, u32>,
        nearest: &BTreeMap<u16, u32>,
        picture: &Picture<'_>,
    ) {
        let Picture {
            pairs,
            merged,
            ais,
            drawn,
            in_echo,
        } = *picture;
        let mut merged_tracks: BTreeMap<u16, Vec<u32>> = BTreeMap::new();
        for (track, mmsi) in merged {
            merged_tracks.entry(*track).or_default().push(*mmsi);
        }
        for (track, under) in &merged_tracks {
            match matched.get(track) {
                Some(ship)
                    if under.contains(ship)
                        || nearest.get(track).is_some_and(|n| under.contains(n)) =>
                {
                    self.scores.merged_correct += 1;
                    if ais.contains(ship) {
                        self.first_associated.entry(*ship).or_insert(scan);
                    }
                }
                Some(ship) => {
                    self.scores.merged_wrong += 1;
                    if !ais.contains(ship) {
                        self.scores.ships_hidden += 1;
                    }
                }
                None => self.scores.merged_unverified += 1,
            }
        }
        for (track, ship) in matched {
            if ais.contains(ship) && drawn.contains(track) {
                self.first_matched.entry(*ship).or_insert(scan);
            }
        }
        for (track, mmsi) in pairs {
            match matched.get(track) {
                Some(ship) if ship == mmsi || nearest.get(track) == Some(mmsi) => {
                    self.scores.pairs_correct += 1;
                    self.first_paired.entry(*ship).or_insert(scan);
                    self.first_associated.entry(*ship).or_insert(scan);
                }
                Some(_) => self.scores.pairs_wrong += 1,
                None => self.scores.pairs_unverified += 1,
            }
        }
        for (track, ship) in matched {
            // A paired track is drawn as its AIS target (another ship's: counted wrong above).
            let paired = pairs.iter().any(|(t, _)| t == track);
            if ais.contains(ship)
                && drawn.contains(track)
                && !paired
                && !merged_tracks.contains_key(track)
            {
                self.scores.ships_unpaired += 1;
                let since = self
                    .first_matched
                    .get(ship)
                    .map_or(0, |first| scan.saturating_sub(*first));
                if since > PAIRING_ALLOWANCE_SCANS {
                    self.scores.ships_unpaired_late += 1;
                }
            }
        }
        let in_echo_only: BTreeSet<u32> = matched
            .iter()
            .filter(|(track, ship)| {
                in_echo.contains(track)
                    && !ais.contains(ship)
                    && !matched.iter().any(|(t, s)| s == *ship && drawn.contains(t))
            })
            .map(|(_, ship)| *ship)
            .collect();
        self.scores.ships_in_echo_only += in_echo_only.len() as u64;
    }

    /// The scores, times in s with scans of `scan_s`.
    pub fn scores(&self, scan_s: f64) -> PairingScores {
        let mut s = self.scores.clone();
        s.ships_with_track_and_ais = self.first_matched.len();
        let delays_of = |first: &BTreeMap<u32, u32>| -> Vec<u32> {
            first
                .iter()
                .filter_map(|(ship, p)| self.first_matched.get(ship).map(|m| p.saturating_sub(*m)))
                .collect()
        };
        let delays = delays_of(&self.first_paired);
        s.ships_paired = delays.len();
        s.ships_paired_in_time = delays
            .iter()
            .filter(|d| **d <= PAIRING_ALLOWANCE_SCANS)
            .count();
        s.time_to_pair_mean_s =
            delays.iter().map(|d| f64::from(*d)).sum::<f64>() / delays.len().max(1) as f64 * scan_s;
        s.time_to_pair_max_s = f64::from(delays.iter().copied().max().unwrap_or(0)) * scan_s;
        // The delay of the ship at the 95th percentile of all ships with a track and AIS.
        let at = (s.ships_with_track_and_ais as f64 * 0.95).ceil() as usize;
        let p95 = |delays: &[u32]| {
            let mut sorted = delays.to_vec();
            sorted.sort_unstable();
            match at.checked_sub(1) {
                None => Some(0.0),
                Some(i) => sorted.get(i).map(|d| f64::from(*d) * scan_s),
            }
        };
        s.time_to_pair_p95_s = p95(&delays);
        let associated = delays_of(&self.first_associated);
        s.ships_associated = associated.len();
        s.time_to_associate_mean_s = associated.iter().map(|d| f64::from(*d)).sum::<f64>()
            / associated.len().max(1) as f64
            * scan_s;
        s.time_to_associate_p95_s = p95(&associated);
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every track of the tests drawn.
    const ALL: [u16; 3] = [1, 2, 3];

    #[test]
    fn pairs_are_scored_against_the_ships_the_tracks_follow() {
        let mut p = PairingScorer::default();
        let matched: BTreeMap<u16, u32> = [(1, 100), (2, 200)].into();
        // Scan 0: nothing paired yet; both ships have AIS: both shown twice.
        p.scan(
            0,
            &matched,
            &matched,
            &Picture {
                pairs: &[],
                merged: &[],
                ais: &[100, 200],
                drawn: &ALL,
                in_echo: &[],
            },
        );
        // Scan 3: track 1 paired right, track 2 paired wrong.
        p.scan(
            3,
            &matched,
            &matched,
            &Picture {
                pairs: &[(1, 100), (2, 300)],
                merged: &[],
                ais: &[100, 200, 300],
                drawn: &ALL,
                in_echo: &[],
            },
        );
        // Scan 10: track 2 paired right, late.
        p.scan(
            10,
            &matched,
            &matched,
            &Picture {
                pairs: &[(1, 100), (2, 200)],
                merged: &[],
                ais: &[100, 200, 300],
                drawn: &ALL,
                in_echo: &[],
            },
        );
        // Track 2 follows ship 200 but ship 300 is nearest it (one resolution cell): right.
        let nearest: BTreeMap<u16, u32> = [(1, 100), (2, 300)].into();
        p.scan(
            11,
            &matched,
            &nearest,
            &Picture {
                pairs: &[(2, 300)],
                merged: &[],
                ais: &[100, 200, 300],
                drawn: &ALL,
                in_echo: &[],
            },
        );
        assert_eq!(p.scores(2.5).pairs_correct, 4);
        p.scan(
            12,
            &matched,
            &matched,
            &Picture {
                pairs: &[(2, 300)],
                merged: &[],
                ais: &[100, 200, 300],
                drawn: &ALL,
                in_echo: &[],
            },
        );
        let s = p.scores(2.5);
        assert_eq!((s.pairs_correct, s.pairs_wrong), (4, 2));
        // Shown twice: both at scan 0, then ship 100 at scans 11 and 12 (track 1 apart from
        // its AIS target); a paired track is drawn as its AIS target, so ship 200 is not
        // shown twice at scans 3, 11 and 12 (its track stands as another ship's: wrong or
        // right by the rules above, but one symbol).
        assert_eq!(s.ships_unpaired, 4);
        assert_eq!(s.ships_unpaired_late, 2);
        assert_eq!(
            (
                s.ships_with_track_and_ais,
                s.ships_paired,
                s.ships_paired_in_time
            ),
            (2, 2, 1)
        );
        assert!((s.time_to_pair_mean_s - 6.5 * 2.5).abs() < 1e-9);
        assert!((s.time_to_pair_max_s - 25.0).abs() < 1e-9);
        // Two ships, both paired: the 95th percentile is the slower one's 10 scans.
        assert_eq!(s.time_to_pair_p95_s, Some(25.0));
        assert_eq!(s.ships_associated, 2);
        assert_eq!(s.time_to_associate_p95_s, Some(25.0));
    }

    #[test]
    fn a_radar_target_shown_as_ais_counts_once_and_hides_a_ship_without_ais() {
        let mut p = PairingScorer::default();
        // Track 1 follows ship 100, track 2 ship 200 (no AIS held), track 3 ship 300.
        let matched: BTreeMap<u16, u32> = [(1, 100), (2, 200), (3, 300)].into();
        // Track 1 shown as AIS 100 and 400 (ships it does not tell apart): right, ship 100
        // shown once and associated; track 2 shown as AIS 100 too: wrong, and ship 200 is
        // not shown at all; track 3 shown apart from AIS 300: twice.
        p.scan(
            4,
            &matched,
            &matched,
            &Picture {
                pairs: &[],
                merged: &[(1, 100), (1, 400), (2, 100)],
                ais: &[100, 300, 400],
                drawn: &ALL,
                in_echo: &[],
            },
        );
        let s = p.scores(2.5);
        assert_eq!(
            (s.merged_correct, s.merged_wrong, s.merged_unverified),
            (1, 1, 0)
        );
        assert_eq!(s.ships_hidden, 1);
        assert_eq!(s.ships_unpaired, 1);
        assert_eq!((s.ships_associated, s.ships_paired), (1, 0));
        assert_eq!(s.time_to_associate_p95_s, None);
    }

    #[test]
    fn a_second_track_on_a_paired_ship_shows_it_twice() {
        let mut p = PairingScorer::default();
        // Tracks 1 and 2 both follow ship 100; track 1 is paired with its AIS target, track
        // 2 is drawn apart: the ship is shown twice.
        let matched: BTreeMap<u16, u32> = [(1, 100), (2, 100)].into();
        p.scan(
            0,
            &matched,
            &matched,
            &Picture {
                pairs: &[(1, 100)],
                merged: &[],
                ais: &[100],
                drawn: &ALL,
                in_echo: &[],
            },
        );
        let s = p.scores(2.5);
        assert_eq!((s.pairs_correct, s.ships_unpaired), (1, 1));
        // Shown as the AIS target as well (merged): once.
        p.scan(
            1,
            &matched,
            &matched,
            &Picture {
                pairs: &[(1, 100)],
                merged: &[(2, 100)],
                ais: &[100],
                drawn: &ALL,
                in_echo: &[],
            },
        );
        assert_eq!(p.scores(2.5).ships_unpaired, 1);
        // Not drawn at all (its acquisition failed): once.
        p.scan(
            2,
            &matched,
            &matched,
            &Picture {
                pairs: &[(1, 100)],
                merged: &[],
                ais: &[100],
                drawn: &[1],
                in_echo: &[],
            },
        );
        assert_eq!(p.scores(2.5).ships_unpaired, 1);
        p.scan(
            3,
            &matched,
            &matched,
            &Picture {
                pairs: &[(1, 100)],
                merged: &[],
                ais: &[100],
                drawn: &ALL,
                in_echo: &[],
            },
        );
        assert_eq!(p.scores(2.5).ships_unpaired, 2);
    }

    #[test]
    fn a_ship_without_ais_whose_track_is_hidden_in_an_echo_is_counted_as_shown_only_by_it() {
        let mut p = PairingScorer::default();
        // Track 2 follows ship 200, hidden in the plot track 1 (ship 100) took: not drawn.
        let matched: BTreeMap<u16, u32> = [(1, 100), (2, 200)].into();
        let scan = |p: &mut PairingScorer, scan: u32, ais: &[u32], drawn: &[u16]| {
            p.scan(
                scan,
                &matched,
                &matched,
                &Picture {
                    pairs: &[],
                    merged: &[],
                    ais,
                    drawn,
                    in_echo: &[2],
                },
            );
            p.scores(2.5).ships_in_echo_only
        };
        // Ship 200 has no AIS target held: shown only as the echo it shares.
        assert_eq!(scan(&mut p, 0, &[100], &[1]), 1);
        // Its AIS target held: it is shown by that, not counted.
        assert_eq!(scan(&mut p, 1, &[100, 200], &[1]), 1);
        // No AIS, but its track drawn (another scan's picture): not counted.
        assert_eq!(scan(&mut p, 2, &[100], &[1, 2]), 1);
        // Hidden again without AIS: counted again, and nothing else is.
        assert_eq!(scan(&mut p, 3, &[100], &[1]), 2);
    }
}
