//! Sweep specifications: `omega=0.5:3.5:0.01` (start:stop:step, stop included when on the
//! grid), `omega=1.57,1.585,2.0` (a list) or `omega=2.0` (one value), over the dimensionless
//! parameters of the study's Eq. 5–6.

use pendulum_model::Dimensionless;
use serde::{Deserialize, Serialize};

use crate::MapsError;

/// A dimensionless parameter that can be swept.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum SweepParam {
    /// Forcing frequency ω = 2πΩ/ω0 (R held fixed, as the study sweeps).
    Omega,
    /// Forcing amplitude R = r ω²/l.
    R,
    /// Crank ratio λ = r/L.
    Lambda,
    /// Quadratic drag α.
    Alpha,
    /// Linear drag β.
    Beta,
    /// Bearing friction M.
    M,
}

impl SweepParam {
    pub const ALL: [SweepParam; 6] = [
        SweepParam::Omega,
        SweepParam::R,
        SweepParam::Lambda,
        SweepParam::Alpha,
        SweepParam::Beta,
        SweepParam::M,
    ];

    /// The key, as `--param` spells it and as the column name in the outputs.
    pub fn name(self) -> &'static str {
        match self {
            SweepParam::Omega => "omega",
            SweepParam::R => "R",
            SweepParam::Lambda => "lambda",
            SweepParam::Alpha => "alpha",
            SweepParam::Beta => "beta",
            SweepParam::M => "M",
        }
    }

    /// Axis label for figures.
    pub fn label(self) -> &'static str {
        match self {
            SweepParam::Omega => "forcing frequency ω = 2πΩ/ω0",
            SweepParam::R => "forcing amplitude R = rω²/l",
            SweepParam::Lambda => "crank ratio λ = r/L",
            SweepParam::Alpha => "quadratic drag α",
            SweepParam::Beta => "linear drag β",
            SweepParam::M => "bearing friction M",
        }
    }

    /// Short symbol for titles.
    pub fn symbol(self) -> &'static str {
        match self {
            SweepParam::Omega => "ω",
            SweepParam::R => "R",
            SweepParam::Lambda => "λ",
            SweepParam::Alpha => "α",
            SweepParam::Beta => "β",
            SweepParam::M => "M",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    pub fn get(self, d: &Dimensionless) -> f64 {
        match self {
            SweepParam::Omega => d.omega,
            SweepParam::R => d.r,
            SweepParam::Lambda => d.lambda,
            SweepParam::Alpha => d.alpha,
            SweepParam::Beta => d.beta,
            SweepParam::M => d.m_coulomb,
        }
    }

    pub fn set(self, d: &mut Dimensionless, v: f64) {
        match self {
            SweepParam::Omega => d.omega = v,
            SweepParam::R => d.r = v,
            SweepParam::Lambda => d.lambda = v,
            SweepParam::Alpha => d.alpha = v,
            SweepParam::Beta => d.beta = v,
            SweepParam::M => d.m_coulomb = v,
        }
    }
}

/// Largest number of values one sweep may have.
pub const MAX_VALUES: usize = 1_000_000;

/// One swept parameter and its values, in the order given.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sweep {
    pub param: SweepParam,
    pub values: Vec<f64>,
}

/// `start + i·step`, rounded to 1e-10 so that 2.6 + 1·0.05 prints as 2.65.
fn grid_value(start: f64, step: f64, i: usize) -> f64 {
    let v = start + i as f64 * step;
    let r = (v * 1e10).round() / 1e10;
    if (r - v).abs() <= 1e-9 * step.abs().max(1e-300) {
        r
    } else {
        v
    }
}

impl Sweep {
    /// `start..=stop` in steps of `step` (the stop is included when it is on the grid, to
    /// within 1e-9 of a step).
    pub fn range(param: SweepParam, start: f64, stop: f64, step: f64) -> Result<Self, MapsError> {
        let bad = |what: String| MapsError::Invalid(format!("sweep {}: {what}", param.name()));
        if !(start.is_finite() && stop.is_finite() && step.is_finite()) {
            return Err(bad("start, stop and step must be finite numbers".into()));
        }
        if step <= 0.0 {
            return Err(bad(format!("step {step} must be > 0")));
        }
        if stop < start {
            return Err(bad(format!("stop {stop} is below start {start}")));
        }
        let n = ((stop - start) / step + 1e-9).floor();
        if n + 1.0 > MAX_VALUES as f64 {
            return Err(bad(format!("{} values; at most {MAX_VALUES}", n + 1.0)));
        }
        let n = n as usize + 1;
        Ok(Self {
            param,
            values: (0..n).map(|i| grid_value(start, step, i)).collect(),
        })
    }

    /// Parses `name=start:stop:step`, `name=v1,v2,…` or `name=v`.
    pub fn parse(text: &str) -> Result<Self, MapsError> {
        let expected = "NAME=START:STOP:STEP, NAME=V1,V2,… or NAME=V with NAME one of omega, R, lambda, alpha, beta, M";
        let (name, spec) = text
            .split_once('=')
            .ok_or_else(|| MapsError::Invalid(format!("sweep {text:?}: expected {expected}")))?;
        let name = name.trim();
        let param = SweepParam::from_name(name).ok_or_else(|| {
            MapsError::Invalid(format!(
                "sweep {text:?}: unknown parameter {name:?}; expected {expected}"
            ))
        })?;
        let num = |s: &str| -> Result<f64, MapsError> {
            let v: f64 = s.trim().parse().map_err(|_| {
                MapsError::Invalid(format!(
                    "sweep {text:?}: cannot read {s:?} as a number; expected {expected}"
                ))
            })?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(MapsError::Invalid(format!(
                    "sweep {text:?}: {s:?} is not a finite number"
                )))
            }
        };
        let parts: Vec<&str> = spec.split(':').collect();
        let sweep = match parts.as_slice() {
            [a, b, c] => Self::range(param, num(a)?, num(b)?, num(c)?)?,
            [one] => {
                let values = one.split(',').map(num).collect::<Result<Vec<_>, _>>()?;
                Self { param, values }
            }
            _ => {
                return Err(MapsError::Invalid(format!(
                    "sweep {text:?}: expected {expected}"
                )))
            }
        };
        if sweep.values.is_empty() {
            return Err(MapsError::Invalid(format!("sweep {text:?}: no values")));
        }
        Ok(sweep)
    }

    /// The parameters at value `i`: `base` with the swept parameter set.
    pub fn apply(&self, base: &Dimensionless, i: usize) -> Dimensionless {
        let mut d = *base;
        self.param.set(&mut d, self.values[i]);
        d
    }

    pub fn len(&self) -> usize {
        self.values.len()
    }

    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// Cell edges for a heat map: midpoints between values, the ends extended by half the
    /// neighbouring gap (a lone value gets a cell of width 1 % of itself, or 1).
    pub fn edges(&self) -> Vec<f64> {
        let v = &self.values;
        match v.len() {
            0 => Vec::new(),
            1 => {
                let h = if v[0] != 0.0 { 0.01 * v[0].abs() } else { 0.5 };
                vec![v[0] - h, v[0] + h]
            }
            n => {
                let mut e = Vec::with_capacity(n + 1);
                e.push(v[0] - 0.5 * (v[1] - v[0]));
                for i in 0..n - 1 {
                    e.push(0.5 * (v[i] + v[i + 1]));
                }
                e.push(v[n - 1] + 0.5 * (v[n - 1] - v[n - 2]));
                e
            }
        }
    }

    /// `omega 0.5..3.5 (301 values)`.
    pub fn describe(&self) -> String {
        match self.values.as_slice() {
            [] => format!("{} (no values)", self.param.name()),
            [v] => format!("{} = {v}", self.param.name()),
            v => format!(
                "{} {}..{} ({} values)",
                self.param.name(),
                v[0],
                v[v.len() - 1],
                v.len()
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_include_the_stop() {
        let s = Sweep::parse("omega=0.5:3.5:0.01").unwrap();
        assert_eq!(s.param, SweepParam::Omega);
        assert_eq!(s.values.len(), 301);
        assert_eq!(s.values[0], 0.5);
        assert_eq!(s.values[300], 3.5);
        assert_eq!(s.values[107], 1.57);
        let s = Sweep::parse("R=2.6:3.0:0.05").unwrap();
        assert_eq!(s.values.len(), 9);
        assert_eq!(s.values[1], 2.65);
        assert_eq!(s.values[8], 3.0);
        // Stop off the grid: the last grid value below it.
        let s = Sweep::parse("beta=0:0.1:0.03").unwrap();
        assert_eq!(s.values, vec![0.0, 0.03, 0.06, 0.09]);
    }

    #[test]
    fn lists_and_single_values() {
        let s = Sweep::parse("omega=1.57,1.585, 2").unwrap();
        assert_eq!(s.values, vec![1.57, 1.585, 2.0]);
        let s = Sweep::parse("M=0.007").unwrap();
        assert_eq!((s.param, s.values.clone()), (SweepParam::M, vec![0.007]));
        assert_eq!(s.edges().len(), 2);
    }

    #[test]
    fn errors_say_what_is_expected() {
        for bad in [
            "omega",
            "omgea=1:2:0.1",
            "omega=1:2",
            "omega=2:1:0.1",
            "omega=1:2:0",
            "omega=1:2:x",
            "omega=inf",
        ] {
            let e = Sweep::parse(bad).unwrap_err().to_string();
            assert!(e.contains("sweep"), "{bad}: {e}");
        }
        let e = Sweep::parse("omgea=1").unwrap_err().to_string();
        assert!(e.contains("omgea") && e.contains("omega"), "{e}");
    }

    #[test]
    fn edges_surround_the_values() {
        let s = Sweep::parse("R=0.3:0.5:0.1").unwrap();
        let e = s.edges();
        assert_eq!(e.len(), 4);
        for (i, v) in s.values.iter().enumerate() {
            assert!(e[i] < *v && *v < e[i + 1]);
        }
    }
}
