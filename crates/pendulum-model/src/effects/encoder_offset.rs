//! `encoder_offset`: the count was zeroed away from the hanging position.

use super::{Draw, Effect, Kind, Param, Regressor, Sensors, Survey, Tolerance};

#[derive(Debug)]
pub struct EncoderOffset;

/// Discover's column: (1 + A_y) cos θ, the equation error's first-order change with the
/// reading's offset (its coefficient is −θ_off).
static REGRESSORS: [Regressor; 1] = [Regressor {
    name: "offset",
    group: 0,
    lobes: 1,
    term: |s| (1.0 + s.a_y) * s.theta.cos(),
    per_si: |_| 1.0,
}];

static PARAMS: [Param; 1] = [Param::real(
    "encoder_offset.theta_off",
    "rad",
    "rad",
    (-0.2, 0.2),
)];

impl Effect for EncoderOffset {
    fn name(&self) -> &'static str {
        "encoder_offset"
    }
    fn kind(&self) -> Kind {
        Kind::Observation
    }
    /// Under 4 counts (6.1 mrad at 4096 per turn): the rig's normal zeroing error.
    fn tolerance(&self) -> Option<Tolerance> {
        Some(Tolerance::EncoderCounts(4.0))
    }
    /// Each run's free decay swings about θ_off plus that run's own zeroing error.
    fn reads_hanging_position(&self) -> bool {
        true
    }
    /// Within half a turn: an offset beyond it is another zero, not an offset.
    fn possible(&self, size: f64) -> bool {
        size.abs() < std::f64::consts::PI
    }
    fn regressors(&self) -> &'static [Regressor] {
        &REGRESSORS
    }
    /// θ_off = −(the coefficient).
    fn estimate(&self, coef: &[(f64, f64)]) -> (f64, f64) {
        let (v, e) = coef[0];
        (-v, e)
    }
    fn params(&self) -> &'static [Param] {
        &PARAMS
    }
    fn what(&self) -> &'static str {
        "the count was zeroed away from the hanging position"
    }
    fn term(&self) -> &'static str {
        "measured angle = θ + θ_off"
    }
    fn survey(&self) -> Survey {
        Survey {
            base: "reference",
            draws: &[("encoder_offset.theta_off", Draw::Signed(0.02, 0.08))],
        }
    }
    fn sense(&self, v: &[f64], s: &mut Sensors) {
        s.encoder_offset_rad = v[0];
    }
}
