//! Real traffic: 84 minutes of the Solent's AIS position reports (Stone Soup's file in
//! `../shared/realdata/ais/`, or where `TRACKER_REALDATA` says) as the truth, for two own
//! ships (234586000 leaving Portsmouth, 370869000 arriving from the east): the others seen
//! by the radar model and heard on AIS (sent as AIVDM, read back by the product's decoder),
//! tracked and paired. A table is printed; asserted, for each own ship: every AIS sentence
//! decoded; at most 0.5 % of pair-scans wrong (measured 0.08 % and 0.15 %: ships moored side
//! by side heard one at a time, and radar tracks swapped to a ship passing their own); at
//! most 1 % on a track that follows no ship (coasting tracks of ships whose truth ended); at
//! most 5 % of the scans a radar target is shown as an AIS target on another ship (3.2 % and
//! 1.1 %), and at most 0.15 % of ship-scans hidden (a ship with no AIS target held whose
//! radar target is shown as another's AIS target: 45 and 3, 0.11 % and 0.02 %); at most 2 %
//! of the ship-scans with a track and AIS shown twice (a track drawn apart while the ship's
//! AIS target is held: 0.45 % and 0.62 %, 183 and 99 ship-scans); at least 95 % of the ships
//! with a track and AIS associated (paired, or shown as their AIS target) within 60 s of
//! their track and on average within 45 s (measured 2.5 s and 0 s, 0.4 s and 3.4 s on
//! average), and 90 % paired at some time. (Seed 1, measured on 2026-12-05, since the
//! vessels are placed about own ship along WGS84 geodesics; docs/ais.md has the figures over
//! seeds 1–3.)

use tracker_core::filter::FilterKind;
use tracker_core::sim::ScenarioKind;
use tracker_host::app::demo::{self, DemoOptions};
use tracker_host::link::{Client, InprocTransport};
use tracker_host::source::ais_truth::AisTruthOptions;

mod realdata;

#[test]
fn real_traffic_is_tracked_and_paired_with_its_ais() {
    let path = realdata::file("ais/stonesoup-SolentAIS_20160112_130211.csv");
    println!("| own ship | scans | targets confirmed | false tracks | swaps | RMS m, m/s | pair-scans right / wrong / no ship | ships paired (within 15 s) | time to pair mean, 95 %, max s | ship-scans shown twice |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    use tracker_host::session::ais::AssociatedData;
    use tracker_host::source::ais_truth::{MAX_GAP_S, MOORED_GAP_S};
    // The last run shows associated ships with their radar tracks' data: the AIS data are
    // made from the very reports the truth is, so the radar's own motion and alarms are
    // held to their bounds there.
    let runs = [
        (234_586_000, MAX_GAP_S, AssociatedData::Ais),
        (370_869_000, MAX_GAP_S, AssociatedData::Ais),
        (234_586_000, MOORED_GAP_S, AssociatedData::Ais),
        (370_869_000, MOORED_GAP_S, AssociatedData::Ais),
        (234_586_000, MAX_GAP_S, AssociatedData::Radar),
    ];
    for (own_mmsi, still_gap_s, data) in runs {
        let options = DemoOptions {
            ais_truth: Some(AisTruthOptions {
                path: path.clone(),
                own_mmsi,
                start_s: None,
                duration_s: None,
                seed: 1,
                still_gap_s,
            }),
            ..DemoOptions::new(ScenarioKind::OpenSea, 0, 1, 0.0, FilterKind::KalmanCv)
        };
        let mut options = options;
        options.outputs.associated_data = data;
        let mut d = demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
        while d.step().unwrap().is_some() {}
        let report = d.report("inproc");
        let s = report.scores.expect("scored");
        let p = s.pairing.clone().expect("pairing scored");
        let ais = report.ais.expect("AIS heard");
        println!(
            "| {own_mmsi}{} | {} | {} of {} | {} | {} | {:.1}, {:.2} | {} / {} / {} | {} of {} ({}) | {:.0}, {}, {:.0} | {} ({} late) |",
            if still_gap_s > MAX_GAP_S {
                " (moored ships in)"
            } else {
                ""
            },
            s.scans,
            s.targets_confirmed,
            s.targets_detected,
            s.false_tracks,
            s.track_swaps,
            s.rms_position_m,
            s.rms_velocity_mps,
            p.pairs_correct,
            p.pairs_wrong,
            p.pairs_unverified,
            p.ships_paired,
            p.ships_with_track_and_ais,
            p.ships_paired_in_time,
            p.time_to_pair_mean_s,
            p.time_to_pair_p95_s
                .map_or("not reached".to_string(), |t| format!("{t:.0}")),
            p.time_to_pair_max_s,
            p.ships_unpaired,
            p.ships_unpaired_late
        );
        println!(
            "|   | shown as AIS while pairing: right / wrong / no ship {} / {} / {}, ships hidden {}; associated (paired or shown as AIS) {} of {}, mean {:.0} s, 95 % within {}; pairings {}, partings {} |",
            p.merged_correct,
            p.merged_wrong,
            p.merged_unverified,
            p.ships_hidden,
            p.ships_associated,
            p.ships_with_track_and_ais,
            p.time_to_associate_mean_s,
            p.time_to_associate_p95_s
                .map_or("not reached".to_string(), |t| format!("{t:.0} s")),
            ais.pairing.paired,
            ais.pairing.parted,
        );
        println!(
            "|   | targets in the truth {}; AIS targets taken {}, lost {} |",
            s.targets, ais.table.targets, ais.table.lost
        );
        let m = &s.motion;
        println!("|   | motion shown: {} |", m.line());
        assert!(s.scans > 1000, "{own_mmsi}: {} scans", s.scans);
        assert_eq!(
            ais.sentences.decoded(),
            ais.sentences.sentences,
            "{}",
            ais.sentences
        );
        assert_eq!(ais.sentences.rejected_total(), 0);
        if still_gap_s > MAX_GAP_S {
            // Moored ships (3-minute reports) kept in the truth and sent as moored: the
            // radar sees some 37 more ships, and their AIS targets are held between
            // reports, not lost and taken again at every one (955 and 779 lost without).
            assert!(s.targets >= 80, "{own_mmsi}: {} targets", s.targets);
            assert!(ais.table.lost <= 150, "{:?}", ais.table);
            // What holds there too (docs/ais.md has the rest, which does not).
            let pair_scans = p.pairs_correct + p.pairs_wrong;
            assert!(p.pairs_wrong * 200 <= pair_scans, "{p:?}");
            assert!(
                p.ships_associated * 20 >= p.ships_with_track_and_ais * 19,
                "{p:?}"
            );
            continue;
        }
        assert!(
            p.ships_paired * 10 >= p.ships_with_track_and_ais * 9,
            "{p:?}"
        );
        // Shown with the AIS target's data (associated ships), own ship 234586000 / 370869000:
        // moored boats shown moving 3.4 % / 5.4 % of their target-scans; ships under way
        // shown still 0.6 % / 0.8 %; 234586000's alarms not borne out by the truth 7.4 %, on
        // targets standing still 3.1 %, of those due by the truth 8.5 % missed (370869000
        // raises a few and misses none of the 3 due). On the radar tracks' data (the last
        // run, and the default before 2026-12-06): 5.5 %, 3.0 %, 10.6 %, 3.9 %, 12.4 % (6.3 %
        // and 10.9 % shown moving before a target found standing still was associated where
        // it stands; 38 % / 61 % before it was shown still, the CV filter's velocity noise;
        // 14.7 % missed before a relative speed under 0.25 kn was taken as none). Seeds 1–3
        // in docs/ais.md.
        if data == AssociatedData::Ais {
            assert!(m.still_shown_moving * 15 <= m.still_target_scans, "{m:?}");
            assert!(m.moving_shown_still * 50 <= m.moving_target_scans, "{m:?}");
        } else {
            assert!(m.still_shown_moving * 10 <= m.still_target_scans, "{m:?}");
            assert!(m.moving_shown_still * 20 <= m.moving_target_scans, "{m:?}");
        }
        if own_mmsi == 234_586_000 {
            assert!(m.alarms_false_still * 15 <= m.alarm_target_scans, "{m:?}");
            if data == AssociatedData::Ais {
                assert!(m.alarms_false * 100 <= m.alarm_target_scans * 9, "{m:?}");
                assert!(m.alarms_missed * 100 <= m.alarms_due * 11, "{m:?}");
            } else {
                assert!(m.alarms_missed * 100 <= m.alarms_due * 18, "{m:?}");
            }
        }
        let pair_scans = p.pairs_correct + p.pairs_wrong;
        assert!(p.pairs_wrong * 200 <= pair_scans, "{p:?}");
        let all = p.pairs_correct + p.pairs_wrong + p.pairs_unverified;
        assert!(p.pairs_unverified * 100 <= all, "{p:?}");
        let merged = p.merged_correct + p.merged_wrong;
        assert!(p.merged_wrong * 20 <= merged, "{p:?}");
        let ship_scans = p.pairs_correct + p.merged_correct + p.ships_unpaired;
        // Hidden: over seeds 1–6 and both own ships 1–49 ship-scans (at most 0.12 %, with
        // targets placed along geodesics; seed 1 of own ship 234586000 gave 15 before the
        // frame was put on the WGS84 ellipsoid and 46 after, the size of a change of seed:
        // 217 → 227 over the twelve runs, 235 along geodesics).
        assert!(p.ships_hidden * 1000 <= ship_scans * 3 / 2, "{p:?}");
        // Shown twice: 0.45 % / 0.62 % of the ship-scans on seed 1 (208 / 111 ship-scans
        // before a pair was kept through its ship's manoeuvre; 0.66 % / 2.4 % before a radar target
        // shown as an AIS target was held, and shown so just outside the velocity gate).
        assert!(p.ships_unpaired * 50 <= ship_scans, "{p:?}");
        assert!(
            p.ships_associated * 20 >= p.ships_with_track_and_ais * 19,
            "{p:?}"
        );
        // The mean within 45 s; the 95th percentile of 37 ships is the 36th's delay, set by
        // the one or two whose first track fitted last: 2.5–22.5 s over seeds 1–3 since a
        // settled track just outside the velocity gate is shown as its AIS target (2.5–210
        // s before: a moored ship getting under way, its first track 8 m/s off; docs/ais.md).
        // One ship's delay: bounded at 60 s, not at what seed 1 reached.
        assert!(p.time_to_associate_mean_s <= 45.0, "{p:?}");
        assert!(
            p.time_to_associate_p95_s.is_some_and(|t| t <= 60.0),
            "{p:?}"
        );
    }
}

/// Own ship's heading (its simulated gyro, sent as `HDT`) is its course while it makes way
/// and held while it is stopped: 234586000 lies moored at first, its fixes centimetres
/// apart, and the course between them pointed anywhere (its `HDT` swung 52–212° on a
/// plotter).
#[test]
fn own_ships_heading_is_held_while_it_is_stopped() {
    use tracker_core::geo::{course_speed, MPS_PER_KNOT};
    use tracker_host::source::ais_truth::{AisTruthSource, MAX_GAP_S, OWN_HEADING_FROM_KN};
    use tracker_host::source::PlotSource;
    let options = AisTruthOptions {
        path: realdata::file("ais/stonesoup-SolentAIS_20160112_130211.csv"),
        own_mmsi: 234_586_000,
        start_s: None,
        duration_s: None,
        seed: 1,
        still_gap_s: MAX_GAP_S,
    };
    let origin = tracker_host::origin::Origin::default();
    let mut source = AisTruthSource::open(&options, &origin).unwrap();
    let (mut stopped, mut under_way) = (0u32, 0u32);
    let mut last: Option<f32> = None;
    while let Some(scan) = source.next_scan().unwrap() {
        let own = scan.own_ship.unwrap();
        let heading = own.heading_rad.unwrap();
        let (course, speed) = course_speed(own.velocity_mps);
        if speed < OWN_HEADING_FROM_KN * MPS_PER_KNOT {
            stopped += 1;
            if let Some(h) = last {
                assert_eq!(heading, h, "scan {}: turned while stopped", scan.radar.scan);
            }
        } else {
            under_way += 1;
            assert_eq!(heading, course, "scan {}", scan.radar.scan);
        }
        last = Some(heading);
    }
    assert!(
        stopped > 100 && under_way > 100,
        "{stopped} stopped, {under_way} under way"
    );
}
