//! Initial conditions at t = 0 from the encoder: a local polynomial fit (not a two-point
//! difference, which would amplify the encoder's quantisation), with uncertainties; and the
//! encoder zero checked against the hanging position from the free decay's turning points.

use pendulum_numerics::ols;
use serde::{Deserialize, Serialize};

use crate::run::RunData;
use crate::ProcessError;

/// Initial-condition settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct IcConfig {
    /// Half-width of the fitted window around t = 0, s.
    pub half_window_s: f64,
    /// Polynomial order (2–5).
    pub order: usize,
}

impl Default for IcConfig {
    fn default() -> Self {
        Self {
            half_window_s: 0.06,
            order: 3,
        }
    }
}

impl IcConfig {
    pub fn validate(&self) -> Result<(), ProcessError> {
        if !(self.half_window_s > 0.0 && self.half_window_s < 1.0) {
            return Err(ProcessError::BadConfig {
                stage: "initial_conditions".into(),
                field: "half_window_s".into(),
                message: format!("{} is not in (0, 1) s", self.half_window_s),
            });
        }
        if !(2..=5).contains(&self.order) {
            return Err(ProcessError::BadConfig {
                stage: "initial_conditions".into(),
                field: "order".into(),
                message: format!("{} is not in 2..=5", self.order),
            });
        }
        Ok(())
    }
}

/// θ and θ̇ at a time, with standard uncertainties.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct InitialState {
    pub theta_rad: f64,
    pub theta_sigma_rad: f64,
    pub theta_dot_rad_s: f64,
    pub theta_dot_sigma_rad_s: f64,
}

/// Local polynomial estimate of θ, θ̇ at `t_s`.
pub fn estimate_state(
    run: &RunData,
    t_s: f64,
    cfg: &IcConfig,
) -> Result<InitialState, ProcessError> {
    cfg.validate()?;
    let (t, th) = (&run.enc_t_s, &run.theta_rad);
    let lo = t.partition_point(|&x| x < t_s - cfg.half_window_s);
    let hi = t.partition_point(|&x| x <= t_s + cfg.half_window_s);
    if hi - lo < cfg.order + 3 {
        return Err(ProcessError::Run {
            run: run.id.clone(),
            reason: format!(
                "only {} encoder samples within ±{} s of t = {t_s:.4} s; need {} for an order-{} fit",
                hi - lo,
                cfg.half_window_s,
                cfg.order + 3,
                cfg.order
            ),
        });
    }
    let rows: Vec<Vec<f64>> = (lo..hi)
        .map(|i| {
            let x = (t[i] - t_s) / cfg.half_window_s;
            (0..=cfg.order).map(|p| x.powi(p as i32)).collect()
        })
        .collect();
    let fit = ols(&rows, &th[lo..hi]).map_err(|_| ProcessError::Run {
        run: run.id.clone(),
        reason: format!("singular initial-condition fit at t = {t_s:.4} s"),
    })?;
    let (b, cov) = (fit.coef, fit.cov);
    let n = cfg.order + 1;
    // Quantisation (uniform, 2π/4096) is a floor on the residual variance.
    let q2 = (2.0 * std::f64::consts::PI / 4096.0).powi(2) / 12.0;
    let s0 = cov[0].max(q2 / (hi - lo) as f64).sqrt();
    Ok(InitialState {
        theta_rad: b[0],
        theta_sigma_rad: s0,
        theta_dot_rad_s: b[1] / cfg.half_window_s,
        theta_dot_sigma_rad_s: cov[n + 1].max(0.0).sqrt() / cfg.half_window_s,
    })
}

/// Hanging position from a free decay's turning points in [t_from, t_to]: the median, over
/// windows of k + 1 successive extrema e_i = c + (−1)^i A_i, of their binomial mean
/// Σ C(k, j) e_{i+j} / 2^k, k = 4 where five extrema are read (else as many as there are). The
/// alternating signs make it c + (−1)^i Δ^k A_i / 2^k: an amplitude shrinking as a polynomial of
/// degree < k cancels exactly. Dry friction shrinks it linearly, but a quadratic drag on a wide
/// hand start shrinks it fast and then slowly, and the three-point mean (k = 2) left a quarter of
/// its second difference: on the eight free decays of a drawn campaign (the every-effect survey's
/// `encoder_offset` k=2, `SURVEY_SEED=15`) 0.9 to 5.8 mrad off each run's true zero, where k = 4
/// on the turning points below leaves at most 0.39 (at `SURVEY_SEED=36`, k=0: at most 0.64, and
/// 1.3 and 1.8 on two short decays of three and five turning points);
/// `a_wide_decay_s_centre_is_read_within_a_fraction_of_a_count`. The binomial weights also
/// average the extrema's noise better as k grows (Σ C(k, j)² / 4^k: 0.375, 0.31, 0.27). `None`
/// when there are fewer than three swings or the pendulum turns over.
pub fn hanging_position(run: &RunData, t_from: f64, t_to: f64) -> Option<f64> {
    let (t, th) = (&run.enc_t_s, &run.theta_rad);
    let lo = t.partition_point(|&x| x < t_from);
    let hi = t.partition_point(|&x| x <= t_to);
    if hi < lo + 20 {
        return None;
    }
    let seg = &th[lo..hi];
    if seg.iter().any(|x| x.abs() > std::f64::consts::PI) {
        return None;
    }
    // The turning points the free decay's envelope and alignment read (hysteresis on the
    // angle's noise, so encoder steps and a creeping stop make none; each refined by a parabola),
    // from the first real swing (a hand's tremor before the release is none).
    let tps = pendulum_explain::turning_points(&t[lo..hi], seg);
    let extrema: Vec<f64> = tps[pendulum_explain::first_swing(&tps)..]
        .iter()
        .map(|p| p.theta_rad)
        .collect();
    if extrema.len() < 3 {
        return None;
    }
    // Rows of Pascal's triangle, k = 2, 3, 4.
    const BINOMIAL: [&[f64]; 3] = [
        &[1.0, 2.0, 1.0],
        &[1.0, 3.0, 3.0, 1.0],
        &[1.0, 4.0, 6.0, 4.0, 1.0],
    ];
    let k = (extrema.len() - 1).min(4);
    let weights = BINOMIAL[k - 2];
    let total = weights.iter().sum::<f64>();
    let mut centres: Vec<f64> = extrema
        .windows(k + 1)
        .map(|w| w.iter().zip(weights).map(|(e, c)| e * c).sum::<f64>() / total)
        .collect();
    centres.sort_by(f64::total_cmp);
    Some(centres[centres.len() / 2])
}
