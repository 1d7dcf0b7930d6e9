//! The experiments' noise: standard normal samples from a seeded `fastrand` generator, so a
//! run repeats exactly.

/// A standard normal sample (Box–Muller); the experiments' only noise source.
pub fn normal(rng: &mut fastrand::Rng) -> f64 {
    let (u, v) = (rng.f64().max(1e-300), rng.f64());
    (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
}
