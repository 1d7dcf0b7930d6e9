//! A radar on the network as `tracker-host track --radar navico@ADDR` meets it: the 3G
//! capture's datagrams sent again, at their recorded pace, to their multicast groups on the
//! loopback interface (nothing leaves the machine), received by the binary, decoded,
//! extracted and tracked, then ended with Ctrl-C once it has tracked every whole rotation. The spokes, rotations and plots must be
//! those of the same capture read as a file, and nothing may be lost on the way; a second
//! radar sending the same spokes to the same group from another address is ignored; the
//! radar's reports give its range scales, as in the file. (The binary listens where a real
//! 3G sends, 236.6.7.8:6678 and 236.6.7.9:6679: anything else sending there on this
//! machine while the test runs, a replay or a radar, is counted too and fails it.)
#![cfg(target_os = "linux")]

use std::io::{BufRead, BufReader};
use std::net::{Ipv4Addr, SocketAddrV4, UdpSocket};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use tracker_host::radar::capture::{CaptureOptions, CaptureReader};

mod realdata;

/// The capture's multicast datagrams, with their times from the first, s.
fn multicast_datagrams(name: &str) -> Vec<(f64, SocketAddrV4, Vec<u8>)> {
    let path = realdata::file(&format!("radar/{name}"));
    let mut reader = CaptureReader::open(&path, CaptureOptions::default()).unwrap();
    let mut out = Vec::new();
    let mut t0 = None;
    while let Some(d) = reader.next_datagram().unwrap() {
        if d.dst.ip().is_multicast() {
            let t0 = *t0.get_or_insert(d.time_s);
            out.push((d.time_s - t0, d.dst, d.payload.to_vec()));
        }
    }
    out
}

fn summary(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// True once a socket is bound to UDP `port` on this machine (the binary has joined).
fn udp_port_bound(port: u16) -> bool {
    let want = format!(":{port:04X} ");
    std::fs::read_to_string("/proc/net/udp")
        .map(|t| {
            t.lines().skip(1).any(|l| {
                l.split_whitespace()
                    .nth(1)
                    .is_some_and(|a| (a.to_owned() + " ").ends_with(&want))
            })
        })
        .unwrap_or(false)
}

#[test]
fn a_live_radar_is_tracked_as_its_capture_is() {
    let name = "radar_pi-3g-trueheading.pcap.gz";
    let dir = tempfile::tempdir().unwrap();
    let (file_json, live_json) = (dir.path().join("file.json"), dir.path().join("live.json"));
    let bin = env!("CARGO_BIN_EXE_tracker-host");

    let capture = realdata::file(&format!("radar/{name}"));
    let out = Command::new(bin)
        .args(["--link", "inproc", "track", "--plain", "--radar"])
        .arg(format!("pcap:{}", capture.display()))
        .arg("--summary-json")
        .arg(&file_json)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let file_stdout = String::from_utf8_lossy(&out.stdout).into_owned();

    let mut live = Command::new(bin)
        .args([
            "--link",
            "inproc",
            "track",
            "--plain",
            "--radar",
            "navico@127.0.0.1",
        ])
        .arg("--summary-json")
        .arg(&live_json)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(live.stdout.take().unwrap());
    let deadline = Instant::now() + Duration::from_secs(20);
    while !(udp_port_bound(6678) && udp_port_bound(6679)) {
        assert!(
            Instant::now() < deadline,
            "the binary never joined the 3G's group"
        );
        std::thread::sleep(Duration::from_millis(50));
    }

    // Sent as the radar sent them: to the group, out of the loopback interface, at the
    // capture's pace (the tracker takes a spoke's time from its arrival).
    let datagrams = multicast_datagrams(name);
    let sender = socket2::Socket::new(
        socket2::Domain::IPV4,
        socket2::Type::DGRAM,
        Some(socket2::Protocol::UDP),
    )
    .unwrap();
    sender.set_multicast_if_v4(&Ipv4Addr::LOCALHOST).unwrap();
    sender.set_multicast_loop_v4(true).unwrap();
    let sender: UdpSocket = sender.into();
    // A second radar on the same network and group (two scanners on one bridge), here at
    // 127.0.0.2, sending the same spokes just after the first: the first heard is tracked.
    let second = socket2::Socket::new(
        socket2::Domain::IPV4,
        socket2::Type::DGRAM,
        Some(socket2::Protocol::UDP),
    )
    .unwrap();
    second
        .bind(&SocketAddrV4::new(Ipv4Addr::new(127, 0, 0, 2), 0).into())
        .unwrap();
    second.set_multicast_if_v4(&Ipv4Addr::LOCALHOST).unwrap();
    second.set_multicast_loop_v4(true).unwrap();
    let second: UdpSocket = second.into();
    let start = Instant::now();
    // And junk on the spoke group now and then (another program's traffic): refused as
    // spoke packets and counted, the picture unchanged.
    let mut junk = 0;
    for (k, (t, dst, payload)) in datagrams.iter().enumerate() {
        if let Some(wait) =
            (start + Duration::from_secs_f64(*t)).checked_duration_since(Instant::now())
        {
            std::thread::sleep(wait);
        }
        sender.send_to(payload, dst).unwrap();
        // The second radar on another range scale (5 km): its reports are not the tracked
        // radar's, and must not be taken for its scale.
        let mut theirs = payload.clone();
        if theirs.len() == 99 && theirs[..2] == [0x02, 0xC4] {
            theirs[2..6].copy_from_slice(&50_000u32.to_le_bytes());
        }
        second.send_to(&theirs, dst).unwrap();
        if k % 20 == 0 && dst.port() == 6678 {
            sender
                .send_to(b"not a spoke: junk on the group", dst)
                .unwrap();
            junk += 1;
        }
    }
    // Every whole rotation tracked (however far behind a slow machine is), the partial
    // last one's spokes read, then Ctrl-C: the run ends with its summary.
    let file_scans = summary(&file_json)["scans"].as_u64().unwrap();
    let deadline = Instant::now() + Duration::from_secs(120);
    let mut stdout = String::new();
    while (stdout.lines().filter(|l| l.starts_with("scan ")).count() as u64) < file_scans {
        let mut line = String::new();
        assert_ne!(out.read_line(&mut line).unwrap(), 0, "the run ended early");
        stdout += &line;
        assert!(
            Instant::now() < deadline,
            "the rotations never came: {stdout}"
        );
    }
    std::thread::sleep(Duration::from_secs(1));
    let interrupted = Command::new("kill")
        .args(["-INT", &live.id().to_string()])
        .status()
        .unwrap();
    assert!(interrupted.success());
    std::io::Read::read_to_string(&mut out, &mut stdout).unwrap();
    let done = live.wait_with_output().unwrap();
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    assert!(stdout.contains("== summary"), "{stdout}");

    let (file, live) = (summary(&file_json), summary(&live_json));
    let (f, l) = (&file["radar"], &live["radar"]);
    println!("file: {f}\nlive: {l}");
    // The spoke group and the report group beside it are joined (its reports give the
    // model and the range scale); the radar's other groups are not.
    let spoke_datagrams = datagrams.iter().filter(|d| d.1.port() == 6678).count();
    let report_datagrams = datagrams.iter().filter(|d| d.1.port() == 6679).count();
    assert!(report_datagrams > 0);
    assert_eq!(
        l["live"]["received"],
        2 * (spoke_datagrams + report_datagrams) + junk,
        "spoke and report datagrams sent by the two radars, and the junk, received"
    );
    // The range scales the radar reported, live as in the file: ½ NM, then 1 NM (not the
    // second radar's 5 km).
    assert_eq!(
        l["range_settings_m"],
        serde_json::json!([926.0, 1852.0]),
        "{l}"
    );
    assert_eq!(f["range_settings_m"], l["range_settings_m"]);
    assert!(stdout.contains("(the radar on 0.5 NM, 1 NM)"), "{stdout}");
    assert!(junk > 10, "{junk}");
    assert_eq!(l["spoke_packets_refused"], junk, "{l}");
    assert!(
        stdout.contains(&format!("{junk} spoke packets refused")),
        "{stdout}"
    );
    assert_eq!(l["other_radar"], "127.0.0.2");
    assert_eq!(l["other_radar_datagrams"], spoke_datagrams);
    assert!(
        stdout.contains(&format!(
            "{spoke_datagrams} spoke datagrams from a second radar at 127.0.0.2 ignored"
        )),
        "{stdout}"
    );
    assert_eq!(l["live"]["dropped"], 0);
    assert_eq!(l["live"]["kernel_dropped"], 0);
    assert!(stdout.contains("0 dropped by the kernel"), "{stdout}");
    for key in ["spokes", "detections", "restarts", "plots_without_heading"] {
        assert_eq!(f[key], l[key], "{key}");
    }
    // The capture's last rotation is cut short: counted, not tracked; a live radar's partial
    // rotation at Ctrl-C is not tracked either, so both track the same rotations.
    let count = |v: &serde_json::Value| v.as_u64().unwrap();
    assert_eq!(count(&l["scans"]), count(&f["scans"]));
    assert_eq!(count(&l["plots"]), count(&f["plots"]));
    assert!(count(&f["last_rotation_cut_plots"]) > 0, "{f}");
    assert!(
        file_stdout.contains("the capture's last rotation, ended mid-rotation, not tracked"),
        "{file_stdout}"
    );
    assert!(count(&l["plots"]) > 100);
    assert!(count(&live["targets_seen"]) > 0);
}
