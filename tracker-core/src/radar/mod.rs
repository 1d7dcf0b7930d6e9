//! A radar's raw picture: spokes, one line of echo strengths per antenna angle, as a
//! navigator's radar sends them; and (in the modules that grow here) the plot extraction
//! that turns them into the tracker's plots.

pub mod spoke;

pub use spoke::Spoke;
