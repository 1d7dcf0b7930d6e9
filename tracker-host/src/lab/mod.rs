//! The lab: research and engineering tools beside the product. They use the core and the
//! session, but nothing in the product's command path uses them.
//!
//! | module | command | what |
//! |---|---|---|
//! | [`replay`], [`replay_nav`] | `replay` | one filter over recorded measurements, CSV in and out |
//! | [`compare`] | `compare` | GRNN against the Kalman and α-β filters on a manoeuvre |
//! | [`turns`] | `compare` | the IMM against CV Kalman, α-β-γ and GRNN on turns of 1–7°/s at 20–40 m |
//! | [`precision`] | `precision` | f32 and fixed point against f64 |
//! | [`arpa`] | `arpa` | the IMO ARPA accuracy test by Monte Carlo (paper 004's EKFs) |
//! | [`reproduce`] | `reproduce` | the seed papers' experiments, report and plots |
//! | [`bench_mcu`] | `bench-mcu` | instruction counts on the emulated Cortex-M4F |
//! | [`link_budget`] | `link-budget` | bytes a scan on the link; the largest picture a UART carries |
//!
//! [`noise`] and [`kinematics`] are the experiments' shared noise and f64 geometry.

pub mod arpa;
pub mod bench_mcu;
pub mod compare;
pub mod kinematics;
pub mod link_budget;
pub mod noise;
pub mod precision;
pub mod replay;
pub mod replay_nav;
pub mod reproduce;
pub mod turns;
