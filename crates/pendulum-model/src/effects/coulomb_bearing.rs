//! `coulomb_bearing`: the reference model's load-proportional dry friction μ r_b F_N sgn θ'.

use super::{Decompiled, Draw, Effect, FreeDecay, Kind, Param, Regressor, Survey};
use crate::{Dimensionless, Physical};

#[derive(Debug)]
pub struct CoulombBearing;

/// Discover's column: the bearing load without the base's acceleration, |θ'² + cos θ| sgn θ'
/// (M = μ r_b/l).
static REGRESSORS: [Regressor; 1] = [Regressor {
    name: "coul_ref",
    group: 0,
    lobes: 0,
    term: |s| (s.theta_dot * s.theta_dot + s.theta.cos()).abs() * s.sgn(),
    per_si: |p| p.r_b_m / p.l_m,
}];

static PARAMS: [Param; 1] = [Param::real("mu", "mu", "1", (0.0, 0.25))];

/// In a free decay (`pendulum-explain`).
static FREE_DECAY: FreeDecay = FreeDecay {
    symbol: "M",
    unit: "1",
    meaning: "M = mu r_b m g/(I omega_n^2) (load N = |theta'^2 + cos theta|)",
    friction: |th, w2| (w2 + th.cos()).abs(),
    set: |d, v| d.m_coulomb = v,
    fd_floor: 1e-7,
};

impl Effect for CoulombBearing {
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
        "coulomb_bearing"
    }
    fn kind(&self) -> Kind {
        Kind::Dynamics
    }
    fn regressors(&self) -> &'static [Regressor] {
        &REGRESSORS
    }
    fn params(&self) -> &'static [Param] {
        &PARAMS
    }
    fn what(&self) -> &'static str {
        "load-proportional dry friction of the ball bearings (the reference model's own term)"
    }
    fn term(&self) -> &'static str {
        "μ r_b F_N sgn θ', F_N = m \\|l θ'² + g cos θ\\|"
    }
    fn survey(&self) -> Survey {
        Survey {
            base: "linear",
            draws: &[("mu", Draw::Uniform(0.08, 0.2))],
        }
    }
    fn in_physical(&self) -> bool {
        true
    }
    fn get(&self, p: &Physical) -> Option<Vec<f64>> {
        Some(vec![p.mu])
    }
    fn set(&self, p: &mut Physical, values: Option<&[f64]>) {
        p.mu = values.map_or(0.0, |v| v[0]);
    }
    fn compile(&self, v: &[f64], p: &Physical, d: &mut Dimensionless) {
        d.m_coulomb = v[0] * p.r_b_m / p.l_m;
    }
    fn decompile(&self, d: &Dimensionless, p: &Physical) -> Decompiled {
        Decompiled::Set(Some(vec![d.m_coulomb * p.l_m / p.r_b_m]))
    }
}
