//! `accel_gain`: the accelerometer's sensitivity is (1 + k_a) times nominal.

use super::{Draw, Effect, Kind, Param, Sensors, Survey};

#[derive(Debug)]
pub struct AccelGain;

static PARAMS: [Param; 1] = [Param {
    key: "accel_gain.k_a",
    field: "k_a",
    unit: "1",
    // Not refitted: a model simulated from the crank's geometry does not read the accelerometer;
    // discover measures the gain against that geometry instead.
    fit_range: None,
    integer: false,
    unset: 0.0,
}];

impl Effect for AccelGain {
    fn name(&self) -> &'static str {
        "accel_gain"
    }
    fn kind(&self) -> Kind {
        Kind::Input
    }
    fn params(&self) -> &'static [Param] {
        &PARAMS
    }
    fn what(&self) -> &'static str {
        "the accelerometer's sensitivity is (1 + k_a) times nominal"
    }
    fn term(&self) -> &'static str {
        "measured acceleration = (1 + k_a) × true"
    }
    fn survey(&self) -> Survey {
        Survey {
            base: "reference",
            draws: &[("accel_gain.k_a", Draw::Signed(0.02, 0.08))],
        }
    }
    fn sense(&self, v: &[f64], s: &mut Sensors) {
        s.accel_gain_k_a = v[0];
    }
}
