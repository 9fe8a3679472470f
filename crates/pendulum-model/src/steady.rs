//! Steady-state classes from a Poincaré section (one sample per forcing period after a transient).
//!
//! The names (`rest`, `oscillation`, `rotation_ccw`, `rotation_cw`, `chaos`) are used in every
//! output of the project.

use std::fmt;
use std::ops::ControlFlow;
use std::str::FromStr;

use pendulum_numerics::wrap_pi;
use serde::{Deserialize, Serialize};

use crate::sim::{integrate, Model, SimOptions};
use crate::ModelError;

/// The kind of motion a run settles into.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SteadyClass {
    Rest,
    Oscillation,
    /// θ increasing.
    RotationCcw,
    /// θ decreasing.
    RotationCw,
    Chaos,
}

impl SteadyClass {
    pub const ALL: [SteadyClass; 5] = [
        SteadyClass::Rest,
        SteadyClass::Oscillation,
        SteadyClass::RotationCcw,
        SteadyClass::RotationCw,
        SteadyClass::Chaos,
    ];

    pub fn as_str(self) -> &'static str {
        match self {
            SteadyClass::Rest => "rest",
            SteadyClass::Oscillation => "oscillation",
            SteadyClass::RotationCcw => "rotation_ccw",
            SteadyClass::RotationCw => "rotation_cw",
            SteadyClass::Chaos => "chaos",
        }
    }

    pub fn is_rotation(self) -> bool {
        matches!(self, SteadyClass::RotationCcw | SteadyClass::RotationCw)
    }
}

impl fmt::Display for SteadyClass {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for SteadyClass {
    type Err = ModelError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        SteadyClass::ALL
            .into_iter()
            .find(|c| c.as_str() == s)
            .ok_or_else(|| ModelError::BadInput(format!(
                "unknown steady state {s:?}: expected rest, oscillation, rotation_ccw, rotation_cw or chaos"
            )))
    }
}

/// A class with its period in forcing periods (0 for rest and chaos).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SteadyState {
    pub class: SteadyClass,
    pub period: u32,
    /// Mean θ̇ over the recorded section, in the time unit of the history (dimensionless for
    /// simulations); the rotation speed for rotations, 0 for rest and oscillation.
    /// [`classify_poincare`] alone, knowing no period, gives it per Poincaré step.
    pub mean_theta_dot: f64,
}

impl fmt::Display for SteadyState {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.class {
            SteadyClass::Rest | SteadyClass::Chaos => write!(f, "{}", self.class),
            _ => write!(f, "{} (period {})", self.class, self.period),
        }
    }
}

/// Tolerances of the classifier. Defaults suit simulations; measured data need tolerances above
/// the encoder's resolution and noise.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClassifyOptions {
    /// Two Poincaré points repeat when θ (mod 2π) agrees within this, rad.
    pub theta_tol: f64,
    /// … and θ̇ agrees within this (dimensionless).
    pub theta_dot_tol: f64,
    /// Longest period looked for, in forcing periods.
    pub max_period: u32,
    /// Motion whose θ stays within this of its mean (and θ̇ within `theta_dot_tol` of 0) is rest.
    pub rest_tol: f64,
}

impl Default for ClassifyOptions {
    fn default() -> Self {
        Self {
            theta_tol: 1e-3,
            theta_dot_tol: 1e-3,
            max_period: 16,
            rest_tol: 1e-4,
        }
    }
}

/// Classifies Poincaré points (θ unwrapped, θ̇), one per forcing period, transient removed.
pub fn classify_poincare(theta: &[f64], theta_dot: &[f64], opts: &ClassifyOptions) -> SteadyState {
    let n = theta.len().min(theta_dot.len());
    let mean_theta_dot = if n >= 2 {
        // Net drift per period, robust to where the section falls within a rotation.
        (theta[n - 1] - theta[0]) / (n - 1) as f64
    } else {
        0.0
    };
    if n < 2 {
        return SteadyState {
            class: SteadyClass::Chaos,
            period: 0,
            mean_theta_dot: 0.0,
        };
    }
    let mean = theta[..n].iter().sum::<f64>() / n as f64;
    let still = theta[..n].iter().all(|t| (t - mean).abs() <= opts.rest_tol)
        && theta_dot[..n].iter().all(|w| w.abs() <= opts.theta_dot_tol);
    if still {
        return SteadyState {
            class: SteadyClass::Rest,
            period: 0,
            mean_theta_dot: 0.0,
        };
    }
    let max_p = (opts.max_period as usize).min(n / 2);
    for p in 1..=max_p {
        let repeats = (0..n - p).all(|k| {
            wrap_pi(theta[k + p] - theta[k]).abs() <= opts.theta_tol
                && (theta_dot[k + p] - theta_dot[k]).abs() <= opts.theta_dot_tol
        });
        if repeats {
            // Net turns over one period of the orbit.
            let class = turns_class(theta[p] - theta[0]);
            return SteadyState {
                class,
                period: p as u32,
                mean_theta_dot: if class.is_rotation() {
                    mean_theta_dot
                } else {
                    0.0
                },
            };
        }
    }
    SteadyState {
        class: SteadyClass::Chaos,
        period: 0,
        mean_theta_dot,
    }
}

/// What the first Poincaré points already decide about [`classify_poincare`] on all `n` of them,
/// so that a simulation can stop as soon as the class it will reach is certain (the decision is
/// the classifier's own comparisons on the points seen, not a numerical guess).
#[derive(Debug, Clone)]
pub struct PartialClass {
    n: usize,
    opts: ClassifyOptions,
    theta: Vec<f64>,
    theta_dot: Vec<f64>,
    theta_min: f64,
    theta_max: f64,
    /// Some |θ̇| is above the rest tolerance.
    moving: bool,
    /// `violated[p]`: two points p apart already differ, so the orbit is not of period p.
    violated: Vec<bool>,
}

impl PartialClass {
    /// For `n` points to come, classified with `opts`.
    pub fn new(n: usize, opts: &ClassifyOptions) -> Self {
        let max_p = (opts.max_period as usize).min(n / 2);
        Self {
            n,
            opts: *opts,
            theta: Vec::with_capacity(n),
            theta_dot: Vec::with_capacity(n),
            theta_min: f64::INFINITY,
            theta_max: f64::NEG_INFINITY,
            moving: false,
            violated: vec![false; max_p + 1],
        }
    }

    /// The next point (θ unwrapped, θ̇).
    pub fn push(&mut self, theta: f64, theta_dot: f64) {
        let m = self.theta.len();
        for p in 1..self.violated.len().min(m + 1) {
            if !self.violated[p] {
                let (t0, w0) = (self.theta[m - p], self.theta_dot[m - p]);
                // The negation of classify_poincare's repeat test, NaN included.
                self.violated[p] = !(wrap_pi(theta - t0).abs() <= self.opts.theta_tol
                    && (theta_dot - w0).abs() <= self.opts.theta_dot_tol);
            }
        }
        self.theta_min = self.theta_min.min(theta);
        self.theta_max = self.theta_max.max(theta);
        self.moving |= !(theta_dot.abs() <= self.opts.theta_dot_tol);
        self.theta.push(theta);
        self.theta_dot.push(theta_dot);
    }

    /// The points so far (θ, θ̇).
    pub fn points(&self) -> (&[f64], &[f64]) {
        (&self.theta, &self.theta_dot)
    }

    /// `Some(true)` if the class of all `n` points is certain to differ from `class`,
    /// `Some(false)` if it is certain to be `class`, `None` while undecided.
    pub fn differs_from(&self, class: SteadyClass) -> Option<bool> {
        if self.n < 2 {
            return None;
        }
        let m = self.theta.len();
        // Some θ is farther than rest_tol from any mean (a margin for the mean's rounding).
        let not_rest = self.moving
            || self.theta_max - self.theta_min > 2.0 * self.opts.rest_tol * (1.0 + 1e-6);
        let periods = 1..self.violated.len();
        match class {
            SteadyClass::Rest => not_rest.then_some(true),
            SteadyClass::Chaos => {
                (not_rest && periods.clone().all(|p| self.violated[p])).then_some(false)
            }
            _ => {
                // Rest or chaos would differ too: only a period whose turns give `class` matches.
                let can_match = periods.clone().any(|p| {
                    !self.violated[p]
                        && (m <= p || turns_class(self.theta[p] - self.theta[0]) == class)
                });
                (!can_match).then_some(true)
            }
        }
    }
}

/// The class of a repeating orbit that turns by `dtheta` over its period.
fn turns_class(dtheta: f64) -> SteadyClass {
    let turns = (dtheta / (2.0 * std::f64::consts::PI)).round();
    if turns > 0.0 {
        SteadyClass::RotationCcw
    } else if turns < 0.0 {
        SteadyClass::RotationCw
    } else {
        SteadyClass::Oscillation
    }
}

/// Simulates past a transient of `transient_periods` forcing periods, records `record_periods`
/// Poincaré points (at t = t0 + k·T, the forcing phase of t0) and classifies them.
/// Returns the class and the recorded points (θ, θ̇).
pub fn steady_state_of(
    model: &Model,
    opts: &SimOptions,
    y0: [f64; 2],
    t0: f64,
    transient_periods: u32,
    record_periods: u32,
    copts: &ClassifyOptions,
) -> Result<(SteadyState, Vec<f64>, Vec<f64>), ModelError> {
    let period = model.params.forcing_period();
    let period = if period.is_finite() {
        period
    } else {
        2.0 * std::f64::consts::PI
    };
    let t_rec = t0 + transient_periods as f64 * period;
    let t_end = t_rec + record_periods as f64 * period;
    let mut th = Vec::with_capacity(record_periods as usize + 1);
    let mut thd = Vec::with_capacity(record_periods as usize + 1);
    let times = (0..=record_periods).map(|k| t_rec + k as f64 * period);
    let stats = integrate(model, opts, t0, y0, t_end, times, |s| {
        th.push(s.theta);
        thd.push(s.theta_dot);
        ControlFlow::Continue(())
    })?;
    let _ = stats;
    let mut s = classify_poincare(&th, &thd, copts);
    s.mean_theta_dot /= period;
    Ok((s, th, thd))
}

/// Classifies a sampled θ(t) history — simulated or measured — without θ̇: samples θ at one
/// point per period, and uses θ a quarter period later as the second coordinate (it plays θ̇'s
/// role and needs no differentiation of noisy data). `t` must be increasing.
pub fn classify_history(
    t: &[f64],
    theta: &[f64],
    period: f64,
    t_from: f64,
    opts: &ClassifyOptions,
) -> Result<SteadyState, ModelError> {
    if t.len() != theta.len() || t.len() < 4 {
        return Err(ModelError::BadInput(format!(
            "history needs ≥ 4 samples and equal lengths (t {}, theta {})",
            t.len(),
            theta.len()
        )));
    }
    if !(period > 0.0) {
        return Err(ModelError::BadInput(format!("period {period} must be > 0")));
    }
    let interp = |x: f64| -> f64 {
        let i = t.partition_point(|&v| v < x).clamp(1, t.len() - 1);
        let (t0, t1) = (t[i - 1], t[i]);
        let w = if t1 > t0 { (x - t0) / (t1 - t0) } else { 0.0 };
        theta[i - 1] + w * (theta[i] - theta[i - 1])
    };
    let t_last = t[t.len() - 1] - 0.25 * period;
    let mut a = Vec::new();
    let mut b = Vec::new();
    let mut x = t_from.max(t[0]);
    while x <= t_last {
        a.push(interp(x));
        // The quarter-period-later angle difference, scaled to θ̇ units.
        b.push((interp(x + 0.25 * period) - interp(x)) / (0.25 * period));
        x += period;
    }
    if a.len() < 2 {
        return Err(ModelError::BadInput(format!(
            "history from t={t_from} holds fewer than 2 forcing periods of {period}"
        )));
    }
    let mut s = classify_poincare(&a, &b, opts);
    s.mean_theta_dot /= period;
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for c in SteadyClass::ALL {
            assert_eq!(c.as_str().parse::<SteadyClass>().unwrap(), c);
        }
        assert!("spinning".parse::<SteadyClass>().is_err());
    }

    /// Whenever a prefix decides, the full classification agrees with it.
    #[test]
    fn partial_class_decisions_hold() {
        let o = ClassifyOptions::default();
        let two_pi = 2.0 * std::f64::consts::PI;
        let n = 40;
        let series: Vec<(Vec<f64>, Vec<f64>)> = vec![
            // Period-2 oscillation after a 10-point transient.
            (
                (0..n)
                    .map(|k| {
                        if k < 10 {
                            0.1 * k as f64
                        } else if k % 2 == 0 {
                            0.5
                        } else {
                            -0.4
                        }
                    })
                    .collect(),
                (0..n)
                    .map(|k| if k % 2 == 0 { 0.1 } else { -0.2 })
                    .collect(),
            ),
            // Clockwise rotation, settling late.
            (
                (0..n)
                    .map(|k| 0.3 - two_pi * k as f64 + if k < 30 { 0.01 * k as f64 } else { 0.0 })
                    .collect(),
                vec![-1.2; n],
            ),
            // Rest after motion; rest throughout.
            (
                (0..n).map(|k| if k < 5 { 0.2 } else { 0.01 }).collect(),
                vec![0.0; n],
            ),
            (vec![0.01; n], vec![0.0; n]),
            // Irregular.
            (
                (0..n)
                    .map(|k| ((k * k * 7919) % 101) as f64 * 0.05)
                    .collect(),
                (0..n).map(|k| ((k * 31) % 17) as f64 * 0.05).collect(),
            ),
        ];
        let mut decided = 0;
        for (th, w) in &series {
            let full = classify_poincare(th, w, &o).class;
            for class in SteadyClass::ALL {
                let mut pc = PartialClass::new(n, &o);
                for k in 0..n {
                    pc.push(th[k], w[k]);
                    if let Some(d) = pc.differs_from(class) {
                        assert_eq!(d, full != class, "{class} vs {full} after {} points", k + 1);
                        decided += 1;
                        break;
                    }
                }
            }
        }
        assert!(decided >= 10, "{decided}");
    }

    #[test]
    fn synthetic_sections() {
        let o = ClassifyOptions::default();
        let two_pi = 2.0 * std::f64::consts::PI;
        // Period-2 oscillation.
        let th: Vec<f64> = (0..40)
            .map(|k| if k % 2 == 0 { 0.5 } else { -0.4 })
            .collect();
        let w: Vec<f64> = (0..40)
            .map(|k| if k % 2 == 0 { 0.1 } else { -0.2 })
            .collect();
        let s = classify_poincare(&th, &w, &o);
        assert_eq!((s.class, s.period), (SteadyClass::Oscillation, 2));
        // Period-1 clockwise rotation: one turn per period.
        let th: Vec<f64> = (0..40).map(|k| 0.3 - two_pi * k as f64).collect();
        let w = vec![-1.2; 40];
        let s = classify_poincare(&th, &w, &o);
        assert_eq!((s.class, s.period), (SteadyClass::RotationCw, 1));
        assert!((s.mean_theta_dot + two_pi).abs() < 1e-12);
        // Rest.
        let s = classify_poincare(&[0.01; 30], &[0.0; 30], &o);
        assert_eq!(s.class, SteadyClass::Rest);
        // Irregular.
        let th: Vec<f64> = (0..60)
            .map(|k| ((k * k * 7919) % 101) as f64 * 0.05)
            .collect();
        let s = classify_poincare(&th, &th, &o);
        assert_eq!(s.class, SteadyClass::Chaos);
    }
}
