//! The STM32F4DISCOVERY firmware (`boards/stm32f4-discovery`, built with its `qemu` feature,
//! which only skips the clock set-up QEMU cannot model) on QEMU's `netduinoplus2`, an
//! STM32F405: the same device behind the STM32's USART2 and the HAL, its RX interrupt and
//! queue. scripts/test builds the ELF to `target/board-stm32f4-discovery-qemu.elf` first.

use std::net::{TcpListener, TcpStream};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use tracker_core::filter::FilterKind;
use tracker_host::app::demo::{self, DemoOptions};
use tracker_host::link::check::{self as link_check, LinkCheckOptions};
use tracker_host::link::qemu;
use tracker_host::link::{Client, InprocTransport, TcpTransport};

struct Board(Child);

impl Drop for Board {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// The board's ELF, or `None` (the test is skipped) outside scripts/test.
fn elf() -> Option<PathBuf> {
    let elf = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../target/board-stm32f4-discovery-qemu.elf");
    let required = std::env::var_os("TRACKER_REQUIRE_QEMU").is_some();
    if elf.exists() && qemu::qemu_available() {
        return Some(elf);
    }
    assert!(
        !required,
        "{} and qemu-system-arm are required (TRACKER_REQUIRE_QEMU is set)",
        elf.display()
    );
    eprintln!("skipped: no board ELF (scripts/test builds it) or no qemu-system-arm");
    None
}

/// Starts the board with USART2 on a loopback socket and returns a client that has
/// completed the handshake (bytes sent before the firmware enables USART2 are dropped, as on
/// a real chip, so the handshake is retried until the board is up).
fn start(elf: &PathBuf) -> (Board, Client) {
    let port = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let child = Command::new("qemu-system-arm")
        .args([
            "-machine",
            "netduinoplus2",
            "-nographic",
            "-monitor",
            "none",
        ])
        .args(["-serial", "null", "-serial"])
        .arg(format!(
            "tcp:127.0.0.1:{port},server=on,wait=off,nodelay=on"
        ))
        .arg("-kernel")
        .arg(elf)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .spawn()
        .expect("qemu-system-arm starts");
    let board = Board(child);
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        if let Ok(stream) = TcpStream::connect(("127.0.0.1", port)) {
            let mut client = Client::new(Box::new(TcpTransport::from_stream(stream).unwrap()));
            client.timeout = Duration::from_millis(500);
            if client.hello().is_ok() {
                client.timeout = Duration::from_secs(2);
                return (board, client);
            }
        }
        assert!(Instant::now() < deadline, "the board never answered");
        std::thread::sleep(Duration::from_millis(100));
    }
}

#[test]
fn the_stm32_board_passes_the_link_check_and_tracks_like_inproc() {
    let Some(elf) = elf() else {
        return;
    };
    let (_board, mut client) = start(&elf);
    let info = client.hello().unwrap();
    assert!(
        info.firmware.contains("STM32F4DISCOVERY"),
        "{}",
        info.firmware
    );
    let report = link_check::run(
        &mut client,
        &LinkCheckOptions {
            frames: 300,
            seed: 4,
        },
    )
    .unwrap();
    assert!(report.passed(), "{}", report.summary());

    // The main job: the same tracks as the core in-process, scan for scan.
    let options = DemoOptions::new(
        tracker_core::sim::ScenarioKind::OpenSea,
        40,
        1,
        150.0,
        FilterKind::KalmanCv,
    );
    let mut on_board = demo::start(client, &options).unwrap();
    let mut in_process =
        demo::start(Client::new(Box::new(InprocTransport::new())), &options).unwrap();
    for _ in 0..60 {
        let a = on_board.step().unwrap().unwrap();
        let b = in_process.step().unwrap().unwrap();
        assert_eq!(a.tracks, b.tracks, "scan {}", a.scan);
    }
}
