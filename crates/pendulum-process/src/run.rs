//! A run as the stages see it: the rig's description and the cleaned sample streams, in SI units
//! and seconds since the capture's first sample. Where it came from (raw capture or MCAP) is the
//! loader's business.

use serde::{Deserialize, Serialize};

/// Which runs fit the parameters and which only check them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    Identify,
    Validate,
}

impl Role {
    pub fn as_str(self) -> &'static str {
        match self {
            Role::Identify => "identify",
            Role::Validate => "validate",
        }
    }
}

/// The rig of one run, SI units (`rig.md`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RigParams {
    pub m_kg: f64,
    pub l_m: f64,
    pub crank_r_m: f64,
    pub rod_l_m: f64,
    pub r_b_m: f64,
    /// Crank speed set point, Hz; `None` = no shaker (a free decay only).
    pub omega_hz: Option<f64>,
    pub g_m_s2: f64,
}

impl RigParams {
    /// Natural frequency sqrt(g/l), rad/s.
    pub fn omega0_rad_s(&self) -> f64 {
        (self.g_m_s2 / self.l_m).sqrt()
    }
}

/// One run's samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunData {
    pub id: String,
    pub role: Role,
    pub rig: RigParams,
    /// Encoder sample times, s since the first sample.
    pub enc_t_s: Vec<f64>,
    /// Encoder angle, rad from the encoder zero, unwrapped.
    pub theta_rad: Vec<f64>,
    /// Accelerometer sample times, s.
    pub acc_t_s: Vec<f64>,
    /// Vertical specific force (z), m/s² (≈ +g at rest).
    pub az_m_s2: Vec<f64>,
    /// Horizontal acceleration in the pendulum's plane (x), m/s².
    pub ax_m_s2: Vec<f64>,
}

impl RunData {
    /// Linear interpolation of θ at time t (clamped at the ends).
    pub fn theta_at(&self, t: f64) -> f64 {
        interp(&self.enc_t_s, &self.theta_rad, t)
    }
}

/// The id of run `run`'s free segment before its shaker starts, prepared as a run of its own
/// (`pendulum identify --free-segments`, discover's refits and held-out judgement).
pub fn free_segment_id(run: &str) -> String {
    format!("{run}{FREE_SEGMENT_SUFFIX}")
}

/// The run a piece with id `id` belongs to: the run whose free segment it is
/// ([`free_segment_id`]), or itself. One suffix only: a run the user named "warm-free" has the
/// free segment "warm-free-free", whose run is "warm-free" (and "warm-free" itself reads as the
/// free segment of a run "warm", so ask it only of ids known to be pieces of runs).
pub fn parent_run_id(id: &str) -> &str {
    id.strip_suffix(FREE_SEGMENT_SUFFIX).unwrap_or(id)
}

const FREE_SEGMENT_SUFFIX: &str = "-free";

/// Linear interpolation of (xs, ys) at x, clamped at the ends; xs increasing.
pub fn interp(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    if xs.is_empty() {
        return f64::NAN;
    }
    let i = xs.partition_point(|&v| v < x);
    if i == 0 {
        return ys[0];
    }
    if i >= xs.len() {
        return ys[xs.len() - 1];
    }
    let (x0, x1) = (xs[i - 1], xs[i]);
    let w = if x1 > x0 { (x - x0) / (x1 - x0) } else { 0.0 };
    ys[i - 1] + w * (ys[i] - ys[i - 1])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_free_segments_run_is_the_run_it_was_cut_from_even_when_that_names_itself_free() {
        for run in ["r01", "warm-free", "a-free-b"] {
            let free = free_segment_id(run);
            assert_ne!(free, run);
            assert_eq!(parent_run_id(&free), run);
        }
        assert_eq!(parent_run_id("r01"), "r01");
    }
}
