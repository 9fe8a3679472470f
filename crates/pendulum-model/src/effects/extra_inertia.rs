//! `extra_inertia`: rotating inertia J besides the bob (rod, shaft, coupled rotor).

use super::{Decompiled, Draw, Effect, Kind, Param, Regressor, Survey, Tolerance, Variable};
use crate::{Dimensionless, Physical};

#[derive(Debug)]
pub struct ExtraInertia;

/// Discover's column: −(1 + A_y) sin θ, the model's θ'' standing in for the measured one (free
/// of its noise), j = J/(m l²).
static REGRESSORS: [Regressor; 1] = [Regressor {
    name: "inertia",
    group: 0,
    lobes: 1,
    term: |s| -(1.0 + s.a_y) * s.theta.sin(),
    per_si: |p| 1.0 / (p.m_kg * p.l_m * p.l_m),
}];

static PARAMS: [Param; 1] = [Param::real(
    "extra_inertia.J",
    "j_kg_m2",
    "kg·m²",
    (0.0, 0.02),
)];

impl Effect for ExtraInertia {
    fn positive(&self) -> bool {
        true
    }
    fn name(&self) -> &'static str {
        "extra_inertia"
    }
    fn kind(&self) -> Kind {
        Kind::Mass
    }
    fn follows(&self) -> &'static [Variable] {
        &[Variable::Angle, Variable::AngleInTurn]
    }
    /// Under 1 % of the lightest bob's m l²: a 2 cm bob's own moment is (2/5)(r/l)² ≈ 0.4 % of
    /// m l² at l = 0.2 m, a rod's and shaft's of the same order. (A 1.2e-5 kg·m² "inertia",
    /// 0.02 % of m l², rode along with hidden quadratic drag on a drawn design, accepted on an
    /// equation-error gain of 8 %.)
    fn tolerance(&self) -> Option<Tolerance> {
        Some(Tolerance::BobInertia(0.01))
    }
    fn regressors(&self) -> &'static [Regressor] {
        &REGRESSORS
    }
    fn params(&self) -> &'static [Param] {
        &PARAMS
    }
    fn what(&self) -> &'static str {
        "rotating inertia besides the bob: rod, shaft, coupled rotor"
    }
    fn term(&self) -> &'static str {
        "(m l² + J) θ''"
    }
    fn survey(&self) -> Survey {
        Survey {
            base: "reference",
            draws: &[("extra_inertia.J", Draw::Uniform(0.005, 0.02))],
        }
    }
    fn compile(&self, v: &[f64], p: &Physical, d: &mut Dimensionless) {
        d.j = v[0] / (p.m_kg * p.l_m * p.l_m);
    }
    fn decompile(&self, d: &Dimensionless, p: &Physical) -> Decompiled {
        Decompiled::Set((d.j != 0.0).then(|| vec![d.j * p.m_kg * p.l_m * p.l_m]))
    }
}
