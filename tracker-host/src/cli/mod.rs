//! The command line: `tracker-host [--link …] <command> …`, parsed with `clap` and
//! dispatched: the product's commands to [`crate::app`], the lab's to [`crate::lab`].

pub mod args;

use std::ffi::OsString;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::builder::{PossibleValuesParser, TypedValueParser};
use clap::{Parser, Subcommand};

use crate::app::run::Run;
use crate::app::{demo, track};
use crate::display::plain::{Plain, PlainMode};
use crate::lab::{arpa, bench_mcu, compare, link_budget, precision, replay, replay_nav, reproduce};
use crate::link::faults::{FaultRates, FaultyTransport};
use crate::link::qemu::{self, QemuOptions};
use crate::link::{self, check, Client, LinkSpec};
use crate::source::radar::RadarOptions;
use crate::source::simulator::SimulatorOptions;
use args::RunArgs;

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

    /// How long to wait for the device's answer before asking again, s (default 5; each
    /// request is asked up to 6 times).
    #[arg(long, allow_negative_numbers = true, global = true, value_name = "SECONDS", value_parser = link_timeout_s)]
    pub link_timeout: Option<f64>,

    /// Damage the link on purpose: this probability per byte, both ways, of a flipped bit
    /// (80 %), a lost byte (10 %) or a repeated one (10 %). For testing; the host retries.
    #[arg(long, allow_negative_numbers = true, global = true, value_name = "RATE", value_parser = byte_error_rate)]
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
        /// Number of targets (at most 64).
        #[arg(long, allow_negative_numbers = true, default_value_t = 40)]
        targets: usize,
        /// Seed of the scenario.
        #[arg(long, allow_negative_numbers = true, default_value_t = 1)]
        seed: u64,
        /// Simulated duration, s (default 600; with `--nmea-in file:`, the recording's length).
        #[arg(long, allow_negative_numbers = true)]
        duration: Option<f64>,
        /// Write the simulation's truth to this file (the truth file format `track --truth`
        /// reads: `t_s,target,east_m,north_m,vx_mps,vy_mps,detected`, own ship as target 0).
        #[arg(long, value_name = "PATH")]
        record_truth: Option<PathBuf>,
        /// See the ships through a synthetic radar (spokes: beam, pulse, noise, sea clutter)
        /// and the plot extractor instead of the plot model; the summary adds the plots'
        /// detection probability, false plots and position error.
        #[arg(long)]
        video: bool,
        /// Real traffic: recorded AIS position reports (`Time,MMSI,Latitude_degrees,
        /// Longitude_degrees,COG_degrees,SOG_knots`, Stone Soup's Solent file) as the truth;
        /// own ship follows --own-mmsi, the others are targets seen by the radar model and
        /// heard on AIS; the summary scores radar/AIS pairing too.
        #[arg(
            long,
            value_name = "PATH",
            requires = "own_mmsi",
            conflicts_with = "video"
        )]
        ais_truth: Option<PathBuf>,
        /// With --ais-truth: own ship's MMSI.
        #[arg(
            long,
            allow_negative_numbers = true,
            value_name = "MMSI",
            requires = "ais_truth"
        )]
        own_mmsi: Option<u32>,
        /// With --ais-truth: start this many seconds after the file's first report (default:
        /// own ship's first report).
        #[arg(long, allow_negative_numbers = true, value_name = "S", requires = "ais_truth", value_parser = args::non_negative)]
        start: Option<f64>,
        /// With --ais-truth: a vessel still at both ends of a silence (under 1 kn at both
        /// reports and between them: moored) stays in the truth across silences up to this
        /// long, s, and its reports are sent as moored (at least 120, any vessel's gap, the
        /// default: out between its reports). Moored class A ships report every 3 minutes
        /// (ITU-R M.1371); 400 keeps them in, as a radar sees them.
        #[arg(
            long,
            allow_negative_numbers = true,
            value_name = "S",
            requires = "ais_truth"
        )]
        moored_gap: Option<f64>,
        /// How the run is shown, own ship, outputs.
        #[command(flatten)]
        run: RunArgs,
    },
    /// The tracker on recorded plots (a plots file; see the README for its columns) or on
    /// a radar (spokes from a capture or live, plots extracted), with the same display,
    /// table and outputs as `demo`; given the truth, the same scored summary. With
    /// `--nmea-in` alone (no radar): own ship and the AIS targets, their table and CPA/TCPA
    /// alarm.
    #[command(group = clap::ArgGroup::new("input").args(["plots", "radar"]))]
    Track {
        /// The plots file.
        #[arg(long, value_name = "PATH")]
        plots: Option<PathBuf>,
        /// The truth file, to score the tracks against.
        #[arg(long, value_name = "PATH", requires = "plots")]
        truth: Option<PathBuf>,
        /// A radar: `pcap:PATH` (a capture, pcap or pcapng, gzip too), `navico[@IFACE_IP]`
        /// or `garmin[@IFACE_IP]` (live, the spoke multicast joined on the interface with
        /// that address). Own ship from the capture's NMEA unless --nmea-in.
        #[arg(long, value_name = "pcap:PATH|navico[@IP]|garmin[@IP]")]
        radar: Option<crate::radar::RadarSpec>,
        /// With --radar: own ship's heading, degrees true in [0, 360), when neither the radar
        /// nor NMEA gives one (a moored ship), turned by own ship's yaw measured from the
        /// picture (a moored ship swings); without any heading, plots are not tracked.
        #[arg(long, allow_negative_numbers = true, value_name = "DEG", requires = "radar", value_parser = args::heading_deg)]
        heading_deg: Option<f64>,
        /// The plots' accuracy, m (one axis), for the filters and gates. With --radar by
        /// default 0.25 % of the range scale in use, 2 to 40 m (live: 40 m until the first
        /// rotation); with --plots the file's `plot_sigma_m` (which --record-plots writes),
        /// else 40 m.
        #[arg(long, allow_negative_numbers = true, value_name = "M", value_parser = args::positive_f32)]
        plot_sigma_m: Option<f32>,
        /// How the run is shown, own ship, outputs.
        #[command(flatten)]
        run: RunArgs,
    },
    /// Check the link: handshake, echo frames of every size, bad input rejected, counters.
    LinkCheck {
        /// Good frames to send (at least 1); each bad input is then followed by one more,
        /// to show the link recovered, and the report counts those too.
        #[arg(long, allow_negative_numbers = true, default_value_t = 1000, value_parser = at_least_one::<usize>)]
        frames: usize,
        /// Seed for frame sizes and contents.
        #[arg(long, allow_negative_numbers = true, default_value_t = 1)]
        seed: u64,
    },
    /// Run one single-target filter over recorded measurements (CSV `t,x,y` in, CSV out).
    Replay {
        /// The filter.
        #[arg(long, value_parser = replay_filter_parser())]
        filter: replay::ReplayFilter,
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
        #[arg(long, allow_negative_numbers = true, default_value_t = 20.0)]
        range_sd: f64,
        /// Radar bearing σ for `--filter ttkf`, degrees.
        #[arg(long, allow_negative_numbers = true, default_value_t = 0.5)]
        bearing_sd: f64,
    },
    /// GRNN against the CV Kalman and α-β filters on a manoeuvring target, and the GRNN
    /// manoeuvre detector's false alarms and delay (Monte Carlo).
    Compare {
        /// Monte Carlo runs.
        #[arg(long, allow_negative_numbers = true, default_value_t = 200, value_parser = at_least_one::<u64>)]
        runs: u64,
        /// Position noise per axis, m.
        #[arg(long, allow_negative_numbers = true, default_value_t = 5.0, value_parser = args::positive)]
        sigma: f64,
    },
    /// The IMO ARPA accuracy test (A.823 App. 2) by Monte Carlo: our EKFs and a least-squares plot.
    Arpa {
        /// Monte Carlo runs per scenario.
        #[arg(long, allow_negative_numbers = true, default_value_t = 500, value_parser = at_least_one::<u64>)]
        runs: u64,
    },
    /// Reruns the seed papers' experiments: DIR/report.md (paper figure beside ours) and plots.
    Reproduce {
        /// Experiments: all (default), abg-2drms, abge-sweep, thesis, grnn, drttkf.
        #[arg(value_name = "NAME")]
        names: Vec<String>,
        /// Directory for report.md and the plots.
        #[arg(long, value_name = "DIR", default_value = "reproduce")]
        out: PathBuf,
    },
    /// How far f32 and fixed point drift from f64 on a long run, per filter.
    Precision {
        /// Scans in the run.
        #[arg(long, allow_negative_numbers = true, default_value_t = 100_000, value_parser = at_least_one::<usize>)]
        scans: usize,
        /// Noise seed.
        #[arg(long, allow_negative_numbers = true, default_value_t = 1)]
        seed: u64,
    },
    /// Instruction counts on the emulated Cortex-M4F, as CSV.
    BenchMcu {
        /// Bench ELF to run, repeatable (default: the workspace's release builds of the
        /// `bench`, `bench-nav` and `bench-radar` binaries, built first).
        #[arg(long, value_name = "ELF")]
        elf: Vec<PathBuf>,
    },
    /// Bytes on the link a scan, and the largest picture a serial line carries.
    LinkBudget {
        /// Line speeds, baud (8N1).
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "115200,38400",
            value_parser = at_least_one::<u32>
        )]
        baud: Vec<u32>,
    },
}

/// `--link-timeout`: 0.01 to 600 s.
fn link_timeout_s(s: &str) -> Result<f64, String> {
    args::number(s, |v| (0.01..=600.0).contains(&v), "0.01 to 600 seconds")
}

/// `--byte-errors`: a probability up to 0.1 (more, and hardly a frame gets through).
fn byte_error_rate(s: &str) -> Result<f64, String> {
    args::number(s, |v| (0.0..=0.1).contains(&v), "a probability up to 0.1")
}

/// A count of 1 or more (runs, scans, baud).
fn at_least_one<T: std::str::FromStr + PartialOrd + From<u8>>(s: &str) -> Result<T, String> {
    match s.parse::<T>() {
        Ok(n) if n >= T::from(1) => Ok(n),
        _ => Err(format!("`{s}`: expected a whole number, 1 or more")),
    }
}

fn replay_filter_parser() -> impl TypedValueParser<Value = replay::ReplayFilter> {
    PossibleValuesParser::new(replay::ReplayFilter::names())
        .try_map(|name| name.parse::<replay::ReplayFilter>())
}

/// Scenario names on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ScenarioArg {
    /// Targets scattered around own ship, a quarter in crossing pairs.
    OpenSea,
    /// Every target in a crossing pair.
    Crossing,
    /// Every target in a merging pair: side by side inside one resolution cell, then apart.
    Merging,
}

impl ScenarioArg {
    fn kind(self) -> tracker_core::sim::ScenarioKind {
        match self {
            ScenarioArg::OpenSea => tracker_core::sim::ScenarioKind::OpenSea,
            ScenarioArg::Crossing => tracker_core::sim::ScenarioKind::Crossing,
            ScenarioArg::Merging => tracker_core::sim::ScenarioKind::Merging,
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

    /// The client over the link the run uses, and that link (in-process when QEMU was
    /// chosen, not asked for, and no firmware could be built for it).
    fn connect(&self) -> anyhow::Result<(Client, LinkSpec)> {
        let spec = self.resolve_link();
        let how = match (&self.link, &spec) {
            (None, LinkSpec::Qemu) => " (QEMU found; --link inproc runs without it)",
            (None, _) => " (qemu-system-arm not found; running the core in-process)",
            _ => "",
        };
        eprintln!("link: {spec}{how}");
        let mut options = self.qemu_options();
        let mut spec = spec;
        // QEMU chosen because it is installed, not asked for (no --link, no --firmware):
        // without a firmware to run (no toolchain to build it, no source tree) the demo still
        // runs, in-process. QEMU's own failures stay errors.
        if self.link.is_none() && spec == LinkSpec::Qemu && options.firmware.is_none() {
            match qemu::firmware_elf(qemu::FIRMWARE_BIN, None) {
                Ok(elf) => options.firmware = Some(elf),
                Err(e) => {
                    eprintln!(
                        "link: no firmware to run in QEMU ({e:#}); running the core \
                         in-process instead (--link qemu to insist)"
                    );
                    spec = LinkSpec::Inproc;
                }
            }
        }
        let mut transport = link::open(&spec, &options)?;
        let mut client_timeout = None;
        if let Some(rate) = self.byte_errors {
            eprintln!("link: damaging {rate} of the bytes on purpose");
            transport = Box::new(FaultyTransport::new(
                transport,
                FaultRates::byte_errors(rate),
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
        if let Some(s) = self.link_timeout {
            client.timeout = std::time::Duration::from_secs_f64(s);
        }
        Ok((client, spec))
    }
}

/// Parses `args` and runs the command; what the binary's `main` does.
///
/// # Errors
/// The command failed: the message says why (a file's line and column, a link that did
/// not answer, …).
pub fn run<I, T>(args: I) -> anyhow::Result<ExitCode>
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let args: Vec<OsString> = args.into_iter().map(Into::into).collect();
    let command: Vec<String> = args
        .iter()
        .map(|a| a.to_string_lossy().into_owned())
        .collect();
    let cli = match Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            // --help and --version are successes; the rest are usage errors (exit 2).
            let _ = e.print();
            return Ok(ExitCode::from(e.exit_code() as u8));
        }
    };
    match &cli.command {
        Command::Demo {
            scenario,
            targets,
            seed,
            duration,
            record_truth,
            video,
            ais_truth,
            own_mmsi,
            start,
            moored_gap,
            run,
        } => {
            if run.fixed_position {
                anyhow::bail!("--fixed-position is for a radar that does not move (track --radar): the demo's own ship moves on its own track");
            }
            // A live source's sentences come in real time: the simulation run faster went
            // back in time every few scans and ended early (a new user's trial).
            if run.speedup.is_some()
                && run
                    .nmea_in
                    .first()
                    .is_some_and(|s| !matches!(s, crate::nmea::InSpec::File(_)))
            {
                anyhow::bail!("--speedup is for a recording or the simulation alone: with a live --nmea-in the demo runs in real time, as its sentences come");
            }
            if let Some(d) = duration {
                if !(d.is_finite() && *d > 0.0) {
                    anyhow::bail!("--duration {d}: must be a positive number of seconds");
                }
            }
            let still_gap_s = moored_gap.unwrap_or(crate::source::ais_truth::MAX_GAP_S);
            if !(still_gap_s.is_finite() && still_gap_s >= crate::source::ais_truth::MAX_GAP_S) {
                anyhow::bail!(
                    "--moored-gap {still_gap_s}: must be at least {} s (any vessel's gap)",
                    crate::source::ais_truth::MAX_GAP_S
                );
            }
            if *targets > tracker_core::sim::MAX_TARGETS {
                anyhow::bail!(
                    "--targets {targets}: the simulator holds at most {}",
                    tracker_core::sim::MAX_TARGETS
                );
            }
            let read: Vec<(&'static str, &std::path::Path)> = ais_truth
                .iter()
                .map(|p| ("--ais-truth", p.as_path()))
                .collect();
            run.check_outputs(record_truth.as_deref(), &read)?;
            let options = demo::DemoOptions {
                simulator: SimulatorOptions {
                    scenario: scenario.kind(),
                    targets: *targets,
                    seed: *seed,
                    duration_s: duration.unwrap_or(600.0),
                    // Live: the scans' UTC is now.
                    epoch_s: (crate::utc::now_s() * 1000.0).round() / 1000.0,
                },
                duration_from_recording: duration.is_none(),
                filter: run.filter,
                association: run.association.into(),
                alarms: run.alarms(),
                own_ship: run.own_ship(),
                outputs: run.outputs(record_truth.clone()),
                video: *video,
                ais_truth: ais_truth.as_ref().map(|path| {
                    crate::source::ais_truth::AisTruthOptions {
                        path: path.clone(),
                        own_mmsi: own_mmsi.unwrap_or_default(),
                        start_s: *start,
                        duration_s: *duration,
                        seed: *seed,
                        still_gap_s,
                    }
                }),
            };
            // Before the wiring: Ctrl-C while it waits for a live source's first fix ends
            // the run with its summary too.
            crate::app::interrupt::install().context("installing the Ctrl-C handler")?;
            let (client, link) = cli.connect()?;
            let tracking = demo::start(client, &options)?;
            track_to_end(&link, tracking, run, &command, true)
        }
        Command::Track {
            plots,
            truth,
            radar,
            heading_deg,
            plot_sigma_m,
            run,
        } => {
            let input = match (plots, radar) {
                (Some(_), _) if run.fixed_position => anyhow::bail!(
                    "--fixed-position is for a radar that does not move (track --radar): a plots file gives own ship's position in its own_east_m and own_north_m"
                ),
                (Some(_), _) if heading_deg.is_some() => anyhow::bail!(
                    "--heading-deg is for a radar (track --radar): a plots file gives own ship's heading in its heading_deg column"
                ),
                (Some(plots), _) => track::TrackInput::Plots {
                    plots: plots.clone(),
                    truth: truth.clone(),
                    plot_sigma_m: *plot_sigma_m,
                },
                (None, Some(spec)) => {
                    let mut o = RadarOptions::new(spec.clone());
                    o.fixed_heading_rad =
                        heading_deg.map(|d| tracker_core::geo::wrap_2pi(d.to_radians() as f32));
                    o.plot_sigma_m = *plot_sigma_m;
                    track::TrackInput::Radar(o)
                }
                (None, None) if run.nmea_in.is_empty() => anyhow::bail!(
                    "track needs one of --radar (a radar), --plots (recorded plots), or --nmea-in alone (own ship and AIS targets, no radar)"
                ),
                (None, None) if heading_deg.is_some() || plot_sigma_m.is_some() => anyhow::bail!(
                    "--heading-deg and --plot-sigma-m are for a radar (track --radar); --nmea-in alone has no radar"
                ),
                (None, None) => track::TrackInput::NoRadar,
            };
            let capture = match radar {
                Some(crate::radar::RadarSpec::Capture(p)) => Some(("--radar", p.as_path())),
                _ => None,
            };
            let read: Vec<(&'static str, &std::path::Path)> = [
                plots.as_deref().map(|p| ("--plots", p)),
                truth.as_deref().map(|p| ("--truth", p)),
                capture,
            ]
            .into_iter()
            .flatten()
            .collect();
            run.check_outputs(None, &read)?;
            let options = track::TrackOptions {
                input,
                filter: run.filter,
                association: run.association.into(),
                alarms: run.alarms(),
                own_ship: run.own_ship(),
                outputs: run.outputs(None),
            };
            // Before the wiring: Ctrl-C while it waits for a live source's first fix ends
            // the run with its summary too.
            crate::app::interrupt::install().context("installing the Ctrl-C handler")?;
            let (client, link) = cli.connect()?;
            let tracking = track::start(client, &options)?;
            track_to_end(&link, tracking, run, &command, false)
        }
        Command::LinkCheck { frames, seed } => {
            let (mut client, _) = cli.connect()?;
            let report = check::run(
                &mut client,
                &check::LinkCheckOptions {
                    frames: *frames,
                    seed: *seed,
                },
            )?;
            say(&format!("{}\n", report.summary()));
            for f in &report.failures {
                say(&format!("failure: {f}\n"));
            }
            Ok(exit(report.passed()))
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
            crate::record::check_writable(output).context("--output")?;
            let kind = match filter {
                replay::ReplayFilter::Ttkf => {
                    let nav = nav
                        .as_ref()
                        .ok_or_else(|| anyhow::anyhow!("--filter ttkf needs --nav CSV"))?;
                    if !(*range_sd > 0.0 && *bearing_sd > 0.0) {
                        anyhow::bail!("options --range-sd and --bearing-sd must be positive");
                    }
                    let noise = replay_nav::RadarNoise {
                        range_sd_m: *range_sd,
                        bearing_sd_deg: *bearing_sd,
                    };
                    let n = replay_nav::replay(input, nav, output, noise)?;
                    eprintln!(
                        "replay: {n} radar fixes through the DRKF + TTKF -> {}",
                        output.display()
                    );
                    return Ok(ExitCode::SUCCESS);
                }
                replay::ReplayFilter::Track(kind) => *kind,
            };
            if nav.is_some() {
                anyhow::bail!("option --nav applies to --filter ttkf only");
            }
            let config = replay::config_from_args(kind, gains)?;
            let measurements = replay::read_measurements(input)?;
            let rows = replay::run(&config, *scalar, &measurements)?;
            replay::write_estimates(
                output,
                &rows,
                kind == tracker_core::filter::FilterKind::Grnn,
            )?;
            eprintln!(
                "replay: {} measurements through {} in {} -> {}",
                rows.len(),
                replay::describe(&config),
                scalar.name(),
                output.display()
            );
            Ok(ExitCode::SUCCESS)
        }
        Command::Compare { runs, sigma } => {
            let (scores, detector) = compare::run(*runs, *sigma)?;
            say(&compare::report(*runs, *sigma, &scores, &detector));
            let turns = crate::lab::turns::run(*runs)?;
            say(&crate::lab::turns::report(*runs, &turns));
            Ok(ExitCode::SUCCESS)
        }
        Command::Arpa { runs } => {
            let table = arpa::run(*runs)?;
            say(&arpa::report(*runs, &table));
            let missed = arpa::missed(&table);
            for m in &missed {
                say(&format!("{m}\n"));
            }
            Ok(exit(missed.iter().all(|m| m.out_of_reach())))
        }
        Command::Reproduce { names, out } => {
            let report = reproduce::run(names, out)?;
            say(&report);
            eprintln!("written: {}", out.join("report.md").display());
            Ok(ExitCode::SUCCESS)
        }
        Command::Precision { scans, seed } => {
            println!(
                "{scans} scans at 2.5 s, 70 to 99 km from the origin, 15 m noise, seed {seed}"
            );
            print!("{}", precision::table(&precision::run(*scans, *seed)?));
            Ok(ExitCode::SUCCESS)
        }
        Command::BenchMcu { elf } => {
            let rows = bench_mcu::run(elf)?;
            say(&bench_mcu::to_csv(&rows));
            Ok(ExitCode::SUCCESS)
        }
        Command::LinkBudget { baud } => {
            say(&link_budget::report(baud));
            Ok(ExitCode::SUCCESS)
        }
    }
}

/// Writes to standard output; a closed one (`| head`) is not a failure of the command
/// (`println!` would panic on it).
pub fn say(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    let _ = out.write_all(text.as_bytes()).and_then(|()| out.flush());
}

fn exit(ok: bool) -> ExitCode {
    if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

/// Runs a wired tracking run to its end: the radar display in a terminal (titled as a
/// simulation's with `simulated`; without a radar, the AIS target table shown first), else
/// the plain table (`--plain`) or progress lines; then the summary,
/// and the JSON summary if asked.
fn track_to_end(
    link: &LinkSpec,
    mut tracking: Run,
    args: &RunArgs,
    command: &[String],
    simulated: bool,
) -> anyhow::Result<ExitCode> {
    let limits = tracking.session().config().alarms;
    let radar = tracking.has_radar();
    let link = link.to_string();
    // Ctrl-C ends the run after the scan in hand, with its summary; twice, at once (the
    // handler is installed before the run is wired).
    let use_tui = !args.plain && std::io::IsTerminal::is_terminal(&std::io::stdout());
    if use_tui {
        let mut state = crate::display::DisplayState::new(link.clone());
        state.limits = limits;
        state.associated = args.associated_symbol.into();
        state.simulated = simulated;
        state.ais_table = !radar;
        let ran = crate::display::run_tui(&mut tracking, &mut state, args.speedup());
        // Finished whatever happened: plotters are told the targets are gone, recordings
        // flushed.
        let finished = tracking.finish();
        ran?;
        finished?;
    } else {
        let mode = if args.plain {
            PlainMode::Table
        } else {
            PlainMode::Progress { every: 24 }
        };
        tracking.add_sink(Box::new(
            Plain::new(mode, limits)
                .with_simulated(simulated)
                .with_radar(radar),
        ));
        if let Err(e) = tracking.run_to_end(args.speedup(), |_| {}) {
            let _ = tracking.finish();
            return Err(e);
        }
    }
    let mut report = tracking.report(&link);
    report.command = command.to_vec();
    // A closed standard output (`| head`) is not a failure of the run.
    let _ = std::io::Write::write_all(
        &mut std::io::stdout(),
        format!("\n{}", report.text()).as_bytes(),
    );
    if let Some(path) = &args.summary_json {
        std::fs::write(path, report.json() + "\n")
            .with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(ExitCode::SUCCESS)
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
    use std::io::Write as _;

    #[test]
    fn link_is_accepted_before_or_after_the_command() {
        let a = Cli::try_parse_from(["t", "--link", "inproc", "link-check"]).unwrap();
        let b = Cli::try_parse_from(["t", "link-check", "--link", "inproc"]).unwrap();
        assert_eq!(a.link, Some(LinkSpec::Inproc));
        assert_eq!(b.link, Some(LinkSpec::Inproc));
        assert!(Cli::try_parse_from(["t", "link-check", "--link", "usb"]).is_err());
    }

    #[test]
    fn a_southern_western_origin_parses_as_typed() {
        let c = Cli::try_parse_from(["t", "demo", "--origin", "-33.9,151.2"]).unwrap();
        let Command::Demo { run, .. } = c.command else {
            panic!("{:?}", c.command)
        };
        assert_eq!(run.origin.map(|o| o.lat_deg), Some(-33.9));
        let c = Cli::try_parse_from(["t", "track", "--plots", "p.csv", "--filter", "sswt"]);
        assert!(c.is_ok());
        assert!(Cli::try_parse_from(["t", "demo", "--filter", "kalman"]).is_err());
    }

    /// `--fixed-position` needs `--origin` (the position it fixes), and is refused where own
    /// ship's position comes with the plots (`demo`, a plots file).
    #[test]
    fn a_fixed_position_needs_an_origin_and_a_radar() {
        let radar = ["t", "track", "--radar", "pcap:x.pcap", "--fixed-position"];
        let e = Cli::try_parse_from(radar).unwrap_err().to_string();
        assert!(e.contains("--origin"), "{e}");
        assert!(Cli::try_parse_from([&radar[..], &["--origin", "50.8,-1.3"]].concat()).is_ok());
        let live = ["t", "demo", "--nmea-in", "udp:10110", "--speedup", "10"];
        let e = super::run(live).unwrap_err().to_string();
        assert!(e.contains("--speedup is for a recording"), "{e}");
        for args in [
            &["t", "demo", "--fixed-position", "--origin", "50.8,-1.3"][..],
            &[
                "t",
                "track",
                "--plots",
                "p.csv",
                "--fixed-position",
                "--origin",
                "50.8,-1.3",
            ],
        ] {
            let e = super::run(args).unwrap_err().to_string();
            assert!(e.contains("--fixed-position is for a radar"), "{e}");
        }
        // … and `--heading-deg` likewise (a plots file's heading is in the file; it was
        // taken and ignored).
        let args = ["t", "track", "--plots", "p.csv", "--heading-deg", "10"];
        let e = super::run(args).unwrap_err().to_string();
        assert!(e.contains("--heading-deg is for a radar"), "{e}");
    }

    #[test]
    fn nmea_in_may_be_given_more_than_once() {
        let c = Cli::try_parse_from([
            "t",
            "demo",
            "--nmea-in",
            "udp:10110",
            "--nmea-in",
            "serial:/dev/ttyUSB1@38400",
        ])
        .unwrap();
        let Command::Demo { run, .. } = c.command else {
            panic!("{:?}", c.command)
        };
        let own = run.own_ship();
        assert_eq!(own.nmea_in, Some(crate::nmea::InSpec::Udp(10110)));
        assert_eq!(
            own.nmea_in_more,
            [crate::nmea::InSpec::Serial("/dev/ttyUSB1".into(), 38400)]
        );
        assert_eq!(run.speedup(), Some(1.0), "live: real time");
    }

    #[test]
    fn a_recording_without_a_date_is_taken_as_today() {
        // GGA alone: times of day, no date.
        let mut file = tempfile::NamedTempFile::new().unwrap();
        for t in ["123519", "123520", "123521"] {
            let gga = format!("GPGGA,{t},4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,");
            writeln!(file, "{}", crate::nmea::sentence(&gga).trim_end()).unwrap();
        }
        let spec = format!("file:{}", file.path().display());
        let c = Cli::try_parse_from(["t", "demo", "--nmea-in", &spec]).unwrap();
        let Command::Demo { run, .. } = c.command else {
            panic!("{:?}", c.command)
        };
        let today = crate::app::today();
        let track =
            crate::own_ship::recording::RecordedTrack::read(file.path(), &run.own_ship().nmea)
                .unwrap();
        // (Or tomorrow, had midnight passed since `today`.)
        let day = crate::own_ship::clock::day_of_s(track.start_s());
        assert!(day == today || day == today + 1, "day {day}, today {today}");
        assert_eq!(track.start_s().rem_euclid(86_400.0).round(), 45_319.0);
        // GLL without a time (the HALO network's recording): today's too, at its start.
        let mut untimed = tempfile::NamedTempFile::new().unwrap();
        let gll = crate::nmea::sentence("GPGLL,4807.038,N,01131.000,E,,A,A");
        writeln!(untimed, "{}", gll.trim_end()).unwrap();
        let track =
            crate::own_ship::recording::RecordedTrack::read(untimed.path(), &run.own_ship().nmea)
                .unwrap();
        let day = crate::own_ship::clock::day_of_s(track.start_s());
        assert!(day == today || day == today + 1, "day {day}, today {today}");
    }

    #[test]
    fn angles_and_counts_out_of_range_are_refused_as_they_are_parsed() {
        let radar = ["t", "track", "--radar", "pcap:x.pcap"];
        let with = |base: &[&str], arg: String| {
            let args: Vec<String> = base.iter().map(|a| a.to_string()).chain([arg]).collect();
            Cli::try_parse_from(args)
        };
        for (base, option, bad, good) in [
            (
                &["t", "demo"][..],
                "--magnetic-variation",
                &["400", "-181", "NaN", "inf", "east"][..],
                &["-180", "3.5", "180"][..],
            ),
            (
                &radar,
                "--heading-deg",
                &["400", "360", "-1", "NaN"],
                &["0", "359.9"],
            ),
            (
                &radar,
                "--plot-sigma-m",
                &["0", "-5", "NaN", "1e39"],
                &["12"],
            ),
            (
                &["t", "link-budget"],
                "--baud",
                &["0", "9600,0", "-1"],
                &["9600,300"],
            ),
            (&["t", "compare"], "--runs", &["0"], &["1"]),
            (&["t", "compare"], "--sigma", &["0", "-1", "NaN"], &["5"]),
            (&["t", "arpa"], "--runs", &["0"], &["1"]),
            (&["t", "precision"], "--scans", &["0"], &["1"]),
            (&["t", "link-check"], "--frames", &["0", "-1"], &["1"]),
            (
                &["t", "link-check"],
                "--byte-errors",
                &["0.5", "-0.1"],
                &["0.01"],
            ),
            (
                &["t", "link-check"],
                "--link-timeout",
                &["0", "NaN", "601"],
                &["2"],
            ),
        ] {
            for value in bad {
                let arg = format!("{option}={value}");
                let e = with(base, arg.clone()).unwrap_err();
                assert_eq!(e.kind(), clap::error::ErrorKind::ValueValidation, "{arg}");
                assert!(e.to_string().contains("expected"), "{arg}: {e}");
            }
            for value in good {
                let arg = format!("{option}={value}");
                assert!(with(base, arg.clone()).is_ok(), "{arg}");
            }
        }
        let c = Cli::try_parse_from(["t", "demo", "--magnetic-variation", "-3"]).unwrap();
        let Command::Demo { run, .. } = c.command else {
            panic!("{:?}", c.command)
        };
        assert_eq!(run.magnetic_variation, Some(-3.0));
    }

    #[test]
    fn every_output_path_is_checked_before_anything_runs() {
        // The command line after `tracker-host --link inproc`.
        let inproc = |args: &[&str]| run(["t", "--link", "inproc"].iter().chain(args));
        let dir = tempfile::tempdir().unwrap();
        let nowhere = dir.path().join("no-such-dir");
        let in_nowhere = |name: &str| nowhere.join(name).display().to_string();
        let txt = dir.path().join("s.txt").display().to_string();
        for (option, path, told) in [
            ("--summary-json", in_nowhere("s.json"), "does not exist"),
            ("--snapshot", in_nowhere("s.png"), "does not exist"),
            ("--snapshot", txt, "must end in .png"),
            ("--record-plots", in_nowhere("p.csv"), "does not exist"),
            ("--record-tracks", in_nowhere("t.csv"), "does not exist"),
            ("--record-truth", in_nowhere("t.csv"), "does not exist"),
            ("--nmea-record", in_nowhere("n.nmea"), "does not exist"),
            (
                "--summary-json",
                dir.path().display().to_string(),
                "is a directory",
            ),
        ] {
            // 10 000 s of demo: refused before it, by the check's words (a failure at the
            // end would say "writing …"), not by the clock.
            let e = inproc(&["demo", "--duration", "10000", option, path.as_str()]).unwrap_err();
            let e = format!("{e:#}");
            assert!(
                e.starts_with(option) && e.contains(told),
                "{option} {path}: {e}"
            );
        }
        // One file named by two outputs: the later would overwrite the earlier.
        let same = dir.path().join("out.csv").display().to_string();
        let e = inproc(&[
            "demo",
            "--duration",
            "10000",
            "--record-plots",
            &same,
            "--record-tracks",
            &same,
        ])
        .unwrap_err();
        assert!(
            format!("{e:#}").starts_with("--record-plots and --record-tracks both name"),
            "{e:#}"
        );
        // The same file by another name.
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let other_name = dir.path().join("sub/../out.csv").display().to_string();
        let e = inproc(&[
            "demo",
            "--record-plots",
            &same,
            "--summary-json",
            &other_name,
        ])
        .unwrap_err();
        assert!(format!("{e:#}").contains("both name"), "{e:#}");
        std::fs::remove_dir(dir.path().join("sub")).unwrap();
        // An output on the recording being read: refused, the recording left as it was.
        let input = dir.path().join("in.csv");
        std::fs::write(
            &input,
            "scan,t_s,range_m,bearing_deg,own_east_m,own_north_m\n0,0,1500,45,0,0\n",
        )
        .unwrap();
        let before = std::fs::read(&input).unwrap();
        let e = inproc(&[
            "track",
            "--plots",
            input.to_str().unwrap(),
            "--record-tracks",
            input.to_str().unwrap(),
        ])
        .unwrap_err();
        assert!(
            format!("{e:#}").starts_with("--record-tracks names")
                && format!("{e:#}").contains("the file --plots reads"),
            "{e:#}"
        );
        assert_eq!(std::fs::read(&input).unwrap(), before);
        std::fs::remove_file(&input).unwrap();
        // Not regular files (a device) may take two outputs.
        inproc(&[
            "demo",
            "--duration",
            "5",
            "--plain",
            "--record-plots",
            "/dev/null",
            "--record-tracks",
            "/dev/null",
        ])
        .expect("two outputs to /dev/null");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "no trace"
        );
        let e = inproc(&[
            "track",
            "--plots",
            "no-such.csv",
            "--summary-json",
            &in_nowhere("s.json"),
        ])
        .unwrap_err();
        assert!(format!("{e:#}").starts_with("--summary-json"), "{e:#}");
    }

    #[test]
    fn a_moored_gap_shorter_than_any_vessels_is_refused_before_anything_runs() {
        // Refused by the check, or (120 and more) passing it and failing on the missing file.
        for (gap, refused) in [
            ("60", true),
            ("-1", true),
            ("NaN", true),
            ("inf", true),
            ("400", false),
        ] {
            let gap = format!("--moored-gap={gap}");
            let e = run([
                "t",
                "--link",
                "inproc",
                "demo",
                "--ais-truth",
                "no-such.csv",
                "--own-mmsi",
                "1",
                gap.as_str(),
            ])
            .unwrap_err();
            assert_eq!(
                e.to_string().contains("--moored-gap"),
                refused,
                "{gap}: {e}"
            );
        }
    }
}
