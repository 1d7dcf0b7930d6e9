//! Bad AIS input: wrong fill bits, a missing fragment, fragments out of order, a latitude of
//! 91° ("not available") and 95° (off the globe), a 10,000-station flood, and thousands of
//! mutated real sentences: every one counted, memory bounded, never a panic, and the good
//! sentences around them still decoded.

use aivdm::AisMessage;
use tracker_host::ais::targets::MAX_AIS_TARGETS;
use tracker_host::ais::{AisDecoder, AisTargets};
use tracker_host::nmea::checksum;
use tracker_host::origin::Origin;

/// A real class A position report (gpsd's corpus).
const REAL: &str = "!AIVDM,1,1,,B,13aDp<PP000IwSlN?Wm@0?wN2<1T,0*29";
/// A real two-fragment type 5 (gpsd's AIS log).
const PART1: &str = "!AIVDM,2,1,9,B,55R3Vn82=ILTQ3KKS>1<D60Dq@E918U<F222221J1`?164vc03S1CCAD,0*2A";
const PART2: &str = "!AIVDM,2,2,9,B,`88888888888880,2*76";

fn line(fields: &str) -> String {
    format!("!{fields}*{:02X}", checksum(fields))
}

/// `REAL` with its latitude set to `raw` (1/10,000 minute) and its MMSI to `mmsi`.
fn position_report(lat_raw: i32, mmsi: u32) -> String {
    let AisMessage::PositionReportClassA(mut p) = aivdm::decode_line(REAL).unwrap() else {
        panic!("not a position report");
    };
    p.latitude = aivdm::Latitude::from_raw(lat_raw);
    p.mmsi = aivdm::Mmsi::from_raw(mmsi);
    let mut buf = [0u8; 128];
    let (payload, fill) =
        aivdm::encode_payload(&AisMessage::PositionReportClassA(p), &mut buf).unwrap();
    line(&format!(
        "AIVDM,1,1,,A,{},{fill}",
        std::str::from_utf8(payload).unwrap()
    ))
}

#[test]
fn bad_ais_is_counted_and_the_good_still_decoded() {
    let mut d = AisDecoder::new();
    let mut table = AisTargets::new(Origin::default());
    // Wrong fill bits: 7 is outside 0–5.
    assert!(d
        .feed(&line("AIVDM,1,1,,B,13aDp<PP000IwSlN?Wm@0?wN2<1T,7"))
        .is_none());
    assert_eq!(d.counts().rejected["fragment fields out of range"], 1);
    // A missing fragment: the first alone never makes a message, and is given up.
    assert!(d.feed(PART1).is_none());
    for _ in 0..60 {
        assert!(d.feed(REAL).is_some());
    }
    assert_eq!(d.counts().assembly.incomplete, 1);
    // Fragments out of order still make the message.
    assert!(d.feed(PART2).is_none());
    let r = d
        .feed(PART1)
        .expect("type 5 from fragments in reverse order");
    assert_eq!((r.msg_type, r.mmsi), (5, 371_255_000));
    assert_eq!(r.name.as_deref(), Some("SEA ENTERPRISE"));
    assert!(
        r.ship_type.is_some() && r.size_m.is_some_and(|(l, b)| l > b && b > 0),
        "{r:?}"
    );
    // Where its antenna sits: the hull's centre within half the length and beam of it.
    let (l, b) = r.size_m.unwrap();
    let (forward, starboard) = r.centre_from_antenna_m.expect("the antenna's place");
    assert!(
        forward.abs() < f32::from(l) / 2.0 && starboard.abs() < f32::from(b) / 2.0,
        "{r:?}"
    );
    // Latitude 91°: not available, no position, no target made of it.
    let r = d.feed(&position_report(91 * 600_000, 1)).unwrap();
    assert_eq!(r.position_deg, None);
    table.report(0.0, &r);
    assert!(table.get(1).is_none());
    // 95°: off the globe, counted, no position.
    let r = d.feed(&position_report(95 * 600_000, 2)).unwrap();
    assert_eq!(r.position_deg, None);
    assert_eq!(d.counts().off_the_globe, 1);
    // A 10,000-station flood: the table holds its bound, the newest stations in it.
    for mmsi in 0..10_000u32 {
        if let Some(r) = d.feed(&position_report(30 * 600_000, 100_000 + mmsi)) {
            table.report(f64::from(mmsi), &r);
        }
    }
    assert_eq!(table.len(), MAX_AIS_TARGETS);
    assert!(table.get(100_000 + 9_999).is_some());
    assert_eq!(table.counts().crowded_out, 10_000 - MAX_AIS_TARGETS as u64);
}

#[test]
fn mutated_sentences_never_panic_and_are_all_counted() {
    let mut d = AisDecoder::new();
    let mut rng = fastrand::Rng::with_seed(7);
    let sources = [REAL, PART1, PART2];
    let mut fed = 0u64;
    for i in 0..30_000 {
        let mut bytes = sources[i % 3].as_bytes().to_vec();
        for _ in 0..rng.usize(1..4) {
            match rng.u8(0..3) {
                0 if !bytes.is_empty() => {
                    let at = rng.usize(..bytes.len());
                    bytes[at] = rng.u8(32..127);
                }
                1 if !bytes.is_empty() => {
                    bytes.truncate(rng.usize(..bytes.len()));
                }
                _ => bytes.push(rng.u8(32..127)),
            }
        }
        let mut text = String::from_utf8_lossy(&bytes).to_string();
        // Half of them with a good checksum, so the fields themselves are tried.
        if i % 2 == 0 {
            if let Some(body) = text.strip_prefix('!').and_then(|t| t.split('*').next()) {
                text = line(body);
            }
        }
        if tracker_host::ais::fragment::is_ais(&text) {
            fed += 1;
        }
        let _ = d.feed(&text);
    }
    let c = d.counts();
    assert_eq!(c.sentences, fed);
    assert!(c.rejected_total() > 0 && c.decoded() > 0, "{c}");
    // Every AIS sentence came to something: decoded, refused, undecodable, ignored, or a
    // fragment (held, given up, or part of a message).
    let whole = c.decoded() + c.ignored + c.undecodable.values().sum::<u64>();
    assert!(whole + c.rejected_total() <= c.sentences, "{c}");
    assert!(d.counts().assembly.incomplete <= c.sentences);
}
