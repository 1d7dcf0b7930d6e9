//! Any bytes as a replay input: the CSV reader refuses bad input with an error, and what it
//! accepts runs through every filter in every scalar without a panic and with finite output.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tracker_core::filter::alpha_beta::AlphaBetaGains;
use tracker_core::filter::alpha_beta_gamma::AbgGains;
use tracker_core::filter::kalman::{KalmanConfig, QModel};
use tracker_core::filter::sswt::SswtConfig;
use tracker_core::filter::FilterConfig as FilterSpec;
use tracker_host::lab::replay::{parse_measurements, run, ScalarKind};

fuzz_target!(|data: &[u8]| {
    let Ok(input) = parse_measurements(data, "fuzz") else {
        return;
    };
    let specs = [
        FilterSpec::AlphaBeta(AlphaBetaGains::LeastSquares),
        FilterSpec::AlphaBetaGamma(AbgGains::FadingMemory { xi: 0.5 }),
        FilterSpec::Sswt(SswtConfig {
            window: 3,
            start: AlphaBetaGains::BenedictBordner { alpha: 0.5 },
        }),
        FilterSpec::KalmanCv(KalmanConfig::new(0.1, QModel::Continuous, 100.0)),
    ];
    for spec in &specs {
        for scalar in [ScalarKind::F64, ScalarKind::F32, ScalarKind::Fixed] {
            if let Ok(rows) = run(spec, scalar, &input) {
                for r in rows {
                    assert!(
                        [r.x, r.y, r.vx, r.vy, r.px, r.py]
                            .iter()
                            .all(|v| v.is_finite()),
                        "{spec:?} {scalar:?} {r:?}"
                    );
                }
            }
        }
    }
});
