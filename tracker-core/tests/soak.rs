//! Numerical soak: 10⁷ updates of each Kalman-family filter in f32 on random scenarios (random
//! scan intervals, noise levels, manoeuvres, coasting), checking all along that the
//! covariance stays symmetric positive definite (Cholesky) and the estimates finite.

use rand::RngExt;
use rand_core::SeedableRng;
use rand_pcg::Pcg32;
use tracker_core::filter::kalman::{KalmanConfig, QModel};
use tracker_core::filter::{Filter, Interval, Measurement};

const UPDATES: u64 = 10_000_000;
/// A new random scenario every this many updates.
const LEG: u64 = 10_000;

/// A random scenario's parameters and a target to follow.
struct Leg {
    config: KalmanConfig,
    position: [f32; 2],
    velocity: [f32; 2],
    noise: f32,
}

fn leg(rng: &mut Pcg32) -> Leg {
    let q_model = [QModel::Identity, QModel::Discrete, QModel::Continuous][rng.random_range(0..3)];
    let noise = 10f32.powf(rng.random_range(0.0..2.5));
    Leg {
        config: KalmanConfig::new(
            10f64.powf(rng.random_range(-4.0..1.0)),
            q_model,
            f64::from(noise * noise),
        ),
        position: [
            rng.random_range(-20_000.0..20_000.0),
            rng.random_range(-20_000.0..20_000.0),
        ],
        velocity: [rng.random_range(-15.0..15.0), rng.random_range(-15.0..15.0)],
        noise,
    }
}

fn soak<F: Filter<f32>>(
    build: impl Fn(&KalmanConfig) -> F,
    check: impl Fn(&F) -> Result<(), String>,
) {
    let mut rng = Pcg32::seed_from_u64(2026);
    let mut done = 0u64;
    while done < UPDATES {
        let mut l = leg(&mut rng);
        let mut f = build(&l.config);
        f.start(Measurement::new(l.position).unwrap());
        for k in 0..LEG {
            let dt: f32 = rng.random_range(0.5..5.0);
            if rng.random::<f32>() < 0.01 {
                // A manoeuvre: the velocity jumps.
                l.velocity = [rng.random_range(-15.0..15.0), rng.random_range(-15.0..15.0)];
            }
            l.position[0] += l.velocity[0] * dt;
            l.position[1] += l.velocity[1] * dt;
            f.predict(Interval::new(dt).unwrap());
            // One scan in ten the target is missed and the track coasts.
            if rng.random::<f32>() < 0.9 {
                let z = [
                    l.position[0] + l.noise * (rng.random::<f32>() - 0.5) * 3.46,
                    l.position[1] + l.noise * (rng.random::<f32>() - 0.5) * 3.46,
                ];
                f.update(Measurement::new(z).unwrap());
            }
            let e = f.estimate();
            let finite = e
                .position_m
                .iter()
                .chain(&e.velocity_mps)
                .all(|v| v.is_finite());
            assert!(finite, "update {}: {e:?}", done + k);
            if k % 97 == 0 {
                check(&f).unwrap_or_else(|why| panic!("update {}: {why}", done + k));
            }
        }
        done += LEG;
    }
}

#[test]
fn cv_kalman_stays_positive_definite_over_ten_million_updates() {
    soak(
        |c| c.build_cv::<f32>().unwrap(),
        |f| {
            let p = f.covariance();
            let det = f64::from(p.pp) * f64::from(p.vv) - f64::from(p.pv) * f64::from(p.pv);
            if p.pp > 0.0 && p.vv > 0.0 && det > 0.0 {
                Ok(())
            } else {
                Err(format!("not positive definite: {p:?}"))
            }
        },
    );
}

#[test]
fn ca_kalman_stays_symmetric_positive_definite_over_ten_million_updates() {
    soak(
        |c| c.build_ca::<f32>().unwrap(),
        |f| {
            let p = f.covariance();
            let asym = (p - p.transpose()).abs().max();
            if asym > 1e-3 * p.abs().max() {
                return Err(format!("not symmetric ({asym}): {p}"));
            }
            let p64 = p.map(f64::from);
            match p64.cholesky() {
                Some(_) => Ok(()),
                None => Err(format!("Cholesky fails: {p}")),
            }
        },
    );
}
