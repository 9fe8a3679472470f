//! Initial states for the sweeps: a θ0 × θ̇0 grid, seeded random draws, or an explicit list.
//!
//! The grid spans θ0 ∈ [−π, π) (π and −π are the same angle) in `n_theta` equal steps and
//! θ̇0 ∈ [−w, w] (both ends included) in `n_theta_dot` points, w = `theta_dot_max`
//! (dimensionless, 3 by default). Start `i·n_theta_dot + j` is (θ0_i, θ̇0_j).

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::MapsError;

/// Default half-width of the θ̇0 range (dimensionless).
pub const THETA_DOT_MAX: f64 = 3.0;

/// How the initial states are chosen.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum IcSpec {
    /// `n_theta × n_theta_dot` grid.
    Grid {
        n_theta: usize,
        n_theta_dot: usize,
        theta_dot_max: f64,
    },
    /// `n` uniform draws over the grid's box from a ChaCha8 stream seeded with `seed`.
    Random {
        n: usize,
        seed: u64,
        theta_dot_max: f64,
    },
    /// Explicit (θ0 rad, θ̇0 dimensionless) pairs.
    List(Vec<[f64; 2]>),
}

/// Largest number of initial states per sweep value.
pub const MAX_STARTS: usize = 1_000_000;

impl IcSpec {
    /// `NxM` (θ0 points × θ̇0 points), or `N` for N×N.
    pub fn parse_grid(text: &str, theta_dot_max: f64) -> Result<Self, MapsError> {
        let bad = || {
            MapsError::Invalid(format!(
                "initial-condition grid {text:?}: expected NxM (θ0 points × θ̇0 points, e.g. 8x8) or N"
            ))
        };
        let (a, b) = match text.split_once(['x', 'X', '×']) {
            Some((a, b)) => (a, b),
            None => (text, text),
        };
        let n_theta: usize = a.trim().parse().map_err(|_| bad())?;
        let n_theta_dot: usize = b.trim().parse().map_err(|_| bad())?;
        let spec = IcSpec::Grid {
            n_theta,
            n_theta_dot,
            theta_dot_max,
        };
        spec.validate()?;
        Ok(spec)
    }

    /// Parses `THETA,THETA_DOT` (rad, dimensionless).
    pub fn parse_pair(text: &str) -> Result<[f64; 2], MapsError> {
        let bad = || {
            MapsError::Invalid(format!(
                "initial state {text:?}: expected THETA,THETA_DOT (rad, dimensionless), e.g. 0.5,0"
            ))
        };
        let (a, b) = text.split_once(',').ok_or_else(bad)?;
        let a: f64 = a.trim().parse().map_err(|_| bad())?;
        let b: f64 = b.trim().parse().map_err(|_| bad())?;
        if !(a.is_finite() && b.is_finite()) {
            return Err(bad());
        }
        Ok([a, b])
    }

    pub fn validate(&self) -> Result<(), MapsError> {
        let n = self.len();
        if n == 0 {
            return Err(MapsError::Invalid(
                "no initial states: the grid or the count must be at least 1".into(),
            ));
        }
        if n > MAX_STARTS {
            return Err(MapsError::Invalid(format!(
                "{n} initial states; at most {MAX_STARTS}"
            )));
        }
        let w = match self {
            IcSpec::Grid { theta_dot_max, .. } | IcSpec::Random { theta_dot_max, .. } => {
                *theta_dot_max
            }
            IcSpec::List(_) => 0.0,
        };
        if !(w.is_finite() && w >= 0.0) {
            return Err(MapsError::Invalid(format!(
                "theta_dot_max {w} must be a finite value ≥ 0"
            )));
        }
        Ok(())
    }

    /// Number of initial states.
    pub fn len(&self) -> usize {
        match self {
            IcSpec::Grid {
                n_theta,
                n_theta_dot,
                ..
            } => n_theta.saturating_mul(*n_theta_dot),
            IcSpec::Random { n, .. } => *n,
            IcSpec::List(v) => v.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The initial states, (θ0 rad, θ̇0 dimensionless), in a fixed order.
    pub fn starts(&self) -> Vec<[f64; 2]> {
        let pi = std::f64::consts::PI;
        match self {
            IcSpec::Grid {
                n_theta,
                n_theta_dot,
                theta_dot_max: w,
            } => {
                let mut v = Vec::with_capacity(self.len());
                for i in 0..*n_theta {
                    let th = -pi + 2.0 * pi * i as f64 / *n_theta as f64;
                    for j in 0..*n_theta_dot {
                        let wd = if *n_theta_dot == 1 {
                            0.0
                        } else {
                            -w + 2.0 * w * j as f64 / (*n_theta_dot - 1) as f64
                        };
                        v.push([th, wd]);
                    }
                }
                v
            }
            IcSpec::Random {
                n,
                seed,
                theta_dot_max: w,
            } => {
                let mut rng = ChaCha8Rng::seed_from_u64(*seed);
                (0..*n)
                    .map(|_| {
                        let th = rng.random_range(-pi..pi);
                        let wd = if *w > 0.0 {
                            rng.random_range(-*w..=*w)
                        } else {
                            0.0
                        };
                        [th, wd]
                    })
                    .collect()
            }
            IcSpec::List(v) => v.clone(),
        }
    }

    /// `8×8 grid, θ̇0 ∈ [−3, 3]`.
    pub fn describe(&self) -> String {
        match self {
            IcSpec::Grid {
                n_theta,
                n_theta_dot,
                theta_dot_max,
            } => format!(
                "{n_theta}×{n_theta_dot} grid, θ0 ∈ [−π, π), θ̇0 ∈ [−{theta_dot_max}, {theta_dot_max}]"
            ),
            IcSpec::Random {
                n,
                seed,
                theta_dot_max,
            } => format!(
                "{n} random starts (seed {seed}), θ0 ∈ [−π, π), θ̇0 ∈ [−{theta_dot_max}, {theta_dot_max}]"
            ),
            IcSpec::List(v) => format!("{} given start(s)", v.len()),
        }
    }
}

/// The checks every map's starts and recording share: at least one start, all finite, and
/// at least 2 recorded periods (what the classifier needs; 32 find a period of 16).
pub fn check_starts(starts: &[[f64; 2]], record_periods: u32) -> Result<(), MapsError> {
    if starts.is_empty() {
        return Err(MapsError::Invalid("no initial states".into()));
    }
    if starts.iter().flatten().any(|v| !v.is_finite()) {
        return Err(MapsError::Invalid("initial states must be finite".into()));
    }
    if record_periods < 2 {
        return Err(MapsError::Invalid(format!(
            "record {record_periods} periods: at least 2 are needed to classify (32 to find period 16)"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_covers_the_box() {
        let g = IcSpec::parse_grid("8x4", 3.0).unwrap();
        let s = g.starts();
        assert_eq!(s.len(), 32);
        assert_eq!(s[0], [-std::f64::consts::PI, -3.0]);
        assert_eq!(s[3], [-std::f64::consts::PI, 3.0]);
        assert!(s.iter().all(|p| p[0] < std::f64::consts::PI));
        assert_eq!(IcSpec::parse_grid("3", 3.0).unwrap().len(), 9);
        assert!(IcSpec::parse_grid("0x4", 3.0).is_err());
        assert!(IcSpec::parse_grid("ax4", 3.0).is_err());
    }

    #[test]
    fn random_starts_follow_the_seed() {
        let a = IcSpec::Random {
            n: 20,
            seed: 1,
            theta_dot_max: 3.0,
        };
        let b = IcSpec::Random {
            n: 20,
            seed: 2,
            theta_dot_max: 3.0,
        };
        assert_eq!(a.starts(), a.starts());
        assert_ne!(a.starts(), b.starts());
        assert!(a
            .starts()
            .iter()
            .all(|p| p[0].abs() <= std::f64::consts::PI && p[1].abs() <= 3.0));
    }

    #[test]
    fn pairs() {
        assert_eq!(IcSpec::parse_pair("0.5,-1").unwrap(), [0.5, -1.0]);
        assert!(IcSpec::parse_pair("0.5").is_err());
    }
}
