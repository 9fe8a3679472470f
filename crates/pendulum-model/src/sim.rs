//! The simulator: Dormand–Prince 5(4) with its 4th-order dense output, and Coulomb friction as
//! the hybrid stick/slip system of `effects.md`.
//!
//! Why our own integrator: the state has two components and the right-hand side costs ~10 ns, so
//! generic solver overhead dominates (`notes/crates.md`: 170–190 ns/step for a crate's DOPRI5 vs
//! ~45 ns for a hand RK4 step). The stick/slip logic also needs to own the step loop.
//!
//! Hybrid system: while slipping in direction d = ±1 the friction term is
//! (M·N + c + s·e^{−(θ̇/v)²})·d, a smooth right-hand side; the event θ̇ = 0 is located on the dense
//! output. At the event the applied torque Q (everything but friction, at θ̇ = 0) is compared with
//! the static capacity C = M·N + c + s: |Q| ≤ C → stick (θ̇ = 0 exactly, θ fixed) until
//! |Q(t)| > C(t); otherwise slip in direction sgn Q.
//!
//! A generator behind a rectifier, g·(|θ̇| − w)⁺ sgn θ̇, is a second switching surface, |θ̇| = w:
//! the torque is continuous there but its slope is not, and a step straddling the kink loses
//! DOPRI5's order (its error estimate no longer measures its error). So it is handled like
//! θ̇ = 0: within a step the generator is in a fixed mode (off, or on on one side, where its term
//! is the smooth g·(θ̇ ∓ w)), and a step that ends on the other side of the surface is cut at the
//! crossing, located on the dense output.

use std::ops::ControlFlow;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::excitation::CrankTable;
use crate::{Dimensionless, Excitation, ModelError};

/// A model ready to integrate: parameters plus what drives the base.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Model {
    pub params: Dimensionless,
    pub excitation: Excitation,
    /// Tabulated crank geometry (see [`Model::with_crank_table`]); used only while it matches
    /// the crank's λ.
    #[serde(skip)]
    pub crank_table: Option<Arc<CrankTable>>,
}

impl Model {
    /// The dimensionless model driven by its own constant-speed crank (φ = ωt).
    pub fn new(params: Dimensionless) -> Self {
        Self {
            excitation: Excitation::from_dimensionless(&params),
            params,
            crank_table: None,
        }
    }

    /// The model of `phys` in the clock its captures are aligned on (t = 0 at the accelerometer's
    /// peak), through the shared sensor transform ([`crate::Sensors`]): with `accel_delay` the
    /// accelerometer lags, so the true forcing leads that clock by Δ. Fit, discover and replay
    /// all build their models here ([`Model::new`] alone would drop the delay).
    pub fn measured(phys: &crate::Physical) -> Self {
        let d = phys.to_dimensionless();
        let mut m = Model::new(d);
        if let Excitation::Crank(c) = &mut m.excitation {
            c.phi0 = crate::Sensors::of(phys).forcing_lead_rad(d.omega, phys.omega0_rad_s());
        }
        m
    }

    /// Same parameters, another excitation.
    pub fn with_excitation(params: Dimensionless, excitation: Excitation) -> Self {
        Self {
            params,
            excitation,
            crank_table: None,
        }
    }

    /// Evaluates a crank excitation from the shared [`CrankTable`] of its λ instead of the exact
    /// formula (errors below 1e-13, a third cheaper right-hand side); no effect otherwise.
    pub fn with_crank_table(mut self) -> Self {
        if let Excitation::Crank(c) = &self.excitation {
            self.crank_table = Some(CrankTable::shared(c.lambda));
        }
        self
    }

    /// Base accelerations (ÿ/g, ẍ/g) at time t.
    #[inline(always)]
    fn base_accel(&self, t: f64) -> (f64, f64) {
        match (&self.excitation, &self.crank_table) {
            (Excitation::Crank(c), Some(tab)) if tab.lambda() == c.lambda => {
                c.accel_tabulated(tab, t)
            }
            (e, _) => e.accel(t),
        }
    }

    fn has_dry_friction(&self) -> bool {
        let p = &self.params;
        p.m_coulomb > 0.0 || p.c > 0.0 || p.s_break > 0.0 || p.c_rate > 0.0 || p.c_lobes > 0.0
    }

    /// Non-friction torque at rest, Q, and the static friction capacity C, at (t, θ).
    #[inline]
    pub fn static_balance(&self, t: f64, theta: f64) -> (f64, f64) {
        let p = &self.params;
        let (ay, ax) = self.base_accel(t);
        let (s, c) = sin_cos(theta);
        let mut q = -(1.0 + ay) * s - ax * c;
        if p.p != 0.0 {
            q -= p.p * (p.k as f64 * theta + p.phi_p).sin();
        }
        q -= p.kappa * p.spring_stretch(theta);
        let load = if p.base_load {
            ((1.0 + ay) * c - ax * s).abs()
        } else {
            c.abs()
        };
        // At rest the fading dry torque holds with its full size s.
        (
            q,
            p.m_coulomb * load + p.c + p.c_rate * t + p.s_break + p.lobed_dry(theta),
        )
    }

    /// The generator's mode at θ̇: ±1 on (beyond the dead band on that side), 0 off (inside it).
    /// Without a dead band (w = 0) its term g·θ̇ is smooth: always "on" with sign 1.
    #[inline]
    pub fn gen_mode(&self, theta_dot: f64) -> f64 {
        let w = self.params.gen_w;
        if w == 0.0 || theta_dot > w {
            1.0
        } else if theta_dot < -w {
            -1.0
        } else {
            0.0
        }
    }

    /// θ̈ while slipping in direction `dir` (±1; 0 when there is no dry friction).
    #[inline]
    pub fn accel(&self, t: f64, theta: f64, theta_dot: f64, dir: f64) -> f64 {
        // The mode only matters with a generator; most models have none (and RK4 baselines
        // call this per stage).
        let gen = if self.params.gen_c != 0.0 {
            self.gen_mode(theta_dot)
        } else {
            0.0
        };
        self.accel_in::<true, true>(t, theta, theta_dot, dir, gen)
    }

    /// θ̈ with the generator held in mode `gen` ([`Model::gen_mode`]): the integrator's smooth
    /// right-hand side within a step. `STRIBECK` / `RARE` false compile the breakaway / the
    /// generator and the departures' drags out (chosen once per integration from the coefficients, see [`integrate`]); true keeps
    /// the run-time test of the coefficient, so `<true, true>` is right for every model.
    #[inline(always)]
    fn accel_in<const STRIBECK: bool, const RARE: bool>(
        &self,
        t: f64,
        theta: f64,
        theta_dot: f64,
        dir: f64,
        gen: f64,
    ) -> f64 {
        let p = &self.params;
        let (ay, ax) = self.base_accel(t);
        let (s, c) = sin_cos(theta);
        let w2 = theta_dot * theta_dot;
        let mut q =
            -(1.0 + ay) * s - ax * c - p.beta * theta_dot - p.alpha * theta_dot * theta_dot.abs();
        if dir != 0.0 {
            let load = if p.base_load {
                (w2 + (1.0 + ay) * c - ax * s).abs()
            } else {
                (w2 + c).abs()
            };
            // `lobed_dry` tests its own zero first: most models lack it.
            let mut dry = p.m_coulomb * load + p.c + p.c_rate * t + p.lobed_dry(theta);
            // Tested, not multiplied by zero: the exp is the costliest term, and most models lack it.
            if STRIBECK && p.s_break != 0.0 {
                let x = theta_dot / p.v_break;
                dry += p.s_break * (-x * x).exp();
            }
            q -= dry * dir;
        }
        // Tested first: most models have no generator, and those that do spend time in its band.
        if RARE && p.gen_c != 0.0 && gen != 0.0 {
            q -= p.gen_c * (theta_dot - gen * p.gen_w);
        }
        if p.p != 0.0 {
            q -= p.p * (p.k as f64 * theta + p.phi_p).sin();
        }
        if p.kappa != 0.0 {
            q -= p.kappa * p.spring_stretch(theta);
        }
        // The departures' drags (only a departure's tests have them) go with the generator's
        // rarely present term (`RARE`).
        if RARE && p.cubic_drag != 0.0 {
            q -= p.cubic_drag * theta_dot * w2;
        }
        if RARE && p.eddy_brake != 0.0 {
            q -= p.eddy_brake * theta_dot * p.eddy_share(theta);
        }
        if p.j != 0.0 {
            q / (1.0 + p.j)
        } else {
            q
        }
    }

    /// The torques (per m g l) acting at (t, θ, θ̇), term by term, each signed as it acts on θ
    /// (so a loss is opposite to θ̇): the power balance's terms. Not the integrator's path (that
    /// is [`Model::accel`]); a test holds their sum to it. Dry friction acts in sgn θ̇ (0 at rest:
    /// a stuck pendulum's friction does no work).
    pub fn torques(&self, t: f64, theta: f64, theta_dot: f64) -> Torques {
        let p = &self.params;
        let (ay, ax) = self.base_accel(t);
        let (s, c) = sin_cos(theta);
        let dir = if theta_dot > 0.0 {
            1.0
        } else if theta_dot < 0.0 {
            -1.0
        } else {
            0.0
        };
        let load = if p.base_load {
            (theta_dot * theta_dot + (1.0 + ay) * c - ax * s).abs()
        } else {
            (theta_dot * theta_dot + c).abs()
        };
        let fading = if p.s_break != 0.0 {
            let x = theta_dot / p.v_break;
            p.s_break * (-x * x).exp()
        } else {
            0.0
        };
        let excess = (theta_dot.abs() - p.gen_w).max(0.0);
        Torques {
            gravity: -s,
            base: -ay * s - ax * c,
            viscous: -p.beta * theta_dot,
            quadratic: -p.alpha * theta_dot * theta_dot.abs(),
            dry: -(p.m_coulomb * load + p.c + p.c_rate * t + p.lobed_dry(theta) + fading) * dir,
            generator: -p.gen_c * excess * dir,
            position: -p.p * (p.k as f64 * theta + p.phi_p).sin(),
            spring: -p.kappa * p.spring_stretch(theta),
            cubic: -p.cubic_drag * theta_dot * theta_dot * theta_dot,
            eddy: -p.eddy_brake * theta_dot * p.eddy_share(theta),
        }
    }

    /// Mechanical energy per m g l of the unforced pendulum: (1 + j) θ̇²/2 − cos θ + κ·stretch²/2
    /// ([`Dimensionless::spring_stretch`]).
    pub fn energy(&self, theta: f64, theta_dot: f64) -> f64 {
        0.5 * (1.0 + self.params.j) * theta_dot * theta_dot - theta.cos()
            + 0.5 * self.params.kappa * self.params.spring_stretch(theta).powi(2)
    }
}

/// The torques of [`Model::torques`], per m g l, each signed as it acts on θ; their sum is
/// (1 + j) θ̈.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Torques {
    /// Gravity, −sin θ.
    pub gravity: f64,
    /// The base's motion seen in the pendulum's frame, −A_y sin θ − A_x cos θ.
    pub base: f64,
    pub viscous: f64,
    pub quadratic: f64,
    /// Bearing (load-proportional), constant and fading (stribeck) dry friction.
    pub dry: f64,
    pub generator: f64,
    pub position: f64,
    pub spring: f64,
    /// The cubic drag of a departure, −γ θ̇³ ([`Dimensionless::cubic_drag`]).
    pub cubic: f64,
    /// The eddy brake of a departure, −β_e θ̇ (1 + cos(θ − φ_e))/2
    /// ([`Dimensionless::eddy_brake`]).
    pub eddy: f64,
}

impl Torques {
    pub fn sum(&self) -> f64 {
        self.gravity
            + self.base
            + self.viscous
            + self.quadratic
            + self.dry
            + self.generator
            + self.position
            + self.spring
            + self.cubic
            + self.eddy
    }
}

/// sin θ and cos θ within ~2 ulp for |θ| < 1e6 (fdlibm's kernels after a two-part reduction by
/// π/2), inlined: libm's `sincos` was a quarter of a fit's time.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    const PIO2_1: f64 = 1.570_796_326_734_125_6; // the first 33 bits of π/2
    const PIO2_1T: f64 = 6.077_100_506_506_192e-11; // π/2 − PIO2_1
                                                    // Round to nearest without a libm call (valid for |x·2/π| < 2^51).
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    let k = (x * std::f64::consts::FRAC_2_PI + SHIFT) - SHIFT;
    // k·PIO2_1 is exact for |k| < 2^20, so r carries x's own accuracy.
    let r = (x - k * PIO2_1) - k * PIO2_1T;
    let z = r * r;
    let s = r + r
        * z
        * (-1.666_666_666_666_663_2e-1
            + z * (8.333_333_333_322_49e-3
                + z * (-1.984_126_982_985_795e-4
                    + z * (2.755_731_370_707_006_8e-6
                        + z * (-2.505_076_025_340_686_3e-8 + z * 1.589_690_995_211_55e-10)))));
    let c = 1.0 - 0.5 * z
        + z * z
            * (4.166_666_666_666_66e-2
                + z * (-1.388_888_888_887_411e-3
                    + z * (2.480_158_728_947_673e-5
                        + z * (-2.755_731_435_139_066_3e-7
                            + z * (2.087_572_321_298_175e-9 + z * -1.135_964_755_778_819_5e-11)))));
    match (k as i64) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// x^a for the step-size controller, x > 0 (0 below 1e-300), to ~1e-7 relative without a libm
/// call: the controller needs no more (it multiplies by a safety factor of 0.9 anyway), and two
/// `powf` per step were a tenth of a fit's time.
#[inline]
fn pow_ctrl(x: f64, a: f64) -> f64 {
    if !(x > 1e-300) {
        return 0.0;
    }
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    let ln2 = std::f64::consts::LN_2;
    let bits = x.to_bits();
    let e = (bits >> 52) as f64 - 1023.0;
    let m = f64::from_bits((bits & ((1u64 << 52) - 1)) | (1023u64 << 52));
    // ln m = 2 atanh t, t = (m − 1)/(m + 1) ∈ [0, 1/3).
    let t = (m - 1.0) / (m + 1.0);
    let t2 = t * t;
    let ln_m = 2.0
        * t
        * (1.0
            + t2 * (1.0 / 3.0
                + t2 * (1.0 / 5.0 + t2 * (1.0 / 7.0 + t2 * (1.0 / 9.0 + t2 / 11.0)))));
    let y = a * (e * ln2 + ln_m);
    // e^y = 2^n e^r, |r| ≤ ln 2 / 2.
    let n = (y * std::f64::consts::LOG2_E + SHIFT) - SHIFT;
    let r = y - n * ln2;
    let p = 1.0
        + r * (1.0
            + r / 2.0
                * (1.0
                    + r / 3.0
                        * (1.0 + r / 4.0 * (1.0 + r / 5.0 * (1.0 + r / 6.0 * (1.0 + r / 7.0))))));
    p * f64::from_bits(((n as i64 + 1023) as u64) << 52)
}

/// Relative margin by which the applied torque must exceed the static capacity to break loose.
/// Without it, |Q| = C to rounding gives a slip whose θ̈ has the wrong sign by an ulp, an event at
/// the segment's start, and no progress (Zeno by round-off).
const BREAK_MARGIN: f64 = 1e-10;

#[inline]
/// Whether an applied torque `q` breaks a stuck shaft loose against the static capacity `c`.
pub fn breaks_loose(q: f64, c: f64) -> bool {
    q.abs() > c * (1.0 + BREAK_MARGIN) + 1e-14
}

/// Integrator settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimOptions {
    /// Relative tolerance (θ is scaled by min(|θ|, π): it is an angle, its accuracy is absolute).
    pub rtol: f64,
    /// Absolute tolerance.
    pub atol: f64,
    /// Largest step (dimensionless time); keeps θ̇ sign changes from hiding inside a step.
    pub h_max: f64,
    /// Give up after this many steps.
    pub max_steps: u64,
    /// First step to try; `None` = 0.01. Restarted integrations (multiple shooting) pass the
    /// last accepted step of the previous one, so they do not climb from a tiny step again.
    #[serde(default)]
    pub h_init: Option<f64>,
}

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            rtol: 1e-8,
            atol: 1e-8,
            h_max: 0.5,
            max_steps: 50_000_000,
            h_init: None,
        }
    }
}

impl SimOptions {
    /// Both tolerances set to `tol`.
    pub fn with_tol(tol: f64) -> Self {
        Self {
            rtol: tol,
            atol: tol,
            ..Self::default()
        }
    }
}

/// Counters of one integration.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct SimStats {
    pub steps: u64,
    pub rejected: u64,
    pub rhs_evals: u64,
    /// θ̇ = 0 events located.
    pub events: u64,
    /// Crossings of the generator's dead-band edge |θ̇| = w located.
    #[serde(default)]
    pub band_events: u64,
    /// Times the pendulum stuck.
    pub sticks: u64,
    /// True if the integration ended stuck (θ̇ = 0 exactly).
    pub ended_stuck: bool,
    /// True if the callback stopped the integration early.
    pub stopped_early: bool,
    /// The last step size the controller proposed (dimensionless time).
    pub last_h: f64,
}

/// Dormand–Prince 5(4) coefficients.
mod dp {
    pub const C2: f64 = 1.0 / 5.0;
    pub const C3: f64 = 3.0 / 10.0;
    pub const C4: f64 = 4.0 / 5.0;
    pub const C5: f64 = 8.0 / 9.0;
    pub const A21: f64 = 1.0 / 5.0;
    pub const A31: f64 = 3.0 / 40.0;
    pub const A32: f64 = 9.0 / 40.0;
    pub const A41: f64 = 44.0 / 45.0;
    pub const A42: f64 = -56.0 / 15.0;
    pub const A43: f64 = 32.0 / 9.0;
    pub const A51: f64 = 19372.0 / 6561.0;
    pub const A52: f64 = -25360.0 / 2187.0;
    pub const A53: f64 = 64448.0 / 6561.0;
    pub const A54: f64 = -212.0 / 729.0;
    pub const A61: f64 = 9017.0 / 3168.0;
    pub const A62: f64 = -355.0 / 33.0;
    pub const A63: f64 = 46732.0 / 5247.0;
    pub const A64: f64 = 49.0 / 176.0;
    pub const A65: f64 = -5103.0 / 18656.0;
    pub const A71: f64 = 35.0 / 384.0;
    pub const A73: f64 = 500.0 / 1113.0;
    pub const A74: f64 = 125.0 / 192.0;
    pub const A75: f64 = -2187.0 / 6784.0;
    pub const A76: f64 = 11.0 / 84.0;
    pub const E1: f64 = 71.0 / 57600.0;
    pub const E3: f64 = -71.0 / 16695.0;
    pub const E4: f64 = 71.0 / 1920.0;
    pub const E5: f64 = -17253.0 / 339200.0;
    pub const E6: f64 = 22.0 / 525.0;
    pub const E7: f64 = -1.0 / 40.0;
    // Dense output (Hairer & Wanner's DOPRI5 continuous extension).
    pub const D1: f64 = -12715105075.0 / 11282082432.0;
    pub const D3: f64 = 87487479700.0 / 32700410799.0;
    pub const D4: f64 = -10690763975.0 / 1880347072.0;
    pub const D5: f64 = 701980252875.0 / 199316789632.0;
    pub const D6: f64 = -1453857185.0 / 822651844.0;
    pub const D7: f64 = 69997945.0 / 29380423.0;
}

type Y = [f64; 2];

/// Dense output of one accepted step on [t, t + h].
#[derive(Clone, Copy)]
struct Dense {
    t: f64,
    h: f64,
    r: [Y; 5],
}

impl Dense {
    #[inline]
    fn eval(&self, t: f64) -> Y {
        let s = (t - self.t) / self.h;
        let s1 = 1.0 - s;
        let mut y = [0.0; 2];
        for (i, yi) in y.iter_mut().enumerate() {
            let r = &self.r;
            *yi = r[0][i] + s * (r[1][i] + s1 * (r[2][i] + s * (r[3][i] + s1 * r[4][i])));
        }
        y
    }
}

/// One output sample (dimensionless time and state).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    pub t: f64,
    pub theta: f64,
    pub theta_dot: f64,
}

/// A sampled trajectory.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Trajectory {
    pub t: Vec<f64>,
    pub theta: Vec<f64>,
    pub theta_dot: Vec<f64>,
    pub stats: SimStats,
}

/// Integrates `model` from (t0, θ0, θ̇0) to `t_end`, calling `sink` at each time of `times`
/// (increasing, within [t0, t_end]) with the state there. `sink` may stop the run early
/// (`ControlFlow::Break`): that is how a fit abandons a trial that cannot win.
pub fn integrate<I, F>(
    model: &Model,
    opts: &SimOptions,
    t0: f64,
    y0: [f64; 2],
    t_end: f64,
    times: I,
    sink: F,
) -> Result<SimStats, ModelError>
where
    I: IntoIterator<Item = f64>,
    F: FnMut(Sample) -> ControlFlow<()>,
{
    // The optional terms are chosen once here, not tested in every right-hand side and step:
    // a model without them runs the step loop it had before they existed (issue 14: "the
    // simulator bench must not slow down"). Each variant computes the same numbers as the
    // general one, since a term compiled out is one whose coefficient is zero.
    let p = &model.params;
    let rare = p.gen_c != 0.0 || p.cubic_drag != 0.0 || p.eddy_brake != 0.0;
    match (p.s_break != 0.0, rare) {
        (false, false) => {
            integrate_with::<false, false, I, F>(model, opts, t0, y0, t_end, times, sink)
        }
        (true, false) => {
            integrate_with::<true, false, I, F>(model, opts, t0, y0, t_end, times, sink)
        }
        (false, true) => {
            integrate_with::<false, true, I, F>(model, opts, t0, y0, t_end, times, sink)
        }
        (true, true) => integrate_with::<true, true, I, F>(model, opts, t0, y0, t_end, times, sink),
    }
}

/// [`integrate`] with the breakaway (`STRIBECK`) and the generator and departure drags (`RARE`)
/// compiled in or out.
fn integrate_with<const STRIBECK: bool, const RARE: bool, I, F>(
    model: &Model,
    opts: &SimOptions,
    t0: f64,
    y0: [f64; 2],
    t_end: f64,
    times: I,
    mut sink: F,
) -> Result<SimStats, ModelError>
where
    I: IntoIterator<Item = f64>,
    F: FnMut(Sample) -> ControlFlow<()>,
{
    if !(y0[0].is_finite() && y0[1].is_finite() && t0.is_finite() && t_end.is_finite()) {
        return Err(ModelError::BadInput(format!(
            "non-finite start: t0={t0}, theta={}, theta_dot={}, t_end={t_end}",
            y0[0], y0[1]
        )));
    }
    let mut times = times.into_iter().peekable();
    let mut stats = SimStats::default();
    let dry = model.has_dry_friction();
    let mut t = t0;
    let mut y = y0;
    // Slip direction; 0 = stuck (only with dry friction) or no dry friction at all.
    let mut dir: f64;
    let mut stuck = false;
    macro_rules! emit {
        ($tt:expr, $yy:expr) => {{
            let yy: Y = $yy;
            if sink(Sample {
                t: $tt,
                theta: yy[0],
                theta_dot: yy[1],
            })
            .is_break()
            {
                stats.stopped_early = true;
                return Ok(stats);
            }
        }};
    }
    // Skip requested times before t0.
    while let Some(&ts) = times.peek() {
        if ts < t0 - 1e-12 * t0.abs().max(1.0) {
            times.next();
        } else {
            break;
        }
    }
    if dry {
        if y[1] != 0.0 {
            dir = y[1].signum();
        } else {
            let (q, c) = model.static_balance(t, y[0]);
            if breaks_loose(q, c) {
                dir = q.signum();
            } else {
                stuck = true;
                dir = 0.0;
            }
        }
    } else {
        dir = 0.0;
    }
    // The generator's mode (see the module docs); it switches only where its dead band has an
    // edge (w > 0). RARE is true whenever g ≠ 0 (and for the departures' drags).
    let gen_switch = RARE && model.params.gen_w > 0.0;
    let mut gen = model.gen_mode(y[1]);
    // Events that made no progress in a row (a guard against Zeno behaviour).
    let mut idle_events = 0u32;
    let mut h = opts
        .h_init
        .filter(|h| *h > 0.0)
        .unwrap_or(1e-2)
        .min(opts.h_max);
    // PI step-size control (Hairer's DOPRI5 constants); err_old^β is kept, not recomputed per
    // attempt.
    let beta = 0.04;
    let mut err_old_beta: f64 = pow_ctrl(1e-4, beta);
    let mut k1: Y = [0.0; 2];
    let mut need_k1 = true;

    while t < t_end {
        if stuck {
            stats.sticks += 1;
            y[1] = 0.0;
            // Find when the pendulum breaks loose, if ever.
            let t_break = if model.excitation.is_still() {
                None
            } else {
                find_breakaway(model, t, y[0], t_end)
            };
            let t_until = t_break.unwrap_or(t_end);
            while let Some(&ts) = times.peek() {
                if ts <= t_until {
                    times.next();
                    emit!(ts, [y[0], 0.0]);
                } else {
                    break;
                }
            }
            match t_break {
                None => {
                    stats.ended_stuck = true;
                    return Ok(stats);
                }
                Some(tb) => {
                    t = tb;
                    let (q, _) = model.static_balance(t, y[0]);
                    dir = q.signum();
                    gen = model.gen_mode(0.0);
                    stuck = false;
                    need_k1 = true;
                    h = h.min(1e-2);
                    continue;
                }
            }
        }
        if stats.steps >= opts.max_steps {
            return Err(ModelError::TooManySteps {
                steps: stats.steps,
                t,
            });
        }
        if need_k1 {
            k1 = f::<STRIBECK, RARE>(model, t, y, dir, gen);
            stats.rhs_evals += 1;
            need_k1 = false;
        }
        let last = t + h >= t_end;
        if last {
            h = t_end - t;
        }
        // One DOPRI5 step.
        let k2 = f::<STRIBECK, RARE>(model, t + dp::C2 * h, add(y, h, &[(dp::A21, k1)]), dir, gen);
        let k3 = f::<STRIBECK, RARE>(
            model,
            t + dp::C3 * h,
            add(y, h, &[(dp::A31, k1), (dp::A32, k2)]),
            dir,
            gen,
        );
        let k4 = f::<STRIBECK, RARE>(
            model,
            t + dp::C4 * h,
            add(y, h, &[(dp::A41, k1), (dp::A42, k2), (dp::A43, k3)]),
            dir,
            gen,
        );
        let k5 = f::<STRIBECK, RARE>(
            model,
            t + dp::C5 * h,
            add(
                y,
                h,
                &[(dp::A51, k1), (dp::A52, k2), (dp::A53, k3), (dp::A54, k4)],
            ),
            dir,
            gen,
        );
        let y6 = add(
            y,
            h,
            &[
                (dp::A61, k1),
                (dp::A62, k2),
                (dp::A63, k3),
                (dp::A64, k4),
                (dp::A65, k5),
            ],
        );
        let k6 = f::<STRIBECK, RARE>(model, t + h, y6, dir, gen);
        let y_new = add(
            y,
            h,
            &[
                (dp::A71, k1),
                (dp::A73, k3),
                (dp::A74, k4),
                (dp::A75, k5),
                (dp::A76, k6),
            ],
        );
        let k7 = f::<STRIBECK, RARE>(model, t + h, y_new, dir, gen);
        stats.rhs_evals += 6;
        let mut err = 0.0;
        for i in 0..2 {
            let e = h
                * (dp::E1 * k1[i]
                    + dp::E3 * k3[i]
                    + dp::E4 * k4[i]
                    + dp::E5 * k5[i]
                    + dp::E6 * k6[i]
                    + dp::E7 * k7[i]);
            let mut mag = y[i].abs().max(y_new[i].abs());
            if i == 0 {
                mag = mag.min(std::f64::consts::PI);
            }
            let sc = opts.atol + opts.rtol * mag;
            err += (e / sc) * (e / sc);
        }
        let err = (err / 2.0).sqrt();
        if !err.is_finite() {
            h *= 0.1;
            stats.rejected += 1;
            if h < 1e-14 {
                return Err(ModelError::StepUnderflow { t });
            }
            continue;
        }
        let fac11 = pow_ctrl(err, 0.2 - 0.75 * beta);
        let fac = (fac11 / err_old_beta / 0.9).clamp(0.1, 5.0);
        let h_next = (h / fac).min(opts.h_max);
        if err > 1.0 {
            stats.rejected += 1;
            h /= (fac11 / 0.9).min(5.0);
            if h < 1e-14 * t.abs().max(1.0) {
                return Err(ModelError::StepUnderflow { t });
            }
            continue;
        }
        stats.steps += 1;
        err_old_beta = pow_ctrl(err.max(1e-4), beta);
        // The dense output is built only for a step that holds an event or an output time (most
        // steps of a steady-state tail hold neither).
        let dense = || {
            let ydiff = [y_new[0] - y[0], y_new[1] - y[1]];
            let bspl = [h * k1[0] - ydiff[0], h * k1[1] - ydiff[1]];
            Dense {
                t,
                h,
                r: [
                    y,
                    ydiff,
                    bspl,
                    [
                        ydiff[0] - h * k7[0] - bspl[0],
                        ydiff[1] - h * k7[1] - bspl[1],
                    ],
                    [
                        h * (dp::D1 * k1[0]
                            + dp::D3 * k3[0]
                            + dp::D4 * k4[0]
                            + dp::D5 * k5[0]
                            + dp::D6 * k6[0]
                            + dp::D7 * k7[0]),
                        h * (dp::D1 * k1[1]
                            + dp::D3 * k3[1]
                            + dp::D4 * k4[1]
                            + dp::D5 * k5[1]
                            + dp::D6 * k6[1]
                            + dp::D7 * k7[1]),
                    ],
                ],
            }
        };
        let t_new = if last { t_end } else { t + h };
        // Did θ̇ reach zero against the slip direction?
        let crossing = dir != 0.0 && y_new[1] * dir <= 0.0;
        // Did θ̇ cross the generator's dead-band edge? On: fell back to w on its side (or
        // below); off: left the band on either side.
        // Off, θ̇ can also leave the band and come back within one step (a swing whose peak
        // speed just exceeds w): when θ̈ changes sign in the step, θ̇'s extremum (where θ̈,
        // interpolated linearly, vanishes) is checked on the dense output.
        let mut band_until = t_new;
        let mut graze = false;
        let mut band_speed = y_new[1];
        let band = gen_switch
            && if gen != 0.0 {
                y_new[1] * gen <= model.params.gen_w
            } else if y_new[1].abs() > model.params.gen_w {
                true
            } else if k1[1] * k7[1] < 0.0 {
                let te = t + h * k1[1] / (k1[1] - k7[1]);
                let v = dense().eval(te)[1];
                band_until = te;
                band_speed = v;
                v.abs() > model.params.gen_w
            } else {
                false
            };
        if band {
            let dense = dense();
            let w = model.params.gen_w;
            // g(t) = σθ̇ − κ, > 0 at t and ≤ 0 at the crossing.
            let (side, sigma, kappa) = if gen != 0.0 {
                (gen, gen, w)
            } else {
                let side = band_speed.signum();
                (side, -side, -w)
            };
            let tb = locate_level(&dense, t, band_until, sigma, kappa);
            // θ̇ = 0 (dry friction) can only come first from inside the band.
            let td = if crossing && gen == 0.0 {
                locate_zero(&dense, t, t_new, dir)
            } else {
                f64::INFINITY
            };
            // No time gained: the step starts on the edge and the motion grazes it (θ̈ ≈ 0
            // there). Cutting would repeat forever (each mode sends it to the other); the step
            // is taken whole instead, its mode error g·(|θ̇| − w) being as small as the graze,
            // and the mode regraded from where it ends.
            graze = tb <= t + 1e-12 * t.abs().max(1.0);
            if tb < td && !graze {
                stats.band_events += 1;
                while let Some(&ts) = times.peek() {
                    if ts < tb {
                        times.next();
                        emit!(ts, dense.eval(ts));
                    } else {
                        break;
                    }
                }
                let mut yb = dense.eval(tb);
                yb[1] = side * w;
                // On the edge both modes give the same θ̈ (the torque is continuous): its sign
                // says which side the motion goes on to.
                let a = model.accel_in::<STRIBECK, RARE>(tb, yb[0], yb[1], dir, 0.0);
                gen = if a * side > 0.0 { side } else { 0.0 };
                t = tb;
                y = yb;
                need_k1 = true;
                h = h_next.min(h);
                continue;
            }
        }
        if crossing {
            let dense = dense();
            let te = locate_zero(&dense, t, t_new, dir);
            // The step began at rest, broke loose (θ̈ along dir), and ends with θ̇ back at or past
            // zero: the slip's return to rest lies inside the step, but the root search stops at
            // its start, where θ̇ is 0 too. Taking that as the event would stick the pendulum
            // where it slips (and when the slip outlasts the step, an event per 1e-9·t of time:
            // half a million where the forcing's vertical acceleration passes g with the bob
            // just outside the friction cone). A shorter step resolves the slip.
            if te <= t && y[1] == 0.0 && h > 1e-12 * t.abs().max(1.0) {
                stats.rejected += 1;
                h *= 0.25;
                continue;
            }
            stats.events += 1;
            let mut ye = dense.eval(te);
            ye[1] = 0.0;
            while let Some(&ts) = times.peek() {
                if ts < te {
                    times.next();
                    emit!(ts, dense.eval(ts));
                } else {
                    break;
                }
            }
            idle_events = if te - t <= 1e-12 * t.abs().max(1.0) {
                idle_events + 1
            } else {
                0
            };
            t = te;
            y = ye;
            gen = model.gen_mode(0.0);
            let (q, c) = model.static_balance(t, y[0]);
            if breaks_loose(q, c) && idle_events < 3 {
                dir = q.signum();
            } else {
                stuck = true;
                dir = 0.0;
                if idle_events >= 3 {
                    // Balanced on the edge of the friction cone: hold still for a moment.
                    t += 1e-9 * t.abs().max(1.0);
                    idle_events = 0;
                }
            }
            need_k1 = true;
            h = h_next.min(h);
            continue;
        }
        if times.peek().is_some_and(|&ts| ts <= t_new) {
            let dense = dense();
            while let Some(&ts) = times.peek() {
                if ts <= t_new {
                    times.next();
                    emit!(ts, dense.eval(ts));
                } else {
                    break;
                }
            }
        }
        t = t_new;
        y = y_new;
        k1 = k7;
        if graze {
            let regraded = model.gen_mode(y[1]);
            if regraded != gen {
                gen = regraded;
                need_k1 = true;
            }
        }
        if !last {
            h = h_next;
            stats.last_h = h;
        }
    }
    Ok(stats)
}

#[inline]
fn f<const STRIBECK: bool, const RARE: bool>(model: &Model, t: f64, y: Y, dir: f64, gen: f64) -> Y {
    [
        y[1],
        model.accel_in::<STRIBECK, RARE>(t, y[0], y[1], dir, gen),
    ]
}

#[inline]
fn add(y: Y, h: f64, terms: &[(f64, Y)]) -> Y {
    let mut out = y;
    for (a, k) in terms {
        out[0] += h * a * k[0];
        out[1] += h * a * k[1];
    }
    out
}

/// Root of θ̇ on the dense output in (a, b], where θ̇·dir > 0 at a and ≤ 0 at b (Illinois).
fn locate_zero(dense: &Dense, a: f64, b: f64, dir: f64) -> f64 {
    locate_level(dense, a, b, dir, 0.0)
}

/// Root of σθ̇ − κ on the dense output in (a, b], > 0 at a and ≤ 0 at b (Illinois). With κ = 0
/// the same numbers as a plain sign test (x − 0 = x).
fn locate_level(dense: &Dense, a: f64, b: f64, sigma: f64, kappa: f64) -> f64 {
    let g = |t: f64| dense.eval(t)[1] * sigma - kappa;
    let (mut a, mut b) = (a, b);
    let (mut ga, mut gb) = (g(a), g(b));
    if ga <= 0.0 {
        return a;
    }
    let mut side = 0;
    for _ in 0..100 {
        let m = if (ga - gb).abs() > 0.0 {
            (a * gb - b * ga) / (gb - ga)
        } else {
            0.5 * (a + b)
        };
        let m = if m > a && m < b { m } else { 0.5 * (a + b) };
        let gm = g(m);
        if gm > 0.0 {
            a = m;
            ga = gm;
            if side == -1 {
                gb *= 0.5;
            }
            side = -1;
        } else {
            b = m;
            gb = gm;
            if side == 1 {
                ga *= 0.5;
            }
            side = 1;
        }
        if (b - a) <= 1e-14 * b.abs().max(1.0) {
            break;
        }
    }
    b
}

/// First time after `t` when a stuck pendulum at θ breaks loose (|Q| > C), or `None` before t_end.
fn find_breakaway(model: &Model, t: f64, theta: f64, t_end: f64) -> Option<f64> {
    let excess = |tt: f64| {
        let (q, c) = model.static_balance(tt, theta);
        q.abs() - (c * (1.0 + BREAK_MARGIN) + 1e-14)
    };
    // Scan finely enough for the forcing (64 points per period) and the measured signal's grid.
    let mut h = match &model.excitation {
        Excitation::Crank(c) => 2.0 * std::f64::consts::PI / c.omega.max(1e-3) / 64.0,
        Excitation::Measured(m) => m.dt * 0.5,
        Excitation::None => return None,
    };
    h = h.min(0.1);
    // A periodic forcing that has not broken the pendulum loose over one whole period never will
    // (θ is fixed): scanning one period (and a step) is enough, however far t_end is.
    let scan_end = match &model.excitation {
        Excitation::Crank(c)
            if c.omega_drift == 0.0
                && c.omega > 0.0
                && (c.t_start.is_none() || t >= c.t_at_speed()) =>
        {
            t_end.min(t + 2.0 * std::f64::consts::PI / c.omega + h)
        }
        _ => t_end,
    };
    let mut a = t;
    while a < scan_end {
        let b = (a + h).min(t_end);
        if excess(b) > 0.0 {
            // Bisect: excess(a) ≤ 0 < excess(b).
            let (mut lo, mut hi) = (a, b);
            for _ in 0..60 {
                let m = 0.5 * (lo + hi);
                if excess(m) > 0.0 {
                    hi = m;
                } else {
                    lo = m;
                }
                if hi - lo <= 1e-13 * hi.abs().max(1.0) {
                    break;
                }
            }
            return Some(hi);
        }
        a = b;
    }
    None
}

/// Uniform output times t0, t0 + dt, … ≤ t_end.
pub fn uniform_times(t0: f64, t_end: f64, dt: f64) -> impl Iterator<Item = f64> {
    let n = if dt > 0.0 {
        ((t_end - t0) / dt + 1e-9).floor() as u64 + 1
    } else {
        1
    };
    (0..n).map(move |k| t0 + k as f64 * dt)
}

/// Integrates and samples on a uniform grid of step `dt_out`.
pub fn simulate(
    model: &Model,
    opts: &SimOptions,
    y0: [f64; 2],
    t0: f64,
    t_end: f64,
    dt_out: f64,
) -> Result<Trajectory, ModelError> {
    if !(dt_out > 0.0) || !(t_end > t0) {
        return Err(ModelError::BadInput(format!(
            "need t_end > t0 and dt_out > 0 (t0={t0}, t_end={t_end}, dt_out={dt_out})"
        )));
    }
    let mut tr = Trajectory::default();
    let stats = integrate(
        model,
        opts,
        t0,
        y0,
        t_end,
        uniform_times(t0, t_end, dt_out),
        |s| {
            tr.t.push(s.t);
            tr.theta.push(s.theta);
            tr.theta_dot.push(s.theta_dot);
            ControlFlow::Continue(())
        },
    )?;
    tr.stats = stats;
    Ok(tr)
}

/// Plain fixed-step classical RK4 with `sgn θ̇` friction: the benchmark's and tests' baseline.
/// It knows nothing of stick/slip, so use it only where θ̇ never rests at zero.
pub fn rk4_fixed(model: &Model, y0: [f64; 2], t0: f64, t_end: f64, h: f64) -> [f64; 2] {
    let n = ((t_end - t0) / h).round() as u64;
    let mut y = y0;
    let mut t = t0;
    let rhs = |t: f64, y: Y| -> Y {
        let dir = if y[1] > 0.0 {
            1.0
        } else if y[1] < 0.0 {
            -1.0
        } else {
            0.0
        };
        [y[1], model.accel(t, y[0], y[1], dir)]
    };
    for _ in 0..n {
        let k1 = rhs(t, y);
        let k2 = rhs(
            t + 0.5 * h,
            [y[0] + 0.5 * h * k1[0], y[1] + 0.5 * h * k1[1]],
        );
        let k3 = rhs(
            t + 0.5 * h,
            [y[0] + 0.5 * h * k2[0], y[1] + 0.5 * h * k2[1]],
        );
        let k4 = rhs(t + h, [y[0] + h * k3[0], y[1] + h * k3[1]]);
        for i in 0..2 {
            y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        t += h;
    }
    y
}

#[cfg(test)]
mod tests {
    /// The inlined sin/cos agree with libm's to a few ulp of 1 over the angles a fit meets
    /// (rotations run to thousands of radians).
    #[test]
    fn sin_cos_matches_libm() {
        let mut worst: f64 = 0.0;
        for i in 0..400_000 {
            let x = -5000.0 + i as f64 * 0.025_000_1;
            let (s, c) = super::sin_cos(x);
            let (s0, c0) = x.sin_cos();
            worst = worst.max((s - s0).abs()).max((c - c0).abs());
        }
        assert!(worst < 5e-16, "{worst:e}");
        for i in 0..10_000 {
            let x = 10f64.powf(-12.0 + i as f64 * 0.0021);
            for a in [0.04, 0.17] {
                let p = super::pow_ctrl(x, a);
                assert!((p / x.powf(a) - 1.0).abs() < 1e-6, "{x}^{a}");
            }
        }
        assert_eq!(super::pow_ctrl(0.0, 0.17), 0.0);
        for x in [0.0, 1e-300, -0.0, std::f64::consts::FRAC_PI_4, 1.0e5] {
            let (s, c) = super::sin_cos(x);
            assert!(
                (s - x.sin()).abs() < 5e-16 && (c - x.cos()).abs() < 5e-16,
                "{x}"
            );
        }
    }
}
