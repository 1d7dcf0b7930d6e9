//! Every tracking filter of tracker-core on the emulated Cortex-M4F (f32 and fixed point):
//! the host's known answers, rerun on the target's FPU and integer unit.
#![no_std]
#![no_main]

use tracker_core::filter::gh::GhFilter;
use tracker_core::filter::gh_fixed_scan::FixedScanGh;
use tracker_core::filter::{Filter, Interval, Measurement};
use tracker_core::scalar::Scalar;
use tracker_firmware as _; // panic handler, HardFault handler, defmt transport

/// Feeds `x(t) = Σ c_i t^i` (same on both axes, north scaled by −0.5) every `dt` seconds
/// for `n` scans; returns the largest position error over the last quarter and the final
/// east velocity.
pub fn track_polynomial<S: Scalar, F: Filter<S>>(
    f: &mut F,
    c: &[f64],
    dt: f64,
    n: usize,
) -> (f64, f64) {
    let eval = |t: f64| c.iter().rev().fold(0.0, |acc, &ci| acc * t + ci);
    let slope = |t: f64| {
        c.iter()
            .enumerate()
            .skip(1)
            .map(|(i, ci)| i as f64 * ci * libm::pow(t, (i - 1) as f64))
            .sum::<f64>()
    };
    let z = |t: f64| Measurement::new([S::of(eval(t)), S::of(-0.5 * eval(t))]);
    let (Ok(first), Ok(step)) = (z(0.0), Interval::new(S::of(dt))) else {
        defmt::panic!("bad test input");
    };
    f.start(first);
    let mut worst = 0.0f64;
    for k in 1..n {
        let t = k as f64 * dt;
        f.predict(step);
        let Ok(m) = z(t) else {
            defmt::panic!("bad measurement")
        };
        f.update(m);
        if k > 3 * n / 4 {
            let e = f.estimate();
            let err = libm::fabs(e.position_m[0].to_f64() - eval(t))
                + libm::fabs(e.position_m[1].to_f64() + 0.5 * eval(t));
            worst = worst.max(err);
        }
    }
    let t = (n - 1) as f64 * dt;
    (worst, f.estimate().velocity_mps[0].to_f64() - slope(t))
}

/// 10⁵ updates of a Kalman filter on a random target with random intervals and coasting;
/// `check` must hold every 97 updates. Returns the number of checks.
pub fn soak<F: Filter<f32>>(mut f: F, check: impl Fn(&F) -> bool) -> u32 {
    use rand::RngExt;
    use rand_core::SeedableRng;
    let mut rng = rand_pcg::Pcg32::seed_from_u64(7);
    let (mut p, mut v) = ([1000.0f32, -2000.0], [5.0f32, -3.0]);
    let Ok(first) = Measurement::new(p) else {
        defmt::panic!("bad start")
    };
    f.start(first);
    let mut checks = 0;
    for k in 0..100_000u32 {
        if k % 1000 == 0 {
            v = [rng.random_range(-15.0..15.0), rng.random_range(-15.0..15.0)];
        }
        let dt: f32 = rng.random_range(0.5..5.0);
        p = [p[0] + v[0] * dt, p[1] + v[1] * dt];
        let Ok(step) = Interval::new(dt) else {
            defmt::panic!("bad interval")
        };
        f.predict(step);
        if rng.random::<f32>() < 0.9 {
            let z = [
                p[0] + rng.random_range(-50.0..50.0),
                p[1] + rng.random_range(-50.0..50.0),
            ];
            let Ok(m) = Measurement::new(z) else {
                defmt::panic!("bad measurement")
            };
            f.update(m);
        }
        // Keep the numbers at radar scale: restart far out.
        if p[0].abs() > 50_000.0 || p[1].abs() > 50_000.0 {
            p = [0.0, 0.0];
            let Ok(m) = Measurement::new(p) else {
                defmt::panic!("bad restart")
            };
            f.start(m);
        }
        if k % 97 == 0 {
            let e = f.estimate();
            defmt::assert!(e
                .position_m
                .iter()
                .chain(&e.velocity_mps)
                .all(|x| x.is_finite()));
            defmt::assert!(check(&f), "covariance lost definiteness at update {}", k);
            checks += 1;
        }
    }
    checks
}

/// Runs a general g-h filter and its fixed-scan form side by side for `n` scans of a turning
/// target (every fifth scan without a plot, a longer interval every 37th), predicting the
/// fixed-scan one only when the interval changes, as the track table does. True when every
/// prediction and estimate has the same bits.
pub fn fixed_scan_matches<S: Scalar, const N: usize>(general: GhFilter<S, N>, n: usize) -> bool {
    let Some(mut f) = FixedScanGh::from_filter(&general) else {
        return false;
    };
    let mut g = general;
    let bits = |v: [S; 2]| v.map(|x| x.to_f64().to_bits());
    let z = |t: f64| {
        let east = 3000.0 + 7.0 * t + 300.0 * libm::sin(t / 60.0);
        Measurement::new([S::of(east), S::of(-500.0 - 4.0 * t)])
    };
    let Ok(first) = z(0.0) else { return false };
    g.start(first);
    f.start(first);
    let (mut t, mut held) = (0.0, false);
    for k in 0..n {
        let dt_s = if k % 37 == 36 { 3.0 } else { 2.5 };
        t += dt_s;
        let (Ok(dt), Ok(plot)) = (Interval::new(S::of(dt_s)), z(t)) else {
            return false;
        };
        let pg = g.predict(dt);
        let pf = if held && dt.seconds() == f.interval() {
            f.prediction()
        } else {
            f.predict(dt)
        };
        if k % 5 == 4 {
            f.coast();
        } else {
            g.update(plot);
            f.update(plot);
        }
        held = true;
        let (eg, ef) = (g.estimate(), f.estimate());
        let same = bits(pg) == bits(pf)
            && bits(eg.position_m) == bits(ef.position_m)
            && bits(eg.velocity_mps) == bits(ef.velocity_mps);
        if !same {
            return false;
        }
    }
    true
}

#[defmt_test::tests]
mod tests {
    use super::{fixed_scan_matches, track_polynomial};
    use tracker_core::filter::alpha_beta::AlphaBetaGains;
    use tracker_core::filter::alpha_beta_gamma::AbgGains;
    use tracker_core::filter::alpha_beta_gamma_eta::AbgeGains;
    use tracker_core::filter::kalman::{KalmanConfig, QModel};
    use tracker_core::filter::sswt::SswtConfig;
    use tracker_core::filter::{Filter, Interval, Measurement};
    use tracker_core::scalar::Fix;

    #[test]
    fn alpha_beta_follows_constant_velocity() {
        let design = AlphaBetaGains::FadingMemory { xi: 0.7 };
        let (e, v) = track_polynomial::<f32, _>(
            &mut design.build::<f32>().unwrap(),
            &[1000.0, 6.0],
            3.0,
            200,
        );
        defmt::assert!(e < 0.05 && libm::fabs(v) < 1e-3, "f32 {} {}", e, v);
        let (e, v) = track_polynomial::<Fix, _>(
            &mut design.build::<Fix>().unwrap(),
            &[1000.0, 6.0],
            3.0,
            200,
        );
        defmt::assert!(e < 0.01 && libm::fabs(v) < 1e-3, "fixed {} {}", e, v);
    }

    #[test]
    fn alpha_beta_gamma_follows_constant_acceleration() {
        let design = AbgGains::FadingMemory { xi: 0.8 };
        let c = [-2000.0, 4.0, 0.05];
        let (e, v) = track_polynomial::<f32, _>(&mut design.build::<f32>().unwrap(), &c, 2.5, 300);
        defmt::assert!(e < 0.5 && libm::fabs(v) < 0.01, "f32 {} {}", e, v);
        let (e, v) = track_polynomial::<Fix, _>(&mut design.build::<Fix>().unwrap(), &c, 2.5, 300);
        defmt::assert!(e < 0.05 && libm::fabs(v) < 0.01, "fixed {} {}", e, v);
    }

    #[test]
    fn alpha_beta_gamma_eta_follows_constant_jerk() {
        let design = AbgeGains::FadingMemory { xi: 0.7 };
        let c = [500.0, 3.0, 0.02, 0.0005];
        let (e, v) = track_polynomial::<f32, _>(&mut design.build::<f32>().unwrap(), &c, 2.0, 250);
        defmt::assert!(e < 1.0 && libm::fabs(v) < 0.05, "f32 {} {}", e, v);
        let (e, v) = track_polynomial::<Fix, _>(&mut design.build::<Fix>().unwrap(), &c, 2.0, 250);
        defmt::assert!(e < 0.1 && libm::fabs(v) < 0.05, "fixed {} {}", e, v);
    }

    #[test]
    fn the_fixed_scan_form_is_the_general_filter_bit_for_bit() {
        let ab = AlphaBetaGains::BenedictBordner { alpha: 0.5 };
        let abg = AbgGains::FadingMemory { xi: 0.6 };
        let abge = AbgeGains::FadingMemory { xi: 0.7 };
        defmt::assert!(fixed_scan_matches(ab.build::<f32>().unwrap(), 500));
        defmt::assert!(fixed_scan_matches(ab.build::<Fix>().unwrap(), 500));
        defmt::assert!(fixed_scan_matches(abg.build::<f32>().unwrap(), 500));
        defmt::assert!(fixed_scan_matches(abg.build::<Fix>().unwrap(), 500));
        defmt::assert!(fixed_scan_matches(abge.build::<f32>().unwrap(), 500));
        defmt::assert!(fixed_scan_matches(abge.build::<Fix>().unwrap(), 500));
    }

    #[test]
    fn sswt_follows_a_straight_track() {
        let cfg = SswtConfig {
            window: 4,
            start: AlphaBetaGains::BenedictBordner { alpha: 0.6 },
        };
        let (e, v) =
            track_polynomial::<f32, _>(&mut cfg.build::<f32>().unwrap(), &[300.0, -9.0], 3.0, 150);
        defmt::assert!(e < 0.05 && libm::fabs(v) < 1e-3, "f32 {} {}", e, v);
        let (e, v) =
            track_polynomial::<Fix, _>(&mut cfg.build::<Fix>().unwrap(), &[300.0, -9.0], 3.0, 150);
        defmt::assert!(e < 0.01 && libm::fabs(v) < 1e-3, "fixed {} {}", e, v);
    }

    #[test]
    fn kalman_cv_reaches_kalatas_steady_state_gain() {
        let (q, r, dt) = (0.04f32, 225.0f32, 2.5f32);
        let lambda = libm::sqrtf(q) * dt * dt / libm::sqrtf(r);
        let root = libm::sqrtf(lambda * lambda + 8.0 * lambda);
        let alpha = -(lambda * lambda + 8.0 * lambda - (lambda + 4.0) * root) / 8.0;
        let mut f = KalmanConfig::new(q as f64, QModel::Discrete, r as f64)
            .build_cv::<f32>()
            .unwrap();
        let origin = Measurement::new([0.0, 0.0]).unwrap();
        f.start(origin);
        for _ in 0..500 {
            f.predict(Interval::new(dt).unwrap());
            f.update(origin);
        }
        defmt::assert!(
            libm::fabsf(f.gain()[0] - alpha) < 1e-4,
            "{} vs {}",
            f.gain()[0],
            alpha
        );
        let (e, v) = track_polynomial::<f32, _>(&mut f, &[0.0, 5.0], 2.5, 200);
        defmt::assert!(e < 0.05 && libm::fabs(v) < 0.01, "{} {}", e, v);
    }

    #[test]
    fn kalman_filters_survive_a_100k_update_soak() {
        let k = KalmanConfig::new(0.05, QModel::Continuous, 900.0);
        let n = super::soak(k.build_cv::<f32>().unwrap(), |f| {
            let p = f.covariance();
            p.pp > 0.0 && p.vv > 0.0 && p.pp * p.vv - p.pv * p.pv > 0.0
        });
        defmt::assert!(n > 1000);
        super::soak(k.build_ca::<f32>().unwrap(), |f| {
            let p = f.covariance();
            let symmetric = (p - p.transpose()).abs().max() <= 1e-3 * p.abs().max();
            // Leading principal minors positive: Sylvester's test for a 3×3.
            let m1 = p[(0, 0)];
            let m2 = p[(0, 0)] * p[(1, 1)] - p[(0, 1)] * p[(1, 0)];
            symmetric && m1 > 0.0 && m2 > 0.0 && p.determinant() > 0.0
        });
    }

    #[test]
    fn kalman_ca_follows_constant_acceleration() {
        let mut f = KalmanConfig::new(1e-6, QModel::Discrete, 25.0)
            .build_ca::<f32>()
            .unwrap();
        let (e, v) = track_polynomial::<f32, _>(&mut f, &[10.0, 2.0, 0.05], 2.0, 300);
        defmt::assert!(e < 1.0 && libm::fabs(v) < 0.05, "{} {}", e, v);
        let p = f.covariance();
        defmt::assert!(p[(0, 0)] > 0.0 && p[(1, 1)] > 0.0 && p[(2, 2)] > 0.0);
    }
}
