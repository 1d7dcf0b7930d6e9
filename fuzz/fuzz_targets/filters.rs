//! Every filter fed arbitrary numbers (NaN, ±inf, subnormals, huge values, time standing
//! still or going backwards): what validation lets through never produces a non-finite
//! estimate, and the Kalman covariances stay positive definite.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tracker_core::filter::alpha_beta::AlphaBetaGains;
use tracker_core::filter::alpha_beta_gamma_eta::AbgeGains;
use tracker_core::filter::kalman::{KalmanConfig, QModel};
use tracker_core::filter::sswt::SswtConfig;
use tracker_core::filter::{Filter, Interval, Measurement};
use tracker_core::scalar::{Fix, Scalar};

/// Runs `f` over the values as (dt, x, y) triples. Estimates must stay finite always;
/// `check` must hold while every step so far was at most `check_dt_s`.
fn drive<S: Scalar, F: Filter<S>>(
    mut f: F,
    values: &[f64],
    check_dt_s: f64,
    check: impl Fn(&F) -> bool,
) {
    let mut started = false;
    let mut checking = true;
    for chunk in values.chunks_exact(3) {
        let (dt, x, y) = (S::of(chunk[0]), S::of(chunk[1]), S::of(chunk[2]));
        let Ok(z) = Measurement::new([x, y]) else {
            continue;
        };
        if !started {
            f.start(z);
            started = true;
            continue;
        }
        if let Ok(dt) = Interval::new(dt) {
            checking &= dt.seconds().to_f64() <= check_dt_s;
            f.predict(dt);
            f.update(z);
        }
        let e = f.estimate();
        assert!(
            e.position_m
                .iter()
                .chain(&e.velocity_mps)
                .all(|v| v.is_finite()),
            "{} {e:?}",
            core::any::type_name::<F>()
        );
        assert!(
            !checking || check(&f),
            "{} {:?}",
            core::any::type_name::<F>(),
            chunk
        );
    }
}

fuzz_target!(|data: &[u8]| {
    let values: Vec<f64> = data
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
        .collect();
    let ab = AlphaBetaGains::LeastSquares;
    drive::<f32, _>(ab.build().unwrap(), &values, f64::MAX, |_| true);
    drive::<Fix, _>(ab.build().unwrap(), &values, f64::MAX, |_| true);
    let abge = AbgeGains::FadingMemory { xi: 0.3 };
    drive::<f64, _>(abge.build().unwrap(), &values, f64::MAX, |_| true);
    drive::<Fix, _>(abge.build().unwrap(), &values, f64::MAX, |_| true);
    let sswt = SswtConfig {
        window: 4,
        start: AlphaBetaGains::FadingMemory { xi: 0.5 },
    };
    drive::<f32, _>(sswt.build().unwrap(), &values, f64::MAX, |_| true);
    let k = KalmanConfig::new(1.0, QModel::Discrete, 25.0);
    drive::<f32, _>(k.build_cv().unwrap(), &values, 600.0, |f| {
        // Positive semi-definite up to f32 rounding: the discrete white-noise Q is rank one,
        // so after a very long interval P is nearly singular and its determinant is the
        // difference of two nearly equal products.
        let p = f.covariance();
        let (pp, pv, vv) = (f64::from(p.pp), f64::from(p.pv), f64::from(p.vv));
        pp > 0.0 && vv > 0.0 && pp * vv - pv * pv >= -1e-5 * pp * vv
    });
    // The CA filter's covariance spans many orders of magnitude after a long step; in f32
    // it stays positive definite for steps up to half a minute (longer than a track ever
    // coasts in one step; see the README).
    drive::<f32, _>(k.build_ca().unwrap(), &values, 30.0, |f| {
        let p = f.covariance();
        p[(0, 0)] > 0.0 && p[(1, 1)] > 0.0 && p[(2, 2)] > 0.0
    });
});
