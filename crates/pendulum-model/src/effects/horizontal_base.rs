//! `horizontal_base`: the shaker's guide is tilted δ, so the axis also moves horizontally.

use super::{Decompiled, Draw, Effect, Kind, Param, Survey};
use crate::{Dimensionless, Physical};

#[derive(Debug)]
pub struct HorizontalBase;

static PARAMS: [Param; 1] = [Param::real(
    "horizontal_base.delta",
    "delta_rad",
    "rad",
    (-0.2, 0.2),
)];

impl Effect for HorizontalBase {
    fn name(&self) -> &'static str {
        "horizontal_base"
    }
    fn kind(&self) -> Kind {
        Kind::Dynamics
    }
    fn params(&self) -> &'static [Param] {
        &PARAMS
    }
    fn what(&self) -> &'static str {
        "the shaker's guide is tilted δ from vertical in the pendulum's plane: x = y·tan δ"
    }
    fn term(&self) -> &'static str {
        "− m l ẍ cos θ"
    }
    fn survey(&self) -> Survey {
        Survey {
            base: "reference",
            draws: &[("horizontal_base.delta", Draw::Signed(0.02, 0.08))],
        }
    }
    fn compile(&self, v: &[f64], _: &Physical, d: &mut Dimensionless) {
        d.tan_delta = v[0].tan();
    }
    fn decompile(&self, d: &Dimensionless, _: &Physical) -> Decompiled {
        Decompiled::Set((d.tan_delta != 0.0).then(|| vec![d.tan_delta.atan()]))
    }
}
