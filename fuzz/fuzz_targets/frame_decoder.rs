//! Any bytes through the frame decoder, a byte at a time and in slices: no panic, the same
//! frames either way, and every payload it accepts decodes (or is refused) without
//! panicking, as either message type; the records of a gate or track report are read as the
//! host reads them (against a base of made-up tracks, and against none) without panicking.
#![no_main]

use libfuzzer_sys::fuzz_target;
use tracker_core::frame::{decode_payload, FrameDecoder};
use tracker_core::icd::records::{self, GateReference, StateOnGrid};
use tracker_core::icd::varint::Reader;
use tracker_core::icd::{DeviceToHost, HostToDevice, TrackStatus, HOST_TO_DEVICE_VARIANTS};

fn read_records(payload: &[u8]) {
    let Ok((_, reply)) = decode_payload::<DeviceToHost>(payload, u32::MAX) else {
        return;
    };
    let base = |track: u16| {
        (track % 3 != 0).then_some(StateOnGrid {
            track,
            status: TrackStatus::Confirmed,
            position_tenths: [i32::from(track) * 997, -1_000_000],
            velocity_hundredths: [i32::MAX, -300],
            age_scans: u16::MAX,
            hit_history: u16::MAX,
        })
    };
    match reply {
        DeviceToHost::Gated(g) => {
            let mut r = Reader::new(g.gates.0);
            let mut prev = 0;
            while let Ok(gate) = records::read_gate(
                &mut r,
                prev,
                |t| GateReference {
                    moved_on: base(t).map(|b| b.moved_on(2.5)),
                    cholesky_cm: base(t).map(|_| [i32::MAX, i32::MIN, 5]),
                },
                |i| (i < 200).then_some([i32::from(i), -i32::from(i)]),
            ) {
                let _ = gate.gated();
                prev = gate.track;
            }
        }
        DeviceToHost::Tracks(t) => {
            let mut r = Reader::new(t.states.0);
            let mut prev = 0;
            while let Ok(s) = records::read_state(&mut r, prev, base, 1e9) {
                let _ = s.state();
                prev = s.track;
            }
        }
        _ => {}
    }
}

fuzz_target!(|data: &[u8]| {
    let mut bytewise = FrameDecoder::new();
    let mut sliced = FrameDecoder::new();
    let mut by_byte = Vec::new();
    for &b in data {
        if let Some(frame) = bytewise.push(b) {
            by_byte.push(frame.map(<[u8]>::to_vec));
            if let Ok(payload) = frame {
                let _ = decode_payload::<HostToDevice>(payload, HOST_TO_DEVICE_VARIANTS);
                read_records(payload);
            }
        }
    }
    // The same bytes in slices cut where the data says.
    let mut by_slice = Vec::new();
    let mut rest = data;
    while !rest.is_empty() {
        let cut = 1 + usize::from(rest[0]) % rest.len();
        let (mut piece, tail) = rest.split_at(cut);
        rest = tail;
        while !piece.is_empty() {
            let (used, frame) = sliced.push_slice(piece);
            piece = &piece[used..];
            if let Some(frame) = frame {
                by_slice.push(frame.map(<[u8]>::to_vec));
            }
        }
    }
    assert_eq!(by_byte, by_slice);
});
