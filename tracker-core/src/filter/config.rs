//! The one list of filters: their names ([`FilterKind`]) and their configurations
//! ([`FilterConfig`]).
//!
//! Everything that chooses a filter goes through these two types: the command line
//! (`--filter NAME` in `demo`, `track` and `replay`), the device's configuration on the
//! wire ([`crate::icd::TrackerConfig`]), the track table's per-track state
//! ([`crate::track::TrackFilter`]) and the host's single-filter replay. Configuration is
//! apart from state (as in `idsp`): a config is a few plain numbers, built once into a
//! filter of any scalar.

use serde::{Deserialize, Serialize};

use super::alpha_beta::AlphaBetaGains;
use super::alpha_beta_gamma::AbgGains;
use super::alpha_beta_gamma_eta::AbgeGains;
use super::grnn::GrnnConfig;
use super::imm::ImmConfig;
use super::kalman::KalmanConfig;
use super::sswt::SswtConfig;
use super::FilterError;

/// The filters, by name.
///
/// The names (kebab-case, as on the command line) are [`FilterKind::name`]; [`FilterKind::ALL`]
/// lists every one in a fixed order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FilterKind {
    /// α-β (thesis eq. 2-1 to 2-4).
    AlphaBeta,
    /// α-β-γ, constant acceleration (paper 000).
    AlphaBetaGamma,
    /// α-β-γ-η, constant jerk (paper 001).
    AlphaBetaGammaEta,
    /// Switched slide-window tracker (thesis §2.3.1).
    Sswt,
    /// Constant-velocity Kalman filter (thesis eq. 2-6 to 2-13).
    KalmanCv,
    /// Constant-acceleration Kalman filter (thesis eq. 2-6 to 2-13).
    KalmanCa,
    /// GRNN neural filter with a manoeuvre detector (paper 003).
    Grnn,
    /// Interacting multiple model: CV, CA and settling-CV Kalman filters mixed (Bar-Shalom
    /// et al. 2001, §11.6.6).
    Imm,
}

impl FilterKind {
    /// Every filter, in the order the documentation lists them.
    pub const ALL: [FilterKind; 8] = [
        FilterKind::AlphaBeta,
        FilterKind::AlphaBetaGamma,
        FilterKind::AlphaBetaGammaEta,
        FilterKind::Sswt,
        FilterKind::KalmanCv,
        FilterKind::KalmanCa,
        FilterKind::Grnn,
        FilterKind::Imm,
    ];

    /// The name on the command line and in reports, e.g. `kalman-cv`.
    pub const fn name(self) -> &'static str {
        match self {
            FilterKind::AlphaBeta => "alpha-beta",
            FilterKind::AlphaBetaGamma => "alpha-beta-gamma",
            FilterKind::AlphaBetaGammaEta => "alpha-beta-gamma-eta",
            FilterKind::Sswt => "sswt",
            FilterKind::KalmanCv => "kalman-cv",
            FilterKind::KalmanCa => "kalman-ca",
            FilterKind::Grnn => "grnn",
            FilterKind::Imm => "imm",
        }
    }

    /// The filter called `name` ([`FilterKind::name`]).
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] when no filter has that name.
    pub fn from_name(name: &str) -> Result<Self, FilterError> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == name)
            .ok_or(FilterError::BadParameter)
    }

    /// True for the filters that carry a covariance, and so know their innovation
    /// covariance (the Kalman filters and the IMM).
    pub const fn has_covariance(self) -> bool {
        matches!(
            self,
            FilterKind::KalmanCv | FilterKind::KalmanCa | FilterKind::Imm
        )
    }
}

impl core::fmt::Display for FilterKind {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

impl core::str::FromStr for FilterKind {
    type Err = FilterError;
    fn from_str(s: &str) -> Result<Self, FilterError> {
        Self::from_name(s)
    }
}

/// A filter fully specified: which one and its design parameters (gains in f64, designed
/// once when the filter is built, in any scalar).
///
/// Sent to the device in [`crate::icd::TrackerConfig`], so the variants' order is part of
/// the wire format (append only).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum FilterConfig {
    /// α-β.
    AlphaBeta(AlphaBetaGains),
    /// α-β-γ.
    AlphaBetaGamma(AbgGains),
    /// α-β-γ-η.
    AlphaBetaGammaEta(AbgeGains),
    /// SSWT.
    Sswt(SswtConfig),
    /// CV Kalman.
    KalmanCv(KalmanConfig),
    /// CA Kalman.
    KalmanCa(KalmanConfig),
    /// GRNN.
    Grnn(GrnnConfig),
    /// IMM (CV, CA and settling CV).
    Imm(ImmConfig),
}

impl FilterConfig {
    /// Which filter this configures.
    pub const fn kind(&self) -> FilterKind {
        match self {
            FilterConfig::AlphaBeta(_) => FilterKind::AlphaBeta,
            FilterConfig::AlphaBetaGamma(_) => FilterKind::AlphaBetaGamma,
            FilterConfig::AlphaBetaGammaEta(_) => FilterKind::AlphaBetaGammaEta,
            FilterConfig::Sswt(_) => FilterKind::Sswt,
            FilterConfig::KalmanCv(_) => FilterKind::KalmanCv,
            FilterConfig::KalmanCa(_) => FilterKind::KalmanCa,
            FilterConfig::Grnn(_) => FilterKind::Grnn,
            FilterConfig::Imm(_) => FilterKind::Imm,
        }
    }

    /// Checks every parameter is in the range where the filter is defined and stable.
    ///
    /// # Errors
    /// [`FilterError::BadParameter`] naming nothing more: the caller knows which config it
    /// gave.
    pub fn validate(&self) -> Result<(), FilterError> {
        match self {
            FilterConfig::AlphaBeta(g) => g.validate(),
            FilterConfig::AlphaBetaGamma(g) => g.validate(),
            FilterConfig::AlphaBetaGammaEta(g) => g.validate(),
            FilterConfig::Sswt(c) => c.build::<f64>().map(|_| ()),
            FilterConfig::KalmanCv(c) | FilterConfig::KalmanCa(c) => c.validate(),
            FilterConfig::Grnn(c) => c.validate(),
            FilterConfig::Imm(c) => c.validate(),
        }
    }

    /// The configuration a radar tracker runs `kind` with: plots of `plot_sigma_m`
    /// standard deviation per axis, targets up to `max_speed_mps` (a new Kalman track's
    /// velocity variance is `max_speed_mps²`).
    ///
    /// | filter | parameters |
    /// |---|---|
    /// | α-β | α = 0.5, β = 1/6 (Benedict–Bordner) |
    /// | α-β-γ | critically damped, ξ = 0.6 |
    /// | α-β-γ-η | critically damped, ξ = 0.7 |
    /// | SSWT | M = 4, α-β start α = 0.5 (Benedict–Bordner) |
    /// | CV Kalman | CWNA, q = 0.05 m²/s³, r = σ² |
    /// | CA Kalman | CWNJ, q = 0.001 m²/s⁵, r = σ² |
    /// | GRNN | teaching sequences 10 and 45 scans, σ from the measured noise, the residual manoeuvre detector |
    /// | IMM | straight CV q = 0.001 m²/s³, CA q = 0.05 m²/s⁵, settling CV q = 0.05 m²/s³, mean sojourns 300, 3 and 10 s, acceleration σ₀ = 1 m/s² (chosen on `compare`'s turn study) |
    ///
    /// Numbers are given as `f32` and widened, as the device has always received them, so
    /// the device's gains are bit for bit those of earlier versions.
    pub fn tracking(kind: FilterKind, plot_sigma_m: f32, max_speed_mps: f32) -> Self {
        use super::kalman::QModel;
        let r = f64::from(plot_sigma_m * plot_sigma_m);
        let kalman = |q: f32| KalmanConfig {
            p0_derivative: f64::from(max_speed_mps * max_speed_mps),
            ..KalmanConfig::new(f64::from(q), QModel::Continuous, r)
        };
        match kind {
            FilterKind::AlphaBeta => FilterConfig::AlphaBeta(AlphaBetaGains::Fixed {
                alpha: f64::from(0.5f32),
                beta: f64::from(0.25f32 / 1.5),
            }),
            FilterKind::AlphaBetaGamma => FilterConfig::AlphaBetaGamma(AbgGains::FadingMemory {
                xi: f64::from(0.6f32),
            }),
            FilterKind::AlphaBetaGammaEta => {
                FilterConfig::AlphaBetaGammaEta(AbgeGains::FadingMemory {
                    xi: f64::from(0.7f32),
                })
            }
            FilterKind::Sswt => FilterConfig::Sswt(SswtConfig {
                window: 4,
                start: AlphaBetaGains::BenedictBordner {
                    alpha: f64::from(0.5f32),
                },
            }),
            FilterKind::KalmanCv => FilterConfig::KalmanCv(kalman(0.05)),
            FilterKind::KalmanCa => FilterConfig::KalmanCa(kalman(0.001)),
            FilterKind::Grnn => FilterConfig::Grnn(GrnnConfig {
                short: 10,
                long: 45,
                ..GrnnConfig::default()
            }),
            FilterKind::Imm => FilterConfig::Imm(ImmConfig {
                q_cv: 0.001,
                q_ca: 0.05,
                q_settle: 0.05,
                r,
                p0_velocity: f64::from(max_speed_mps * max_speed_mps),
                p0_acceleration: 1.0,
                sojourn_cv_s: 300.0,
                sojourn_ca_s: 3.0,
                sojourn_settle_s: 10.0,
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_every_tracking_config_is_valid() {
        for k in FilterKind::ALL {
            assert_eq!(FilterKind::from_name(k.name()), Ok(k));
            let c = FilterConfig::tracking(k, 40.0, 20.0);
            assert_eq!(c.kind(), k);
            assert_eq!(c.validate(), Ok(()), "{k}");
        }
        assert!("kalman".parse::<FilterKind>().is_err());
    }
}
