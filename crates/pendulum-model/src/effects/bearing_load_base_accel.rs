//! `bearing_load_base_accel`: the bearing load also carries the base's acceleration.

use super::{Decompiled, Draw, Effect, Kind, Param, Regressor, Survey};
use crate::{Dimensionless, Physical};

#[derive(Debug)]
pub struct BearingLoadBaseAccel;

/// Discover's column: the bearing load with the base's acceleration,
/// |θ'² + (1 + A_y) cos θ| sgn θ' (M = μ r_b/l), in place of coulomb_bearing's.
static REGRESSORS: [Regressor; 1] = [Regressor {
    name: "coul_base",
    group: 0,
    lobes: 0,
    term: |s| (s.theta_dot * s.theta_dot + (1.0 + s.a_y) * s.theta.cos()).abs() * s.sgn(),
    per_si: |p| p.r_b_m / p.l_m,
}];

impl Effect for BearingLoadBaseAccel {
    fn positive(&self) -> bool {
        true
    }
    fn sets_sticking_capacity(&self) -> bool {
        true
    }
    fn name(&self) -> &'static str {
        "bearing_load_base_accel"
    }
    fn kind(&self) -> Kind {
        Kind::Dynamics
    }
    fn regressors(&self) -> &'static [Regressor] {
        &REGRESSORS
    }
    fn size_key(&self) -> Option<&'static str> {
        Some("mu")
    }
    fn replaces(&self) -> Option<&'static str> {
        Some("coulomb_bearing")
    }
    fn params(&self) -> &'static [Param] {
        &[]
    }
    fn what(&self) -> &'static str {
        "the bearing load also carries the base's acceleration, which the reference model leaves out"
    }
    fn term(&self) -> &'static str {
        "F_N = m \\|l θ'² + (g + ÿ) cos θ − ẍ sin θ\\|"
    }
    fn survey(&self) -> Survey {
        // A switch: its size is the bearing friction it changes, so μ is drawn (and judged).
        Survey {
            base: "reference",
            draws: &[("mu", Draw::Uniform(0.1, 0.2))],
        }
    }
    fn compile(&self, _: &[f64], _: &Physical, d: &mut Dimensionless) {
        d.base_load = true;
    }
    fn decompile(&self, d: &Dimensionless, _: &Physical) -> Decompiled {
        Decompiled::Set(d.base_load.then(Vec::new))
    }
}
