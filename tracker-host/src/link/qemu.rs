//! Running the firmware under `qemu-system-arm` on the mps2-an386 board (Cortex-M4F).
//!
//! UART0 goes to a loopback TCP socket with `nodelay` on both ends (Nagle otherwise holds
//! every small frame ~40 ms); semihosting stdout carries defmt, decoded by `defmt-print`
//! when `--mcu-log` asks for it.

use std::io;
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{bail, Context};

use super::transport::{TcpTransport, Transport};

/// The QEMU machine and CPU the firmware is built for.
pub const MACHINE: [&str; 4] = ["-machine", "mps2-an386", "-cpu", "cortex-m4"];

/// The thumb target the firmware is built for.
pub const TARGET: &str = "thumbv7em-none-eabihf";

/// How QEMU-backed commands find and run the firmware.
#[derive(Clone, Debug, Default)]
pub struct QemuOptions {
    /// The ELF to run; by default the workspace's release build (built when missing).
    pub firmware: Option<PathBuf>,
    /// Decode the firmware's defmt log to stderr (needs `defmt-print`).
    pub mcu_log: bool,
}

/// True when `qemu-system-arm` is on the PATH.
pub fn qemu_available() -> bool {
    Command::new("qemu-system-arm")
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// The workspace this binary was built from, if its firmware crate is still there.
fn workspace_root() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()?
        .to_path_buf();
    root.join("tracker-firmware")
        .join("Cargo.toml")
        .is_file()
        .then_some(root)
}

/// The firmware's binaries and the cargo features each needs.
fn features_of(bin: &str) -> &'static [&'static str] {
    match bin {
        "bench" | "bench-nav" | "bench-radar" => &["--features", "bench"],
        _ => &[],
    }
}

/// How long the firmware's `cargo build` may take before the user is told it is building.
const BUILD_NOTE_AFTER: Duration = Duration::from_secs(2);

/// The firmware binary QEMU runs (`tracker-firmware`'s `tracker-firmware`).
pub const FIRMWARE_BIN: &str = "tracker-firmware";

/// The path of firmware binary `bin`: `explicit` if given, else the workspace's release
/// build, brought up to date with cargo (a no-op when nothing changed).
///
/// # Errors
/// An explicit ELF that does not exist or is not an ARM executable (`check_arm_elf`); no
/// source workspace to build from; cargo failing (the thumb target missing: `scripts/setup`
/// installs it).
pub fn firmware_elf(bin: &str, explicit: Option<&Path>) -> anyhow::Result<PathBuf> {
    if let Some(p) = explicit {
        if !p.exists() {
            bail!("firmware {} does not exist", p.display());
        }
        check_arm_elf(p)?;
        return Ok(p.to_path_buf());
    }
    let Some(root) = workspace_root() else {
        bail!("no firmware given (--firmware PATH) and no source workspace to build one from");
    };
    let target_dir = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"));
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut child = Command::new(cargo)
        .current_dir(&root)
        .args(["build", "--quiet", "--release", "-p", "tracker-firmware"])
        .args(["--target", TARGET, "--bin", bin])
        .args(features_of(bin))
        .spawn()
        .context("running cargo to build the firmware")?;
    // Up to date, cargo is done at once; otherwise the user is told what the wait is (a
    // first build takes minutes, and another build holding cargo's lock delays it).
    let told_after = Instant::now() + BUILD_NOTE_AFTER;
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) => {}
            Err(e) => {
                // Not left building behind the error.
                let _ = child.kill();
                let _ = child.wait();
                return Err(e).context("waiting for cargo");
            }
        }
        if Instant::now() >= told_after {
            eprintln!(
                "building the firmware (cargo build --release -p tracker-firmware --target {TARGET} in {}); a first build takes a few minutes",
                root.display()
            );
            break child.wait().context("waiting for cargo")?;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    if !status.success() {
        bail!(
            "building the firmware failed (cargo: {status}; is the {TARGET} target installed? run scripts/setup)"
        );
    }
    let elf = target_dir.join(TARGET).join("release").join(bin);
    if !elf.exists() {
        bail!("cargo built no {}", elf.display());
    }
    Ok(elf)
}

/// Refuses a file that is not a 32-bit little-endian ARM ELF executable before QEMU is
/// given it: QEMU runs anything, and a text file given by mistake ended in its register
/// dump ("Lockup: can't escalate 3 to HardFault") and a link error (a new user's trial).
///
/// # Errors
/// The file does not open or read, or it is shorter than an ELF header's first 20 bytes,
/// or they (System V ABI, ELF32: `\x7fELF`, class 1, data 1, `e_type` 2, `e_machine` 40)
/// say otherwise.
fn check_arm_elf(path: &Path) -> anyhow::Result<()> {
    let mut header = Vec::with_capacity(20);
    std::fs::File::open(path)
        .and_then(|f| std::io::Read::read_to_end(&mut std::io::Read::take(f, 20), &mut header))
        .with_context(|| format!("reading firmware {}", path.display()))?;
    let u16_at = |i: usize| {
        header
            .get(i..i + 2)
            .map(|b| u16::from_le_bytes([b[0], b[1]]))
    };
    let arm = header.starts_with(b"\x7fELF")
        && header.get(4..6) == Some(&[1, 1][..])
        && u16_at(16) == Some(2)
        && u16_at(18) == Some(40);
    if !arm {
        bail!(
            "firmware {} is not an ARM executable (an ELF32 for the Cortex-M, as the firmware's build writes under target/{TARGET}/release/)",
            path.display()
        );
    }
    Ok(())
}

fn base_command(elf: &Path) -> Command {
    let mut cmd = Command::new("qemu-system-arm");
    cmd.args(MACHINE)
        .args(["-nographic", "-monitor", "none"])
        .args(["-semihosting-config", "enable=on,target=native"])
        .arg("-kernel")
        .arg(elf);
    cmd
}

/// The firmware in QEMU with UART0 on a loopback socket. QEMU is killed on drop.
pub struct QemuLink {
    child: Child,
    logger: Option<Child>,
    link: TcpTransport,
}

impl QemuLink {
    /// Builds or finds the firmware, starts QEMU and connects to its UART0.
    ///
    /// # Errors
    /// QEMU not installed, the firmware not built, QEMU exiting early, or its UART not reachable within 10 s.
    pub fn start(opts: &QemuOptions) -> anyhow::Result<Self> {
        if !qemu_available() {
            bail!("qemu-system-arm is not installed (scripts/setup installs it, or use --link inproc)");
        }
        let elf = firmware_elf(FIRMWARE_BIN, opts.firmware.as_deref())?;
        // Pick a free port; QEMU waits (wait=on) for us before starting the CPU.
        let port = TcpListener::bind("127.0.0.1:0")?.local_addr()?.port();
        let mut cmd = base_command(&elf);
        cmd.arg("-serial")
            .arg(format!("tcp:127.0.0.1:{port},server=on,wait=on,nodelay=on"))
            .stdin(Stdio::null())
            .stderr(Stdio::piped());
        let decode_log = opts.mcu_log && which("defmt-print");
        if opts.mcu_log && !decode_log {
            eprintln!("note: defmt-print is not installed; the firmware log is not shown");
        }
        cmd.stdout(if decode_log {
            Stdio::piped()
        } else {
            Stdio::null()
        });
        let mut child = cmd.spawn().context("starting qemu-system-arm")?;
        if let Some(err) = child.stderr.take() {
            // Relay QEMU's messages, less its note that it waits for our connection.
            std::thread::spawn(move || {
                for line in io::BufRead::lines(io::BufReader::new(err)).map_while(Result::ok) {
                    if !line.contains("QEMU waiting for connection") {
                        eprintln!("{line}");
                    }
                }
            });
        }
        let logger = match child.stdout.take() {
            Some(out) if decode_log => Some(
                Command::new("defmt-print")
                    .arg("-e")
                    .arg(&elf)
                    .stdin(out)
                    .stdout(Stdio::inherit())
                    .spawn()
                    .context("starting defmt-print")?,
            ),
            _ => None,
        };
        let deadline = Instant::now() + Duration::from_secs(10);
        let stream = loop {
            match TcpStream::connect(("127.0.0.1", port)) {
                Ok(s) => break s,
                Err(e) => {
                    if let Some(status) = child.try_wait()? {
                        bail!("qemu-system-arm exited early ({status})");
                    }
                    if Instant::now() > deadline {
                        let _ = child.kill();
                        return Err(e).context("connecting to QEMU's UART0");
                    }
                    std::thread::sleep(Duration::from_millis(20));
                }
            }
        };
        Ok(QemuLink {
            child,
            logger,
            link: TcpTransport::from_stream(stream)?,
        })
    }
}

impl Drop for QemuLink {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        if let Some(l) = &mut self.logger {
            let _ = l.wait();
        }
    }
}

impl Transport for QemuLink {
    fn write_all(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.link.write_all(bytes)
    }

    fn read(&mut self, buf: &mut [u8], timeout: Duration) -> io::Result<usize> {
        self.link.read(buf, timeout)
    }
}

/// Runs `elf` to completion with deterministic instruction timing (`-icount shift=0`) and
/// returns its semihosting stdout. Fails when QEMU exits non-zero (the firmware reports
/// failure through semihosting) or runs past `limit`.
///
/// # Errors
/// QEMU not installed or exiting non-zero, the run taking longer than `limit`, its output not readable.
pub fn run_to_exit(elf: &Path, limit: Duration) -> anyhow::Result<String> {
    if !qemu_available() {
        bail!("qemu-system-arm is not installed (scripts/setup installs it)");
    }
    let mut child = base_command(elf)
        .args(["-serial", "null", "-icount", "shift=0"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .context("starting qemu-system-arm")?;
    let mut stdout = child.stdout.take().context("qemu stdout")?;
    let reader = std::thread::spawn(move || {
        let mut s = Vec::new();
        io::Read::read_to_end(&mut stdout, &mut s).map(|_| s)
    });
    let deadline = Instant::now() + limit;
    let status = loop {
        if let Some(s) = child.try_wait()? {
            break s;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            bail!("{} ran longer than {:?}", elf.display(), limit);
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let out = reader
        .join()
        .map_err(|_| anyhow::anyhow!("reading qemu output failed"))??;
    let out = String::from_utf8_lossy(&out).into_owned();
    if !status.success() {
        bail!("{} failed ({status}); output:\n{out}", elf.display());
    }
    Ok(out)
}

fn which(program: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()))
}

#[cfg(test)]
mod tests {
    #[test]
    fn only_an_arm_executable_is_given_to_qemu() {
        let dir = tempfile::tempdir().unwrap();
        let file = |name: &str, bytes: &[u8]| {
            let p = dir.path().join(name);
            std::fs::write(&p, bytes).unwrap();
            p
        };
        let mut arm = vec![0x7f, b'E', b'L', b'F', 1, 1, 1, 0];
        arm.extend([0; 8]);
        arm.extend(2u16.to_le_bytes());
        arm.extend(40u16.to_le_bytes());
        arm.extend([0; 32]);
        assert!(super::check_arm_elf(&file("arm.elf", &arm)).is_ok());
        let mut x86 = arm.clone();
        x86[18..20].copy_from_slice(&62u16.to_le_bytes());
        let mut object = arm.clone();
        object[16..18].copy_from_slice(&1u16.to_le_bytes());
        for (name, bytes) in [
            ("hello.txt", b"hello radar, a text file\n".to_vec()),
            ("x86.elf", x86),
            ("object.o", object),
            ("short", b"\x7fELF".to_vec()),
            ("empty", Vec::new()),
        ] {
            let e = format!(
                "{:#}",
                super::check_arm_elf(&file(name, &bytes)).unwrap_err()
            );
            assert!(e.contains("is not an ARM executable"), "{name}: {e}");
        }
        let absent = super::check_arm_elf(&dir.path().join("absent")).unwrap_err();
        assert!(
            format!("{absent:#}").contains("reading firmware"),
            "{absent:#}"
        );
    }
}
