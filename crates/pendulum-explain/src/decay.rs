//! Free-decay analysis: how a freely swinging pendulum (no base motion) loses its energy, for a
//! pendulum whose inertia may be unknown (an arm, a hub: a physical pendulum).
//!
//! The equation of motion of a free physical pendulum with the damping terms of `effects.md`,
//! divided by its inertia I about the pivot, is
//!
//! ```text
//! θ̈ = −ω_n² sin θ − γ θ̇ − q θ̇|θ̇| − (T_c/I + (μ r_b m g/I)·N) sgn θ̇,    ω_n² = m g a / I
//! ```
//!
//! (with a stiffness term, `− (k/I) θ` besides, and ω_n² above becomes ω_g², gravity's share)
//!
//! (a = pivot to centre of mass). Only these ratios are identifiable from θ(t): I, m·a and the
//! torques cannot be separated without knowing m and a. The fits run in the model crate's
//! dimensionless form with time in units of 1/ω_n: β = γ/ω_n (`viscous_linear`), c = T_c/(I ω_n²)
//! = T_c/(m g a) (`coulomb_constant`: the half-width of the dry-friction dead band, in rad for
//! small angles), α = q (`viscous_quadratic`), M = μ r_b m g/(I ω_n²) (`coulomb_bearing`, with the
//! point-mass bearing load N = |θ'² + cos θ|), so the pendulum crate's simulator (exact stick/slip)
//! does the integration.
//!
//! What [`diagnose_decay`] does:
//! 1. Turning points (hysteresis on the noise level, refined by a local parabola over ±T/12, so
//!    encoder steps average out) and the envelope: amplitude per half swing, loss per cycle against
//!    amplitude, fitted as ΔA = c0 + c1·A + c2·A² and, exactly for the pendulum, as a
//!    non-negative sum of the catalogue terms' loss-per-cycle curves.
//! 2. Trajectory fits by Levenberg–Marquardt (finite-difference Jacobian) on (ω_n, angle offset,
//!    damping terms), with multiple shooting: the simulation restarts every few half swings from
//!    the measured turning point (θ measured, θ̇ = 0), so no phase drift accumulates and no
//!    initial state needs fitting. 95 % intervals from the Jacobian, inflated by the residuals'
//!    integrated autocorrelation time (the residuals of a physical fit are not white).
//! 3. Held-out gain: every model is fitted on the first half of the swings; the rest of the motion
//!    is simulated in one piece from the measured turning point at the split and scored by
//!    E_θ = Σ|θ_meas − θ_sim|. One decay law, three views ([`DECAY_RULE`], issue 16): a term
//!    whose model contradicts the measured loss per cycle (the loss bands) is never accepted;
//!    otherwise it is accepted if its interval excludes 0 and the held-out E_θ falls by more
//!    than the block-to-block scatter of the improvement (2 standard errors) explains, or if
//!    the envelope resolves it (interval clear of 0), the trajectory fit agrees with the
//!    envelope within intervals and the held-out E_θ gets no worse than that scatter (the
//!    held-out noise can exceed a small effect that the envelope measures directly). Terms are
//!    added greedily (forward selection) to the base model (viscous only).
//! 4. A linear stiffness (a torsion spring beside gravity) is tried only when the half periods
//!    do not follow the gravity law ([`PeriodLaw`]).
//! 5. What stays unexplained: the half period's drift with amplitude beyond the exact pendulum
//!    period (elliptic K, with the fitted stiffness), residual structure by amplitude band, the
//!    final rest position.

use std::fmt;
use std::ops::ControlFlow;

use pendulum_model::{
    integrate, Dimensionless, Excitation, FreeDecay, Model, ModelError, SimOptions,
};
use serde::{Deserialize, Serialize};

use pendulum_numerics::{bic, inverse_spd, median, solve_spd, LsFit};

/// Errors of the free-decay analysis.
#[derive(Debug, thiserror::Error)]
pub enum DecayError {
    #[error("free decay: {0}")]
    Input(String),
    #[error(
        "free decay: only {found} turning points found (need at least {needed}: a few swings)"
    )]
    TooFewSwings { found: usize, needed: usize },
    #[error(transparent)]
    Model(#[from] ModelError),
}

/// A damping term of the catalogue (`effects.md`) that a free decay can show.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Term {
    /// β θ' (β = γ/ω_n).
    ViscousLinear,
    /// c sgn θ' (c = T_c/(m g a), the dead band's half-width in rad for small angles).
    CoulombConstant,
    /// α θ'|θ'| (α = q, 1/rad).
    ViscousQuadratic,
    /// M |θ'² + cos θ| sgn θ' (point-mass bearing load).
    CoulombBearing,
    /// κ θ: a linear restoring torque −k θ besides gravity (a torsion spring, a cable), κ =
    /// k/(m g a) = k/(I ω_g²) with ω_g² = m g a/I gravity's share; the small-swing ω_n² is
    /// ω_g²(1 + κ). Not a loss: it shows only in how the period follows the amplitude (the
    /// spring's share is isochronous, gravity's is not), so it is tried only when the half
    /// periods do not follow the gravity law (see [`PeriodLaw`]). Not in [`Term::ALL`].
    Stiffness,
}

/// The stiffness is a departure, not a catalogue effect (a torsion spring beside gravity): its
/// definition lives here.
static STIFFNESS: FreeDecay = FreeDecay {
    symbol: "kappa",
    unit: "1",
    meaning: "kappa = k/(m g a) = k/(I omega_g^2): restoring torque -k theta beside gravity \
              (omega_n^2 = omega_g^2 (1 + kappa))",
    friction: |_, _| 0.0,
    set: |d, v| d.kappa = v,
    fd_floor: 1e-6,
};

impl Term {
    /// Every term, in catalogue order.
    pub const ALL: [Term; 4] = [
        Term::ViscousLinear,
        Term::ViscousQuadratic,
        Term::CoulombBearing,
        Term::CoulombConstant,
    ];

    /// The catalogue name (`effects.md`).
    pub fn name(self) -> &'static str {
        match self {
            Term::ViscousLinear => "viscous_linear",
            Term::CoulombConstant => "coulomb_constant",
            Term::ViscousQuadratic => "viscous_quadratic",
            Term::CoulombBearing => "coulomb_bearing",
            Term::Stiffness => "stiffness",
        }
    }

    /// Its definition: the catalogue effect's [`FreeDecay`] (the stiffness's own, here).
    fn def(self) -> &'static FreeDecay {
        pendulum_model::effects::by_name(self.name())
            .and_then(|e| e.free_decay())
            .unwrap_or(&STIFFNESS)
    }

    /// The dimensionless parameter's symbol.
    pub fn symbol(self) -> &'static str {
        self.def().symbol
    }

    /// Unit of the dimensionless parameter (as reported).
    pub fn unit(self) -> &'static str {
        self.def().unit
    }

    /// What the parameter is.
    pub fn meaning(self) -> &'static str {
        self.def().meaning
    }

    /// Dry friction (stick/slip) terms: those that set the sticking capacity.
    pub fn is_dry(self) -> bool {
        pendulum_model::effects::by_name(self.name()).is_some_and(|e| e.sets_sticking_capacity())
    }

    fn set(self, d: &mut Dimensionless, v: f64) {
        (self.def().set)(d, v)
    }

    /// Finite-difference step floor.
    fn fd_floor(self) -> f64 {
        self.def().fd_floor
    }

    /// Loss of amplitude per cycle at amplitude `a` (rad) per unit of the parameter, for the
    /// exact pendulum to first order in the damping: the energy a term takes over a half swing,
    /// ∫ f(θ, θ') dθ with θ'² = 2(cos θ − cos A), divided by dE/dA = sin A, times two.
    pub fn loss_per_cycle(self, a: f64) -> f64 {
        self.loss_per_cycle_with(a, 0.0)
    }

    /// [`Term::loss_per_cycle`] with a stiffness κ beside gravity: the potential is
    /// 1 − cos θ + κθ²/2, so θ'² = 2(V(A) − V(θ)) and dE/dA = sin A + κA. A stiffness takes no
    /// energy (0).
    pub fn loss_per_cycle_with(self, a: f64, kappa: f64) -> f64 {
        if self == Term::Stiffness {
            return 0.0;
        }
        let a = a.clamp(1e-9, std::f64::consts::PI - 1e-3);
        let ca = a.cos();
        let friction = self.def().friction;
        let f = |th: f64| -> f64 {
            let w2 = (2.0 * (th.cos() - ca) + kappa * (a * a - th * th)).max(0.0);
            friction(th, w2)
        };
        // θ = A sin φ removes the square-root end points; Simpson on φ ∈ [−π/2, π/2].
        let n = 64;
        let h = std::f64::consts::PI / n as f64;
        let mut s = 0.0;
        for k in 0..=n {
            let phi = -std::f64::consts::FRAC_PI_2 + k as f64 * h;
            let w = if k == 0 || k == n {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            s += w * f(a * phi.sin()) * a * phi.cos();
        }
        2.0 * (s * h / 3.0) / (a.sin() + kappa * a)
    }
}

/// Mass and geometry, when the campaign knows them: they turn the ratios into torques and an
/// inertia.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct KnownRig {
    pub m_kg: f64,
    /// Pivot to the centre of mass of everything that swings, m.
    pub a_m: f64,
    pub g_m_s2: f64,
    /// Bearing bore radius, m (for μ of `coulomb_bearing`).
    pub r_b_m: Option<f64>,
}

/// A fixed model to score next to the fitted ones (e.g. the authors' own).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceModel {
    pub name: String,
    pub omega_n_rad_s: f64,
    /// Viscous damping per unit inertia γ, 1/s.
    pub gamma_per_s: f64,
    /// Dry torque per unit inertia, rad/s².
    pub dry_rad_s2: f64,
}

/// Settings of [`diagnose_decay`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DecayOptions {
    /// The model in hand (default: viscous only, the classic free-decay model).
    pub base: Vec<Term>,
    /// Terms to try adding, in order of preference (default: `coulomb_constant`,
    /// `viscous_quadratic`, `coulomb_bearing`, and `stiffness` where the period does not follow
    /// the gravity law).
    pub candidates: Vec<Term>,
    pub rig: Option<KnownRig>,
    pub reference: Option<ReferenceModel>,
    /// Multiple shooting: the simulation restarts from the measured turning point every this
    /// many half swings.
    pub segment_half_swings: usize,
    /// Samples per small-swing period used by the fits (the data are decimated to this).
    pub fit_points_per_period: usize,
    /// Simulator tolerance.
    pub sim_tol: f64,
    /// Levenberg–Marquardt iterations per fit.
    pub max_iter: usize,
    /// Two-sided normal quantile of the intervals (1.96: 95 %).
    pub z: f64,
    /// A term must lower the held-out E_theta by at least this fraction (besides beating the
    /// noise): smaller changes are fit-to-fit variation, not physics.
    pub min_heldout_gain: f64,
    /// The angle's resolution, rad (2π / counts per revolution), when the capture states it;
    /// `None` = the smallest step seen in the data. See [`Resolution`].
    #[serde(default)]
    pub resolution_rad: Option<f64>,
}

impl Default for DecayOptions {
    fn default() -> Self {
        Self {
            base: vec![Term::ViscousLinear],
            candidates: vec![
                Term::CoulombConstant,
                Term::ViscousQuadratic,
                Term::CoulombBearing,
                Term::Stiffness,
            ],
            rig: None,
            reference: None,
            segment_half_swings: 4,
            fit_points_per_period: 48,
            sim_tol: 1e-9,
            max_iter: 40,
            z: 1.96,
            min_heldout_gain: 0.02,
            resolution_rad: None,
        }
    }
}

/// A turning point (θ̇ = 0), refined by a local parabola.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TurningPoint {
    pub t_s: f64,
    pub theta_rad: f64,
    /// +1 maximum, −1 minimum.
    pub sign: i8,
    /// The sample nearest to it.
    pub sample: usize,
    /// False when the parabola could not be trusted (the coarse sample is used).
    pub refined: bool,
}

/// Swings smaller than this many resolution steps (encoder counts) are not analysed: with the
/// angle known only to a step q, a turning point is uncertain by about q/√12 after the parabola
/// and a swing of 1–2 steps is mostly the quantiser's pattern (its period and loss per cycle are
/// then artefacts: the issue-16 recordings gave period drifts of +5,220 % and negative losses).
pub const MIN_SWING_STEPS: f64 = 3.0;

/// What the angle's resolution did to the analysis.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Resolution {
    /// One step of the angle, rad (one encoder count); 0 when the data have no step at all.
    pub step_rad: f64,
    /// Where the step comes from: the capture's counts per revolution, or the data.
    pub source: String,
    /// The quantiser's noise q/√12, rad: the noise floor is never below it.
    pub noise_floor_rad: f64,
    /// Swings (half the distance between successive turning points) below this, rad
    /// ([`MIN_SWING_STEPS`] steps), end the analysis.
    pub min_swing_rad: f64,
    /// The last turning point analysed, s, when smaller swings followed (`None`: every swing
    /// found was above [`Self::min_swing_rad`]).
    pub ended_at_s: Option<f64>,
    /// The swing that ended it, rad.
    pub ended_swing_rad: Option<f64>,
    /// Turning points found after the end and left out.
    pub dropped_turning_points: usize,
}

impl Resolution {
    /// One line for the report.
    pub fn describe(&self) -> String {
        let head = format!(
            "resolution: {:.3e} rad per step ({}); noise floor q/√12 = {:.1e} rad; swings below \
             {MIN_SWING_STEPS} steps ({:.3e} rad) are not analysed",
            self.step_rad, self.source, self.noise_floor_rad, self.min_swing_rad
        );
        match (self.ended_at_s, self.ended_swing_rad) {
            (Some(t), Some(a)) => format!(
                "{head}: the resolution ended the analysis at t = {t:.2} s (the next swing, \
                 {a:.3e} rad, is {:.1} steps; {} later turning points left out)",
                a / self.step_rad.max(1e-300),
                self.dropped_turning_points
            ),
            _ => format!("{head}: every swing found is above it"),
        }
    }
}

/// One row of the envelope table: turning point n (half swing number n).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnvelopeRow {
    pub n: usize,
    pub t_s: f64,
    pub theta_rad: f64,
    /// |θ − centre|.
    pub amplitude_rad: f64,
    /// Time to the next turning point.
    pub half_period_s: Option<f64>,
    /// (|θ_{n−1} − θ_n| + |θ_n − θ_{n+1}|)/4: the amplitude at n, free of the centre's offset.
    pub mid_amplitude_rad: Option<f64>,
    /// |θ_{n−1} − θ_{n+1}| with sign: the amplitude lost over the cycle around n.
    pub loss_per_cycle_rad: Option<f64>,
}

/// A fitted coefficient with its interval.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Coef {
    pub name: String,
    pub estimate: f64,
    pub ci_low: f64,
    pub ci_high: f64,
    pub unit: String,
    /// The interval excludes 0.
    pub significant: bool,
}

/// The decay envelope and what its shape says.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnvelopeFit {
    pub rows: Vec<EnvelopeRow>,
    /// The oscillation's centre (median of three-point turning-point averages), rad.
    pub centre_rad: f64,
    /// Measurement noise of θ, rad, never below the quantiser's (see `resolution`).
    pub noise_rad: f64,
    /// The angle's resolution and where it ended the analysis.
    #[serde(default)]
    pub resolution: Resolution,
    /// ΔA per cycle = c0 + c1·A + c2·A², all three terms.
    pub polynomial: Vec<Coef>,
    /// The subset of {c0, c1, c2} with the lowest BIC, refitted alone.
    pub polynomial_best: Vec<Coef>,
    /// In words: linear decay (dry), exponential (viscous), 1/n-like (quadratic), or a mix.
    pub shape: String,
    /// ΔA per cycle as a non-negative sum of the catalogue terms' exact pendulum loss curves
    /// (the subset with the lowest BIC); estimates are the dimensionless parameters.
    pub catalogue: Vec<Coef>,
    pub notes: Vec<String>,
}

/// An estimate with its 95 % interval.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    pub name: String,
    pub estimate: f64,
    pub ci_low: f64,
    pub ci_high: f64,
    pub unit: String,
}

/// One fitted model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelFit {
    /// Catalogue names of its damping terms.
    pub terms: Vec<String>,
    /// ω_n, the angle offset and each term's dimensionless parameter, with intervals.
    pub params: Vec<Estimate>,
    /// The same in identifiable physical ratios (and in SI torques when m and a are known).
    pub physical: Vec<Estimate>,
    pub t_from_s: f64,
    pub t_to_s: f64,
    pub n_points: usize,
    pub rss_rad2: f64,
    pub rms_rad: f64,
    /// Integrated autocorrelation time of the residuals (samples); the covariance is inflated by it.
    pub tau_int: f64,
    pub bic: f64,
    pub iterations: usize,
    #[serde(skip)]
    x: Vec<f64>,
    #[serde(skip)]
    cov: Vec<f64>,
    #[serde(skip)]
    term_list: Vec<Term>,
}

impl ModelFit {
    /// The small-swing ω_n, rad/s: ω_g √(1 + κ) (ω_g alone without a stiffness term).
    pub fn omega_n(&self) -> f64 {
        self.x[0] * (1.0 + self.term_value(Term::Stiffness)).sqrt()
    }

    /// The model's time scale ω_g, rad/s: gravity's share of ω_n (all of it without a
    /// stiffness term), the unit the simulation's time is counted in.
    pub fn omega_g(&self) -> f64 {
        self.x[0]
    }

    /// The angle offset (θ_meas = θ_model + offset), rad.
    pub fn offset_rad(&self) -> f64 {
        self.x[1]
    }

    /// A term's dimensionless parameter (0 if the model lacks it).
    pub fn term_value(&self, t: Term) -> f64 {
        self.term_list
            .iter()
            .position(|&x| x == t)
            .map_or(0.0, |k| self.x[2 + k])
    }
}

/// A held-out score.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HeldOutScore {
    pub model: String,
    /// Σ|θ_meas − θ_sim| over the held-out samples, rad, the simulation restarted from the
    /// measured turning point every `segment_half_swings` half swings.
    pub e_theta_rad: f64,
    /// The same per sample, rad.
    pub mean_abs_rad: f64,
    /// Σ|θ_meas − θ_sim| with one continuous simulation from the split (phase drift included).
    pub e_theta_continuous_rad: f64,
    pub samples: usize,
}

/// A candidate term tried on top of a model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Candidate {
    /// Catalogue name.
    pub term: String,
    /// The model it was added to (catalogue names).
    pub added_to: Vec<String>,
    /// Terms added in the same step (tried as a pair when no single term qualified).
    pub together_with: Vec<String>,
    /// Forward-selection round (1 = added to the base model).
    pub round: usize,
    /// The dimensionless parameter (see [`Term::meaning`]).
    pub parameter: String,
    pub estimate: f64,
    pub ci_low: f64,
    pub ci_high: f64,
    pub unit: String,
    /// The same in identifiable ratios / SI.
    pub physical: Vec<Estimate>,
    pub accepted: bool,
    /// 1 − E_θ(model + term)/E_θ(model) on the held-out part (both fitted on the first half
    /// of the swings; the second half simulated from the measured turning points).
    pub heldout_gain: f64,
    /// What noise explains: 2 standard errors of the gain from its block-to-block scatter.
    pub heldout_noise: f64,
    /// The gain when the held-out part is simulated in one piece from the split (long records
    /// drift in phase, which this score includes).
    pub heldout_gain_continuous: f64,
    pub e_theta_model_rad: f64,
    pub e_theta_extended_rad: f64,
    /// BIC(model + term) − BIC(model), full-record fits (negative favours the term).
    pub delta_bic: f64,
    /// Why it was (not) accepted.
    pub verdict: String,
}

/// A departure no tried term explains.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Unexplained {
    /// `period_drift`, `residual_structure`, `rest_position`, `envelope_misfit`.
    pub what: String,
    /// Where it lives (amplitude band, time range).
    pub location: String,
    pub magnitude: f64,
    pub unit: String,
    pub detail: String,
}

/// Loss of amplitude per cycle in one amplitude band: measured (envelope) and predicted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LossBand {
    pub amplitude_from_rad: f64,
    pub amplitude_to_rad: f64,
    pub amplitude_mean_rad: f64,
    /// Envelope rows (cycles) in the band.
    pub cycles: usize,
    /// Mean measured loss per cycle, rad, and its standard error.
    pub measured_rad: f64,
    pub measured_se_rad: f64,
    /// The base model's loss per cycle at the band's mean amplitude (full-record fit).
    pub base_model_rad: f64,
    /// The best model's.
    pub best_model_rad: f64,
    /// Each of the best model's terms' share (catalogue name, rad per cycle).
    pub best_terms: Vec<(String, f64)>,
}

/// Everything [`diagnose_decay`] finds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DecayDiagnosis {
    pub samples: usize,
    pub duration_s: f64,
    pub turning_points: usize,
    /// The fitted motion: first turning point to the end of the motion.
    pub t_motion_from_s: f64,
    pub t_motion_to_s: f64,
    /// Fits use the first half of the swings; the held-out part starts here.
    pub t_split_s: f64,
    pub envelope: EnvelopeFit,
    /// How the half period follows the amplitude (gravity law or a stiffness beside it);
    /// `None` with too few large swings.
    #[serde(default)]
    pub period_law: Option<PeriodLaw>,
    /// Loss per cycle by amplitude band: measured, base model, best model and its terms.
    pub loss_bands: Vec<LossBand>,
    /// The model in hand, fitted to the whole motion.
    pub base: ModelFit,
    pub candidates: Vec<Candidate>,
    /// Accepted terms, in the order they were added.
    pub accepted: Vec<String>,
    /// The base model plus the accepted terms, fitted to the whole motion.
    pub best: ModelFit,
    /// Held-out E_θ of the base model, the best model and the reference model, if any.
    pub heldout: Vec<HeldOutScore>,
    /// The quantities the data cannot separate.
    pub not_separable: Vec<String>,
    pub unexplained: Vec<Unexplained>,
    pub notes: Vec<String>,
}

impl DecayDiagnosis {
    /// The candidate record of a term's first round in which it was accepted, or its last try.
    pub fn candidate(&self, term: Term) -> Option<&Candidate> {
        let tries: Vec<&Candidate> = self
            .candidates
            .iter()
            .filter(|c| c.term == term.name())
            .collect();
        tries.iter().find(|c| c.accepted).or(tries.last()).copied()
    }

    /// Whether a term was accepted.
    pub fn is_accepted(&self, term: Term) -> bool {
        self.accepted.iter().any(|a| a == term.name())
    }
}

impl ModelFit {
    /// The model's loss of amplitude per cycle at amplitude `a` (first order in the damping).
    pub fn loss_per_cycle(&self, a: f64) -> f64 {
        let kappa = self.term_value(Term::Stiffness);
        self.term_list
            .iter()
            .map(|&t| self.term_value(t) * t.loss_per_cycle_with(a, kappa))
            .sum()
    }
}

// ---------------------------------------------------------------------------------------------
// Input, noise, turning points
// ---------------------------------------------------------------------------------------------

fn check_input(t: &[f64], th: &[f64]) -> Result<(), DecayError> {
    if t.len() != th.len() {
        return Err(DecayError::Input(format!(
            "{} times but {} angles",
            t.len(),
            th.len()
        )));
    }
    if t.len() < 50 {
        return Err(DecayError::Input(format!(
            "{} samples: too few for a free decay",
            t.len()
        )));
    }
    if let Some(i) = t.iter().chain(th).position(|v| !v.is_finite()) {
        return Err(DecayError::Input(format!(
            "non-finite value at position {i}"
        )));
    }
    if let Some(i) = t.windows(2).position(|w| w[1] <= w[0]) {
        return Err(DecayError::Input(format!(
            "times must increase: t[{}] = {} ≥ t[{}] = {}",
            i,
            t[i],
            i + 1,
            t[i + 1]
        )));
    }
    Ok(())
}

/// Ordinary least squares for the loss-per-cycle fits, `None` unless there are more points
/// than terms: an exact fit through as many points as terms would win every BIC comparison.
fn ols(rows: &[Vec<f64>], y: &[f64]) -> Option<LsFit> {
    if rows.len() <= rows.first()?.len() {
        return None;
    }
    pendulum_numerics::ols(rows, y).ok()
}

/// The angle's step q and where it comes from: `stated` (2π / counts per revolution) when the
/// capture gives it, else the smallest non-zero step seen.
fn angle_step(th: &[f64], stated: Option<f64>) -> (f64, String) {
    let mut steps: Vec<f64> = th
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 0.0)
        .collect();
    steps.sort_by(f64::total_cmp);
    // The smallest step seen at least 3 times (within 2 %, for values printed with few
    // digits): one odd tiny step does not set it, and a fast swing, whose steps are mostly
    // several counts, still shows its single counts near the turning points.
    let seen = (0..steps.len())
        .find(|&i| steps.partition_point(|&x| x <= 1.02 * steps[i]) - i >= 3)
        .map_or(0.0, |i| steps[i]);
    match stated {
        Some(q) if q > 0.0 && q.is_finite() => {
            let mut source = format!(
                "stated: {:.0} counts per revolution",
                std::f64::consts::TAU / q
            );
            // Steps much finer than the stated count mean the key is wrong (or the data were
            // smoothed): say so rather than trust either silently.
            if seen > 0.0 && seen < 0.5 * q {
                source.push_str(&format!(
                    "; the data move in finer steps ({seen:.2e} rad): check counts_per_rev"
                ));
            }
            (q, source)
        }
        _ => (
            seen,
            if seen > 0.0 {
                format!(
                    "the smallest step seen in the data, ≈ {:.0} per revolution",
                    std::f64::consts::TAU / seen
                )
            } else {
                "the data never change".to_string()
            },
        ),
    }
}

/// Noise of θ: the robust scatter of second differences (white noise: σ·√6), never below the
/// quantiser's q/√12 (a signal at rest on one count has no scatter at all, which is not a
/// noise-free measurement).
fn noise_level(th: &[f64], q: f64) -> f64 {
    let mut d2: Vec<f64> = th
        .windows(3)
        .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
        .collect();
    let mad = median(&mut d2) / 0.6745;
    let sigma_white = mad / 6f64.sqrt();
    sigma_white.max(q / 12f64.sqrt())
}

/// The noise, the resolution and the turning points of θ(t), cut where the swings fall below
/// [`MIN_SWING_STEPS`] steps.
fn resolved_turning_points(
    t: &[f64],
    th: &[f64],
    stated_step_rad: Option<f64>,
) -> (Vec<TurningPoint>, f64, Resolution) {
    let (q, source) = angle_step(th, stated_step_rad);
    let noise = noise_level(th, q);
    let h = (8.0 * noise).max(3.0 * q);
    let mut tps = turning_points_h(t, th, h);
    let mut res = Resolution {
        step_rad: q,
        source,
        noise_floor_rad: q / 12f64.sqrt(),
        min_swing_rad: MIN_SWING_STEPS * q,
        ended_at_s: None,
        ended_swing_rad: None,
        dropped_turning_points: 0,
    };
    let swing = |w: &[TurningPoint]| 0.5 * (w[1].theta_rad - w[0].theta_rad).abs();
    // From the largest swing on (small wiggles before a hand release are not the decay's end).
    let from = tps
        .windows(2)
        .enumerate()
        .max_by(|a, b| swing(a.1).total_cmp(&swing(b.1)))
        .map_or(0, |(i, _)| i);
    if let Some(n) = tps
        .windows(2)
        .enumerate()
        .skip(from)
        .find(|(_, w)| swing(w) < res.min_swing_rad)
        .map(|(i, _)| i)
    {
        res.ended_at_s = Some(tps[n].t_s);
        res.ended_swing_rad = Some(swing(&tps[n..n + 2]));
        res.dropped_turning_points = tps.len() - (n + 1);
        tps.truncate(n + 1);
    } else if let Some(last) = tps.last().filter(|_| q > 0.0) {
        // The swing after the last turning point found: too small for the hysteresis to close
        // it into a turning point. When it is under MIN_SWING_STEPS steps (but a step at least:
        // not a count flickering at rest), the resolution ended the analysis there, not the
        // pendulum's stop (the MultiArm small decay read at 4096 counts: its 14th swing, 2.6
        // counts, went unreported as "every swing found is above it").
        let after = &th[(last.sample + 1).min(th.len())..];
        let far = if last.sign > 0 {
            after.iter().copied().fold(f64::INFINITY, f64::min)
        } else {
            after.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        };
        let next = 0.5 * (last.theta_rad - far).abs();
        if next.is_finite() && next >= q && next < res.min_swing_rad {
            res.ended_at_s = Some(last.t_s);
            res.ended_swing_rad = Some(next);
        }
    }
    (tps, noise, res)
}

/// Turning points of θ(t): hysteresis on 8× the noise (so noise and encoder steps do not make
/// extrema), each refined by a parabola over ±T/12 around it. Extrema whose window reaches the
/// record's ends are dropped (the record's first sample is not a turning point), and so is
/// everything from the first swing smaller than [`MIN_SWING_STEPS`] steps of the angle's
/// resolution on (here the smallest step seen; [`turning_points_with`] takes a stated one).
/// Index of the first turning point that starts a swing. Leading turning points that belong to
/// a hold before the release (a hand's tremor holding the pendulum, whose swings from one
/// turning point to the next stay under [`HOLD_SWING_FRACTION`] of the largest of the first
/// eight) are skipped: a thesis recording held near upright before its release had the hold
/// counted as its first swing, which moved its dry-torque estimate by 44 %.
pub fn first_swing(tps: &[TurningPoint]) -> usize {
    let swings: Vec<f64> = tps
        .windows(2)
        .map(|w| (w[1].theta_rad - w[0].theta_rad).abs())
        .collect();
    let largest = swings.iter().take(8).fold(0.0_f64, |a, &b| a.max(b));
    swings
        .iter()
        .position(|&s| s >= HOLD_SWING_FRACTION * largest)
        .unwrap_or(0)
}

/// See [`first_swing`]: a decay's swing shrinks by far less than this between two turning points.
pub const HOLD_SWING_FRACTION: f64 = 0.2;

pub fn turning_points(t_s: &[f64], theta_rad: &[f64]) -> Vec<TurningPoint> {
    turning_points_with(t_s, theta_rad, None).0
}

/// [`turning_points`] with the angle's resolution when the capture states it (2π / counts per
/// revolution), and what the resolution did.
pub fn turning_points_with(
    t_s: &[f64],
    theta_rad: &[f64],
    resolution_rad: Option<f64>,
) -> (Vec<TurningPoint>, Resolution) {
    if check_input(t_s, theta_rad).is_err() {
        return (Vec::new(), Resolution::default());
    }
    let (tps, _, res) = resolved_turning_points(t_s, theta_rad, resolution_rad);
    (tps, res)
}

fn turning_points_h(t: &[f64], th: &[f64], h: f64) -> Vec<TurningPoint> {
    let n = th.len();
    // Coarse pass: (index range of the plateau, sign).
    // (first, last sample of the extreme value's plateau, sign)
    let mut coarse: Vec<(usize, usize, i8)> = Vec::new();
    let (mut imax, mut imax_last, mut imin, mut imin_last) = (0usize, 0usize, 0usize, 0usize);
    let mut dir: i8 = 0;
    for i in 1..n {
        let v = th[i];
        if dir >= 0 {
            if v > th[imax] {
                imax = i;
                imax_last = i;
            } else if v == th[imax] {
                imax_last = i;
            }
        }
        if dir <= 0 {
            if v < th[imin] {
                imin = i;
                imin_last = i;
            } else if v == th[imin] {
                imin_last = i;
            }
        }
        if dir >= 0 && v < th[imax] - h {
            coarse.push((imax, imax_last, 1));
            dir = -1;
            imin = i;
            imin_last = i;
        } else if dir <= 0 && v > th[imin] + h {
            coarse.push((imin, imin_last, -1));
            dir = 1;
            imax = i;
            imax_last = i;
        }
    }
    if coarse.len() < 3 {
        return Vec::new();
    }
    let mid = |c: &(usize, usize, i8)| (c.0 + c.1) / 2;
    let mut halves: Vec<f64> = coarse
        .windows(2)
        .map(|w| t[mid(&w[1])] - t[mid(&w[0])])
        .collect();
    let half = median(&mut halves);
    let w = half / 6.0;
    let mut out = Vec::with_capacity(coarse.len());
    for c in &coarse {
        let (first, last, sign) = *c;
        // A plateau longer than the refinement window is a hold (the pendulum held, then let
        // go): the turning point is the release, its last sample.
        if t[last] - t[first] > w {
            if t[last] + w <= t[n - 1] {
                out.push(TurningPoint {
                    t_s: t[last],
                    theta_rad: th[last],
                    sign,
                    sample: last,
                    refined: false,
                });
            }
            continue;
        }
        let i = mid(c);
        if t[i] - w < t[0] || t[i] + w > t[n - 1] {
            continue;
        }
        let (tp, refined) = refine(t, th, i, w, sign);
        out.push(TurningPoint {
            t_s: tp.0,
            theta_rad: tp.1,
            sign,
            sample: tp.2,
            refined,
        });
    }
    out
}

/// Parabola through the samples within ±w of sample i; twice recentred on its vertex.
fn refine(t: &[f64], th: &[f64], i: usize, w: f64, sign: i8) -> ((f64, f64, usize), bool) {
    let coarse = ((t[i], th[i], i), false);
    let mut centre = i;
    let mut best = coarse;
    for _ in 0..3 {
        let tc = t[centre];
        let lo = t.partition_point(|&x| x < tc - w);
        let hi = t.partition_point(|&x| x <= tc + w);
        if hi - lo < 5 {
            return best;
        }
        let mut s = [0.0f64; 5];
        let mut b = [0.0f64; 3];
        for j in lo..hi {
            let u = t[j] - tc;
            let mut p = 1.0;
            for (k, sk) in s.iter_mut().enumerate() {
                *sk += p;
                if k < 3 {
                    b[k] += p * th[j];
                }
                p *= u;
            }
        }
        let a = [s[0], s[1], s[2], s[1], s[2], s[3], s[2], s[3], s[4]];
        let Ok(c) = solve_spd(&a, &b, 3) else {
            return best;
        };
        // θ = c0 + c1 u + c2 u²
        if c[2] * f64::from(sign) >= 0.0 {
            return best;
        }
        let u_star = -c[1] / (2.0 * c[2]);
        if u_star.abs() > w {
            return best;
        }
        let t_star = tc + u_star;
        let th_star = c[0] - c[1] * c[1] / (4.0 * c[2]);
        let k = t.partition_point(|&x| x < t_star).min(t.len() - 1);
        let k = if k > 0 && (t[k] - t_star).abs() > (t[k - 1] - t_star).abs() {
            k - 1
        } else {
            k
        };
        best = ((t_star, th_star, k), true);
        if k == centre {
            break;
        }
        centre = k;
    }
    best
}

/// Complete elliptic integral of the first kind K(k) (modulus k), by the AGM.
fn ellip_k(k: f64) -> f64 {
    let mut a = 1.0;
    let mut b = (1.0 - k * k).max(0.0).sqrt();
    for _ in 0..40 {
        let an = 0.5 * (a + b);
        b = (a * b).sqrt();
        a = an;
        if (a - b).abs() < 1e-15 * a {
            break;
        }
    }
    std::f64::consts::PI / (2.0 * a)
}

/// Half period of the undamped pendulum at amplitude A, in units of 1/ω_n.
fn half_period_factor(a: f64) -> f64 {
    2.0 * ellip_k((0.5 * a).sin())
}

/// Half period of the undamped pendulum with restoring torque −u sin θ − (1 − u) θ (u = 1/(1 + κ):
/// gravity's share of the small-swing stiffness) at amplitude A, in units of 1/ω_n:
/// 2∫₀^{π/2} A cos φ dφ / √(2u(cos(A sin φ) − cos A) + (1 − u)A² cos² φ) (θ = A sin φ), by
/// Simpson; the end φ = π/2 is the integrand's limit A/√(uA sin A + (1 − u)A²).
fn half_period_mix(a: f64, u: f64) -> f64 {
    let a = a.clamp(1e-9, std::f64::consts::PI - 1e-3);
    let u = u.clamp(0.0, 1.0);
    let g = |phi: f64| -> f64 {
        let c = phi.cos();
        if c <= 1e-12 {
            return a / (u * a * a.sin() + (1.0 - u) * a * a).sqrt();
        }
        let x = a * phi.sin();
        // cos x − cos A without cancellation: 2 sin((A + x)/2) sin((A − x)/2), A − x = A c²/(1 + sin φ).
        let dc = 2.0 * (0.5 * (a + x)).sin() * (0.5 * a * c * c / (1.0 + phi.sin())).sin();
        a * c / (2.0 * u * dc + (1.0 - u) * a * a * c * c).sqrt()
    };
    let n = 64;
    let h = std::f64::consts::FRAC_PI_2 / n as f64;
    let mut s = 0.0;
    for k in 0..=n {
        let w = if k == 0 || k == n {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        };
        s += w * g(k as f64 * h);
    }
    2.0 * s * h / 3.0
}

/// Half period at amplitude A with a stiffness κ beside gravity, in units of 1/ω_g (the model's
/// time): [`half_period_factor`] when κ = 0.
fn half_period_units(a: f64, kappa: f64) -> f64 {
    if kappa == 0.0 {
        return half_period_factor(a);
    }
    let k1 = 1.0 + kappa.max(0.0);
    half_period_mix(a, 1.0 / k1) / k1.sqrt()
}

/// How the half period follows the amplitude: fitted as the period of θ'' = −u sin θ − (1 − u)θ
/// (gravity plus a linear stiffness κ = (1 − u)/u) to the larger swings' half periods. Gravity
/// alone (u = 1) lengthens the period by about A²/16; a spring's share does not, so the
/// amplitude dependence measures it, whatever ω_n is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PeriodLaw {
    /// Half swings used (amplitude ≥ 30 % of the largest and ≥ 20 resolution steps).
    pub swings: usize,
    pub amplitude_from_rad: f64,
    pub amplitude_to_rad: f64,
    /// u = 1/(1 + κ): gravity's share of the small-swing stiffness, with its interval.
    pub gravity_share: f64,
    pub gravity_share_ci_low: f64,
    pub gravity_share_ci_high: f64,
    /// κ = (1 − u)/u and its interval (from u's).
    pub kappa: f64,
    pub kappa_ci_low: f64,
    pub kappa_ci_high: f64,
    /// The small-swing ω_n, rad/s.
    pub omega_n_rad_s: f64,
    /// Rms relative misfit of the half periods.
    pub rms_rel: f64,
    /// The interval of u excludes 1: the period does not follow the gravity law.
    pub departs: bool,
    /// The interval of u leaves part of [0, 1] out: the swings' amplitudes say something about
    /// gravity's share. Small swings (the period's amplitude dependence ∝ A² below the timing
    /// noise) leave it anywhere in [0, 1]; then no interval is printed.
    pub determined: bool,
}

impl PeriodLaw {
    /// One line for the report.
    pub fn describe(&self) -> String {
        if !self.determined {
            return format!(
                "period law ({} half swings, A {:.3}–{:.3} rad, rms {:.2} %): undetermined — the \
                 swings are too small for their periods to tell gravity from a spring (gravity's \
                 share anywhere in [0, 1]); stiffness not tried",
                self.swings,
                self.amplitude_from_rad,
                self.amplitude_to_rad,
                100.0 * self.rms_rel,
            );
        }
        format!(
            "period law ({} half swings, A {:.3}–{:.3} rad, rms {:.2} %): gravity's share of the \
             small-swing stiffness u = {:.4} [{:.4}, {:.4}], kappa = {:.3e} [{:.3e}, {:.3e}]: {}",
            self.swings,
            self.amplitude_from_rad,
            self.amplitude_to_rad,
            100.0 * self.rms_rel,
            self.gravity_share,
            self.gravity_share_ci_low,
            self.gravity_share_ci_high,
            self.kappa,
            self.kappa_ci_low,
            self.kappa_ci_high,
            if self.departs {
                "the period does not follow the gravity law (stiffness tried)"
            } else {
                "the period follows the gravity law (stiffness not tried)"
            }
        )
    }
}

/// Fits [`PeriodLaw`] to the turning points; `None` with fewer than 6 usable half swings.
fn period_law(tps: &[TurningPoint], step_rad: f64, z: f64) -> Option<PeriodLaw> {
    let sw: Vec<(f64, f64)> = tps
        .windows(2)
        .map(|w| {
            (
                0.5 * (w[0].theta_rad - w[1].theta_rad).abs(),
                w[1].t_s - w[0].t_s,
            )
        })
        .collect();
    let amax = sw.iter().map(|s| s.0).fold(0.0, f64::max);
    // Only the larger swings: the amplitude dependence is there (∝ A²), and the encoder's
    // staircase times the small ones (see the period-drift allowance).
    let sel: Vec<(f64, f64)> = sw
        .into_iter()
        .filter(|s| s.0 >= 0.3 * amax && s.0 >= 20.0 * step_rad && s.1 > 0.0)
        .collect();
    let n = sel.len();
    if n < 6 {
        return None;
    }
    // log h = log(1/ω_n) + log P(A, u); the intercept is profiled out.
    let resid = |u: f64| -> (Vec<f64>, f64) {
        let r: Vec<f64> = sel
            .iter()
            .map(|&(a, h)| h.ln() - half_period_mix(a, u).ln())
            .collect();
        let m = r.iter().sum::<f64>() / n as f64;
        let r: Vec<f64> = r.iter().map(|v| v - m).collect();
        (r, m)
    };
    let rss = |u: f64| resid(u).0.iter().map(|v| v * v).sum::<f64>();
    // Golden section on u ∈ [0, 1] (the misfit is smooth in u).
    let gs = pendulum_numerics::golden_section(rss, 0.0, 1.0, 60);
    let mut u = 0.5 * (gs.lo + gs.hi);
    for end in [0.0, 1.0] {
        if rss(end) <= rss(u) {
            u = end;
        }
    }
    let (r, m) = resid(u);
    let s2 = r.iter().map(|v| v * v).sum::<f64>() / (n - 2) as f64;
    // Sensitivity of log P to u (one-sided at the ends), centred: the profiled intercept.
    let hstep = 1e-4;
    let (ua, ub) = ((u - hstep).max(0.0), (u + hstep).min(1.0));
    let gr: Vec<f64> = sel
        .iter()
        .map(|&(a, _)| (half_period_mix(a, ub).ln() - half_period_mix(a, ua).ln()) / (ub - ua))
        .collect();
    let gm = gr.iter().sum::<f64>() / n as f64;
    let sgg: f64 = gr.iter().map(|v| (v - gm) * (v - gm)).sum();
    let se = if sgg > 0.0 {
        (s2 / sgg).sqrt()
    } else {
        f64::INFINITY
    };
    let (u_lo, u_hi) = ((u - z * se).max(1e-9), u + z * se);
    let kap = |u: f64| (1.0 - u.max(1e-9)) / u.max(1e-9);
    Some(PeriodLaw {
        swings: n,
        amplitude_from_rad: sel.iter().map(|s| s.0).fold(f64::INFINITY, f64::min),
        amplitude_to_rad: amax,
        gravity_share: u,
        gravity_share_ci_low: u_lo,
        gravity_share_ci_high: u_hi,
        kappa: kap(u),
        kappa_ci_low: kap(u_hi).max(0.0),
        kappa_ci_high: kap(u_lo),
        omega_n_rad_s: (-m).exp(),
        rms_rel: (s2 * (n - 2) as f64 / n as f64).sqrt(),
        departs: u_hi < 1.0,
        determined: u_lo > 0.01 || u_hi < 1.0,
    })
}

/// The small-swing natural frequency ω_n, rad/s, from successive turning points: the median over
/// half swings of (exact pendulum half period at that swing's amplitude, in units of 1/ω_n) /
/// (measured half period), so large swings do not bias it. NaN with fewer than two points.
pub fn omega_n_estimate(tps: &[TurningPoint]) -> f64 {
    let mut w_est: Vec<f64> = tps
        .windows(2)
        .map(|w| {
            let a = 0.5 * (w[0].theta_rad - w[1].theta_rad).abs();
            half_period_factor(a) / (w[1].t_s - w[0].t_s)
        })
        .collect();
    median(&mut w_est)
}

// ---------------------------------------------------------------------------------------------
// Envelope
// ---------------------------------------------------------------------------------------------

fn coef(name: &str, est: f64, var: f64, z: f64, unit: &str) -> Coef {
    let se = var.max(0.0).sqrt();
    let (lo, hi) = (est - z * se, est + z * se);
    Coef {
        name: name.into(),
        estimate: est,
        ci_low: lo,
        ci_high: hi,
        unit: unit.into(),
        significant: lo > 0.0 || hi < 0.0,
    }
}

/// The envelope of a free decay: turning points, loss per cycle against amplitude, and its
/// shape.
pub fn envelope(t_s: &[f64], theta_rad: &[f64]) -> Result<EnvelopeFit, DecayError> {
    envelope_with(t_s, theta_rad, None)
}

/// [`envelope`] with the angle's resolution, rad, when the capture states it (`counts_per_rev`):
/// `None` takes the smallest step seen in the data.
pub fn envelope_with(
    t_s: &[f64],
    theta_rad: &[f64],
    resolution_rad: Option<f64>,
) -> Result<EnvelopeFit, DecayError> {
    check_input(t_s, theta_rad)?;
    let (tps, noise, res) = resolved_turning_points(t_s, theta_rad, resolution_rad);
    envelope_of(&tps, noise, res, 1.96)
}

/// How the envelope's note begins when its polynomial has a constant (in words, dry friction)
/// but the exact pendulum's terms keep no dry term: the constant is the curvature of the
/// pendulum's viscous or quadratic loss at large swings, not friction.
pub const DRY_CONSTANT_NOTE: &str =
    "the polynomial's constant is not by itself dry friction at amplitudes";

fn envelope_of(
    tps: &[TurningPoint],
    noise: f64,
    resolution: Resolution,
    z: f64,
) -> Result<EnvelopeFit, DecayError> {
    const NEEDED: usize = 6;
    if tps.len() < NEEDED && resolution.ended_at_s.is_some() {
        return Err(DecayError::Input(format!(
            "only {} turning points before the swings fall below {MIN_SWING_STEPS} steps of the \
             angle's resolution ({:.3e} rad, {}) at t = {:.2} s: need at least {NEEDED}",
            tps.len(),
            resolution.step_rad,
            resolution.source,
            resolution.ended_at_s.unwrap_or(f64::NAN)
        )));
    }
    if tps.len() < NEEDED {
        return Err(DecayError::TooFewSwings {
            found: tps.len(),
            needed: NEEDED,
        });
    }
    let k = tps.len();
    let th: Vec<f64> = tps.iter().map(|p| p.theta_rad).collect();
    let mut centres: Vec<f64> = (1..k - 1)
        .map(|i| 0.25 * (th[i - 1] + 2.0 * th[i] + th[i + 1]))
        .collect();
    let centre = median(&mut centres);
    let mut rows = Vec::with_capacity(k);
    for i in 0..k {
        let (mid, loss) = if i > 0 && i + 1 < k {
            let mid = 0.25 * ((th[i - 1] - th[i]).abs() + (th[i] - th[i + 1]).abs());
            let s = f64::from(tps[i - 1].sign);
            (Some(mid), Some(s * (th[i - 1] - th[i + 1])))
        } else {
            (None, None)
        };
        rows.push(EnvelopeRow {
            n: i,
            t_s: tps[i].t_s,
            theta_rad: th[i],
            amplitude_rad: (th[i] - centre).abs(),
            half_period_s: (i + 1 < k).then(|| tps[i + 1].t_s - tps[i].t_s),
            mid_amplitude_rad: mid,
            loss_per_cycle_rad: loss,
        });
    }
    let pts: Vec<(f64, f64)> = rows
        .iter()
        .filter_map(|r| Some((r.mid_amplitude_rad?, r.loss_per_cycle_rad?)))
        .collect();
    let y: Vec<f64> = pts.iter().map(|p| p.1).collect();
    let mut notes = Vec::new();

    // Polynomial in A.
    let names = ["c0", "c1", "c2"];
    let units = ["rad", "1", "1/rad"];
    let basis = |a: f64, j: usize| a.powi(j as i32);
    let fit_subset = |sub: &[usize]| -> Option<LsFit> {
        let rows: Vec<Vec<f64>> = pts
            .iter()
            .map(|p| sub.iter().map(|&j| basis(p.0, j)).collect())
            .collect();
        ols(&rows, &y)
    };
    let to_coefs = |sub: &[usize], beta: &[f64], cov: &[f64]| -> Vec<Coef> {
        let m = sub.len();
        sub.iter()
            .enumerate()
            .map(|(q, &j)| coef(names[j], beta[q], cov[q * m + q], z, units[j]))
            .collect()
    };
    let polynomial = match fit_subset(&[0, 1, 2]) {
        Some(f) => to_coefs(&[0, 1, 2], &f.coef, &f.cov),
        None => Vec::new(),
    };
    let subsets: [&[usize]; 7] = [&[0], &[1], &[2], &[0, 1], &[0, 2], &[1, 2], &[0, 1, 2]];
    let mut best: Option<(f64, Vec<Coef>)> = None;
    for sub in subsets {
        if let Some(LsFit {
            coef: b,
            cov: c,
            rss,
            ..
        }) = fit_subset(sub)
        {
            let cols: Vec<Vec<f64>> = sub
                .iter()
                .map(|&j| pts.iter().map(|p| basis(p.0, j)).collect())
                .collect();
            if !material(&b, &cols) {
                continue;
            }
            let score = bic(rss, pts.len(), sub.len());
            if best.as_ref().is_none_or(|(s, _)| score < *s) {
                best = Some((score, to_coefs(sub, &b, &c)));
            }
        }
    }
    let polynomial_best = best.map(|b| b.1).unwrap_or_default();
    let has = |n: &str| polynomial_best.iter().any(|c| c.name == n);
    let shape = match (has("c0"), has("c1"), has("c2")) {
        (true, false, false) => "linear decay: constant loss per cycle (dry friction)",
        (false, true, false) => "exponential decay: loss per cycle proportional to amplitude (viscous)",
        (false, false, true) => "1/n-like decay: loss per cycle proportional to amplitude squared (quadratic drag)",
        (true, true, false) => "mixed: constant + proportional to amplitude (dry friction + viscous)",
        (true, false, true) => "mixed: constant + amplitude squared (dry friction + quadratic drag or load-dependent friction)",
        (false, true, true) => "mixed: proportional to amplitude + amplitude squared (viscous + quadratic drag)",
        (true, true, true) => "mixed: constant + amplitude + amplitude squared",
        _ => "undetermined",
    }
    .to_string();

    // Catalogue basis (exact pendulum), non-negative, best subset by BIC.
    let terms = Term::ALL;
    let amax = pts.iter().map(|p| p.0).fold(0.0, f64::max);
    let amin = pts.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
    let mut best_cat: Option<(f64, Vec<Coef>)> = None;
    for mask in 1u32..(1 << terms.len()) {
        let sub: Vec<Term> = (0..terms.len())
            .filter(|j| mask & (1 << j) != 0)
            .map(|j| terms[j])
            .collect();
        let rows: Vec<Vec<f64>> = pts
            .iter()
            .map(|p| sub.iter().map(|t| t.loss_per_cycle(p.0)).collect())
            .collect();
        let Some(LsFit {
            coef: b,
            cov: c,
            rss,
            ..
        }) = ols(&rows, &y)
        else {
            continue;
        };
        if b.iter().any(|v| *v <= 0.0) {
            continue;
        }
        let cols: Vec<Vec<f64>> = sub
            .iter()
            .map(|t| pts.iter().map(|p| t.loss_per_cycle(p.0)).collect())
            .collect();
        if !material(&b, &cols) {
            continue;
        }
        let score = bic(rss, pts.len(), sub.len());
        if best_cat.as_ref().is_none_or(|(s, _)| score < *s) {
            let m = sub.len();
            let coefs = sub
                .iter()
                .enumerate()
                .map(|(q, t)| coef(t.name(), b[q], c[q * m + q], z, t.unit()))
                .collect();
            best_cat = Some((score, coefs));
        }
    }
    let catalogue = best_cat.map(|b| b.1).unwrap_or_default();
    // Dry terms whose loss curves cannot be told apart over the amplitudes seen.
    let cc: Vec<f64> = pts
        .iter()
        .map(|p| Term::CoulombConstant.loss_per_cycle(p.0))
        .collect();
    let cb: Vec<f64> = pts
        .iter()
        .map(|p| Term::CoulombBearing.loss_per_cycle(p.0))
        .collect();
    let corr = correlation(&cc, &cb);
    if corr > 0.995 {
        notes.push(format!(
            "coulomb_constant and coulomb_bearing give the same loss curve at amplitudes \
             {amin:.3}–{amax:.3} rad (correlation {corr:.4}): the envelope cannot tell them apart"
        ));
    }
    if catalogue.iter().any(|c| c.name == "coulomb_constant")
        && polynomial_best.iter().any(|c| c.name == "c2")
    {
        notes.push(
            "for a pendulum even a constant dry torque loses more per cycle at large amplitude \
             (2A/sin A per half swing): an A² term in the polynomial is not by itself quadratic drag"
                .into(),
        );
    }
    if polynomial_best.iter().any(|c| c.name == "c0")
        && !catalogue.is_empty()
        && !catalogue
            .iter()
            .any(|c| c.name == "coulomb_constant" || c.name == "coulomb_bearing")
    {
        notes.push(format!(
            "{DRY_CONSTANT_NOTE} {amin:.3}–{amax:.3} rad: a viscous loss per cycle there is \
             not proportional to A (fitted as c0 + c2·A² over 1.24–1.50 rad, a purely viscous \
             loss has c0 ≈ 0.24 of its mean), and the catalogue terms, fitted with the exact \
             curves, keep no dry term"
        ));
    }
    notes.push(
        "successive losses share turning points (negatively correlated errors): the polynomial's \
         intervals are approximate"
            .into(),
    );
    Ok(EnvelopeFit {
        rows,
        centre_rad: centre,
        noise_rad: noise,
        resolution,
        polynomial,
        polynomial_best,
        shape,
        catalogue,
        notes,
    })
}

/// Whether every term of a fit carries at least 5 % of the fitted loss somewhere in the
/// observed range (a significant but negligible term does not change the envelope's shape:
/// for a pendulum the exact loss curves are not pure powers of the amplitude).
fn material(b: &[f64], cols: &[Vec<f64>]) -> bool {
    let n = cols.first().map_or(0, Vec::len);
    let total: Vec<f64> = (0..n)
        .map(|k| cols.iter().zip(b).map(|(c, bj)| bj * c[k]).sum::<f64>())
        .collect();
    cols.iter()
        .zip(b)
        .all(|(c, bj)| (0..n).any(|k| (bj * c[k]).abs() >= 0.05 * total[k].abs().max(1e-300)))
}

fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    if a.len() < 2 {
        return 1.0;
    }
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    if saa <= 0.0 || sbb <= 0.0 {
        return 1.0;
    }
    sab / (saa * sbb).sqrt()
}

// ---------------------------------------------------------------------------------------------
// Trajectory fits (multiple shooting from measured turning points)
// ---------------------------------------------------------------------------------------------

/// A simulated piece: from turning point (t0, θ0, θ̇ = 0) over the given samples.
#[derive(Debug, Clone)]
struct Seg {
    t0: f64,
    theta0: f64,
    /// Sample indices (t ≥ t0), increasing.
    idx: Vec<usize>,
}

struct Decay<'a> {
    t: &'a [f64],
    th: &'a [f64],
    tps: Vec<TurningPoint>,
    half_s: f64,
    sim: SimOptions,
    seg_len: usize,
}

#[derive(Debug, Clone)]
struct LmOut {
    x: Vec<f64>,
    r: Vec<f64>,
    jac: Vec<Vec<f64>>,
    rss: f64,
    iters: usize,
}

impl<'a> Decay<'a> {
    /// Samples with t in [from, to], every `stride`-th.
    fn samples(&self, from: f64, to: f64, stride: usize) -> Vec<usize> {
        let lo = self.t.partition_point(|&x| x < from);
        let hi = self.t.partition_point(|&x| x <= to);
        (lo..hi).step_by(stride.max(1)).collect()
    }

    /// Segments restarting every `seg_len` turning points from `k_from`, ending at `t_to`.
    fn segments(&self, k_from: usize, t_to: f64, seg_len: usize, stride: usize) -> Vec<Seg> {
        let mut segs = Vec::new();
        let mut k = k_from;
        while k < self.tps.len() && self.tps[k].t_s < t_to {
            let next = k + seg_len.max(1);
            let end = if next < self.tps.len() {
                self.tps[next].t_s.min(t_to)
            } else {
                t_to
            };
            let p = self.tps[k];
            // The end sample belongs to the next segment, except for the last one.
            let mut idx = self.samples(p.t_s, end, stride);
            if end < t_to {
                idx.retain(|&i| self.t[i] < end);
            }
            if !idx.is_empty() {
                segs.push(Seg {
                    t0: p.t_s,
                    theta0: p.theta_rad,
                    idx,
                });
            }
            k = next;
        }
        segs
    }

    fn single(&self, k_from: usize, t_to: f64) -> Vec<Seg> {
        let p = self.tps[k_from];
        vec![Seg {
            t0: p.t_s,
            theta0: p.theta_rad,
            idx: self.samples(p.t_s, t_to, 1),
        }]
    }

    fn model(terms: &[Term], x: &[f64]) -> Model {
        let mut d = Dimensionless::conservative();
        for (k, t) in terms.iter().enumerate() {
            t.set(&mut d, x[2 + k]);
        }
        Model::with_excitation(d, Excitation::None)
    }

    /// θ_meas − θ_sim at every sample of every segment (θ_sim includes the offset).
    fn residuals(&self, terms: &[Term], x: &[f64], segs: &[Seg]) -> Result<Vec<f64>, DecayError> {
        let n: usize = segs.iter().map(|s| s.idx.len()).sum();
        let mut r = Vec::with_capacity(n);
        let model = Self::model(terms, x);
        let (w, off) = (x[0], x[1]);
        for s in segs {
            let sim = self.simulate(&model, w, s.t0, s.theta0 - off, &s.idx)?;
            for (&i, v) in s.idx.iter().zip(sim) {
                r.push(self.th[i] - off - v);
            }
        }
        Ok(r)
    }

    fn simulate(
        &self,
        model: &Model,
        omega_n: f64,
        t0: f64,
        theta0: f64,
        idx: &[usize],
    ) -> Result<Vec<f64>, DecayError> {
        let times: Vec<f64> = idx
            .iter()
            .map(|&i| ((self.t[i] - t0) * omega_n).max(0.0))
            .collect();
        let t_end = times.last().copied().unwrap_or(0.0).max(1e-9);
        let mut out = Vec::with_capacity(times.len());
        integrate(
            model,
            &self.sim,
            0.0,
            [theta0, 0.0],
            t_end * (1.0 + 1e-12) + 1e-12,
            times.iter().copied(),
            |s| {
                out.push(s.theta);
                ControlFlow::Continue(())
            },
        )?;
        // A requested time the integrator did not reach (it should not happen): the last state.
        let last = out.last().copied().unwrap_or(theta0);
        out.resize(times.len(), last);
        Ok(out)
    }

    fn lower(terms: &[Term], x0: &[f64]) -> Vec<f64> {
        let mut lo = vec![1e-3 * x0[0], f64::NEG_INFINITY];
        lo.extend(terms.iter().map(|_| 0.0));
        lo
    }

    fn step(terms: &[Term], x: &[f64], j: usize) -> f64 {
        match j {
            0 => 1e-6 * x[0],
            1 => 1e-6,
            _ => (1e-3 * x[j].abs()).max(terms[j - 2].fd_floor()),
        }
    }

    /// Levenberg–Marquardt ([`pendulum_fit::LevenbergMarquardt`], default schedule) with the
    /// parameters projected onto their lower bounds; Jacobian of `r = θ − θ_sim` by central
    /// differences of step [`Self::step`], forward ones next to a bound.
    fn lm(
        &self,
        terms: &[Term],
        x0: &[f64],
        segs: &[Seg],
        max_iter: usize,
    ) -> Result<LmOut, DecayError> {
        struct Ls<'p, 'a> {
            decay: &'p Decay<'a>,
            terms: &'p [Term],
            segs: &'p [Seg],
            lo: Vec<f64>,
            /// The latest simulation failure, reported instead of the solver's generic error.
            failure: std::cell::RefCell<Option<DecayError>>,
        }
        impl pendulum_fit::LeastSquaresProblem for Ls<'_, '_> {
            fn dim(&self) -> usize {
                self.lo.len()
            }
            fn bounds(&self) -> Vec<(f64, f64)> {
                self.lo.iter().map(|&l| (l, f64::INFINITY)).collect()
            }
            fn residuals(&self, x: &[f64]) -> Option<Vec<f64>> {
                let r = self.decay.residuals(self.terms, x, self.segs);
                r.map_err(|e| *self.failure.borrow_mut() = Some(e)).ok()
            }
            fn fd_step(&self, x: &[f64], j: usize) -> f64 {
                Decay::step(self.terms, x, j)
            }
        }
        let problem = Ls {
            decay: self,
            terms,
            segs,
            lo: Self::lower(terms, x0),
            failure: std::cell::RefCell::new(None),
        };
        let config = pendulum_fit::LmConfig::default().with_max_iterations(max_iter);
        let solver = pendulum_fit::LevenbergMarquardt::new(config).expect("valid LM settings");
        let out = solver.solve(&problem, x0).map_err(|e| {
            let failure = problem.failure.take();
            failure.unwrap_or_else(|| DecayError::Input(format!("least squares: {e}")))
        })?;
        Ok(LmOut {
            x: out.x,
            r: out.residuals,
            jac: out.jacobian,
            rss: out.rss,
            iters: out.iterations,
        })
    }

    /// Fits `terms` on the segments and wraps the result with its covariance.
    fn fit(
        &self,
        terms: &[Term],
        x0: &[f64],
        segs: &[Seg],
        opts: &DecayOptions,
    ) -> Result<ModelFit, DecayError> {
        let out = self.lm(terms, x0, segs, opts.max_iter)?;
        let n = out.r.len();
        let p = out.x.len();
        let tau = tau_int(&out.r);
        let mut a = vec![0.0; p * p];
        for i in 0..p {
            for k in 0..p {
                a[i * p + k] = out.jac[i].iter().zip(&out.jac[k]).map(|(u, w)| u * w).sum();
            }
        }
        let s2 = out.rss / (n.saturating_sub(p)).max(1) as f64;
        let cov = match inverse_spd(&a, p) {
            Ok(inv) => inv.iter().map(|v| v * s2 * tau).collect(),
            Err(_) => vec![f64::INFINITY; p * p],
        };
        let t_from = segs.first().map_or(f64::NAN, |s| s.t0);
        let t_to = segs
            .last()
            .and_then(|s| s.idx.last())
            .map_or(f64::NAN, |&i| self.t[i]);
        let n_eff = (n as f64 / tau).max(p as f64 + 1.0);
        let bic = n_eff * (out.rss / n as f64).max(1e-300).ln() + p as f64 * n_eff.ln();
        let mut fit = ModelFit {
            terms: terms.iter().map(|t| t.name().to_string()).collect(),
            params: Vec::new(),
            physical: Vec::new(),
            t_from_s: t_from,
            t_to_s: t_to,
            n_points: n,
            rss_rad2: out.rss,
            rms_rad: (out.rss / n.max(1) as f64).sqrt(),
            tau_int: tau,
            bic,
            iterations: out.iters,
            x: out.x,
            cov,
            term_list: terms.to_vec(),
        };
        fit.params = params_of(&fit, opts.z);
        fit.physical = physical_of(&fit, opts);
        Ok(fit)
    }

    /// Residuals of a fitted model over one continuous simulation from turning point `k_from`
    /// to `t_to` (every sample).
    fn heldout_residuals(
        &self,
        terms: &[Term],
        x: &[f64],
        k_from: usize,
        t_to: f64,
    ) -> Result<(Vec<usize>, Vec<f64>), DecayError> {
        let segs = self.single(k_from, t_to);
        let r = self.residuals(terms, x, &segs)?;
        Ok((segs[0].idx.clone(), r))
    }

    /// Block boundaries for the held-out comparison: turning points, and half periods after
    /// the last one.
    fn block_of(&self, idx: &[usize]) -> Vec<usize> {
        let last_tp = self.tps.last().map_or(f64::NEG_INFINITY, |p| p.t_s);
        idx.iter()
            .map(|&i| {
                let t = self.t[i];
                let k = self.tps.partition_point(|p| p.t_s <= t);
                if t <= last_tp {
                    k
                } else {
                    self.tps.len() + ((t - last_tp) / self.half_s).floor() as usize
                }
            })
            .collect()
    }
}

/// Integrated autocorrelation time of a residual series (initial positive sequence).
fn tau_int(r: &[f64]) -> f64 {
    let n = r.len();
    if n < 10 {
        return 1.0;
    }
    let mean = r.iter().sum::<f64>() / n as f64;
    let c0: f64 = r.iter().map(|v| (v - mean) * (v - mean)).sum();
    if c0 <= 0.0 {
        return 1.0;
    }
    let mut tau = 1.0;
    for lag in 1..(n / 4).min(400) {
        let c: f64 = (0..n - lag)
            .map(|i| (r[i] - mean) * (r[i + lag] - mean))
            .sum();
        let rho = c / c0;
        if rho <= 0.0 {
            break;
        }
        tau += 2.0 * rho;
    }
    tau
}

fn estimate(name: &str, v: f64, var: f64, z: f64, unit: &str) -> Estimate {
    let se = var.max(0.0).sqrt();
    Estimate {
        name: name.into(),
        estimate: v,
        ci_low: v - z * se,
        ci_high: v + z * se,
        unit: unit.into(),
    }
}

fn params_of(fit: &ModelFit, z: f64) -> Vec<Estimate> {
    let p = fit.x.len();
    let var = |j: usize| fit.cov[j * p + j];
    let stiff = fit.term_list.contains(&Term::Stiffness);
    let mut v = vec![
        estimate(
            if stiff {
                "omega_g (gravity's share of omega_n)"
            } else {
                "omega_n"
            },
            fit.x[0],
            var(0),
            z,
            "rad/s",
        ),
        estimate("theta_offset", fit.x[1], var(1), z, "rad"),
    ];
    for (k, t) in fit.term_list.iter().enumerate() {
        v.push(estimate(t.symbol(), fit.x[2 + k], var(2 + k), z, t.unit()));
    }
    v
}

/// A derived quantity f(x) with its delta-method variance.
fn derived(fit: &ModelFit, f: &dyn Fn(&[f64]) -> f64) -> (f64, f64) {
    let p = fit.x.len();
    let v = f(&fit.x);
    let mut grad = vec![0.0; p];
    for (j, g) in grad.iter_mut().enumerate() {
        let h = 1e-6 * fit.x[j].abs().max(1e-6);
        let mut xp = fit.x.clone();
        xp[j] += h;
        let mut xm = fit.x.clone();
        xm[j] -= h;
        *g = (f(&xp) - f(&xm)) / (2.0 * h);
    }
    let mut var = 0.0;
    for i in 0..p {
        for k in 0..p {
            var += grad[i] * fit.cov[i * p + k] * grad[k];
        }
    }
    (v, var)
}

/// Identifiable physical ratios of one term (and SI values when m and a are known).
fn term_physical(fit: &ModelFit, t: Term, opts: &DecayOptions) -> Vec<Estimate> {
    let z = opts.z;
    let Some(k) = fit.term_list.iter().position(|&x| x == t) else {
        return Vec::new();
    };
    let j = 2 + k;
    let mut out = Vec::new();
    let mut push = |name: &str, unit: &str, f: &dyn Fn(&[f64]) -> f64| {
        let (v, var) = derived(fit, f);
        out.push(estimate(name, v, var, z, unit));
    };
    // m g a = I ω_n²: with m and a known, I = m g a / ω_n².
    let mga = opts.rig.map(|r| r.m_kg * r.g_m_s2 * r.a_m);
    match t {
        Term::ViscousLinear => {
            push("gamma = b_theta/I", "1/s", &|x| x[j] * x[0]);
            if let Some(mga) = mga {
                push("b_theta (viscous torque per rad/s)", "N·m·s", &|x| {
                    x[j] * mga / x[0]
                });
            }
        }
        Term::CoulombConstant => {
            push("T_c/I", "rad/s²", &|x| x[j] * x[0] * x[0]);
            push("loss per cycle 4c", "rad", &|x| 4.0 * x[j]);
            if let Some(mga) = mga {
                push("T_c", "N·m", &|x| x[j] * mga);
            }
        }
        Term::ViscousQuadratic => {
            push("q = a_theta/I", "1/rad", &|x| x[j]);
            if let Some(mga) = mga {
                push("a_theta (torque per (rad/s)²)", "N·m·s²", &|x| {
                    x[j] * mga / (x[0] * x[0])
                });
            }
        }
        Term::CoulombBearing => {
            push("mu r_b m g/I", "rad/s²", &|x| x[j] * x[0] * x[0]);
            if let Some(r) = opts.rig {
                if let Some(rb) = r.r_b_m {
                    let a = r.a_m;
                    push("mu (point-mass load)", "1", &|x| x[j] * a / rb);
                }
            }
        }
        Term::Stiffness => {
            push("k/I", "rad/s²", &|x| x[j] * x[0] * x[0]);
            push(
                "k/(I omega_n²): the spring's share of the small-swing stiffness",
                "1",
                &|x| x[j] / (1.0 + x[j]),
            );
            if let Some(mga) = mga {
                push("k (torsion stiffness)", "N·m/rad", &|x| x[j] * mga);
            }
        }
    }
    out
}

fn physical_of(fit: &ModelFit, opts: &DecayOptions) -> Vec<Estimate> {
    let z = opts.z;
    let mut out = Vec::new();
    // Small swings: ω_n = ω_g √(1 + κ) (κ = 0 without a stiffness term).
    let ks = fit.term_list.iter().position(|&t| t == Term::Stiffness);
    let wn = move |x: &[f64]| x[0] * (1.0 + ks.map_or(0.0, |k| x[2 + k])).sqrt();
    if ks.is_some() {
        let (v, var) = derived(fit, &wn);
        out.push(estimate("omega_n (small swings)", v, var, z, "rad/s"));
    }
    let (v, var) = derived(fit, &|x| wn(x) / std::f64::consts::TAU);
    out.push(estimate("f_n", v, var, z, "Hz"));
    let (v, var) = derived(fit, &|x| std::f64::consts::TAU / wn(x));
    out.push(estimate("small-swing period", v, var, z, "s"));
    if let Some(r) = opts.rig {
        let mga = r.m_kg * r.g_m_s2 * r.a_m;
        let (v, var) = derived(fit, &|x| mga / (x[0] * x[0]));
        out.push(estimate("I (pivot) = m g a/omega_n^2", v, var, z, "kg·m²"));
        let ma2 = r.m_kg * r.a_m * r.a_m;
        let (v, var) = derived(fit, &|x| mga / (x[0] * x[0]) - ma2);
        out.push(estimate(
            "I − m a² (inertia beyond a point mass)",
            v,
            var,
            z,
            "kg·m²",
        ));
    }
    for &t in &fit.term_list {
        out.extend(term_physical(fit, t, opts));
    }
    out
}

// ---------------------------------------------------------------------------------------------
// The diagnosis
// ---------------------------------------------------------------------------------------------

/// Diagnoses a free decay θ(t) (s, rad from the hanging position; an offset is fitted): see the
/// module docs.
pub fn diagnose_decay(
    t_s: &[f64],
    theta_rad: &[f64],
    opts: &DecayOptions,
) -> Result<DecayDiagnosis, DecayError> {
    check_input(t_s, theta_rad)?;
    if opts.base.is_empty() && opts.candidates.is_empty() {
        return Err(DecayError::Input("no damping terms to fit".into()));
    }
    let (tps, noise, res) = resolved_turning_points(t_s, theta_rad, opts.resolution_rad);
    let env = envelope_of(&tps, noise, res, opts.z)?;
    let k = tps.len();
    let mut halves: Vec<f64> = tps.windows(2).map(|w| w[1].t_s - w[0].t_s).collect();
    let half_s = median(&mut halves);
    let dt = {
        let mut d: Vec<f64> = t_s.windows(2).map(|w| w[1] - w[0]).collect();
        median(&mut d)
    };
    let per_period = (2.0 * half_s / dt).max(1.0);
    let stride = ((per_period / opts.fit_points_per_period.max(8) as f64).floor() as usize).max(1);
    let d = Decay {
        t: t_s,
        th: theta_rad,
        tps: tps.clone(),
        half_s,
        sim: SimOptions {
            rtol: opts.sim_tol,
            atol: opts.sim_tol,
            h_max: 0.25,
            ..SimOptions::default()
        },
        seg_len: opts.segment_half_swings.max(1),
    };
    let t_last = t_s[t_s.len() - 1];
    let t_motion_end = (tps[k - 1].t_s + half_s).min(t_last);
    let k_split = k / 2;
    let t_split = tps[k_split].t_s;

    // Initial guesses: ω_n from the half periods with the exact pendulum's amplitude factor.
    let omega0 = omega_n_estimate(&tps);
    // Does the period follow the gravity law? A stiffness is tried only when it does not.
    let law = period_law(&tps, env.resolution.step_rad, opts.z);
    let law_departs = law.as_ref().is_some_and(|l| l.departs);
    let kappa0 = law
        .as_ref()
        .filter(|l| l.departs)
        .map_or(0.1, |l| l.kappa.clamp(1e-3, 1e3));
    let init_losses = |terms: &[Term]| -> Vec<f64> {
        let pts: Vec<(f64, f64)> = env
            .rows
            .iter()
            .filter_map(|r| Some((r.mid_amplitude_rad?, r.loss_per_cycle_rad?)))
            .collect();
        let rows: Vec<Vec<f64>> = pts
            .iter()
            .map(|p| terms.iter().map(|t| t.loss_per_cycle(p.0)).collect())
            .collect();
        let y: Vec<f64> = pts.iter().map(|p| p.1).collect();
        match ols(&rows, &y) {
            Some(f) => f.coef.iter().map(|v| v.max(0.0) * 0.7 + 1e-6).collect(),
            None => vec![1e-4; terms.len()],
        }
    };
    // A stiffness takes no energy: it has no loss curve and starts from the period law.
    let init_terms = |terms: &[Term]| -> Vec<f64> {
        let losses: Vec<Term> = terms
            .iter()
            .copied()
            .filter(|&t| t != Term::Stiffness)
            .collect();
        let b = init_losses(&losses);
        let mut it = b.into_iter();
        terms
            .iter()
            .map(|&t| {
                if t == Term::Stiffness {
                    kappa0
                } else {
                    it.next().unwrap_or(1e-4)
                }
            })
            .collect()
    };
    let x0_for = |terms: &[Term], from: Option<&ModelFit>| -> Vec<f64> {
        let mut x = vec![omega0, env.centre_rad];
        let init = init_terms(terms);
        for (j, t) in terms.iter().enumerate() {
            let v = match from {
                Some(f) if f.term_list.contains(t) => f.term_value(*t),
                _ => init[j],
            };
            x.push(v);
        }
        // x[0] is the model's time scale ω_g = ω_n/√(1 + κ): the small-swing ω_n carries over
        // (from the model in hand, or the period law's when a stiffness starts from it).
        let kappa = terms
            .iter()
            .position(|&t| t == Term::Stiffness)
            .map_or(0.0, |k| x[2 + k]);
        let w_small = match (from, &law) {
            (Some(f), _) => f.omega_n(),
            (None, Some(l)) if kappa > 0.0 && l.departs => l.omega_n_rad_s,
            _ => omega0,
        };
        x[0] = w_small / (1.0 + kappa).sqrt();
        if let Some(f) = from {
            x[1] = f.offset_rad();
        }
        x
    };

    let segs_full = d.segments(0, t_motion_end, d.seg_len, stride);
    let segs_half = d.segments(0, t_split, d.seg_len, stride);

    // Held-out residuals of a model fitted on the first half: simulated in segments restarted
    // at the measured turning points (primary: no phase drift accumulates) and in one piece.
    let heldout_of = |terms: &[Term], fit: &ModelFit| -> Result<HeldOut, DecayError> {
        let segs = d.segments(k_split, t_motion_end, d.seg_len, 1);
        let r = d.residuals(terms, &fit.x, &segs)?;
        let idx: Vec<usize> = segs.iter().flat_map(|s| s.idx.iter().copied()).collect();
        let (_, rc) = d.heldout_residuals(terms, &fit.x, k_split, t_motion_end)?;
        Ok(HeldOut {
            blocks: d.block_of(&idx),
            r,
            rc,
        })
    };
    // Two starts (from the model in hand, and from the envelope); the better fit is kept.
    let fit2 = |terms: &[Term], from: &ModelFit, segs: &[Seg]| -> Result<ModelFit, DecayError> {
        let a = d.fit(terms, &x0_for(terms, Some(from)), segs, opts)?;
        let b = d.fit(terms, &x0_for(terms, None), segs, opts)?;
        Ok(if b.rss_rad2 < a.rss_rad2 { b } else { a })
    };
    let try_add = |current: &[Term],
                   full_cur: &ModelFit,
                   half_cur: &ModelFit,
                   h_cur: &HeldOut,
                   add: &[Term]|
     -> Result<Trial, DecayError> {
        let mut terms = current.to_vec();
        terms.extend_from_slice(add);
        let full = fit2(&terms, full_cur, &segs_full)?;
        let half = fit2(&terms, half_cur, &segs_half)?;
        let h = heldout_of(&terms, &half)?;
        let e_cur: f64 = h_cur.r.iter().map(|v| v.abs()).sum();
        let e_ext: f64 = h.r.iter().map(|v| v.abs()).sum();
        let ec_cur: f64 = h_cur.rc.iter().map(|v| v.abs()).sum();
        let ec_ext: f64 = h.rc.iter().map(|v| v.abs()).sum();
        let gain = 1.0 - e_ext / e_cur.max(1e-300);
        let noise_gain = 2.0 * block_se(&h_cur.r, &h.r, &h_cur.blocks) / e_cur.max(1e-300);
        let p = full.x.len();
        let ests: Vec<Estimate> = add
            .iter()
            .map(|t| {
                let j = 2 + terms.iter().position(|x| x == t).unwrap_or(0);
                estimate(t.symbol(), full.x[j], full.cov[j * p + j], opts.z, t.unit())
            })
            .collect();
        let n_eff = (full_cur.n_points as f64 / full_cur.tau_int).max(2.0);
        let delta_bic = n_eff * (full.rss_rad2 / full_cur.rss_rad2.max(1e-300)).ln()
            + add.len() as f64 * n_eff.ln();
        let excludes_zero = ests.iter().all(|e| e.ci_low > 0.0);
        let used_in_half = add.iter().all(|&t| half.term_value(t) > 0.0);
        let beats_noise = gain > noise_gain && gain > opts.min_heldout_gain;
        // The three views of one decay law (see DECAY_RULE). The energy balance vetoes: a term
        // whose model loses energy per cycle the pendulum does not is wrong whatever the
        // held-out score says. Then either the trajectory view alone (interval clear of 0 and a
        // held-out gain beyond its noise), or the envelope's: it resolves the term and the
        // trajectory fit agrees with it, and the held-out score, whose noise can exceed a small
        // effect (a dry loss that matters only at the last few-count swings), is not worse.
        let contradicted = loss_contradictions(&env, full_cur, &full, opts.z);
        let envelope = envelope_support(&env, current, add, &ests);
        let not_worse = gain > -noise_gain;
        let by_heldout = excludes_zero && beats_noise;
        let by_envelope = !envelope.is_empty() && envelope.iter().all(|e| e.agrees) && not_worse;
        let ok = contradicted.is_empty() && used_in_half && (by_heldout || by_envelope);
        let mut evidence = Vec::new();
        evidence.push(if envelope.is_empty() {
            "envelope: no loss curve (a stiffness)".to_string()
        } else {
            format!(
                "envelope: {}",
                envelope
                    .iter()
                    .map(|e| e.text.clone())
                    .collect::<Vec<_>>()
                    .join("; ")
            )
        });
        evidence.push(format!(
            "trajectory fit: {}",
            ests.iter()
                .map(|e| format!(
                    "{} = {:.3e} {}",
                    e.name,
                    e.estimate,
                    ci(e.ci_low, e.ci_high)
                ))
                .collect::<Vec<_>>()
                .join(", ")
        ));
        evidence.push(format!(
            "held-out E_theta {:+.1} % (noise {:.1} %)",
            -100.0 * gain,
            100.0 * noise_gain
        ));
        evidence.push(if contradicted.is_empty() {
            format!(
                "loss per cycle within the measured bands (mean ± {:.2}·se, ×{LOSS_BAND_FACTOR})",
                opts.z
            )
        } else {
            format!(
                "loss per cycle contradicts the measured: {}",
                contradicted.join("; ")
            )
        });
        let evidence = evidence.join(" | ");
        let verdict = if ok {
            format!(
                "qualifies ({}): {evidence}",
                if by_heldout {
                    "interval excludes 0 and held-out E_theta falls beyond its noise"
                } else {
                    "the envelope resolves it, the trajectory fit agrees, held-out E_theta no worse than its noise"
                }
            )
        } else {
            let mut why = Vec::new();
            if !contradicted.is_empty() {
                why.push("the model with it contradicts the measured loss per cycle".to_string());
            }
            if !used_in_half {
                why.push("the first-half fit sets it to 0".to_string());
            }
            if !by_heldout && !by_envelope {
                let mut t = Vec::new();
                if !excludes_zero {
                    t.push("its interval includes 0".to_string());
                }
                if !beats_noise {
                    t.push(format!(
                        "held-out E_theta changes {:+.1} % (needs a fall of more than {:.1} %: \
                         noise explains {:.1} %)",
                        -100.0 * gain,
                        100.0 * noise_gain.max(opts.min_heldout_gain),
                        100.0 * noise_gain
                    ));
                }
                t.push(format!(
                    "the envelope {}",
                    if envelope.is_empty() || !envelope.iter().all(|e| e.agrees) {
                        "does not resolve it with an interval that agrees"
                    } else {
                        "agrees but held-out E_theta gets worse beyond its noise"
                    }
                ));
                why.push(t.join(", "));
            }
            format!("rejected: {}: {evidence}", why.join("; "))
        };
        Ok(Trial {
            add: add.to_vec(),
            full,
            half,
            heldout: h,
            ok,
            gain,
            noise_gain,
            gain_cont: 1.0 - ec_ext / ec_cur.max(1e-300),
            e_cur,
            e_ext,
            delta_bic,
            ests,
            verdict,
        })
    };

    let mut current: Vec<Term> = opts.base.clone();
    let mut full_cur = d.fit(&current, &x0_for(&current, None), &segs_full, opts)?;
    let mut half_cur = d.fit(&current, &x0_for(&current, None), &segs_half, opts)?;
    let mut h_cur = heldout_of(&current, &half_cur)?;
    let base_full = full_cur.clone();
    let base_half = half_cur.clone();
    let base_heldout = h_cur.clone();
    let mut candidates = Vec::new();
    let mut accepted = Vec::new();
    // A stiffness only where the period does not follow the gravity law: it changes nothing
    // else, and trying it on every decay would only give the held-out noise a chance.
    let mut remaining: Vec<Term> = opts
        .candidates
        .iter()
        .copied()
        .filter(|t| !current.contains(t) && (*t != Term::Stiffness || law_departs))
        .collect();
    let mut round = 0;
    while !remaining.is_empty() {
        round += 1;
        let mut trials = Vec::new();
        for &term in &remaining {
            trials.push(try_add(&current, &full_cur, &half_cur, &h_cur, &[term])?);
        }
        // Terms that only help together (e.g. dry friction hidden by viscous damping until
        // quadratic drag takes the large swings' loss): pairs, when no single term qualifies.
        if !trials.iter().any(|t| t.ok) && remaining.len() >= 2 {
            for i in 0..remaining.len() {
                for j in i + 1..remaining.len() {
                    trials.push(try_add(
                        &current,
                        &full_cur,
                        &half_cur,
                        &h_cur,
                        &[remaining[i], remaining[j]],
                    )?);
                }
            }
        }
        let ok: Vec<usize> = (0..trials.len()).filter(|&i| trials[i].ok).collect();
        // The largest gain wins, but an earlier (simpler, preferred) trial within noise of it
        // is taken instead.
        let pick = ok
            .iter()
            .copied()
            .max_by(|&a, &b| trials[a].gain.total_cmp(&trials[b].gain))
            .map(|best| {
                let g = trials[best].gain - trials[best].noise_gain;
                ok.iter()
                    .copied()
                    .find(|&i| trials[i].gain >= g)
                    .unwrap_or(best)
            });
        let current_names: Vec<String> = current.iter().map(|t| t.name().to_string()).collect();
        for (i, tr) in trials.iter().enumerate() {
            for (q, &term) in tr.add.iter().enumerate() {
                let est = &tr.ests[q];
                let chosen = Some(i) == pick;
                let verdict = if chosen {
                    tr.verdict.replacen("qualifies", "accepted", 1)
                } else if tr.ok {
                    format!(
                        "qualifies, but {} was preferred this round",
                        pick.map(|p| names_of(&trials[p].add)).unwrap_or_default()
                    )
                } else {
                    tr.verdict.clone()
                };
                candidates.push(Candidate {
                    term: term.name().into(),
                    added_to: current_names.clone(),
                    together_with: tr
                        .add
                        .iter()
                        .filter(|&&t| t != term)
                        .map(|t| t.name().to_string())
                        .collect(),
                    round,
                    parameter: term.meaning().into(),
                    estimate: est.estimate,
                    ci_low: est.ci_low,
                    ci_high: est.ci_high,
                    unit: est.unit.clone(),
                    physical: term_physical(&tr.full, term, opts),
                    accepted: chosen,
                    heldout_gain: tr.gain,
                    heldout_noise: tr.noise_gain,
                    heldout_gain_continuous: tr.gain_cont,
                    e_theta_model_rad: tr.e_cur,
                    e_theta_extended_rad: tr.e_ext,
                    delta_bic: tr.delta_bic,
                    verdict,
                });
            }
        }
        let Some(i) = pick else {
            break;
        };
        let tr = trials.swap_remove(i);
        for &t in &tr.add {
            current.push(t);
            accepted.push(t.name().to_string());
        }
        remaining.retain(|t| !tr.add.contains(t));
        full_cur = tr.full;
        half_cur = tr.half;
        h_cur = tr.heldout;
    }

    // Held-out scores.
    let mut heldout = Vec::new();
    let mut push_score = |name: String, h: &HeldOut| {
        let e: f64 = h.r.iter().map(|v| v.abs()).sum();
        let ec: f64 = h.rc.iter().map(|v| v.abs()).sum();
        heldout.push(HeldOutScore {
            model: name,
            e_theta_rad: e,
            mean_abs_rad: e / h.r.len().max(1) as f64,
            e_theta_continuous_rad: ec,
            samples: h.r.len(),
        });
    };
    push_score(format!("base: {}", names_of(&opts.base)), &base_heldout);
    if current.len() > opts.base.len() {
        push_score(format!("best: {}", names_of(&current)), &h_cur);
    }
    if let Some(rm) = &opts.reference {
        let mut terms = vec![Term::ViscousLinear];
        let mut x = vec![
            rm.omega_n_rad_s,
            base_half.offset_rad(),
            rm.gamma_per_s / rm.omega_n_rad_s,
        ];
        if rm.dry_rad_s2 > 0.0 {
            terms.push(Term::CoulombConstant);
            x.push(rm.dry_rad_s2 / (rm.omega_n_rad_s * rm.omega_n_rad_s));
        }
        let mut fixed = base_half.clone();
        fixed.x = x;
        fixed.term_list = terms.clone();
        let h = heldout_of(&terms, &fixed)?;
        push_score(format!("reference: {}", rm.name), &h);
    }

    let best = full_cur;
    let mut notes = Vec::new();
    if let Some(l) = &law {
        notes.push(l.describe());
    }
    let loss_bands = loss_bands(&env, &base_full, &best);
    if let (Some(b), Some(x)) = (
        heldout.iter().find(|h| h.model.starts_with("base")),
        heldout.iter().find(|h| h.model.starts_with("best")),
    ) {
        if x.e_theta_continuous_rad > b.e_theta_continuous_rad {
            let cycles = (t_motion_end - t_split) / (2.0 * half_s);
            notes.push(format!(
                "simulated in one piece over the {cycles:.0} held-out cycles, the best model's \
                 E_theta ({:.4} rad) is larger than the base model's ({:.4} rad): phase and \
                 amplitude errors accumulate over that many cycles (omega_n from the first half \
                 is {:+.1e} off the whole record's), so the held-out gain is judged with the \
                 simulation restarted at the measured turning points",
                x.e_theta_continuous_rad,
                b.e_theta_continuous_rad,
                half_cur.omega_n() / best.omega_n() - 1.0
            ));
        }
    }
    for (k, t) in best.term_list.iter().enumerate() {
        let p = best.x.len();
        let j = 2 + k;
        let se = best.cov[j * p + j].max(0.0).sqrt();
        if opts.base.contains(t)
            && best.x[j] - opts.z * se <= 0.0
            && current.len() > opts.base.len()
        {
            notes.push(format!(
                "the base model's {} is not supported once {} is added: {} = {:.3e} ± {:.3e}",
                t.name(),
                accepted.join(" + "),
                t.symbol(),
                best.x[j],
                opts.z * se
            ));
        }
    }
    let unexplained = unexplained(&d, &best, &env, noise, t_motion_end, &mut notes)?;
    notes.push(format!("decision rule: {DECAY_RULE}"));
    let mut not_separable = vec![
        "the inertia I and the gravity moment m·g·a enter only as omega_n² = m g a / I".to_string(),
        "damping torques enter only per unit inertia (gamma = b_theta/I, T_c/I = c·omega_n², q = a_theta/I)".into(),
    ];
    match opts.rig {
        Some(r) => not_separable.push(format!(
            "with m = {} kg and a = {} m given, I = m g a/omega_n² and the torques follow; this \
             assumes a is the pivot-to-centre-of-mass distance of everything that swings",
            r.m_kg, r.a_m
        )),
        None => not_separable.push(
            "m, a (and so I, T_c, b_theta in SI) are unknown: only the ratios above are reported"
                .into(),
        ),
    }
    if current.contains(&Term::CoulombBearing) || opts.candidates.contains(&Term::CoulombBearing) {
        not_separable.push(
            "coulomb_bearing uses the point-mass bearing load |theta'² + cos theta|; for an arm \
             the true load has m a²/I in front of theta'², and at small swings the load is \
             constant, so it cannot be told from coulomb_constant there"
                .into(),
        );
    }
    notes.push(format!(
        "fits: Levenberg–Marquardt, multiple shooting restarted every {} half swings at the \
         measured turning point; {} fit points (every {}th sample); held-out part {:.3}–{:.3} s \
         simulated in one piece from the turning point at the split",
        d.seg_len, best.n_points, stride, t_split, t_motion_end
    ));
    Ok(DecayDiagnosis {
        samples: t_s.len(),
        duration_s: t_last - t_s[0],
        turning_points: k,
        t_motion_from_s: tps[0].t_s,
        t_motion_to_s: t_motion_end,
        t_split_s: t_split,
        envelope: env,
        period_law: law,
        loss_bands,
        base: base_full,
        candidates,
        accepted,
        best,
        heldout,
        not_separable,
        unexplained,
        notes,
    })
}

/// The rule [`diagnose_decay`] accepts a term by, as the report states it.
pub const DECAY_RULE: &str = "a term is never accepted when the model with it contradicts the \
     measured loss per cycle (in an amplitude band, more than 1.5× above the measured interval's \
     upper end or below its lower end / 1.5, where the model without it was closer); otherwise it \
     is accepted when the first-half fit uses it and either (held-out) its trajectory-fit \
     interval excludes 0 and held-out E_theta falls beyond its noise (and by ≥ 2 %), or \
     (envelope) the envelope resolves it with an interval clear of 0, the trajectory fit's \
     interval overlaps the envelope's, and held-out E_theta gets no worse than its noise";

/// Widening of the measured loss-per-cycle interval before a model contradicts it: the
/// first-order loss curves and the envelope's turning points (parabola-refined, quantised) are
/// not exact, but a model losing 3–14× the measured energy per cycle (issue 16's false quadratic
/// drag) is far outside.
pub const LOSS_BAND_FACTOR: f64 = 1.5;

/// Whether a model contradicts a band's measured loss per cycle: outside the measured interval
/// (mean ± z·se) widened by [`LOSS_BAND_FACTOR`]. Bands of fewer than 3 cycles have no interval.
pub fn loss_band_contradicts(b: &LossBand, model_rad: f64, z: f64) -> bool {
    if b.cycles < 3 || !b.measured_se_rad.is_finite() {
        return false;
    }
    let hi = b.measured_rad + z * b.measured_se_rad;
    let lo = b.measured_rad - z * b.measured_se_rad;
    model_rad > LOSS_BAND_FACTOR * hi || (lo > 0.0 && model_rad < lo / LOSS_BAND_FACTOR)
}

/// The bands where `ext` (the model with a term) contradicts the measured loss per cycle and
/// `cur` (the model without it) did not, or was closer: the term's own contradiction.
fn loss_contradictions(env: &EnvelopeFit, cur: &ModelFit, ext: &ModelFit, z: f64) -> Vec<String> {
    loss_bands(env, cur, ext)
        .iter()
        .filter(|b| {
            loss_band_contradicts(b, b.best_model_rad, z)
                && (!loss_band_contradicts(b, b.base_model_rad, z)
                    || (b.best_model_rad - b.measured_rad).abs()
                        > (b.base_model_rad - b.measured_rad).abs())
        })
        .map(|b| {
            format!(
                "A {:.4}–{:.4} rad: model {:.3e} rad/cycle ({:.1}× the measured {:.3e} ± {:.1e})",
                b.amplitude_from_rad,
                b.amplitude_to_rad,
                b.best_model_rad,
                b.best_model_rad / b.measured_rad,
                b.measured_rad,
                z * b.measured_se_rad
            )
        })
        .collect()
}

/// What the envelope says about one added term.
struct EnvelopeSupport {
    /// The envelope resolves it (interval clear of 0) and its interval overlaps the trajectory
    /// fit's.
    agrees: bool,
    text: String,
}

/// The envelope's catalogue fit for each added loss term (a dry term stands for the other when
/// their loss curves cannot be told apart over the amplitudes seen, unless the other is already
/// in the model or added with it: the envelope's dry loss is then claimed). Empty for a
/// stiffness.
fn envelope_support(
    env: &EnvelopeFit,
    current: &[Term],
    add: &[Term],
    ests: &[Estimate],
) -> Vec<EnvelopeSupport> {
    let claimed = |name: &str| current.iter().chain(add).any(|t| t.name() == name);
    let amps: Vec<f64> = env
        .rows
        .iter()
        .filter_map(|r| r.mid_amplitude_rad)
        .collect();
    let curve = |t: Term| -> Vec<f64> { amps.iter().map(|&a| t.loss_per_cycle(a)).collect() };
    let dry_alike =
        correlation(&curve(Term::CoulombConstant), &curve(Term::CoulombBearing)) > 0.995;
    add.iter()
        .zip(ests)
        .filter(|(t, _)| **t != Term::Stiffness)
        .map(|(&t, e)| {
            let found = env
                .catalogue
                .iter()
                .find(|c| c.name == t.name())
                .or_else(|| {
                    env.catalogue.iter().find(|c| {
                        dry_alike
                            && t.is_dry()
                            && c.name.starts_with("coulomb")
                            && !claimed(&c.name)
                    })
                });
            match found {
                Some(c) => {
                    let resolved = c.ci_low > 0.0;
                    let overlap = c.ci_low <= e.ci_high && e.ci_low <= c.ci_high;
                    EnvelopeSupport {
                        agrees: resolved && overlap,
                        text: format!(
                            "{} {:.3e} {} ({})",
                            c.name,
                            c.estimate,
                            ci(c.ci_low, c.ci_high),
                            match (resolved, overlap) {
                                (true, true) => "resolved, overlaps the trajectory fit",
                                (true, false) => "resolved, but disagrees with the trajectory fit",
                                _ => "not resolved",
                            }
                        ),
                    }
                }
                None => EnvelopeSupport {
                    agrees: false,
                    text: format!("{} not in its best catalogue subset", t.name()),
                },
            }
        })
        .collect()
}

/// Held-out residuals of one model.
#[derive(Debug, Clone)]
struct HeldOut {
    /// Block (half swing) of each sample.
    blocks: Vec<usize>,
    /// Segmented simulation (restarted at measured turning points).
    r: Vec<f64>,
    /// One continuous simulation from the split.
    rc: Vec<f64>,
}

/// One tried extension of the model in hand.
struct Trial {
    add: Vec<Term>,
    full: ModelFit,
    half: ModelFit,
    heldout: HeldOut,
    ok: bool,
    gain: f64,
    noise_gain: f64,
    gain_cont: f64,
    e_cur: f64,
    e_ext: f64,
    delta_bic: f64,
    ests: Vec<Estimate>,
    verdict: String,
}

fn names_of(terms: &[Term]) -> String {
    terms
        .iter()
        .map(|t| t.name())
        .collect::<Vec<_>>()
        .join(" + ")
}

/// Loss per cycle by amplitude band (up to five bands of equal count).
fn loss_bands(env: &EnvelopeFit, base: &ModelFit, best: &ModelFit) -> Vec<LossBand> {
    let pts: Vec<(f64, f64)> = env
        .rows
        .iter()
        .filter_map(|r| Some((r.mid_amplitude_rad?, r.loss_per_cycle_rad?)))
        .collect();
    let amps: Vec<f64> = pts.iter().map(|p| p.0).collect();
    let nb = (pts.len() / 4).clamp(1, 5);
    amplitude_bins_n(&amps, nb)
        .into_iter()
        .filter_map(|(lo, hi)| {
            let sel: Vec<&(f64, f64)> = pts.iter().filter(|p| p.0 >= lo && p.0 <= hi).collect();
            if sel.is_empty() {
                return None;
            }
            let n = sel.len() as f64;
            let a = sel.iter().map(|p| p.0).sum::<f64>() / n;
            let m = sel.iter().map(|p| p.1).sum::<f64>() / n;
            let se = if sel.len() > 1 {
                (sel.iter().map(|p| (p.1 - m).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt()
            } else {
                f64::NAN
            };
            Some(LossBand {
                amplitude_from_rad: lo,
                amplitude_to_rad: hi,
                amplitude_mean_rad: a,
                cycles: sel.len(),
                measured_rad: m,
                measured_se_rad: se,
                base_model_rad: base.loss_per_cycle(a),
                best_model_rad: best.loss_per_cycle(a),
                best_terms: best
                    .term_list
                    .iter()
                    .filter(|&&t| t != Term::Stiffness)
                    .map(|&t| {
                        (
                            t.name().to_string(),
                            best.term_value(t)
                                * t.loss_per_cycle_with(a, best.term_value(Term::Stiffness)),
                        )
                    })
                    .collect(),
            })
        })
        .collect()
}

/// Standard error of Σ(|r_a| − |r_b|) from the scatter of its per-block sums.
fn block_se(ra: &[f64], rb: &[f64], blocks: &[usize]) -> f64 {
    let mut sums: Vec<f64> = Vec::new();
    let mut last = usize::MAX;
    for ((a, b), &bk) in ra.iter().zip(rb).zip(blocks) {
        if bk != last {
            sums.push(0.0);
            last = bk;
        }
        if let Some(s) = sums.last_mut() {
            *s += a.abs() - b.abs();
        }
    }
    let n = sums.len();
    if n < 2 {
        return f64::INFINITY;
    }
    let mean = sums.iter().sum::<f64>() / n as f64;
    let var = sums.iter().map(|s| (s - mean) * (s - mean)).sum::<f64>() / (n - 1) as f64;
    (var * n as f64).sqrt()
}

/// Groups of half swings by amplitude (terciles, or halves with few swings).
fn amplitude_bins(amps: &[f64]) -> Vec<(f64, f64)> {
    amplitude_bins_n(amps, if amps.len() >= 12 { 3 } else { 2 })
}

/// `nb` groups of equal count by amplitude, ascending.
fn amplitude_bins_n(amps: &[f64], nb: usize) -> Vec<(f64, f64)> {
    let mut s: Vec<f64> = amps.to_vec();
    s.sort_by(f64::total_cmp);
    let nb = nb.clamp(1, s.len().max(1));
    (0..nb)
        .map(|b| {
            let lo = s[b * s.len() / nb];
            let hi = s[((b + 1) * s.len() / nb).min(s.len()) - 1];
            (lo, hi)
        })
        .collect()
}

fn unexplained(
    d: &Decay<'_>,
    best: &ModelFit,
    env: &EnvelopeFit,
    noise: f64,
    t_motion_end: f64,
    notes: &mut Vec<String>,
) -> Result<Vec<Unexplained>, DecayError> {
    let mut out = Vec::new();
    let tps = &d.tps;
    // The model's time scale (ω_g: gravity's share when a stiffness is in the model).
    let w = best.omega_g();
    let kappa = best.term_value(Term::Stiffness);
    // 1. Half period against the exact pendulum period at each half swing's amplitude.
    let swings: Vec<(f64, f64, f64)> = tps
        .windows(2)
        .map(|p| {
            let a = 0.5 * (p[0].theta_rad - p[1].theta_rad).abs();
            let tm = p[1].t_s - p[0].t_s;
            let tmod = half_period_units(a, kappa) / w;
            (a, tm / tmod - 1.0, p[0].t_s)
        })
        .collect();
    let amps: Vec<f64> = swings.iter().map(|s| s.0).collect();
    let bins = amplitude_bins(&amps);
    let mut drift_txt = Vec::new();
    for (lo, hi) in &bins {
        let sel: Vec<f64> = swings
            .iter()
            .filter(|s| s.0 >= *lo && s.0 <= *hi)
            .map(|s| s.1)
            .collect();
        if sel.is_empty() {
            continue;
        }
        let n = sel.len() as f64;
        let mean = sel.iter().sum::<f64>() / n;
        drift_txt.push(format!("A {lo:.4}–{hi:.4} rad: {:+.2} %", 100.0 * mean));
    }
    notes.push(format!(
        "half period vs the exact pendulum period (sin θ{}) at the fitted omega_n, by amplitude: {}",
        if kappa > 0.0 { " + kappa θ" } else { "" },
        drift_txt.join("; ")
    ));
    // Reference: the largest third of the swings; scatter from successive differences.
    if swings.len() >= 6 {
        let mut by_amp: Vec<&(f64, f64, f64)> = swings.iter().collect();
        by_amp.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut top: Vec<f64> = by_amp[..swings.len() / 3].iter().map(|s| s.1).collect();
        let r_ref = median(&mut top);
        let mut diffs: Vec<f64> = swings.windows(2).map(|p| (p[1].1 - p[0].1).abs()).collect();
        let sigma = 1.4826 * median(&mut diffs) / std::f64::consts::SQRT_2;
        let thr = (5.0 * sigma).max(0.01);
        // On a staircase of step q a turning point can sit anywhere on the plateau where the
        // swing stays within one step of its extreme, sqrt(2q/A)/omega_n either side: that
        // much of the half period (π/omega_n) is the encoder's, not the restoring torque's.
        let q = env.resolution.step_rad;
        let allowance = |a: f64| (2.0 * q / a.max(1e-300)).sqrt() / std::f64::consts::PI;
        let off: Vec<&(f64, f64, f64)> = swings
            .iter()
            .filter(|s| (s.1 - r_ref).abs() > thr.max(allowance(s.0)))
            .collect();
        if off.len() >= 2 {
            let lo = off.iter().map(|s| s.0).fold(f64::INFINITY, f64::min);
            let hi = off.iter().map(|s| s.0).fold(0.0, f64::max);
            let t0 = off.iter().map(|s| s.2).fold(f64::INFINITY, f64::min);
            let t1 = off.iter().map(|s| s.2).fold(f64::NEG_INFINITY, f64::max);
            let worst = off
                .iter()
                .map(|s| s.1 - r_ref)
                .max_by(|a, b| a.abs().total_cmp(&b.abs()))
                .unwrap_or(0.0);
            let amax = by_amp.first().map_or(0.0, |s| s.0);
            out.push(Unexplained {
                what: "period_drift".into(),
                location: format!(
                    "{} half swings of amplitude {lo:.4}–{hi:.4} rad (t = {t0:.2}–{t1:.2} s)",
                    off.len()
                ),
                magnitude: worst,
                unit: "fraction of the half period".into(),
                detail: format!(
                    "the half period departs from the exact pendulum period (sin θ) by up to \
                     {:+.1} % relative to the largest swings (≤ {amax:.3} rad; scatter {:.2} %): a \
                     restoring torque the model lacks (no catalogue damping term changes the \
                     period like this)",
                    100.0 * worst,
                    100.0 * sigma
                ),
            });
        }
    }

    // 2. Residual structure by amplitude band (best model, multiple shooting, every sample).
    let segs = d.segments(0, t_motion_end, d.seg_len, 1);
    let r = d.residuals(&best.term_list, &best.x, &segs)?;
    let idx: Vec<usize> = segs.iter().flat_map(|s| s.idx.iter().copied()).collect();
    let mut band_txt = Vec::new();
    let mut band_rel = Vec::new();
    for (lo, hi) in &bins {
        let mut ss = 0.0;
        let mut n = 0usize;
        for (&i, v) in idx.iter().zip(&r) {
            let t = d.t[i];
            let k = tps.partition_point(|p| p.t_s <= t);
            if k == 0 || k >= tps.len() {
                continue;
            }
            let a = 0.5 * (tps[k - 1].theta_rad - tps[k].theta_rad).abs();
            if a >= *lo && a <= *hi {
                ss += v * v;
                n += 1;
            }
        }
        if n > 0 {
            let rms = (ss / n as f64).sqrt();
            let mid = 0.5 * (lo + hi);
            band_txt.push(format!(
                "A {lo:.4}–{hi:.4} rad: rms {rms:.2e} rad ({:.1}× noise, {:.2} % of A)",
                rms / noise,
                100.0 * rms / mid
            ));
            band_rel.push((*lo, *hi, rms, rms / mid));
        }
    }
    notes.push(format!(
        "best model's residual by amplitude band: {}",
        band_txt.join("; ")
    ));
    if let (Some(small), Some(large)) = (band_rel.first(), band_rel.last()) {
        if band_rel.len() >= 2 && small.3 > 2.0 * large.3 && small.2 > 5.0 * noise {
            out.push(Unexplained {
                what: "residual_structure".into(),
                location: format!("half swings of amplitude {:.4}–{:.4} rad", small.0, small.1),
                magnitude: small.2,
                unit: "rad (rms)".into(),
                detail: format!(
                    "relative to the amplitude the residual is {:.1}× larger there than at \
                     {:.3}–{:.3} rad ({:.1}× the noise)",
                    small.3 / large.3,
                    large.0,
                    large.1,
                    small.2 / noise
                ),
            });
        }
    }

    // 3. Rest position.
    let t_last = d.t[d.t.len() - 1];
    if t_last - t_motion_end > 2.0 * d.half_s {
        let tail = d.samples(t_motion_end, t_last, 1);
        let quarter = &tail[tail.len() * 3 / 4..];
        let (mn, mx) = quarter
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |a, &i| {
                (a.0.min(d.th[i]), a.1.max(d.th[i]))
            });
        if mx - mn <= (6.0 * noise).max(1e-12) {
            let mut v: Vec<f64> = quarter.iter().map(|&i| d.th[i]).collect();
            let rest = median(&mut v) - best.offset_rad();
            let last = tps.len() - 1;
            let segs = d.single(last, t_last);
            let model = Decay::model(&best.term_list, &best.x);
            let sim = d.simulate(
                &model,
                w,
                segs[0].t0,
                segs[0].theta0 - best.offset_rad(),
                &segs[0].idx,
            )?;
            let rest_model = sim.last().copied().unwrap_or(f64::NAN);
            let band = (best.term_value(Term::CoulombConstant)
                + best.term_value(Term::CoulombBearing))
            .min(1.0)
            .asin();
            let diff = rest - rest_model;
            notes.push(format!(
                "at rest from t ≈ {t_motion_end:.2} s: measured {rest:+.5} rad, model {rest_model:+.5} rad \
                 (from the centre {:.5} rad); dry-friction dead band ±{band:.5} rad",
                best.offset_rad()
            ));
            let last_tp = tps[last].theta_rad - best.offset_rad();
            if diff.abs() > (5.0 * noise).max(0.25 * band) {
                let crept = rest - last_tp;
                out.push(Unexplained {
                    what: "rest_position".into(),
                    location: format!("after the last swing (t > {:.2} s)", tps[last].t_s),
                    magnitude: diff,
                    unit: "rad".into(),
                    detail: format!(
                        "the pendulum comes to rest at {rest:+.5} rad but the model stops at \
                         {rest_model:+.5} rad; after its last turning point ({last_tp:+.5} rad) it \
                         moved {crept:+.5} rad{}",
                        if band > 0.0 && rest.abs() < band {
                            " inside the dead band, where the dry-friction model cannot move (micro-slip, pre-sliding?)"
                        } else {
                            ""
                        }
                    ),
                });
            }
        }
    }

    // 4. Envelope misfit: the best model's loss per cycle against the measured one.
    let pts: Vec<(f64, f64)> = env
        .rows
        .iter()
        .filter_map(|r| Some((r.mid_amplitude_rad?, r.loss_per_cycle_rad?)))
        .collect();
    if pts.len() >= 4 {
        // With the stiffness the model has (the loss curves depend on the potential).
        let pred = |a: f64| -> f64 { best.loss_per_cycle(a) };
        let res: Vec<f64> = pts.iter().map(|p| p.1 - pred(p.0)).collect();
        let n = res.len() as f64;
        let sd = (res.iter().map(|v| v * v).sum::<f64>() / n).sqrt();
        // Runs of one sign at the small- or large-amplitude end.
        let mut order: Vec<usize> = (0..pts.len()).collect();
        order.sort_by(|&a, &b| pts[a].0.total_cmp(&pts[b].0));
        let m = (pts.len() / 3).max(2);
        for (label, sel) in [
            ("smallest", &order[..m]),
            ("largest", &order[order.len() - m..]),
        ] {
            let mean = sel.iter().map(|&i| res[i]).sum::<f64>() / m as f64;
            let se = sd / (m as f64).sqrt();
            let lo = sel.iter().map(|&i| pts[i].0).fold(f64::INFINITY, f64::min);
            let hi = sel.iter().map(|&i| pts[i].0).fold(0.0, f64::max);
            let level = sel.iter().map(|&i| pts[i].1).sum::<f64>() / m as f64;
            if mean.abs() > 3.0 * se && mean.abs() > 0.1 * level.abs() {
                out.push(Unexplained {
                    what: "envelope_misfit".into(),
                    location: format!("the {label} swings, amplitude {lo:.4}–{hi:.4} rad"),
                    magnitude: mean,
                    unit: "rad per cycle".into(),
                    detail: format!(
                        "the model's loss per cycle is {} than measured by {:.2e} rad ({:.0} % of \
                         {:.2e})",
                        if mean > 0.0 { "smaller" } else { "larger" },
                        mean.abs(),
                        100.0 * mean.abs() / level.abs(),
                        level
                    ),
                });
            }
        }
    }
    Ok(out)
}

// ---------------------------------------------------------------------------------------------
// Display
// ---------------------------------------------------------------------------------------------

fn ci(lo: f64, hi: f64) -> String {
    format!("[{lo:.3e}, {hi:.3e}]")
}

impl fmt::Display for DecayDiagnosis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let e = &self.envelope;
        let a0 = e.rows.first().map_or(f64::NAN, |r| r.amplitude_rad);
        let a1 = e.rows.last().map_or(f64::NAN, |r| r.amplitude_rad);
        writeln!(
            f,
            "free decay: {} samples over {:.2} s; {} turning points, amplitude {a0:.4} → {a1:.4} rad; \
             motion {:.2}–{:.2} s, fits on the swings before {:.2} s, held out after",
            self.samples,
            self.duration_s,
            self.turning_points,
            self.t_motion_from_s,
            self.t_motion_to_s,
            self.t_split_s
        )?;
        writeln!(
            f,
            "omega_n = {:.5} rad/s (small-swing period {:.5} s), centre {:+.5} rad, noise {:.1e} rad",
            self.best.omega_n(),
            std::f64::consts::TAU / self.best.omega_n(),
            self.best.offset_rad(),
            e.noise_rad
        )?;
        writeln!(f, "{}", e.resolution.describe())?;
        let poly: Vec<String> = e
            .polynomial
            .iter()
            .map(|c| {
                format!(
                    "{} = {:.3e} {}{}",
                    c.name,
                    c.estimate,
                    ci(c.ci_low, c.ci_high),
                    if c.significant { "*" } else { "" }
                )
            })
            .collect();
        writeln!(
            f,
            "envelope: loss/cycle = c0 + c1·A + c2·A²: {}",
            poly.join(", ")
        )?;
        let best_poly: Vec<&str> = e.polynomial_best.iter().map(|c| c.name.as_str()).collect();
        writeln!(f, "  best subset {{{}}}: {}", best_poly.join(", "), e.shape)?;
        let cat: Vec<String> = e
            .catalogue
            .iter()
            .map(|c| format!("{} {:.3e} {}", c.name, c.estimate, ci(c.ci_low, c.ci_high)))
            .collect();
        writeln!(
            f,
            "  as catalogue terms (exact pendulum): {}",
            cat.join(", ")
        )?;
        writeln!(
            f,
            "{:>17} {:>7} {:>12} {:>12} {:>12}  best model's terms",
            "amplitude, rad", "cycles", "measured", "base model", "best model"
        )?;
        for b in &self.loss_bands {
            let terms: Vec<String> = b
                .best_terms
                .iter()
                .map(|(n, v)| format!("{n} {v:.2e}"))
                .collect();
            writeln!(
                f,
                "{:>8.4}–{:<8.4} {:>7} {:>12.3e} {:>12.3e} {:>12.3e}  {}",
                b.amplitude_from_rad,
                b.amplitude_to_rad,
                b.cycles,
                b.measured_rad,
                b.base_model_rad,
                b.best_model_rad,
                terms.join(", ")
            )?;
        }
        if let Some(l) = &self.period_law {
            writeln!(f, "{}", l.describe())?;
        }
        writeln!(f, "decision rule: {DECAY_RULE}")?;
        writeln!(
            f,
            "{:<2} {:<18} {:<34} {:>11} {:>24} {:>6} {:>9} {:>7} {:>9} {:>8}",
            "rd",
            "term",
            "added to (+ together with)",
            "estimate",
            "95 % CI",
            "unit",
            "held-out",
            "noise",
            "ΔBIC",
            "accepted"
        )?;
        for c in &self.candidates {
            let mut to = c.added_to.join("+");
            if !c.together_with.is_empty() {
                to = format!("{to} (+{})", c.together_with.join("+"));
            }
            writeln!(
                f,
                "{:<2} {:<18} {:<34} {:>11.4e} {:>24} {:>6} {:>8.1}% {:>6.1}% {:>9.1} {:>8}",
                c.round,
                c.term,
                to,
                c.estimate,
                ci(c.ci_low, c.ci_high),
                c.unit,
                100.0 * c.heldout_gain,
                100.0 * c.heldout_noise,
                c.delta_bic,
                if c.accepted { "yes" } else { "no" }
            )?;
            writeln!(f, "   {}", c.verdict)?;
        }
        for h in &self.heldout {
            writeln!(
                f,
                "held-out E_theta {:<52} {:>10.4} rad ({:.2e} rad/sample; in one piece {:.4} rad)",
                h.model, h.e_theta_rad, h.mean_abs_rad, h.e_theta_continuous_rad
            )?;
        }
        writeln!(f, "best model: {}", self.best.terms.join(" + "))?;
        for p in self.best.params.iter().chain(&self.best.physical) {
            writeln!(
                f,
                "  {:<44} {:>11.4e} {} {}",
                p.name,
                p.estimate,
                ci(p.ci_low, p.ci_high),
                p.unit
            )?;
        }
        for u in &self.unexplained {
            writeln!(f, "unexplained {} — {}: {}", u.what, u.location, u.detail)?;
        }
        if self.unexplained.is_empty() {
            writeln!(f, "unexplained: nothing beyond the noise")?;
        }
        for n in &self.not_separable {
            writeln!(f, "not separable: {n}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The decay's terms are the catalogue's: every effect that defines how it shows in a free
    /// decay is a term (in catalogue order), and every term but the stiffness (a departure) is
    /// such an effect.
    #[test]
    fn decay_terms_are_the_catalogues() {
        let from_catalogue: Vec<&str> = pendulum_model::CATALOGUE
            .iter()
            .filter(|e| e.free_decay().is_some())
            .map(|e| e.name())
            .collect();
        let mut terms: Vec<&str> = Term::ALL.iter().map(|t| t.name()).collect();
        let order = |n: &&str| from_catalogue.iter().position(|c| c == n);
        terms.sort_by_key(order);
        assert_eq!(terms, from_catalogue);
        assert!(pendulum_model::effects::by_name(Term::Stiffness.name()).is_none());
        assert_eq!(Term::Stiffness.symbol(), "kappa");
        assert!(Term::CoulombConstant.is_dry() && Term::CoulombBearing.is_dry());
        assert!(!Term::ViscousLinear.is_dry() && !Term::Stiffness.is_dry());
    }

    #[test]
    fn loss_curves_match_small_amplitude_limits() {
        let a = 1e-3;
        assert!((Term::CoulombConstant.loss_per_cycle(a) - 4.0).abs() < 1e-5);
        assert!((Term::CoulombBearing.loss_per_cycle(a) - 4.0).abs() < 1e-4);
        let v = Term::ViscousLinear.loss_per_cycle(a) / a;
        assert!((v - std::f64::consts::PI).abs() < 1e-4, "{v}");
        let q = Term::ViscousQuadratic.loss_per_cycle(a) / (a * a);
        assert!((q - 8.0 / 3.0).abs() < 1e-3, "{q}");
        // Dry friction of a pendulum at large amplitude: 4A/sin A per cycle.
        let big = 1.5;
        let exact = 4.0 * big / f64::sin(big);
        assert!((Term::CoulombConstant.loss_per_cycle(big) - exact).abs() < 1e-6 * exact);
    }

    #[test]
    fn elliptic_period() {
        assert!((half_period_factor(1e-6) - std::f64::consts::PI).abs() < 1e-9);
        // T/T0 at 90°: 1.18034
        let r = half_period_factor(std::f64::consts::FRAC_PI_2) / std::f64::consts::PI;
        assert!((r - 1.180341).abs() < 1e-5, "{r}");
    }

    #[test]
    fn turning_points_of_a_quantised_cosine() {
        let q = std::f64::consts::TAU / 40000.0;
        let t: Vec<f64> = (0..5000).map(|i| i as f64 * 1e-3).collect();
        let th: Vec<f64> = t
            .iter()
            .map(|&t| {
                let v = 0.05 * (8.0 * t).cos() * (-0.1 * t).exp();
                (v / q).floor() * q + 0.5 * q
            })
            .collect();
        let tps = turning_points(&t, &th);
        assert!(tps.len() >= 9, "{}", tps.len());
        for p in &tps {
            let k = (p.t_s * 8.0 / std::f64::consts::PI).round();
            let t_true = k * std::f64::consts::PI / 8.0;
            // exact extrema of the damped cosine are shifted by atan(0.1/8)/8
            assert!((p.t_s - t_true).abs() < 4e-3, "{} vs {}", p.t_s, t_true);
            let a = 0.05 * (-0.1 * p.t_s).exp();
            assert!(
                (p.theta_rad.abs() - a).abs() < 1.5e-4,
                "{} vs {a}",
                p.theta_rad
            );
        }
    }

    /// A free decay from the model's simulator (exact stick/slip), released at rest from
    /// `theta0` and sampled at `fs_hz`.
    fn model_decay(
        d: Dimensionless,
        omega_g: f64,
        theta0: f64,
        duration_s: f64,
        fs_hz: f64,
    ) -> (Vec<f64>, Vec<f64>) {
        let model = Model::with_excitation(d, Excitation::None);
        let n = (duration_s * fs_hz) as usize;
        let t: Vec<f64> = (0..n).map(|i| i as f64 / fs_hz).collect();
        let mut th = Vec::with_capacity(n);
        integrate(
            &model,
            &SimOptions {
                rtol: 1e-10,
                atol: 1e-10,
                ..SimOptions::default()
            },
            0.0,
            [theta0, 0.0],
            t[n - 1] * omega_g * (1.0 + 1e-12),
            t.iter().map(|&x| x * omega_g),
            |s| {
                th.push(s.theta);
                ControlFlow::Continue(())
            },
        )
        .unwrap();
        assert_eq!(th.len(), n);
        (t, th)
    }

    /// Issue 16's recording, as a twin: the decay law's viscous ζ = 0.0056 (β = 2ζ = 0.0112)
    /// and 5·10⁻⁴ rad of dry loss per half cycle (c = 2.5e-4 rad), so the decay is exponential at
    /// large swings and linear below ~2° (πβA and 4c cross at A = 4c/(πβ) = 0.028 rad);
    /// ω_n = 6 rad/s, released from 0.35 rad, 90 s at 150 Hz (the thesis' rate), read through a
    /// 4096-count encoder whose zero creeps ±2 counts (3e-3 rad) over 23 s (a cable relaxing, a
    /// stand warming: what real records have and twins lack). The creep barely touches the loss
    /// per cycle (it alternates in sign from maxima to minima) but dominates the held-out
    /// residuals at the last swings, where the dry loss shows: the held-out rule's noise
    /// (3.7 %) then exceeds the dry term's effect on E_theta, as on the issue's recording.
    fn viscous_dry_twin() -> (Vec<f64>, Vec<f64>, f64, f64) {
        let (beta, c) = (0.0112, 2.5e-4);
        let d = Dimensionless {
            beta,
            c,
            ..Dimensionless::conservative()
        };
        let (t, th) = model_decay(d, 6.0, 0.35, 90.0, 150.0);
        let q = std::f64::consts::TAU / 4096.0;
        let th = t
            .iter()
            .zip(&th)
            .map(|(t, v)| {
                let creep = 3e-3 * (std::f64::consts::TAU * t / 23.0).sin();
                ((v + creep) / q).floor() * q
            })
            .collect();
        (t, th, beta, c)
    }

    fn linear_base() -> DecayOptions {
        // `discover --base linear` on a free decay: viscous in hand, the others screened.
        DecayOptions {
            base: vec![Term::ViscousLinear],
            resolution_rad: Some(std::f64::consts::TAU / 4096.0),
            ..DecayOptions::default()
        }
    }

    /// Issue 16 item 1: the envelope resolves dry friction + viscous with intervals clear of
    /// zero, so on the linear base the dry term is accepted (it was rejected by a held-out rule
    /// whose noise exceeded the effect) and viscous is kept, both estimates within their
    /// intervals of the truth, and the report states the rule and each view's evidence.
    #[test]
    fn regression_issue_16_dry_named_with_the_envelope_on_linear_base() {
        let (t, th, beta, c) = viscous_dry_twin();
        let d = diagnose_decay(&t, &th, &linear_base()).unwrap();
        let text = d.to_string();
        eprintln!("{text}");
        let env_dry = d
            .envelope
            .catalogue
            .iter()
            .find(|k| k.name == "coulomb_constant" || k.name == "coulomb_bearing")
            .unwrap_or_else(|| panic!("the envelope does not see the dry loss:\n{text}"));
        assert!(env_dry.ci_low > 0.0, "{env_dry:?}");
        assert!(
            env_dry.ci_low <= c && c <= env_dry.ci_high,
            "the envelope's dry loss {env_dry:?} misses the truth {c}"
        );
        assert!(
            d.is_accepted(Term::CoulombConstant),
            "dry friction not named:\n{text}"
        );
        assert_eq!(
            d.best.terms,
            ["viscous_linear", "coulomb_constant"],
            "{text}"
        );
        // Viscous kept (its interval clear of 0, which it was not on the issue's recording);
        // the trajectory fit's dry interval is wide (the creep), the envelope's is not.
        let e = d.best.params.iter().find(|p| p.name == "beta").unwrap();
        assert!(e.ci_low > 0.0, "beta's interval includes 0: {e:?}");
        for (symbol, truth) in [("beta", beta), ("c", c)] {
            let e = d.best.params.iter().find(|p| p.name == symbol).unwrap();
            assert!(
                e.ci_low <= truth && truth <= e.ci_high,
                "{symbol} = {} [{}, {}] misses the truth {truth}",
                e.estimate,
                e.ci_low,
                e.ci_high
            );
        }
        let cand = d.candidate(Term::CoulombConstant).unwrap();
        // The held-out rule alone would reject it (the issue's −4.7 % against a noise of 7.1 %):
        // the envelope's view accepts it.
        assert!(
            cand.heldout_gain <= cand.heldout_noise,
            "the held-out rule alone accepts it here: {}",
            cand.verdict
        );
        assert!(
            cand.verdict.contains("the envelope resolves it"),
            "{}",
            cand.verdict
        );
        assert!(cand.verdict.contains("envelope: "), "{}", cand.verdict);
        assert!(cand.verdict.contains("loss per cycle"), "{}", cand.verdict);
        assert!(text.contains(DECAY_RULE), "{text}");
    }

    /// Issue 16 item 1: nothing accepted loses energy per cycle the pendulum does not. Every
    /// accepted model's loss per cycle stays inside each amplitude band's measured interval
    /// (mean ± 1.96·se) widened by `LOSS_BAND_FACTOR` = 1.5, and a quadratic drag like the
    /// issue's false one (α = 0.25, the decay law's ~0.003 × 100) added to the fitted model is a
    /// contradiction of its own (it loses several times the measured energy per cycle at the
    /// large swings), so no held-out gain can make it accepted.
    #[test]
    fn regression_issue_16_accepted_loss_within_measured_bands() {
        let (t, th, _, _) = viscous_dry_twin();
        let opts = linear_base();
        let d = diagnose_decay(&t, &th, &opts).unwrap();
        assert!(d.loss_bands.len() >= 3, "{d}");
        for b in &d.loss_bands {
            eprintln!(
                "A {:.4}–{:.4}: measured {:.3e} ± {:.1e}, best {:.3e}",
                b.amplitude_from_rad,
                b.amplitude_to_rad,
                b.measured_rad,
                opts.z * b.measured_se_rad,
                b.best_model_rad
            );
            assert!(
                !loss_band_contradicts(b, b.best_model_rad, opts.z),
                "the accepted model {:?} contradicts the band {b:?}",
                d.best.terms
            );
        }
        for c in d.candidates.iter().filter(|c| c.accepted) {
            assert!(!c.verdict.contains("contradicts"), "{}", c.verdict);
        }
        let mut false_drag = d.best.clone();
        false_drag.term_list.push(Term::ViscousQuadratic);
        false_drag.x.push(0.25);
        let bad = loss_contradictions(&d.envelope, &d.best, &false_drag, opts.z);
        eprintln!("{bad:?}");
        assert!(
            !bad.is_empty(),
            "a quadratic drag of 0.25 passes the loss check"
        );
        let worst = loss_bands(&d.envelope, &d.best, &false_drag)
            .iter()
            .map(|b| b.best_model_rad / b.measured_rad)
            .fold(0.0, f64::max);
        assert!(
            worst > 3.0,
            "the false drag loses only {worst:.2}× the measured"
        );
    }

    /// A free decay θ'' = −ω_g² sin θ − (k/I) θ − γ θ' by classical RK4 (its own integrator, not
    /// the model's: the reference for the stiffness test), 10 steps per sample at `fs_hz`,
    /// read through a 4096-count encoder.
    fn rk4_spring_decay(
        omega_g: f64,
        k_over_i: f64,
        gamma: f64,
        theta0: f64,
        duration_s: f64,
        fs_hz: f64,
    ) -> (Vec<f64>, Vec<f64>) {
        let f =
            |th: f64, w: f64| -> f64 { -omega_g * omega_g * th.sin() - k_over_i * th - gamma * w };
        let q = std::f64::consts::TAU / 4096.0;
        let n = (duration_s * fs_hz) as usize;
        let h = 1.0 / (10.0 * fs_hz);
        let (mut th, mut w) = (theta0, 0.0);
        let mut t_out = Vec::with_capacity(n);
        let mut th_out = Vec::with_capacity(n);
        for i in 0..n {
            t_out.push(i as f64 / fs_hz);
            th_out.push((th / q).floor() * q);
            for _ in 0..10 {
                let (k1t, k1w) = (w, f(th, w));
                let (k2t, k2w) = (w + 0.5 * h * k1w, f(th + 0.5 * h * k1t, w + 0.5 * h * k1w));
                let (k3t, k3w) = (w + 0.5 * h * k2w, f(th + 0.5 * h * k2t, w + 0.5 * h * k2w));
                let (k4t, k4w) = (w + h * k3w, f(th + h * k3t, w + h * k3w));
                th += h / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t);
                w += h / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w);
            }
        }
        (t_out, th_out)
    }

    #[test]
    fn half_period_with_stiffness() {
        for a in [0.01, 0.5, 1.5, 2.5] {
            assert!((half_period_units(a, 0.0) - half_period_mix(a, 1.0)).abs() < 1e-9);
            assert!((half_period_mix(a, 0.0) - std::f64::consts::PI).abs() < 1e-9);
        }
        // Small swings: π/√(1 + κ) in units of 1/ω_g.
        let k = 3.0;
        assert!((half_period_units(1e-4, k) - std::f64::consts::PI / 2.0).abs() < 1e-6);
    }

    /// Issue 16 item 5: a pendulum with a torsion spring as stiff as gravity (κ = k/(m g a) = 1,
    /// so half its small-swing stiffness is the spring's), and one dominated by its spring
    /// (κ = 5), released from 1.2 rad: the period lengthens with amplitude 1/(1 + κ) as much as
    /// gravity alone would make it, the stiffness is named with κ within 10 %, and the period
    /// drift it left unexplained is gone. A plain gravity pendulum
    /// (the same run without the spring) gets nothing named, the stiffness not even tried.
    /// Issue 16: swings of a few hundredths of a radian cannot tell gravity from a spring by
    /// their periods (the amplitude dependence ∝ A² is below the timing noise); the period law
    /// says so instead of printing an interval of u over all of [0, 1]. Large swings of the same
    /// pendulum determine it and find the gravity law.
    #[test]
    fn regression_issue_16_period_law_of_small_swings_is_undetermined() {
        let (omega_g, gamma) = (5.0, 0.02);
        let opts = DecayOptions {
            resolution_rad: Some(std::f64::consts::TAU / 4096.0),
            ..DecayOptions::default()
        };
        for (a0, want_determined) in [(0.12, false), (1.5, true)] {
            let (t, th) = rk4_spring_decay(omega_g, 0.0, gamma, a0, 30.0, 200.0);
            let d = diagnose_decay(&t, &th, &opts).unwrap();
            let law = d.period_law.as_ref().expect("no period law");
            assert_eq!(
                law.determined,
                want_determined,
                "A0 = {a0}: {}",
                law.describe()
            );
            assert!(!law.departs, "A0 = {a0}: {}", law.describe());
            if !want_determined {
                assert!(
                    law.describe().contains("undetermined"),
                    "{}",
                    law.describe()
                );
            }
        }
    }

    #[test]
    fn regression_issue_16_torsion_spring_named_as_stiffness() {
        let (omega_g, gamma) = (5.0, 0.08);
        let opts = DecayOptions {
            resolution_rad: Some(std::f64::consts::TAU / 4096.0),
            ..DecayOptions::default()
        };
        for kappa in [1.0, 5.0] {
            let (t, th) =
                rk4_spring_decay(omega_g, kappa * omega_g * omega_g, gamma, 1.2, 30.0, 200.0);
            let d = diagnose_decay(&t, &th, &opts).unwrap();
            let text = d.to_string();
            eprintln!("{text}");
            let law = d.period_law.as_ref().expect("no period law");
            assert!(law.departs, "{}", law.describe());
            assert!(
                d.is_accepted(Term::Stiffness),
                "stiffness not named:\n{text}"
            );
            let k_est = d.best.term_value(Term::Stiffness);
            assert!(
                (k_est / kappa - 1.0).abs() < 0.10,
                "kappa {k_est} vs the truth {kappa}"
            );
            let wn = omega_g * (1.0 + kappa).sqrt();
            assert!(
                (d.best.omega_n() / wn - 1.0).abs() < 0.01,
                "{} vs {wn}",
                d.best.omega_n()
            );
            // Nothing left over: no period drift, and the loss per cycle of the spring-loaded
            // potential (not gravity's) matches the envelope.
            assert!(d.unexplained.is_empty(), "{:?}", d.unexplained);
        }

        let (t, th) = rk4_spring_decay(omega_g, 0.0, gamma, 1.2, 30.0, 200.0);
        let d = diagnose_decay(&t, &th, &opts).unwrap();
        let text = d.to_string();
        eprintln!("{text}");
        assert!(d.accepted.is_empty(), "named {:?}:\n{text}", d.accepted);
        assert!(
            !d.candidates.iter().any(|c| c.term == "stiffness"),
            "stiffness tried on a gravity pendulum:\n{text}"
        );
        assert!(!d.period_law.as_ref().is_some_and(|l| l.departs), "{text}");
    }

    /// Issue 16 item 2: a 12-bit encoder logged in degrees to 0.01° (steps of 0.08° and 0.09°,
    /// not multiples of one quantum) that decays to rest. The noise floor is the quantiser's
    /// (it was 1e-12: at rest the second differences are all 0), no swing under 3 steps is
    /// analysed, and the stated resolution is used when given.
    #[test]
    fn regression_issue_16_noise_floor_and_three_step_rule() {
        let q = std::f64::consts::TAU / 4096.0;
        let t: Vec<f64> = (0..30_000).map(|i| i as f64 * 2e-3).collect();
        let th: Vec<f64> = t
            .iter()
            .map(|&t| {
                let v = 0.3 * (-0.15 * t).exp() * (6.0 * t).cos();
                let deg = ((v / q).floor() * q).to_degrees();
                ((deg * 100.0).round() / 100.0).to_radians()
            })
            .collect();
        for stated in [None, Some(q)] {
            let (tps, res) = turning_points_with(&t, &th, stated);
            assert!(
                (res.step_rad / q - 1.0).abs() < 0.1,
                "{stated:?}: step {} vs {q}",
                res.step_rad
            );
            assert!(
                res.ended_at_s.is_some() && res.dropped_turning_points > 0,
                "{res:?}"
            );
            for w in tps.windows(2) {
                let swing = 0.5 * (w[1].theta_rad - w[0].theta_rad).abs();
                assert!(
                    swing >= MIN_SWING_STEPS * res.step_rad,
                    "{swing} at {}",
                    w[0].t_s
                );
            }
            let d = diagnose_decay(
                &t,
                &th,
                &DecayOptions {
                    resolution_rad: stated,
                    candidates: vec![],
                    ..DecayOptions::default()
                },
            )
            .unwrap();
            assert!(d.envelope.noise_rad >= res.step_rad / 12f64.sqrt() * (1.0 - 1e-12));
            let text = d.to_string();
            assert!(text.contains("the resolution ended the analysis"), "{text}");
            assert!(!text.contains("noise 1.0e-12"), "{text}");
        }
    }

    /// Issue 16 item 2: a dry-friction decay on a 4096-count encoder whose last half swing,
    /// 2.25 counts, never closes into a turning point (the hysteresis needs 3 counts back): the
    /// swings between the turning points found are all above 3 counts, yet the resolution ended
    /// the analysis, and the report says where (it said "every swing found is above it").
    #[test]
    fn regression_issue_16_resolution_ends_at_an_unclosed_last_swing() {
        let q = std::f64::consts::TAU / 4096.0;
        // Turning points of a decay losing 1.5 counts per half swing: 12, 10.5, …, 3, 1.5.
        let amps: Vec<f64> = (0..8).map(|k| (12.0 - 1.5 * k as f64) * q).collect();
        let fs = 1000.0;
        let (mut t, mut th) = (Vec::new(), Vec::new());
        let push = |t: &mut Vec<f64>, th: &mut Vec<f64>, v: f64| {
            t.push(t.len() as f64 / fs);
            th.push((v / q).floor() * q);
        };
        for _ in 0..300 {
            push(&mut t, &mut th, amps[0]);
        }
        for k in 0..amps.len() - 1 {
            let (a, b) = (
                amps[k] * if k % 2 == 0 { 1.0 } else { -1.0 },
                amps[k + 1] * if k % 2 == 0 { -1.0 } else { 1.0 },
            );
            for i in 0..500 {
                let s = i as f64 / 500.0;
                let v = 0.5 * (a + b) + 0.5 * (a - b) * (std::f64::consts::PI * s).cos();
                push(&mut t, &mut th, v);
            }
        }
        let rest = *amps.last().unwrap() * -1.0;
        for _ in 0..3000 {
            push(&mut t, &mut th, rest);
        }
        let env = envelope_with(&t, &th, Some(q)).expect("envelope");
        let r = &env.resolution;
        eprintln!("{}", r.describe());
        let ended = r.ended_at_s.expect("the resolution ended the analysis");
        // At the last turning point found, +3 counts at 3.3 s: the swing after it is 2.25.
        assert!((ended - 3.3).abs() < 0.05, "ended at {ended} s");
        let next = r.ended_swing_rad.expect("the swing that ended it") / q;
        assert!((next - 2.25).abs() < 0.6, "{next} counts");
        assert!(
            r.describe()
                .contains("the resolution ended the analysis at t ="),
            "{}",
            r.describe()
        );
    }
}
