//! AIS in on every real recording with AIVDM/AIVDO in `../shared/realdata/ais/` and
//! `../shared/realdata/nmea/` (read where CI has them, or where `TRACKER_REALDATA` says),
//! checked against an independent decoder: `tools/ais_reference.py` (pyais 3.3.1, its own
//! reassembly). Every message of a type the table uses (1–3, 5, 18, 19, 24, 27) that pyais
//! decodes, we decode from the same line with the same type, MMSI and position (1e-5°);
//! no sentence of the recordings that pyais takes is refused by us; each file's counts are
//! printed.

use std::collections::HashMap;
use std::io::BufRead;
use std::path::{Path, PathBuf};

use tracker_host::ais::AisDecoder;

mod realdata;

const FILES: [&str; 10] = [
    "ais/gpsd-ais-nmea.log",
    "ais/signalk-nais300-merrimac.log",
    "ais/signalk-nais400-merrimac.log",
    "ais/pyais-nmea_data_sample.txt",
    "ais/gpsd-sample.aivdm",
    "nmea/gpsd-saab-r4.log",
    "nmea/mayara-halo_and_0183-nmea.log",
    "nmea/radar_pi-3g-trueheading-udp10110.log",
    "nmea/radar_pi-4g-noheading-merrimac-tcp2000.log",
    "nmea/signalk-gofree-merrimac.log",
];

const USED_TYPES: [u8; 8] = [1, 2, 3, 5, 18, 19, 24, 27];

/// (file name, line) → (type, MMSI, position) as pyais decodes it.
type Reference = HashMap<(String, usize), (u8, u32, Option<(f64, f64)>)>;

fn reference(paths: &[PathBuf]) -> Option<Reference> {
    let python = std::env::var("TRACKER_PYTHON").unwrap_or_else(|_| "python3".to_string());
    let have = std::process::Command::new(&python)
        .args(["-c", "import pyais"])
        .status()
        .is_ok_and(|s| s.success());
    if !have {
        assert!(
            std::env::var_os("TRACKER_REQUIRE_TOOLS").is_none(),
            "pyais is required (TRACKER_REQUIRE_TOOLS is set): scripts/setup installs it"
        );
        eprintln!("pyais not installed: the comparison is skipped");
        return None;
    }
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tools/ais_reference.py");
    let out = std::process::Command::new(&python)
        .arg(script)
        .args(paths)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut r = Reference::new();
    let mut csv = csv::Reader::from_reader(out.stdout.as_slice());
    for row in csv.records() {
        let row = row.unwrap();
        let num = |i: usize| row.get(i).unwrap_or("").parse::<f64>().ok();
        let position = num(5).zip(num(6));
        r.insert(
            (row[0].to_string(), row[1].parse().unwrap()),
            (row[3].parse().unwrap(), row[4].parse().unwrap(), position),
        );
    }
    Some(r)
}

#[test]
fn every_real_ais_message_decodes_as_pyais_decodes_it() {
    let paths: Vec<PathBuf> = FILES.iter().map(|f| realdata::dir().join(f)).collect();
    for p in &paths {
        assert!(
            p.is_file(),
            "{}: missing (set TRACKER_REALDATA)",
            p.display()
        );
    }
    let reference = reference(&paths);
    println!("| file | AIS sentences | decoded | types not used | refused | undecodable | incomplete | pyais messages of used types | same |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for p in &paths {
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        let mut ours = HashMap::new();
        let mut d = AisDecoder::new();
        let reader = std::io::BufReader::new(std::fs::File::open(p).unwrap());
        for (i, line) in reader.split(b'\n').enumerate() {
            let line = String::from_utf8_lossy(&line.unwrap()).to_string();
            if let Some(r) = d.feed(&line) {
                ours.insert(i + 1, (r.msg_type, r.mmsi, r.position_deg));
            }
        }
        let c = d.counts();
        let (mut expected, mut same) = (0, 0);
        let mut missing = Vec::new();
        if let Some(reference) = &reference {
            for ((file, line), (msg_type, mmsi, position)) in reference {
                if *file != name || !USED_TYPES.contains(msg_type) {
                    continue;
                }
                expected += 1;
                let Some(&(t, m, pos)) = ours.get(line) else {
                    missing.push(format!("{line}: type {msg_type} MMSI {mmsi}"));
                    continue;
                };
                assert_eq!((t, m), (*msg_type, *mmsi), "{name}:{line}");
                match (pos, position) {
                    (Some(a), Some(b)) => assert!(
                        (a.0 - b.0).abs() < 1e-5 && (a.1 - b.1).abs() < 1e-5,
                        "{name}:{line}: {a:?} against pyais {b:?}"
                    ),
                    (None, None) => {}
                    (a, b) => panic!("{name}:{line}: position {a:?} against pyais {b:?}"),
                }
                same += 1;
            }
        }
        println!(
            "| {name} | {} | {} | {} | {} | {} | {} | {expected} | {same} |",
            c.sentences,
            c.decoded(),
            c.ignored,
            c.rejected_total(),
            c.undecodable.values().sum::<u64>(),
            c.assembly.incomplete
        );
        assert!(
            missing.is_empty(),
            "{name}: pyais decodes, we do not ({c}): {missing:?}"
        );
        // Only the pyais sample (100 sentences with an empty payload, 20 lone first
        // fragments) and gpsd's annotated corpus (types 37 and 41 in comments) hold
        // sentences pyais refuses too.
        if !name.starts_with("pyais") && !name.starts_with("gpsd-sample") {
            assert_eq!(c.rejected_total(), 0, "{name}: {c} {:?}", c.rejected);
            assert_eq!(
                c.undecodable.values().sum::<u64>(),
                0,
                "{name}: {:?}",
                c.undecodable
            );
            assert_eq!(c.assembly.incomplete, 0, "{name}: {c}");
        }
        assert!(c.decoded() > 0, "{name}: nothing decoded");
    }
}

/// `track --nmea-in` alone, no radar: the AIS targets and own ship of a real recording, a
/// scan every 2.5 s of the recording's own time from its first fix to its last. Every AIS
/// sentence of the recording is taken (none refused, none told as heard too far from the
/// scans: before the recording's times were put on its own first date, the sentences ahead
/// of its first dated one fell on today's and 509 of the NAIS-400's were not taken), and
/// the scans cover the recording.
#[test]
fn ais_alone_without_a_radar_takes_every_sentence_of_a_recording() {
    for (file, span_s) in [
        ("ais/signalk-nais400-merrimac.log", 14.0),
        ("nmea/signalk-gofree-merrimac.log", 135.0),
    ] {
        let path = realdata::file(file);
        let dir = tempfile::tempdir().unwrap();
        let json = dir.path().join("summary.json");
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_tracker-host"))
            .args(["--link", "inproc", "track", "--plain", "--nmea-in"])
            .arg(format!("file:{}", path.display()))
            .arg("--summary-json")
            .arg(&json)
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{file}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let in_file = text.lines().filter(|l| l.contains("!AIVD")).count() as u64;
        let ais = &s["ais"]["sentences"];
        assert_eq!(ais["sentences"].as_u64(), Some(in_file), "{file}: {ais}");
        assert_eq!(ais["rejected"], serde_json::json!({}), "{file}: {ais}");
        let events = s["events"].as_array().unwrap();
        assert!(
            !events
                .iter()
                .any(|e| e.as_str().unwrap().contains("not taken")),
            "{file}: {events:?}"
        );
        assert!(s["ais"]["targets_now"].as_u64().unwrap() > 100, "{file}");
        assert_eq!(
            s["own_ship_nmea"]["after_last_scan"].as_u64(),
            Some(0),
            "{file}"
        );
        let scans = s["scans"].as_u64().unwrap();
        assert!(
            (scans as f64 - 1.0) * 2.5 >= span_s - 2.5,
            "{file}: {scans} scans for {span_s} s"
        );
        // The plain table's header says own ship has its fix, and no radar target shows:
        // every scan lists the AIS targets (as many rows as the header counts), no radar
        // table; the summary says there was no radar.
        assert!(stdout.contains(" fix  AIS "), "{file}: {stdout}");
        assert_eq!(s["targets_seen"].as_u64(), Some(0), "{file}");
        assert_eq!(s["without_radar"], serde_json::json!(true), "{file}");
        assert!(!stdout.contains(" TGT STATUS"), "{file}");
        assert!(!stdout.contains("targets tracked"), "{file}");
        assert!(stdout.contains("  no radar  "), "{file}");
        let last = stdout.rsplit("\nscan ").next().unwrap();
        let heard: usize = last
            .lines()
            .next()
            .and_then(|h| h.rsplit("AIS ").next())
            .and_then(|n| n.trim().parse().ok())
            .unwrap();
        let listed = last
            .lines()
            .skip_while(|l| !l.starts_with("AIS MMSI"))
            .skip(1)
            .take_while(|l| l.as_bytes().first().is_some_and(u8::is_ascii_digit))
            .count();
        assert_eq!(listed, heard, "{file}: {last}");
    }
}
