//! A boat moored 60 m from another casts off. While moored its target is found standing
//! still and associated at where it stands (`session/stationary.rs`); as it moves off, its
//! plots leave the gate about that place scans before the stationary test finds it moving,
//! and are tested from the device's prediction. Its track follows it out: it is not left
//! behind at the mooring with the boat acquired anew (a first version, on where it stood
//! alone, followed it on 13 of the 129 scans after casting off with plots of 3 m, seed 0).

use tracker_core::filter::FilterKind;
use tracker_core::geo;
use tracker_core::icd::Plot;
use tracker_host::lab::noise::normal;
use tracker_host::link::{Client, InprocTransport};
use tracker_host::own_ship::OwnShip;
use tracker_host::session::{Session, SessionConfig};
use tracker_host::source::RadarScan;

const PERIOD_S: f64 = 2.5;
/// Moored for 3 minutes: found standing still after about one.
const CAST_OFF_S: f64 = 180.0;
const ACCELERATION_MPS2: f64 = 0.1;
const TOP_SPEED_MPS: f64 = 5.0;
const MOORING_M: [f64; 2] = [1500.0, 1500.0];
/// The neighbour, moored 60 m north of the boat.
const NEIGHBOUR_M: [f64; 2] = [1500.0, 1560.0];
const P_DETECTION: f64 = 0.9;

/// The plot of an echo at `at`, m (east, north), from own ship at the origin.
fn plot(at: [f64; 2]) -> Plot {
    let (range_m, bearing_rad) = geo::range_bearing([0.0; 2], at.map(|v| v as f32));
    Plot {
        range_m,
        bearing_rad,
    }
}

/// The boat at `time_s`: moored, then east at 0.1 m/s² up to 5 m/s.
fn boat(time_s: f64) -> [f64; 2] {
    let t = (time_s - CAST_OFF_S).max(0.0);
    let t_top = TOP_SPEED_MPS / ACCELERATION_MPS2;
    let east = if t < t_top {
        0.5 * ACCELERATION_MPS2 * t * t
    } else {
        0.5 * ACCELERATION_MPS2 * t_top * t_top + TOP_SPEED_MPS * (t - t_top)
    };
    [MOORING_M[0] + east, MOORING_M[1]]
}

/// One run of 200 scans (about 5 minutes after casting off), plots `sigma_m` a side:
/// (scans after casting off on which the track that followed the boat moored is within
/// 4σ + 10 m of it, scans after casting off, firm tracks in all, whether the boat was
/// shown standing still on the scan before it cast off).
fn run(sigma_m: f64, seed: u64) -> (u32, u32, usize, bool) {
    let config = SessionConfig::tracking_plots_of(FilterKind::KalmanCv, sigma_m as f32);
    let client = Client::new(Box::new(InprocTransport::new()));
    let mut session = Session::start(client, config).unwrap();
    let mut rng = fastrand::Rng::with_seed(seed);
    let own = OwnShip::at([0.0, 0.0], [0.0, 0.0]);
    let near = |p: [f32; 2], x: [f64; 2], within: f64| {
        (f64::from(p[0]) - x[0]).hypot(f64::from(p[1]) - x[1]) < within
    };
    let (mut boat_track, mut followed, mut after) = (None, 0, 0);
    let mut shown_still = false;
    let mut firm = std::collections::BTreeSet::new();
    for scan in 1..=200u32 {
        let time_s = PERIOD_S * f64::from(scan);
        let at = boat(time_s);
        let mut plots = Vec::new();
        for x in [at, NEIGHBOUR_M] {
            if rng.f64() < P_DETECTION {
                let (e, n) = (sigma_m * normal(&mut rng), sigma_m * normal(&mut rng));
                plots.push(plot([x[0] + e, x[1] + n]));
            }
        }
        let radar = RadarScan {
            scan,
            time_s,
            plots,
        };
        let report = session.scan(&radar, &own).unwrap();
        let tracks: Vec<_> = report
            .tracks
            .iter()
            .filter(|t| t.status.is_firm())
            .collect();
        firm.extend(tracks.iter().map(|t| t.track));
        if time_s < CAST_OFF_S {
            boat_track = tracks
                .iter()
                .find(|t| near(t.position_m, at, 3.0 * sigma_m + 5.0))
                .map(|t| t.track)
                .or(boat_track);
            // Found standing still (so associated where it stands): shown with no motion.
            shown_still = report
                .targets
                .iter()
                .any(|t| Some(t.track) == boat_track && t.speed_mps == 0.0);
            continue;
        }
        after += 1;
        let track = tracks.iter().find(|t| Some(t.track) == boat_track);
        if track.is_some_and(|t| near(t.position_m, at, 4.0 * sigma_m + 10.0)) {
            followed += 1;
        }
    }
    (followed, after, firm.len(), shown_still)
}

#[test]
fn a_boat_casting_off_beside_a_moored_neighbour_is_followed_out() {
    // Plots of 3 m (a harbour radar's at short range) and 10 m; five seeds each.
    for sigma_m in [3.0, 10.0] {
        for seed in 0..5 {
            let (followed, after, firm, shown_still) = run(sigma_m, seed);
            assert!(
                shown_still,
                "σ {sigma_m} m, seed {seed}: not found still moored"
            );
            assert_eq!(
                followed, after,
                "σ {sigma_m} m, seed {seed}: followed on {followed} of {after} scans"
            );
            assert_eq!(firm, 2, "σ {sigma_m} m, seed {seed}: {firm} firm tracks");
        }
    }
}
