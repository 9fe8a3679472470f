//! What a sensor reads of an effect's size directly, beside the screen's equation error: where
//! each run's free decay hangs (an offset of the angle's reading), the accelerometer's horizontal
//! axis over its vertical one (a tilted guide), the crank fit's amplitude (the accelerometer's
//! gain), and how those readings are pooled and judged on the validate runs.

use pendulum_process::fit::{FitParam, ModelSpec, PreparedRun};
use pendulum_process::identify::{validate, FitOutcome, RunFit};
use pendulum_process::pipeline::Context;
use pendulum_process::{ProcessError, Role};

use crate::agreement::{sizes_disagree, views_agree};
use crate::discover::{judged_for, DiagnosisRow, DiscoverConfig};
use crate::heldout::{e_total, heldout_gain};
use crate::trajectories::{
    followed_ics, moving_runs, refit, refit_profile, substitution_segments,
    trajectory_substitution, with_run_zeros,
};

/// An accelerometer sensitivity error under 1 % is within a calibrated MPU-6050's tolerance and
/// the crank fit's own systematic error (the sensor's 44 Hz low-pass alone scales the
/// fundamental by −0.06 %), not the effect `accel_gain`.
pub const ACCEL_GAIN_FLOOR: f64 = 0.01;

/// Two-sided 95 % quantile of Student's t with `df` degrees of freedom (infinite at 0).
pub(crate) fn t95(df: usize) -> f64 {
    if df == 0 {
        f64::INFINITY
    } else {
        pendulum_numerics::t_quantile(0.975, df as f64)
    }
}

/// A per-run reading (`value`, where a run has one) of the identify runs and of the validate
/// runs, each in the campaign's run order: the sensor effects' two sets of readings.
pub(crate) fn per_role(
    ctx: &Context,
    value: impl Fn(&pendulum_process::run::RunData) -> Option<f64>,
) -> (Vec<f64>, Vec<f64>) {
    let of = |role: Role| -> Vec<f64> {
        ctx.runs
            .iter()
            .filter(|r| r.role == role)
            .filter_map(&value)
            .collect()
    };
    (of(Role::Identify), of(Role::Validate))
}

/// A quantity measured once per run (n ≥ 2): its mean, the half-width of the mean's 95 %
/// interval from the runs' scatter (Student's t), and ΔBIC of "mean" against `nominal`.
pub(crate) fn per_run_mean(values: &[f64], nominal: f64) -> (f64, f64, f64) {
    let n = values.len();
    let nf = n as f64;
    let mean = values.iter().sum::<f64>() / nf;
    let rss1 = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>();
    let rss0 = values.iter().map(|v| (v - nominal).powi(2)).sum::<f64>();
    let half = t95(n.saturating_sub(1)) * (rss1 / (nf - 1.0) / nf).sqrt();
    let delta_bic = nf * (rss1.max(1e-300) / rss0.max(1e-300)).ln() + nf.ln();
    (mean, half, delta_bic)
}

/// Where a position torque T_p sin(kθ + φ) holds a bob of `mgl` (m g l, N·m) at rest: the
/// equilibrium nearest hanging, sin θ + (T_p/m g l) sin(kθ + φ) = 0, by Newton from 0.
pub(crate) fn position_torque_rest_rad(mgl: f64, t_p: f64, k: f64, phi: f64) -> f64 {
    let p = t_p / mgl;
    let mut th = 0.0f64;
    for _ in 0..20 {
        let f = th.sin() + p * (k * th + phi).sin();
        let df = th.cos() + p * k * (k * th + phi).cos();
        if !(df.abs() > 1e-12) {
            break;
        }
        let step = f / df;
        th -= step;
        if step.abs() < 1e-12 {
            break;
        }
    }
    th
}

/// Whether the identify runs' free decays (`readings`: each run's m g l and the angle its free
/// decay swings about) hang where an offset of the reading puts them, one angle for every bob,
/// rather than where a position torque (T_p, k, φ) would: the torque's rest angles
/// ([`position_torque_rest_rad`]) against the readings' common mean, by the runs' scatter about
/// each, ΔBIC n ln(RSS_torque / RSS_mean) beyond 10 (Kass and Raftery's "very strong"). Each
/// reading also holds its run's zeroing error and how well a centre is read, which the mean's
/// scatter carries. Not with fewer than three readings.
pub(crate) fn hangs_as_an_offset(readings: &[(f64, f64)], t_p: f64, k: f64, phi: f64) -> bool {
    if readings.len() < 3 || !(t_p.is_finite() && phi.is_finite()) {
        return false;
    }
    let n = readings.len() as f64;
    let mean = readings.iter().map(|r| r.1).sum::<f64>() / n;
    let rss_mean = readings.iter().map(|r| (r.1 - mean).powi(2)).sum::<f64>();
    let rss_torque = readings
        .iter()
        .map(|&(mgl, h)| (h - position_torque_rest_rad(mgl, t_p, k, phi)).powi(2))
        .sum::<f64>();
    n * (rss_torque.max(1e-300) / rss_mean.max(1e-300)).ln() > 10.0
}

/// Whether the runs' free decays (`readings`: each run's m g l, N·m, and the angle its free decay
/// swings about) hang where a torque the bob balances puts them, rather than at one angle for
/// every bob: an offset of the reading moves every run's centre alike (beside its own few
/// counts of zeroing error), while a torque T the rig itself carries tilts a bob of m g l by
/// about T/(m g l). The line a + c/(m g l) against the mean alone, by the runs' scatter about
/// each: ΔBIC n ln(RSS_line / RSS_mean) + ln n below −10 (Kass and Raftery's "very strong").
/// Not with fewer than four readings, or where the bobs' m g l hardly differ (one bob in every
/// run: the two cannot be told apart). A cable anchored 0.35 rad to one side (a departure: a
/// spring and a constant torque, 0.25 N·m/rad) hung eight mixed bobs of m g l 1.29 to 3.67 N·m
/// at 0.064 down to 0.026 rad, about 0.08 N·m over each one's m g l; read as an offset of the
/// reading, their centres confirmed a 3.8e-2 rad `encoder_offset`, and it was named.
pub(crate) fn hangs_by_the_bob(readings: &[(f64, f64)]) -> bool {
    let n = readings.len();
    if n < 4 {
        return false;
    }
    let nf = n as f64;
    let x: Vec<f64> = readings.iter().map(|r| 1.0 / r.0).collect();
    let (mx, mh) = (
        x.iter().sum::<f64>() / nf,
        readings.iter().map(|r| r.1).sum::<f64>() / nf,
    );
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    // The bobs' 1/(m g l) must spread by more than rounding (one bob: no line to fit).
    if !(sxx > 1e-6 * nf * mx * mx) {
        return false;
    }
    let sxh: f64 = x
        .iter()
        .zip(readings)
        .map(|(v, r)| (v - mx) * (r.1 - mh))
        .sum();
    let rss_mean: f64 = readings.iter().map(|r| (r.1 - mh).powi(2)).sum();
    let rss_line = (rss_mean - sxh * sxh / sxx).max(0.0);
    nf * (rss_line.max(1e-300) / rss_mean.max(1e-300)).ln() + nf.ln() < -10.0
}

/// The identify runs' direct reading of an offset of the angle's reading: each run's free decay
/// swings about the offset plus that run's own zeroing error (a few counts, rig.md), so the 95 %
/// interval of their mean from the runs' scatter ([`per_run_mean`]). `None` with fewer than
/// three readings (`hanging_position`: a free decay with swings to read).
pub(crate) fn hanging_interval(readings: &[f64]) -> Option<(f64, f64)> {
    if readings.len() < 3 {
        return None;
    }
    let (mean, half, _) = per_run_mean(readings, 0.0);
    Some((mean - half, mean + half))
}

/// How far apart two sets of runs, of `n_a` and `n_b` runs, may put an offset of the angle's
/// reading by their own zeroing errors alone (95 %): each set's value of the offset is the offset
/// plus the (weighted) mean of its runs' zeros, which the zeroing contrasts hold to a zero sum
/// within the set ([`crate::weak::add_zero_error_contrasts`]), so the screen's intervals leave
/// it out. The runs' zero scatter is read from where the identify runs' free decays hang
/// (`readings`, each the offset plus that run's zero: their scatter also holds how well a centre
/// is read, so this errs wide); 0 with fewer than three readings.
pub(crate) fn zeroing_half(readings: &[f64], n_a: usize, n_b: usize) -> f64 {
    if readings.len() < 3 || n_a == 0 || n_b == 0 {
        return 0.0;
    }
    // The mean's half-width, t95 · s / √n, back to one reading's: t95 · s.
    let (_, half, _) = per_run_mean(readings, 0.0);
    half * (readings.len() as f64).sqrt() * (1.0 / n_a as f64 + 1.0 / n_b as f64).sqrt()
}

/// A named sensor effect's value from every run's reading, identify (`id`) and validate (`val`):
/// their mean less the `nominal` value, its interval from their scatter (as [`per_run_mean`]),
/// once the validate runs have judged it (as a torque's is estimated on every run: see
/// [`pooled_screen_estimate`]). Unchanged unless the row is accepted and there are validate
/// readings.
pub(crate) fn pool_readings(row: &mut DiagnosisRow, id: &[f64], val: &[f64], nominal: f64) {
    if !row.accepted || val.is_empty() || id.is_empty() {
        return;
    }
    let all: Vec<f64> = id.iter().chain(val).copied().collect();
    let (mean, half, _) = per_run_mean(&all, nominal);
    let v = mean - nominal;
    row.estimate = v;
    row.ci_low = v - half;
    row.ci_high = v + half;
    row.note.push_str(&format!(
        "; estimated on every run's reading (identify and validate) once the validate runs had judged it: {v:.4e} {} (the identify runs alone: {:.4e})",
        row.unit, row.identify_estimate
    ));
}

/// The accelerometer's own held-out view of an input effect read from it: the validate runs'
/// squared error Σ(v − ·)² about the `nominal` value and about the identify runs' `fitted` one
/// (v each validate run's own reading), and its fall, as (gain, before, after); the gain is NaN
/// without validate runs.
pub(crate) fn sensor_heldout(val: &[f64], nominal: f64, fitted: f64) -> (f64, f64, f64) {
    let before = val.iter().map(|v| (v - nominal).powi(2)).sum::<f64>();
    let after = val.iter().map(|v| (v - fitted).powi(2)).sum::<f64>();
    let gain = if val.is_empty() {
        f64::NAN
    } else {
        1.0 - after / before.max(1e-300)
    };
    (gain, before, after)
}

/// A value with its 95 % interval (`value`, low, high) joined with a direct reading of the same
/// quantity (`reading`: its value and 95 % half-width) by inverse-variance weights, where the
/// two agree ([`sizes_disagree`] says not): the joined value and its interval. None where they
/// disagree (one of the views holds something the other does not: the value stays as it was)
/// or where either interval is not finite and positive.
///
/// `shared`: the reading's scatter is an error the value shares, not one of its own. The free
/// decays' centres read each run's zero, the offset plus that run's zeroing error (a few counts),
/// and the equation error's offset column is those zeros' mean too (each run's zero contrast
/// free): both views read one mean, whose distance from the offset is the zeroing draws' and
/// only the centres' scatter measures. Joined as independent, the interval shrank below that:
/// drawn seed 7's offset joined to ±1.02 mrad while its centres' own interval was ±1.18. So the
/// joined interval is then no narrower than the reading's own.
pub(crate) fn joined_with_reading(
    value: (f64, f64, f64),
    reading: (f64, f64),
    shared: bool,
) -> Option<(f64, f64, f64)> {
    let (v, lo, hi) = value;
    let (r, r_half) = reading;
    let v_half = 0.5 * (hi - lo);
    let usable = |h: f64| h.is_finite() && h > 0.0;
    if !(usable(v_half) && usable(r_half) && v.is_finite() && r.is_finite()) {
        return None;
    }
    if sizes_disagree(v, v_half, r, r_half) {
        return None;
    }
    let (wv, wr) = (v_half.powi(-2), r_half.powi(-2));
    let joined = (wv * v + wr * r) / (wv + wr);
    let half = (wv + wr).sqrt().recip();
    let half = if shared { half.max(r_half) } else { half };
    Some((joined, joined - half, joined + half))
}

/// The sensor view's held-out gain above which it confirms an input effect: the validate runs'
/// own readings must sit nearer the identify runs' value than the nominal one by more than half
/// their squared error.
pub(crate) const SENSOR_HELDOUT_GAIN: f64 = 0.5;

/// `accel_gain` is a sensor effect: the model is driven by the crank's geometry, so it cannot
/// change E_θ; it shows in the amplitude the alignment's crank-rod fit needs (G = 1 + k_a).
/// Estimate k_a from the identify runs' G (interval from their scatter, Student's t), and score
/// it on the validate runs: the held-out gain is the fall of their squared sensitivity error
/// Σ(G_v − 1)² when 1 + k_a replaces the nominal 1. Accepted when the interval excludes 0,
/// |k_a| exceeds [`ACCEL_GAIN_FLOOR`], ΔBIC (over the runs' G) beats the screen threshold and the
/// held-out gain is above one half.
pub(crate) fn accel_gain_row(ctx: &Context, cfg: &DiscoverConfig) -> Option<DiagnosisRow> {
    let (g_id, g_val) = per_role(ctx, |r| {
        ctx.alignments
            .get(&r.id)
            .filter(|a| !a.is_free() && a.accel_gain.is_finite() && a.forcing_understood())
            .map(|a| a.accel_gain)
    });
    let n = g_id.len();
    if n < 3 {
        return None;
    }
    let (mean, half, delta_bic) = per_run_mean(&g_id, 1.0);
    let est = mean - 1.0;
    let (gain, before, after) = sensor_heldout(&g_val, 1.0, mean);
    let excludes_zero = est - half > 0.0 || est + half < 0.0;
    let accepted = excludes_zero
        && est.abs() > ACCEL_GAIN_FLOOR
        && delta_bic < cfg.screen_threshold
        && gain > SENSOR_HELDOUT_GAIN;
    let mut row = DiagnosisRow {
        accepted,
        estimate: est,
        identify_estimate: est,
        ci_low: est - half,
        ci_high: est + half,
        delta_bic,
        heldout_gain: gain,
        screen_estimate: est,
        e_validate_before: before,
        e_validate_after: after,
        note: format!(
            "sensor effect, read from the crank fit's amplitude G = 1 + k_a on {n} identify runs \
             (E_θ cannot change: the model is driven by the crank geometry); held-out: validate \
             runs' Σ(G − 1)² {before:.3e} → {after:.3e}; named only above {:.0} % (calibration \
             tolerance){}",
            100.0 * ACCEL_GAIN_FLOOR,
            if est.abs() > ACCEL_GAIN_FLOOR {
                ""
            } else {
                ": below it"
            }
        ),
        ..DiagnosisRow::words_only("accel_gain", "1", String::new())
    };
    pool_readings(&mut row, &g_id, &g_val, 1.0);
    Some(row)
}

/// The accelerometer's int16 limit (±4 g, rig.md), m/s², less a margin: a sample at it is
/// clipped, and its slope is not the axis's.
pub(crate) const ACCEL_CLIP_M_S2: f64 = 0.99 * 4.0 * 9.806_65;

/// One LSB of the accelerometer (±4 g at 8192 LSB/g, rig.md), m/s².
pub(crate) const ACCEL_LSB_M_S2: f64 = 9.806_65 / 8192.0;

/// Robust spreads (1.4826 × the median absolute residual) beyond which an accelerometer sample
/// is taken for a glitch in a slope fit.
pub(crate) const SLOPE_GLITCH_SIGMAS: f64 = 5.0;

/// The least-squares line of `x` on `z` through `(z, x)` points as (slope, intercept); `None`
/// without ten points or without a spread in `z` of `min_z_rms` (rms).
pub(crate) fn line_fit(pts: &[(f64, f64)], min_z_rms: f64) -> Option<(f64, f64)> {
    if pts.len() < 10 {
        return None;
    }
    let n = pts.len() as f64;
    let mz = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let mx = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let szz = pts.iter().map(|p| (p.0 - mz).powi(2)).sum::<f64>();
    let szx = pts.iter().map(|p| (p.0 - mz) * (p.1 - mx)).sum::<f64>();
    if !(szz / n > min_z_rms * min_z_rms) {
        return None;
    }
    let b = szx / szz;
    Some((b, mx - b * mz))
}

/// The slope of `x` on `z` with glitches left out: a first line, then again without the points
/// beyond [`SLOPE_GLITCH_SIGMAS`] robust spreads of its residual. `None` where `x` spreads about
/// the line by under half an LSB: a live MPU-6050 axis reads tens of LSB of noise, and one that
/// never changes is not connected (its slope of 0 would deny every tilt).
pub(crate) fn robust_slope(pts: &[(f64, f64)], min_z_rms: f64) -> Option<f64> {
    let (b, c) = line_fit(pts, min_z_rms)?;
    let mut r: Vec<f64> = pts.iter().map(|(z, x)| (x - c - b * z).abs()).collect();
    let s = 1.4826 * pendulum_numerics::median(&mut r);
    if !(s >= 0.5 * ACCEL_LSB_M_S2) {
        return None;
    }
    let kept: Vec<(f64, f64)> = pts
        .iter()
        .filter(|(z, x)| (x - c - b * z).abs() <= SLOPE_GLITCH_SIGMAS * s)
        .copied()
        .collect();
    line_fit(&kept, min_z_rms).map(|l| l.0)
}

/// Least rms vertical motion, m/s², a forced run must show for its horizontal slope to be read:
/// the slowest crank the rig allows, 0.87 Hz on the short 0.0725 m radius, shakes at 2.2 m/s²
/// amplitude (1.5 rms); a run whose axis hardly moves says nothing about where it moves.
pub(crate) const SLOPE_MIN_Z_RMS_M_S2: f64 = 0.5;

/// Each forced run's reading of a tilted guide (`role`'s runs, in run order): the slope of the
/// accelerometer's horizontal axis on its vertical one from t = 0 on, which is tan δ (the axis
/// moves x = y·tan δ, and both axes see the same gain, lag and filter, so none of those sensor
/// effects moves it; each axis's zero-g offset is the line's intercept).
pub(crate) fn horizontal_slopes(ctx: &Context, role: Role) -> Vec<f64> {
    ctx.runs
        .iter()
        .filter(|r| r.role == role)
        .filter_map(|r| {
            let al = ctx.alignments.get(&r.id)?;
            if al.is_free() {
                return None;
            }
            let pts: Vec<(f64, f64)> = r
                .acc_t_s
                .iter()
                .zip(r.az_m_s2.iter().zip(&r.ax_m_s2))
                .filter(|(t, _)| **t >= al.t0_s)
                .map(|(_, (z, x))| (*z, *x))
                .filter(|(z, x)| {
                    z.is_finite()
                        && x.is_finite()
                        && z.abs() < ACCEL_CLIP_M_S2
                        && x.abs() < ACCEL_CLIP_M_S2
                })
                .collect();
            robust_slope(&pts, SLOPE_MIN_Z_RMS_M_S2)
        })
        .collect()
}

/// A tilt read from forced runs' horizontal slopes ([`horizontal_slopes`], each tan δ): δ, the
/// half-width of its 95 % interval from their scatter ([`per_run_mean`]), and ΔBIC against no
/// tilt; `None` with fewer than three runs.
pub(crate) fn tilt_reading(slopes: &[f64]) -> Option<(f64, f64, f64)> {
    if slopes.len() < 3 {
        return None;
    }
    let (m, h, delta_bic) = per_run_mean(slopes, 0.0);
    Some((m.atan(), 0.5 * ((m + h).atan() - (m - h).atan()), delta_bic))
}

/// Discover's state that the accelerometer's reading of a tilted guide is judged against (see
/// [`TiltJudge::judge`]): the model in hand and the runs it was judged on.
pub(crate) struct TiltJudge<'a> {
    pub(crate) cfg: &'a DiscoverConfig,
    /// The model in hand's initial states of the identify runs (two per run).
    pub(crate) ics: &'a [f64],
    pub(crate) id_runs: &'a [PreparedRun],
    pub(crate) free_moving: &'a [PreparedRun],
    pub(crate) held_runs: &'a [PreparedRun],
    pub(crate) free_moving_val: &'a [PreparedRun],
    /// The identify and the validate runs' horizontal slopes ([`horizontal_slopes`]): the
    /// captures do not change during the search, so they are read once.
    pub(crate) id_slopes: Vec<f64>,
    pub(crate) val_slopes: Vec<f64>,
}

/// A tilt the accelerometer read: its row, and the model that holds it when it is named (spec,
/// parameters, and its validation on the held-out runs).
pub(crate) struct TiltFound {
    pub(crate) row: DiagnosisRow,
    pub(crate) model: Option<(ModelSpec, Vec<f64>, Vec<RunFit>)>,
}

impl TiltJudge<'_> {
    /// A tilt of the guide (`effect`, [`pendulum_model::Effect::reads_horizontal_slope`]) that the
    /// equation error could not estimate (`n_windows`: none of its windows holds a forced
    /// stretch where the pendulum moves, so its column there is 0), or whose screened value
    /// (`screened`: the estimate and its 95 % half-width) the accelerometer's reading refuses:
    /// read from the accelerometer
    /// ([`horizontal_slopes`], the identify runs' mean and its interval from their scatter) and
    /// named only where the pendulum agrees. Its forced swing under the shaker's horizontal
    /// motion (a few counts to tens about the hanging position, which the equation error leaves
    /// out as a stretch where dry friction may hold it) is what the trajectories see: their
    /// refit must be able to tell the tilt from its absence, the profile through the
    /// accelerometer's value must fit them as well as the refit, the validate runs' E_θ must
    /// fall beyond its bar with the other terms refitted at that value, and the validate runs'
    /// own slopes must sit nearer it than 0 ([`SENSOR_HELDOUT_GAIN`]). An accelerometer mounted
    /// a degree off vertical would read a slope that no torque follows: the trajectories, not
    /// the sensor, decide. `None` with fewer than three forced identify runs. Judged first beside
    /// the base model, so that what follows is screened and sized with the tilt's torque known,
    /// and, refused there, again beside what the search named.
    /// A hidden 2.97e-2 rad tilt beside a 1.02e-2 N·m dry torque on a drawn design (four of five
    /// identify runs resting under the shaker, `SURVEY_DAMPING=drawn SURVEY_SEED=5`, pair 4) was
    /// "not estimable on the identify runs' 56 equation-error windows", while each forced run's
    /// accelerometer read tan δ = 0.0297 to 0.0298 and its pendulum swung ±5 to ±20 counts.
    /// `current` is the model in hand and `current_val` its validation on the held-out runs.
    pub(crate) fn judge(
        &self,
        current: &FitOutcome,
        current_val: &[RunFit],
        effect: &'static dyn pendulum_model::effects::Effect,
        unit: &str,
        n_windows: usize,
        screened: Option<(f64, f64)>,
    ) -> Result<Option<TiltFound>, ProcessError> {
        let cfg = self.cfg;
        let (id, val) = (&self.id_slopes, &self.val_slopes);
        let Some((est, half, delta_bic)) = tilt_reading(id) else {
            return Ok(None);
        };
        let mean = est.tan();
        let (lo, hi) = (est - half, est + half);
        let reads = (lo > 0.0 || hi < 0.0) && delta_bic < cfg.screen_threshold;
        let screen_words = match screened {
            Some((e, h)) => format!(
                "the equation error's {e:.4e} ± {h:.4e} rad on its {n_windows} windows on the identify runs is refused by the accelerometer's reading (another departure beside the tilt can pull it), and is set aside"
            ),
            None => format!(
                "the equation error could not estimate it (its {n_windows} windows on the identify runs leave out the forced stretches where dry friction may hold the pendulum, and there it swings a few counts under the shaker)"
            ),
        };
        let read_words = format!(
            "{screen_words}; the accelerometer's horizontal axis reads it directly, its slope on the vertical axis tan δ on {} forced identify runs: δ = {est:.4e} [{lo:.4e}, {hi:.4e}] rad (ΔBIC {delta_bic:.1})",
            id.len()
        );
        // (The screen has no value of it: `screen_estimate` stays NaN.)
        let mut row = DiagnosisRow {
            estimate: est,
            identify_estimate: est,
            ci_low: lo,
            ci_high: hi,
            delta_bic,
            screen_estimate: screened.map_or(f64::NAN, |(e, _)| e),
            ..DiagnosisRow::words_only(effect.name(), unit, String::new())
        };
        if !reads {
            row.note = format!("{read_words}: no tilt beyond that interval; not named");
            return Ok(Some(TiltFound { row, model: None }));
        }
        let Some(p) = effect.size_key().and_then(FitParam::find) else {
            return Ok(None);
        };
        let mut spec = current.spec.clone();
        if !spec.params.contains(&p) {
            spec.params.push(p);
            spec.name = format!("{}+{}", spec.name, effect.name());
        }
        let Some(i) = spec.params.iter().position(|q| *q == p) else {
            return Ok(None);
        };
        let x0: Vec<f64> = spec
            .params
            .iter()
            .map(|q| if *q == p { est } else { current.param(*q) })
            .collect();
        for (&q, &v) in spec.params.clone().iter().zip(&x0) {
            spec.hold(q, v);
        }
        // The trajectories as a torque's refit sees them (the loop's `refit_zeroed`): the
        // moving identify runs and the free segments, each run's zeroing error held.
        let (mut traj, mut held_ics) = moving_runs(self.id_runs, self.ics, false);
        for r in self.free_moving {
            held_ics.extend(r.ic_est);
            traj.push(r.clone());
        }
        let evals = cfg.refit_evals;
        let refit_zeroed = |spec: &ModelSpec, start: &[f64]| {
            let ics = followed_ics(&traj, spec, start, &held_ics);
            let (x1, _) = refit(&traj, spec, start, &ics, evals);
            let tz = with_run_zeros(&traj, spec, &x1, &ics);
            let (x2, _) = refit(&tz, spec, &x1, &ics, evals);
            (x2, tz, ics)
        };
        let (x, tz, tics) = refit_zeroed(&spec, &x0);
        let mut start = x.clone();
        start[i] = est;
        let x_prof = refit_profile(&tz, &spec, &start, &tics, evals, i);
        let seg_x = substitution_segments(&tz, &spec, &x, &tics, true);
        let (g_prof, n_prof) = trajectory_substitution(&tz, &spec, &seg_x, &x_prof, &tics, true);
        let mut x_zero = x.clone();
        x_zero[i] = 0.0;
        let (g0, n0) = trajectory_substitution(&tz, &spec, &seg_x, &x_zero, &tics, true);
        let informative = g0 < -n0;
        // The two views agree as the screen's and the refit's must ([`views_agree`]): the same
        // sign, and the refit within the reading's interval or the promised 10 %, or the
        // profile through the reading fitting the trajectories as well as the refit.
        let agree = views_agree(est, half, x[i], g_prof >= -n_prof);
        row.refit_estimate = x[i];
        // The held-out runs, the tilt at the accelerometer's value and the other terms refitted
        // there, against the best of the model in hand (as fitted, refitted the same way, and
        // the profile through the tilt's absence).
        let v_tilt = validate(self.held_runs, &spec, &x_prof, &cfg.validate)?;
        let (xc, _, _) = refit_zeroed(&current.spec, &current.params);
        let v_refit = validate(self.held_runs, &current.spec, &xc, &cfg.validate)?;
        let mut start = x_prof.clone();
        start[i] = 0.0;
        let xa = refit_profile(&tz, &spec, &start, &tics, evals, i);
        let v_absent = validate(self.held_runs, &spec, &xa, &cfg.validate)?;
        let (before_judged, before) = [current_val, &v_refit[..], &v_absent[..]]
            .into_iter()
            .map(|v| {
                let judged = judged_for(effect, v, self.free_moving_val);
                let total = e_total(&judged);
                (judged, total)
            })
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .expect("three validations");
        let after_judged = judged_for(effect, &v_tilt, self.free_moving_val);
        let (gain, noise) = heldout_gain(&before_judged, &after_judged);
        let gain_needed = cfg.gain_min.max(noise);
        row.heldout_gain = gain;
        row.heldout_noise = noise;
        row.e_validate_before = before;
        row.e_validate_after = e_total(&after_judged);
        let (s_gain, s_before, s_after) = sensor_heldout(val, 0.0, mean);
        let sensor_confirms = val.is_empty() || s_gain > SENSOR_HELDOUT_GAIN;
        row.accepted =
            informative && agree && gain > gain_needed && sensor_confirms && effect.possible(est);
        let why = if row.accepted {
            "named".to_string()
        } else {
            let mut w = Vec::new();
            if !informative {
                w.push("the trajectories cannot tell it from its absence");
            }
            if !agree {
                w.push("the trajectories put it elsewhere than the accelerometer (beyond its interval and 10 %, the profile through its value rejected): the slope is the sensor's, not the guide's");
            }
            if !(gain > gain_needed) {
                w.push("the validate runs' E_θ does not fall beyond its bar");
            }
            if !sensor_confirms {
                w.push("the validate runs' own slopes do not confirm it");
            }
            if !effect.possible(est) {
                w.push("not physically possible");
            }
            format!("not named: {}", w.join("; "))
        };
        row.note = format!(
            "{read_words}; the trajectories' refit {:.4e} (the profile through the accelerometer's value {:+.1} % ± {:.1} % against it, the tilt's absence {:+.1} % ± {:.1} %); held-out: validate runs' E_θ {before:.4} → {:.4} ({:.1} % ± {:.1} %, needed {:.1} %), their own slopes Σ tan² δ {s_before:.3e} → {s_after:.3e}; {why}",
            x[i],
            100.0 * g_prof,
            100.0 * n_prof,
            100.0 * g0,
            100.0 * n0,
            row.e_validate_after,
            100.0 * gain,
            100.0 * noise,
            100.0 * gain_needed,
        );
        if !row.accepted {
            return Ok(Some(TiltFound { row, model: None }));
        }
        // Named: sized on every run's reading, identify and validate, as a sensor effect is
        // ([`pool_readings`]).
        let all: Vec<f64> = id.iter().chain(val).copied().collect();
        if let Some((d, h, _)) = tilt_reading(&all).filter(|_| !val.is_empty()) {
            row.estimate = d;
            row.ci_low = d - h;
            row.ci_high = d + h;
            row.note.push_str(&format!(
                "; estimated on every run's reading (identify and validate) once the validate runs had judged it: {:.4e} rad (the identify runs alone: {est:.4e})",
                row.estimate
            ));
        }
        Ok(Some(TiltFound {
            row,
            model: Some((spec, x_prof, v_tilt)),
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A k = 1 position torque's rest angle has a closed form, tan θ = −p sin φ / (1 + p cos φ)
    /// (p = T_p / m g l); Newton's agrees, and for k = 3 it solves the balance it states.
    /// An offset moves every bob's centre alike (beside each run's own zeroing error); a torque
    /// the bob balances tilts each by its own m g l. Only the second hangs by the bob, and one
    /// bob in every run tells neither.
    #[test]
    fn a_torque_the_bob_balances_hangs_by_the_bob_an_offset_does_not() {
        let mgl = [1.29, 1.38, 1.60, 1.64, 1.68, 2.70, 2.80, 3.67];
        // A few counts (1.53 mrad each) of zeroing error, run by run.
        let zero = [
            1.5e-3, -3.1e-3, 0.0, 4.6e-3, -1.5e-3, 3.1e-3, -4.6e-3, 1.5e-3,
        ];
        let offset: Vec<(f64, f64)> = mgl.iter().zip(zero).map(|(&g, z)| (g, 0.04 + z)).collect();
        assert!(!hangs_by_the_bob(&offset));
        let torque: Vec<(f64, f64)> = mgl
            .iter()
            .zip(zero)
            .map(|(&g, z)| (g, (0.08 / g).asin() + z))
            .collect();
        assert!(hangs_by_the_bob(&torque));
        // One bob: the same centres cannot be told apart.
        let one: Vec<(f64, f64)> = zero.iter().map(|&z| (1.6, 0.05 + z)).collect();
        assert!(!hangs_by_the_bob(&one));
        assert!(!hangs_by_the_bob(&torque[..3]));
    }

    #[test]
    fn a_position_torques_rest_angle_balances_gravity() {
        for (mgl, t_p, phi) in [(1.46, 0.0868, -1.59), (3.19, 0.04, -1.0), (1.25, 0.02, 2.5)] {
            let p: f64 = t_p / mgl;
            let closed = (-p * f64::sin(phi)).atan2(1.0 + p * f64::cos(phi));
            let th = position_torque_rest_rad(mgl, t_p, 1.0, phi);
            assert!((th - closed).abs() < 1e-12, "{th} against {closed}");
        }
        let th = position_torque_rest_rad(1.46, 0.05, 3.0, 0.7);
        assert!((th.sin() + 0.05 / 1.46 * (3.0 * th + 0.7).sin()).abs() < 1e-12);
        assert!(th.abs() > 1e-3);
    }

    /// Free decays that swing about one angle on bobs of different m g l are an offset's, not
    /// a position torque's (whose rest angle scales as 1/(m g l)); centres that follow the
    /// torque's rest angles are the torque's, on mixed bobs or on one; fewer than three readings
    /// cannot tell.
    #[test]
    fn free_decays_hanging_at_one_angle_over_mixed_bobs_read_as_an_offset() {
        let (t_p, phi) = (0.0868, -1.59);
        let mgls = [1.46, 1.28, 1.28, 1.68, 3.19, 1.25, 1.48, 2.52];
        // Each run's zeroing error, a count or two of a 4096-count encoder.
        let zero = [1.5e-3, -1.5e-3, 0.0, 3.0e-3, -3.0e-3, 1.5e-3, 0.0, -1.5e-3];
        let offset: Vec<(f64, f64)> = mgls
            .iter()
            .zip(&zero)
            .map(|(&m, z)| (m, 0.048 + z))
            .collect();
        assert!(hangs_as_an_offset(&offset, t_p, 1.0, phi));
        let torque: Vec<(f64, f64)> = mgls
            .iter()
            .zip(&zero)
            .map(|(&m, z)| (m, position_torque_rest_rad(m, t_p, 1.0, phi) + z))
            .collect();
        assert!(!hangs_as_an_offset(&torque, t_p, 1.0, phi));
        let one_bob: Vec<(f64, f64)> = zero.iter().map(|z| (1.46, 0.0595 + z)).collect();
        assert!(!hangs_as_an_offset(&one_bob, t_p, 1.0, phi));
        assert!(!hangs_as_an_offset(&offset[..2], t_p, 1.0, phi));
    }

    /// A tilted guide's forced run as the accelerometer sees it: the horizontal axis is tan δ
    /// times the vertical one's motion, each axis with its own zero-g offset and noise, and a
    /// glitch to full scale on the horizontal axis every 2 s (at the crest of the motion, where
    /// it tilts a line most). The slope reads tan δ within the noise; the plain line, glitches
    /// in, does not; a vertical axis that does not move, or a horizontal one that never changes, says nothing.
    #[test]
    fn the_horizontal_axis_reads_a_tilt_as_its_slope_on_the_vertical_one() {
        let tan_d = 0.03;
        // Deterministic noise, uniform in (−0.5, 0.5).
        let noise = |i: usize, k: f64| ((i as f64 * 12.9898 + k).sin() * 43_758.545).fract() - 0.5;
        let pts: Vec<(f64, f64)> = (0..4000)
            .map(|i| {
                let t = i as f64 * 0.005;
                let y = 8.0 * (2.0 * std::f64::consts::PI * 1.5 * t).sin();
                let z = 9.806_65 + 0.3 + y + 0.04 * noise(i, 1.0);
                let crest = i % 400 == 33;
                let x = if crest {
                    30.0
                } else {
                    -0.2 + tan_d * y + 0.04 * noise(i, 2.0)
                };
                (z, x)
            })
            .collect();
        let b = robust_slope(&pts, SLOPE_MIN_Z_RMS_M_S2).unwrap();
        assert!((b - tan_d).abs() < 2e-4, "{b}");
        let (plain, _) = line_fit(&pts, SLOPE_MIN_Z_RMS_M_S2).unwrap();
        assert!((plain - tan_d).abs() > 5e-3, "{plain}");
        let still: Vec<(f64, f64)> = (0..4000)
            .map(|i| (9.8 + 0.04 * noise(i, 1.0), 0.04 * noise(i, 2.0)))
            .collect();
        assert!(robust_slope(&still, SLOPE_MIN_Z_RMS_M_S2).is_none());
        // Nor does a horizontal axis that never changes (not connected).
        let dead: Vec<(f64, f64)> = pts.iter().map(|&(z, _)| (z, -0.2)).collect();
        assert!(robust_slope(&dead, SLOPE_MIN_Z_RMS_M_S2).is_none());
    }

    /// The free decays' centres as a reading of an offset: the drawn seed-4 campaign's five
    /// identify runs (+0.0621 … +0.0620 rad) hold their mean, 0.0596, within Student's t over
    /// their scatter (t 2.776 for 4 degrees of freedom: ± 0.0040) and tell it from 0; zeroing
    /// errors of a few counts either side of 0 do not; two readings are not enough to say.
    #[test]
    fn free_decay_centres_read_an_offset_within_their_scatter() {
        let seed4 = [0.0621, 0.0553, 0.0568, 0.0616, 0.0620];
        let (lo, hi) = hanging_interval(&seed4).unwrap();
        let mean = seed4.iter().sum::<f64>() / 5.0;
        let sd = (seed4.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 4.0).sqrt();
        let half = 2.776 * sd / 5f64.sqrt();
        assert!((lo - (mean - half)).abs() < 1e-4 && (hi - (mean + half)).abs() < 1e-4);
        assert!(lo > 0.0);
        let count = 2.0 * std::f64::consts::PI / 4096.0;
        let zeros = [2.0 * count, -3.0 * count, count, -count, 0.0];
        let (lo, hi) = hanging_interval(&zeros).unwrap();
        assert!(lo < 0.0 && hi > 0.0, "[{lo}, {hi}]");
        assert!(hanging_interval(&seed4[..2]).is_none());
    }

    /// A named sensor effect's value from every run's reading, by hand: the mean of identify
    /// and validate readings less the nominal, its interval Student's t over their scatter;
    /// a row not named, or one without validate readings, keeps the identify runs' value.
    #[test]
    fn a_named_sensor_effect_is_sized_on_every_runs_reading() {
        let mut row = DiagnosisRow::words_only("accel_gain", "1", String::new());
        row.estimate = 0.2;
        row.identify_estimate = 0.2;
        let (id, val) = ([1.1, 1.2, 1.3], [1.4, 1.5]);
        pool_readings(&mut row, &id, &val, 1.0);
        assert_eq!(row.estimate, 0.2, "not named: unchanged");
        row.accepted = true;
        pool_readings(&mut row, &id, &[], 1.0);
        assert_eq!(row.estimate, 0.2, "no validate readings: unchanged");
        pool_readings(&mut row, &id, &val, 1.0);
        assert!((row.estimate - 0.3).abs() < 1e-12, "{}", row.estimate);
        // Readings 1.1..1.5: sample variance 0.025, standard error sqrt(0.025 / 5); t(4) = 2.776.
        let half = 2.776 * (0.025_f64 / 5.0).sqrt();
        assert!((row.ci_high - row.estimate - half).abs() < 2e-3 * half);
        assert!((row.estimate - row.ci_low - half).abs() < 2e-3 * half);
        assert_eq!(row.identify_estimate, 0.2);
        assert!(
            row.note.contains("the identify runs alone: 2.0000e-1"),
            "{}",
            row.note
        );
    }

    /// A reading joins a value by precision where the two agree: the more precise leads, the
    /// joined interval is narrower than either, and a reading that disagrees leaves the value
    /// alone. (The survey's pair 2 at seed 34: the equation error's 4.45e-2 [2.92e-2, 5.98e-2]
    /// rad and eight free decays' centres 5.95e-2 ± 0.46e-2.)
    #[test]
    fn a_direct_reading_joins_a_value_by_precision_where_they_agree() {
        let (v, lo, hi) =
            joined_with_reading((4.45e-2, 2.92e-2, 5.98e-2), (5.95e-2, 0.46e-2), false)
                .expect("they agree");
        assert!(v > 5.7e-2 && v < 5.95e-2, "{v}");
        assert!(hi - lo < 2.0 * 0.46e-2 && lo < v && v < hi);
        // Equal precision: the midpoint.
        let (m, ..) = joined_with_reading((1.0, 0.9, 1.1), (1.05, 0.1), false).unwrap();
        assert!((m - 1.025).abs() < 1e-12);
        // Apart beyond both intervals and 10 %: no join.
        assert!(
            joined_with_reading((4.45e-2, 4.3e-2, 4.6e-2), (5.95e-2, 0.46e-2), false).is_none()
        );
        // No interval to weigh: no join.
        assert!(
            joined_with_reading((4.45e-2, f64::NAN, 5.0e-2), (5.95e-2, 0.46e-2), false).is_none()
        );
        assert!(joined_with_reading((4.45e-2, 4.0e-2, 5.0e-2), (5.95e-2, 0.0), false).is_none());
    }

    /// A reading whose scatter the value shares (the free decays' centres and the equation
    /// error both read the runs' zeros' mean): the joined value is still weighed by precision,
    /// but its interval is no narrower than the reading's own, which alone measures how far
    /// that mean may sit from the offset. (Drawn seed 7's offset: every run's equation error
    /// about ±2.0 mrad, the centres ±1.18, joined as independent to ±1.02.)
    #[test]
    fn a_reading_whose_scatter_the_value_shares_keeps_its_own_interval() {
        let value = (3.80e-2, 3.60e-2, 4.00e-2);
        let reading = (3.84e-2, 0.118e-2);
        let (vi, loi, hii) = joined_with_reading(value, reading, false).unwrap();
        let (vs, los, his) = joined_with_reading(value, reading, true).unwrap();
        // The same value either way: only the interval differs.
        assert!((vi - vs).abs() < 1e-15);
        assert!(0.5 * (hii - loi) < 0.99 * 0.118e-2, "{loi} {hii}");
        assert!((0.5 * (his - los) - 0.118e-2).abs() < 1e-12, "{los} {his}");
        // A reading far less precise than the value: the joined interval is the reading's width.
        let (_, lo, hi) = joined_with_reading((1.0, 0.99, 1.01), (1.0, 0.5), true).unwrap();
        assert!((0.5 * (hi - lo) - 0.5).abs() < 1e-12);
    }
}
