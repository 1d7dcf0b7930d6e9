//! A device that answers with valid frames carrying what cannot be right: track states with
//! NaN, infinities and 3e38; a gate report in 255 parts of 16 gates; a report in 0 parts.
//! The host validates everything that crosses the link: nothing of it reaches the targets,
//! the display or the plotter, every such scan is skipped with a reason, association stays
//! bounded by what was sent, and the run goes on.

use std::collections::VecDeque;
use std::io;
use std::time::Duration;

use tracker_core::filter::FilterKind;
use tracker_core::frame::{self, FrameDecoder};
use tracker_core::icd::{
    DeviceInfo, DeviceToHost, GatedBatch, GatedPlots, Header, HostToDevice, TrackBatch, TrackState,
    TrackStatus, MAX_ENCODED_FRAME_BYTES, MAX_FRAME_BYTES, PROTOCOL_VERSION,
};
use tracker_core::sim::ScenarioKind;
use tracker_host::app::demo::{self, DemoOptions};
use tracker_host::link::{Client, Transport};

#[derive(Clone, Copy, Debug, PartialEq)]
enum Mischief {
    /// Track states with NaN, infinity and 3e38.
    BadNumbers,
    /// A gate report of 255 parts, 16 gates each, every one gating plots 0–7.
    HugeGates,
    /// A track report in 0 parts.
    NoParts,
}

/// A fake device: handshakes and acknowledges like a real one, answers plots and
/// assignments with `mischief`.
struct Hostile {
    mischief: Mischief,
    decoder: FrameDecoder,
    outbox: VecDeque<u8>,
}

impl Hostile {
    fn new(mischief: Mischief) -> Self {
        Hostile {
            mischief,
            decoder: FrameDecoder::new(),
            outbox: VecDeque::new(),
        }
    }

    fn reply(&mut self, id: u32, body: &DeviceToHost) {
        let header = Header {
            protocol: PROTOCOL_VERSION,
            request_id: id,
        };
        let mut scratch = vec![0u8; MAX_FRAME_BYTES];
        let mut out = vec![0u8; MAX_ENCODED_FRAME_BYTES];
        let n = frame::encode(&header, body, &mut scratch, &mut out).unwrap();
        self.outbox.extend(&out[..n]);
    }

    fn bad_track(n: u16, value: f32) -> TrackState {
        TrackState {
            track: n,
            status: TrackStatus::Confirmed,
            position_m: [value, 1000.0],
            velocity_mps: [1.0, value],
            age_scans: 10,
            hit_history: 0x3ff,
        }
    }

    fn handle(&mut self, id: u32, request: HostToDevice) {
        match request {
            HostToDevice::Hello => self.reply(
                id,
                &DeviceToHost::HelloAck(DeviceInfo {
                    protocol: PROTOCOL_VERSION,
                    firmware: heapless::String::try_from("hostile").unwrap(),
                    max_frame_bytes: MAX_FRAME_BYTES as u16,
                    max_tracks: 64,
                    max_plots_per_scan: 256,
                    boot_id: 7,
                }),
            ),
            HostToDevice::Plots(batch) if batch.part + 1 == batch.parts => {
                if self.mischief == Mischief::HugeGates {
                    for part in 0..255u8 {
                        let gates = (0..16u16)
                            .map(|i| GatedPlots {
                                track: u16::from(part) * 16 + i,
                                predicted_m: [0.0, 1000.0],
                                innovation_cov_m2: [100.0, 0.0, 100.0],
                                plots: (0..8u16).collect(),
                            })
                            .collect();
                        self.reply(
                            id,
                            &DeviceToHost::Gated(GatedBatch {
                                scan: batch.scan,
                                part,
                                parts: 255,
                                gates,
                            }),
                        );
                    }
                } else {
                    self.reply(
                        id,
                        &DeviceToHost::Gated(GatedBatch {
                            scan: batch.scan,
                            part: 0,
                            parts: 1,
                            gates: heapless::Vec::new(),
                        }),
                    );
                }
            }
            HostToDevice::Assign(batch) => {
                let tracks = [
                    Self::bad_track(1, f32::NAN),
                    Self::bad_track(2, f32::INFINITY),
                    Self::bad_track(3, 3e38),
                ];
                let parts = if self.mischief == Mischief::NoParts {
                    0
                } else {
                    1
                };
                self.reply(
                    id,
                    &DeviceToHost::Tracks(TrackBatch {
                        scan: batch.scan,
                        part: 0,
                        parts,
                        tracks: tracks.into_iter().collect(),
                    }),
                );
            }
            _ => self.reply(id, &DeviceToHost::Ack),
        }
    }
}

impl Transport for Hostile {
    fn write_all(&mut self, bytes: &[u8]) -> io::Result<()> {
        for &b in bytes {
            if let Some(Ok(payload)) = self.decoder.push(b) {
                if let Ok((h, req)) = frame::decode_payload::<HostToDevice>(payload, u32::MAX) {
                    self.handle(h.request_id, req);
                }
            }
        }
        Ok(())
    }

    fn read(&mut self, buf: &mut [u8], _timeout: Duration) -> io::Result<usize> {
        let n = buf.len().min(self.outbox.len());
        for (d, s) in buf.iter_mut().zip(self.outbox.drain(..n)) {
            *d = s;
        }
        Ok(n)
    }
}

#[test]
fn nonsense_from_the_device_is_not_believed_and_the_run_goes_on() {
    for mischief in [Mischief::BadNumbers, Mischief::HugeGates, Mischief::NoParts] {
        let mut client = Client::new(Box::new(Hostile::new(mischief)));
        client.timeout = Duration::from_millis(50);
        client.retries = 2;
        let options = DemoOptions::new(ScenarioKind::OpenSea, 20, 3, 25.0, FilterKind::KalmanCv);
        let mut run = demo::start(client, &options).unwrap();
        let mut scans = 0;
        while let Some(report) = run.step().expect("the run goes on") {
            scans += 1;
            assert!(
                report.skipped.is_some(),
                "{mischief:?}: scan {} believed",
                report.scan
            );
            assert!(report.targets.is_empty() && report.tracks.is_empty());
            assert!(report.association.assignments.is_empty());
        }
        assert_eq!(scans, 10, "{mischief:?}");
        assert_eq!(run.session().scans_skipped(), 10);
        let events = run.session().events();
        assert!(events.iter().any(|e| e.contains("skipped")), "{events:?}");
    }
}
