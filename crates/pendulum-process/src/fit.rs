//! The study's identification: Differential Evolution on E_θ = Σ_j Σ_k |θ̂_jk − θ_j(t_k)| over
//! each run's fit window, with a steady-state penalty, over the damping parameters and every
//! identify run's initial state.
//!
//! Penalty: run j's term is multiplied by κ when the steady state its simulation reaches (over
//! the same tail of the capture that classified the measurement) differs from the measured one:
//! f = Σ_j E_j·(κ if class_j differs else 1). Since every factor is ≥ 1, a partial sum of the E_j
//! is a lower bound of f, which is what lets a trial be abandoned as soon as it exceeds its target
//! (the selection is then the same as the plain algorithm's). To get there early, a bounded
//! evaluation integrates the window segments with the largest typical error first and then the
//! tails likeliest to be penalised, and stops a tail once its class is decided; the value is
//! summed in a fixed order, so it never depends on the bound.
//!
//! Free decays (runs aligned as [`crate::AlignmentKind::FreeDecay`]) go through the same objective
//! with the excitation off. m, l and the inertia are not separable from θ(t) alone, so their
//! model is fitted in identifiable terms (`ModelSpec::free_decay`): the small-swing natural
//! frequency ω0 (rad/s) and the dimensionless damping of `pendulum_model::Dimensionless` in
//! t = ω0·τ (β, α, M, c: torques per unit inertia over ω0 or ω0²), plus the swing's centre. A
//! run's times are made dimensionless with its period-derived ω0 estimate; a trial ω0 rescales
//! them by ω0/ω0_est (and velocities by the inverse).

use std::collections::BTreeMap;
use std::ops::ControlFlow;
use std::sync::atomic::AtomicU64;
use std::sync::atomic::Ordering::Relaxed;
use std::sync::OnceLock;

use pendulum_fit::{Cost, Problem};
use pendulum_model::{
    classify_poincare, integrate, ClassifyOptions, EffectParam, Effects, Model, PartialClass,
    Physical, SimOptions, SteadyClass, SteadyState,
};
use serde::{Deserialize, Serialize};

use crate::run::{RigParams, Role};

/// A parameter a model can fit. The SI ones are the catalogue's (`pendulum_model::effects`):
/// their name, unit, search range and how they enter the model come from the effect's entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FitParam {
    /// Quadratic drag a, kg/m (`viscous_quadratic`).
    A,
    /// Linear drag b, N·s/m (`viscous_linear`).
    B,
    /// Bearing friction μ (`coulomb_bearing`).
    Mu,
    /// Any other refitted parameter of the catalogue, e.g. `coulomb_constant.T_c`.
    Effect(EffectParam),
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

/// A free-decay parameter: (it, spec name, column name, unit, bounds).
type FreeDecayParam = (
    FitParam,
    &'static str,
    &'static str,
    &'static str,
    (f64, f64),
);

/// Free-decay parameters (identifiable ratios: not the catalogue's SI ones).
const FREE_DECAY: [FreeDecayParam; 5] = [
    // ω0's bounds are relative to the run's estimate.
    (
        FitParam::Omega0,
        "omega0",
        "omega0_rad_s",
        "rad/s",
        (0.95, 1.05),
    ),
    (FitParam::Beta, "beta", "beta", "1", (0.0, 0.2)),
    (FitParam::Alpha, "alpha", "alpha", "1/rad", (0.0, 0.5)),
    (FitParam::MBearing, "m_bearing", "M", "1", (0.0, 0.05)),
    (FitParam::DryC, "dry_c", "c", "rad", (0.0, 0.05)),
];

impl FitParam {
    /// The parameter a spec or the code names: `a`, `b`, `mu`, an effect's key
    /// (`position_torque.phi_p`) or an effect's name (its first refitted parameter:
    /// `coulomb_constant`), or a free-decay ratio (`beta`, `dry_c`, …).
    pub fn find(name: &str) -> Option<Self> {
        if let Some(f) = FREE_DECAY.iter().find(|f| f.1 == name) {
            return Some(f.0);
        }
        // Written by the enum this replaced.
        let name = if name == "position_torque_phase" {
            "position_torque.phi_p"
        } else {
            name
        };
        let ep = EffectParam::find(name)?;
        Some(Self::from_effect(ep))
    }

    /// Like [`FitParam::find`], for names in the code (panics on a name the catalogue lacks).
    pub fn of(name: &str) -> Self {
        Self::find(name).unwrap_or_else(|| panic!("no fit parameter {name:?}"))
    }

    fn from_effect(ep: EffectParam) -> Self {
        match ep.def().key {
            "a" => FitParam::A,
            "b" => FitParam::B,
            "mu" => FitParam::Mu,
            _ => FitParam::Effect(ep),
        }
    }

    /// The catalogue parameter, for the SI ones.
    pub fn effect_param(self) -> Option<EffectParam> {
        match self {
            FitParam::A => Some(EffectParam::of("a")),
            FitParam::B => Some(EffectParam::of("b")),
            FitParam::Mu => Some(EffectParam::of("mu")),
            FitParam::Effect(ep) => Some(ep),
            _ => None,
        }
    }

    /// The catalogue effect it belongs to (`None` for the free-decay ratios).
    pub fn effect_name(self) -> Option<&'static str> {
        self.effect_param().map(|ep| ep.effect().name())
    }

    /// Every refitted SI parameter of the catalogue beyond a, b, μ (the outputs' columns).
    pub fn all_effects() -> Vec<FitParam> {
        EffectParam::all_fitted()
            .into_iter()
            .map(Self::from_effect)
            .filter(|p| matches!(p, FitParam::Effect(_)))
            .collect()
    }

    fn free(self) -> Option<&'static FreeDecayParam> {
        FREE_DECAY.iter().find(|f| f.0 == self)
    }

    /// Column name in the outputs.
    pub fn name(self) -> &'static str {
        match self.effect_param() {
            Some(ep) => ep.def().key,
            None => self.free().expect("a free-decay parameter").2,
        }
    }

    pub fn unit(self) -> &'static str {
        match self.effect_param() {
            Some(ep) => ep.def().unit,
            None => self.free().expect("a free-decay parameter").3,
        }
    }

    /// Search bounds: the catalogue's (the study's for a, b, μ: 0 < a < 1, 0 < b < 1,
    /// 0 < μ < 0.25).
    pub fn bounds(self) -> (f64, f64) {
        match self.effect_param() {
            Some(ep) => ep
                .def()
                .fit_range
                .unwrap_or_else(|| panic!("{} is not refitted", ep.def().key)),
            None => self.free().expect("a free-decay parameter").4,
        }
    }

    fn apply(self, v: f64, p: &mut Physical) {
        // Identifiable ratios of a free decay have no SI counterpart without m, l and J.
        if let Some(ep) = self.effect_param() {
            ep.apply(v, p);
        }
    }

    /// Free-decay parameters (identifiable ratios, excitation off).
    pub fn is_free_decay(self) -> bool {
        self.free().is_some()
    }

    /// The name a spec is written with (what [`FitParam::find`] reads back).
    pub fn spec_name(self) -> &'static str {
        match self.effect_param() {
            Some(ep) => ep.spec_name(),
            None => self.free().expect("a free-decay parameter").1,
        }
    }
}

impl Serialize for FitParam {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.spec_name())
    }
}

impl<'de> Deserialize<'de> for FitParam {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        FitParam::find(&name).ok_or_else(|| {
            let mut known: Vec<&str> = vec!["a", "b", "mu"];
            known.extend(FitParam::all_effects().iter().map(|p| p.spec_name()));
            serde::de::Error::custom(format!(
                "unknown fit parameter {name:?}: expected one of {}",
                known.join(", ")
            ))
        })
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
    /// Search ranges widened past the catalogue's (by [`FitParam::spec_name`]; see
    /// [`ModelSpec::widen_at_bounds`]). Empty: every parameter searches its catalogue range.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub ranges: BTreeMap<String, (f64, f64)>,
}

/// How many times a fit widens a search range its estimate was pinned at (each doubles the
/// range's span on that side): up to 8 times the catalogue's span.
pub const MAX_WIDENINGS: usize = 3;

/// An end of a search range.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    Lower,
    Upper,
}

/// `range` of `p` widened on `side`: the span doubled that way (a positive lower end halved),
/// or `None` where that end is physics (0 of a range that starts or ends there) or the range
/// has reached 2^[`MAX_WIDENINGS`] times the catalogue's span (a positive lower end, 1/2^… of
/// the catalogue's).
fn widened_range(p: FitParam, (lo, hi): (f64, f64), side: Side) -> Option<(f64, f64)> {
    let (lo0, hi0) = p.bounds();
    let cap = f64::from(1u32 << MAX_WIDENINGS);
    let span = hi - lo;
    let new = match side {
        Side::Upper if hi != 0.0 => (lo, hi + span),
        Side::Lower if lo > 0.0 => (lo / 2.0, hi),
        Side::Lower if lo < 0.0 => (lo - span, hi),
        _ => return None,
    };
    let too_wide = new.1 - new.0 > cap * (hi0 - lo0) * (1.0 + 1e-9);
    let too_low = lo0 > 0.0 && new.0 < lo0 / cap * (1.0 - 1e-9);
    (!too_wide && !too_low).then_some(new)
}

impl ModelSpec {
    /// The study's model: a, b, μ.
    pub fn reference() -> Self {
        Self {
            name: "reference".into(),
            params: vec![FitParam::A, FitParam::B, FitParam::Mu],
            fixed: Effects::default(),
            ranges: BTreeMap::new(),
        }
    }

    /// Where this model's parameter vector holds the parameter keyed `key` (`"stribeck.v_s"`),
    /// if it fits it.
    pub fn index_of(&self, key: &str) -> Option<usize> {
        FitParam::find(key).and_then(|p| self.params.iter().position(|q| *q == p))
    }

    /// The search range of `p` in this model: widened, or the catalogue's ([`FitParam::bounds`]).
    pub fn range(&self, p: FitParam) -> (f64, f64) {
        self.ranges
            .get(p.spec_name())
            .copied()
            .unwrap_or_else(|| p.bounds())
    }

    /// The end of `p`'s search range that `v` sits at (within a thousandth of the span), if any:
    /// there the range, not the data, set the value.
    pub fn at_end(&self, p: FitParam, v: f64) -> Option<Side> {
        let (lo, hi) = self.range(p);
        let tol = 1e-3 * (hi - lo);
        if v >= hi - tol {
            Some(Side::Upper)
        } else if v <= lo + tol {
            Some(Side::Lower)
        } else {
            None
        }
    }

    /// Widens the search range of each parameter whose value in `x` (one per [`Self::params`]) sits
    /// at an end of it that is a search convenience, not physics, by doubling the span on that
    /// side; returns the names widened. A catalogue range is the search's: the data may put a
    /// bearing's μ at 0.35 (the study's μ < 0.25 pinned a drawn campaign's at 0.24999) or b at 1.2
    /// N·s/m (twice the survey's, pinned at the study's 1). Only an end at 0 of a range that starts
    /// there is physical (a loss, a torque's size, an inertia cannot be negative), and it stays.
    /// The SI catalogue parameters only: ω0 and a free decay's ratios keep their data-derived
    /// bounds, and an integer is never fitted.
    pub fn widen_at_bounds(&mut self, x: &[f64]) -> Vec<&'static str> {
        let mut widened = Vec::new();
        for (&p, &v) in self.params.clone().iter().zip(x) {
            let Some(ep) = p.effect_param() else { continue };
            if ep.def().integer || !v.is_finite() {
                continue;
            }
            let Some(side) = self.at_end(p, v) else {
                continue;
            };
            if let Some(new) = widened_range(p, self.range(p), side) {
                self.ranges.insert(p.spec_name().into(), new);
                widened.push(p.name());
            }
        }
        widened
    }

    /// Widens the search range of `p` (as [`Self::widen_at_bounds`] would, side by side, to at most
    /// 2^[`MAX_WIDENINGS`] times the catalogue's span) until `v` lies inside it with room to move:
    /// a tenth of the span below the upper end and above a lower end ≤ 0, a tenth of the end's own
    /// value above a positive lower end (halving it hardly changes the span). A refit that starts
    /// at a value the catalogue's range does not hold (the screen's estimate of a large effect) can
    /// then move. Never further: with a margin of a tenth of the span on the positive end too, a
    /// stribeck v_s of 0.2 rad/s "needed" its 0.01 floor halved without end, and the refit tried
    /// breakaways fading within 1e-11 rad/s, steps too sharp to integrate (a nothing-hidden
    /// campaign's discover took 280 s instead of 3).
    pub fn hold(&mut self, p: FitParam, v: f64) {
        let Some(ep) = p.effect_param() else { return };
        if ep.def().integer || !v.is_finite() {
            return;
        }
        loop {
            let (lo, hi) = self.range(p);
            let span = hi - lo;
            let side = if v > hi - 0.1 * span {
                Side::Upper
            } else if (lo > 0.0 && v < 1.1 * lo) || (lo < 0.0 && v < lo + 0.1 * span) {
                Side::Lower
            } else {
                return;
            };
            match widened_range(p, (lo, hi), side) {
                Some(new) => self.ranges.insert(p.spec_name().into(), new),
                None => return,
            };
        }
    }

    /// The classic linear model: b only.
    pub fn linear() -> Self {
        Self {
            name: "linear".into(),
            params: vec![FitParam::B],
            fixed: Effects::default(),
            ranges: BTreeMap::new(),
        }
    }

    /// Dry bearing friction alone: μ only (the base in which `viscous_linear` can be missing).
    pub fn dry() -> Self {
        Self {
            name: "dry".into(),
            params: vec![FitParam::Mu],
            fixed: Effects::default(),
            ranges: BTreeMap::new(),
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
            let q = match (p, p.effect_name()) {
                (FitParam::A, _) => FitParam::Alpha,
                (FitParam::B, _) => FitParam::Beta,
                (FitParam::Mu, _) => FitParam::MBearing,
                (_, Some("coulomb_constant")) => FitParam::DryC,
                (_, Some("encoder_offset")) => *p,
                (other, _) => {
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
        let offset = FitParam::of("encoder_offset");
        if !params.contains(&offset) {
            params.push(offset);
        }
        Ok(ModelSpec {
            name: self.name.clone(),
            params,
            fixed: Effects::default(),
            ranges: BTreeMap::new(),
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
            // The shared sensor transform: an accel_delay shifts the forcing's phase.
            Model::measured(&self.physical(&run.rig, run.omega_hz, x))
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
    /// This run's own encoder zeroing error, rad, on top of the model's offset (0 unless a
    /// caller has estimated it). The count is zeroed at every power-on to within a few counts
    /// (rig.md), and a 2-count error is a gravity torque of 3e-3 m g l, as large as a plausible
    /// dry torque: a caller comparing models on one run's fine torques can hold it as a nuisance
    /// of the run, as its initial state is.
    pub zero_rad: f64,
}

impl PreparedRun {
    /// The sample ranges in `t` of its multiple-shooting segments, in time order: the first from
    /// t = 0, each later one from a restart inside the window (none for an empty window). The
    /// objective's E_θ per segment (`Evaluation::per_run_segment_e`) follows these.
    pub fn segment_ranges(&self) -> Vec<std::ops::Range<usize>> {
        let n = self.t.len();
        if n == 0 {
            return Vec::new();
        }
        let mut starts = vec![0];
        starts.extend(
            self.restarts
                .iter()
                .map(|(i, _)| *i)
                .filter(|&i| i > 0 && i < n),
        );
        let ends = starts.iter().skip(1).copied().chain([n]);
        starts.iter().zip(ends).map(|(&a, b)| a..b).collect()
    }

    /// This free decay (the free segment before a shaker starts, prepared as a decay) as a run
    /// of the shaker model with the crank still: crank radius 0, the crank's speed `omega_hz`
    /// kept only for the time unit's sake, and a shaker run's time unit sqrt(g/l). An SI model
    /// then simulates it with every term it holds (a free-decay model knows only the
    /// identifiable ratios of a, b, μ and a dry torque). `None` for a run that is not a free
    /// decay.
    pub fn unforced(&self, omega_hz: f64) -> Option<PreparedRun> {
        if !self.free || !(omega_hz > 0.0) {
            return None;
        }
        let w = self.rig.omega0_rad_s();
        let s = w / self.omega0_rad_s;
        let mut r = self.clone();
        r.t.iter_mut().for_each(|t| *t *= s);
        r.tail_t.iter_mut().for_each(|t| *t *= s);
        r.restarts.iter_mut().for_each(|(_, y)| y[1] /= s);
        r.ic_est[1] /= s;
        r.rig.crank_r_m = 0.0;
        r.rig.omega_hz = Some(omega_hz);
        r.omega_hz = omega_hz;
        r.free = false;
        r.omega0_rad_s = w;
        Some(r)
    }

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

/// First step of every window segment. Each segment starts afresh, so its value does not depend
/// on which segments were integrated before it (a bounded evaluation integrates the typically
/// worst ones first); 0.1 is about the step the controller settles on at the fit's tolerance.
const SEGMENT_H_INIT: f64 = 0.1;

/// One multiple-shooting segment of a run's window: samples `i0..i1`, starting at `t0`.
#[derive(Debug, Clone, Copy)]
struct Segment {
    run: usize,
    i0: usize,
    i1: usize,
    t0: f64,
    /// The measured restart state (θ rad, dθ/dt dimensionless); `None`: the run's fitted
    /// initial state at t = 0.
    y0: Option<[f64; 2]>,
}

/// The segments of `runs`' windows, run by run, in time order.
fn segments(runs: &[PreparedRun]) -> Vec<Segment> {
    let mut out = Vec::new();
    for (j, run) in runs.iter().enumerate() {
        let mut restarts = run
            .restarts
            .iter()
            .filter(|(i, _)| *i > 0 && *i < run.t.len());
        for (k, r) in run.segment_ranges().into_iter().enumerate() {
            let y0 = if k == 0 {
                None
            } else {
                restarts.next().map(|(_, y)| *y)
            };
            debug_assert!(r.start < r.end);
            out.push(Segment {
                run: j,
                t0: if k == 0 { 0.0 } else { run.t[r.start] },
                i0: r.start,
                i1: r.end,
                y0,
            });
        }
    }
    out
}

/// Outcome of one segment's simulation.
enum SegmentError {
    /// Σ|θ̂ − θ| over the segment and the state at its last sample.
    Done(f64, [f64; 2]),
    /// The sum exceeded the limit: the value is the partial sum.
    Abandoned(f64),
    /// The integration failed.
    Failed,
}

/// Simulates one segment of `run` (θ measured = θ + `offset`, the initial state `ic` in measured
/// coordinates), stopping once the segment's sum exceeds `limit`. `k` converts the run's time
/// unit to the model's (1 except for a free decay with a fitted ω0): times × k, rates / k. The
/// returned end state is in the model's units.
#[allow(clippy::too_many_arguments)]
fn segment_error(
    model: &Model,
    opts: &SimOptions,
    run: &PreparedRun,
    seg: &Segment,
    ic: [f64; 2],
    offset: f64,
    limit: f64,
    k: f64,
) -> SegmentError {
    let y = seg.y0.unwrap_or(ic);
    let mut sum = 0.0;
    let mut end = [y[0] - offset, y[1] / k];
    let mut j = seg.i0;
    let res = integrate(
        model,
        &SimOptions {
            h_init: Some(SEGMENT_H_INIT),
            ..*opts
        },
        seg.t0 * k,
        [y[0] - offset, y[1] / k],
        run.t[seg.i1 - 1] * k,
        run.t[seg.i0..seg.i1].iter().map(|t| t * k),
        |smp| {
            sum += (run.theta[j] - (smp.theta + offset)).abs();
            j += 1;
            end = [smp.theta, smp.theta_dot];
            if sum > limit {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
    );
    match res {
        Ok(stats) if !stats.stopped_early => SegmentError::Done(sum, end),
        Ok(_) => SegmentError::Abandoned(sum),
        Err(_) => SegmentError::Failed,
    }
}

/// Integrator tolerance of the steady-state tails (the window's `sim_tol` if looser): 1.4× fewer
/// steps than 1e-6. A class is decided with tolerances of 0.01–0.05 rad on an attracting orbit,
/// which 1e-5 resolves as a tight 1e-10 does (test `tail_decision_matches_full_classification`;
/// 1e-4 lost a rotation there). Through transient chaos no tolerance reproduces the tight class:
/// on 560 study trial tails 1e-6 agreed with 1e-10 on 379, 1e-5 on 361 (5e-7 … 2e-6: 379–390).
pub const TAIL_TOL: f64 = 1e-5;

/// Relative margin on a bound before a partial sum computed in another order than the value
/// counts as exceeding it: sums of ≤ 10⁴ non-negative terms differ by far less with reordering.
const ORDER_MARGIN: f64 = 1e-11;

/// What a bounded evaluation learns to abandon hopeless trials early: each window segment's
/// typical error (the largest are integrated first) and how often and at what cost each run's
/// tail was penalised. Only the order of the work depends on it, never a value, so the fit is the
/// same whatever it holds (and with any number of threads).
#[derive(Debug, Default)]
pub struct WorkOrder {
    /// Per segment: a running mean of its error (f64 bits).
    seg_err: OnceLock<Vec<AtomicU64>>,
    /// Per run: tails simulated, tails penalised, right-hand sides spent on tails.
    tails: OnceLock<Vec<[AtomicU64; 3]>>,
}

impl WorkOrder {
    fn seg_err(&self, n: usize) -> &[AtomicU64] {
        self.seg_err
            .get_or_init(|| (0..n).map(|_| AtomicU64::new(0)).collect())
    }

    fn tails(&self, n: usize) -> &[[AtomicU64; 3]] {
        self.tails.get_or_init(|| {
            (0..n)
                .map(|_| [AtomicU64::new(0), AtomicU64::new(0), AtomicU64::new(0)])
                .collect()
        })
    }

    /// Segment indices, the largest typical error first.
    fn segment_order(&self, n: usize) -> Vec<usize> {
        let means: Vec<f64> = self
            .seg_err(n)
            .iter()
            .map(|m| f64::from_bits(m.load(Relaxed)))
            .collect();
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|a, b| means[*b].total_cmp(&means[*a]));
        order
    }

    fn record_segment(&self, n: usize, k: usize, e: f64) {
        // Races lose an update at worst: this only orders the work.
        let m = &self.seg_err(n)[k];
        let old = f64::from_bits(m.load(Relaxed));
        m.store((old + 0.05 * (e - old)).to_bits(), Relaxed);
    }

    /// Run indices for the tails, the likeliest penalty per unit of work first.
    fn tail_order(&self, es: &[f64]) -> Vec<usize> {
        let stats = self.tails(es.len());
        let score: Vec<f64> = stats
            .iter()
            .zip(es)
            .map(|(c, e)| {
                let (n, pen, rhs) = (c[0].load(Relaxed), c[1].load(Relaxed), c[2].load(Relaxed));
                let p = (pen as f64 + 1.0) / (n as f64 + 2.0);
                let cost = (rhs as f64 + 1.0) / (n as f64 + 1.0);
                p * e / cost
            })
            .collect();
        let mut order: Vec<usize> = (0..es.len()).collect();
        order.sort_by(|a, b| score[*b].total_cmp(&score[*a]));
        order
    }

    fn record_tail(&self, j: usize, n_runs: usize, penalised: bool, rhs: u64) {
        let c = &self.tails(n_runs)[j];
        c[0].fetch_add(1, Relaxed);
        c[1].fetch_add(u64::from(penalised), Relaxed);
        c[2].fetch_add(rhs, Relaxed);
    }
}

/// θ simulated from (`t_from`, `y_from`) at each of `times` (ascending); `None` when there are
/// none or the integration fails.
fn theta_at(
    model: &Model,
    opts: &SimOptions,
    t_from: f64,
    y_from: [f64; 2],
    times: &[f64],
) -> Option<Vec<f64>> {
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
    Some(th)
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
        let th = theta_at(model, opts, t_from, y_from, &times)?;
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
    let th = theta_at(model, opts, t_from, y_from, &times)?;
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

/// Whether run j's steady-state penalty applies: [`simulated_steady`]'s class differs from the
/// measured one. The simulation stops as soon as the Poincaré points so far decide that (see
/// [`PartialClass`]), e.g. a trial that turns the wrong way or never repeats. Also returns the
/// right-hand-side evaluations spent.
fn tail_penalised(
    model: &Model,
    opts: &SimOptions,
    run: &PreparedRun,
    t_from: f64,
    y_from: [f64; 2],
    k: f64,
) -> (bool, u64) {
    if run.free {
        // A free decay's tail is classified whole (rest or swinging): no early decision.
        let st = simulated_steady(model, opts, run, t_from, y_from, k);
        return (st.is_none_or(|s| s.class != run.steady.class), 0);
    }
    let q = 0.25 * run.period();
    let mut times: Vec<f64> = Vec::with_capacity(run.tail_t.len() * 2);
    for &t in &run.tail_t {
        if t >= t_from {
            times.push(t);
            times.push(t + q);
        }
    }
    let Some(&t_end) = times.last().filter(|_| times.len() >= 4) else {
        return (true, 0);
    };
    let n = times.len() / 2;
    let mut partial = PartialClass::new(n, &run.classify);
    let mut first = 0.0;
    let mut decided = None;
    let mut k = 0;
    let stats = integrate(
        model,
        opts,
        t_from,
        y_from,
        t_end,
        times.iter().copied(),
        |s| {
            k += 1;
            if k % 2 == 1 {
                first = s.theta;
                return ControlFlow::Continue(());
            }
            // Exactly as simulated_steady forms the points.
            partial.push(first, (s.theta - first) / q);
            decided = partial.differs_from(run.steady.class);
            if decided.is_some() {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        },
    );
    let Ok(stats) = stats else {
        return (true, 0);
    };
    let differs = decided.unwrap_or_else(|| {
        let (a, b) = partial.points();
        classify_poincare(a, b, &run.classify).class != run.steady.class
    });
    (differs, stats.rhs_evals)
}

/// [`Model::measured`]: the model of a physical parameter set, driven by the aligned crank, with
/// `accel_delay` shifting the forcing: the accelerometer's peak came Δ after the true one, so the
/// true crank angle is ω(t + Δ).
pub fn model_for(phys: &Physical) -> Model {
    Model::measured(phys)
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
    /// Learned order of a bounded evaluation's work (start with `WorkOrder::default()`).
    pub order: WorkOrder,
}

/// The breakdown of one evaluation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    pub f_obj: f64,
    pub e_theta: f64,
    pub per_run_e: Vec<f64>,
    /// Per run, E_θ of each multiple-shooting segment in time order (one entry without
    /// segments; empty for a failed run): the units a paired held-out comparison resamples.
    pub per_run_segment_e: Vec<Vec<f64>>,
    pub per_run_sim_steady: Vec<Option<SteadyState>>,
}

impl Evaluation {
    /// `runs` (one per run evaluated, in order) with this evaluation's E_θ, segment errors and
    /// simulated steady states.
    pub fn update_runs(&self, runs: &[crate::identify::RunFit]) -> Vec<crate::identify::RunFit> {
        runs.iter()
            .enumerate()
            .map(|(j, r)| crate::identify::RunFit {
                e_theta: self.per_run_e[j],
                segment_e: self.per_run_segment_e[j].clone(),
                simulated: self.per_run_sim_steady[j],
                ..r.clone()
            })
            .collect()
    }
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

    /// The model of run j for parameters p (crank tabulated: this is the fit's inner loop).
    pub fn model_of(&self, run: &PreparedRun, p: &[f64]) -> Model {
        let m = self.spec.run_model(run, p);
        if run.free {
            m
        } else {
            m.with_crank_table()
        }
    }

    fn offset(&self, p: &[f64]) -> f64 {
        self.spec
            .params
            .iter()
            .zip(p)
            .find(|(q, _)| q.effect_name() == Some("encoder_offset"))
            .map_or(
                self.spec
                    .fixed
                    .value("encoder_offset.theta_off")
                    .unwrap_or(0.0),
                |(_, v)| *v,
            )
    }

    /// Every segment's error in `order` (stopping once their sum exceeds `limit`), into `seg_e`
    /// and each run's end state into `ends`. `Err` carries the cost to report when stopped.
    #[allow(clippy::too_many_arguments)]
    fn windows(
        &self,
        models: &[Model],
        ks: &[f64],
        segs: &[Segment],
        order: &[usize],
        ics: &[f64],
        off: f64,
        limit: f64,
        seg_e: &mut [f64],
        ends: &mut [[f64; 2]],
    ) -> Result<(), Cost> {
        let mut done = 0.0;
        for &k in order {
            let g = &segs[k];
            let ic = [ics[2 * g.run], ics[2 * g.run + 1]];
            let run = &self.runs[g.run];
            match segment_error(
                &models[g.run],
                &self.sim,
                run,
                g,
                ic,
                off + run.zero_rad,
                limit - done,
                ks[g.run],
            ) {
                SegmentError::Done(e, end) => {
                    seg_e[k] = e;
                    done += e;
                    if g.i1 == run.t.len() {
                        ends[g.run] = end;
                    }
                    self.order.record_segment(segs.len(), k, e);
                }
                SegmentError::Abandoned(partial) => return Err(Cost::AtLeast(done + partial)),
                SegmentError::Failed => return Err(Cost::Exact(FAILED_COST)),
            }
        }
        Ok(())
    }

    /// Integrator settings of the steady-state tails: the fit's, loosened to [`TAIL_TOL`].
    pub fn tail_sim(&self) -> SimOptions {
        SimOptions {
            rtol: self.sim.rtol.max(TAIL_TOL),
            atol: self.sim.atol.max(TAIL_TOL),
            ..self.sim
        }
    }

    /// Each run's fitted initial state in the model's coordinates (its end state when its window
    /// has no samples).
    fn initial_states(&self, ics: &[f64], off: f64, ks: &[f64]) -> Vec<[f64; 2]> {
        (0..self.runs.len())
            .map(|j| {
                [
                    ics[2 * j] - off - self.runs[j].zero_rad,
                    ics[2 * j + 1] / ks[j],
                ]
            })
            .collect()
    }

    /// Each run's E_θ: its segments' errors summed in time order (whatever order they were
    /// integrated in, so the value does not depend on it).
    fn per_run(&self, segs: &[Segment], seg_e: &[f64]) -> Vec<f64> {
        let mut es = vec![0.0; self.runs.len()];
        for (g, e) in segs.iter().zip(seg_e) {
            es[g.run] += e;
        }
        es
    }

    /// Full evaluation with the per-run breakdown (no abandoning).
    pub fn evaluate(&self, x: &[f64]) -> Evaluation {
        let (p, ics) = self.split(x);
        let off = self.offset(&p);
        let models: Vec<Model> = self.runs.iter().map(|r| self.model_of(r, &p)).collect();
        let ks: Vec<f64> = self
            .runs
            .iter()
            .map(|r| self.spec.time_scale(r, &p))
            .collect();
        let segs = segments(self.runs);
        let mut seg_e = vec![0.0; segs.len()];
        let mut ends = self.initial_states(ics, off, &ks);
        let mut failed = vec![false; self.runs.len()];
        // Run by run, so that a failed integration costs only its run.
        for (k, g) in segs.iter().enumerate() {
            let ic = [ics[2 * g.run], ics[2 * g.run + 1]];
            let run = &self.runs[g.run];
            match segment_error(
                &models[g.run],
                &self.sim,
                run,
                g,
                ic,
                off + run.zero_rad,
                f64::INFINITY,
                ks[g.run],
            ) {
                SegmentError::Done(e, end) => {
                    seg_e[k] = e;
                    if g.i1 == run.t.len() {
                        ends[g.run] = end;
                    }
                }
                SegmentError::Abandoned(_) | SegmentError::Failed => failed[g.run] = true,
            }
        }
        let es = self.per_run(&segs, &seg_e);
        let mut per_run_segment_e = vec![Vec::new(); self.runs.len()];
        for (g, e) in segs.iter().zip(&seg_e) {
            if !failed[g.run] {
                per_run_segment_e[g.run].push(*e);
            }
        }
        let mut per_run_e = Vec::new();
        let mut steadies = Vec::new();
        let mut f = 0.0;
        for (j, run) in self.runs.iter().enumerate() {
            if failed[j] {
                per_run_e.push(FAILED_COST);
                steadies.push(None);
                f += FAILED_COST;
                continue;
            }
            let e = es[j];
            let t_last = *run.t.last().unwrap_or(&0.0) * ks[j];
            let st = simulated_steady(&models[j], &self.tail_sim(), run, t_last, ends[j], ks[j]);
            let differs = st.is_none_or(|s| s.class != run.steady.class);
            f += if self.penalty && differs {
                self.kappa * e
            } else {
                e
            };
            per_run_e.push(e);
            steadies.push(st);
        }
        Evaluation {
            f_obj: f,
            e_theta: per_run_e.iter().sum(),
            per_run_e,
            per_run_segment_e,
            per_run_sim_steady: steadies,
        }
    }

    /// The residual this objective minimises, sample by sample: every multiple-shooting
    /// segment simulated as [`Self::evaluate`] does (the first from the run's initial state in
    /// `x`, later ones restarted from the measured state), per run in time order. A segment whose
    /// integration fails ends early; its remaining samples are absent.
    pub fn segment_series(&self, x: &[f64]) -> Vec<Vec<SegmentSample>> {
        let (p, ics) = self.split(x);
        let off = self.offset(&p);
        let mut out: Vec<Vec<SegmentSample>> = vec![Vec::new(); self.runs.len()];
        let mut seg_no = vec![0usize; self.runs.len()];
        for g in segments(self.runs) {
            let run = &self.runs[g.run];
            let model = self.model_of(run, &p);
            let k = self.spec.time_scale(run, &p);
            let y = g.y0.unwrap_or([ics[2 * g.run], ics[2 * g.run + 1]]);
            let off = off + run.zero_rad;
            let segment = seg_no[g.run];
            seg_no[g.run] += 1;
            let rec = &mut out[g.run];
            let mut j = g.i0;
            // A failed integration leaves the samples it reached; the rest are absent.
            let _ = integrate(
                &model,
                &SimOptions {
                    h_init: Some(SEGMENT_H_INIT),
                    ..self.sim
                },
                g.t0 * k,
                [y[0] - off, y[1] / k],
                run.t[g.i1 - 1] * k,
                run.t[g.i0..g.i1].iter().map(|t| t * k),
                |smp| {
                    rec.push(SegmentSample {
                        segment,
                        index: j,
                        theta_sim: smp.theta + off,
                        theta_dot_sim: smp.theta_dot * k,
                    });
                    j += 1;
                    ControlFlow::Continue(())
                },
            );
        }
        out
    }

    /// Each run's own encoder zeroing error ([`PreparedRun::zero_rad`]) under the damping
    /// parameters `p` and initial states `ics` (two per run): the value within ±`bound_rad` that
    /// minimises that run's E_θ alone (golden section, `iters` shrinks), each run on its own, its
    /// initial state held. The runs' own `zero_rad` are replaced, not added to; the objective's
    /// settings are used but not its `fixed_params` (`p` are the parameters).
    pub fn run_zeros(&self, p: &[f64], ics: &[f64], bound_rad: f64, iters: usize) -> Vec<f64> {
        use rayon::prelude::*;
        self.runs
            .par_iter()
            .enumerate()
            .map(|(j, run)| {
                let mut x = p.to_vec();
                x.extend_from_slice(&ics[2 * j..2 * j + 2]);
                let e_theta = |z: f64| {
                    let one = [PreparedRun {
                        zero_rad: z,
                        ..run.clone()
                    }];
                    StudyObjective {
                        runs: &one,
                        spec: self.spec,
                        kappa: self.kappa,
                        sim: self.sim,
                        ic_halfwidth: self.ic_halfwidth,
                        fixed_params: None,
                        penalty: self.penalty,
                        order: WorkOrder::default(),
                    }
                    .evaluate(&x)
                    .e_theta
                };
                pendulum_numerics::golden_section(e_theta, -bound_rad, bound_rad, iters).x
            })
            .collect()
    }
}

/// One sample of [`StudyObjective::segment_series`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentSample {
    /// The segment's number within its run (0: from the fitted initial state).
    pub segment: usize,
    /// Index of the sample in the run's `t`/`theta`.
    pub index: usize,
    /// Simulated θ in measured coordinates (rad) and dθ/dt in the run's time unit.
    pub theta_sim: f64,
    pub theta_dot_sim: f64,
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
                    _ if free && p.effect_name() == Some("encoder_offset") => (-0.05, 0.05),
                    _ => self.spec.range(*p),
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

    /// The work is ordered to exceed `bound` as early as possible (see [`WorkOrder`]): window
    /// segments with the largest typical error first, then the tails likeliest to be penalised
    /// per unit of work. The value itself is summed in a fixed order, so it does not depend on
    /// the bound; a partial sum counts as exceeding the bound only beyond [`ORDER_MARGIN`].
    fn cost(&self, x: &[f64], bound: f64) -> Cost {
        let (p, ics) = self.split(x);
        let off = self.offset(&p);
        let models: Vec<Model> = self.runs.iter().map(|r| self.model_of(r, &p)).collect();
        let ks: Vec<f64> = self
            .runs
            .iter()
            .map(|r| self.spec.time_scale(r, &p))
            .collect();
        let limit = bound + ORDER_MARGIN * bound.abs();
        let segs = segments(self.runs);
        let order = self.order.segment_order(segs.len());
        let mut seg_e = vec![0.0; segs.len()];
        let mut ends = self.initial_states(ics, off, &ks);
        if let Err(c) = self.windows(
            &models, &ks, &segs, &order, ics, off, limit, &mut seg_e, &mut ends,
        ) {
            return match c {
                // The true cost is ≥ the partial sum > bound; report a value strictly above bound.
                Cost::AtLeast(v) => Cost::AtLeast(v.max(bound.next_up())),
                Cost::Exact(v) if v > bound => Cost::AtLeast(v),
                c => c,
            };
        }
        let es = self.per_run(&segs, &seg_e);
        let total: f64 = es.iter().sum();
        if !(self.penalty && self.kappa > 1.0) {
            return Cost::Exact(total);
        }
        let tail_sim = self.tail_sim();
        let mut penalised = vec![false; self.runs.len()];
        let mut lower = total;
        for j in self.order.tail_order(&es) {
            if lower > limit {
                return Cost::AtLeast(lower.max(bound.next_up()));
            }
            let run = &self.runs[j];
            let t_last = *run.t.last().unwrap_or(&0.0) * ks[j];
            let (pen, rhs) = tail_penalised(&models[j], &tail_sim, run, t_last, ends[j], ks[j]);
            penalised[j] = pen;
            self.order
                .record_tail(j, self.runs.len(), penalised[j], rhs);
            if penalised[j] {
                lower += (self.kappa - 1.0) * es[j];
            }
        }
        let mut f = total;
        for (e, pen) in es.iter().zip(&penalised) {
            if *pen {
                f += (self.kappa - 1.0) * e;
            }
        }
        // Exact even when above the bound: the driver only needs AtLeast to be a lower bound.
        Cost::Exact(f)
    }
}

/// Whether two classes agree (periods are not compared: a measured period-2 that a simulation
/// reaches as period 2 or 4 is the same kind of motion for a harvester).
pub fn classes_agree(a: SteadyClass, b: SteadyClass) -> bool {
    a == b
}

#[cfg(test)]
mod tests {
    use super::*;

    const STUDY: [f64; 3] = [0.0, 0.5, 0.15];

    /// A value pinned at a search convenience widens that side (the span doubles); a loss at its
    /// physical floor 0 does not; an interior value changes nothing.
    #[test]
    fn a_search_range_widens_where_the_data_push_and_never_past_physics() {
        let off = FitParam::of("encoder_offset");
        let v_s = FitParam::of("stribeck.v_s");
        let mut spec = ModelSpec::reference();
        spec.params.extend([off, v_s]);
        assert_eq!(spec.range(FitParam::Mu), (0.0, 0.25));
        // a at its floor 0 (unused), b inside, μ at the study's 0.25, the offset at −0.2 rad,
        // v_s at its 0.01 rad/s.
        let widened = spec.widen_at_bounds(&[0.0, 0.5, 0.25, -0.2, 0.01]);
        assert_eq!(widened, ["mu", "encoder_offset.theta_off", "stribeck.v_s"]);
        assert_eq!(spec.range(FitParam::A), (0.0, 1.0));
        assert_eq!(spec.range(FitParam::B), (0.0, 1.0));
        assert_eq!(spec.range(FitParam::Mu), (0.0, 0.5));
        let (lo, hi) = spec.range(off);
        assert!((lo + 0.6).abs() < 1e-12 && hi == 0.2, "{lo} {hi}");
        // A range above 0 halves its lower end towards 0, never past it.
        assert_eq!(spec.range(v_s), (0.005, 2.0));
        assert!(spec.widen_at_bounds(&[0.1, 0.5, 0.3, 0.0, 0.2]).is_empty());
        // The widened ranges are the fit's bounds, and survive a round trip through the spec's
        // TOML (a catalogue-range spec writes no `ranges`).
        let back: ModelSpec = toml::from_str(&toml::to_string(&spec).unwrap()).unwrap();
        assert_eq!(back, spec);
        assert!(!toml::to_string(&ModelSpec::reference())
            .unwrap()
            .contains("ranges"));

        // `hold`: a start past the range (the screen's J = 0.05 kg·m² against 0.02) widens it
        // until the start has a tenth of the span to spare; a start inside changes nothing.
        let j = FitParam::of("extra_inertia");
        let mut spec = ModelSpec::reference();
        spec.params.push(j);
        spec.hold(j, 0.01);
        assert!(spec.ranges.is_empty());
        spec.hold(j, 0.05);
        assert_eq!(spec.range(j), (0.0, 0.08));
        // A speed scale of 0.2 rad/s is well inside (0.01, 2): its floor is not moved.
        let v_s = FitParam::of("stribeck.v_s");
        spec.params.push(v_s);
        spec.hold(v_s, 0.2);
        assert_eq!(spec.range(v_s), (0.01, 2.0));
        // At most `MAX_WIDENINGS` doublings, however far the start: then it is clamped.
        spec.hold(j, 100.0);
        assert_eq!(spec.range(j), (0.0, 0.16));
        // A negative start of a non-negative size stays outside: the floor is physics.
        spec.hold(FitParam::B, -0.1);
        assert_eq!(spec.range(FitParam::B), (0.0, 1.0));
    }

    fn rig() -> RigParams {
        RigParams {
            m_kg: 1.46,
            l_m: 0.265,
            crank_r_m: 0.0725,
            rod_l_m: 0.575,
            r_b_m: 0.01225,
            omega_hz: Some(1.75),
            g_m_s2: 9.81,
        }
    }

    /// Output error only (no steady-state penalty), tolerance 1e-8, parameters free.
    fn plain_objective<'a>(runs: &'a [PreparedRun], spec: &'a ModelSpec) -> StudyObjective<'a> {
        StudyObjective {
            runs,
            spec,
            kappa: 1.0,
            sim: SimOptions::with_tol(1e-8),
            ic_halfwidth: 0.1,
            fixed_params: None,
            penalty: false,
            order: WorkOrder::default(),
        }
    }

    /// A run's own zeroing error is found from its trajectory: the same simulated run read
    /// 2 counts high (every sample and restart state shifted) is given back its 2 counts, and the
    /// unshifted one 0, each to a tenth of a count; the model's own offset is not counted twice.
    #[test]
    fn a_runs_zeroing_error_is_recovered_from_its_trajectory() {
        let count = std::f64::consts::TAU / 4096.0;
        let p = [0.0, 0.5, 0.15];
        let plain = run(1.75, p, [0.6, 0.0]);
        let mut shifted = plain.clone();
        shifted.theta.iter_mut().for_each(|v| *v += 2.0 * count);
        shifted
            .restarts
            .iter_mut()
            .for_each(|(_, y)| y[0] += 2.0 * count);
        let runs = [plain.clone(), shifted];
        let spec = ModelSpec::reference();
        let ics: Vec<f64> = runs
            .iter()
            .flat_map(|r| [r.ic_est[0] + (r.theta[0] - plain.theta[0]), r.ic_est[1]])
            .collect();
        let objective = plain_objective(&runs, &spec);
        let zeros = objective.run_zeros(&p, &ics, 4.0 * count, 40);
        assert!(zeros[0].abs() < 0.1 * count, "{}", zeros[0] / count);
        assert!(
            (zeros[1] - 2.0 * count).abs() < 0.1 * count,
            "{}",
            zeros[1] / count
        );
        // With the zeros held, the shifted run's E_θ is the plain run's (the shift undone).
        let held: Vec<PreparedRun> = runs
            .iter()
            .zip(&zeros)
            .map(|(r, &z)| PreparedRun {
                zero_rad: z,
                ..r.clone()
            })
            .collect();
        let e = StudyObjective {
            runs: &held,
            ..objective
        }
        .evaluate(&[&p[..], &ics[..]].concat());
        assert!(
            (e.per_run_e[1] - e.per_run_e[0]).abs() < 0.05 * e.per_run_e[0].max(1e-3),
            "{:?}",
            e.per_run_e
        );
    }

    /// A run whose "measurement" is the model's own tight simulation from `y0`: a 5 s window at
    /// 100 Hz in 0.5 s segments, the tail over 40–60 s.
    fn run(omega_hz: f64, p: [f64; 3], y0: [f64; 2]) -> PreparedRun {
        let rig = rig();
        let w0 = rig.omega0_rad_s();
        let model = Model::new(
            ModelSpec::reference()
                .physical(&rig, omega_hz, &p)
                .to_dimensionless(),
        );
        let t: Vec<f64> = (0..500).map(|k| w0 * k as f64 * 0.01).collect();
        let (mut theta, mut state) = (Vec::new(), Vec::new());
        integrate(
            &model,
            &SimOptions::with_tol(1e-10),
            0.0,
            y0,
            t[t.len() - 1],
            t.iter().copied(),
            |s| {
                theta.push(s.theta);
                state.push([s.theta, s.theta_dot]);
                ControlFlow::Continue(())
            },
        )
        .unwrap();
        let period = w0 / omega_hz;
        let tail_t = (0..)
            .map(|k| w0 * 40.0 + k as f64 * period)
            .take_while(|t| *t <= w0 * 60.0 - 0.25 * period)
            .collect();
        PreparedRun {
            id: "test".into(),
            role: Role::Identify,
            rig,
            omega_hz,
            restarts: (1..10).map(|s| (50 * s, state[50 * s])).collect(),
            t,
            theta,
            ic_est: y0,
            steady: SteadyState {
                class: SteadyClass::Chaos,
                period: 0,
                mean_theta_dot: 0.0,
            },
            tail_t,
            free: false,
            omega0_rad_s: w0,
            zero_rad: 0.0,
            classify: ClassifyOptions {
                theta_tol: 0.05,
                theta_dot_tol: 0.05 / (0.25 * period),
                max_period: 16,
                rest_tol: 0.01,
            },
        }
    }

    /// The free segment before a shaker starts, prepared as a free decay (in its period-derived
    /// time unit, 7 % off sqrt(g/l) here), and converted by [`PreparedRun::unforced`]: the SI
    /// model that swung it (crank still) follows it as it follows a forced run of its own, its
    /// times and rates are the shaker's units again, and a forced run is not converted.
    #[test]
    fn an_unforced_free_segment_is_followed_by_the_model_that_swung_it() {
        // `run` forces its truth; the measurement again, with the crank still.
        let mut swung = run(1.75, STUDY, [1.2, 0.0]);
        swung.rig.crank_r_m = 0.0;
        let w0 = swung.rig.omega0_rad_s();
        let model = Model::new(
            ModelSpec::reference()
                .physical(&swung.rig, 1.75, &STUDY)
                .to_dimensionless(),
        );
        let (mut theta, mut state) = (Vec::new(), Vec::new());
        integrate(
            &model,
            &SimOptions::with_tol(1e-10),
            0.0,
            [1.2, 0.0],
            swung.t[swung.t.len() - 1],
            swung.t.iter().copied(),
            |s| {
                theta.push(s.theta);
                state.push([s.theta, s.theta_dot]);
                ControlFlow::Continue(())
            },
        )
        .unwrap();
        let w_est = 1.07 * w0;
        let s = w_est / w0;
        let mut decay = swung.clone();
        decay.rig.crank_r_m = 0.0725;
        decay.rig.omega_hz = None;
        decay.omega_hz = f64::NAN;
        decay.free = true;
        decay.omega0_rad_s = w_est;
        decay.t = swung.t.iter().map(|t| t * s).collect();
        decay.theta = theta;
        decay.restarts = (1..10)
            .map(|k| (50 * k, [state[50 * k][0], state[50 * k][1] / s]))
            .collect();
        decay.ic_est = [1.2, 0.0];
        assert!(
            swung.unforced(1.75).is_none(),
            "a forced run is not a free decay"
        );
        let r = decay.unforced(1.75).expect("a free decay");
        assert!(!r.free && r.rig.crank_r_m == 0.0 && r.omega_hz == 1.75);
        for (a, b) in r.t.iter().zip(&swung.t) {
            assert!((a - b).abs() < 1e-9 * b.max(1.0), "{a} against {b}");
        }
        let spec = ModelSpec::reference();
        let e = |p: [f64; 3]| {
            let objective = plain_objective(std::slice::from_ref(&r), &spec);
            let mut x = p.to_vec();
            x.extend_from_slice(&r.ic_est);
            objective.evaluate(&x).per_run_e[0]
        };
        let truth = e(STUDY);
        let ratio = crate::identify::misfit_ratio(&r, truth).expect("a moving run");
        assert!(ratio < 0.01, "the truth misses {ratio}");
        let doubled = e([STUDY[0], 2.0 * STUDY[1], STUDY[2]]);
        assert!(
            doubled > 10.0 * truth,
            "b doubled {doubled} against the truth {truth}"
        );
    }

    /// Parameter sets and starts with robust classes: stuck at rest, oscillation, rotation.
    fn cases() -> Vec<PreparedRun> {
        vec![
            run(1.3, STUDY, [0.5, 0.0]),
            run(1.3, [0.0, 0.2, 0.24], [0.2, 0.0]),
            run(1.0, [0.0, 0.3, 0.02], [0.3, 0.0]),
            run(1.75, STUDY, [1.0, -1.5]),
            run(1.75, [0.01, 0.4, 0.1], [1.0, 1.5]),
            run(1.65, STUDY, [0.5, 0.0]),
        ]
    }

    /// The early-stopping tail decides the penalty exactly as classifying the whole tail does,
    /// for every measured class; and the fit tolerance's class is the tight reference's.
    #[test]
    fn tail_decision_matches_full_classification() {
        let opts = SimOptions::with_tol(TAIL_TOL);
        let mut seen = Vec::new();
        for r in cases() {
            let model = Model::new(
                ModelSpec::reference()
                    .physical(&r.rig, r.omega_hz, &STUDY)
                    .to_dimensionless(),
            )
            .with_crank_table();
            let y = [0.2, 0.0];
            let full = simulated_steady(&model, &opts, &r, 5.0, y, 1.0)
                .unwrap()
                .class;
            let tight = simulated_steady(&model, &SimOptions::with_tol(1e-10), &r, 5.0, y, 1.0)
                .unwrap()
                .class;
            assert_eq!(full, tight, "ω = {} Hz", r.omega_hz);
            seen.push(full);
            for class in SteadyClass::ALL {
                let mut r = r.clone();
                r.steady.class = class;
                let (penalised, _) = tail_penalised(&model, &opts, &r, 5.0, y, 1.0);
                assert_eq!(penalised, full != class, "{full} measured as {class}");
            }
        }
        eprintln!("classes: {seen:?}");
        assert!(seen.contains(&SteadyClass::Rest) && seen.iter().any(|c| c.is_rotation()));
    }

    /// The misfit ratio: a model that is the run's own truth follows it (its segments' E_θ is a
    /// small share of how far the angle moves), a prediction that stands still at each
    /// segment's start scores exactly 1 (counted by hand over the 50-sample segments), and a run
    /// at rest has no ratio.
    /// A run's segment ranges cut its window at the restarts inside it (one at its first or
    /// past its last sample is no cut), cover it without gap or overlap, and are the segments
    /// the objective reports an E_θ for, one each.
    #[test]
    fn segment_ranges_partition_the_window_as_the_objective_cuts_it() {
        let mut r = run(1.75, STUDY, [1.0, -1.5]);
        let n = r.t.len();
        r.restarts.insert(0, (0, [0.0, 0.0]));
        r.restarts.push((n, [0.0, 0.0]));
        let ranges = r.segment_ranges();
        let inner: Vec<usize> = r
            .restarts
            .iter()
            .map(|(i, _)| *i)
            .filter(|&i| i > 0 && i < n)
            .collect();
        assert_eq!(ranges.len(), inner.len() + 1);
        assert_eq!((ranges[0].start, ranges[ranges.len() - 1].end), (0, n));
        for (w, &i) in ranges.windows(2).zip(&inner) {
            assert!(w[0].start < w[0].end && w[0].end == w[1].start && w[1].start == i);
        }
        let spec = ModelSpec::reference();
        let objective = plain_objective(std::slice::from_ref(&r), &spec);
        let mut x = STUDY.to_vec();
        x.extend_from_slice(&r.ic_est);
        let eval = objective.evaluate(&x);
        assert_eq!(eval.per_run_segment_e[0].len(), ranges.len());
        let mut empty = r.clone();
        empty.t.clear();
        assert!(empty.segment_ranges().is_empty());
    }

    #[test]
    fn misfit_ratio_tells_a_following_model_from_standing_still() {
        let r = run(1.75, STUDY, [1.0, -1.5]);
        let spec = ModelSpec::reference();
        let objective = plain_objective(std::slice::from_ref(&r), &spec);
        let mut x = STUDY.to_vec();
        x.extend_from_slice(&r.ic_est);
        let e = objective.evaluate(&x).per_run_e[0];
        let ratio = crate::identify::misfit_ratio(&r, e).expect("a moving run");
        assert!(ratio < 0.01, "the truth misses {ratio}");
        let still: f64 = r
            .theta
            .iter()
            .enumerate()
            .map(|(k, th)| (th - r.theta[50 * (k / 50)]).abs())
            .sum();
        let one = crate::identify::misfit_ratio(&r, still).unwrap();
        assert!((one - 1.0).abs() < 1e-12, "standing still scores {one}");
        let mut rest = r.clone();
        rest.theta = vec![0.01; rest.theta.len()];
        for (_, y) in &mut rest.restarts {
            *y = [0.01, 0.0];
        }
        assert!(crate::identify::misfit_ratio(&rest, 1.0).is_none());
    }

    /// A bounded cost is the unbounded one, or a lower bound above the bound when that is
    /// above the bound: the early abandon cannot change a selection.
    #[test]
    fn bounded_cost_is_exact() {
        let runs = cases();
        let spec = ModelSpec::reference();
        let objective = StudyObjective {
            runs: &runs,
            spec: &spec,
            kappa: 2.0,
            sim: SimOptions::with_tol(1e-6),
            ic_halfwidth: 0.1,
            fixed_params: None,
            penalty: true,
            order: WorkOrder::default(),
        };
        let bounds = objective.bounds();
        let mut u = 0.37_f64;
        for _ in 0..12 {
            let x: Vec<f64> = bounds
                .iter()
                .map(|(lo, hi)| {
                    u = (u * 997.0 + 0.123).fract();
                    lo + (hi - lo) * u
                })
                .collect();
            let Cost::Exact(v) = objective.cost(&x, f64::INFINITY) else {
                panic!("unbounded cost must be exact");
            };
            for b in [0.3 * v, v.next_down(), v, 2.0 * v] {
                match objective.cost(&x, b) {
                    Cost::Exact(w) => assert_eq!(w.to_bits(), v.to_bits()),
                    Cost::AtLeast(w) => assert!(w > b && v > b && w <= v, "{w} {v} {b}"),
                }
            }
            let f = objective.evaluate(&x).f_obj;
            assert!((f - v).abs() <= 1e-9 * v, "{f} vs {v}");
        }
    }
}
