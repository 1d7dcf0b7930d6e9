//! The plots' accuracy the filters and gates are made for follows the source: a radar's is
//! its range scale's ([`plot_sigma_m`]), known to a live radar from its first spoke and
//! changed by the operator; the session remakes the device's configuration when it changes.

use tracker_core::filter::{FilterConfig, FilterKind};
use tracker_core::icd::{Plot, TrackerConfig};
use tracker_host::app::run::Run;
use tracker_host::link::{Client, InprocTransport};
use tracker_host::own_ship::{FromPlotSource, OwnShip};
use tracker_host::radar::RadarSpec;
use tracker_host::session::{Session, SessionConfig};
use tracker_host::source::radar::{plot_sigma_m, CaptureSurvey, RadarOptions, RadarPlotSource};
use tracker_host::source::{PlotSource, RadarScan, SourceScan};

mod realdata;

fn session(config: SessionConfig) -> Session {
    Session::start(Client::new(Box::new(InprocTransport::new())), config).unwrap()
}

/// The measurement variance of a Kalman configuration, m².
fn kalman_r_m2(c: &TrackerConfig) -> f64 {
    match c.filter {
        FilterConfig::KalmanCv(k) => k.r,
        other => panic!("not the CV Kalman: {other:?}"),
    }
}

#[test]
fn a_session_remakes_its_filters_for_a_new_plot_accuracy() {
    let mut s = session(SessionConfig::tracking_plots_of(FilterKind::KalmanCv, 40.0));
    assert_eq!(kalman_r_m2(&s.config().tracker), 1600.0);
    assert!(s.set_plot_sigma_m(5.0).unwrap());
    assert_eq!(s.config().tracker.plot_sigma_m, 5.0);
    assert_eq!(kalman_r_m2(&s.config().tracker), 25.0);
    assert!(
        s.events().iter().any(|e| e.contains("accuracy now 5.0 m")),
        "{:?}",
        s.events()
    );
    // Within 1 % of the accuracy in use: nothing sent, nothing said.
    let said = s.events().len();
    assert!(!s.set_plot_sigma_m(5.04).unwrap());
    assert_eq!(s.events().len(), said);
    // Not a distance: refused, the configuration kept.
    for bad in [0.0, -3.0, f32::NAN, f32::INFINITY] {
        assert!(s.set_plot_sigma_m(bad).is_err(), "{bad}");
    }
    assert_eq!(s.config().tracker.plot_sigma_m, 5.0);
    // A configuration made by hand is kept as it is.
    let mut hand = session(SessionConfig {
        filter_kind: None,
        ..SessionConfig::tracking_plots_of(FilterKind::KalmanCv, 40.0)
    });
    assert!(!hand.set_plot_sigma_m(5.0).unwrap());
    assert_eq!(hand.config().tracker.plot_sigma_m, 40.0);
}

/// Scans of one stationary plot whose accuracy changes as a radar's range scale would.
struct RangeChanging {
    scan: u32,
    sigmas_m: Vec<f32>,
}

impl PlotSource for RangeChanging {
    fn next_scan(&mut self) -> anyhow::Result<Option<SourceScan>> {
        if self.scan as usize >= self.sigmas_m.len() {
            return Ok(None);
        }
        self.scan += 1;
        Ok(Some(SourceScan {
            radar: RadarScan {
                scan: self.scan,
                time_s: 2.5 * f64::from(self.scan),
                plots: vec![Plot {
                    range_m: 500.0,
                    bearing_rad: 1.0,
                }],
            },
            own_ship: Some(OwnShip::at([0.0, 0.0], [0.0, 0.0])),
            ..SourceScan::default()
        }))
    }

    fn scan_period_s(&self) -> Option<f64> {
        Some(2.5)
    }

    fn scans_left(&self) -> Option<u64> {
        None
    }

    fn plot_sigma_m(&self) -> Option<f32> {
        self.scan
            .checked_sub(1)
            .and_then(|i| self.sigmas_m.get(i as usize).copied())
    }
}

#[test]
fn a_run_follows_its_sources_plot_accuracy_scan_by_scan() {
    // Started for plots of unknown origin (40 m), as a live radar is before its first spoke;
    // the source then tells 2 m (a short scale), then 21 m (a longer one).
    let source = RangeChanging {
        scan: 0,
        sigmas_m: vec![2.0, 2.0, 21.0, 21.0],
    };
    let config = SessionConfig::tracking_plots_of(FilterKind::KalmanCv, 40.0);
    let mut run = Run::new(
        Box::new(source),
        Box::new(FromPlotSource),
        session(config),
        Vec::new(),
    );
    let mut seen = Vec::new();
    while run.step().unwrap().is_some() {
        seen.push(run.session().config().tracker.plot_sigma_m);
    }
    assert_eq!(seen, [2.0, 2.0, 21.0, 21.0]);
    let said = run.session().events();
    let retuned = said.iter().filter(|e| e.contains("accuracy now")).count();
    assert_eq!(retuned, 2, "{said:?}");
}

#[test]
fn a_radar_tells_its_range_scales_plot_accuracy() {
    let path = realdata::file("radar/radar_pi-4g-noheading-merrimac.pcap.gz");
    let first_range_m = CaptureSurvey::of(&path).unwrap().first_range_m.unwrap();
    let mut radar = RadarOptions::new(RadarSpec::Capture(path.clone()));
    let origin = Default::default();
    let mut source = RadarPlotSource::open(&radar, origin).unwrap();
    assert_eq!(source.plot_sigma_m(), None, "no spoke read yet");
    source.next_scan().unwrap().expect("a scan");
    assert_eq!(source.plot_sigma_m(), Some(plot_sigma_m(first_range_m)));
    // Given by the operator (`--plot-sigma-m`): that, whatever the scale.
    radar.plot_sigma_m = Some(7.5);
    let mut source = RadarPlotSource::open(&radar, origin).unwrap();
    source.next_scan().unwrap().expect("a scan");
    assert_eq!(source.plot_sigma_m(), Some(7.5));
}
