//! Alignment: where the shaker starts, where it is at speed, the real crank speed and phase from a
//! least-squares fit of the exact crank-rod acceleration to the accelerometer, and t = 0 at the
//! first positive acceleration peak at speed (the study's convention).
//!
//! Method: (1) the shaker start is where the vertical signal's short-time RMS leaves the quiet
//! level of the free segment; (2) on a window safely at speed, a coarse search of the fundamental's
//! power over speeds near the set point gives Ω and the phase; (3) Gauss–Newton on
//! a_z = c0 + G·r(2πΩ)²·f''(2πΩ(t − t_p)) refines (c0, G, Ω, t_p) and gives their covariance;
//! (4) walking back peak by peak from the window, the earliest peak from which every cycle carries
//! at least `at_speed_fraction` of the fitted amplitude is t = 0.
//!
//! A run with no shaker (no `omega_hz`: a free decay) is not an error: it gets a
//! [`AlignmentKind::FreeDecay`] alignment with the excitation off. Its t = 0 is the recording's
//! first turning point (θ̇ = 0 there, so the initial state is well determined and a hand release
//! or hold before it is skipped), and the time unit of its fit is the small-swing natural
//! frequency estimated from the swing periods (`pendulum_explain::omega_n_estimate`), since
//! sqrt(g/l) is wrong for a physical pendulum and m, l may be unknown.

use pendulum_fit::{FitError, GaussNewton, GnConfig, LeastSquaresProblem, LsResult, LsStop};
use pendulum_model::excitation::{crank_f1, crank_f2};
use pendulum_numerics::{inverse_spd, median, ols, wls};
use serde::{Deserialize, Serialize};

use crate::run::RunData;
use crate::ProcessError;

/// Alignment settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AlignConfig {
    /// Length of the at-speed window the crank model is fitted on, s.
    pub fit_window_s: f64,
    /// Quiet reference at the start of the capture (shaker off), s.
    pub quiet_s: f64,
    /// A cycle is at speed when its amplitude is at least this fraction of the fitted one
    /// (amplitude ∝ speed², so 0.98 means 99 % of the speed).
    pub at_speed_fraction: f64,
    /// Relative range of real speeds searched around the set point.
    pub speed_search: f64,
    /// Crank turns after the detected start before the fit window begins.
    pub settle_turns: f64,
}

impl Default for AlignConfig {
    fn default() -> Self {
        Self {
            fit_window_s: 20.0,
            quiet_s: 1.0,
            at_speed_fraction: 0.98,
            speed_search: 0.02,
            settle_turns: 3.0,
        }
    }
}

impl AlignConfig {
    pub fn validate(&self) -> Result<(), ProcessError> {
        let checks = [
            ("fit_window_s", self.fit_window_s, self.fit_window_s > 0.0),
            ("quiet_s", self.quiet_s, self.quiet_s > 0.0),
            (
                "at_speed_fraction",
                self.at_speed_fraction,
                self.at_speed_fraction > 0.0 && self.at_speed_fraction < 1.0,
            ),
            (
                "speed_search",
                self.speed_search,
                self.speed_search > 0.0 && self.speed_search < 0.5,
            ),
            ("settle_turns", self.settle_turns, self.settle_turns >= 0.0),
        ];
        for (field, value, ok) in checks {
            if !(ok && value.is_finite()) {
                return Err(ProcessError::BadConfig {
                    stage: "align".into(),
                    field: field.into(),
                    message: format!("{value} is out of range"),
                });
            }
        }
        Ok(())
    }
}

/// Whether a run was aligned to its shaker or is a free decay (excitation off).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AlignmentKind {
    /// t = 0 at the first positive acceleration peak at speed (the study's convention).
    #[default]
    Shaker,
    /// No base motion: t = 0 at the first turning point; the crank fields are NaN.
    FreeDecay,
}

impl AlignmentKind {
    pub fn as_str(self) -> &'static str {
        match self {
            AlignmentKind::Shaker => "shaker",
            AlignmentKind::FreeDecay => "free_decay",
        }
    }
}

/// Where a run's forced motion starts and how its crank turns.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Alignment {
    /// Shaker-aligned or free decay.
    #[serde(default)]
    pub kind: AlignmentKind,
    /// Free decay: the small-swing natural frequency from the swing periods, rad/s: the time
    /// unit of the fit until ω0 is fitted. NaN for shaker runs (their unit is sqrt(g/l)).
    #[serde(default = "nan")]
    pub omega0_est_rad_s: f64,
    /// Detected shaker start, s since the first sample.
    pub shaker_start_s: f64,
    /// The free-motion segment [start, end] before the shaker (a free decay), s: it ends where
    /// the accelerometer last reads quiet before the detected start ([`motion_onset_s`]).
    pub free_segment_s: (f64, f64),
    /// t = 0: the first positive acceleration peak at speed, s since the first sample.
    pub t0_s: f64,
    /// Its standard uncertainty, s.
    pub t0_sigma_s: f64,
    /// Real crank speed, Hz, and its standard uncertainty.
    pub omega_hz: f64,
    pub omega_sigma_hz: f64,
    /// Fitted amplitude over the nominal r(2πΩ)² (accelerometer gain × geometry), –.
    pub accel_gain: f64,
    /// Fitted vertical offset (g plus the sensor's zero-g offset), m/s².
    pub az_offset_m_s2: f64,
    /// RMS of the fit's residual, m/s².
    pub residual_rms_m_s2: f64,
    /// The window the crank model was fitted on, s.
    pub fit_window_s: (f64, f64),
    /// dΩ/dτ from t0, Hz/s: 0 from [`align`]; set when a run is re-aligned on a drifting speed
    /// ([`fit_speed_drift`]).
    #[serde(default)]
    pub speed_drift_hz_per_s: f64,
    /// The accelerometer's own noise, m/s²: robust spread of the vertical signal while the
    /// shaker is off (NaN for free decays).
    #[serde(default = "nan")]
    pub accel_noise_m_s2: f64,
    /// Robust RMS residual of the crank-rod model along the whole forced segment with the crank phase
    /// tracked turn by turn ([`track_crank_phase`]), m/s² (NaN when not tracked).
    #[serde(default = "nan")]
    pub forcing_residual_rms_m_s2: f64,
}

fn nan() -> f64 {
    f64::NAN
}

/// How far above the accelerometer's own noise the crank-rod model's residual may be before the
/// forcing counts as not understood: the model is exact for a rigid crank and rod, so with the
/// phase tracked its residual is the sensor noise; three times it (nine times its variance) is
/// a shape the model does not have.
pub const FORCING_MISFIT_RATIO: f64 = 3.0;

/// The accelerometer's quantisation noise, m/s²: its step (the smallest non-zero change between
/// samples, which a forced run's crossing of adjacent levels shows) over √12. The sensor's noise
/// is never below it, even where the shaker-off stretch reads one level throughout (a noiseless
/// simulated sensor: its measured spread was 0, and every run's forcing, fitted to 4.4e-4 m/s²,
/// its quantisation, counted as not understood).
fn quantisation_noise_m_s2(az: &[f64]) -> f64 {
    let step = az
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| *d > 1e-9)
        .fold(f64::INFINITY, f64::min);
    if step.is_finite() {
        step / 12f64.sqrt()
    } else {
        0.0
    }
}

/// Width of the windows [`motion_onset_s`] tests for base motion, s.
const ONSET_WINDOW_S: f64 = 0.25;

/// Where the base starts to move, walking back from the detected shaker start `start_s`: the
/// end of the latest window of [`ONSET_WINDOW_S`] before it whose mean square about the quiet
/// `level` is what the sensor's `noise` alone gives (within 4 standard deviations of a
/// χ²/n), and whose mean is within 4 standard errors of the level (a crank starting from rest
/// first pushes the base one way: r φ̈ before φ̇² counts). The start is detected where the
/// short-time RMS passes several times the noise or 5 % of the full amplitude, so that a glitch
/// is not a start; a smooth spin-up has then been
/// shaking the base for a second already (0.3–1.2 s on the twin's captures), and a free segment
/// ending there held base motion its free model leaves out: at 5 % of full amplitude, 0.07 g,
/// ten times a cogging torque that the equation error was to find. The walk is bounded by three
/// crank turns at the set speed (the gearmotor is at speed within about two, rig.md): a table
/// that never reads quiet again (a heavy pendulum shaking it) ends the segment there.
fn motion_onset_s(
    t: &[f64],
    az: &[f64],
    level: f64,
    noise: f64,
    start_s: f64,
    omega_hz: f64,
) -> f64 {
    let earliest = start_s - 3.0 / omega_hz;
    let step = 0.025;
    let mut end = start_s;
    while end - ONSET_WINDOW_S > earliest.max(t[0]) {
        let lo = t.partition_point(|&x| x < end - ONSET_WINDOW_S);
        let hi = t.partition_point(|&x| x <= end);
        let n = hi.saturating_sub(lo);
        if n >= 10 {
            let nf = n as f64;
            let ms = az[lo..hi].iter().map(|a| (a - level).powi(2)).sum::<f64>() / nf;
            let mean = az[lo..hi].iter().map(|a| a - level).sum::<f64>() / nf;
            let var = noise * noise;
            if ms <= var * (1.0 + 4.0 * (2.0 / nf).sqrt()) && mean.abs() <= 4.0 * noise / nf.sqrt()
            {
                return end;
            }
        }
        end -= step;
    }
    earliest.max(t[0])
}

impl Alignment {
    /// A free decay (excitation off).
    pub fn is_free(&self) -> bool {
        self.kind == AlignmentKind::FreeDecay
    }

    /// Whether the crank-rod model explains the accelerometer along the whole forced segment
    /// (tracked residual within [`FORCING_MISFIT_RATIO`] of the sensor's noise). Free decays and
    /// runs that could not be tracked count as understood: there is nothing to contradict.
    pub fn forcing_understood(&self) -> bool {
        !(self.forcing_residual_rms_m_s2 > FORCING_MISFIT_RATIO * self.accel_noise_m_s2)
    }

    /// The encoder samples of `run` inside the free-motion segment before the shaker, when the
    /// segment lasts at least `min_s` seconds.
    pub fn free_segment_samples(
        &self,
        run: &crate::RunData,
        min_s: f64,
    ) -> Option<std::ops::Range<usize>> {
        let (a, b) = self.free_segment_s;
        if !(b - a >= min_s) {
            return None;
        }
        Some(run.enc_t_s.partition_point(|&t| t < a)..run.enc_t_s.partition_point(|&t| t <= b))
    }
}

/// The alignment of a run with no shaker (see the module docs).
pub fn align_free_decay(run: &RunData) -> Result<Alignment, ProcessError> {
    let fail = |reason: String| ProcessError::Align {
        run: run.id.clone(),
        reason,
    };
    let (t, th) = (&run.enc_t_s, &run.theta_rad);
    let tps = pendulum_explain::turning_points(t, th);
    // A hold before the release (a hand's tremor) is no swing.
    let tps = &tps[pendulum_explain::first_swing(&tps)..];
    if tps.len() < 3 {
        return Err(fail(format!(
            "no shaker (no omega_hz) and only {} turning points: a free decay needs a few swings",
            tps.len()
        )));
    }
    let w0 = pendulum_explain::omega_n_estimate(tps);
    if !(w0.is_finite() && w0 > 0.0) {
        return Err(fail(format!(
            "free decay: no natural frequency from the swing periods ({w0})"
        )));
    }
    let (first, last) = (t[0], t[t.len() - 1]);
    Ok(Alignment {
        kind: AlignmentKind::FreeDecay,
        omega0_est_rad_s: w0,
        shaker_start_s: f64::NAN,
        free_segment_s: (first, last),
        t0_s: tps[0].t_s,
        t0_sigma_s: f64::NAN,
        omega_hz: f64::NAN,
        omega_sigma_hz: f64::NAN,
        accel_gain: f64::NAN,
        az_offset_m_s2: f64::NAN,
        residual_rms_m_s2: f64::NAN,
        fit_window_s: (f64::NAN, f64::NAN),
        speed_drift_hz_per_s: 0.0,
        accel_noise_m_s2: f64::NAN,
        forcing_residual_rms_m_s2: f64::NAN,
    })
}

fn f3(phi: f64, lambda: f64) -> f64 {
    let h = 1e-5;
    (crank_f2(phi + h, lambda) - crank_f2(phi - h, lambda)) / (2.0 * h)
}

/// Aligns one run (see the module docs).
pub fn align(run: &RunData, cfg: &AlignConfig) -> Result<Alignment, ProcessError> {
    cfg.validate()?;
    let fail = |reason: String| ProcessError::Align {
        run: run.id.clone(),
        reason,
    };
    let Some(omega_set) = run.rig.omega_hz else {
        return align_free_decay(run);
    };
    let (t, az) = (&run.acc_t_s, &run.az_m_s2);
    if t.len() < 50 {
        return Err(fail(format!("only {} accelerometer samples", t.len())));
    }
    let r = run.rig.crank_r_m;
    let lambda = r / run.rig.rod_l_m;
    let two_pi = 2.0 * std::f64::consts::PI;
    let expected_amp = r * (two_pi * omega_set).powi(2) * (1.0 + lambda);

    // (1) Shaker start: short-time RMS about the quiet level.
    let quiet_end = t[0] + cfg.quiet_s;
    let mut quiet: Vec<f64> = t
        .iter()
        .zip(az)
        .filter(|(tt, _)| **tt < quiet_end)
        .map(|(_, a)| *a)
        .collect();
    if quiet.len() < 10 {
        return Err(fail(format!(
            "fewer than 10 accelerometer samples in the first {} s",
            cfg.quiet_s
        )));
    }
    let level = median(&mut quiet.clone());
    let mut dev: Vec<f64> = quiet.iter_mut().map(|a| (*a - level).abs()).collect();
    let sigma_q = 1.4826 * median(&mut dev);
    let threshold = (8.0 * sigma_q).max(0.05 * expected_amp);
    let win = 0.1;
    let mut start = None;
    let mut j0 = 0;
    let mut acc = 0.0;
    for i in 0..t.len() {
        acc += (az[i] - level).powi(2);
        while t[i] - t[j0] > win {
            acc -= (az[j0] - level).powi(2);
            j0 += 1;
        }
        let n = (i - j0 + 1) as f64;
        if n >= 5.0 && (acc / n).sqrt() > threshold {
            start = Some(t[j0]);
            break;
        }
    }
    let shaker_start_s = start.ok_or_else(|| {
        fail(format!(
            "the vertical acceleration never leaves its quiet level {level:.3} m/s² by more than {threshold:.3} m/s² RMS: did the shaker run?"
        ))
    })?;

    // (2) Coarse speed and phase on a window safely at speed.
    let w_start = shaker_start_s + cfg.settle_turns / omega_set;
    let w_end = (w_start + cfg.fit_window_s).min(t[t.len() - 1]);
    if w_end - w_start < 5.0 / omega_set {
        return Err(fail(format!(
            "fewer than 5 crank turns at speed after the shaker start at {shaker_start_s:.3} s"
        )));
    }
    let idx: Vec<usize> = (0..t.len())
        .filter(|&i| t[i] >= w_start && t[i] <= w_end)
        .collect();
    let t_mid = 0.5 * (w_start + w_end);
    let mean_az = idx.iter().map(|&i| az[i]).sum::<f64>() / idx.len() as f64;
    let step = 0.2 / (two_pi * (w_end - w_start)); // ≤ 0.2 rad of phase drift across the window
    let n_steps = ((cfg.speed_search * omega_set) / step).ceil() as i64;
    let mut best = (0.0, omega_set, 0.0);
    for k in -n_steps..=n_steps {
        let om = omega_set + k as f64 * step;
        let (mut c, mut s) = (0.0, 0.0);
        for &i in &idx {
            let ph = two_pi * om * (t[i] - t_mid);
            c += (az[i] - mean_az) * ph.cos();
            s += (az[i] - mean_az) * ph.sin();
        }
        let p = c * c + s * s;
        if p > best.0 {
            best = (p, om, s.atan2(c));
        }
    }
    // Fundamental ∝ cos(2πΩ(t − t_mid) − ψ): its peak (φ = 0) is at t_mid + ψ/(2πΩ).
    let p = [mean_az, 1.0, best.1, best.2 / (two_pi * best.1)];

    // (3) Gauss–Newton on (c0, G, Ω, t_p − t_mid).
    let window = CrankWindow {
        t,
        az,
        idx: &idx,
        r,
        lambda,
        t_mid,
    };
    // Converged when Ω moves by < 1e-12 relative and t_p by < 0.1 ns, after at least 3 steps.
    let inf = f64::INFINITY;
    let gn = GnConfig::default()
        .with_max_iterations(30)
        .with_min_iterations(3)
        .with_step_tolerance(vec![inf, inf, 0.0, 1e-10], vec![0.0, 0.0, 1e-12, 0.0]);
    let fit = GaussNewton::new(gn)
        .and_then(|gn| gn.solve(&window, &p))
        .map_err(|e| match e {
            FitError::Singular { .. } => fail("the crank-model fit is singular".into()),
            e => fail(format!("the crank-model fit failed: {e}")),
        })?;
    let n = idx.len() as f64;
    let rms = (fit.rss / n).sqrt();
    let cov = covariance(&fit, (n - 4.0).max(1.0)).unwrap_or_else(|| vec![0.0; 16]);
    let p = fit.x;
    if !(p[1] > 0.0 && p[2] > 0.0) {
        return Err(fail(format!(
            "the crank-model fit diverged (gain {}, speed {} Hz)",
            p[1], p[2]
        )));
    }
    let (c0, gain, omega, tp) = (p[0], p[1], p[2], p[3] + t_mid);
    let period = 1.0 / omega;

    // (4) Walk back from the first peak in the window while peaks carry the full amplitude.
    // At a peak (φ = 0) f'(0) = 0, so the peak value is r(1 + λ)·φ̇²: a local quadratic fit of
    // a_z around the peak measures the speed there, with no bias from the ramp before it.
    let full = gain * r * (two_pi * omega).powi(2) * crank_f2(0.0, lambda);
    let peak_ratio = |tc: f64| -> Option<f64> {
        let half = 0.1 * period;
        let lo = t.partition_point(|&x| x < tc - half);
        let hi = t.partition_point(|&x| x <= tc + half);
        if hi - lo < 6 {
            return None;
        }
        let rows: Vec<Vec<f64>> = (lo..hi)
            .map(|i| {
                let x = (t[i] - tc) / half;
                vec![1.0, x, x * x]
            })
            .collect();
        let b = ols(&rows, &az[lo..hi]).ok()?.coef;
        // Vertex of the parabola if it lies in the window, else the value at the predicted peak.
        let peak = if b[2] < 0.0 && (b[1] / (2.0 * b[2])).abs() <= 1.0 {
            b[0] - b[1] * b[1] / (4.0 * b[2])
        } else {
            b[0]
        };
        Some((peak - c0) / full)
    };
    let mut k = ((w_start - tp) / period).ceil();
    loop {
        let prev = tp + (k - 1.0) * period;
        if prev < shaker_start_s - period {
            break;
        }
        match peak_ratio(prev) {
            Some(q) if q >= cfg.at_speed_fraction => k -= 1.0,
            _ => break,
        }
    }
    let t0_s = tp + k * period;
    let noise = sigma_q.max(quantisation_noise_m_s2(az));
    // t0 = t_p + k/Ω: propagate the covariance of (Ω, t_p).
    let d_om = -k / (omega * omega);
    let var = cov[3 * 4 + 3] + d_om * d_om * cov[2 * 4 + 2] + 2.0 * d_om * cov[2 * 4 + 3];
    let mut al = Alignment {
        kind: AlignmentKind::Shaker,
        omega0_est_rad_s: f64::NAN,
        shaker_start_s,
        free_segment_s: (
            t[0],
            (motion_onset_s(t, az, level, noise, shaker_start_s, omega_set) - 0.05).max(t[0]),
        ),
        t0_s,
        t0_sigma_s: var.max(0.0).sqrt(),
        omega_hz: omega,
        omega_sigma_hz: cov[2 * 4 + 2].max(0.0).sqrt(),
        accel_gain: gain,
        az_offset_m_s2: c0,
        residual_rms_m_s2: rms,
        fit_window_s: (w_start, w_end),
        speed_drift_hz_per_s: 0.0,
        accel_noise_m_s2: noise,
        forcing_residual_rms_m_s2: f64::NAN,
    };
    if let Some(track) = track_crank_phase(run, &al) {
        al.forcing_residual_rms_m_s2 = track.residual_rms_m_s2;
    }
    Ok(al)
}

/// The crank phase followed turn by turn along a run's forced segment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhaseTrack {
    /// Block centres, s from the alignment's t0.
    pub tau_s: Vec<f64>,
    /// Crank phase at each centre (unwrapped, 0 at t0 for the alignment's own phase), rad, and
    /// its standard uncertainty.
    pub phase_rad: Vec<f64>,
    pub phase_sigma_rad: Vec<f64>,
    /// Robust RMS (1.4826 × the median absolute residual) of the crank-rod model over every
    /// tracked block, m/s²: a systematic misfit shows in every sample, a glitch or a dropout's
    /// edge in a few, which must not make a run's forcing look misunderstood.
    pub residual_rms_m_s2: f64,
}

impl PhaseTrack {
    /// Weighted least-squares quadratic φ(τ) = a0 + a1 τ + a2 τ² through the track: Ω at t0 is
    /// a1/2π and dΩ/dτ is a2/π. Returns (a0, a1, a2) and the covariance's diagonal, the latter
    /// scaled by the fit's reduced χ² when that exceeds 1 (a speed that wanders more than the
    /// track's own scatter says widens the interval rather than hiding in it).
    pub fn quadratic(&self) -> Option<([f64; 3], [f64; 3])> {
        let n = self.tau_s.len();
        if n < 6 {
            return None;
        }
        let rows: Vec<[f64; 3]> = self.tau_s.iter().map(|&t| [1.0, t, t * t]).collect();
        let w: Vec<f64> = self
            .phase_sigma_rad
            .iter()
            .map(|s| 1.0 / s.powi(2).max(1e-300))
            .collect();
        // Inverse-variance weights: the weighted RSS is the χ², (XᵀWX)⁻¹ the covariance.
        let fit = wls(&rows, &self.phase_rad, &w).ok()?;
        let (c, inv) = (fit.coef, fit.cov_unscaled);
        let red = (fit.rss / (n as f64 - 3.0)).max(1.0);
        Some((
            [c[0], c[1], c[2]],
            [inv[0] * red, inv[4] * red, inv[8] * red],
        ))
    }
}

/// Follows the crank phase from t0 to the end of the capture in blocks of two crank turns: in
/// each, Gauss–Newton on a local phase and speed (offset and gain from the alignment), started
/// from the previous block's phase and speed carried forward, so the phase never has to be
/// found across more than a fraction of a turn. A drifting motor, which puts a constant-speed
/// model tens of radians off by the end of a run (and a linear-drift fit started from zero
/// drift out of reach), is then just a slowly bending track. Stops at a block it cannot lock
/// onto (a gap, the shaker stopping). `None` for free decays or fewer than six blocks.
pub fn track_crank_phase(run: &RunData, al: &Alignment) -> Option<PhaseTrack> {
    if al.is_free() || !(al.omega_hz > 0.0) {
        return None;
    }
    let (t, az) = (&run.acc_t_s, &run.az_m_s2);
    let r = run.rig.crank_r_m;
    let lambda = r / run.rig.rod_l_m;
    let two_pi = 2.0 * std::f64::consts::PI;
    let (c0, g) = (al.az_offset_m_s2, al.accel_gain);
    let mut omega = two_pi * al.omega_hz; // rad/s
    let mut period = 1.0 / al.omega_hz;
    // The phase at t0 is 0 by the alignment's definition; the first block starts there.
    let (mut tc_prev, mut psi_prev) = (al.t0_s, 0.0);
    let mut a = al.t0_s;
    let t_end = *t.last()?;
    let mut track = PhaseTrack {
        tau_s: Vec::new(),
        phase_rad: Vec::new(),
        phase_sigma_rad: Vec::new(),
        residual_rms_m_s2: f64::NAN,
    };
    let mut abs_res: Vec<f64> = Vec::new();
    // Converged when the phase moves by < 1e-9 rad and the speed by < 1e-9 relative.
    let inf = f64::INFINITY;
    let gn = GnConfig::default()
        .with_max_iterations(10)
        .with_step_tolerance(vec![1e-9, 0.0, inf, inf], vec![0.0, 1e-9, 0.0, 0.0]);
    let gn = GaussNewton::new(gn).ok()?;
    while a + 2.0 * period <= t_end {
        let b = a + 2.0 * period;
        let tc = 0.5 * (a + b);
        let lo = t.partition_point(|&x| x < a);
        let hi = t.partition_point(|&x| x < b);
        // A block with a gap (fewer than 80 % of its samples) is stepped over on the prediction.
        let expected = 2.0 * period / median_step(t).max(1e-9);
        if ((hi - lo) as f64) < 0.8 * expected || hi - lo < 12 {
            a = b;
            continue;
        }
        // p = [ψ, ω, G, c0]: the block's own gain and offset too, so that a constant-speed
        // alignment's biased amplitude (a drifting crank) or a slowly moving zero-g offset is not
        // counted as a forcing the model does not understand.
        let block = CrankBlock {
            t,
            az,
            range: lo..hi,
            tc,
            r,
            lambda,
        };
        let p0 = [psi_prev + omega * (tc - tc_prev), omega, g, c0];
        let Ok(fit) = gn.solve(&block, &p0) else {
            break;
        };
        let ok = fit.stop == LsStop::Converged;
        let cov00 = covariance(&fit, (hi - lo) as f64 - 4.0).map_or(f64::NAN, |c| c[0]);
        let p = fit.x;
        let predicted = psi_prev + omega * (tc - tc_prev);
        // Lost lock: no convergence, or a jump of more than a quarter turn from the prediction.
        if !ok || (p[0] - predicted).abs() > 0.25 * two_pi || !(p[1] > 0.0 && p[2] > 0.0) {
            break;
        }
        abs_res.extend(fit.residuals.iter().map(|v| v.abs()));
        track.tau_s.push(tc - al.t0_s);
        track.phase_rad.push(p[0]);
        track.phase_sigma_rad.push(cov00.max(1e-12).sqrt());
        (tc_prev, psi_prev, omega) = (tc, p[0], p[1]);
        period = two_pi / omega;
        a = b;
    }
    if track.tau_s.len() < 6 {
        return None;
    }
    track.residual_rms_m_s2 = 1.4826 * median(&mut abs_res);
    Some(track)
}

fn median_step(t: &[f64]) -> f64 {
    let mut d: Vec<f64> = t
        .windows(2)
        .map(|w| w[1] - w[0])
        .filter(|d| *d > 0.0)
        .collect();
    median(&mut d)
}

/// A crank fit that lets the speed drift linearly (the effect `speed_drift`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DriftFit {
    /// The positive acceleration peak nearest the alignment's t0 under the drifting phase, s.
    pub t0_s: f64,
    /// Crank speed at that peak, Hz.
    pub omega_hz: f64,
    /// Amplitude over the nominal crank-rod acceleration (as [`Alignment::accel_gain`]), –.
    pub accel_gain: f64,
    /// dΩ/dτ, Hz/s, and its standard uncertainty.
    pub drift_hz_per_s: f64,
    pub drift_sigma_hz_per_s: f64,
    /// RMS of the fit's residual, m/s².
    pub residual_rms_m_s2: f64,
}

/// Refits a shaker run's crank model from the alignment's window start to the end of the
/// capture with a linearly drifting speed Ω(τ) = Ω0 + (dΩ/dτ)·τ, τ from the (re-found) t0:
/// a_z = c0 + G·r·[(2πΩ(τ))² f''(φ) + 2π(dΩ/dτ) f'(φ)], φ = 2π(Ω0 τ + ½(dΩ/dτ)τ²).
/// Gauss–Newton from the constant-speed alignment (numerical Jacobian). `None` for free decays
/// or when the fit does not converge.
pub fn fit_speed_drift(run: &RunData, al: &Alignment) -> Option<DriftFit> {
    debug_assert!(
        al.speed_drift_hz_per_s == 0.0,
        "re-fitting a re-aligned run"
    );
    if al.is_free() {
        return None;
    }
    let (t, az) = (&run.acc_t_s, &run.az_m_s2);
    let r = run.rig.crank_r_m;
    let lambda = r / run.rig.rod_l_m;
    let two_pi = 2.0 * std::f64::consts::PI;
    let idx: Vec<usize> = (0..t.len())
        .filter(|&i| t[i] >= al.fit_window_s.0)
        .collect();
    if idx.len() < 50 {
        return None;
    }
    // p = [c0, G, Ω0 (Hz), dΩ/dτ (Hz/s), δ (s): the peak's shift from al.t0_s].
    let problem = DriftProblem {
        t,
        az,
        idx: &idx,
        t0: al.t0_s,
        r,
        lambda,
    };
    // Start from the phase track's quadratic (Ω at t0, dΩ/dτ, the peak's shift): started from
    // zero drift, Gauss–Newton cannot reach a drift whose phase error is many turns by the end.
    let mut p = [al.az_offset_m_s2, al.accel_gain, al.omega_hz, 0.0, 0.0];
    if let Some(([a0, a1, a2], _)) = track_crank_phase(run, al).and_then(|tr| tr.quadratic()) {
        // φ = 2πΩ0(τ − δ) + πΩ̇(τ − δ)² = a0 + a1 τ + a2 τ² to first order in δ.
        let drift = a2 / std::f64::consts::PI;
        let delta = -a0 / a1;
        let om0 = (a1 + 2.0 * a2 * delta) / two_pi;
        if drift.is_finite() && delta.is_finite() && om0 > 0.0 {
            p = [al.az_offset_m_s2, al.accel_gain, om0, drift, delta];
        }
    }
    // Converged when Ω0 moves by < 1e-12 relative, dΩ/dτ by < 1e-12 Hz/s and δ by < 0.1 ns.
    let inf = f64::INFINITY;
    let gn = GnConfig::default()
        .with_max_iterations(20)
        .with_step_tolerance(
            vec![inf, inf, 0.0, 1e-12, 1e-10],
            vec![0.0, 0.0, 1e-12, 0.0, 0.0],
        );
    let fit = GaussNewton::new(gn).ok()?.solve(&problem, &p).ok()?;
    let n = idx.len() as f64;
    let rms = (fit.rss / n).sqrt();
    let var = covariance(&fit, n - 5.0).map_or(0.0, |c| c[3 * 5 + 3]);
    let converged = fit.stop == LsStop::Converged;
    let p = fit.x;
    (converged && p[1] > 0.0 && p[2] > 0.0).then_some(DriftFit {
        t0_s: al.t0_s + p[4],
        omega_hz: p[2],
        accel_gain: p[1],
        drift_hz_per_s: p[3],
        drift_sigma_hz_per_s: var.max(0.0).sqrt(),
        residual_rms_m_s2: rms,
    })
}

/// (JᵀJ)⁻¹ · rss/`dof` at a least-squares solution, row-major; `None` if JᵀJ is singular.
fn covariance(fit: &LsResult, dof: f64) -> Option<Vec<f64>> {
    let s2 = fit.rss / dof;
    let inv = inverse_spd(&fit.jtj(), fit.x.len()).ok()?;
    Some(inv.iter().map(|v| v * s2).collect())
}

/// Step (3) of [`align`]: a_z = c0 + G·r(2πΩ)²·f''(2πΩ(t − t_mid − t_p)) on the fit window, in
/// p = (c0, G, Ω, t_p − t_mid), with its analytic Jacobian.
struct CrankWindow<'a> {
    t: &'a [f64],
    az: &'a [f64],
    idx: &'a [usize],
    r: f64,
    lambda: f64,
    t_mid: f64,
}

impl CrankWindow<'_> {
    /// The model at `ti` and its gradient in p.
    fn model(&self, p: &[f64], ti: f64) -> (f64, [f64; 4]) {
        let two_pi = 2.0 * std::f64::consts::PI;
        let (c0, g, om, tp) = (p[0], p[1], p[2], p[3]);
        let kk = self.r * (two_pi * om).powi(2);
        let dt = ti - self.t_mid - tp;
        let phi = two_pi * om * dt;
        let f2 = crank_f2(phi, self.lambda);
        let d3 = f3(phi, self.lambda);
        let val = c0 + g * kk * f2;
        let j = [
            1.0,
            kk * f2,
            g * (2.0 * kk / om * f2 + kk * d3 * two_pi * dt),
            -g * kk * d3 * two_pi * om,
        ];
        (val, j)
    }
}

impl LeastSquaresProblem for CrankWindow<'_> {
    fn dim(&self) -> usize {
        4
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        vec![(f64::NEG_INFINITY, f64::INFINITY); 4]
    }
    fn residuals(&self, p: &[f64]) -> Option<Vec<f64>> {
        let r = self
            .idx
            .iter()
            .map(|&i| self.az[i] - self.model(p, self.t[i]).0);
        Some(r.collect())
    }
    fn jacobian(&self, p: &[f64], _r: &[f64]) -> Option<Vec<Vec<f64>>> {
        let mut cols: Vec<Vec<f64>> = (0..4).map(|_| Vec::with_capacity(self.idx.len())).collect();
        for &i in self.idx {
            let (_, j) = self.model(p, self.t[i]);
            for (c, v) in cols.iter_mut().zip(j) {
                c.push(-v);
            }
        }
        Some(cols)
    }
}

/// One block of [`track_crank_phase`]: a_z = c0 + G·r·ω²·f''(ψ + ω(t − tc)) on samples `range`,
/// in p = [ψ, ω, G, c0], with its analytic Jacobian.
struct CrankBlock<'a> {
    t: &'a [f64],
    az: &'a [f64],
    range: std::ops::Range<usize>,
    tc: f64,
    r: f64,
    lambda: f64,
}

impl LeastSquaresProblem for CrankBlock<'_> {
    fn dim(&self) -> usize {
        4
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        vec![(f64::NEG_INFINITY, f64::INFINITY); 4]
    }
    fn residuals(&self, p: &[f64]) -> Option<Vec<f64>> {
        let model = |i: usize| {
            let phi = p[0] + p[1] * (self.t[i] - self.tc);
            p[3] + p[2] * self.r * p[1] * p[1] * crank_f2(phi, self.lambda)
        };
        Some(self.range.clone().map(|i| self.az[i] - model(i)).collect())
    }
    fn jacobian(&self, p: &[f64], _r: &[f64]) -> Option<Vec<Vec<f64>>> {
        let mut cols: Vec<Vec<f64>> = (0..4)
            .map(|_| Vec::with_capacity(self.range.len()))
            .collect();
        for i in self.range.clone() {
            let dt = self.t[i] - self.tc;
            let phi = p[0] + p[1] * dt;
            let f2 = crank_f2(phi, self.lambda);
            let d_psi = p[2] * self.r * p[1] * p[1] * f3(phi, self.lambda);
            let j = [
                d_psi,
                d_psi * dt + 2.0 * p[2] * self.r * p[1] * f2,
                self.r * p[1] * p[1] * f2,
                1.0,
            ];
            for (c, v) in cols.iter_mut().zip(j) {
                c.push(-v);
            }
        }
        Some(cols)
    }
}

/// [`fit_speed_drift`]'s model a_z = c0 + G·r·[(2πΩ(τ))² f''(φ) + 2π(dΩ/dτ) f'(φ)] on samples
/// `idx`, in p = [c0, G, Ω0 (Hz), dΩ/dτ (Hz/s), δ (s)], τ = t − t0 − δ.
struct DriftProblem<'a> {
    t: &'a [f64],
    az: &'a [f64],
    idx: &'a [usize],
    t0: f64,
    r: f64,
    lambda: f64,
}

impl DriftProblem<'_> {
    fn model(&self, p: &[f64], ti: f64) -> f64 {
        let two_pi = 2.0 * std::f64::consts::PI;
        let tau = ti - self.t0 - p[4];
        let phi = two_pi * (p[2] * tau + 0.5 * p[3] * tau * tau);
        let rate = two_pi * (p[2] + p[3] * tau);
        p[0] + p[1]
            * self.r
            * (rate * rate * crank_f2(phi, self.lambda)
                + two_pi * p[3] * crank_f1(phi, self.lambda))
    }
}

impl LeastSquaresProblem for DriftProblem<'_> {
    fn dim(&self) -> usize {
        5
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        vec![(f64::NEG_INFINITY, f64::INFINITY); 5]
    }
    fn residuals(&self, p: &[f64]) -> Option<Vec<f64>> {
        Some(
            self.idx
                .iter()
                .map(|&i| self.az[i] - self.model(p, self.t[i]))
                .collect(),
        )
    }
    /// Central differences of the model itself with fixed steps (not of a_z − model, which
    /// would put the data into the cancellation).
    fn jacobian(&self, p: &[f64], _r: &[f64]) -> Option<Vec<Vec<f64>>> {
        let steps = [1e-4, 1e-7, 1e-8, 1e-8, 1e-7];
        let mut cols: Vec<Vec<f64>> = (0..5).map(|_| Vec::with_capacity(self.idx.len())).collect();
        for &i in self.idx {
            for (k, col) in cols.iter_mut().enumerate() {
                let (mut hi, mut lo) = ([0.0; 5], [0.0; 5]);
                hi.copy_from_slice(p);
                lo.copy_from_slice(p);
                hi[k] += steps[k];
                lo[k] -= steps[k];
                let d = self.model(&hi, self.t[i]) - self.model(&lo, self.t[i]);
                col.push(-d / (2.0 * steps[k]));
            }
        }
        Some(cols)
    }
}
