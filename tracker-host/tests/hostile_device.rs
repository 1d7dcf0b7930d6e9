//! A device that answers with valid frames carrying what cannot be right: track states
//! 200,000 km out and at 20,000 km/s; records that do not decode, or that are coded against
//! a base the host never held; a gate report in 255 parts of 16 gates; a report that never
//! says it is done. The host validates everything that crosses the link: nothing of it
//! reaches the targets, the display or the plotter, every such scan is skipped with a
//! reason, association stays bounded by what was sent, and the run goes on.

use std::collections::VecDeque;
use std::io;
use std::time::Duration;

use tracker_core::filter::FilterKind;
use tracker_core::frame::{self, FrameDecoder};
use tracker_core::icd::records::{self, GateOnGrid, GateReference, StateOnGrid};
use tracker_core::icd::varint::Writer;
use tracker_core::icd::{
    Bytes, DeviceInfo, DeviceToHost, GatedBatch, Header, HostToDevice, TrackBatch, TrackStatus,
    MAX_ENCODED_FRAME_BYTES, MAX_FRAME_BYTES, MAX_RECORD_BYTES, PROTOCOL_VERSION,
};
use tracker_core::sim::ScenarioKind;
use tracker_host::app::demo::{self, DemoOptions};
use tracker_host::link::{Client, Transport};

#[derive(Clone, Copy, Debug, PartialEq)]
enum Mischief {
    /// Whole track states 200,000 km out and at 20,000 km/s.
    BadNumbers,
    /// State records that do not decode.
    Garbage,
    /// State records coded against a base the host does not hold.
    NoSuchBase,
    /// A gate report of 255 parts, 16 gates each, every one gating plots 0–7.
    HugeGates,
    /// A track report whose one part is not the last.
    NeverDone,
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
        let mut out = vec![0u8; MAX_ENCODED_FRAME_BYTES];
        let n = frame::encode(&header, body, &mut out).unwrap();
        self.outbox.extend(&out[..n]);
    }

    fn handle(&mut self, id: u32, request: HostToDevice) {
        let mut records = [0u8; MAX_RECORD_BYTES];
        match request {
            HostToDevice::Hello => self.reply(
                id,
                &DeviceToHost::HelloAck(DeviceInfo {
                    protocol: PROTOCOL_VERSION,
                    firmware: "hostile",
                    max_frame_bytes: MAX_FRAME_BYTES as u16,
                    max_tracks: tracker_core::track::MAX_TRACKS as u16,
                    max_plots_per_scan: 256,
                    boot_id: 7,
                }),
            ),
            HostToDevice::Plots(batch) if batch.part + 1 == batch.parts => {
                let parts = if self.mischief == Mischief::HugeGates {
                    255
                } else {
                    1
                };
                for part in 0..parts {
                    let mut w = Writer::new(&mut records);
                    if self.mischief == Mischief::HugeGates {
                        let mut prev = 0;
                        for i in 0..16u16 {
                            let track = u16::from(part) * 16 + i + 1;
                            let gate = GateOnGrid::of(
                                track,
                                (0..8u16).collect(),
                                [0.0, 1000.0],
                                [100.0, 0.0, 100.0],
                            );
                            records::write_gate(
                                &mut w,
                                prev,
                                &gate,
                                GateReference::default(),
                                [0, 0],
                            );
                            prev = track;
                        }
                    }
                    let n = w.len();
                    self.reply(
                        id,
                        &DeviceToHost::Gated(GatedBatch {
                            scan: batch.scan,
                            part,
                            last: part + 1 == parts,
                            base_scan: None,
                            live_tracks: 3,
                            gates: Bytes(&records[..n]),
                        }),
                    );
                }
            }
            HostToDevice::Assign(batch) => {
                let mut w = Writer::new(&mut records);
                let far = StateOnGrid {
                    track: 1,
                    status: TrackStatus::Confirmed,
                    position_tenths: [i32::MAX, 10_000],
                    velocity_hundredths: [100, i32::MAX],
                    age_scans: 10,
                    hit_history: 0x3ff,
                };
                let base_scan = match self.mischief {
                    Mischief::Garbage => {
                        w.byte(0xEE);
                        w.byte(0x80);
                        None
                    }
                    Mischief::NoSuchBase => {
                        records::write_state(&mut w, 0, &far, true, Some(&far), 2.5);
                        Some(batch.scan.wrapping_sub(1))
                    }
                    _ => {
                        records::write_state(&mut w, 0, &far, true, None, 2.5);
                        None
                    }
                };
                let n = w.len();
                self.reply(
                    id,
                    &DeviceToHost::Tracks(TrackBatch {
                        scan: batch.scan,
                        part: 0,
                        last: self.mischief != Mischief::NeverDone,
                        base_scan,
                        states: Bytes(&records[..n]),
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
            let Some(Ok(payload)) = self.decoder.push(b) else {
                continue;
            };
            let payload = payload.to_vec();
            if let Ok((h, req)) = frame::decode_payload::<HostToDevice>(&payload, u32::MAX) {
                self.handle(h.request_id, req);
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
    for mischief in [
        Mischief::BadNumbers,
        Mischief::Garbage,
        Mischief::NoSuchBase,
        Mischief::HugeGates,
        Mischief::NeverDone,
    ] {
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
