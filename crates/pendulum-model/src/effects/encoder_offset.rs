//! `encoder_offset`: the count was zeroed away from the hanging position.

use super::{Draw, Effect, Kind, Param, Sensors, Survey};

#[derive(Debug)]
pub struct EncoderOffset;

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
