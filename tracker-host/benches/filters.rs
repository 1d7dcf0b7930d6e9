//! Host throughput of every filter: one scan (predict + update) on a noisy straight track.
//! Run with `cargo bench -p tracker-host --bench filters`; criterion prints time per scan,
//! updates per second = 1 / that.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use tracker_core::filter::alpha_beta::AlphaBetaGains;
use tracker_core::filter::alpha_beta_gamma::AbgGains;
use tracker_core::filter::alpha_beta_gamma_eta::AbgeGains;
use tracker_core::filter::kalman::{KalmanConfig, QModel};
use tracker_core::filter::sswt::SswtConfig;
use tracker_core::filter::{Filter, Interval, Measurement};
use tracker_core::scalar::{Fix, Scalar};

fn bench_filter<S: Scalar, F: Filter<S>>(c: &mut Criterion, name: &str, mut f: F) {
    let plots: Vec<Measurement<S>> = (0..64)
        .map(|i| {
            let t = i as f64 * 2.5;
            let jitter = ((i * 37) % 11) as f64 - 5.0;
            Measurement::new([
                S::of(100.0 + 7.0 * t + jitter),
                S::of(-50.0 + 2.0 * t - jitter),
            ])
            .expect("finite")
        })
        .collect();
    let dt = Interval::new(S::of(2.5)).expect("positive");
    f.start(plots[0]);
    let mut group = c.benchmark_group("scan");
    group.throughput(Throughput::Elements(1));
    let mut i = 0;
    group.bench_function(format!("{name}/{}", S::NAME), |b| {
        b.iter(|| {
            i = (i + 1) % plots.len();
            let f = black_box(&mut f);
            f.predict(black_box(dt));
            f.update(black_box(plots[i]))
        })
    });
    group.finish();
}

fn gh_family<S: Scalar>(c: &mut Criterion) {
    bench_filter::<S, _>(
        c,
        "alpha-beta",
        AlphaBetaGains::BenedictBordner { alpha: 0.5 }
            .build()
            .unwrap(),
    );
    bench_filter::<S, _>(
        c,
        "alpha-beta-gamma",
        AbgGains::FadingMemory { xi: 0.9 }.build().unwrap(),
    );
    bench_filter::<S, _>(
        c,
        "alpha-beta-gamma-eta",
        AbgeGains::FadingMemory { xi: 0.9 }.build().unwrap(),
    );
    let sswt = SswtConfig {
        window: 4,
        start: AlphaBetaGains::BenedictBordner { alpha: 0.5 },
    };
    bench_filter::<S, _>(c, "sswt", sswt.build().unwrap());
}

fn all(c: &mut Criterion) {
    gh_family::<f64>(c);
    gh_family::<f32>(c);
    gh_family::<Fix>(c);
    let k = KalmanConfig::new(0.1, QModel::Continuous, 100.0);
    bench_filter::<f64, _>(c, "kalman-cv", k.build_cv().unwrap());
    bench_filter::<f32, _>(c, "kalman-cv", k.build_cv().unwrap());
    bench_filter::<f64, _>(c, "kalman-ca", k.build_ca().unwrap());
    bench_filter::<f32, _>(c, "kalman-ca", k.build_ca().unwrap());
}

criterion_group!(benches, all);
criterion_main!(benches);
