//! Host throughput of plot extraction on real spokes: the Navico HALO capture's spokes
//! (`../shared/realdata/radar/mayara-halo_and_0183.pcap`, 25 km, 1,024 4-bit samples; or
//! where `TRACKER_REALDATA` says) decoded once into memory, then pushed through the
//! extractor with the Navico defaults, a rotation (2,048 spokes) per iteration. Criterion
//! prints the time per rotation and spokes per second; a HALO sends 1,024 spokes a second
//! (2,048 per 2 s rotation), and the line after says how many times real time that is.
//! Run with `cargo bench -p tracker-host --bench extract`.

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Instant;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use tracker_core::radar::{Extractor, ExtractorConfig, Spoke};
use tracker_host::radar::{RadarSpec, SpokeSource};

/// Spokes a second from a HALO (2,048 a 2.0 s rotation).
const HALO_SPOKES_PER_S: f64 = 1024.0;

struct Owned {
    angle: u16,
    heading_rad: Option<f32>,
    range_m: f32,
    time_ms: u64,
    samples: Vec<u8>,
}

fn spokes() -> Vec<Owned> {
    let dir = std::env::var_os("TRACKER_REALDATA").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/realdata"),
        PathBuf::from,
    );
    let path = dir.join("radar/mayara-halo_and_0183.pcap");
    let mut source = SpokeSource::open(&RadarSpec::Capture(path)).expect("the HALO capture");
    let mut out = Vec::new();
    while let Some((s, _)) = source.next_spoke().expect("readable") {
        out.push(Owned {
            angle: s.angle,
            heading_rad: s.heading_rad,
            range_m: s.range_m,
            time_ms: s.time_ms,
            samples: s.samples.to_vec(),
        });
    }
    out
}

fn bench(c: &mut Criterion) {
    let spokes = spokes();
    let rotation = 2048.min(spokes.len());
    let mut x: Extractor = Extractor::new(ExtractorConfig::navico_4bit()).expect("defaults");
    let mut at = 0usize;
    let mut push_rotation = |x: &mut Extractor| {
        let mut plots = 0u32;
        for _ in 0..rotation {
            let o = &spokes[at % spokes.len()];
            at += 1;
            let s = Spoke {
                angle: o.angle,
                spokes_per_rotation: 2048,
                north_up: false,
                heading_rad: o.heading_rad,
                range_m: o.range_m,
                time_ms: o.time_ms,
                samples: &o.samples,
                max_sample: 15,
            };
            x.push(black_box(&s), |_| plots += 1);
        }
        plots
    };
    let mut group = c.benchmark_group("extract");
    group.throughput(Throughput::Elements(rotation as u64));
    group.bench_function("halo-rotation-2048-spokes", |b| {
        b.iter(|| push_rotation(&mut x))
    });
    group.finish();
    // One more measured pass for the line a navigator reads.
    let start = Instant::now();
    let rotations = 20;
    for _ in 0..rotations {
        push_rotation(&mut x);
    }
    let per_s = (rotations * rotation) as f64 / start.elapsed().as_secs_f64();
    println!(
        "extraction: {per_s:.0} spokes/s on this machine, {:.0} times a HALO's {HALO_SPOKES_PER_S} spokes/s",
        per_s / HALO_SPOKES_PER_S
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
