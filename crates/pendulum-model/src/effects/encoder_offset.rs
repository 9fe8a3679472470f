//! `encoder_offset`: the count was zeroed away from the hanging position.

use super::{Draw, Effect, Kind, Param, Regressor, Sensors, Survey, Tolerance, Variable};

#[derive(Debug)]
pub struct EncoderOffset;

/// Discover's column: (1 + A_y) cos θ, the equation error's first-order change with the
/// reading's offset (its coefficient is −θ_off).
static REGRESSORS: [Regressor; 1] = [Regressor {
    name: "offset",
    group: 0,
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
    /// Within half a turn: an offset beyond it is another zero, not an offset.
    fn possible(&self, size: f64) -> bool {
        size.abs() < std::f64::consts::PI
    }
    /// In the equation of motion an offset is a torque that follows the angle, (1 + A_y) cos θ
    /// to first order, so a freer shape in θ that does clearly better makes it a partial
    /// explanation: a cable anchored 0.5 rad off the hanging position (a spring, −κ(θ − θ_a),
    /// whose constant part shifts the rest angle as an offset would) was named a −0.016 rad
    /// offset on an E_θ fall of 32 % ± 5 %, the validate runs' equation error rising 7.5 %,
    /// while a spring in the unwrapped θ took 89 % off it.
    fn follows(&self) -> &'static [Variable] {
        &[Variable::Angle, Variable::AngleInTurn]
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
