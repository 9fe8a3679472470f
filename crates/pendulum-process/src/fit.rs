//! The study's identification: Differential Evolution on E_θ = Σ_j Σ_k |θ̂_jk − θ_j(t_k)| over
//! each run's fit window, with a steady-state penalty, over the damping parameters and every
//! identify run's initial state.
//!
//! Penalty: run j's term is multiplied by κ when the steady state its simulation reaches (over
//! the same tail of the capture that classified the measurement) differs from the measured one:
//! f = Σ_j E_j·(κ if class_j differs else 1). Since every factor is ≥ 1, a partial sum of the E_j
//! is a lower bound of f, which is what lets a trial be abandoned as soon as it exceeds its target
//! (the selection is then the same as the plain algorithm's).
//!
//! Free decays (runs aligned as [`crate::AlignmentKind::FreeDecay`]) go through the same objective
//! with the excitation off. m, l and the inertia are not separable from θ(t) alone, so their
//! model is fitted in identifiable terms (`ModelSpec::free_decay`): the small-swing natural
//! frequency ω0 (rad/s) and the dimensionless damping of `pendulum_model::Dimensionless` in
//! t = ω0·τ (β, α, M, c: torques per unit inertia over ω0 or ω0²), plus the swing's centre. A
//! run's times are made dimensionless with its period-derived ω0 estimate; a trial ω0 rescales
//! them by ω0/ω0_est (and velocities by the inverse).

use std::ops::ControlFlow;

use pendulum_fit::{Cost, Problem};
use pendulum_model::{
    classify_poincare, integrate, ClassifyOptions, Effects, Model, Physical, SimOptions,
    SteadyClass, SteadyState,
};
use serde::{Deserialize, Serialize};

use crate::run::{RigParams, Role};

/// A parameter a model can fit, with its SI unit and the study's (or a plausible) search range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitParam {
    /// Quadratic drag a, kg/m.
    A,
    /// Linear drag b, N·s/m.
    B,
    /// Bearing friction μ.
    Mu,
    /// `coulomb_constant` T_c, N·m.
    CoulombConstant,
    /// `extra_inertia` J, kg·m².
    ExtraInertia,
    /// `horizontal_base` δ, rad.
    HorizontalBase,
    /// `position_torque` T_p (k = 1, φ_p fitted separately), N·m.
    PositionTorque,
    /// `position_torque` φ_p, rad.
    PositionTorquePhase,
    /// `encoder_offset` θ_off, rad.
    EncoderOffset,
    /// `accel_delay` Δ, s: the forcing leads the accelerometer-aligned clock by Δ.
    AccelDelay,
    /// `speed_drift` dΩ/dτ, Hz/s.
    SpeedDrift,
    /// Free decay: small-swing natural frequency ω0, rad/s (the unit of dimensionless time).
    Omega0,
    /// Free decay: β = viscous torque/(I ω0 θ̇) (`viscous_linear` per unit inertia).
    Beta,
    /// Free decay: α = quadratic drag torque/(I θ̇²) (`viscous_quadratic`).
    Alpha,
    /// Free decay: M = μ r_b m g/(I ω0²) (`coulomb_bearing`, point-mass load |θ'² + cos θ|).
    MBearing,
    /// Free decay: c = T_c/(I ω0²) (`coulomb_constant`: the dead band's half-width, rad).
    DryC,
}

impl FitParam {
    /// Column name in the outputs.
    pub fn name(self) -> &'static str {
        match self {
            FitParam::A => "a",
            FitParam::B => "b",
            FitParam::Mu => "mu",
            FitParam::CoulombConstant => "coulomb_constant.T_c",
            FitParam::ExtraInertia => "extra_inertia.J",
            FitParam::HorizontalBase => "horizontal_base.delta",
            FitParam::PositionTorque => "position_torque.T_p",
            FitParam::PositionTorquePhase => "position_torque.phi_p",
            FitParam::EncoderOffset => "encoder_offset.theta_off",
            FitParam::AccelDelay => "accel_delay.Delta",
            FitParam::SpeedDrift => "speed_drift.dOmega_dtau",
            FitParam::Omega0 => "omega0_rad_s",
            FitParam::Beta => "beta",
            FitParam::Alpha => "alpha",
            FitParam::MBearing => "M",
            FitParam::DryC => "c",
        }
    }

    pub fn unit(self) -> &'static str {
        match self {
            FitParam::A => "kg/m",
            FitParam::B => "N·s/m",
            FitParam::Mu => "1",
            FitParam::CoulombConstant | FitParam::PositionTorque => "N·m",
            FitParam::ExtraInertia => "kg·m²",
            FitParam::HorizontalBase | FitParam::PositionTorquePhase | FitParam::EncoderOffset => {
                "rad"
            }
            FitParam::AccelDelay => "s",
            FitParam::SpeedDrift => "Hz/s",
            FitParam::Omega0 => "rad/s",
            FitParam::Beta | FitParam::MBearing => "1",
            FitParam::Alpha => "1/rad",
            FitParam::DryC => "rad",
        }
    }

    /// Search bounds: the study's for a, b, μ (0 < a < 1, 0 < b < 1, 0 < μ < 0.25).
    pub fn bounds(self) -> (f64, f64) {
        match self {
            FitParam::A => (0.0, 1.0),
            FitParam::B => (0.0, 1.0),
            FitParam::Mu => (0.0, 0.25),
            FitParam::CoulombConstant => (0.0, 0.05),
            FitParam::ExtraInertia => (0.0, 0.02),
            FitParam::HorizontalBase => (-0.2, 0.2),
            FitParam::PositionTorque => (0.0, 0.1),
            FitParam::PositionTorquePhase => (-std::f64::consts::PI, std::f64::consts::PI),
            FitParam::EncoderOffset => (-0.2, 0.2),
            FitParam::AccelDelay => (-0.05, 0.05),
            FitParam::SpeedDrift => (-0.01, 0.01),
            // Relative to the period-derived estimate: the objective scales it (see `bounds`).
            FitParam::Omega0 => (0.95, 1.05),
            FitParam::Beta => (0.0, 0.2),
            FitParam::Alpha => (0.0, 0.5),
            FitParam::MBearing | FitParam::DryC => (0.0, 0.05),
        }
    }

    fn apply(self, v: f64, p: &mut Physical) {
        let e = &mut p.effects;
        match self {
            FitParam::A => p.a_kg_m = v,
            FitParam::B => p.b_n_s_m = v,
            FitParam::Mu => p.mu = v,
            FitParam::CoulombConstant => e.coulomb_constant_t_c_nm = Some(v),
            FitParam::ExtraInertia => e.extra_inertia_j_kg_m2 = Some(v),
            FitParam::HorizontalBase => e.horizontal_base_delta_rad = Some(v),
            FitParam::PositionTorque | FitParam::PositionTorquePhase => {
                let mut pt = e.position_torque.unwrap_or(pendulum_model::PositionTorque {
                    t_p_nm: 0.0,
                    k: 1,
                    phi_p_rad: 0.0,
                });
                if self == FitParam::PositionTorque {
                    pt.t_p_nm = v;
                } else {
                    pt.phi_p_rad = v;
                }
                e.position_torque = Some(pt);
            }
            FitParam::EncoderOffset => e.encoder_offset_rad = Some(v),
            FitParam::AccelDelay => e.accel_delay_s = Some(v),
            FitParam::SpeedDrift => e.speed_drift_hz_per_s = Some(v),
            // Identifiable ratios of a free decay: no SI counterpart without m, l and J.
            FitParam::Omega0
            | FitParam::Beta
            | FitParam::Alpha
            | FitParam::MBearing
            | FitParam::DryC => {}
        }
    }

    /// Free-decay parameters (identifiable ratios, excitation off).
    pub fn is_free_decay(self) -> bool {
        matches!(
            self,
            FitParam::Omega0
                | FitParam::Beta
                | FitParam::Alpha
                | FitParam::MBearing
                | FitParam::DryC
        )
    }
}

/// A model to fit: which parameters are free; the rest are zero (or as in `fixed`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelSpec {
    pub name: String,
    pub params: Vec<FitParam>,
    /// Effects held fixed (e.g. `bearing_load_base_accel = true`).
    #[serde(default)]
    pub fixed: Effects,
}

impl ModelSpec {
    /// The study's model: a, b, μ.
    pub fn reference() -> Self {
        Self {
            name: "reference".into(),
            params: vec![FitParam::A, FitParam::B, FitParam::Mu],
            fixed: Effects::default(),
        }
    }

    /// The classic linear model: b only.
    pub fn linear() -> Self {
        Self {
            name: "linear".into(),
            params: vec![FitParam::B],
            fixed: Effects::default(),
        }
    }

    /// Dry bearing friction alone: μ only (the base in which `viscous_linear` can be missing).
    pub fn dry() -> Self {
        Self {
            name: "dry".into(),
            params: vec![FitParam::Mu],
            fixed: Effects::default(),
        }
    }

    /// By name: `reference`, `linear` or `dry`.
    pub fn by_name(name: &str) -> Option<Self> {
        match name {
            "reference" => Some(Self::reference()),
            "linear" => Some(Self::linear()),
            "dry" => Some(Self::dry()),
            _ => None,
        }
    }

    /// The same model for free decays, in identifiable terms: ω0 first, then each damping term
    /// as its ratio per unit inertia (a → α, b → β, μ → M, T_c → c), and the swing's centre
    /// (`encoder_offset`), which a decay of a few hundredths of a radian cannot do without.
    /// Effects that need a shaker or an SI inertia are refused (the error says which).
    pub fn free_decay(&self) -> Result<ModelSpec, String> {
        if self.is_free_decay() {
            return Ok(self.clone());
        }
        let mut params = vec![FitParam::Omega0];
        for p in &self.params {
            let q = match p {
                FitParam::A => FitParam::Alpha,
                FitParam::B => FitParam::Beta,
                FitParam::Mu => FitParam::MBearing,
                FitParam::CoulombConstant => FitParam::DryC,
                FitParam::EncoderOffset => FitParam::EncoderOffset,
                other => {
                    return Err(format!(
                    "{} cannot be fitted to a free decay (no shaker; inertia absorbed in omega0)",
                    other.name()
                ))
                }
            };
            if !params.contains(&q) {
                params.push(q);
            }
        }
        if !params.contains(&FitParam::EncoderOffset) {
            params.push(FitParam::EncoderOffset);
        }
        Ok(ModelSpec {
            name: self.name.clone(),
            params,
            fixed: Effects::default(),
        })
    }

    /// Whether this is a free-decay model (fits ω0 in identifiable terms).
    pub fn is_free_decay(&self) -> bool {
        self.params.contains(&FitParam::Omega0)
    }

    /// Value of a parameter in `x`, if the model fits it.
    pub fn value_of(&self, p: FitParam, x: &[f64]) -> Option<f64> {
        self.params
            .iter()
            .zip(x)
            .find(|(q, _)| **q == p)
            .map(|(_, v)| *v)
    }

    /// The dimensionless free-decay model for values `x` (excitation off).
    pub fn free_model(&self, x: &[f64]) -> Model {
        let mut d = pendulum_model::Dimensionless::conservative();
        for (p, &v) in self.params.iter().zip(x) {
            match p {
                FitParam::Beta => d.beta = v,
                FitParam::Alpha => d.alpha = v,
                FitParam::MBearing => d.m_coulomb = v,
                FitParam::DryC => d.c = v,
                _ => {}
            }
        }
        Model::with_excitation(d, pendulum_model::Excitation::None)
    }

    /// The model a run is simulated with: driven by its crank, or free (excitation off).
    pub fn run_model(&self, run: &PreparedRun, x: &[f64]) -> Model {
        if run.free {
            self.free_model(x)
        } else {
            // model_for: an accel_delay shifts the forcing's phase (Model::new alone would drop it).
            model_for(&self.physical(&run.rig, run.omega_hz, x))
        }
    }

    /// Factor from a run's time unit to the model's: ω0/ω0_est for a free decay whose ω0 is
    /// fitted, else exactly 1.
    pub fn time_scale(&self, run: &PreparedRun, x: &[f64]) -> f64 {
        match self.value_of(FitParam::Omega0, x) {
            Some(w) if run.free => w / run.omega0_rad_s,
            _ => 1.0,
        }
    }

    /// The physical parameters of a run for the model's parameter values `x`.
    pub fn physical(&self, rig: &RigParams, omega_hz: f64, x: &[f64]) -> Physical {
        let mut p = Physical {
            m_kg: rig.m_kg,
            l_m: rig.l_m,
            crank_r_m: rig.crank_r_m,
            rod_l_m: rig.rod_l_m,
            r_b_m: rig.r_b_m,
            omega_hz,
            g_m_s2: rig.g_m_s2,
            a_kg_m: 0.0,
            b_n_s_m: 0.0,
            mu: 0.0,
            effects: self.fixed.clone(),
        };
        for (param, &v) in self.params.iter().zip(x) {
            param.apply(v, &mut p);
        }
        p
    }
}

/// One run prepared for fitting: dimensionless times from the aligned t = 0.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PreparedRun {
    pub id: String,
    pub role: Role,
    pub rig: RigParams,
    /// Real crank speed from the alignment, Hz.
    pub omega_hz: f64,
    /// Fit-window sample times (dimensionless, t = ω0·τ from the aligned t = 0).
    pub t: Vec<f64>,
    /// Measured θ at those times, rad.
    pub theta: Vec<f64>,
    /// Estimated initial state (θ0 rad, dθ/dt dimensionless).
    pub ic_est: [f64; 2],
    /// Measured steady state of the tail.
    pub steady: SteadyState,
    /// Dimensionless times of the tail's Poincaré points (one per crank turn).
    pub tail_t: Vec<f64>,
    /// Tolerances the measured class used, for classifying the simulation the same way.
    pub classify: ClassifyOptions,
    /// Multiple shooting: later segments restart from the measured state, as (index of the
    /// segment's first sample in `t`, θ rad, dθ/dt dimensionless). Empty = single shooting over
    /// the whole window (the study's method).
    pub restarts: Vec<(usize, [f64; 2])>,
    /// A free decay (excitation off; `omega_hz` is NaN and `tail_t` are plain sample times).
    pub free: bool,
    /// The time unit of `t`, rad/s: sqrt(g/l) with a shaker, the period-derived ω0 estimate
    /// for a free decay.
    pub omega0_rad_s: f64,
}

impl PreparedRun {
    /// ω0 of the run, rad/s.
    pub fn omega0(&self) -> f64 {
        self.omega0_rad_s
    }

    /// Dimensionless crank period (a small swing's, 2π, for a free decay).
    pub fn period(&self) -> f64 {
        if self.free {
            2.0 * std::f64::consts::PI
        } else {
            self.omega0() / self.omega_hz
        }
    }
}

/// Outcome of one run's fit-window simulation.
enum Window {
    /// Σ|θ̂ − θ| over the window and the state at its last sample.
    Done(f64, [f64; 2]),
    /// The partial sum exceeded the bound: the value is that partial sum.
    Abandoned(f64),
    /// The integration failed.
    Failed,
}

/// Simulates `model` from `y0` through `run`'s window (θ measured = θ + `offset`); with
/// restarts, each later segment starts again from its measured state. `k` converts the run's
/// time unit to the model's (1 except for a free decay with a fitted ω0): times × k, rates / k.
/// The returned end state is in the model's units.
#[allow(clippy::too_many_arguments)]
fn window_error(
    model: &Model,
    opts: &SimOptions,
    run: &PreparedRun,
    y0: [f64; 2],
    offset: f64,
    bound: f64,
    k: f64,
) -> Window {
    let mut sum = 0.0;
    let mut end = y0;
    let n = run.t.len();
    if n == 0 {
        return Window::Done(0.0, y0);
    }
    // Initial and restart states are in measured coordinates (θ_meas = θ + offset).
    let mut starts: Vec<(usize, f64, [f64; 2])> = vec![(0, 0.0, [y0[0] - offset, y0[1] / k])];
    for &(i, y) in &run.restarts {
        if i > 0 && i < n {
            starts.push((i, run.t[i] * k, [y[0] - offset, y[1] / k]));
        }
    }
    let mut seg_opts = *opts;
    for (s, &(i0, t_start, y_start)) in starts.iter().enumerate() {
        let i1 = starts.get(s + 1).map_or(n, |x| x.0);
        let t_end = run.t[i1 - 1] * k;
        let mut j = i0;
        let res = integrate(
            model,
            &seg_opts,
            t_start,
            y_start,
            t_end,
            run.t[i0..i1].iter().map(|t| t * k),
            |smp| {
                sum += (run.theta[j] - (smp.theta + offset)).abs();
                j += 1;
                end = [smp.theta, smp.theta_dot];
                if sum > bound {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            },
        );
        match res {
            Ok(stats) if !stats.stopped_early => {
                if stats.last_h > 0.0 {
                    seg_opts.h_init = Some(stats.last_h);
                }
            }
            Ok(_) => return Window::Abandoned(sum),
            Err(_) => return Window::Failed,
        }
    }
    Window::Done(sum, end)
}

/// The simulated steady state over the run's tail, classified like the measurement
/// (θ at each Poincaré time and a quarter period later; a free decay's θ at its tail's sample
/// times, rest or not). `t_from` and `y_from` are in the model's time unit, `k` as in
/// `window_error`.
pub fn simulated_steady(
    model: &Model,
    opts: &SimOptions,
    run: &PreparedRun,
    t_from: f64,
    y_from: [f64; 2],
    k: f64,
) -> Option<SteadyState> {
    if run.free {
        let times: Vec<f64> = run
            .tail_t
            .iter()
            .map(|t| t * k)
            .filter(|&t| t >= t_from)
            .collect();
        let t_end = *times.last()?;
        let mut th = Vec::with_capacity(times.len());
        integrate(
            model,
            opts,
            t_from,
            y_from,
            t_end,
            times.iter().copied(),
            |s| {
                th.push(s.theta);
                ControlFlow::Continue(())
            },
        )
        .ok()?;
        return Some(crate::measured::classify_free(&th, run.classify.rest_tol));
    }
    let q = 0.25 * run.period();
    let mut times: Vec<f64> = Vec::with_capacity(run.tail_t.len() * 2);
    for &t in &run.tail_t {
        if t >= t_from {
            times.push(t);
            times.push(t + q);
        }
    }
    if times.len() < 4 {
        return None;
    }
    let t_end = *times.last()?;
    let mut th = Vec::with_capacity(times.len());
    integrate(
        model,
        opts,
        t_from,
        y_from,
        t_end,
        times.iter().copied(),
        |s| {
            th.push(s.theta);
            ControlFlow::Continue(())
        },
    )
    .ok()?;
    let a: Vec<f64> = th.iter().step_by(2).copied().collect();
    let b: Vec<f64> = th
        .chunks(2)
        .filter(|c| c.len() == 2)
        .map(|c| (c[1] - c[0]) / q)
        .collect();
    let n = a.len().min(b.len());
    let mut s = classify_poincare(&a[..n], &b[..n], &run.classify);
    s.mean_theta_dot /= run.period();
    Some(s)
}

/// The model of a physical parameter set, driven by the aligned crank (φ = ωt at t = 0), with
/// `accel_delay` shifting the forcing: the accelerometer's peak came Δ after the true one, so the
/// true crank angle is ω(t + Δ).
pub fn model_for(phys: &Physical) -> Model {
    let d = phys.to_dimensionless();
    let mut m = Model::new(d);
    if let (Some(delay_s), pendulum_model::Excitation::Crank(c)) =
        (phys.effects.accel_delay_s, &mut m.excitation)
    {
        c.phi0 = d.omega * delay_s * phys.omega0_rad_s();
    }
    m
}

/// Cost value used for a trial whose simulation failed: finite (DE needs it) and huge.
pub const FAILED_COST: f64 = 1e12;

/// The study's objective over a set of runs (one `Problem` for the DE driver).
pub struct StudyObjective<'a> {
    pub runs: &'a [PreparedRun],
    pub spec: &'a ModelSpec,
    /// Steady-state penalty factor κ ≥ 1.
    pub kappa: f64,
    pub sim: SimOptions,
    /// Half-width of each initial-condition box around its estimate (θ rad, dθ/dt dimensionless).
    pub ic_halfwidth: f64,
    /// Damping parameters held fixed (validation): the objective's variables are then the ICs only.
    pub fixed_params: Option<Vec<f64>>,
    /// Whether to apply the steady-state penalty.
    pub penalty: bool,
}

/// The breakdown of one evaluation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    pub f_obj: f64,
    pub e_theta: f64,
    pub per_run_e: Vec<f64>,
    pub per_run_sim_steady: Vec<Option<SteadyState>>,
}

impl StudyObjective<'_> {
    fn n_params(&self) -> usize {
        if self.fixed_params.is_some() {
            0
        } else {
            self.spec.params.len()
        }
    }

    /// Splits x into the damping parameters and the per-run initial states.
    pub fn split<'x>(&'x self, x: &'x [f64]) -> (Vec<f64>, &'x [f64]) {
        match &self.fixed_params {
            Some(p) => (p.clone(), x),
            None => {
                let n = self.spec.params.len();
                (x[..n].to_vec(), &x[n..])
            }
        }
    }

    /// The model of run j for parameters p.
    pub fn model_of(&self, run: &PreparedRun, p: &[f64]) -> Model {
        self.spec.run_model(run, p)
    }

    fn offset(&self, p: &[f64]) -> f64 {
        self.spec
            .params
            .iter()
            .zip(p)
            .find(|(q, _)| **q == FitParam::EncoderOffset)
            .map_or(
                self.spec.fixed.encoder_offset_rad.unwrap_or(0.0),
                |(_, v)| *v,
            )
    }

    /// Full evaluation with the per-run breakdown (no abandoning).
    pub fn evaluate(&self, x: &[f64]) -> Evaluation {
        let (p, ics) = self.split(x);
        let off = self.offset(&p);
        let mut per_run_e = Vec::new();
        let mut steadies = Vec::new();
        let mut f = 0.0;
        for (j, run) in self.runs.iter().enumerate() {
            let model = self.model_of(run, &p);
            let k = self.spec.time_scale(run, &p);
            let y0 = [ics[2 * j], ics[2 * j + 1]];
            match window_error(&model, &self.sim, run, y0, off, f64::INFINITY, k) {
                Window::Done(e, end) => {
                    let t_last = *run.t.last().unwrap_or(&0.0) * k;
                    let st = simulated_steady(&model, &self.sim, run, t_last, end, k);
                    let differs = st.is_none_or(|s| s.class != run.steady.class);
                    f += if self.penalty && differs {
                        self.kappa * e
                    } else {
                        e
                    };
                    per_run_e.push(e);
                    steadies.push(st);
                }
                Window::Abandoned(_) | Window::Failed => {
                    per_run_e.push(FAILED_COST);
                    steadies.push(None);
                    f += FAILED_COST;
                }
            }
        }
        Evaluation {
            f_obj: f,
            e_theta: per_run_e.iter().sum(),
            per_run_e,
            per_run_sim_steady: steadies,
        }
    }
}

impl Problem for StudyObjective<'_> {
    fn dim(&self) -> usize {
        self.n_params() + 2 * self.runs.len()
    }

    fn bounds(&self) -> Vec<(f64, f64)> {
        // ω0's bounds are relative to the runs' period-derived estimate (one pendulum per
        // campaign: their mean); a free decay's centre is within a few degrees of hanging.
        let w_est = {
            let w: Vec<f64> = self.runs.iter().map(|r| r.omega0_rad_s).collect();
            w.iter().sum::<f64>() / w.len().max(1) as f64
        };
        let free = self.spec.is_free_decay();
        let mut b: Vec<(f64, f64)> = if self.fixed_params.is_some() {
            Vec::new()
        } else {
            self.spec
                .params
                .iter()
                .map(|p| match p {
                    FitParam::Omega0 => {
                        let (lo, hi) = p.bounds();
                        (lo * w_est, hi * w_est)
                    }
                    FitParam::EncoderOffset if free => (-0.05, 0.05),
                    _ => p.bounds(),
                })
                .collect()
        };
        for run in self.runs {
            for v in run.ic_est {
                b.push((v - self.ic_halfwidth, v + self.ic_halfwidth));
            }
        }
        b
    }

    fn cost(&self, x: &[f64], bound: f64) -> Cost {
        let (p, ics) = self.split(x);
        let off = self.offset(&p);
        let models: Vec<Model> = self.runs.iter().map(|r| self.model_of(r, &p)).collect();
        let ks: Vec<f64> = self
            .runs
            .iter()
            .map(|r| self.spec.time_scale(r, &p))
            .collect();
        let mut es = Vec::with_capacity(self.runs.len());
        let mut ends = Vec::with_capacity(self.runs.len());
        let mut total = 0.0;
        for (j, run) in self.runs.iter().enumerate() {
            let y0 = [ics[2 * j], ics[2 * j + 1]];
            match window_error(&models[j], &self.sim, run, y0, off, bound - total, ks[j]) {
                Window::Done(e, end) => {
                    total += e;
                    es.push(e);
                    ends.push(end);
                }
                // The true cost is ≥ total + partial > bound; report a value strictly above bound.
                Window::Abandoned(partial) => {
                    return Cost::AtLeast((total + partial).max(bound.next_up()));
                }
                Window::Failed => {
                    return if FAILED_COST > bound {
                        Cost::AtLeast(FAILED_COST)
                    } else {
                        Cost::Exact(FAILED_COST)
                    };
                }
            }
        }
        if self.penalty && self.kappa > 1.0 {
            for (j, run) in self.runs.iter().enumerate() {
                if total > bound {
                    return Cost::AtLeast(total.max(bound.next_up()));
                }
                let t_last = *run.t.last().unwrap_or(&0.0) * ks[j];
                let st = simulated_steady(&models[j], &self.sim, run, t_last, ends[j], ks[j]);
                if st.is_none_or(|s| s.class != run.steady.class) {
                    total += (self.kappa - 1.0) * es[j];
                }
            }
        }
        // Exact even when above the bound: the driver only needs AtLeast to be a lower bound.
        Cost::Exact(total)
    }
}

/// Whether two classes agree (periods are not compared: a measured period-2 that a simulation
/// reaches as period 2 or 4 is the same kind of motion for a harvester).
pub fn classes_agree(a: SteadyClass, b: SteadyClass) -> bool {
    a == b
}
