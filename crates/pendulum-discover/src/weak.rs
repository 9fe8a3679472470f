//! The equation-error view in weak form: the torque the model fails to explain, at each instant,
//! without differentiating noise twice.
//!
//! Every term of the equation of motion is integrated against one smooth test function
//! K(t − t_k) = (1 − s²)⁴, s = (t − t_k)/h; the θ̈ term becomes ∫K''θ (integration by parts), so
//! only θ and a first derivative (local cubic fit) are ever used. Windows are spaced by their
//! full width 2h, so rows are close to independent (the information criterion counts them).
//! Extra inertia scales θ̈ itself; regressing on the measured ∫K''θ would put its noise on both
//! sides (errors in variables: a spurious negative inertia). (1 + j)θ̈ = −G − D gives
//! jθ̈ ≈ −j(G + D) ≈ −jG to first order, so the regressor is −∫K(1 + A_y) sin θ, free of noise.
//! Windows where the pendulum sticks (the friction force is then static and unknown), gaps, and
//! the shaker's spin-up are left out.

use pendulum_model::effects::{Kind, RateShape};
use pendulum_model::excitation::{crank_f1, crank_f2};
use pendulum_model::{Effect, Physical, Regressor, WeakSample, CATALOGUE};
use pendulum_process::{Alignment, RunData};
use serde::{Deserialize, Serialize};

/// A weak-form column of a catalogue effect ([`Effect::regressors`]): each ∫K·term over a
/// window, in dimensionless units of θ̈ of the row's own run, times its run's factor from the
/// SI parameter ([`Regressor::per_si`]), so that its coefficient is the SI parameter of
/// effects.md, the same for every run of a campaign that mixes bobs and cranks.
#[derive(Debug, Clone, Copy)]
pub struct Column {
    pub effect: &'static dyn Effect,
    pub reg: &'static Regressor,
}

/// The regression's columns from the catalogue: every effect's regressors, in the catalogue's
/// order (the index in [`WeakRow::x`] is the position here), then the shaped columns
/// ([`shaped_columns`]).
pub fn columns() -> &'static [Column] {
    static COLS: std::sync::OnceLock<Vec<Column>> = std::sync::OnceLock::new();
    COLS.get_or_init(|| {
        CATALOGUE
            .iter()
            .flat_map(|&effect| {
                effect
                    .regressors()
                    .iter()
                    .map(move |reg| Column { effect, reg })
            })
            .collect()
    })
}

/// The first column of an effect (its only one, unless its candidates come in groups).
pub fn column_of(effect: &str) -> Option<usize> {
    columns().iter().position(|c| c.effect.name() == effect)
}

/// The columns of one candidate of an effect (its group, see [`Regressor::group`]).
pub fn group_columns(effect: &str, group: u32) -> Vec<usize> {
    (0..columns().len())
        .filter(|&i| columns()[i].effect.name() == effect && columns()[i].reg.group == group)
        .collect()
}

/// Whether column `c` (catalogue or shaped) is a loss: a torque of the equation of motion that
/// can only take energy out (damping, dry friction, a generator).
pub fn is_loss(c: usize) -> bool {
    let effect = match columns().get(c) {
        Some(col) => Some(col.effect),
        None => shaped(c).and_then(|s| pendulum_model::effects::by_name(s.effect)),
    };
    effect.is_some_and(|e| e.kind() == Kind::Dynamics && e.positive())
}

/// The column of the inertia beside the bob's (the catalogue's mass effect): the screen divides
/// the dynamics columns by 1 + J/(m l²) of each run.
pub fn mass_column() -> Option<usize> {
    columns().iter().position(|c| c.effect.kind() == Kind::Mass)
}

/// The column of the encoder's reading offset (the catalogue's observation effect): also the
/// template of the per-run zeroing contrasts ([`add_zero_error_contrasts`]).
pub fn observation_column() -> Option<usize> {
    columns()
        .iter()
        .position(|c| c.effect.kind() == Kind::Observation)
}

/// A column whose regressor depends on a parameter that is not a coefficient (a speed scale):
/// one per catalogue effect with a [`RateShape`], after the accel-delay column, in the
/// catalogue's order. The screen profiles it over the shape's grid (then refines it), one
/// weighted fit per value.
#[derive(Debug, Clone, Copy)]
pub struct Shaped {
    pub col: usize,
    pub effect: &'static str,
    pub shape: &'static RateShape,
}

/// The shaped columns, from the catalogue.
pub fn shaped_columns() -> &'static [Shaped] {
    static COLS: std::sync::OnceLock<Vec<Shaped>> = std::sync::OnceLock::new();
    COLS.get_or_init(|| {
        pendulum_model::effects::CATALOGUE
            .iter()
            .filter_map(|e| e.rate_shape().map(|s| (e.name(), s)))
            .enumerate()
            .map(|(i, (effect, shape))| Shaped {
                col: columns().len() + i,
                effect,
                shape,
            })
            .collect()
    })
}

/// The shaped column `col` describes, if any.
pub fn shaped(col: usize) -> Option<&'static Shaped> {
    shaped_columns().iter().find(|s| s.col == col)
}

/// The shaped column of an effect, if it has one.
pub fn shaped_column(effect: &str) -> Option<usize> {
    shaped_columns()
        .iter()
        .find(|s| s.effect == effect)
        .map(|s| s.col)
}

/// Width of [`WeakRow::x`] before the per-run zeroing contrasts.
pub fn width() -> usize {
    columns().len() + shaped_columns().len()
}

/// Writes the shaped column `col` of every row for the shape `value` (SI), from each window's
/// kernel-weighted speeds ([`WeakRow::speeds`]).
pub fn set_shape(rows: &mut [WeakRow], col: usize, value: f64) {
    let Some(s) = shaped(col) else { return };
    for r in rows {
        let v: f64 = r
            .speeds
            .iter()
            .map(|&(k, w)| k * (s.shape.f)(w, value))
            .sum();
        if r.x.len() > col {
            r.x[col] = v;
        }
    }
}

/// Whether a column is a term of the equation of motion (damping, torques, tilt, inertia), as
/// opposed to a sensor term (encoder offset, accelerometer lag, per-run zeroing errors). With
/// extra inertia, (1 + j)θ̈ = −G − D: the dynamics reach the target divided by 1 + j_r, the
/// sensor terms (errors of the measured θ and A_y that the target is computed from) do not.
pub fn is_dynamics(col: usize) -> bool {
    shaped(col).is_some()
        || columns()
            .get(col)
            .is_some_and(|c| matches!(c.effect.kind(), Kind::Dynamics | Kind::Mass))
}

/// Per-run factors from the SI parameters of effects.md to the dimensionless coefficients of the
/// run's own equation ([`Regressor::per_si`]: β = b/(m ω0), α = a l/m, M = μ r_b/l,
/// c = T_c/(m g l), …), one per column. A column multiplied by its factor has the SI parameter
/// as its coefficient, so runs with different bobs, rods and cranks share one regression:
/// pooling dimensionless columns would ask a light and a heavy bob for the same β and c, and
/// their difference leaked into other columns (a 2 ms "accelerometer lag" on ideal data). The
/// shaped columns are written in SI torque already (see [`set_shape`]): factor 1.
pub fn si_factors(rig: &pendulum_process::RigParams) -> Vec<f64> {
    let p = Physical {
        m_kg: rig.m_kg,
        l_m: rig.l_m,
        crank_r_m: rig.crank_r_m,
        rod_l_m: rig.rod_l_m,
        r_b_m: rig.r_b_m,
        g_m_s2: rig.g_m_s2,
        ..Physical::default()
    };
    let mut f: Vec<f64> = columns().iter().map(|c| (c.reg.per_si)(&p)).collect();
    f.resize(width(), 1.0);
    f
}

/// One window.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WeakRow {
    pub run: usize,
    /// Window centre, s from the aligned t = 0 (negative: the free segment).
    pub tau_s: f64,
    /// θ, rad; θ̇, rad/s; forcing phase (rad, NaN in the free segment) at the centre.
    pub theta: f64,
    pub theta_dot_rad_s: f64,
    pub phase: f64,
    /// Measured vertical and horizontal accelerations at the centre, m/s² (z without g).
    pub a_y_meas: f64,
    pub a_x_meas: f64,
    /// Target −∫K(θ̈ + (1 + A_y) sin θ): what damping and the effects must explain.
    pub target: f64,
    /// Regressors: the catalogue's [`columns`], then the shaped columns ([`shaped_columns`]).
    pub x: Vec<f64>,
    /// Regression weight (inverse residual variance of the row's regime; 1 until
    /// [`set_weights`] is called).
    #[serde(default = "one")]
    pub weight: f64,
    /// The run's bob inertia m l², kg·m²: extra inertia J divides its dynamics by 1 + J/(m l²).
    #[serde(default = "nan")]
    pub bob_inertia_kg_m2: f64,
    /// The generic library of [`crate::sparse::LIBRARY`], each ∫K·f over the window times the
    /// run's 1/(m g l): coefficients are torques, N·m per unit of f.
    #[serde(default)]
    pub lib: Vec<f64>,
    /// The window's samples as (K·dt/(m g l), θ' rad/s): what a shaped column integrates
    /// ([`set_shape`]). Shared, so that the screen's trial copies of the rows stay cheap.
    #[serde(skip)]
    pub speeds: std::sync::Arc<Vec<(f64, f64)>>,
}

fn nan() -> f64 {
    f64::NAN
}

fn one() -> f64 {
    1.0
}

/// The distinct runs (ascending) of the rows `mask` keeps.
pub(crate) fn runs_of(rows: &[WeakRow], mask: &[bool]) -> Vec<usize> {
    let mut runs: Vec<usize> = (0..rows.len())
        .filter(|&i| mask[i])
        .map(|i| rows[i].run)
        .collect();
    runs.sort_unstable();
    runs.dedup();
    runs
}

/// Weighted squared residuals `res` of `rows` with each run's own encoder zeroing error refitted
/// (least squares on the observation column within the run). On held-out rows that error is a
/// nuisance of the run, not a prediction of any model (as a validate run's initial state is for
/// E_θ): left in, a 2-count zeroing error is a torque as large as a plausible dry torque, and
/// its scatter between runs swamps what a model changes.
pub(crate) fn sq_with_run_offsets(rows: &[&WeakRow], mut res: Vec<f64>) -> Vec<f64> {
    if let Some(offset) = observation_column() {
        let runs: std::collections::BTreeSet<usize> = rows.iter().map(|r| r.run).collect();
        for run in runs {
            let idx: Vec<usize> = (0..rows.len()).filter(|&i| rows[i].run == run).collect();
            let (mut sxy, mut sxx) = (0.0, 0.0);
            // Rows without the catalogue's columns (a bare library fit) have no offset to refit.
            let x_of = |i: usize| rows[i].x.get(offset).copied().unwrap_or(0.0);
            for &i in &idx {
                let (x, w) = (x_of(i), rows[i].weight);
                sxy += w * x * res[i];
                sxx += w * x * x;
            }
            if sxx > 0.0 {
                for &i in &idx {
                    res[i] -= sxy / sxx * x_of(i);
                }
            }
        }
    }
    res.iter()
        .zip(rows)
        .map(|(e, r)| r.weight * e * e)
        .collect()
}

/// Number of |θ̇| classes per run the residual variance is estimated in.
const WEIGHT_CLASSES: usize = 3;

/// Feasible weighted least squares: the equation error's noise differs a lot between runs (a
/// 200 Hz serial capture against a 1000 Hz SD one) and grows with the speed (timestamps jitter,
/// so the angle error is ~θ̇·δt), so every row is weighted by the inverse variance of
/// `residuals` (a fit of the whole catalogue, so that a missing effect's torque is not counted
/// as noise) within its run and |θ̇| class (equal-count classes per run).
pub fn set_weights(rows: &mut [WeakRow], residuals: &[f64]) {
    let runs: std::collections::BTreeSet<usize> = rows.iter().map(|r| r.run).collect();
    for run in runs {
        let mut idx: Vec<usize> = (0..rows.len())
            .filter(|&i| {
                rows[i].run == run
                    && rows[i].theta_dot_rad_s.is_finite()
                    && residuals[i].is_finite()
            })
            .collect();
        let classes = if idx.len() >= WEIGHT_CLASSES * 15 {
            WEIGHT_CLASSES
        } else {
            1
        };
        if idx.len() < 8 {
            continue;
        }
        idx.sort_by(|&a, &b| {
            rows[a]
                .theta_dot_rad_s
                .abs()
                .total_cmp(&rows[b].theta_dot_rad_s.abs())
        });
        let n = idx.len();
        for k in 0..classes {
            let g = &idx[k * n / classes..(k + 1) * n / classes];
            let m = g.iter().map(|&i| residuals[i]).sum::<f64>() / g.len() as f64;
            let var =
                g.iter().map(|&i| (residuals[i] - m).powi(2)).sum::<f64>() / (g.len() as f64 - 1.0);
            for &i in g {
                rows[i].weight = 1.0 / var.max(1e-300);
            }
        }
    }
}

/// Adds one column per identify run but one (the reference) for the encoder's per-run zeroing
/// error: the count is zeroed at every power-on to within a few counts (rig.md), and an offset
/// θ_r adds θ_r (1 + A_y) cos θ to run r's torque. A 2-count zero error is 3e-3 m g l, as large
/// as a plausible constant dry torque, and of a different sign in each run: one global offset
/// column cannot absorb it, and what is left was mistaken for (or hid) other terms. The columns
/// are contrasts constrained so that the global offset column (`offset`) estimates the
/// precision-weighted mean of the runs' zeros, the effect `encoder_offset`: run r's zero is
/// θ + c_r, with Σ w_r c_r = 0, w_r the information run r's rows hold on its own zero
/// ([`zero_information`]: what of the offset column the reference model's damping terms and the
/// inertia column cannot take over in that run). The reference is the best-informed run, whose
/// rows carry −(w_r/w_ref) x in run r's column. (A plain mean, with the last run as reference,
/// let a run of 4 windows decide the common offset: beside an extra inertia its interval was
/// ±151 rad, while every run's free decay swung about −0.03 rad; weighting by the column's bare
/// Σ x² still left it at ±0.03 rad, because those 4 windows could not tell the run's zero from
/// its damping.)
/// Returns the new column indices (empty with fewer than two identify runs). Validate rows get
/// zeros: their own zero errors are not fitted.
pub fn add_zero_error_contrasts(rows: &mut [WeakRow], identify_runs: &[usize]) -> Vec<usize> {
    let width = rows.iter().map(|r| r.x.len()).max().unwrap_or(0);
    let Some(offset) = observation_column() else {
        return Vec::new();
    };
    let Some((info, reference)) = zero_weights(rows, identify_runs) else {
        return Vec::new();
    };
    let others: Vec<usize> = (0..identify_runs.len())
        .filter(|&j| j != reference)
        .collect();
    let w_ref = info[reference];
    let ratios: Vec<f64> = others
        .iter()
        .map(|&j| if w_ref > 0.0 { info[j] / w_ref } else { 1.0 })
        .collect();
    for r in rows.iter_mut() {
        r.x.resize(width, 0.0);
        let off = r.x[offset];
        let mut extra = vec![0.0; others.len()];
        if let Some(k) = others.iter().position(|&j| identify_runs[j] == r.run) {
            extra[k] = off;
        } else if r.run == identify_runs[reference] {
            extra
                .iter_mut()
                .zip(&ratios)
                .for_each(|(v, q)| *v = -q * off);
        }
        r.x.extend(extra);
    }
    (width..width + others.len()).collect()
}

/// The weights of [`add_zero_error_contrasts`]' constraint, one per run of `identify_runs`
/// (the information each run's rows hold on its own zero, [`zero_information`]; all 1 where
/// none holds any), and the index among them of the reference run (the best-informed; on a tie,
/// the first). `None` without runs or without the offset column.
pub fn zero_weights(rows: &[WeakRow], identify_runs: &[usize]) -> Option<(Vec<f64>, usize)> {
    let offset = observation_column()?;
    let mut info: Vec<f64> = identify_runs
        .iter()
        .map(|&q| zero_information(rows, q, offset))
        .collect();
    if info.iter().all(|w| *w <= 0.0) {
        info.iter_mut().for_each(|w| *w = 1.0);
    }
    // (`max_by` keeps the last of the reversed order.)
    let reference = (0..identify_runs.len())
        .rev()
        .max_by(|&a, &b| info[a].total_cmp(&info[b]))?;
    Some((info, reference))
}

/// The information run `run`'s rows hold on the run's own encoder zero: the part of the offset
/// column's Σ x² that the reference model's damping columns and the inertia column, fitted to
/// the same rows, leave (the residual sum of squares of the column regressed on them). 0 where
/// the run has too few rows to tell them apart.
fn zero_information(rows: &[WeakRow], run: usize, offset: usize) -> f64 {
    let others: Vec<usize> = ["viscous_linear", "viscous_quadratic", "coulomb_bearing"]
        .iter()
        .filter_map(|e| column_of(e))
        .chain(mass_column())
        .collect();
    let mine: Vec<&WeakRow> = rows.iter().filter(|r| r.run == run).collect();
    // (A column this run's rows do not hold takes nothing over.)
    let others: Vec<usize> = others
        .into_iter()
        .filter(|&c| mine.iter().any(|r| r.x.get(c).is_some_and(|v| *v != 0.0)))
        .collect();
    let y: Vec<f64> = mine
        .iter()
        .map(|r| r.x.get(offset).copied().unwrap_or(0.0))
        .collect();
    let ss: f64 = y.iter().map(|v| v * v).sum();
    if others.is_empty() {
        return ss;
    }
    if mine.len() <= others.len() {
        return 0.0;
    }
    let design: Vec<Vec<f64>> = mine
        .iter()
        .map(|r| {
            others
                .iter()
                .map(|&c| r.x.get(c).copied().unwrap_or(0.0))
                .collect()
        })
        .collect();
    match pendulum_numerics::ols(&design, &y) {
        Ok(fit) => fit.rss.clamp(0.0, ss),
        // Columns collinear among themselves in this run: count the bare column.
        Err(_) => ss,
    }
}

/// Weak-form settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WeakConfig {
    /// Test-function half-width, s.
    pub half_width_s: f64,
    /// Half-width of the local cubic giving θ̇, s.
    pub deriv_half_width_s: f64,
    /// Widest half-width it may take near a turning point, s (see [`DERIV_MIN_COUNTS`]).
    pub deriv_max_half_width_s: f64,
    /// Longest forced stretch used per run after t = 0, s.
    pub forced_s: f64,
    /// Dimensionless |θ̇| below which a sample may be stuck.
    pub stuck_theta_dot: f64,
    /// Dimensionless driving torque |(1 + A_y) sin θ| below which dry friction may hold a slow
    /// sample at rest (several times any plausible M + T_c/mgl): a window holding such a sample
    /// is left out, because the friction of a stuck stretch is static and unknown, and its
    /// gravity torque would otherwise leak into position-dependent terms.
    pub stick_torque_max: f64,
}

impl Default for WeakConfig {
    fn default() -> Self {
        Self {
            half_width_s: 0.16,
            deriv_half_width_s: 0.02,
            deriv_max_half_width_s: 0.08,
            forced_s: 60.0,
            stuck_theta_dot: 0.02,
            stick_torque_max: 0.05,
        }
    }
}

/// One encoder count (rig.md: 4096 per revolution), rad: only the scale of the widening below,
/// so a capture whose header gives other counts per revolution is not read differently.
pub(crate) const ENCODER_COUNT_RAD: f64 = std::f64::consts::TAU / 4096.0;

/// Weights giving the slope b1 (per unit x) of the least-squares cubic through 2h + 1 equally
/// spaced samples at x_j = (j − h)/h, j = 0..=2h (see where it is used).
fn cubic_slope_filter(h: usize) -> Vec<f64> {
    let xs: Vec<f64> = (0..=2 * h)
        .map(|j| (j as f64 - h as f64) / h as f64)
        .collect();
    let s = |k: i32| xs.iter().map(|x| x.powi(k)).sum::<f64>();
    let (s2, s4, s6) = (s(2), s(4), s(6));
    let det = s2 * s6 - s4 * s4;
    xs.iter().map(|x| (s6 * x - s4 * x.powi(3)) / det).collect()
}

/// Counts θ must move across the local cubic's window for its slope to be read from the motion
/// rather than from where the counts happen to change. Near a turning point θ stays within one
/// count for √(2 q / θ̈) (13 ms at 18 rad/s²): the ±20 ms cubic then saw two or three counts,
/// and the time θ̇ changed sign was wherever the last count changed, off by as much as a
/// breakaway's whole width (v_s/θ̈, 10 ms at 0.18 rad/s): the breakaway's column from
/// quantised angles was off by 0.66 of itself (`a_breakaways_column_from_encoder_counts_…`).
/// Widened until θ spans this many counts (at most `deriv_max_half_width_s`), the cubic
/// locates the turn from the counts on both sides; its slope at the turn stays nearly
/// unbiased, the motion there being nearly even in time. Nearly: dry friction steps θ̈ as θ̇
/// changes sign, and a cubic through that step turns a little late (~0.16 h T/J in θ̇), at
/// every turn alike; on exact samples of a 0.012 N·m dry torque alone (the test of
/// `sign_change_nodes`, 4 decays) a breakaway of v_s 0.05 rad/s took 1.8e-3 ± 2.5e-3 N·m
/// from it. A kink beside the cubic removed that lag but, fitted to counts, left the
/// breakaway's column off by 0.41 of itself instead of 0.11.
const DERIV_MIN_COUNTS: f64 = 12.0;

fn kernel(s: f64) -> (f64, f64) {
    // K = (1 − s²)⁴ and d²K/ds² = −8(1 − s²)³ + 48 s²(1 − s²)².
    let u = 1.0 - s * s;
    if u <= 0.0 {
        return (0.0, 0.0);
    }
    (u.powi(4), -8.0 * u.powi(3) + 48.0 * s * s * u * u)
}

/// The trapezoid rule's sum Σ K_i f_i Δt is the exact integral of the kernel interpolated
/// linearly between samples (a hat of half-width Δt about each sample) times f taken at the
/// samples. That is right for the kernel, which changes over the window, not for f, which on a
/// fast-turning run does not stay put over a hat: the gravity torque sin θ summed at its samples
/// is off by (θ̇Δt)²/12 of itself (8e-4 of m g l at 20 rad/s and 200 Hz, as large as a small
/// cogging torque), and the forcing's product A_y sin θ turns at θ̇ ± the crank's rate, which
/// makes it worse. On a run whose rotation locked to the crank that bias followed the forcing
/// phase and θ (mod 2π): a one-way F of 30 on the forcing phase of one run under a drifting
/// motor, and a 2.5e-4 N·m one-lobed position torque named beside the hidden drift. So each
/// sample's f is its hat's average: θ through the sample and its two neighbours (a quadratic),
/// the forcing at its own time, at [`HAT_NODES`] (three Gauss–Legendre points on either side,
/// weighted by the hat).
///
/// A many-lobed position torque (more than [`HAT_QUADRATURE_MAX_LOBES`] lobes) turns too fast
/// for a few points: a 58-lobe cogging torque turns its phase by 58 θ̇ Δt per 5 ms sample, a
/// whole turn near 21.7 rad/s, where its samples alias into a nearly constant torque whose
/// window sums are as large as a slow run's (a screened 58-lobe torque then raised a validate
/// run's equation error fifteen-fold on windows turning at 19–23 rad/s, where the torque itself
/// averages out). With θ linear across a hat (θ = θ_i + θ̇_i (t − t_i); its curvature moves kθ
/// by under 0.02 rad there), the hat's exact integral of e^{ikθ} is Δt e^{ikθ_i}
/// sinc²(k θ̇_i Δt / 2): the sample's value times this factor. `swept` is θ̇_i Δt, rad; 1 for a
/// term that is not periodic (`lobes` 0).
pub(crate) fn hat_factor(lobes: u32, swept: f64) -> f64 {
    let x = 0.5 * f64::from(lobes) * swept;
    if x.abs() < 1e-6 {
        return 1.0;
    }
    let sinc = x.sin() / x;
    sinc * sinc
}

/// Columns with more lobes per turn than this are integrated over a hat by [`hat_factor`]; those
/// with fewer (but at least one) by the quadrature [`HAT_NODES`] (against the exact hat integral of cos(a + b s):
/// 2.5e-12 off at b = 0.1 rad per sample, 1.0e-8 at 0.4 rad, four lobes at 20 rad/s and 200 Hz).
pub(crate) const HAT_QUADRATURE_MAX_LOBES: u32 = 4;

/// (s, w): the hat ∫(1 − |s|) f(s) ds over s ∈ [−1, 1] (samples) as Σ w f(s): three
/// Gauss–Legendre points on [0, 1] mirrored, each weighted by 1 − |s| (exact for f of degree 4
/// on either side); Σ w = 1.
const HAT_NODES: [(f64, f64); 6] = {
    // Nodes 0.5 (1 + x), x = 0, ±√(3/5); weights 8/18, 5/18 (on [0, 1]).
    const R: f64 = 0.774_596_669_241_483_4;
    const U: [f64; 3] = [0.5 * (1.0 - R), 0.5, 0.5 * (1.0 + R)];
    const W: [f64; 3] = [5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0];
    [
        (U[0], W[0] * (1.0 - U[0])),
        (U[1], W[1] * (1.0 - U[1])),
        (U[2], W[2] * (1.0 - U[2])),
        (-U[0], W[0] * (1.0 - U[0])),
        (-U[1], W[1] * (1.0 - U[1])),
        (-U[2], W[2] * (1.0 - U[2])),
    ]
};

/// (s, w, θ̇ rad/s): the hat of a sample over which θ̇ (linear between this sample's rate and
/// its neighbours') changes sign, split where it does, three Gauss–Legendre points per piece
/// weighted by the hat (Σ w = 1, exact for a term of degree ≤ 4 in s on either side of each
/// change); `None` where θ̇ keeps its sign over the hat (or a neighbour's rate is unknown).
///
/// Why: a term with sgn θ̇ in it (a dry torque, a breakaway) summed at the samples gives each
/// sample's whole hat the sample's sign, so a window holding a turning point is off by up to
/// one sample's share of the kernel, by an amount set by where the turn falls between two
/// samples: errors in the column, uncorrelated with the torque, that the dry torque's and the
/// breakaway's columns share near θ̇ = 0. Regressed on both, that shared error is charged to
/// the breakaway, whose column is small (a narrow v_s acts in a sample or two per turn): on
/// exact 200 Hz samples of a 0.012 N·m dry torque alone, a breakaway of v_s 0.05 rad/s came
/// out at −0.0106 N·m beside it (negative: impossible; the test below), and a hidden
/// breakaway of 1.08e-2 N·m was screened at −1.18e-2.
fn sign_change_nodes(
    prev: Option<f64>,
    at: Option<f64>,
    next: Option<f64>,
) -> Option<Vec<(f64, f64, f64)>> {
    let (p, w, n) = (prev?, at?, next?);
    let left = (p * w < 0.0).then(|| -w / (w - p));
    let right = (w * n < 0.0).then(|| -w / (n - w));
    if left.is_none() && right.is_none() {
        return None;
    }
    let rate = |s: f64| {
        if s < 0.0 {
            w + s * (w - p)
        } else {
            w + s * (n - w)
        }
    };
    let mut breaks = vec![-1.0];
    breaks.extend(left);
    breaks.push(0.0);
    breaks.extend(right);
    breaks.push(1.0);
    // Gauss–Legendre on [−1, 1]: nodes 0, ±√(3/5), weights 8/9, 5/9.
    const R: f64 = 0.774_596_669_241_483_4;
    const GL: [(f64, f64); 3] = [(-R, 5.0 / 9.0), (0.0, 8.0 / 9.0), (R, 5.0 / 9.0)];
    let mut nodes = Vec::with_capacity(3 * (breaks.len() - 1));
    for piece in breaks.windows(2) {
        let (lo, hi) = (piece[0], piece[1]);
        for (x, wt) in GL {
            let s = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x;
            nodes.push((s, 0.5 * (hi - lo) * wt * (1.0 - s.abs()), rate(s)));
        }
    }
    Some(nodes)
}

/// Uniform resampling of θ at the encoder's median rate; `None` entries mark gaps.
fn resample(t: &[f64], y: &[f64], t_from: f64, t_to: f64, dt: f64) -> Vec<Option<f64>> {
    let n = ((t_to - t_from) / dt).floor().max(0.0) as usize + 1;
    let mut out = Vec::with_capacity(n);
    let mut j = 0;
    for i in 0..n {
        let x = t_from + i as f64 * dt;
        while j + 1 < t.len() && t[j + 1] < x {
            j += 1;
        }
        if j + 1 >= t.len() || t[j] > x {
            out.push(None);
            continue;
        }
        let (t0, t1) = (t[j], t[j + 1]);
        if t1 - t0 > 3.5 * dt {
            out.push(None);
            continue;
        }
        let w = (x - t0) / (t1 - t0);
        out.push(Some(y[j] + w * (y[j + 1] - y[j])));
    }
    out
}

/// Builds the weak-form rows of one run: the free segment (no base motion) and the forced part
/// from t = 0 (the crank-rod model of the alignment drives A_y).
pub fn weak_rows(run_idx: usize, run: &RunData, al: &Alignment, cfg: &WeakConfig) -> Vec<WeakRow> {
    let (t, th) = (&run.enc_t_s, &run.theta_rad);
    if t.len() < 100 {
        return Vec::new();
    }
    let mut dts: Vec<f64> = t
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 0.0)
        .collect();
    dts.sort_by(f64::total_cmp);
    let dt = dts[dts.len() / 2];
    let w0 = run.rig.omega0_rad_s();
    let lambda = run.rig.crank_r_m / run.rig.rod_l_m;
    let omega = 2.0 * std::f64::consts::PI * al.omega_hz / w0;
    // dω/dt, dimensionless (zero unless the run was re-aligned on a drifting speed).
    let omega_dot = 2.0 * std::f64::consts::PI * al.speed_drift_hz_per_s / (w0 * w0);
    let r_over_l = run.rig.crank_r_m / run.rig.l_m;
    let factors = si_factors(&run.rig);
    let torque_factor = 1.0 / (run.rig.m_kg * run.rig.g_m_s2 * run.rig.l_m);
    // Forcing in the aligned dimensionless time (φ = ωt + ½ω̇t²), and its rate.
    let ay_at = |tt: f64| -> (f64, f64) {
        let phi = omega * tt + 0.5 * omega_dot * tt * tt;
        let rate = omega + omega_dot * tt;
        (
            r_over_l * (rate * rate * crank_f2(phi, lambda) + omega_dot * crank_f1(phi, lambda)),
            phi,
        )
    };
    let forcing = |tau: f64| -> (f64, f64, f64) {
        let tt = tau * w0;
        let (ay, phi) = ay_at(tt);
        let h = 1e-4;
        let d = (ay_at(tt + h).0 - ay_at(tt - h).0) / (2.0 * h);
        (ay, d, phi.rem_euclid(2.0 * std::f64::consts::PI))
    };
    let mut rows = Vec::new();
    let spans = [
        (
            al.free_segment_s.0 - al.t0_s,
            al.free_segment_s.1 - al.t0_s,
            false,
        ),
        (0.0, (t[t.len() - 1] - al.t0_s).min(cfg.forced_s), true),
    ];
    let hw = cfg.half_width_s;
    let hd = ((cfg.deriv_half_width_s / dt).round() as usize).max(2);
    for (a, b, forced) in spans {
        if b - a < 4.0 * hw {
            continue;
        }
        let grid = resample(t, th, al.t0_s + a, al.t0_s + b, dt);
        let n = grid.len();
        // θ̇ (rad/s) by a local cubic: least-squares slope over ±hd samples, widened (up to
        // `deriv_max_half_width_s`) where θ moves by fewer than `DERIV_MIN_COUNTS` encoder
        // counts across the window: near a turning point.
        let hd_max = ((cfg.deriv_max_half_width_s / dt).round() as usize).max(hd);
        let window = |i: usize, h: usize| -> Option<Vec<f64>> {
            if i < h {
                return None;
            }
            grid.get(i - h..=i + h)?.iter().copied().collect()
        };
        // The window's spread alone decides the width, so the cubic is fitted once, at the
        // final width. On a symmetric grid its slope is a fixed filter of the window
        // (Savitzky–Golay): the odd part alone, b1 = Σ w_j θ_j with w_j = (S6 x_j − S4 x_j³) /
        // (S2 S6 − S4²), S_k = Σ x_j^k, x_j = (j − h)/h; the same number a least-squares
        // cubic through the window gives, without a fit per sample and per width tried.
        let mut filters: Vec<(usize, Vec<f64>)> = Vec::new();
        let mut thd = vec![None; n];
        for (i, slot) in thd
            .iter_mut()
            .enumerate()
            .take(n.saturating_sub(hd))
            .skip(hd)
        {
            let mut h = hd;
            let mut chosen = None;
            while let Some(win) = window(i, h) {
                let (lo, hi) = win
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                        (a.min(v), b.max(v))
                    });
                let done = hi - lo >= DERIV_MIN_COUNTS * ENCODER_COUNT_RAD || h >= hd_max;
                chosen = Some((h, win));
                if done {
                    break;
                }
                h = (2 * h).min(hd_max);
            }
            let Some((h, win)) = chosen else {
                continue;
            };
            let w = match filters.iter().position(|(hh, _)| *hh == h) {
                Some(k) => &filters[k].1,
                None => {
                    filters.push((h, cubic_slope_filter(h)));
                    &filters[filters.len() - 1].1
                }
            };
            let b1: f64 = w.iter().zip(&win).map(|(a, b)| a * b).sum();
            *slot = Some(b1 / (h as f64 * dt));
        }
        let half = (hw / dt).round() as usize;
        let h_dimless = hw * w0;
        let mut c = half + hd;
        while c + half + hd < n {
            let range = c - half..=c + half;
            let ok = range.clone().all(|i| grid[i].is_some() && thd[i].is_some());
            if !ok {
                c += 2 * half;
                continue;
            }
            let may_stick = range.clone().any(|i| {
                let tau = a + i as f64 * dt;
                let ay = if forced { forcing(tau).0 } else { 0.0 };
                (thd[i].unwrap_or(0.0) / w0).abs() < cfg.stuck_theta_dot
                    && ((1.0 + ay) * grid[i].unwrap_or(0.0).sin()).abs() < cfg.stick_torque_max
            });
            // A window still from end to end is at rest wherever it sits: its friction is
            // static and unknown, whatever angle the encoder reports. (An encoder zeroed 0.079
            // rad off the hanging position put seven resting runs past `stick_torque_max`, and
            // their still windows, each asking for a torque of 0.079 m g l, were explained by a
            // breakaway, a position torque and a negative dry torque before the offset.)
            let still = range
                .clone()
                .all(|i| (thd[i].unwrap_or(0.0) / w0).abs() < cfg.stuck_theta_dot);
            if may_stick || still {
                c += 2 * half;
                continue;
            }
            let mut target = 0.0;
            let mut x = vec![0.0; width()];
            let mut speeds = Vec::with_capacity(2 * half + 1);
            let mut lib = vec![0.0; crate::sparse::LIBRARY.len()];
            let th_c = grid[c].unwrap_or(0.0);
            let dtt = dt * w0; // dimensionless step
            for i in range.clone() {
                let s = (i as f64 - c as f64) / half as f64;
                let (k, k2) = kernel(s);
                let wgt = if i == c - half || i == c + half {
                    0.5
                } else {
                    1.0
                };
                let th_i = grid[i].unwrap_or(0.0);
                let w = thd[i].unwrap_or(0.0) / w0;
                let tau = a + i as f64 * dt;
                let (ay, ay_dot, phase_i) = if forced {
                    forcing(tau)
                } else {
                    (0.0, 0.0, f64::NAN)
                };
                let kk = k * wgt * dtt;
                // ∫K''θ dt with d²/dt² = (1/h²) d²/ds², about the window's centre value: ∫K'' = 0
                // exactly, but not its discrete sum, which would multiply a rotating run's
                // unwrapped angle (tens of rad) into the result.
                let theta_dd = k2 / (h_dimless * h_dimless) * (th_i - th_c) * wgt * dtt;
                target -= theta_dd;
                // The gravity torque and every term periodic in θ over this sample's hat (see
                // `HAT_NODES`): θ through its two neighbours (a quadratic), the forcing where it
                // is. (The rest, smooth on a sample's scale, at the sample: as the shaped
                // columns are, so that a breakaway's column at a large v_s stays the constant
                // dry torque's.)
                let (Some(th_prev), Some(th_next)) = (grid[i - 1], grid[i + 1]) else {
                    unreachable!("θ̇ at a sample needs its neighbours");
                };
                let slope = 0.5 * (th_next - th_prev); // rad per step
                let curve = th_next - 2.0 * th_i + th_prev; // rad per step²
                let mut lv = [0.0; crate::sparse::LIBRARY.len()];
                for &(s_hat, w_hat) in &HAT_NODES {
                    let th_s = th_i + s_hat * (slope + 0.5 * s_hat * curve);
                    let w_s = w + s_hat * curve / dt / w0;
                    let tau_s = tau + s_hat * dt;
                    let (ay, ay_dot, phase_s) = if forced {
                        forcing(tau_s)
                    } else {
                        (0.0, 0.0, f64::NAN)
                    };
                    let kw = kk * w_hat;
                    target -= kw * (1.0 + ay) * th_s.sin();
                    let l = crate::sparse::library_values(th_s, w_s * w0, phase_s, tau_s, ay);
                    for ((acc, v), term) in lv.iter_mut().zip(l).zip(&crate::sparse::LIBRARY) {
                        if term.lobes > 0 {
                            *acc += w_hat * v;
                        }
                    }
                    let sample = WeakSample {
                        theta: th_s,
                        theta_dot: w_s,
                        a_y: ay,
                        a_y_dot: ay_dot,
                    };
                    for (xi, col) in x.iter_mut().zip(columns()) {
                        if (1..=HAT_QUADRATURE_MAX_LOBES).contains(&col.reg.lobes) {
                            *xi += kw * (col.reg.term)(&sample);
                        }
                    }
                }
                // The terms that are not periodic in θ (functions of θ̇, A_y, time): at the
                // sample, or, where θ̇ changes sign within the sample's hat, over the hat split
                // at the change (see `sign_change_nodes`).
                let crossing = sign_change_nodes(thd[i - 1], thd[i], thd[i + 1]);
                let nodes: &[(f64, f64, f64)] = match &crossing {
                    Some(nodes) => nodes,
                    None => &[(0.0, 1.0, thd[i].unwrap_or(0.0))],
                };
                let mut smooth = [0.0; crate::sparse::LIBRARY.len()];
                for &(s_hat, w_hat, rate) in nodes {
                    let (th_s, tau_s) = (
                        th_i + s_hat * (slope + 0.5 * s_hat * curve),
                        tau + s_hat * dt,
                    );
                    let (ay_s, ay_dot_s, phase_s) = if s_hat == 0.0 {
                        (ay, ay_dot, phase_i)
                    } else if forced {
                        forcing(tau_s)
                    } else {
                        (0.0, 0.0, f64::NAN)
                    };
                    speeds.push((kk * w_hat * torque_factor, rate));
                    let l = crate::sparse::library_values(th_s, rate, phase_s, tau_s, ay_s);
                    for (acc, v) in smooth.iter_mut().zip(l) {
                        *acc += w_hat * v;
                    }
                    let sample = WeakSample {
                        theta: th_s,
                        theta_dot: rate / w0,
                        a_y: ay_s,
                        a_y_dot: ay_dot_s,
                    };
                    for (xi, col) in x.iter_mut().zip(columns()) {
                        if col.reg.lobes == 0 {
                            *xi += kk * w_hat * (col.reg.term)(&sample);
                        }
                    }
                }
                for (((li, v), v0), term) in lib
                    .iter_mut()
                    .zip(lv)
                    .zip(smooth)
                    .zip(&crate::sparse::LIBRARY)
                {
                    *li += kk * torque_factor * if term.lobes > 0 { v } else { v0 };
                }
                // A many-lobed torque (no forcing in it) over the hat exactly, θ linear.
                let sample = WeakSample {
                    theta: th_i,
                    theta_dot: w,
                    a_y: ay,
                    a_y_dot: ay_dot,
                };
                let swept = thd[i].unwrap_or(0.0) * dt;
                for (xi, col) in x.iter_mut().zip(columns()) {
                    if col.reg.lobes > HAT_QUADRATURE_MAX_LOBES {
                        *xi += kk * (col.reg.term)(&sample) * hat_factor(col.reg.lobes, swept);
                    }
                }
            }
            let tau_c = a + c as f64 * dt;
            let (_, _, phase) = if forced {
                forcing(tau_c)
            } else {
                (0.0, 0.0, f64::NAN)
            };
            let ta = al.t0_s + tau_c;
            for (xi, f) in x.iter_mut().zip(&factors) {
                *xi *= f;
            }
            let ia = run
                .acc_t_s
                .partition_point(|&v| v < ta)
                .min(run.acc_t_s.len().saturating_sub(1));
            rows.push(WeakRow {
                run: run_idx,
                tau_s: tau_c,
                theta: grid[c].unwrap_or(f64::NAN),
                theta_dot_rad_s: thd[c].unwrap_or(f64::NAN),
                phase: if forced { phase } else { f64::NAN },
                a_y_meas: run
                    .az_m_s2
                    .get(ia)
                    .map_or(f64::NAN, |v| v - al.az_offset_m_s2),
                a_x_meas: run.ax_m_s2.get(ia).copied().unwrap_or(f64::NAN),
                target,
                x,
                weight: 1.0,
                bob_inertia_kg_m2: run.rig.m_kg * run.rig.l_m * run.rig.l_m,
                lib,
                speeds: std::sync::Arc::new(speeds),
            });
            c += 2 * half;
        }
    }
    for s in shaped_columns() {
        set_shape(&mut rows, s.col, s.shape.default);
    }
    rows
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use pendulum_model::Dimensionless;
    use pendulum_process::RigParams;

    /// The study's rig (rig.md), turning the crank at 1.5 Hz.
    pub(crate) fn study_rig() -> RigParams {
        RigParams {
            m_kg: 1.46,
            l_m: 0.265,
            crank_r_m: 0.0725,
            rod_l_m: 0.575,
            r_b_m: 0.01225,
            omega_hz: Some(1.5),
            g_m_s2: 9.81,
        }
    }

    /// On an exact free decay with viscous + bearing friction, the weak-form regression returns
    /// β and M (an independent check of the integration by parts and the scalings).
    #[test]
    fn weak_form_recovers_free_decay_damping() {
        let rig = study_rig();
        let w0 = rig.omega0_rad_s();
        let mut d = Dimensionless::conservative();
        d.beta = 0.05;
        d.m_coulomb = 0.007;
        let (run, al) = super::shaped_tests::decay(&rig, d, 2.0, 20.0);
        // The old default half-width and the current one.
        for hw in [0.08, 0.16] {
            let cfg = WeakConfig {
                half_width_s: hw,
                ..WeakConfig::default()
            };
            let rows = weak_rows(0, &run, &al, &cfg);
            assert!(rows.len() > 30, "h = {hw}: {} rows", rows.len());
            // The coefficients are SI: b = β m ω0, μ = M l/r_b, J = j m l².
            let inertia = mass_column().unwrap();
            let fit = crate::screen::ols(&rows, &[0, 2, inertia]).unwrap();
            let (b, _) = fit.coef_of(0).unwrap();
            let (mu, _) = fit.coef_of(2).unwrap();
            let (j, _) = fit.coef_of(inertia).unwrap();
            let (b_true, mu_true) = (0.05 * rig.m_kg * w0, 0.007 * rig.l_m / rig.r_b_m);
            assert!(
                (b / b_true - 1.0).abs() < 0.04,
                "h = {hw}: b {b} vs {b_true}"
            );
            assert!(
                (mu / mu_true - 1.0).abs() < 0.07,
                "h = {hw}: mu {mu} vs {mu_true}"
            );
            let bob = rig.m_kg * rig.l_m * rig.l_m;
            assert!(j.abs() < 0.01 * bob, "h = {hw}: J {j}");
        }
    }
}

#[cfg(test)]
mod lobe_tests {
    use super::*;
    use pendulum_process::Role;

    /// A run turning steadily at `w` rad/s, sampled at 200 Hz (the serial format's rate), as a
    /// free segment of 3 s.
    fn turning(w: f64) -> (RunData, Alignment) {
        let rig = super::tests::study_rig();
        let (mut run, mut al) = super::shaped_tests::decay(
            &rig,
            pendulum_model::Dimensionless::conservative(),
            0.1,
            3.0,
        );
        run.role = Role::Identify;
        run.enc_t_s = (0..=600).map(|i| i as f64 * 0.005).collect();
        run.theta_rad = run.enc_t_s.iter().map(|t| 0.3 + w * t).collect();
        al.free_segment_s = (0.0, 3.0);
        (run, al)
    }

    /// A run still from end to end gives no rows, wherever its encoder says it rests: its
    /// friction is static and unknown. Resting at 0.08 rad (an encoder zeroed off the hanging
    /// position, past `stick_torque_max`), its windows asked for a torque of 0.08 m g l.
    #[test]
    fn a_still_run_gives_no_rows_wherever_its_encoder_says_it_rests() {
        let cfg = WeakConfig::default();
        let (moving, al) = turning(1.0);
        assert!(!weak_rows(0, &moving, &al, &cfg).is_empty());
        for theta in [0.0, 0.08, -0.3, 2.0] {
            let mut run = moving.clone();
            run.theta_rad.iter_mut().for_each(|v| *v = theta);
            let rows = weak_rows(0, &run, &al, &cfg);
            assert!(
                rows.is_empty(),
                "at rest at {theta} rad: {} rows",
                rows.len()
            );
        }
    }

    /// The gravity torque in the target is integrated over each sample's hat (the kernel
    /// linear between samples, θ as it is): on a run turning at 20 rad/s, sampled every 5 ms,
    /// the sum of its samples alone is off by (θ̇Δt)²/12 of it, a bias that follows θ.
    #[test]
    fn the_gravity_torque_of_a_fast_turning_run_is_integrated_over_each_samples_hat() {
        let cfg = WeakConfig::default();
        for w in [20.0, 8.0, 0.5] {
            let (run, al) = turning(w);
            let rows = weak_rows(0, &run, &al, &cfg);
            assert!(rows.len() >= 5, "{} rows", rows.len());
            let dt = 0.005;
            let dtt = dt * run.rig.omega0_rad_s();
            let half = (cfg.half_width_s / dt).round() as i64;
            let (mut worst, mut worst_samples, mut scale) = (0.0f64, 0.0f64, 0.0f64);
            for r in &rows {
                let (mut exact, mut samples) = (0.0, 0.0);
                for j in -half..=half {
                    let (kern, _) = kernel(j as f64 / half as f64);
                    let wgt = if j.abs() == half { 0.5 } else { 1.0 };
                    let kk = kern * wgt * dtt;
                    let th_i = 0.3 + w * (al.t0_s + r.tau_s + j as f64 * dt);
                    // The hat's average of sin θ by a 2000-point midpoint rule.
                    let n = 2000;
                    let avg: f64 = (0..n)
                        .map(|m| {
                            let s = -1.0 + (m as f64 + 0.5) * 2.0 / n as f64;
                            (1.0 - s.abs()) * (th_i + w * s * dt).sin() * 2.0 / n as f64
                        })
                        .sum();
                    exact -= kk * avg;
                    samples -= kk * th_i.sin();
                    scale = scale.max(kk.abs());
                }
                worst = worst.max((r.target - exact).abs());
                worst_samples = worst_samples.max((samples - exact).abs());
            }
            let scale = scale * 2.0 * half as f64;
            assert!(
                worst < 2e-6 * scale,
                "ω {w} rad/s: target off the hat integral by {worst:.3e} (scale {scale:.3e})"
            );
            if w >= 20.0 {
                // What the samples alone would give: the check above can tell.
                assert!(
                    worst_samples > 1e-4 * scale,
                    "ω {w} rad/s: the samples alone are only {worst_samples:.3e} off"
                );
            }
        }
    }

    /// A many-lobed position torque's columns on a fast-turning run are the window integrals
    /// of sin kθ and cos kθ (here by a 200-fold finer quadrature of the exact θ), not the
    /// aliased sum of their samples; on a slow run they are unchanged to the trapezoid's order.
    #[test]
    fn a_many_lobed_column_is_integrated_not_aliased_on_a_fast_run() {
        use pendulum_model::effects::by_name;
        let pos = by_name("position_torque").unwrap();
        let cfg = WeakConfig::default();
        // 21.7 rad/s turns a 58-lobe term by 2π + 0.01 rad per 5 ms sample: its samples alone
        // would read as a nearly constant torque.
        for (w, k) in [(21.7, 58u32), (20.0, 58), (20.0, 17), (1.0, 58), (0.3, 64)] {
            let (run, al) = turning(w);
            let rows = weak_rows(0, &run, &al, &cfg);
            assert!(rows.len() >= 5, "{} rows", rows.len());
            let w0 = run.rig.omega0_rad_s();
            let dt = 0.005;
            let half = (cfg.half_width_s / dt).round() as usize;
            let cols: Vec<usize> = (0..columns().len())
                .filter(|&i| {
                    columns()[i].effect.name() == pos.name() && columns()[i].reg.lobes == k
                })
                .collect();
            assert_eq!(cols.len(), 2);
            for r in &rows {
                for &ci in &cols {
                    let col = columns()[ci];
                    let factor = si_factors(&run.rig)[ci];
                    // The exact window integral: θ linear, kernel over the window's span.
                    let n = 200 * 2 * half;
                    let h = 2.0 * half as f64 * dt / n as f64;
                    let (t_lo, t_c) = (r.tau_s - half as f64 * dt, r.tau_s);
                    let mut exact = 0.0;
                    let mut scale = 0.0;
                    for j in 0..=n {
                        let t = t_lo + j as f64 * h;
                        let (kern, _) = kernel((t - t_c) / (half as f64 * dt));
                        let wgt = if j == 0 || j == n { 0.5 } else { 1.0 };
                        let th = 0.3 + w * (t + al.t0_s);
                        let s = WeakSample {
                            theta: th,
                            theta_dot: w / w0,
                            a_y: 0.0,
                            a_y_dot: 0.0,
                        };
                        exact += kern * wgt * h * w0 * (col.reg.term)(&s) * factor;
                        scale += kern * wgt * h * w0 * factor;
                    }
                    let err = (r.x[ci] - exact).abs();
                    assert!(
                        err < 0.01 * scale,
                        "ω {w} rad/s, k {k}, column {}: {:.4e} against the integral {exact:.4e} (scale {scale:.4e})",
                        col.reg.name,
                        r.x[ci]
                    );
                }
            }
        }
    }
    /// Why a many-lobed torque's size is read from the trajectories (`discover`): on an exact
    /// free decay sampled at 200 Hz (the serial format's rate), the equation error reads a
    /// 61-lobe cogging torque to within 2 % from the exact angle, but well low from the same
    /// angle rounded to the encoder's 4096 counts. Its swings under such a torque differ from
    /// those without it by less than a count near the turning points, where its columns are
    /// large, and the rounding erases that detail from the target (not from the columns: the
    /// columns from the rounded angle beside the exact target read it right). A torque of a few
    /// lobes is read right through the counts.
    #[test]
    fn a_many_lobed_torque_reads_low_through_the_encoders_counts() {
        use pendulum_model::effects::by_name;
        let rig = super::tests::study_rig();
        let mgl = rig.m_kg * rig.g_m_s2 * rig.l_m;
        let pos = by_name("position_torque").unwrap();
        let t_p_nm = 0.017;
        let read = |k: u32, counts: bool, counts_in_columns_only: bool| -> f64 {
            let mut d = pendulum_model::Dimensionless::conservative();
            d.beta = 0.02;
            d.p = t_p_nm / mgl;
            d.k = k;
            d.phi_p = 1.79;
            let (mut run, al) = super::shaped_tests::decay_sampled(&rig, d, 3.0, 20.0, 0.005);
            run.role = pendulum_process::Role::Identify;
            let cfg = WeakConfig::default();
            let exact = weak_rows(0, &run, &al, &cfg);
            let q = ENCODER_COUNT_RAD;
            run.theta_rad
                .iter_mut()
                .for_each(|v| *v = (*v / q).round() * q);
            let rounded = weak_rows(0, &run, &al, &cfg);
            assert_eq!(exact.len(), rounded.len());
            let rows: Vec<WeakRow> = if !counts {
                exact
            } else if counts_in_columns_only {
                rounded
                    .into_iter()
                    .zip(&exact)
                    .map(|(mut r, e)| {
                        r.target = e.target;
                        r
                    })
                    .collect()
            } else {
                rounded
            };
            let cols: Vec<usize> = (0..columns().len())
                .filter(|&i| {
                    columns()[i].effect.name() == pos.name() && columns()[i].reg.lobes == k
                })
                .collect();
            let fit = crate::screen::ols(&rows, &[0, cols[0], cols[1]]).unwrap();
            let (a, _) = fit.coef_of(cols[0]).unwrap();
            let (b, _) = fit.coef_of(cols[1]).unwrap();
            a.hypot(b) / t_p_nm
        };
        let exact = read(61, false, false);
        assert!((exact - 1.0).abs() < 0.02, "61 lobes, exact angle: {exact}");
        let rounded = read(61, true, false);
        assert!(rounded < 0.85, "61 lobes, rounded angle: {rounded}");
        let columns_only = read(61, true, true);
        assert!(
            (columns_only - 1.0).abs() < 0.02,
            "61 lobes, rounded columns only: {columns_only}"
        );
        let few = read(2, true, false);
        assert!((few - 1.0).abs() < 0.03, "2 lobes, rounded angle: {few}");
    }
}

#[cfg(test)]
mod shaped_tests {
    use super::*;
    use pendulum_model::{simulate, Dimensionless, Excitation, Model, SimOptions};
    use pendulum_process::{RigParams, Role};

    /// A free decay of an exact model (1 kHz, no noise) as a run with its alignment (the shaker
    /// starts 10 s after it).
    pub(super) fn decay(
        rig: &RigParams,
        d: Dimensionless,
        theta0: f64,
        dur_s: f64,
    ) -> (RunData, Alignment) {
        decay_sampled(rig, d, theta0, dur_s, 0.001)
    }

    /// A free decay from rest at `theta0` rad, its angle exact at every `dt_s`.
    pub(super) fn decay_sampled(
        rig: &RigParams,
        d: Dimensionless,
        theta0: f64,
        dur_s: f64,
        dt_s: f64,
    ) -> (RunData, Alignment) {
        let w0 = rig.omega0_rad_s();
        let tr = simulate(
            &Model::with_excitation(d, Excitation::None),
            &SimOptions::with_tol(1e-10),
            [theta0, 0.0],
            0.0,
            dur_s * w0,
            dt_s * w0,
        )
        .unwrap();
        let run = RunData {
            id: "x".into(),
            role: Role::Identify,
            rig: rig.clone(),
            enc_t_s: tr.t.iter().map(|t| t / w0).collect(),
            theta_rad: tr.theta.clone(),
            acc_t_s: vec![],
            az_m_s2: vec![],
            ax_m_s2: vec![],
        };
        let al = Alignment {
            kind: pendulum_process::align::AlignmentKind::Shaker,
            omega0_est_rad_s: f64::NAN,
            shaker_start_s: dur_s + 10.0,
            free_segment_s: (0.0, dur_s - 0.1),
            t0_s: dur_s + 5.0,
            t0_sigma_s: 0.0,
            omega_hz: 1.5,
            omega_sigma_hz: 0.0,
            accel_gain: 1.0,
            az_offset_m_s2: 9.81,
            residual_rms_m_s2: 0.0,
            fit_window_s: (0.0, 0.0),
            speed_drift_hz_per_s: 0.0,
            accel_noise_m_s2: f64::NAN,
            forcing_residual_rms_m_s2: f64::NAN,
        };
        (run, al)
    }

    pub(super) fn rig(m_kg: f64, l_m: f64) -> RigParams {
        RigParams {
            m_kg,
            l_m,
            crank_r_m: 0.0725,
            rod_l_m: 0.575,
            r_b_m: 0.01225,
            omega_hz: Some(1.5),
            g_m_s2: 9.81,
        }
    }

    /// A generator's dead band and load, from two exact free decays of different bobs (the
    /// shaped column is in SI, so the runs pool): the profile finds ω_d and the regression c_g,
    /// each within 2 %, and a wrong band fits clearly worse.
    #[test]
    fn generator_band_and_load_from_the_profile() {
        let (c_g, w_d, b) = (0.02, 3.0, 0.3);
        let mut rows = Vec::new();
        for (i, (m, l)) in [(1.46, 0.265), (0.745, 0.2)].into_iter().enumerate() {
            let rg = rig(m, l);
            let w0 = rg.omega0_rad_s();
            let mut d = Dimensionless::conservative();
            d.beta = b / (m * w0);
            d.gen_c = c_g * w0 / (m * 9.81 * l);
            d.gen_w = w_d / w0;
            let (run, al) = decay(&rg, d, 2.6, 25.0);
            rows.extend(weak_rows(i, &run, &al, &WeakConfig::default()));
        }
        assert!(rows.len() > 60, "{} rows", rows.len());
        let gen = shaped_column("generator_rectified").unwrap();
        let cols = [0, gen];
        let (shape, fit) = crate::screen::profile_shape(&rows, &cols, gen).unwrap();
        let (c, _) = fit.coef_of(gen).unwrap();
        let (bb, _) = fit.coef_of(0).unwrap();
        assert!((shape / w_d - 1.0).abs() < 0.02, "ω_d {shape} vs {w_d}");
        assert!((c / c_g - 1.0).abs() < 0.02, "c_g {c} vs {c_g}");
        assert!((bb / b - 1.0).abs() < 0.05, "b {bb} vs {b}");
        let mut wrong = rows.clone();
        set_shape(&mut wrong, gen, 1.5);
        let worse = crate::screen::ols(&wrong, &cols).unwrap();
        assert!(worse.rss > 4.0 * fit.rss, "{} vs {}", worse.rss, fit.rss);
    }

    /// Stribeck's breakaway from an exact decay with bearing friction. The breakaway acts at
    /// each turning point for about 2 v_s/|θ''|, tens of ms, far shorter than a window: a smooth
    /// kernel sees the antisymmetric torque only through its first moment, T_s (v_s/θ'')², so
    /// the equation error measures T_s v_s² (the energy it takes per turning point, as the
    /// envelope does) and pins v_s alone only weakly. The product comes back within 10 %; a
    /// constant dry torque describes the same rows clearly worse (they are told apart).
    #[test]
    fn stribeck_breakaway_energy_from_the_profile() {
        let (t_s, v_s, mu) = (0.02, 0.4, 0.1);
        let rg = rig(1.46, 0.265);
        let w0 = rg.omega0_rad_s();
        let mut d = Dimensionless::conservative();
        d.m_coulomb = mu * rg.r_b_m / rg.l_m;
        d.s_break = t_s / (1.46 * 9.81 * 0.265);
        d.v_break = v_s / w0;
        let (run, al) = decay(&rg, d, 2.9, 30.0);
        let rows = weak_rows(0, &run, &al, &WeakConfig::default());
        let stribeck = shaped_column("stribeck").unwrap();
        let cols = [2, stribeck];
        let (shape, fit) = crate::screen::profile_shape(&rows, &cols, stribeck).unwrap();
        let (t, _) = fit.coef_of(stribeck).unwrap();
        let energy = t * shape * shape;
        assert!(
            (energy / (t_s * v_s * v_s) - 1.0).abs() < 0.10,
            "T_s v_s² {energy} vs {} (v_s {shape}, T_s {t})",
            t_s * v_s * v_s
        );
        let constant = crate::screen::ols(&rows, &[2, 4]).unwrap();
        assert!(
            constant.rss > 2.0 * fit.rss,
            "{} vs {}",
            constant.rss,
            fit.rss
        );
    }
}

#[cfg(test)]
mod turn_tests {
    use super::shaped_tests::decay_sampled;
    use super::*;
    use pendulum_model::Dimensionless;

    /// A constant dry torque alone, sampled exactly at the serial format's 200 Hz: its column
    /// and a narrow breakaway's share every turning point. With each sample's sign standing
    /// for its whole hat, each turn's error depended on where the turn fell between two
    /// samples, and the breakaway, whose column lives at the turns, took it up: T_s came out
    /// −0.0106 ± 0.0006 N·m beside T_c 0.012 at v_s 0.05 rad/s, −0.0061 at 0.1, −0.0008 at
    /// 0.2. Integrated over the hat split where θ̇ changes sign, the dry torque comes back
    /// alone (T_s 4e-4, 5e-5, −1e-6).
    #[test]
    fn a_dry_torque_sampled_at_200_hz_is_not_read_as_a_breakaway_at_its_turns() {
        let rg = super::shaped_tests::rig(1.46, 0.265);
        let t_c = 0.012;
        let mut d = Dimensionless::conservative();
        d.c = t_c / (rg.m_kg * rg.g_m_s2 * rg.l_m);
        d.beta = 0.02;
        // θ̇ from the fixed cubic, as the samples are exact (no counts to widen it for; see
        // `DERIV_MIN_COUNTS` for what widening costs here).
        let cfg = WeakConfig {
            deriv_max_half_width_s: WeakConfig::default().deriv_half_width_s,
            ..WeakConfig::default()
        };
        let mut rows = Vec::new();
        for (i, th0) in [2.9, 2.3, 1.7, 1.1].into_iter().enumerate() {
            let (run, al) = decay_sampled(&rg, d, th0, 30.0, 0.005);
            rows.extend(weak_rows(i, &run, &al, &cfg));
        }
        let stribeck = shaped_column("stribeck").unwrap();
        let cc = column_of("coulomb_constant").unwrap();
        let visc = column_of("viscous_linear").unwrap();
        for v_s in [0.05, 0.1, 0.2] {
            set_shape(&mut rows, stribeck, v_s);
            let fit = crate::screen::ols(&rows, &[visc, cc, stribeck]).unwrap();
            let (t, _) = fit.coef_of(cc).unwrap();
            let (s, s_se) = fit.coef_of(stribeck).unwrap();
            assert!((t / t_c - 1.0).abs() < 0.005, "v_s {v_s}: T_c {t}");
            assert!(
                s.abs() < 0.05 * t_c,
                "v_s {v_s}: T_s {s} ± {s_se} beside T_c {t}"
            );
        }
    }
}

#[cfg(test)]
mod count_tests {
    use super::shaped_tests::decay_sampled;
    use super::*;
    use pendulum_model::Dimensionless;

    /// The slope filter is the least-squares cubic's slope, whatever the window holds: checked
    /// against a cubic fitted by the numerics crate's least squares, for every width the
    /// widening can take at 200 Hz, on windows that are not cubic.
    #[test]
    fn the_slope_filter_is_the_least_squares_cubics_slope() {
        for h in [4usize, 8, 16] {
            let w = cubic_slope_filter(h);
            let ys: Vec<f64> = (0..=2 * h)
                .map(|j| (0.37 * j as f64).sin() + 0.01 * (j * j) as f64 + (j % 3) as f64)
                .collect();
            let rows: Vec<Vec<f64>> = (0..=2 * h)
                .map(|j| {
                    let x = (j as f64 - h as f64) / h as f64;
                    vec![1.0, x, x * x, x * x * x]
                })
                .collect();
            let fit = pendulum_numerics::ols(&rows, &ys).unwrap();
            let b1: f64 = w.iter().zip(&ys).map(|(a, b)| a * b).sum();
            assert!(
                (b1 - fit.coef[1]).abs() < 1e-10 * fit.coef[1].abs().max(1.0),
                "h {h}: filter {b1}, least squares {}",
                fit.coef[1]
            );
        }
    }

    /// The regressors from angles quantised to the encoder's 4096 counts at the serial
    /// format's 200 Hz against the same regressors from exact angles, window by window, on
    /// free decays with a breakaway (0.011 N·m at v_s 0.178 rad/s) beside a dry torque. The
    /// breakaway's column lives within v_s/θ̈ (10 ms) of each turn, where θ stays within one
    /// count for 13 ms: with θ̇ from a fixed ±20 ms cubic its rms error over the windows was
    /// 0.66 of the column's own rms (an errors-in-variables regression shrinks such a
    /// coefficient towards 0 and hands the rest to the dry torque's column, which shares the
    /// errors at θ̇ = 0), and the dry torque's 0.0086. With the cubic widened near the turns
    /// to span `DERIV_MIN_COUNTS` (at most ±80 ms): 0.11 and 0.0025 (±40 ms: 0.32, 0.0048).
    #[test]
    fn a_breakaways_column_from_encoder_counts_follows_the_exact_one() {
        let rg = super::shaped_tests::rig(1.46, 0.265);
        let w0 = rg.omega0_rad_s();
        let mgl = rg.m_kg * rg.g_m_s2 * rg.l_m;
        let mut d = Dimensionless::conservative();
        d.c = 0.004 / mgl;
        d.beta = 0.02;
        d.s_break = 0.011 / mgl;
        d.v_break = 0.178 / w0;
        let stribeck = shaped_column("stribeck").unwrap();
        let cc = column_of("coulomb_constant").unwrap();
        let (mut err, mut size, mut err_c, mut size_c) = (0.0, 0.0, 0.0, 0.0);
        for (i, th0) in [2.9, 2.3, 1.7, 1.1].into_iter().enumerate() {
            let (mut run, al) = decay_sampled(&rg, d, th0, 30.0, 0.005);
            let mut exact = weak_rows(i, &run, &al, &WeakConfig::default());
            for th in run.theta_rad.iter_mut() {
                *th = ((*th / ENCODER_COUNT_RAD).floor() + 0.5) * ENCODER_COUNT_RAD;
            }
            let mut counted = weak_rows(i, &run, &al, &WeakConfig::default());
            set_shape(&mut exact, stribeck, 0.178);
            set_shape(&mut counted, stribeck, 0.178);
            assert_eq!(exact.len(), counted.len());
            for (a, b) in exact.iter().zip(&counted) {
                assert_eq!(a.tau_s, b.tau_s);
                err += (a.x[stribeck] - b.x[stribeck]).powi(2);
                size += a.x[stribeck].powi(2);
                err_c += (a.x[cc] - b.x[cc]).powi(2);
                size_c += a.x[cc].powi(2);
            }
        }
        let (rel, rel_c) = ((err / size).sqrt(), (err_c / size_c).sqrt());
        assert!(rel < 0.2, "breakaway column off by {rel} of itself");
        assert!(rel_c < 0.004, "dry torque column off by {rel_c} of itself");
    }
}

/// A row of unit weight holding only a run, a bob, regressors and a target: what the unit tests
/// of the regressions need.
#[cfg(test)]
pub(crate) fn test_row(run: usize, bob_inertia_kg_m2: f64, x: Vec<f64>, target: f64) -> WeakRow {
    WeakRow {
        run,
        tau_s: 0.0,
        theta: 0.0,
        theta_dot_rad_s: 0.0,
        phase: 0.0,
        a_y_meas: 0.0,
        a_x_meas: 0.0,
        target,
        x,
        weight: 1.0,
        bob_inertia_kg_m2,
        lib: Vec::new(),
        speeds: Default::default(),
    }
}

#[cfg(test)]
mod contrast_tests {
    use super::*;

    fn row(run: usize, x_offset: f64, target: f64) -> WeakRow {
        let mut x = vec![0.0; columns().len()];
        x[observation_column().unwrap()] = x_offset;
        test_row(run, 0.1, x, target)
    }

    /// With per-run offsets θ_r, the offset column estimates their mean weighted by each run's
    /// information (Σ x²), and each run's own offset is the mean plus its contrast; validate
    /// rows (run 3) get zero contrasts.
    #[test]
    fn zero_error_contrasts_split_common_and_per_run_offsets() {
        let offsets = [0.003, -0.002, 0.0015];
        let lens = [40, 70, 25];
        let mut rows = Vec::new();
        let mut info = [0.0; 3];
        for (r, th) in offsets.iter().enumerate() {
            for i in 0..lens[r] {
                let x = ((i * 7 + r * 3) as f64 * 0.37).cos() + 0.2;
                info[r] += x * x;
                rows.push(row(r, x, th * x));
            }
        }
        rows.push(row(3, 1.0, 0.5));
        let n_id = rows.len() - 1;
        let cols = add_zero_error_contrasts(&mut rows, &[0, 1, 2]);
        let n = columns().len();
        assert_eq!(cols, vec![n, n + 1]);
        assert!(rows.last().unwrap().x[n..].iter().all(|v| *v == 0.0));
        let offset = observation_column().unwrap();
        let mut all = vec![offset];
        all.extend(&cols);
        let fit = crate::screen::ols(&rows[..n_id], &all).unwrap();
        let mean =
            offsets.iter().zip(&info).map(|(t, w)| t * w).sum::<f64>() / info.iter().sum::<f64>();
        let (m, _) = fit.coef_of(offset).unwrap();
        assert!((m - mean).abs() < 1e-12, "{m} vs {mean}");
        // Run 1 (the best informed) is the reference; runs 0 and 2 have their own contrasts.
        for (k, r) in [0, 2].into_iter().enumerate() {
            let (d, _) = fit.coef_of(cols[k]).unwrap();
            assert!((m + d - offsets[r]).abs() < 1e-12);
        }
    }

    /// A run whose rows cannot tell its own zero from the damping cannot make the common offset
    /// unknowable: its interval is that of the well-informed runs. Run 2's offset column is
    /// nearly its bearing-friction column (which no other run's rows hold), as large as the other
    /// runs' by Σ x², so only the information left after the damping columns weighs it right.
    #[test]
    fn a_run_that_cannot_see_its_zero_does_not_decide_the_common_offset() {
        let offsets = [0.002, -0.001, 0.0005];
        let lens = [200, 200, 200];
        let mu = column_of("coulomb_bearing").unwrap();
        let mut rows = Vec::new();
        let mut seed = 7u64;
        let mut noise = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 1e-3
        };
        for (r, th) in offsets.iter().enumerate() {
            for i in 0..lens[r] {
                let x = ((i * 5 + r) as f64 * 0.61).cos();
                let mut w = row(r, x, th * x + noise());
                if r == 2 {
                    w.x[mu] = x + 0.02 * (i as f64 * 1.37).sin();
                    w.target += 0.03 * x;
                }
                rows.push(w);
            }
        }
        let cols = add_zero_error_contrasts(&mut rows, &[0, 1, 2]);
        let offset = observation_column().unwrap();
        let mut all = vec![offset, mu];
        all.extend(&cols);
        let fit = crate::screen::ols(&rows, &all).unwrap();
        let (m, se) = fit.coef_of(offset).unwrap();
        let good = (offsets[0] + offsets[1]) / 2.0;
        assert!(se < 1e-4, "common offset's standard error {se}");
        assert!((m - good).abs() < 5.0 * se.max(1e-6), "{m} vs {good}");
    }
}
