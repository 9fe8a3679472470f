//! `coulomb_constant`: a load-independent dry torque T_c sgn θ' (seals, a belt-coupled motor).

use super::{Decompiled, Draw, Effect, FreeDecay, Kind, Param, Regressor, Survey, Variable};
use crate::{Dimensionless, Physical};

#[derive(Debug)]
pub struct CoulombConstant;

/// Discover's column: sgn θ' (c = T_c/(m g l)).
static REGRESSORS: [Regressor; 1] = [Regressor {
    name: "const",
    group: 0,
    lobes: 0,
    term: |s| s.sgn(),
    per_si: |p| 1.0 / (p.m_kg * p.g_m_s2 * p.l_m),
}];

static PARAMS: [Param; 1] = [Param::real(
    "coulomb_constant.T_c",
    "t_c_nm",
    "N·m",
    (0.0, 0.05),
)];

/// In a free decay (`pendulum-explain`).
static FREE_DECAY: FreeDecay = FreeDecay {
    symbol: "c",
    unit: "rad",
    meaning: "c = T_c/(I omega_n^2) = T_c/(m g a): dry-friction dead-band half-width",
    friction: |_, _| 1.0,
    set: |d, v| d.c = v,
    fd_floor: 1e-7,
};

impl Effect for CoulombConstant {
    fn free_decay(&self) -> Option<&'static FreeDecay> {
        Some(&FREE_DECAY)
    }
    fn positive(&self) -> bool {
        true
    }
    fn sets_sticking_capacity(&self) -> bool {
        true
    }
    fn name(&self) -> &'static str {
        "coulomb_constant"
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
        "load-independent dry torque: bearing seals, a belt-coupled idle motor"
    }
    fn term(&self) -> &'static str {
        "T_c sgn θ' in T_fric, and T_c in the sticking capacity"
    }
    fn survey(&self) -> Survey {
        Survey {
            base: "reference",
            draws: &[("coulomb_constant.T_c", Draw::Uniform(0.006, 0.015))],
        }
    }
    fn compile(&self, v: &[f64], p: &Physical, d: &mut Dimensionless) {
        d.c = v[0] / p.torque_scale_nm();
    }
    fn decompile(&self, d: &Dimensionless, p: &Physical) -> Decompiled {
        Decompiled::Set((d.c != 0.0).then(|| vec![d.c * p.torque_scale_nm()]))
    }
}
