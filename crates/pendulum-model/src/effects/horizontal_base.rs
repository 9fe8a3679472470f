//! `horizontal_base`: the shaker's guide is tilted δ, so the axis also moves horizontally.

use super::{Decompiled, Draw, Effect, Kind, Param, Regressor, Survey};
use crate::{Dimensionless, Physical};

#[derive(Debug)]
pub struct HorizontalBase;

/// Discover's column: A_y cos θ (tan δ).
static REGRESSORS: [Regressor; 1] = [Regressor {
    name: "horiz",
    group: 0,
    lobes: 1,
    term: |s| s.a_y * s.theta.cos(),
    per_si: |_| 1.0,
}];

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
    fn regressors(&self) -> &'static [Regressor] {
        &REGRESSORS
    }
    /// δ = atan of the coefficient tan δ.
    fn estimate(&self, coef: &[(f64, f64)]) -> (f64, f64) {
        let (v, e) = coef[0];
        (v.atan(), e / (1.0 + v * v))
    }
    fn params(&self) -> &'static [Param] {
        &PARAMS
    }
    /// The axis moves x = y·tan δ: the accelerometer's x axis reads tan δ times its z axis's
    /// motion.
    fn reads_horizontal_slope(&self) -> bool {
        true
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
