//! The typed messages of a run file. Field names carry their units and match `schemas/*.json`.

use serde::{Deserialize, Serialize};

/// One encoder sample (topic `/encoder`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct EncoderMsg {
    /// Seconds since the first sample of the run (encoder or accelerometer, whichever is first).
    /// Must equal `(t_us − t_us of that first sample) / 1e6` to within a microsecond: the writer
    /// derives message times from the pair and rejects inconsistent ones.
    pub t_s: f64,
    /// Board microsecond clock, unwrapped across its 32-bit wraps.
    pub t_us: u64,
    /// Encoder count, unwrapped across its 16-bit wraps (4096 counts per revolution).
    pub count: i64,
    /// Encoder count exactly as the firmware sent it, kept so the unwrapping can be audited.
    pub count_raw: i16,
    /// Angle from the hanging position, radians, counter-clockwise positive.
    pub theta_rad: f64,
}

/// One accelerometer sample of the shaker's worktable (topic `/accel`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AccelMsg {
    /// Seconds since the first sample of the run; see [`EncoderMsg::t_s`].
    pub t_s: f64,
    /// Board microsecond clock, unwrapped across its 32-bit wraps.
    pub t_us: u64,
    /// Raw x reading, LSB (horizontal, in the pendulum's plane).
    pub ax_raw: i16,
    /// Raw y reading, LSB (along the axis).
    pub ay_raw: i16,
    /// Raw z reading, LSB (vertical up).
    pub az_raw: i16,
    /// x specific force, m/s².
    pub ax_m_s2: f64,
    /// y specific force, m/s².
    pub ay_m_s2: f64,
    /// z specific force, m/s² (about +g at rest).
    pub az_m_s2: f64,
}

/// One sample of a model replay (topic `/sim/theta`), plotted against the measured angle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SimulatedMsg {
    /// Seconds since the first sample of the run, on the same axis as [`EncoderMsg::t_s`].
    pub t_s: f64,
    /// Simulated angle, radians.
    pub theta_rad: f64,
    /// Simulated angular velocity, rad/s.
    pub theta_dot_rad_s: f64,
    /// Measured minus simulated angle at `t_s`, radians.
    pub residual_rad: f64,
}

impl EncoderMsg {
    /// The float fields by name, for the finiteness check (JSON has no NaN or infinity:
    /// serde_json would write `null` and the file would not read back).
    pub(crate) fn floats(&self) -> [(&'static str, f64); 2] {
        [("t_s", self.t_s), ("theta_rad", self.theta_rad)]
    }
}

impl AccelMsg {
    /// See [`EncoderMsg::floats`].
    pub(crate) fn floats(&self) -> [(&'static str, f64); 4] {
        [
            ("t_s", self.t_s),
            ("ax_m_s2", self.ax_m_s2),
            ("ay_m_s2", self.ay_m_s2),
            ("az_m_s2", self.az_m_s2),
        ]
    }
}

impl SimulatedMsg {
    /// See [`EncoderMsg::floats`].
    pub(crate) fn floats(&self) -> [(&'static str, f64); 4] {
        [
            ("t_s", self.t_s),
            ("theta_rad", self.theta_rad),
            ("theta_dot_rad_s", self.theta_dot_rad_s),
            ("residual_rad", self.residual_rad),
        ]
    }
}
