//! The command line: `tracker-host [--link …] <command> …`.

use std::ffi::OsString;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};

use crate::link::{self, Client, LinkSpec};
use crate::qemu::{self, QemuOptions};
use crate::{bench_mcu, compare, demo, display, link_check, precision, replay, reproduce, target};

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

    /// Damage the link on purpose: this probability per byte, both ways, of a flipped bit
    /// (80 %), a lost byte (10 %) or a repeated one (10 %). For testing; the host retries.
    #[arg(long, global = true, value_name = "RATE")]
    pub byte_errors: Option<f64>,

    /// The command.
    #[command(subcommand)]
    pub command: Command,
}

/// The commands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// The main job: a simulated radar picture tracked by the device and this host, with
    /// the target table; ends with a summary scored against the simulation's truth.
    Demo {
        /// Scenario.
        #[arg(long, value_enum, default_value_t = ScenarioArg::OpenSea)]
        scenario: ScenarioArg,
        /// Number of targets.
        #[arg(long, default_value_t = 40)]
        targets: usize,
        /// Seed of the scenario.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Simulated seconds per real second, or `max`.
        #[arg(long, default_value = "max")]
        speedup: Speedup,
        /// Simulated duration, s.
        #[arg(long, default_value_t = 600.0)]
        duration: f64,
        /// Print the target table every scan as plain text (without it: the radar display
        /// in a terminal, progress lines otherwise).
        #[arg(long)]
        plain: bool,
        /// The filter every track runs.
        #[arg(long, value_enum, default_value_t = demo::DemoFilter::KalmanCv)]
        filter: demo::DemoFilter,
        /// Send every confirmed target to a chart plotter as NMEA 0183 `TTM` and `TLL`
        /// sentences each scan: `udp:HOST:PORT` or `tcp:PORT` (a server plotters connect to).
        #[arg(long, value_name = "udp:HOST:PORT|tcp:PORT")]
        nmea_out: Option<crate::nmea::OutSpec>,
        /// Take own ship from NMEA 0183 (GGA/RMC, VTG, HDT, VHW) through the dead-reckoning
        /// filter: `file:PATH` (a recording, replayed scan by scan), `udp:PORT`,
        /// `tcp:HOST:PORT`, `serial:DEVICE@BAUD`.
        #[arg(long, value_name = "SOURCE", conflicts_with = "nmea_record")]
        nmea_in: Option<crate::nmea::InSpec>,
        /// Take own ship from the simulated bridge sensors as NMEA, through the
        /// dead-reckoning filter, and record the sentences to this file (`--nmea-in
        /// file:PATH` replays it with the same result).
        #[arg(long, value_name = "PATH")]
        nmea_record: Option<std::path::PathBuf>,
        /// Latitude and longitude of the local frame's origin, decimal degrees (for `TLL`
        /// and own-ship positions).
        #[arg(long, value_name = "LAT,LON", value_parser = crate::nmea::Origin::parse)]
        origin: Option<crate::nmea::Origin>,
    },
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
        /// Estimates: CSV t,x,y,vx,vy,px,py,ex,ey (GRNN adds manoeuvre).
        #[arg(long, value_name = "CSV")]
        output: PathBuf,
        /// Number type.
        #[arg(long, value_enum, default_value_t = replay::ScalarKind::F64)]
        scalar: replay::ScalarKind,
        /// Own-ship sensors for `--filter ttkf`: CSV t,gps_x,gps_y,gps_vx,gps_vy,loran_x,loran_y,speedlog,gyro (empty cell: not available).
        #[arg(long, value_name = "CSV")]
        nav: Option<PathBuf>,
        /// Radar range σ for `--filter ttkf`, m.
        #[arg(long, default_value_t = 20.0)]
        range_sd: f64,
        /// Radar bearing σ for `--filter ttkf`, degrees.
        #[arg(long, default_value_t = 0.5)]
        bearing_sd: f64,
    },
    /// GRNN against the CV Kalman and α-β filters on a manoeuvring target, and the GRNN
    /// manoeuvre detector's false alarms and delay (Monte Carlo).
    Compare {
        /// Monte Carlo runs.
        #[arg(long, default_value_t = 200)]
        runs: u64,
        /// Position noise per axis, m.
        #[arg(long, default_value_t = 5.0)]
        sigma: f64,
    },
    /// The IMO ARPA accuracy test (A.823 App. 2) by Monte Carlo: our EKFs and a least-squares plot.
    Arpa {
        /// Monte Carlo runs per scenario.
        #[arg(long, default_value_t = 500)]
        runs: u64,
    },
    /// Reruns the seed papers' experiments: DIR/report.md (paper figure beside ours) and plots.
    Reproduce {
        /// Experiments: all (default), abg-2drms, abge-sweep, thesis, grnn.
        #[arg(value_name = "NAME")]
        names: Vec<String>,
        /// Directory for report.md and the plots.
        #[arg(long, value_name = "DIR", default_value = "reproduce")]
        out: PathBuf,
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

/// Scenario names on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ScenarioArg {
    /// Targets scattered around own ship, a quarter in crossing pairs.
    OpenSea,
    /// Every target in a crossing pair.
    Crossing,
}

/// `--speedup X` or `--speedup max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Speedup(pub Option<f64>);

impl std::str::FromStr for Speedup {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "max" {
            return Ok(Speedup(None));
        }
        match s.parse::<f64>() {
            Ok(x) if x.is_finite() && x > 0.0 => Ok(Speedup(Some(x))),
            _ => Err(format!("`{s}`: expected a positive number or `max`")),
        }
    }
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
        let mut transport = link::open(&spec, &self.qemu_options())?;
        let mut client_timeout = None;
        if let Some(rate) = self.byte_errors {
            if !(0.0..=0.1).contains(&rate) {
                anyhow::bail!("--byte-errors {rate}: expected a probability up to 0.1");
            }
            eprintln!("link: damaging {rate} of the bytes on purpose");
            transport = Box::new(crate::faults::FaultyTransport::new(
                transport,
                crate::faults::FaultRates::byte_errors(rate),
                1,
            ));
            // A lost answer is noticed by its timeout when no damaged frame announces it.
            client_timeout = Some(std::time::Duration::from_millis(300));
        }
        let mut client = Client::new(transport);
        if let Some(t) = client_timeout {
            client.timeout = t;
            client.retries = 50;
        }
        Ok(client)
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
            nav,
            range_sd,
            bearing_sd,
        } => {
            if *filter == replay::FilterKind::Ttkf {
                let nav = nav
                    .as_ref()
                    .ok_or_else(|| anyhow::anyhow!("--filter ttkf needs --nav CSV"))?;
                if !(*range_sd > 0.0 && *bearing_sd > 0.0) {
                    anyhow::bail!("options --range-sd and --bearing-sd must be positive");
                }
                let noise = crate::replay_nav::RadarNoise {
                    range_sd_m: *range_sd,
                    bearing_sd_deg: *bearing_sd,
                };
                let n = crate::replay_nav::replay(input, nav, output, noise)?;
                eprintln!(
                    "replay: {n} radar fixes through the DRKF + TTKF -> {}",
                    output.display()
                );
                return Ok(ExitCode::SUCCESS);
            }
            if nav.is_some() {
                anyhow::bail!("option --nav applies to --filter ttkf only");
            }
            let spec = replay::FilterSpec::from_args(*filter, gains)?;
            let measurements = replay::read_measurements(input)?;
            let rows = replay::run(&spec, *scalar, &measurements)?;
            let manoeuvre_column = matches!(spec, replay::FilterSpec::Grnn(_));
            replay::write_estimates(output, &rows, manoeuvre_column)?;
            eprintln!(
                "replay: {} measurements through {:?} ({:?}) -> {}",
                rows.len(),
                spec,
                scalar,
                output.display()
            );
            Ok(ExitCode::SUCCESS)
        }
        Command::Demo {
            scenario,
            targets,
            seed,
            speedup,
            duration,
            plain,
            filter,
            nmea_out,
            nmea_in,
            nmea_record,
            origin,
        } => {
            if !(duration.is_finite() && *duration > 0.0) {
                anyhow::bail!("--duration {duration}: must be a positive number of seconds");
            }
            let client = cli.connect()?;
            let options = demo::DemoOptions {
                scenario: match scenario {
                    ScenarioArg::OpenSea => tracker_core::sim::ScenarioKind::OpenSea,
                    ScenarioArg::Crossing => tracker_core::sim::ScenarioKind::Crossing,
                },
                targets: *targets,
                seed: *seed,
                speedup: speedup.0,
                duration_s: *duration,
                filter: *filter,
            };
            let mut d = demo::Demo::new(client, options)?.with_nmea(&demo::NmeaOptions {
                out: nmea_out.clone(),
                own_ship_in: nmea_in.clone(),
                record: nmea_record.clone(),
                origin: origin.unwrap_or_default(),
            })?;
            let limits = target::AlarmLimits::default();
            let use_tui = !*plain && std::io::IsTerminal::is_terminal(&std::io::stdout());
            let summary = if use_tui {
                let mut state = display::DisplayState::new(cli.resolve_link().to_string());
                let scans = d.scans_planned();
                display::run_tui(&mut d, &mut state, speedup.0, scans)?;
                d.summary()
            } else {
                d.run(|v| {
                    let tentative = v
                        .tracks
                        .iter()
                        .filter(|t| t.status == tracker_core::icd::TrackStatus::Tentative)
                        .count();
                    let header = format!(
                        "scan {:>4}  t {:>6.1} s  plots {:>3}  targets tracked {:>3}  acquiring {:>3}",
                        v.sim.scan,
                        v.sim.time_ms as f64 / 1000.0,
                        v.sim.plots.len(),
                        v.targets.len(),
                        tentative
                    );
                    if *plain {
                        println!("{header}");
                        print!("{}", target::table(&v.targets, &limits));
                    } else if v.sim.scan % 24 == 0 {
                        println!("{header}");
                    }
                })?
            };
            let mut host_times = d.host_times().to_vec();
            host_times.sort();
            let mean =
                host_times.iter().sum::<std::time::Duration>() / host_times.len().max(1) as u32;
            let max = host_times.last().copied().unwrap_or_default();
            println!(
                "\n== summary ({} link, filter {:?}) ==",
                cli.resolve_link(),
                filter
            );
            println!("{}", summary.report());
            if let Some(c) = d.nmea_counts() {
                println!("own-ship NMEA: {c}");
            }
            for event in d.events() {
                println!("event: {event}");
            }
            println!(
                "host time per scan (link included): mean {:.2} ms, max {:.2} ms",
                mean.as_secs_f64() * 1e3,
                max.as_secs_f64() * 1e3
            );
            let stats = d.client().stats();
            println!(
                "link: {} frames sent, {} received, {} damaged, {} requests retried",
                stats.frames_sent, stats.frames_received, stats.frames_damaged, stats.retries
            );
            Ok(ExitCode::SUCCESS)
        }
        Command::Compare { runs, sigma } => {
            let (scores, detector) = compare::run(*runs, *sigma)?;
            print!("{}", compare::report(*runs, *sigma, &scores, &detector));
            Ok(ExitCode::SUCCESS)
        }
        Command::Arpa { runs } => {
            let table = crate::arpa::run(*runs)?;
            print!("{}", crate::arpa::report(*runs, &table));
            let missed = crate::arpa::missed(&table);
            for m in &missed {
                println!("{m}");
            }
            let ok = missed.iter().all(|m| m.out_of_reach());
            Ok(if ok {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            })
        }
        Command::Reproduce { names, out } => {
            let report = reproduce::run(names, out)?;
            print!("{report}");
            eprintln!("written: {}", out.join("report.md").display());
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
