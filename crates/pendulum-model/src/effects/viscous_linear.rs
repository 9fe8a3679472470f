//! `viscous_linear`: the reference model's linear drag b l² θ'.

use super::{Decompiled, Draw, Effect, FreeDecay, Kind, Param, Regressor, Survey, Variable};
use crate::{Dimensionless, Physical};

#[derive(Debug)]
pub struct ViscousLinear;

/// Discover's column: θ' (β = b/(m ω0)).
static REGRESSORS: [Regressor; 1] = [Regressor {
    name: "lin",
    group: 0,
    lobes: 0,
    term: |s| s.theta_dot,
    per_si: |p| 1.0 / (p.m_kg * p.omega0_rad_s()),
}];

static PARAMS: [Param; 1] = [Param::real("b", "b_n_s_m", "N·s/m", (0.0, 1.0))];

/// In a free decay (`pendulum-explain`).
static FREE_DECAY: FreeDecay = FreeDecay {
    symbol: "beta",
    unit: "1",
    meaning: "beta = gamma/omega_n, gamma = viscous torque coefficient / I",
    friction: |_, w2| w2.sqrt(),
    set: |d, v| d.beta = v,
    fd_floor: 1e-6,
};

impl Effect for ViscousLinear {
    fn free_decay(&self) -> Option<&'static FreeDecay> {
        Some(&FREE_DECAY)
    }
    fn positive(&self) -> bool {
        true
    }
    fn name(&self) -> &'static str {
        "viscous_linear"
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
        "air drag linear in speed, grease (the reference model's own term)"
    }
    fn term(&self) -> &'static str {
        "b l² θ' in T_fric"
    }
    fn survey(&self) -> Survey {
        // Found where it is missing: a model with dry friction alone.
        Survey {
            base: "dry",
            draws: &[("b", Draw::Uniform(0.3, 0.7))],
        }
    }
    // The reference terms live in `Physical` itself (every model has them, 0 = absent).
    fn in_physical(&self) -> bool {
        true
    }
    fn get(&self, p: &Physical) -> Option<Vec<f64>> {
        Some(vec![p.b_n_s_m])
    }
    fn set(&self, p: &mut Physical, values: Option<&[f64]>) {
        p.b_n_s_m = values.map_or(0.0, |v| v[0]);
    }
    fn compile(&self, v: &[f64], p: &Physical, d: &mut Dimensionless) {
        d.beta = v[0] / (p.m_kg * p.omega0_rad_s());
    }
    fn decompile(&self, d: &Dimensionless, p: &Physical) -> Decompiled {
        Decompiled::Set(Some(vec![d.beta * p.m_kg * p.omega0_rad_s()]))
    }
}
