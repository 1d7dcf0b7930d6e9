//! The command line: `tracker-host [--link …] <command> …`.

use std::ffi::OsString;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::link::{self, Client, LinkSpec};
use crate::qemu::{self, QemuOptions};
use crate::{bench_mcu, link_check, precision, replay};

/// ARPA-style marine radar target tracker: host side.
#[derive(Debug, Parser)]
#[command(name = "tracker-host", version, about)]
pub struct Cli {
    /// Where the tracker core runs: `qemu` (firmware in qemu-system-arm), `inproc` (in
    /// this process), `tcp:HOST:PORT`, or `serial:PATH[@BAUD]` (a board). Default: qemu
    /// when installed, else inproc.
    #[arg(long, global = true, value_name = "LINK")]
    pub link: Option<LinkSpec>,

    /// Firmware ELF for `--link qemu` (default: the workspace's release build).
    #[arg(long, global = true, value_name = "ELF")]
    pub firmware: Option<PathBuf>,

    /// Show the firmware's defmt log (QEMU; needs defmt-print).
    #[arg(long, global = true)]
    pub mcu_log: bool,

    /// The command.
    #[command(subcommand)]
    pub command: Command,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Check the link: handshake, echo frames of every size, bad input rejected, counters.
    LinkCheck {
        /// Good frames to send.
        #[arg(long, default_value_t = 1000)]
        frames: usize,
        /// Seed for frame sizes and contents.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Run one single-target filter over recorded measurements (CSV `t,x,y` in, CSV out).
    Replay {
        /// The filter.
        #[arg(long, value_enum)]
        filter: replay::FilterKind,
        /// Gain options (each filter takes the ones that apply to it).
        #[command(flatten)]
        gains: Box<replay::GainArgs>,
        /// Measurements: CSV with a header holding t,x,y (s, m).
        #[arg(long, value_name = "CSV")]
        input: PathBuf,
        /// Estimates: CSV t,x,y,vx,vy,px,py,ex,ey.
        #[arg(long, value_name = "CSV")]
        output: PathBuf,
        /// Number type.
        #[arg(long, value_enum, default_value_t = replay::ScalarKind::F64)]
        scalar: replay::ScalarKind,
    },
    /// How far f32 and fixed point drift from f64 on a long run, per filter.
    Precision {
        /// Scans in the run.
        #[arg(long, default_value_t = 100_000)]
        scans: usize,
        /// Noise seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Instruction counts on the emulated Cortex-M4F, as CSV.
    BenchMcu {
        /// Bench ELF (default: the workspace's release build of the `bench` binary).
        #[arg(long, value_name = "ELF")]
        elf: Option<PathBuf>,
    },
}

impl Cli {
    fn qemu_options(&self) -> QemuOptions {
        QemuOptions {
            firmware: self.firmware.clone(),
            mcu_log: self.mcu_log,
        }
    }

    /// The link to use: as given, else QEMU when installed, else in-process.
    fn resolve_link(&self) -> LinkSpec {
        match &self.link {
            Some(l) => l.clone(),
            None if qemu::qemu_available() => LinkSpec::Qemu,
            None => LinkSpec::Inproc,
        }
    }

    fn connect(&self) -> anyhow::Result<Client> {
        let spec = self.resolve_link();
        let how = match (&self.link, &spec) {
            (None, LinkSpec::Qemu) => " (QEMU found; --link inproc runs without it)",
            (None, _) => " (qemu-system-arm not found; running the core in-process)",
            _ => "",
        };
        eprintln!("link: {spec}{how}");
        Ok(Client::new(link::open(&spec, &self.qemu_options())?))
    }
}

/// Parses `args` and runs the command; what the binary's `main` does.
pub fn run<I, T>(args: I) -> anyhow::Result<ExitCode>
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            // --help and --version are successes; the rest are usage errors (exit 2).
            let _ = e.print();
            return Ok(ExitCode::from(e.exit_code() as u8));
        }
    };
    match &cli.command {
        Command::LinkCheck { frames, seed } => {
            let mut client = cli.connect()?;
            let report = link_check::run(
                &mut client,
                &link_check::LinkCheckOptions {
                    frames: *frames,
                    seed: *seed,
                },
            )?;
            println!("{}", report.summary());
            for f in &report.failures {
                println!("failure: {f}");
            }
            Ok(if report.passed() {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            })
        }
        Command::Replay {
            filter,
            gains,
            input,
            output,
            scalar,
        } => {
            let spec = replay::FilterSpec::from_args(*filter, gains)?;
            let measurements = replay::read_measurements(input)?;
            let rows = replay::run(&spec, *scalar, &measurements)?;
            replay::write_estimates(output, &rows)?;
            eprintln!(
                "replay: {} measurements through {:?} ({:?}) -> {}",
                rows.len(),
                spec,
                scalar,
                output.display()
            );
            Ok(ExitCode::SUCCESS)
        }
        Command::Precision { scans, seed } => {
            println!(
                "{} scans at 2.5 s, 70 to 99 km from the origin, 15 m noise, seed {seed}",
                scans
            );
            print!("{}", precision::table(&precision::run(*scans, *seed)?));
            Ok(ExitCode::SUCCESS)
        }
        Command::BenchMcu { elf } => {
            let rows = bench_mcu::run(elf.as_deref().or(cli.firmware.as_deref()))?;
            print!("{}", bench_mcu::to_csv(&rows));
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// The binary's entry point: errors are printed, not panicked.
pub fn main() -> ExitCode {
    match run(std::env::args_os()) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn link_is_accepted_before_or_after_the_command() {
        let a = Cli::try_parse_from(["t", "--link", "inproc", "link-check"]).unwrap();
        let b = Cli::try_parse_from(["t", "link-check", "--link", "inproc"]).unwrap();
        assert_eq!(a.link, Some(LinkSpec::Inproc));
        assert_eq!(b.link, Some(LinkSpec::Inproc));
        assert!(Cli::try_parse_from(["t", "link-check", "--link", "usb"]).is_err());
    }
}
