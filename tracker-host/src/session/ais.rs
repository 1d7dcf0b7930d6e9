//! The AIS half of the picture: the AIS target table fed with the reports heard, and each
//! radar target paired with the AIS target of the same ship (IMO MSC.192(79) §5.31: one
//! ship is shown once), so the radar target keeps its number and takes the AIS name.
//!
//! Pairing is time-aligned (the AIS position is extrapolated along its COG at its SOG to
//! the scan's time) and held with hysteresis, so a pair does not flicker:
//!
//! - a radar target (confirmed) and an AIS target fit when their positions are within
//!   [`PairingGates::position_m`] and their velocities over ground within
//!   [`PairingGates::velocity_mps`] of each other (the vector difference, which holds both
//!   course and speed; widened for a young track); their *cost* is the squared distances
//!   in their sigmas ([`PairingGates::position_sigma_m`], growing with the AIS report's
//!   age, and [`PairingGates::velocity_sigma_mps`]);
//! - a fit is a pair's candidate when each is the other's cheapest and no other AIS target
//!   fits the radar target, nor other radar target the AIS target, within
//!   [`PairingGates::ambiguity_margin`] of its cost: ships in one resolution cell or in
//!   company are not paired wrong;
//! - candidates within [`PairingGates::merge_cost`] for [`PairingGates::scans_to_pair`]
//!   scans in a row are paired (an event);
//! - a pair outside gates [`PairingGates::keep_factor`] times as wide (its velocity
//!   difference taken from the path of the AIS target's velocities over the last
//!   [`PairingGates::manoeuvre_window_s`]: a track lags its ship's manoeuvre) for
//!   [`PairingGates::scans_to_part`] scans in a row is parted (an event), as is one whose
//!   track or AIS target is lost, or one another AIS target fits about as well (within
//!   [`PairingGates::swap_margin`]), or another radar target its AIS target, for as long;
//!   a rival only nearly as good (within the margin) parts a pair after more scans the
//!   longer it has held ([`PairingGates::scans_to_part_rivalled`]);
//! - while a radar target and an AIS target fit but are not paired, the radar target is
//!   shown as the AIS target ([`Candidate`], `ScanReport::merged`), so the ship is not
//!   shown twice while its pair is confirmed, nor while it cannot be told which of
//!   several ships in one cell it is; a young track, or a settled one whose velocity is
//!   just outside the gate, fits on position alone; and a radar target so shown stays so
//!   for a few scans after it stops fitting, as a pair is kept
//!   (`AisPicture::hold_candidates`).

use std::collections::BTreeMap;

use crate::ais::{AisReport, AisTargets};
use crate::origin::Origin;
use crate::session::ScanReport;

/// When a radar target and an AIS target are taken for one ship.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PairingGates {
    /// Largest distance between the radar target and the extrapolated AIS position, m.
    pub position_m: f32,
    /// Largest difference of their velocities over ground, m/s.
    pub velocity_mps: f32,
    /// Scans in a row as candidates before they are paired.
    pub scans_to_pair: u32,
    /// A pair is kept while within gates this many times as wide.
    pub keep_factor: f32,
    /// Scans in a row outside the wide gates before a pair is parted; also scans in a row
    /// with a rival within [`PairingGates::swap_margin`] of the pair's cost (the track
    /// swapped under it).
    pub scans_to_part: u32,
    /// A held pair needs one more scan in a row with a rival within
    /// [`PairingGates::ambiguity_margin`] (but not within the swap margin) to be parted
    /// for every this many scans it has been held, the rivalry's scans included (a pair held
    /// 50 scans before a rival came parts after 16 with growth 5; 0: always
    /// [`PairingGates::scans_to_part`]): ships in company told apart for long are not
    /// parted, and their name dropped, by a rival that comes and goes.
    pub hold_growth_scans: u32,
    /// At most this many scans in a row with such a rival part a pair, however long held.
    pub max_scans_to_part: u32,
    /// A rival within this much of a held pair's cost is taken for the track swapped to
    /// the other ship (or the AIS target to the other track): the pair is parted after
    /// [`PairingGates::scans_to_part`] such scans, however long held.
    pub swap_margin: f32,
    /// The spread of a radar target's position about the ship's AIS position, m: the
    /// track's error, the GNSS fix's and the AIS antenna's offset from the hull's centre.
    pub position_sigma_m: f32,
    /// The spread of their velocities' difference, m/s: mostly the track's.
    pub velocity_sigma_mps: f32,
    /// How fast an AIS position extrapolated from an old report loses accuracy, m/s of its
    /// age (course and speed errors, turns since the report).
    pub drift_sigma_mps: f32,
    /// A pair is taken only when every other AIS target fits the radar target, and every
    /// other radar target the AIS target, worse by at least this much in cost (the sum of
    /// the squared position and velocity differences in their sigmas: a difference of
    /// 6 is a likelihood 20 times smaller). Two ships in one resolution cell, moored side
    /// by side, or sailing in company are not told apart: their radar target is shown as
    /// their AIS targets ([`Candidate`]) rather than paired wrong. A held pair is parted
    /// when another AIS target (or radar target) comes within this much of its cost for
    /// [`PairingGates::scans_to_part`] scans in a row.
    pub ambiguity_margin: f32,
    /// A radar target is shown as an AIS target ([`Candidate`]) only while its cost is at
    /// most this (6 by default; 13.3 would be 99 % of a chi-square of 4 degrees of freedom,
    /// position and velocity), and only for the AIS targets that fit it within
    /// [`PairingGates::ambiguity_margin`] of its best; once so shown, it is held while
    /// within the wide gates (`AisPicture::hold_candidates`). A pair is made only of scans
    /// in a row within it too (once made, it is kept within the wide gates).
    pub merge_cost: f32,
    /// A track younger than this many scans has its velocity gate and sigma widened by
    /// this over its age: its first velocities are rough.
    pub settled_scans: f32,
    /// A pair is kept (and a radar target shown as an AIS target held) through its ship's
    /// manoeuvre: its velocity difference is the radar target's velocity's distance from
    /// the path of the velocities the AIS target has had over this many seconds (s; 0:
    /// its velocity now only). A track lags its ship's turn or change of speed (a CV
    /// filter's vector settles over tens of seconds; IMO MSC.192(79) allows the ARPA a
    /// minute for its trend), its velocity one the ship had on the way, while the AIS
    /// target reports the new one at once: a hovercraft slowing from 30 to 3 kn in a minute
    /// on the Solent was parted from its radar target, and shown twice, for want of it.
    pub manoeuvre_window_s: f32,
}

impl Default for PairingGates {
    /// 150 m and 3.5 m/s (7 kn): about five times a tracked target's position error and
    /// twice its velocity error on real traffic (the Solent run: 26 m and 1.75 m/s RMS,
    /// plots of the IMO model), plus an AIS antenna's offset from the hull's centre; three
    /// scans to pair, three outside 1.5× the gates to part, three with a rival within 4 of
    /// the cost, one more with a rival within 6 for every 5 scans held, at most 20 (chosen
    /// on both Solent runs among 2–10 scans, 6–60 at most, 2–5 of cost: the fewest
    /// pairings with no more wrong pair-scans). Sigmas 30 m (the track's 26 m
    /// RMS and 10 m of GNSS and antenna offset) and 1.8 m/s (the track's 1.75 m/s), 0.5 m/s
    /// of drift a second of the report's age, velocities widened over a track's first
    /// 8 scans; a rival within 6 of the cost makes a pair ambiguous; shown as the AIS
    /// target, and paired, up to a cost of 6 (pairing up to the gates' edge, 9.5 or 13.3
    /// gave 18–55 % more wrong pair-scans on the Solent's six runs, docs/ais.md). Gates
    /// chosen on the Solent run with own ship 234586000 among 150/250 m and 1.5/2.5/3.5 m/s; the margin among 2 and 6, the merge cost among
    /// 6, 9 and 13.3, the drift among 0.2 and 0.5 m/s, the settling among 1 and 8 scans
    /// (wrong pair-scans, ships hidden, ships shown twice), checked on own ship 370869000.
    fn default() -> Self {
        PairingGates {
            position_m: 150.0,
            velocity_mps: 3.5,
            scans_to_pair: 3,
            keep_factor: 1.5,
            scans_to_part: 3,
            hold_growth_scans: 5,
            max_scans_to_part: 20,
            swap_margin: 4.0,
            position_sigma_m: 30.0,
            velocity_sigma_mps: 1.8,
            drift_sigma_mps: 0.5,
            ambiguity_margin: 6.0,
            merge_cost: 6.0,
            settled_scans: 8.0,
            manoeuvre_window_s: 60.0,
        }
    }
}

/// How a ship whose radar target and AIS target are associated (paired, or the radar
/// target shown as the AIS target while their pair is confirmed) is drawn on the display
/// and the snapshot: once either way, as IEC 62388 §11.4 asks, by the AIS symbol unless the
/// operator chooses the radar one. The table and `TTM`/`TLL` are the same either way.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AssociatedSymbol {
    /// The AIS triangle with its heading line; the radar target's symbol not drawn.
    #[default]
    Ais,
    /// The radar target's symbol and vector; the AIS triangle not drawn.
    Radar,
}

/// Whose data a ship is shown with when its radar target is associated with one AIS target
/// (paired, or shown as that AIS target while their pair is confirmed): its position, course
/// and speed, CPA and TCPA, in the target table, on plotters (`TTM`, `TLL`) and in the
/// CPA/TCPA alarm. IEC 62388 §11.4 shows an associated target with the AIS target's
/// alphanumeric data by default, the radar's on the operator's choice. With the AIS
/// target's, the ship raises one CPA/TCPA alarm, not one from each source: in a new user's
/// trial a radar target shown as an AIS target (`NAME?`) kept its radar CPA and TCPA,
/// receding, while the same ship's AIS target raised its own alarm (CPA 0.40 NM in 1.1
/// min, the AIS right: the ship was turning and the track lagged).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AssociatedData {
    /// The AIS target's data ([`crate::session::target::TargetData::with_ais_data`]), its
    /// alarm held on them as a radar target's is.
    #[default]
    Ais,
    /// The radar track's data and alarm.
    Radar,
}

/// A radar target and the AIS target of the same ship.
#[derive(Clone, Debug, PartialEq)]
pub struct Pairing {
    /// The radar track.
    pub track: u16,
    /// Its target number, when it has one.
    pub number: Option<u8>,
    /// The AIS target's MMSI.
    pub mmsi: u32,
    /// Its name, or the MMSI.
    pub label: String,
    /// Distance between the two at the scan, m.
    pub distance_m: f32,
}

/// A radar target taken for an AIS target's ship while their pair is being confirmed, or
/// while it cannot be told which of several AIS targets it is (ships in one resolution
/// cell): the ship is shown once, as the AIS target (IEC 62388 §11.4: a radar target and
/// an AIS target of one ship are shown as one, the AIS symbol by default), and the radar
/// target is not drawn apart. Each AIS target takes at most one radar target, its best
/// within the gates (or one held from the last scans); one radar target may stand for
/// several AIS targets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Candidate {
    /// The radar track.
    pub track: u16,
    /// The AIS target's MMSI.
    pub mmsi: u32,
}

#[derive(Clone, Copy, Debug)]
struct Pair {
    mmsi: u32,
    /// Scans in a row outside the wide gates.
    outside: u32,
    /// Scans in a row another AIS target fitted the track, or another track the AIS
    /// target, nearly as well.
    rivalled: u32,
    /// Scans in a row a rival fitted within the swap margin.
    beaten: u32,
    /// Scans held.
    held: u32,
}

impl Pair {
    fn new(mmsi: u32) -> Self {
        Pair {
            mmsi,
            outside: 0,
            rivalled: 0,
            beaten: 0,
            held: 0,
        }
    }
}

impl PairingGates {
    /// Scans in a row with a rival nearly as good (not within the swap margin) that part a
    /// pair held for `held` scans.
    pub fn scans_to_part_rivalled(&self, held: u32) -> u32 {
        let more = held.checked_div(self.hold_growth_scans).unwrap_or(0);
        self.scans_to_part
            .saturating_add(more)
            .min(self.max_scans_to_part.max(self.scans_to_part))
    }
}

/// What the AIS picture has done.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct PairingCounts {
    /// Pairs made.
    pub paired: u64,
    /// Pairs parted (gates, or a track or AIS target lost).
    pub parted: u64,
}

/// The AIS table and the pairs. See the module documentation.
#[derive(Clone, Debug)]
pub struct AisPicture {
    table: AisTargets,
    gates: PairingGates,
    pairs: BTreeMap<u16, Pair>,
    streaks: BTreeMap<(u16, u32), u32>,
    /// The radar targets shown as AIS targets last scan, with the scans in a row each has
    /// been held without fitting as a candidate (`AisPicture::hold_candidates`).
    shown: BTreeMap<(u16, u32), u32>,
    events: crate::event_log::EventLog,
    counts: PairingCounts,
    /// The scans' clock is UTC ([`ScanReport::time_is_utc`]): the log's times are written
    /// with a `Z` only then.
    clock_is_utc: bool,
    /// The bridge's UTC less the scans' clock ([`ScanReport::utc_offset_s`]): the log's
    /// times are the bridge's, as the display's and the plotters' are.
    utc_offset_s: f64,
    /// Whose data an associated ship is shown with.
    data: AssociatedData,
    /// The alarm limits, and the targets whose alarm was on last scan on the data shown:
    /// held on them ([`crate::session::target::TargetData::alarm_held`]) whichever source
    /// the data came from, so an alarm does not drop or appear as a pair is made or parted.
    limits: crate::session::target::AlarmLimits,
    alarmed: std::collections::BTreeSet<u16>,
    /// Each AIS target's velocities over ground over the last
    /// [`PairingGates::manoeuvre_window_s`] (scan time s, m/s east and north), from the one
    /// in force at the window's start: one each time it changed by
    /// [`MANOEUVRE_STEP_MPS`], at most [`MANOEUVRE_SAMPLES`] (then the newest replaced),
    /// kept only while the AIS target is held and reports its course and speed.
    velocities: BTreeMap<u32, std::collections::VecDeque<(f64, [f32; 2])>>,
}

/// The most velocities kept per AIS target for its manoeuvre
/// ([`PairingGates::manoeuvre_window_s`]).
pub const MANOEUVRE_SAMPLES: usize = 32;

/// An AIS target's velocity is recorded for its manoeuvre when it has changed by this much
/// since the last recorded, m/s (its extrapolation about own ship moves it by far less from
/// scan to scan; a new report's course or speed by more).
pub const MANOEUVRE_STEP_MPS: f32 = 0.05;

impl AisPicture {
    /// An empty picture in the local frame of `origin`.
    pub fn new(origin: Origin, gates: PairingGates) -> Self {
        AisPicture {
            table: AisTargets::new(origin),
            gates,
            pairs: BTreeMap::new(),
            streaks: BTreeMap::new(),
            shown: BTreeMap::new(),
            events: crate::event_log::EventLog::default(),
            counts: PairingCounts::default(),
            clock_is_utc: true,
            utc_offset_s: 0.0,
            data: AssociatedData::default(),
            limits: crate::session::target::AlarmLimits::default(),
            alarmed: std::collections::BTreeSet::new(),
            velocities: BTreeMap::new(),
        }
    }

    /// The CPA/TCPA alarm limits the scans are shown with (to hold an alarm on the data
    /// shown).
    pub fn with_alarm_limits(mut self, limits: crate::session::target::AlarmLimits) -> Self {
        self.limits = limits;
        self
    }

    /// The picture showing associated ships with `data`'s data (the AIS target's by
    /// default).
    pub fn with_associated_data(mut self, data: AssociatedData) -> Self {
        self.data = data;
        self
    }

    /// The AIS table.
    pub fn table(&self) -> &AisTargets {
        &self.table
    }

    /// What pairing has done.
    pub fn counts(&self) -> PairingCounts {
        self.counts
    }

    /// Pairings and partings, the latest [`crate::event_log::EventLog::CAPACITY`], as the
    /// log reads them.
    pub fn events(&self) -> Vec<String> {
        self.events.lines("AIS pairing")
    }

    /// The time of an event at `t` as the log writes it.
    fn when(&self, t: f64) -> String {
        let offset_s = if self.clock_is_utc {
            self.utc_offset_s
        } else {
            0.0
        };
        crate::utc::scan_time_label(t + offset_s, self.clock_is_utc)
    }

    fn log(&mut self, event: String) {
        self.events.push(event);
    }

    /// Takes the AIS reports heard since the last scan (each with its time, s) and fills
    /// `report.ais` and `report.paired` for the scan.
    pub fn scan(&mut self, report: &mut ScanReport, heard: &[(f64, AisReport)]) {
        let t = report.time_s;
        self.clock_is_utc = report.time_is_utc;
        self.utc_offset_s = report.utc_offset_s;
        for (time_s, r) in heard {
            self.table.report(*time_s, r);
        }
        for mmsi in self.table.expire(t) {
            self.part_where(|p| p.mmsi == mmsi, t, "AIS target lost");
        }
        let ais = self.table.picture(&report.own, t);
        if report.skipped.is_some() {
            // A scan the device did not track has no targets: the pairs stand (their
            // tracks are still on the device), shown again with the next tracked scan.
            report.ais = ais;
            return;
        }
        let manoeuvre = self.manoeuvres(&ais, t);
        let targets: BTreeMap<u16, &crate::session::target::TargetData> =
            report.targets.iter().map(|x| (x.track, x)).collect();
        // A paired track held in another's echo is parted: kept through the merge, the pair
        // stayed with the track when it came out on the other ship (Solent, seeds 1–3:
        // wrong pair-scans 124 → 144; docs/ais.md).
        let hidden: Vec<u16> = report.in_echo.iter().map(|x| x.track).collect();
        self.part_where_track(
            |track| hidden.contains(&track),
            t,
            "track hidden in another's echo",
        );
        self.part_where_track(
            |track| !targets.contains_key(&track),
            t,
            "track lost or not shown",
        );
        let gap = |a: [f32; 2], b: [f32; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
        let gates = self.gates;
        let by_mmsi: BTreeMap<u32, &crate::ais::AisTargetData> =
            ais.iter().map(|a| (a.mmsi, a)).collect();
        // The distance between a radar target and an AIS target, m, and its cost in the
        // position sigma (which grows with the AIS report's age). The radar's echo is of
        // the hull: measured from the hull's centre (the AIS position is its antenna's);
        // when the ship's orientation is not known, from the circle about the antenna the
        // centre lies on (0 inside it), in gate and cost alike.
        let position = |x: &crate::session::target::TargetData, a: &crate::ais::AisTargetData| {
            let d = (gap(x.position_m, a.hull_centre_m) - a.hull_centre_unknown_m).max(0.0);
            let drift = a.age_s.max(0.0) * gates.drift_sigma_mps;
            let sp2 = gates.position_sigma_m * gates.position_sigma_m + drift * drift;
            (d, d * d / sp2.max(1.0))
        };
        // Within the gates, or (`keep`) the wide ones that keep a pair or a radar target
        // shown as an AIS target, its velocity taken against the ship's over its manoeuvre.
        let within = |track: u16, mmsi: u32, keep: bool| -> Option<f32> {
            let x = targets.get(&track)?;
            let a = by_mmsi.get(&mmsi)?;
            let (d, position_cost) = position(x, a);
            let factor = if keep { gates.keep_factor } else { 1.0 };
            let dv = match manoeuvre.get(&mmsi) {
                Some(path) if keep => gap_to_path(x.velocity_mps, path),
                _ => gap(x.velocity_mps, a.velocity_mps),
            };
            // A young track's velocity is known only roughly.
            let young = (gates.settled_scans / f32::from(x.age_scans.max(1))).max(1.0);
            let sv = gates.velocity_sigma_mps * young;
            let sv2 = sv * sv;
            (d <= gates.position_m * factor && dv <= gates.velocity_mps * young * factor)
                .then_some(position_cost + dv * dv / sv2.max(1e-3))
        };
        // Every radar target against every AIS target within the gates (the AIS targets
        // nearer than the position gate, by a cheap bound, first).
        let near = |x: &crate::session::target::TargetData, a: &crate::ais::AisTargetData| {
            let hull = gap(a.position_m, a.hull_centre_m) + a.hull_centre_unknown_m;
            (a.range_m - x.range_m).abs() <= gates.position_m * gates.keep_factor + hull
        };
        let mut all = Vec::new();
        for x in targets.values() {
            for a in ais.iter().filter(|a| near(x, a)) {
                if let Some(c) = within(x.track, a.mmsi, false) {
                    all.push((c, x.track, a.mmsi));
                }
            }
        }
        let margin = gates.ambiguity_margin;
        // The best cost of a track against AIS targets other than `mmsi`, and of an AIS
        // target against tracks other than `track`.
        let best_other_ais = |track: u16, mmsi: u32| {
            all.iter()
                .filter(|(_, t, m)| *t == track && *m != mmsi)
                .map(|(c, _, _)| *c)
                .fold(f32::INFINITY, f32::min)
        };
        let best_other_track = |track: u16, mmsi: u32| {
            all.iter()
                .filter(|(_, t, m)| *t != track && *m == mmsi)
                .map(|(c, _, _)| *c)
                .fold(f32::INFINITY, f32::min)
        };
        // Pairs held: within the wide gates, or outside for too long; rivalled by another
        // AIS target fitting the track, or another track the AIS target, nearly as well
        // for too long.
        let mut parted = Vec::new();
        for (track, pair) in &mut self.pairs {
            let own = within(*track, pair.mmsi, true);
            if own.is_some() {
                pair.outside = 0;
            } else {
                pair.outside += 1;
            }
            let rival = best_other_ais(*track, pair.mmsi).min(best_other_track(*track, pair.mmsi));
            if own.is_none_or(|c| rival < c + margin) {
                pair.rivalled += 1;
            } else {
                pair.rivalled = 0;
            }
            // A rival about as good as the pair or better is taken for a track swapped under
            // it: parted as soon as before; one only nearly as good (ships in company) waits
            // longer the longer the pair has held, so the name does not come and go.
            if own.is_none_or(|c| rival < c + gates.swap_margin) {
                pair.beaten += 1;
            } else {
                pair.beaten = 0;
            }
            pair.held = pair.held.saturating_add(1);
            if pair.outside >= gates.scans_to_part
                || pair.beaten >= gates.scans_to_part
                || pair.rivalled >= gates.scans_to_part_rivalled(pair.held)
            {
                parted.push(*track);
            }
        }
        for track in parted {
            self.part_where_track(|x| x == track, t, "out of the gates or rivalled");
        }
        // Candidates: mutual nearest within the gates, among the unpaired, and unambiguous.
        let paired_mmsi: Vec<u32> = self.pairs.values().map(|p| p.mmsi).collect();
        let mut costs: Vec<(f32, u16, u32)> = all
            .iter()
            .copied()
            .filter(|(_, track, mmsi)| {
                !self.pairs.contains_key(track) && !paired_mmsi.contains(mmsi)
            })
            .collect();
        costs.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut streaks = BTreeMap::new();
        let (mut used_tracks, mut used_mmsi) = (Vec::new(), Vec::new());
        for &(c, track, mmsi) in &costs {
            if used_tracks.contains(&track) || used_mmsi.contains(&mmsi) {
                continue;
            }
            used_tracks.push(track);
            used_mmsi.push(mmsi);
            // … and a fit good enough to be shown as the AIS target: a pair is not made of
            // a weaker one (a track on a ship without AIS, or dragged off its ship, 100 m
            // from a neighbour's AIS target with nothing else near).
            let clear = c <= gates.merge_cost
                && best_other_ais(track, mmsi) >= c + margin
                && best_other_track(track, mmsi) >= c + margin;
            if !clear {
                continue;
            }
            let n = self.streaks.get(&(track, mmsi)).copied().unwrap_or(0) + 1;
            if n >= gates.scans_to_pair {
                self.pairs.insert(track, Pair::new(mmsi));
                self.counts.paired += 1;
                let label = self
                    .table
                    .get(mmsi)
                    .map_or(crate::ais::mmsi_text(mmsi), |a| a.described());
                let number = targets.get(&track).map_or("--".to_string(), |x| x.label());
                self.log(format!(
                    "{}: radar target {number} (track {track}) paired with AIS {label}",
                    self.when(t)
                ));
            } else {
                streaks.insert((track, mmsi), n);
            }
        }
        self.streaks = streaks;
        // A young track's velocity (from its first plots, a few metres over 2.5 s) may be
        // far off its ship's even with the widened gate: it is shown as an AIS target it
        // fits on position alone until it has settled (never paired so), rather than apart
        // beside the ship's own symbol. A settled one whose velocity is just outside the
        // gate (within the pair's wide gate, a track lagging its ship's turn) is shown so
        // too. Measured on the Solent (docs/ais.md).
        let mut display = costs.clone();
        let fitted_mmsi: std::collections::BTreeSet<u32> =
            costs.iter().map(|(_, _, m)| *m).collect();
        let fitted_tracks: std::collections::BTreeSet<u16> =
            costs.iter().map(|(_, t, _)| *t).collect();
        for x in targets.values() {
            if self.pairs.contains_key(&x.track) || fitted_tracks.contains(&x.track) {
                continue;
            }
            let settled = f32::from(x.age_scans) >= gates.settled_scans;
            for a in ais
                .iter()
                .filter(|a| near(x, a) && !paired_mmsi.contains(&a.mmsi))
            {
                let (d, cost) = position(x, a);
                let velocity_fits = !settled
                    || gap(x.velocity_mps, a.velocity_mps)
                        <= gates.velocity_mps * gates.keep_factor;
                // … and then only an AIS target no radar target fits within the gates: the
                // weaker fit does not take it from a better one, nor hide an echo near it.
                let fitted = settled && fitted_mmsi.contains(&a.mmsi);
                if d <= gates.position_m && velocity_fits && !fitted {
                    display.push((cost, x.track, a.mmsi));
                }
            }
        }
        display.sort_by(|a, b| a.0.total_cmp(&b.0));
        // Those paired this scan are out too.
        let paired_now: Vec<u32> = self.pairs.values().map(|p| p.mmsi).collect();
        let mut merged = self.candidates(&display, &paired_now);
        self.hold_candidates(&mut merged, &paired_now, |track, mmsi| {
            within(track, mmsi, true).is_some()
        });
        report.merged = merged;
        report.paired = self
            .pairs
            .iter()
            .filter_map(|(track, p)| {
                let x = targets.get(track)?;
                let a = ais.iter().find(|a| a.mmsi == p.mmsi)?;
                Some(Pairing {
                    track: *track,
                    number: x.number,
                    mmsi: p.mmsi,
                    label: a.label.clone(),
                    distance_m: gap(x.position_m, a.hull_centre_m),
                })
            })
            .collect();
        report.ais = ais;
        if self.data == AssociatedData::Ais {
            show_ais_data(report);
            // An alarm is held on what was shown last scan, AIS data or the track's.
            for t in &mut report.targets {
                t.alarm_held = self.alarmed.contains(&t.track);
            }
            self.alarmed = report
                .targets
                .iter()
                .filter(|t| t.dangerous(&self.limits))
                .map(|t| t.track)
                .collect();
        }
    }

    /// Records the AIS targets' velocities at scan time `t` (s) and gives the manoeuvre of
    /// each one a pair or a radar target shown as it may keep (the only ones asked): the
    /// velocities it has had over the last [`PairingGates::manoeuvre_window_s`], oldest
    /// first, ending with the one now (m/s).
    fn manoeuvres(
        &mut self,
        ais: &[crate::ais::AisTargetData],
        t: f64,
    ) -> BTreeMap<u32, Vec<[f32; 2]>> {
        let window_s = f64::from(self.gates.manoeuvre_window_s);
        let kept_by: std::collections::BTreeSet<u32> = (self.pairs.values().map(|p| p.mmsi))
            .chain(self.shown.keys().map(|(_, mmsi)| *mmsi))
            .collect();
        let mut out = BTreeMap::new();
        let mut kept = BTreeMap::new();
        for a in ais {
            let mut seen = self.velocities.remove(&a.mmsi).unwrap_or_default();
            // Kept from the one in force at the window's start (a velocity held since
            // long before is the one the ship changed from).
            while seen.get(1).is_some_and(|(at, _)| t - at > window_s) {
                seen.pop_front();
            }
            let v = a.velocity_mps;
            let moved = |w: &[f32; 2]| (v[0] - w[0]).hypot(v[1] - w[1]) >= MANOEUVRE_STEP_MPS;
            // A report without course and speed (velocity 0 for want of one) is no velocity
            // the ship had.
            let known = window_s > 0.0 && a.motion_reported;
            if known && seen.back().is_none_or(|(_, w)| moved(w)) {
                let full = seen.len() >= MANOEUVRE_SAMPLES;
                match seen.back_mut() {
                    // Full: the newest is replaced (the window's first, the velocity the
                    // ship changed from, and the times the window is trimmed by stay).
                    Some(last) if full => *last = (t, v),
                    _ => seen.push_back((t, v)),
                }
            }
            if kept_by.contains(&a.mmsi) {
                let path = seen.iter().map(|(_, w)| *w).chain(std::iter::once(v));
                out.insert(a.mmsi, path.collect::<Vec<_>>());
            }
            if known {
                kept.insert(a.mmsi, seen);
            }
        }
        // Only the AIS targets held.
        self.velocities = kept;
        out
    }

    /// The radar targets shown as AIS targets this scan: among the unpaired within the
    /// gates and [`PairingGates::merge_cost`], one to one by cost (the cheapest first), then
    /// each AIS target left over whose best radar target was taken within
    /// [`PairingGates::ambiguity_margin`] of that one's cost (one radar target for ships
    /// it does not tell apart). `costs`: the scan's fits among the pairs unpaired before
    /// it, cheapest first.
    fn candidates(&self, costs: &[(f32, u16, u32)], paired_mmsi: &[u32]) -> Vec<Candidate> {
        let free = costs.iter().filter(|(c, track, mmsi)| {
            *c <= self.gates.merge_cost
                && !self.pairs.contains_key(track)
                && !paired_mmsi.contains(mmsi)
        });
        let mut taken: BTreeMap<u16, f32> = BTreeMap::new();
        let mut out: Vec<Candidate> = Vec::new();
        for &(c, track, mmsi) in free.clone() {
            if taken.contains_key(&track) || out.iter().any(|x| x.mmsi == mmsi) {
                continue;
            }
            taken.insert(track, c);
            out.push(Candidate { track, mmsi });
        }
        // Each AIS target left over, at its first (its best) entry: shown as that radar
        // target when the radar target was taken nearly as cheaply, else shown apart.
        let mut seen: Vec<u32> = out.iter().map(|x| x.mmsi).collect();
        let mut grouped = Vec::new();
        for &(c, track, mmsi) in free {
            if seen.contains(&mmsi) {
                continue;
            }
            seen.push(mmsi);
            if taken
                .get(&track)
                .is_some_and(|t| c <= t + self.gates.ambiguity_margin)
            {
                grouped.push(Candidate { track, mmsi });
            }
        }
        out.extend(grouped);
        out.sort_by_key(|x| (x.track, x.mmsi));
        out
    }

    /// Keeps last scan's radar targets shown as AIS targets that are not this scan's
    /// candidates, as a pair is kept: while `kept(track, mmsi)` (within the pair's wide
    /// gates, [`PairingGates::keep_factor`]) for up to [`PairingGates::scans_to_part`] scans
    /// in a row, unless the track or the AIS target is paired, the track is one of this
    /// scan's candidates, or the AIS target is shown on another track (a radar target held
    /// for two AIS targets keeps both). Without
    /// it, a fit that crossed the merge cost or the gates for a scan drew the radar target
    /// apart beside its ship's AIS symbol for that scan (docs/ais.md: ship-scans shown
    /// twice 278 → 239 and 413 → 369 on the two Solent runs).
    fn hold_candidates(
        &mut self,
        merged: &mut Vec<Candidate>,
        paired_mmsi: &[u32],
        kept: impl Fn(u16, u32) -> bool,
    ) {
        let mut shown: BTreeMap<(u16, u32), u32> =
            merged.iter().map(|c| ((c.track, c.mmsi), 0)).collect();
        let fresh = merged.len();
        for (&(track, mmsi), &held) in &self.shown {
            let free = !self.pairs.contains_key(&track)
                && !paired_mmsi.contains(&mmsi)
                && !merged[..fresh].iter().any(|c| c.track == track)
                && !merged.iter().any(|c| c.mmsi == mmsi);
            if free && held < self.gates.scans_to_part && kept(track, mmsi) {
                merged.push(Candidate { track, mmsi });
                shown.insert((track, mmsi), held + 1);
            }
        }
        merged.sort_by_key(|x| (x.track, x.mmsi));
        self.shown = shown;
    }

    fn part_where(&mut self, f: impl Fn(&Pair) -> bool, t: f64, why: &str) {
        let gone: Vec<(u16, u32)> = self
            .pairs
            .iter()
            .filter(|(_, p)| f(p))
            .map(|(k, p)| (*k, p.mmsi))
            .collect();
        for (track, mmsi) in gone {
            self.pairs.remove(&track);
            self.counts.parted += 1;
            self.log(format!(
                "{}: track {track} and AIS {} parted ({why})",
                self.when(t),
                crate::ais::mmsi_text(mmsi)
            ));
        }
    }

    fn part_where_track(&mut self, f: impl Fn(u16) -> bool, t: f64, why: &str) {
        let gone: Vec<u16> = self.pairs.keys().copied().filter(|k| f(*k)).collect();
        for track in gone {
            if let Some(p) = self.pairs.remove(&track) {
                self.counts.parted += 1;
                self.log(format!(
                    "{}: track {track} and AIS {} parted ({why})",
                    self.when(t),
                    crate::ais::mmsi_text(p.mmsi)
                ));
            }
        }
    }
}

/// The distance of velocity `v` from the path through `path`'s velocities in turn (a
/// single velocity: from it), m/s.
fn gap_to_path(v: [f32; 2], path: &[[f32; 2]]) -> f32 {
    let to_segment = |a: [f32; 2], b: [f32; 2]| {
        let ab = [b[0] - a[0], b[1] - a[1]];
        let len2 = ab[0] * ab[0] + ab[1] * ab[1];
        let u = if len2 > 0.0 {
            (((v[0] - a[0]) * ab[0] + (v[1] - a[1]) * ab[1]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (v[0] - a[0] - u * ab[0]).hypot(v[1] - a[1] - u * ab[1])
    };
    match path {
        [] => f32::INFINITY,
        [only] => to_segment(*only, *only),
        _ => path
            .windows(2)
            .map(|w| to_segment(w[0], w[1]))
            .fold(f32::INFINITY, f32::min),
    }
}

/// Shows each radar target associated with one AIS target (its pair, else the one AIS
/// target it is shown as) with that AIS target's data ([`AssociatedData::Ais`]). A radar
/// target shown as several AIS targets (ships in one resolution cell) keeps its own: which
/// ship's data it would show cannot be told.
fn show_ais_data(report: &mut ScanReport) {
    let ScanReport {
        targets,
        paired,
        merged,
        ais,
        own,
        ..
    } = report;
    for t in targets.iter_mut() {
        let mmsi = paired
            .iter()
            .find(|p| p.track == t.track)
            .map(|p| p.mmsi)
            .or_else(|| {
                let mut shown = merged.iter().filter(|c| c.track == t.track);
                match (shown.next(), shown.next()) {
                    (Some(c), None) => Some(c.mmsi),
                    _ => None,
                }
            });
        let Some(a) = mmsi.and_then(|m| ais.iter().find(|a| a.mmsi == m)) else {
            continue;
        };
        if let Some(d) = t.with_ais_data(own, a) {
            *t = d;
        }
    }
    // Nearest first, as the session gives them (the table's order, `TTM`'s).
    targets.sort_by(|a, b| a.range_m.total_cmp(&b.range_m));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_pair_that_has_held_long_needs_a_longer_rival_to_part() {
        let g = PairingGates::default();
        assert_eq!(g.scans_to_part_rivalled(0), g.scans_to_part);
        assert_eq!(
            g.scans_to_part_rivalled(g.hold_growth_scans * 4),
            g.scans_to_part + 4
        );
        assert_eq!(g.scans_to_part_rivalled(u32::MAX), g.max_scans_to_part);
        // No growth: always the scans to part.
        let fixed = PairingGates {
            hold_growth_scans: 0,
            ..g
        };
        assert_eq!(fixed.scans_to_part_rivalled(1_000), fixed.scans_to_part);
    }

    use crate::own_ship::OwnShip;

    /// The AIS targets' velocity in [`scan_ships`] (10 kn east), m/s.
    const SHIP_EAST_MPS: [f32; 2] = [10.0 * tracker_core::geo::MPS_PER_KNOT, 0.0];

    /// One scan with one radar target `age_scans` old, 20 m east of an AIS target heard
    /// that scan, whose velocity (8 m/s south) is far off the ship's (10 kn east).
    fn scan_one(picture: &mut AisPicture, origin: Origin, scan: u32, age_scans: u16) -> ScanReport {
        scan_with(picture, origin, scan, age_scans, [0.0, -8.0], true)
    }

    /// As [`scan_one`], the radar target's velocity `velocity_mps`, the scans' clock UTC
    /// or not.
    fn scan_with(
        picture: &mut AisPicture,
        origin: Origin,
        scan: u32,
        age_scans: u16,
        velocity_mps: [f32; 2],
        time_is_utc: bool,
    ) -> ScanReport {
        let track = Radar {
            track: 7,
            east_m: 20.0,
            velocity_mps,
            age_scans,
        };
        scan_tracks(picture, origin, scan, time_is_utc, &[track])
    }

    /// A radar track in [`scan_tracks`].
    #[derive(Clone, Copy)]
    struct Radar {
        track: u16,
        /// East of the AIS target, m.
        east_m: f32,
        velocity_mps: [f32; 2],
        age_scans: u16,
    }

    /// One scan with the AIS target of [`scan_one`] heard and `tracks` beside it.
    fn scan_tracks(
        picture: &mut AisPicture,
        origin: Origin,
        scan: u32,
        time_is_utc: bool,
        tracks: &[Radar],
    ) -> ScanReport {
        scan_ships(
            picture,
            origin,
            scan,
            time_is_utc,
            tracks,
            &[(235_000_001, 0.0)],
        )
    }

    /// As [`scan_tracks`], with AIS targets (MMSI, m east of the first's place) all on
    /// the first's course and speed.
    fn scan_ships(
        picture: &mut AisPicture,
        origin: Origin,
        scan: u32,
        time_is_utc: bool,
        tracks: &[Radar],
        ships: &[(u32, f32)],
    ) -> ScanReport {
        let heard: Vec<AisReport> = ships.iter().map(|s| ship_report(origin, *s)).collect();
        scan_reports(picture, scan, time_is_utc, tracks, &heard)
    }

    /// The position report of a ship of [`scan_ships`] (MMSI, m east of the first's place).
    fn ship_report(origin: Origin, (mmsi, east_m): (u32, f32)) -> AisReport {
        let (lat, lon) = origin.to_lat_lon([f64::from(east_m), 1_000.0]);
        AisReport {
            msg_type: 1,
            mmsi,
            class: Some(crate::ais::StationClass::ClassA),
            position_deg: Some((lat, lon)),
            sog_kn: Some(10.0),
            cog_deg: Some(90.0),
            ..AisReport::default()
        }
    }

    /// One scan with `tracks` and the AIS reports `heard`.
    fn scan_reports(
        picture: &mut AisPicture,
        scan: u32,
        time_is_utc: bool,
        tracks: &[Radar],
        heard: &[AisReport],
    ) -> ScanReport {
        use crate::session::target::TargetData;
        use tracker_core::icd::{TrackState, TrackStatus};
        let own = OwnShip::at([0.0, 0.0], [0.0, 0.0]);
        let tracks: Vec<TrackState> = tracks
            .iter()
            .map(|r| TrackState {
                track: r.track,
                status: TrackStatus::Confirmed,
                position_m: [r.east_m, 1_000.0],
                velocity_mps: r.velocity_mps,
                age_scans: r.age_scans,
                hit_history: 0b111,
            })
            .collect();
        let time_s = 1_000.0 + 2.5 * f64::from(scan);
        let mut report = ScanReport {
            scan,
            time_s,
            time_is_utc,
            utc_offset_s: 0.0,
            own,
            plots: Vec::new(),
            plots_m: Vec::new(),
            targets: tracks.iter().map(|t| TargetData::new(&own, t)).collect(),
            tracks,
            acquiring: Vec::new(),
            ended: Vec::new(),
            association: Default::default(),
            in_echo: Vec::new(),
            plot_accuracy: None,
            plot_sigma_m: crate::session::PLOT_SIGMA_M,
            host_time: Default::default(),
            skipped: None,
            ais: Vec::new(),
            paired: Vec::new(),
            merged: Vec::new(),
            echoes: None,
            silence: None,
        };
        let heard: Vec<(f64, AisReport)> = heard.iter().map(|r| (time_s, r.clone())).collect();
        picture.scan(&mut report, &heard);
        report
    }

    /// A ship that stops (its AIS SOG 14 kn east, then 0) while its radar target lags
    /// (still 14 kn, 7.2 m/s off, over the wide gate's 5.25): the pair is kept through the
    /// manoeuvre, and parted once the AIS target's old velocity has left the window
    /// (the track no longer excused); without the window, parted at once, as is a track
    /// going the other way (a velocity the ship never had, as far from it).
    #[test]
    fn a_pair_is_kept_while_its_radar_target_lags_the_ships_manoeuvre() {
        let origin = Origin::parse("50.8,-1.1").unwrap();
        let fast_mps = 14.0 * tracker_core::geo::MPS_PER_KNOT;
        // Whether track 7 is paired each scan, its velocity `east_mps` once the ship stops.
        let run = |gates: PairingGates, east_mps: f32| -> Vec<bool> {
            let mut picture = AisPicture::new(origin, gates);
            (0..50)
                .map(|scan| {
                    let track = Radar {
                        track: 7,
                        east_m: 20.0,
                        velocity_mps: [if scan < 10 { fast_mps } else { east_mps }, 0.0],
                        age_scans: 30,
                    };
                    let mut heard = ship_report(origin, (235_000_001, 0.0));
                    // Stopped from scan 10 on (the report heard at the scan: no drift).
                    heard.sog_kn = Some(if scan < 10 { 14.0 } else { 0.0 });
                    let r = scan_reports(&mut picture, scan, true, &[track], &[heard]);
                    r.paired.iter().any(|p| p.track == 7)
                })
                .collect()
        };
        let kept = run(PairingGates::default(), fast_mps);
        assert!(kept[3..10].iter().all(|p| *p), "{kept:?}");
        // The old velocity (scans before 10, at 2.5 s) is in the 60-s window at least to
        // scan 33.
        assert!(kept[10..34].iter().all(|p| *p), "{kept:?}");
        assert!(!kept[40], "{kept:?}");
        let without = run(
            PairingGates {
                manoeuvre_window_s: 0.0,
                ..PairingGates::default()
            },
            fast_mps,
        );
        assert!(without[9] && !without[13], "{without:?}");
        // A track going the other way at that speed had no velocity of the ship's: parted.
        let reversed = run(PairingGates::default(), -fast_mps);
        assert!(reversed[9] && !reversed[13], "{reversed:?}");
    }

    #[test]
    fn a_velocity_is_measured_from_the_path_of_the_ships_velocities() {
        let path = [[10.0, 0.0], [0.0, 0.0], [0.0, 4.0]];
        // On the path, beside its first leg, beyond its end, and the one velocity alone.
        assert_eq!(gap_to_path([5.0, 0.0], &path), 0.0);
        assert!((gap_to_path([5.0, 3.0], &path) - 3.0).abs() < 1e-6);
        assert!((gap_to_path([0.0, 7.0], &path) - 3.0).abs() < 1e-6);
        assert!((gap_to_path([3.0, 4.0], &[[0.0, 0.0]]) - 5.0).abs() < 1e-6);
        assert_eq!(gap_to_path([1.0, 1.0], &[]), f32::INFINITY);
    }

    #[test]
    fn a_long_ships_radar_target_is_paired_at_its_hull_centre_not_its_antenna() {
        let origin = Origin::parse("50.8,-1.1").unwrap();
        let gates = PairingGates::default();
        // A 300 m ship heading east (its COG at 10 kn), its antenna 250 m from the bow and
        // 50 m from the stern: the hull's centre 100 m ahead of the antenna, where the
        // radar's echo is. 100 m in the 30 m sigma is a cost of 11: over the merge cost.
        let mut ship = ship_report(origin, (235_000_001, 0.0));
        ship.size_m = Some((300, 40));
        ship.centre_from_antenna_m = Some((100.0, 0.0));
        let echo = Radar {
            track: 7,
            east_m: 100.0,
            velocity_mps: SHIP_EAST_MPS,
            age_scans: 20,
        };
        let mut picture = AisPicture::new(origin, gates);
        for scan in 0..gates.scans_to_pair {
            let r = scan_reports(&mut picture, scan, true, &[echo], &[ship.clone()]);
            let paired = scan + 1 == gates.scans_to_pair;
            assert_eq!(r.paired.len(), usize::from(paired), "scan {scan}: {r:?}");
            assert_eq!(r.merged.len(), usize::from(!paired), "scan {scan}: {r:?}");
        }
        // At rest with no heading: the centre anywhere 100 m about the antenna; the echo
        // 100 m west of it fits (paired), one 250 m off does not.
        ship.sog_kn = Some(0.0);
        for (west_m, pairs) in [(-100.0, true), (-250.0, false)] {
            let at_rest = Radar {
                east_m: west_m,
                velocity_mps: [0.0, 0.0],
                ..echo
            };
            let mut picture = AisPicture::new(origin, gates);
            for scan in 0..gates.scans_to_pair {
                let r = scan_reports(&mut picture, scan, true, &[at_rest], &[ship.clone()]);
                let paired = pairs && scan + 1 == gates.scans_to_pair;
                assert_eq!(
                    r.paired.len(),
                    usize::from(paired),
                    "{west_m} m, scan {scan}: {r:?}"
                );
            }
        }
        ship.sog_kn = Some(10.0);
        // The same ship with its antenna at the centre: 100 m off, never paired.
        let mut picture = AisPicture::new(origin, gates);
        ship.centre_from_antenna_m = Some((0.0, 0.0));
        for scan in 0..gates.scans_to_pair + 2 {
            let r = scan_reports(&mut picture, scan, true, &[echo], &[ship.clone()]);
            assert!(
                r.paired.is_empty() && r.merged.is_empty(),
                "scan {scan}: {r:?}"
            );
        }
    }

    #[test]
    fn a_young_track_is_shown_as_the_ais_target_it_fits_on_position() {
        let origin = Origin::parse("50.8,-1.1").unwrap();
        let mut young = AisPicture::new(origin, PairingGates::default());
        for scan in 0..4 {
            let r = scan_one(&mut young, origin, scan, 3 + scan as u16);
            let shown = [Candidate {
                track: 7,
                mmsi: 235_000_001,
            }];
            assert_eq!(r.merged, shown, "scan {scan}");
            assert!(r.paired.is_empty(), "never paired on position alone");
        }
        // Settled, the same velocity is another ship's: shown apart.
        let mut settled = AisPicture::new(origin, PairingGates::default());
        let r = scan_one(&mut settled, origin, 0, 20);
        assert!(r.merged.is_empty() && r.paired.is_empty(), "{r:?}");
    }

    #[test]
    fn an_associated_ship_is_shown_with_its_ais_data_and_alarms_once() {
        use crate::session::target::{AlarmLimits, TargetData};
        let origin = Origin::parse("50.8,-1.1").unwrap();
        let limits = AlarmLimits::default();
        // A young radar target 20 m east of the AIS target, shown as it (on position), its
        // velocity (8 m/s north) far off the ship's (10 kn east): by its own data it
        // recedes from own ship (at the origin, stopped), by the AIS target's it passes
        // 1,000 m off now, inside the 1 NM limit.
        let scan = |data: AssociatedData| {
            let mut picture =
                AisPicture::new(origin, PairingGates::default()).with_associated_data(data);
            scan_with(&mut picture, origin, 0, 3, [0.0, 8.0], true)
        };
        let r = scan(AssociatedData::Ais);
        assert_eq!(r.merged.len(), 1, "{r:?}");
        let (t, a) = (&r.targets[0], &r.ais[0]);
        assert_eq!(t.ais_data, Some(a.mmsi));
        assert_eq!((t.track, t.number), (7, None), "the track's own");
        assert_eq!(
            (t.position_m, t.velocity_mps),
            (a.position_m, a.velocity_mps)
        );
        assert!((t.speed_mps - SHIP_EAST_MPS[0]).abs() < 1e-3, "{t:?}");
        assert!((t.course_rad - core::f32::consts::FRAC_PI_2).abs() < 1e-3);
        assert_eq!(Some(t.cpa_m), a.cpa.map(|c| c.cpa_m));
        // One alarm, the radar target's on the AIS target's data; the AIS target raises
        // none of its own.
        assert!(t.dangerous(&limits), "{t:?}");
        assert_eq!(crate::display::ais_alarms(&r, &limits).count(), 0);
        // The radar's data on the operator's choice: the radar target recedes, and the AIS
        // target raises its alarm as before.
        let r = scan(AssociatedData::Radar);
        let t = &r.targets[0];
        assert_eq!(t.ais_data, None);
        assert_eq!(t.velocity_mps, [0.0, 8.0]);
        assert!(!t.dangerous(&limits), "{t:?}");
        assert_eq!(crate::display::ais_alarms(&r, &limits).count(), 1);
        // A pair shows the AIS target's data too.
        let gates = PairingGates::default();
        let mut picture = AisPicture::new(origin, gates);
        let on_course = Radar {
            track: 7,
            east_m: 20.0,
            velocity_mps: [SHIP_EAST_MPS[0], 0.3],
            age_scans: 20,
        };
        for scan in 0..gates.scans_to_pair {
            let r = scan_tracks(&mut picture, origin, scan, true, &[on_course]);
            assert_eq!(
                r.targets[0].ais_data,
                Some(235_000_001),
                "scan {scan}: {r:?}"
            );
            assert_eq!(r.targets[0].velocity_mps, r.ais[0].velocity_mps);
        }
        // Own ship's motion unknown: the AIS target has no CPA, and the radar's data stand.
        let mut picture = AisPicture::new(origin, gates);
        let mut r = scan_with(&mut picture, origin, 0, 3, [0.0, 8.0], true);
        r.own.quality.motion_known = false;
        r.targets = r
            .tracks
            .iter()
            .map(|x| TargetData::new(&r.own, x))
            .collect();
        let r = {
            let mut next = r.clone();
            next.scan = 1;
            next.time_s += 2.5;
            let heard = [(next.time_s, ship_report(origin, (235_000_001, 0.0)))];
            picture.scan(&mut next, &heard);
            next
        };
        assert_eq!(r.merged.len(), 1, "{r:?}");
        assert_eq!(r.targets[0].ais_data, None, "{r:?}");
    }

    #[test]
    fn a_fit_too_weak_to_be_shown_as_the_ais_target_is_never_paired() {
        let origin = Origin::parse("50.8,-1.1").unwrap();
        let east = SHIP_EAST_MPS;
        let gates = PairingGates::default();
        let at = |east_m: f32| Radar {
            track: 7,
            east_m,
            velocity_mps: east,
            age_scans: 20,
        };
        // 100 m off on the ship's velocity: within the 150 m gate, its cost (100 m in the
        // 30 m sigma: 11.1) over the merge cost. Drawn apart, never paired.
        let mut far = AisPicture::new(origin, gates);
        for scan in 0..10 {
            let r = scan_tracks(&mut far, origin, scan, true, &[at(100.0)]);
            assert!(
                r.paired.is_empty() && r.merged.is_empty(),
                "scan {scan}: {r:?}"
            );
        }
        // 20 m off: shown as the AIS target, then paired after the scans to pair.
        let mut near = AisPicture::new(origin, gates);
        for scan in 0..gates.scans_to_pair {
            let r = scan_tracks(&mut near, origin, scan, true, &[at(20.0)]);
            assert_eq!(
                r.paired.len(),
                usize::from(scan + 1 == gates.scans_to_pair),
                "scan {scan}"
            );
        }
        // Once paired, kept out to the wide gates: 100 m off holds.
        let r = scan_tracks(&mut near, origin, gates.scans_to_pair, true, &[at(100.0)]);
        assert_eq!(r.paired.len(), 1, "{r:?}");
    }

    #[test]
    fn the_log_writes_utc_only_for_a_utc_clock() {
        let origin = Origin::parse("50.8,-1.1").unwrap();
        // The ship's velocity, 10 kn east: paired after the gates' scans in a row.
        let east = SHIP_EAST_MPS;
        for (utc, time) in [(true, "00:16:45Z"), (false, "t 00:16:45")] {
            let mut picture = AisPicture::new(origin, PairingGates::default());
            for scan in 0..PairingGates::default().scans_to_pair + 1 {
                scan_with(&mut picture, origin, scan, 20, east, utc);
            }
            let events = picture.events();
            let paired = events.first().expect("paired");
            assert!(paired.starts_with(&format!("{time}: ")), "{paired}");
            assert!(paired.contains("paired with AIS"), "{paired}");
        }
    }

    #[test]
    fn a_radar_target_shown_as_an_ais_target_is_held_as_a_pair_is() {
        let origin = Origin::parse("50.8,-1.1").unwrap();
        let gates = PairingGates::default();
        let shown = vec![Candidate {
            track: 7,
            mmsi: 235_000_001,
        }];
        // Young, shown as the AIS target on position; then settled, on the ship's velocity
        // but 160 m off its AIS position: outside the gates (150 m), inside the wide ones
        // (225 m): held for the scans a pair takes to part, then drawn apart.
        let east = SHIP_EAST_MPS;
        let mut picture = AisPicture::new(origin, gates);
        assert_eq!(scan_one(&mut picture, origin, 0, 3).merged, shown);
        for scan in 1..=gates.scans_to_part + 1 {
            let far = Radar {
                track: 7,
                east_m: 160.0,
                velocity_mps: east,
                age_scans: 20,
            };
            let r = scan_tracks(&mut picture, origin, scan, true, &[far]);
            if scan <= gates.scans_to_part {
                assert_eq!(r.merged, shown, "scan {scan}");
            } else {
                assert!(r.merged.is_empty(), "{r:?}");
            }
            assert!(r.paired.is_empty(), "{r:?}");
        }
        // Outside the wide gates (velocity 9.5 m/s off): drawn apart at once.
        let mut picture = AisPicture::new(origin, gates);
        assert_eq!(scan_one(&mut picture, origin, 0, 3).merged, shown);
        assert!(scan_one(&mut picture, origin, 1, 20).merged.is_empty());
    }

    #[test]
    fn a_settled_track_just_outside_the_velocity_gate_is_shown_as_the_ais_target() {
        let origin = Origin::parse("50.8,-1.1").unwrap();
        let shown = vec![Candidate {
            track: 7,
            mmsi: 235_000_001,
        }];
        // Still, against the ship's 5.1 m/s east: outside the gate (3.5 m/s), within the
        // pair's wide one (5.25): shown as the AIS target (never paired so).
        let mut picture = AisPicture::new(origin, PairingGates::default());
        for scan in 0..4 {
            let r = scan_with(&mut picture, origin, scan, 20, [0.0, 0.0], true);
            assert_eq!(r.merged, shown, "scan {scan}");
            assert!(r.paired.is_empty(), "{r:?}");
        }
        // Beyond the wide gate: another ship's velocity, drawn apart.
        let mut picture = AisPicture::new(origin, PairingGates::default());
        let r = scan_with(&mut picture, origin, 0, 20, [-1.0, 0.0], true);
        assert!(r.merged.is_empty(), "{r:?}");
    }

    #[test]
    fn a_track_just_outside_the_velocity_gate_takes_no_ais_target_another_track_fits() {
        let origin = Origin::parse("50.8,-1.1").unwrap();
        let east = SHIP_EAST_MPS;
        // The ship's own track 45 m off, 2.5 m/s off its velocity: a fit (cost 4.2). A
        // still echo 30 m off (cost 1 on position): shown as the AIS target only when no
        // track fits it, so not here.
        let ship = Radar {
            track: 7,
            east_m: 45.0,
            velocity_mps: [east[0] - 2.5, 0.0],
            age_scans: 20,
        };
        let still = Radar {
            track: 9,
            east_m: -30.0,
            velocity_mps: [0.0, 0.0],
            age_scans: 20,
        };
        let mut picture = AisPicture::new(origin, PairingGates::default());
        let r = scan_tracks(&mut picture, origin, 0, true, &[ship, still]);
        let shown = vec![Candidate {
            track: 7,
            mmsi: 235_000_001,
        }];
        assert_eq!(r.merged, shown);
    }

    #[test]
    fn a_radar_target_held_for_two_ais_targets_keeps_both() {
        let origin = Origin::parse("50.8,-1.1").unwrap();
        let gates = PairingGates::default();
        let east = SHIP_EAST_MPS;
        let ships = [(235_000_001, 0.0), (235_000_002, 10.0)];
        let echo = |east_m: f32| Radar {
            track: 7,
            east_m,
            velocity_mps: east,
            age_scans: 20,
        };
        let both = vec![
            Candidate {
                track: 7,
                mmsi: 235_000_001,
            },
            Candidate {
                track: 7,
                mmsi: 235_000_002,
            },
        ];
        // One echo between two ships 10 m apart: shown as both (not told apart, so never
        // paired); then 170–180 m off both (outside the gates, inside the wide ones): held
        // as both for the scans a pair takes to part.
        let mut picture = AisPicture::new(origin, gates);
        let r = scan_ships(&mut picture, origin, 0, true, &[echo(5.0)], &ships);
        assert_eq!(r.merged, both);
        for scan in 1..=gates.scans_to_part + 1 {
            let r = scan_ships(&mut picture, origin, scan, true, &[echo(180.0)], &ships);
            if scan <= gates.scans_to_part {
                assert_eq!(r.merged, both, "scan {scan}");
            } else {
                assert!(r.merged.is_empty(), "{r:?}");
            }
            assert!(r.paired.is_empty(), "{r:?}");
        }
    }
}
