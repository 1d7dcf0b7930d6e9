use tracker_core::filter::FilterKind;
use tracker_host::app::track::{self, TrackInput, TrackOptions};
use tracker_host::app::{Outputs, OwnShipOptions};
use tracker_host::link::{Client, InprocTransport};
use tracker_host::radar::RadarSpec;
use tracker_host::source::radar::RadarOptions;

#[test]
fn probe() {
    let name = "radar_pi-garmin_xhd.pcap.gz";
    let mut radar = RadarOptions::new(RadarSpec::Capture(
        format!("/work/shared/realdata/radar/{name}").into(),
    ));
    radar.fixed_heading_rad = Some(0.0);
    let options = TrackOptions {
        input: TrackInput::Radar(radar),
        filter: FilterKind::KalmanCv,
        association: Default::default(),
        own_ship: OwnShipOptions::default(),
        outputs: Outputs::default(),
    };
    let mut run = track::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
    let mut reports = vec![];
    while let Some(r) = run.step().unwrap() {
        reports.push(r);
    }
    let mut shown = std::collections::BTreeSet::new();
    let mut n = 0;
    for r in &reports {
        for t in &r.targets {
            if t.rel_speed_mps > 2.57 && shown.insert(t.track) && n < 6 {
                n += 1;
                println!(
                    "== T{} first shown fast at scan {} ({:.1} kn)",
                    t.track,
                    r.scan,
                    t.rel_speed_mps / 0.5144
                );
                for q in &reports {
                    if let Some(k) = q.tracks.iter().find(|k| k.track == t.track) {
                        let took = q
                            .association
                            .assignments
                            .iter()
                            .find(|a| a.track == k.track)
                            .and_then(|a| a.plot);
                        let near: Vec<String> = q
                            .plots_m
                            .iter()
                            .enumerate()
                            .filter(|(_, p)| {
                                (p[0] - k.position_m[0]).hypot(p[1] - k.position_m[1]) < 250.0
                            })
                            .map(|(i, p)| {
                                format!(
                                    "p{i}({:.0},{:.0})",
                                    p[0] - k.position_m[0],
                                    p[1] - k.position_m[1]
                                )
                            })
                            .collect();
                        println!("  scan {} {:?} age {} hits {:06b} at ({:.0},{:.0}) v ({:.1},{:.1}) took {:?} | {}", q.scan, k.status, k.age_scans, k.hit_history & 63, k.position_m[0], k.position_m[1], k.velocity_mps[0], k.velocity_mps[1], took, near.join(" "));
                    }
                }
            }
        }
    }
}
