//! The rig's digital twin: simulates a campaign with the full physics of `effects.md` and the
//! sensors and firmware of `rig.md`, and writes raw captures, `campaign.toml` and the truth.
//!
//! Everything is drawn from one seed (ChaCha8), so a case file always gives the same bytes.
//!
//! A run: the pendulum is released by hand (θ0, θ̇0) with the shaker stopped; after `free_s` the
//! shaker starts and reaches speed with a smooth ramp over `spinup_turns` crank turns; the real
//! crank speed is the set point times (1 + ε), |ε| ≤ `speed_error_max`. The truth's t = 0 is the
//! first crank angle φ = 2πn (the positive acceleration peak) after the crank is at speed.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use pendulum_model::{
    classify_poincare, integrate, ClassifyOptions, CrankDrive, Effects, Excitation, Model,
    Physical, Sensors, SimOptions, SteadyState,
};
use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::capture::Header;
use crate::sd::SdWriter;
use crate::serial::SerialWriter;
use crate::RigError;

/// A twin case: the rig, the truth, the sensors and the runs (`pendulum synth CASE.toml`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwinCase {
    pub name: String,
    pub seed: u64,
    pub rig: TwinRig,
    pub truth: TwinTruth,
    #[serde(default)]
    pub sensors: SensorModel,
    #[serde(rename = "run")]
    pub runs: Vec<TwinRun>,
}

/// Geometry shared by the runs, SI.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwinRig {
    pub m_kg: f64,
    pub l_m: f64,
    pub crank_r_m: f64,
    #[serde(rename = "rod_L_m")]
    pub rod_l_m: f64,
    pub r_b_m: f64,
    #[serde(default = "default_g")]
    pub g_m_s2: f64,
}

fn default_g() -> f64 {
    pendulum_model::params::G_STANDARD_M_S2
}

/// The damping and effects the captures really hold.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwinTruth {
    #[serde(default)]
    pub a_kg_m: f64,
    pub b_n_s_m: f64,
    pub mu: f64,
    #[serde(default)]
    pub effects: Effects,
    /// Departures outside the catalogue (effects.md, last paragraph), for tests of an honest
    /// `unexplained`: the analysis has no name for them.
    #[serde(default)]
    pub departures: Departures,
}

/// What a real rig can hold that no catalogue entry describes.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Departures {
    /// A linear torsion spring (a cable) adding −k θ about the hanging position, θ unwrapped,
    /// N·m/rad.
    #[serde(default)]
    pub torsion_spring_nm_per_rad: Option<f64>,
    /// The spring's cable hangs slack within ± this angle of the hanging position, rad, and
    /// pulls only beyond it (a dead band in the unwrapped θ; with `torsion_spring_nm_per_rad`).
    #[serde(default)]
    pub cable_slack_rad: Option<f64>,
    /// The spring's cable is anchored so that it is unstretched at this angle, rad, not at the
    /// hanging position: −k (θ − anchor), a spring plus a constant torque k·anchor that pulls
    /// the pendulum to one side (with `torsion_spring_nm_per_rad`).
    #[serde(default)]
    pub cable_anchor_rad: Option<f64>,
    /// The encoder's real counts per revolution while its header says 4096 (a mislabelled
    /// encoder).
    #[serde(default)]
    pub encoder_cpr_true: Option<f64>,
    /// A constant dry torque that grows as the rig runs, N·m per second from the capture's
    /// start (a bearing heating up, a seal drying out): T_c(t) = rate · t, sgn θ'.
    #[serde(default)]
    pub dry_torque_growth_nm_per_s: Option<f64>,
    /// Play between the shaft and the encoder (a loose coupling), rad: the encoder's disc stays
    /// put while the shaft turns inside the play and is dragged along at its edge, so the
    /// measured angle lags the shaft by half the play in the direction of motion and stands
    /// still for a moment at every turn-around (a dead band in the measured angle).
    #[serde(default)]
    pub encoder_backlash_rad: Option<f64>,
    /// Bearing friction that differs from run to run (a bearing re-seated, warmed or re-greased
    /// between runs): each run's μ is the truth's times 1 + u, u drawn uniformly within
    /// ± this fraction from the run's own seed.
    #[serde(default)]
    pub mu_run_spread: Option<f64>,
    /// A bob that bounces on a springy mount along the rod (effects.md's "a bob that wobbles"):
    /// the mount's radial natural frequency with the bob on it, Hz. The bob hangs at l at rest
    /// and gives under centrifugal load and the base's acceleration ([`crate::bounce`]).
    #[serde(default)]
    pub bob_bounce_hz: Option<f64>,
    /// The bouncing mount's damping ratio (default 0.05; with `bob_bounce_hz`).
    #[serde(default)]
    pub bob_bounce_damping_ratio: Option<f64>,
    /// A code disc mounted off its shaft's centre (an eccentricity e on a code track of radius
    /// R reads the angle with an error (e/R)·sin(θ − φ), once per revolution): this e/R, rad.
    /// The count is zeroed with the pendulum hanging, so the measured angle is
    /// θ + ε·(sin(θ − φ) + sin φ): a scale error of ε cos φ about the hanging position, a
    /// once-per-turn error on rotating runs.
    #[serde(default)]
    pub encoder_eccentricity_rad: Option<f64>,
    /// Where the eccentricity's error peaks, φ, rad (default 0; with
    /// `encoder_eccentricity_rad`).
    #[serde(default)]
    pub encoder_eccentricity_phase_rad: Option<f64>,
    /// A dry torque that varies around the turn (a bent shaft or an oval seal dragging more
    /// over part of each turn), N·m: T·(1 + cos(k θ − φ)) sgn θ', from 0 to 2T, held in full at
    /// rest.
    #[serde(default)]
    pub dry_torque_lobes_nm: Option<f64>,
    /// Its lobes per turn, k (default 1; with `dry_torque_lobes_nm`).
    #[serde(default)]
    pub dry_torque_lobes_k: Option<u32>,
    /// Where it drags most, φ, rad (default 0; with `dry_torque_lobes_nm`).
    #[serde(default)]
    pub dry_torque_lobes_phase_rad: Option<f64>,
    /// The pendulum's bearing bracket sways in the pendulum's plane as the table shakes (a
    /// compliant mount): its axis moves x = s·y relative to the worktable, this s. The pendulum
    /// feels it as a tilted guide would, but the accelerometer, fixed to the worktable, does not
    /// see it (effects.md's `horizontal_base` is a tilt the accelerometer's x axis sees).
    #[serde(default)]
    pub axis_sway_ratio: Option<f64>,
    /// A drag growing as the cube of the speed (a paddle whose wake turns turbulent, a grease
    /// that thickens with shear): a torque −c θ̇³, this c in N·m·s³/rad³. The catalogue's
    /// viscous and quadratic drags only approximate it.
    #[serde(default)]
    pub cubic_drag_nm_s3_per_rad3: Option<f64>,
    /// A viscous drag over part of the turn (an eddy-current brake: a magnet beside the swing):
    /// a torque −c θ̇ (1 + cos(θ − φ))/2, this c in N·m·s/rad where it is strongest.
    #[serde(default)]
    pub eddy_brake_nm_s_per_rad: Option<f64>,
    /// Where the eddy brake is strongest, φ, rad (default 0, the hanging position; with
    /// `eddy_brake_nm_s_per_rad`).
    #[serde(default)]
    pub eddy_brake_phase_rad: Option<f64>,
}

impl Departures {
    /// The first departure outside its physical range, as (key, what was expected): a spring or
    /// a friction growth below 0 would feed energy in, and an encoder needs counts per turn.
    pub fn invalid(&self) -> Option<(&'static str, &'static str)> {
        let bad =
            |v: Option<f64>, ok: fn(f64) -> bool| v.is_some_and(|v| !(v.is_finite() && ok(v)));
        if bad(self.torsion_spring_nm_per_rad, |v| v >= 0.0) {
            return Some((
                "torsion_spring_nm_per_rad",
                "a finite stiffness ≥ 0 N·m/rad",
            ));
        }
        if bad(self.cable_slack_rad, |v| v >= 0.0) {
            return Some(("cable_slack_rad", "a finite slack ≥ 0 rad"));
        }
        if self.cable_slack_rad.is_some() && self.torsion_spring_nm_per_rad.is_none() {
            return Some((
                "cable_slack_rad",
                "a slack beside a torsion_spring_nm_per_rad (alone it has no cable to slacken)",
            ));
        }
        if bad(self.cable_anchor_rad, |v| v.abs() < std::f64::consts::PI) {
            return Some(("cable_anchor_rad", "a finite anchor within ±π rad"));
        }
        if self.cable_anchor_rad.is_some() && self.torsion_spring_nm_per_rad.is_none() {
            return Some((
                "cable_anchor_rad",
                "an anchor beside a torsion_spring_nm_per_rad (alone it has no cable to anchor)",
            ));
        }
        if bad(self.encoder_cpr_true, |v| v >= 1.0) {
            return Some(("encoder_cpr_true", "a finite count per revolution ≥ 1"));
        }
        if bad(self.encoder_backlash_rad, |v| (0.0..1.0).contains(&v)) {
            return Some((
                "encoder_backlash_rad",
                "a finite play in [0, 1) rad between shaft and encoder",
            ));
        }
        if bad(self.mu_run_spread, |v| (0.0..1.0).contains(&v)) {
            return Some((
                "mu_run_spread",
                "a finite fraction in [0, 1) (a bearing friction below 0 would feed energy in)",
            ));
        }
        if bad(self.bob_bounce_hz, |v| v > 0.0) {
            return Some(("bob_bounce_hz", "a finite mount frequency > 0 Hz"));
        }
        if bad(self.bob_bounce_damping_ratio, |v| (0.0..2.0).contains(&v)) {
            return Some((
                "bob_bounce_damping_ratio",
                "a finite damping ratio in [0, 2) (below 0 the mount would feed energy in)",
            ));
        }
        if self.bob_bounce_damping_ratio.is_some() && self.bob_bounce_hz.is_none() {
            return Some((
                "bob_bounce_damping_ratio",
                "a damping ratio beside a bob_bounce_hz (alone it has no mount to damp)",
            ));
        }
        if bad(self.encoder_eccentricity_rad, |v| (0.0..0.5).contains(&v)) {
            return Some((
                "encoder_eccentricity_rad",
                "a finite eccentricity e/R in [0, 0.5) rad",
            ));
        }
        if bad(self.encoder_eccentricity_phase_rad, |v| {
            v.abs() <= 2.0 * std::f64::consts::PI
        }) {
            return Some((
                "encoder_eccentricity_phase_rad",
                "a finite phase within ±2π rad",
            ));
        }
        if self.encoder_eccentricity_phase_rad.is_some() && self.encoder_eccentricity_rad.is_none()
        {
            return Some((
                "encoder_eccentricity_phase_rad",
                "a phase beside an encoder_eccentricity_rad (alone it has no disc to misplace)",
            ));
        }
        if bad(self.axis_sway_ratio, |v| v.abs() < 0.5) {
            return Some(("axis_sway_ratio", "a finite sway ratio within ±0.5"));
        }
        if bad(self.dry_torque_lobes_nm, |v| v >= 0.0) {
            return Some((
                "dry_torque_lobes_nm",
                "a finite size ≥ 0 N·m (a dry torque below 0 would feed energy in)",
            ));
        }
        if self.dry_torque_lobes_k.is_some_and(|k| k == 0) {
            return Some(("dry_torque_lobes_k", "a lobe count ≥ 1"));
        }
        if bad(self.dry_torque_lobes_phase_rad, |v| {
            v.abs() <= 2.0 * std::f64::consts::PI
        }) {
            return Some((
                "dry_torque_lobes_phase_rad",
                "a finite phase within ±2π rad",
            ));
        }
        if (self.dry_torque_lobes_k.is_some() || self.dry_torque_lobes_phase_rad.is_some())
            && self.dry_torque_lobes_nm.is_none()
        {
            return Some((
                if self.dry_torque_lobes_k.is_some() {
                    "dry_torque_lobes_k"
                } else {
                    "dry_torque_lobes_phase_rad"
                },
                "a lobe count or phase beside a dry_torque_lobes_nm (alone it has no torque to shape)",
            ));
        }
        if bad(self.eddy_brake_nm_s_per_rad, |v| v >= 0.0) {
            return Some((
                "eddy_brake_nm_s_per_rad",
                "a finite drag coefficient ≥ 0 N·m·s/rad (below 0 it would feed energy in)",
            ));
        }
        if bad(self.eddy_brake_phase_rad, |v| {
            v.abs() <= 2.0 * std::f64::consts::PI
        }) {
            return Some(("eddy_brake_phase_rad", "a finite phase within ±2π rad"));
        }
        if self.eddy_brake_phase_rad.is_some() && self.eddy_brake_nm_s_per_rad.is_none() {
            return Some((
                "eddy_brake_phase_rad",
                "a phase beside an eddy_brake_nm_s_per_rad (alone it has no brake to place)",
            ));
        }
        if bad(self.cubic_drag_nm_s3_per_rad3, |v| v >= 0.0) {
            return Some((
                "cubic_drag_nm_s3_per_rad3",
                "a finite drag coefficient ≥ 0 N·m·s³/rad³ (below 0 it would feed energy in)",
            ));
        }
        if bad(self.dry_torque_growth_nm_per_s, |v| v >= 0.0) {
            return Some((
                "dry_torque_growth_nm_per_s",
                "a finite growth ≥ 0 N·m/s (a dry torque that shrinks below 0 would feed energy in)",
            ));
        }
        None
    }
}

/// Sensor and firmware imperfections (`rig.md`); defaults are the rig's typical values.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensorModel {
    /// Accelerometer noise density, µg/√Hz.
    pub accel_noise_ug_rt_hz: f64,
    /// Accelerometer internal low-pass corner, Hz (band-limits the noise; its delay is compensated).
    pub accel_lpf_hz: f64,
    /// Largest zero-g offset per axis, LSB (drawn per run).
    pub accel_offset_lsb_max: f64,
    /// Sample-time jitter (standard deviation), µs.
    pub jitter_us: f64,
    /// Probability that a serial line is cut, garbled or merged with the next.
    pub serial_glitch_rate: f64,
    /// Probability per line that a burst of 5–40 serial samples goes missing.
    pub serial_burst_rate: f64,
    /// Corrupted spots per MB of SD capture.
    pub sd_corruptions_per_mb: f64,
    /// Cut the SD capture's last frame short (a power cut).
    pub sd_truncate_last_frame: bool,
    /// Largest relative error of the real crank speed vs its set point.
    pub speed_error_max: f64,
    /// Spin-up length in crank turns.
    pub spinup_turns: f64,
    /// Largest encoder zeroing error, counts (the effect `encoder_offset` comes on top).
    pub encoder_zero_counts_max: i64,
}

impl Default for SensorModel {
    fn default() -> Self {
        Self {
            accel_noise_ug_rt_hz: 400.0,
            accel_lpf_hz: 44.0,
            accel_offset_lsb_max: 300.0,
            jitter_us: 20.0,
            serial_glitch_rate: 0.002,
            serial_burst_rate: 0.0002,
            sd_corruptions_per_mb: 4.0,
            sd_truncate_last_frame: true,
            speed_error_max: 0.005,
            spinup_turns: 1.5,
            encoder_zero_counts_max: 2,
        }
    }
}

impl SensorModel {
    /// No noise, no glitches, exact speed: for tests that need the bare physics.
    pub fn ideal() -> Self {
        Self {
            accel_noise_ug_rt_hz: 0.0,
            accel_offset_lsb_max: 0.0,
            jitter_us: 0.0,
            serial_glitch_rate: 0.0,
            serial_burst_rate: 0.0,
            sd_corruptions_per_mb: 0.0,
            sd_truncate_last_frame: false,
            speed_error_max: 0.0,
            encoder_zero_counts_max: 0,
            ..Self::default()
        }
    }
}

/// Which firmware wrote a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TwinFormat {
    /// `serial-v1` text at 200 Hz.
    Serial,
    /// `sd-v2` binary, encoder 1000 Hz, accelerometer 200 Hz.
    Sd,
}

/// One run of the case.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwinRun {
    pub id: String,
    pub omega_hz: f64,
    pub role: String,
    pub format: TwinFormat,
    /// Release angle, rad, and rate, rad/s, at the start of the capture.
    pub theta0_rad: f64,
    #[serde(default)]
    pub theta_dot0_rad_s: f64,
    /// Free-motion time before the shaker starts, s.
    #[serde(default = "default_free_s")]
    pub free_s: f64,
    /// Forced time after the shaker starts, s.
    pub forced_s: f64,
    /// Board clock at the first sample, µs (random when absent); near 2³² to force a wrap.
    #[serde(default)]
    pub clock_start_us: Option<u32>,
    /// Crank radius for this run, m (the rig's when absent).
    #[serde(default)]
    pub crank_r_m: Option<f64>,
    /// Bob mass and axis-to-centre-of-mass length for this run (the rig's when absent): rig.md
    /// lets a campaign change bobs between runs.
    #[serde(default)]
    pub m_kg: Option<f64>,
    #[serde(default)]
    pub l_m: Option<f64>,
}

impl TwinRun {
    /// The truth with this run's own bob and crank.
    pub fn physical(&self, case: &TwinCase) -> Physical {
        let mut phys = case.physical();
        phys.crank_r_m = self.crank_r_m.unwrap_or(case.rig.crank_r_m);
        phys.m_kg = self.m_kg.unwrap_or(case.rig.m_kg);
        phys.l_m = self.l_m.unwrap_or(case.rig.l_m);
        phys
    }
}

/// Fraction of the set speed that counts as "at speed" for the truth's t = 0.
pub const AT_SPEED: f64 = 0.99;

/// The longest run the twin simulates, s (`free_s + forced_s`): 4 hours. The twin holds a whole
/// run in memory while it integrates: per sample its stamp (8 bytes), an event (24), the
/// integrator's output time (8) and the value (8; the capture's text or frames come on top,
/// about 40 more), ≈ 90 bytes, at up to 1,200 samples/s (sd: encoder 1 kHz + accelerometer
/// 200 Hz): 14,400 s × 1,200 × 90 B ≈ 1.6 GB. The study's runs last tens of seconds; a
/// `forced_s = 1e9` asked for 10⁵ TB and aborted on allocation (exit 134).
pub const MAX_RUN_S: f64 = 4.0 * 3600.0;

fn default_free_s() -> f64 {
    4.0
}

/// What the captures really hold, for tests (the analysis never reads it).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TwinTruthFile {
    pub case: String,
    pub seed: u64,
    pub params: Physical,
    pub runs: Vec<RunTruth>,
}

/// One run's truth.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunTruth {
    pub id: String,
    pub file: String,
    pub format: TwinFormat,
    pub role: String,
    /// The real crank speed, Hz.
    pub omega_real_hz: f64,
    /// Shaker switched on, s since the first sample.
    pub shaker_start_s: f64,
    /// Aligned t = 0 (first positive acceleration peak at speed), s since the first sample.
    pub t0_s: f64,
    /// Board clock (unwrapped, µs, counted from the first sample's raw value) at t = 0.
    pub t0_board_us: f64,
    /// True θ (rad) and θ̇ (rad/s) at t = 0.
    pub theta0_rad: f64,
    pub theta_dot0_rad_s: f64,
    /// The same in dimensionless time.
    pub theta_dot0_dimless: f64,
    pub steady: SteadyState,
    pub accel_offset_lsb: [i16; 3],
    pub encoder_zero_counts: i64,
    pub clock_start_us: u32,
    pub encoder_samples: u64,
    pub accel_samples: u64,
    /// Samples the firmware lost or damaged on purpose (bursts, glitches, corruption).
    pub damaged_pieces: u64,
}

/// What `synthesize` wrote.
#[derive(Debug, Clone)]
pub struct TwinSummary {
    pub dir: PathBuf,
    pub campaign: PathBuf,
    pub truth: PathBuf,
    pub truth_data: TwinTruthFile,
}

impl TwinCase {
    /// Reads a case file; errors name the file and the offending key.
    pub fn load(path: &Path) -> Result<Self, RigError> {
        let text = std::fs::read_to_string(path).map_err(|source| RigError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_toml(&text, path)
    }

    /// Parses case TOML (`path` only names the source in errors).
    pub fn from_toml(text: &str, path: &Path) -> Result<Self, RigError> {
        let case: TwinCase = toml::from_str(text).map_err(|e| {
            let (line, column) = e.span().map(|s| line_col(text, s.start)).unwrap_or((0, 0));
            RigError::CampaignSyntax {
                path: path.to_path_buf(),
                line,
                column,
                message: e.message().to_string(),
            }
        })?;
        case.physical()
            .validate()
            .map_err(|e| RigError::CampaignKey {
                path: path.to_path_buf(),
                run: None,
                key: "rig/truth".into(),
                expected: e.to_string(),
            })?;
        if let Some((key, expected)) = case.truth.departures.invalid() {
            return Err(RigError::CampaignKey {
                path: path.to_path_buf(),
                run: None,
                key: format!("truth.departures.{key}"),
                expected: expected.into(),
            });
        }
        for run in &case.runs {
            let duration_s = run.free_s + run.forced_s;
            if !(duration_s <= MAX_RUN_S) {
                return Err(RigError::CampaignKey {
                    path: path.to_path_buf(),
                    run: Some(run.id.clone()),
                    key: "forced_s".into(),
                    expected: format!(
                        "free_s + forced_s of at most {MAX_RUN_S} s (4 h), not {} + {} s: the twin \
                         holds a run's samples in memory, about 90 bytes each at up to 1,200 a \
                         second (1.6 GB at the limit)",
                        run.free_s, run.forced_s
                    ),
                });
            }
            run.physical(&case)
                .validate()
                .map_err(|e| RigError::CampaignKey {
                    path: path.to_path_buf(),
                    run: Some(run.id.clone()),
                    key: "m_kg/l_m/crank_r_m".into(),
                    expected: e.to_string(),
                })?;
        }
        Ok(case)
    }

    /// The truth as one physical parameter set (Ω per run is set in `run_physical`).
    pub fn physical(&self) -> Physical {
        Physical {
            m_kg: self.rig.m_kg,
            l_m: self.rig.l_m,
            crank_r_m: self.rig.crank_r_m,
            rod_l_m: self.rig.rod_l_m,
            r_b_m: self.rig.r_b_m,
            omega_hz: 1.0,
            g_m_s2: self.rig.g_m_s2,
            a_kg_m: self.truth.a_kg_m,
            b_n_s_m: self.truth.b_n_s_m,
            mu: self.truth.mu,
            effects: self.truth.effects.clone(),
        }
    }
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line, col)
}

fn gauss<R: Rng>(rng: &mut R) -> f64 {
    // Box–Muller: enough for sensor noise, and needs no extra crate.
    let u1: f64 = rng.random::<f64>().max(1e-300);
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// One sample instant of either sensor.
#[derive(Clone, Copy)]
enum Kind {
    Encoder,
    Accel,
    Poincare,
}

/// Simulates every run of `case` and writes the campaign into `out_dir`.
pub fn synthesize(case: &TwinCase, out_dir: &Path) -> Result<TwinSummary, RigError> {
    std::fs::create_dir_all(out_dir).map_err(|source| RigError::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let mut truths = Vec::new();
    for (i, run) in case.runs.iter().enumerate() {
        let seed = case
            .seed
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add(i as u64 + 1);
        truths.push(synthesize_run(case, run, seed, out_dir)?);
    }
    let campaign_path = out_dir.join("campaign.toml");
    let mut text = String::new();
    text.push_str(&format!(
        "# Written by the pendulum digital twin from case {:?}, seed {}.\nname = {:?}\ng_m_s2 = {}\n\n[rig]\nm_kg = {}\nl_m = {}\nrod_L_m = {}\nr_b_m = {}\n",
        case.name, case.seed, case.name, case.rig.g_m_s2, case.rig.m_kg, case.rig.l_m, case.rig.rod_l_m, case.rig.r_b_m
    ));
    for (run, t) in case.runs.iter().zip(&truths) {
        text.push_str(&format!(
            "\n[[run]]\nid = {:?}\nfile = {:?}\ncrank_r_m = {}\nomega_hz = {}\nrole = {:?}\n",
            run.id,
            t.file,
            run.crank_r_m.unwrap_or(case.rig.crank_r_m),
            run.omega_hz,
            run.role
        ));
        // A run's own bob overrides the [rig] table's (rig.md: "shared by every run unless a
        // run overrides a key").
        if let Some(m) = run.m_kg {
            text.push_str(&format!("m_kg = {m}\n"));
        }
        if let Some(l) = run.l_m {
            text.push_str(&format!("l_m = {l}\n"));
        }
    }
    write_atomic(&campaign_path, text.as_bytes())?;
    let truth = TwinTruthFile {
        case: case.name.clone(),
        seed: case.seed,
        params: case.physical(),
        runs: truths,
    };
    let truth_path = out_dir.join("truth.json");
    let json = serde_json::to_vec_pretty(&truth).map_err(|e| RigError::Io {
        path: truth_path.clone(),
        source: std::io::Error::other(e),
    })?;
    write_atomic(&truth_path, &json)?;
    Ok(TwinSummary {
        dir: out_dir.to_path_buf(),
        campaign: campaign_path,
        truth: truth_path,
        truth_data: truth,
    })
}

fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), RigError> {
    let (tmp, mut file) = TempFile::create(path)?;
    file.write_all(bytes)
        .and_then(|()| file.sync_all())
        .map_err(|source| RigError::Io {
            path: tmp.path.clone(),
            source,
        })?;
    drop(file);
    tmp.persist(path)
}

/// A temporary file of this process beside its final path, `.NAME.<pid>-<n>.tmp` (the
/// program's temporary-name pattern, which the commands' sweep of stale temporaries knows),
/// created only if new: two processes writing one folder never share, truncate or rename away
/// each other's (a fixed `campaign.tmp` let them). Removed when dropped unless persisted.
struct TempFile {
    path: PathBuf,
    persisted: bool,
}

impl TempFile {
    fn create(final_path: &Path) -> Result<(Self, File), RigError> {
        static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let name = final_path
            .file_name()
            .map(|f| f.to_string_lossy().into_owned())
            .unwrap_or_default();
        let path = final_path.with_file_name(format!(".{name}.{}-{n}.tmp", std::process::id()));
        let file = File::create_new(&path).map_err(|source| RigError::Io {
            path: path.clone(),
            source,
        })?;
        Ok((
            Self {
                path,
                persisted: false,
            },
            file,
        ))
    }

    /// Renames the finished file into place.
    fn persist(mut self, final_path: &Path) -> Result<(), RigError> {
        std::fs::rename(&self.path, final_path).map_err(|source| RigError::Io {
            path: final_path.to_path_buf(),
            source,
        })?;
        self.persisted = true;
        Ok(())
    }
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if !self.persisted {
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// The angle an encoder coupled with `play` rad of backlash reads, in place: its disc starts
/// centred on the shaft and moves only when the shaft reaches an edge of the play.
fn backlash(theta: &mut [f64], play: f64) {
    let half = 0.5 * play;
    let Some(&first) = theta.first() else {
        return;
    };
    let mut disc = first;
    for th in theta.iter_mut() {
        disc = disc.clamp(*th - half, *th + half);
        *th = disc;
    }
}

fn synthesize_run(
    case: &TwinCase,
    run: &TwinRun,
    seed: u64,
    out_dir: &Path,
) -> Result<RunTruth, RigError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let s = &case.sensors;
    let mut phys = run.physical(case);
    let speed_err = if s.speed_error_max > 0.0 {
        rng.random_range(-s.speed_error_max..=s.speed_error_max)
    } else {
        0.0
    };
    phys.omega_hz = run.omega_hz * (1.0 + speed_err);
    let bad = |expected: String| RigError::CampaignKey {
        path: PathBuf::from(format!("{}.toml", case.name)),
        run: Some(run.id.clone()),
        key: "run".into(),
        expected,
    };
    phys.validate().map_err(|e| bad(e.to_string()))?;
    let mut d = phys.to_dimensionless();
    if let Some(k) = case.truth.departures.torsion_spring_nm_per_rad {
        d.kappa = k / (phys.m_kg * phys.g_m_s2 * phys.l_m);
        d.kappa_slack = case.truth.departures.cable_slack_rad.unwrap_or(0.0);
        d.kappa_anchor = case.truth.departures.cable_anchor_rad.unwrap_or(0.0);
    }
    if let Some(spread) = case.truth.departures.mu_run_spread {
        d.m_coulomb *= 1.0 + rng.random_range(-spread..=spread);
    }
    if let Some(rate) = case.truth.departures.dry_torque_growth_nm_per_s {
        // Per dimensionless time (t̃ = ω0 t).
        d.c_rate = rate / (phys.m_kg * phys.g_m_s2 * phys.l_m) / phys.omega0_rad_s();
    }
    if let Some(t) = case.truth.departures.dry_torque_lobes_nm {
        d.c_lobes = t / (phys.m_kg * phys.g_m_s2 * phys.l_m);
        d.c_lobes_k = case.truth.departures.dry_torque_lobes_k.unwrap_or(1);
        d.c_lobes_phase = case
            .truth
            .departures
            .dry_torque_lobes_phase_rad
            .unwrap_or(0.0);
    }
    if let Some(c) = case.truth.departures.cubic_drag_nm_s3_per_rad3 {
        // θ̇ = ω0 θ̇' (θ̇' per dimensionless time), per m g l.
        d.cubic_drag = c * phys.omega0_rad_s().powi(3) / (phys.m_kg * phys.g_m_s2 * phys.l_m);
    }
    if let Some(c) = case.truth.departures.eddy_brake_nm_s_per_rad {
        d.eddy_brake = c * phys.omega0_rad_s() / (phys.m_kg * phys.g_m_s2 * phys.l_m);
        d.eddy_brake_phase = case.truth.departures.eddy_brake_phase_rad.unwrap_or(0.0);
    }
    // A swaying bracket moves the axis as a tilt would, unseen by the accelerometer (below).
    let sway = case.truth.departures.axis_sway_ratio.unwrap_or(0.0);
    d.tan_delta += sway;
    let w0 = phys.omega0_rad_s();
    // Dimensionless time of the shaker start and of being at speed.
    let t_start = run.free_s * w0;
    let spinup = if d.omega > 0.0 {
        // ∫φ̇ over the ramp = ω·T/2 = turns·2π.
        2.0 * s.spinup_turns * 2.0 * std::f64::consts::PI / d.omega
    } else {
        0.0
    };
    let phi0 = rng.random_range(0.0..2.0 * std::f64::consts::PI);
    let drive = CrankDrive {
        r_over_l: phys.crank_r_m / phys.l_m,
        lambda: d.lambda,
        tan_delta: d.tan_delta,
        omega: d.omega,
        phi0,
        t_start: Some(t_start),
        spinup,
        omega_drift: d.omega_drift,
    };
    let model = Model::with_excitation(d, Excitation::Crank(drive));
    // Aligned t = 0: the first φ = 2πn once the crank is at speed, taken as φ̇ ≥ 99 % of its
    // final value (the motor's own speed tolerance): with the smooth ramp s(u) = 3u² − 2u³ that
    // is s(u) = 0.99, solved by bisection.
    let t_speed = match drive.t_start {
        Some(ts) if spinup > 0.0 => {
            let (mut lo, mut hi) = (0.0f64, 1.0f64);
            for _ in 0..60 {
                let u = 0.5 * (lo + hi);
                if u * u * (3.0 - 2.0 * u) < AT_SPEED {
                    lo = u;
                } else {
                    hi = u;
                }
            }
            ts + hi * spinup
        }
        _ => drive.t_at_speed(),
    };
    let (phi_speed, _, _) = drive.phase(t_speed);
    let two_pi = 2.0 * std::f64::consts::PI;
    let phi_target = (phi_speed / two_pi).ceil() * two_pi;
    let t0_dimless = {
        // Solve φ(t) = φ_target by Newton (φ̇ ≈ ω, with drift).
        let mut t = t_speed + (phi_target - phi_speed) / d.omega.max(1e-12);
        for _ in 0..30 {
            let (p, dp, _) = drive.phase(t);
            t -= (p - phi_target) / dp.max(1e-12);
        }
        t
    };
    let duration_s = run.free_s + run.forced_s;
    let t_end = duration_s * w0;
    if t0_dimless >= t_end {
        return Err(bad(format!(
            "forced_s = {} is too short to reach speed (needs > {:.2} s)",
            run.forced_s,
            (t0_dimless / w0) - run.free_s
        )));
    }

    // Sample instants (seconds from the first sample), jittered.
    let (enc_hz, acc_hz) = match run.format {
        TwinFormat::Serial => (200.0, 200.0),
        TwinFormat::Sd => (1000.0, 200.0),
    };
    let jitter = |rng: &mut ChaCha8Rng, hz: f64| -> Vec<f64> {
        let n = (duration_s * hz).floor() as usize;
        let mut out = Vec::with_capacity(n);
        let mut last = f64::NEG_INFINITY;
        for k in 0..n {
            let mut t = k as f64 / hz + s.jitter_us * 1e-6 * gauss(rng);
            t = t.max(last + 1e-6).max(0.0);
            // Whole microseconds: what the board stamps.
            t = (t * 1e6).round() * 1e-6;
            if t <= last {
                t = last + 1e-6;
            }
            out.push(t);
            last = t;
        }
        out
    };
    let t_acc = jitter(&mut rng, acc_hz);
    let t_enc = match run.format {
        TwinFormat::Serial => t_acc.clone(), // one line carries both
        TwinFormat::Sd => jitter(&mut rng, enc_hz),
    };
    // Poincaré points of the truth: one per forcing period from t = 0 on.
    let period = d.forcing_period();
    let mut t_poin = Vec::new();
    let mut tp = t0_dimless;
    while tp <= t_end {
        t_poin.push(tp);
        tp += period;
    }
    let mut events: Vec<(f64, Kind, usize)> =
        Vec::with_capacity(t_enc.len() + t_acc.len() + t_poin.len());
    events.extend(
        t_enc
            .iter()
            .enumerate()
            .map(|(i, &t)| (t * w0, Kind::Encoder, i)),
    );
    if run.format == TwinFormat::Sd {
        events.extend(
            t_acc
                .iter()
                .enumerate()
                .map(|(i, &t)| (t * w0, Kind::Accel, i)),
        );
    }
    events.extend(
        t_poin
            .iter()
            .enumerate()
            .map(|(i, &t)| (t, Kind::Poincare, i)),
    );
    events.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut theta = vec![0.0; t_enc.len()];
    let mut poin_th = vec![f64::NAN; t_poin.len()];
    let mut poin_w = vec![f64::NAN; t_poin.len()];
    let mut idx = 0usize;
    let times: Vec<f64> = events.iter().map(|e| e.0).collect();
    let sink = |smp: pendulum_model::Sample| {
        let (_, kind, i) = events[idx];
        idx += 1;
        match kind {
            Kind::Encoder => theta[i] = smp.theta,
            Kind::Poincare => {
                poin_th[i] = smp.theta;
                poin_w[i] = smp.theta_dot;
            }
            Kind::Accel => {}
        }
        ControlFlow::Continue(())
    };
    let y0 = [run.theta0_rad, run.theta_dot0_rad_s / w0];
    match case.truth.departures.bob_bounce_hz {
        // A departure the model's simulator has no term for: its own integrator.
        Some(hz) => crate::bounce::integrate(
            &model,
            crate::bounce::Mount {
                nu: 2.0 * std::f64::consts::PI * hz / w0,
                zeta: case
                    .truth
                    .departures
                    .bob_bounce_damping_ratio
                    .unwrap_or(0.05),
            },
            crate::bounce::Steps::Adaptive,
            0.0,
            y0,
            t_end,
            times,
            sink,
        ),
        None => {
            integrate(
                &model,
                &SimOptions::with_tol(1e-9),
                0.0,
                y0,
                t_end,
                times,
                sink,
            )
            .map_err(|e| bad(format!("simulation failed: {e}")))?;
        }
    }

    // Truth at t = 0 and the steady state of the last part of the run.
    let theta0 = poin_th[0];
    let theta_dot0 = poin_w[0];
    let n = poin_th.len();
    let rec = (n / 3).clamp(2, 40).min(n);
    let steady = classify_poincare(
        &poin_th[n - rec..],
        &poin_w[n - rec..],
        &ClassifyOptions::default(),
    );

    // Accelerometer: true specific force at (t − Δ), gain, offsets, band-limited noise, int16;
    // Δ, the gain and the encoder's offset are the shared sensor transform of the fit and replay.
    let lsb_per_g = 8192.0;
    let sensors = Sensors::of(&phys);
    let off_max = s.accel_offset_lsb_max;
    let mut offsets = [0i16; 3];
    for o in &mut offsets {
        *o = if off_max > 0.0 {
            rng.random_range(-off_max..=off_max).round() as i16
        } else {
            0
        };
    }
    // White noise at the sample rate through a one-pole low-pass at the sensor's corner, scaled
    // so that its standard deviation is density·sqrt(π/2·f_c) (the one-pole noise bandwidth).
    let sigma_g =
        s.accel_noise_ug_rt_hz * 1e-6 * (std::f64::consts::FRAC_PI_2 * s.accel_lpf_hz).sqrt();
    let a_coef = (-2.0 * std::f64::consts::PI * s.accel_lpf_hz / acc_hz).exp();
    let white_scale = sigma_g * ((1.0 - a_coef * a_coef).max(0.0)).sqrt();
    let mut lp = [0.0f64; 3];
    let mut acc_raw = Vec::with_capacity(t_acc.len());
    for &t in &t_acc {
        let (ay, ax) = model.excitation.accel(sensors.accel_shows_s(t) * w0);
        // The worktable's own horizontal motion: a swaying bracket's is not the table's.
        let ax = ax - sway * ay;
        let truth_g = [ax, 0.0, 1.0 + ay];
        let mut raw = [0i16; 3];
        for k in 0..3 {
            lp[k] = a_coef * lp[k] + white_scale * gauss(&mut rng);
            let v = sensors.accel_measured(truth_g[k]) * lsb_per_g
                + lp[k] * lsb_per_g
                + offsets[k] as f64;
            raw[k] = v.round().clamp(i16::MIN as f64, i16::MAX as f64) as i16;
        }
        acc_raw.push(raw);
    }
    // Encoder: floor(4096·(θ + θ_off)/2π) + zeroing error, wrapped to i16.
    let zero_err = if s.encoder_zero_counts_max > 0 {
        rng.random_range(-s.encoder_zero_counts_max..=s.encoder_zero_counts_max)
    } else {
        0
    };
    let cpr_true = case.truth.departures.encoder_cpr_true.unwrap_or(4096.0);
    if let Some(play) = case.truth.departures.encoder_backlash_rad {
        backlash(&mut theta, play);
    }
    if let Some(eps) = case.truth.departures.encoder_eccentricity_rad {
        let phi = case
            .truth
            .departures
            .encoder_eccentricity_phase_rad
            .unwrap_or(0.0);
        // Zeroed hanging: the error at θ = 0, ε sin(−φ), is counted away at power-on.
        for th in &mut theta {
            *th += eps * ((*th - phi).sin() + phi.sin());
        }
    }
    let counts: Vec<i64> = theta
        .iter()
        .map(|&th| (cpr_true * sensors.theta_measured(th) / two_pi).floor() as i64 + zero_err)
        .collect();
    let clock_start = run.clock_start_us.unwrap_or_else(|| rng.random::<u32>());
    let stamp = |t: f64| -> u32 { clock_start.wrapping_add((t * 1e6).round() as u64 as u32) };

    let mut header = Header {
        entries: vec![
            (
                "firmware".into(),
                match run.format {
                    TwinFormat::Serial => "serial-v1".into(),
                    TwinFormat::Sd => "sd-v2".into(),
                },
            ),
            ("encoder_cpr".into(), "4096".into()),
            ("accel_lsb_per_g".into(), "8192".into()),
        ],
    };
    match run.format {
        TwinFormat::Serial => header.entries.push(("sample_hz".into(), "200".into())),
        TwinFormat::Sd => {
            header.entries.push(("encoder_hz".into(), "1000".into()));
            header.entries.push(("accel_hz".into(), "200".into()));
        }
    }
    header
        .entries
        .push(("started".into(), "2026-03-14T10:22:05Z".into()));
    header.entries.push(("twin_seed".into(), seed.to_string()));

    let mut damaged = 0u64;
    let file_name = match run.format {
        TwinFormat::Serial => format!("{}.csv", run.id),
        TwinFormat::Sd => format!("{}.bin", run.id),
    };
    let path = out_dir.join(&file_name);
    // Written under a temporary name and renamed into place whole: a killed synth leaves no
    // half capture under the final name.
    let (tmp, file) = TempFile::create(&path)?;
    let io = |source| RigError::Io {
        path: tmp.path.clone(),
        source,
    };
    match run.format {
        TwinFormat::Serial => {
            let mut w = SerialWriter::new(BufWriter::new(file), &header).map_err(io)?;
            let mut k = 0;
            while k < t_acc.len() {
                if s.serial_burst_rate > 0.0 && rng.random::<f64>() < s.serial_burst_rate {
                    let burst = rng.random_range(5..=40usize);
                    k += burst;
                    damaged += 1;
                    continue;
                }
                let line = format!(
                    "{},{},{},{},{}",
                    stamp(t_acc[k]),
                    counts[k] as i16,
                    acc_raw[k][0],
                    acc_raw[k][1],
                    acc_raw[k][2]
                );
                if s.serial_glitch_rate > 0.0
                    && rng.random::<f64>() < s.serial_glitch_rate
                    && k + 1 < t_acc.len()
                {
                    damaged += 1;
                    match rng.random_range(0..3u8) {
                        0 => {
                            // Cut short, before the last field: a cut inside the last number would
                            // look like a valid line to any reader.
                            let last_comma = line.rfind(',').unwrap_or(1).max(1);
                            let cut = rng.random_range(1..=last_comma);
                            w.write_raw(&format!("{}\n", &line[..cut])).map_err(io)?;
                        }
                        1 => {
                            // Garbled: a few characters replaced by junk.
                            let mut bytes = line.clone().into_bytes();
                            for _ in 0..rng.random_range(1..4) {
                                let p = rng.random_range(0..bytes.len());
                                bytes[p] = b"#@!x?;:~"[rng.random_range(0..8usize)];
                            }
                            w.write_raw(&format!("{}\n", String::from_utf8_lossy(&bytes)))
                                .map_err(io)?;
                        }
                        _ => {
                            // Two lines run into one: this one loses its newline.
                            let next = format!(
                                "{},{},{},{},{}",
                                stamp(t_acc[k + 1]),
                                counts[k + 1] as i16,
                                acc_raw[k + 1][0],
                                acc_raw[k + 1][1],
                                acc_raw[k + 1][2]
                            );
                            w.write_raw(&format!("{line}{next}\n")).map_err(io)?;
                            k += 1;
                        }
                    }
                } else {
                    w.write_sample(stamp(t_acc[k]), counts[k] as i16, acc_raw[k])
                        .map_err(io)?;
                }
                k += 1;
            }
            let mut inner = w.finish().map_err(io)?;
            inner.flush().map_err(io)?;
        }
        TwinFormat::Sd => {
            let mut buf: Vec<u8> = Vec::new();
            {
                let mut w = SdWriter::new(&mut buf, &header).map_err(io)?;
                let (mut ie, mut ia) = (0, 0);
                while ie < t_enc.len() || ia < t_acc.len() {
                    let take_enc =
                        ia >= t_acc.len() || (ie < t_enc.len() && t_enc[ie] <= t_acc[ia]);
                    if take_enc {
                        w.write_encoder(stamp(t_enc[ie]), counts[ie] as i16)
                            .map_err(io)?;
                        ie += 1;
                    } else {
                        w.write_accel(stamp(t_acc[ia]), acc_raw[ia]).map_err(io)?;
                        ia += 1;
                    }
                }
                w.finish().map_err(io)?;
            }
            // A bad card sector: flip bits at a few random spots past the first 64 bytes (so
            // the sync and type bytes that mark the file as a capture stay readable); the
            // header frame's text and CRC are among the spots, as rig.md allows ("corrupt bytes
            // anywhere"): the reader must keep the run.
            let spots = (s.sd_corruptions_per_mb * buf.len() as f64 / 1e6).round() as usize;
            for _ in 0..spots {
                let p = rng.random_range(64..buf.len().max(65));
                if p < buf.len() {
                    buf[p] ^= 1 << rng.random_range(0..8u32);
                    damaged += 1;
                }
            }
            if s.sd_truncate_last_frame && buf.len() > 64 {
                let cut = rng.random_range(1..8usize);
                buf.truncate(buf.len() - cut);
                damaged += 1;
            }
            let mut f = BufWriter::new(file);
            f.write_all(&buf).map_err(io)?;
            f.flush().map_err(io)?;
        }
    }
    tmp.persist(&path)?;
    Ok(RunTruth {
        id: run.id.clone(),
        file: file_name,
        format: run.format,
        role: run.role.clone(),
        omega_real_hz: phys.omega_hz,
        shaker_start_s: run.free_s,
        t0_s: t0_dimless / w0,
        t0_board_us: t0_dimless / w0 * 1e6,
        theta0_rad: theta0,
        theta_dot0_rad_s: theta_dot0 * w0,
        theta_dot0_dimless: theta_dot0,
        steady,
        accel_offset_lsb: offsets,
        encoder_zero_counts: zero_err,
        clock_start_us: clock_start,
        encoder_samples: t_enc.len() as u64,
        accel_samples: t_acc.len() as u64,
        damaged_pieces: damaged,
    })
}

/// Bob masses of rig.md, kg.
pub const BOB_MASSES_KG: [f64; 2] = [0.745, 1.46];
/// Axis-to-bob lengths rig.md allows, m.
pub const BOB_LENGTH_RANGE_M: (f64, f64) = (0.17, 0.27);
/// Crank radii of rig.md, m.
pub const CRANK_RADII_M: [f64; 3] = [0.0725, 0.1065, 0.205];
/// Crank speeds rig.md's motor covers, Hz.
pub const CRANK_SPEED_RANGE_HZ: (f64, f64) = (0.87, 2.36);
/// Largest peak base acceleration a drawn run may ask for, m/s²: the accelerometer's range is
/// ±4 g and z reads 1 g at rest, so 2.5 g keeps the peaks on scale with a margin (a real
/// experimenter does not saturate the sensor they align on).
pub const MAX_BASE_ACCEL_M_S2: f64 = 2.5 * 9.81;

/// Draws a campaign's runs as rig.md allows them, one design per run: bob (mass of rig.md,
/// length in its range), crank radius, crank speed (peak base acceleration on the
/// accelerometer's scale), capture format, hand start (angle and rate), free and forced
/// durations. `roles` gives each run's role ("identify"/"validate"); ids are r01, r02, … .
/// Returns the `[[run]]` tables of a twin case (TOML), every key explicit.
pub fn draw_design(seed: u64, roles: &[&str], rod_l_m: f64) -> String {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0xD351_6E00_0000_0000);
    let mut out = String::new();
    for (i, role) in roles.iter().enumerate() {
        let m = BOB_MASSES_KG[rng.random_range(0..BOB_MASSES_KG.len())];
        let l = rng.random_range(BOB_LENGTH_RANGE_M.0..BOB_LENGTH_RANGE_M.1);
        let (r, omega) = loop {
            let r = CRANK_RADII_M[rng.random_range(0..CRANK_RADII_M.len())];
            let om = rng.random_range(CRANK_SPEED_RANGE_HZ.0..CRANK_SPEED_RANGE_HZ.1);
            let peak = r * (2.0 * std::f64::consts::PI * om).powi(2) * (1.0 + r / rod_l_m);
            if peak <= MAX_BASE_ACCEL_M_S2 {
                break (r, om);
            }
        };
        let format = if rng.random::<bool>() { "serial" } else { "sd" };
        // A hand start: a swing of up to 2.5 rad, or a spin.
        let theta0 = rng.random_range(-2.5..2.5);
        let theta_dot0 = if rng.random_range(0.0..1.0) < 0.25 {
            rng.random_range(-10.0..10.0)
        } else {
            0.0
        };
        let free_s = rng.random_range(3.0..6.0);
        let forced_s = rng.random_range(25.0..40.0);
        out.push_str(&format!(
            "[[run]]\nid = \"r{:02}\"\nrole = \"{role}\"\nformat = \"{format}\"\nm_kg = {m}\nl_m = {l:.4}\ncrank_r_m = {r}\nomega_hz = {omega:.3}\ntheta0_rad = {theta0:.3}\ntheta_dot0_rad_s = {theta_dot0:.3}\nfree_s = {free_s:.2}\nforced_s = {forced_s:.1}\n",
            i + 1
        ));
    }
    out
}
