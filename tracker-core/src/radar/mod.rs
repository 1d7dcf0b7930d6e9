//! A radar's raw picture and the plot extraction that turns it into the tracker's plots.
//!
//! - [`spoke`]: one line of echo strengths per antenna angle, as a navigator's radar sends
//!   them;
//! - [`cfar`]: the detector along one spoke (ordered-statistic CFAR);
//! - [`blob`]: detections connected across spokes, and the plot a closed one measures;
//! - [`echo`]: the echo threshold, by which an echo's whole extent around its detections
//!   is measured;
//! - [`extract`]: the [`Extractor`], spokes in, plots and extended returns out;
//! - [`config`]: its settings, with defaults per radar;
//! - `synthetic` (feature `sim`): a synthetic radar that paints the simulator's targets,
//!   noise, sea clutter and rain into spokes, for tests and the host.

pub mod blob;
pub mod cfar;
pub mod config;
pub mod echo;
pub mod extract;
pub mod spoke;
#[cfg(feature = "sim")]
pub mod synthetic;

pub use blob::RadarPlot;
pub use config::{ConfigError, ExtractorConfig, ReturnClass};
pub use extract::{Event, Extractor, ExtractorStats};
pub use spoke::Spoke;
