//! `viscous_quadratic`: the reference model's quadratic drag a l³ θ'|θ'|.

use super::{Decompiled, Draw, Effect, FreeDecay, Kind, Param, Regressor, Survey, Variable};
use crate::{Dimensionless, Physical};

#[derive(Debug)]
pub struct ViscousQuadratic;

/// Discover's column: θ'|θ'| (α = a l/m).
static REGRESSORS: [Regressor; 1] = [Regressor {
    name: "quad",
    group: 0,
    lobes: 0,
    term: |s| s.theta_dot * s.theta_dot.abs(),
    per_si: |p| p.l_m / p.m_kg,
}];

static PARAMS: [Param; 1] = [Param::real("a", "a_kg_m", "kg/m", (0.0, 1.0))];

/// In a free decay (`pendulum-explain`).
static FREE_DECAY: FreeDecay = FreeDecay {
    symbol: "alpha",
    unit: "1/rad",
    meaning: "alpha = q: quadratic drag torque / (I theta_dot^2)",
    friction: |_, w2| w2,
    set: |d, v| d.alpha = v,
    fd_floor: 1e-6,
};

impl Effect for ViscousQuadratic {
    fn free_decay(&self) -> Option<&'static FreeDecay> {
        Some(&FREE_DECAY)
    }
    fn positive(&self) -> bool {
        true
    }
    fn name(&self) -> &'static str {
        "viscous_quadratic"
    }
    fn kind(&self) -> Kind {
        Kind::Dynamics
    }
    fn follows(&self) -> &'static [Variable] {
        &[Variable::Rate]
    }
    fn regressors(&self) -> &'static [Regressor] {
        &REGRESSORS
    }
    fn params(&self) -> &'static [Param] {
        &PARAMS
    }
    fn what(&self) -> &'static str {
        "air drag quadratic in speed (the reference model's own term)"
    }
    fn term(&self) -> &'static str {
        "a l³ θ'\\|θ'\\| in T_fric"
    }
    fn survey(&self) -> Survey {
        Survey {
            base: "linear",
            draws: &[("a", Draw::Uniform(0.05, 0.2))],
        }
    }
    fn in_physical(&self) -> bool {
        true
    }
    fn get(&self, p: &Physical) -> Option<Vec<f64>> {
        Some(vec![p.a_kg_m])
    }
    fn set(&self, p: &mut Physical, values: Option<&[f64]>) {
        p.a_kg_m = values.map_or(0.0, |v| v[0]);
    }
    fn compile(&self, v: &[f64], p: &Physical, d: &mut Dimensionless) {
        d.alpha = v[0] * p.l_m / p.m_kg;
    }
    fn decompile(&self, d: &Dimensionless, p: &Physical) -> Decompiled {
        Decompiled::Set(Some(vec![d.alpha * p.m_kg / p.l_m]))
    }
}
