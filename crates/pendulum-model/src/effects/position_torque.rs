//! `position_torque`: a torque of the angle alone, T_p sin(kθ + φ_p) (cogging, bob imbalance).

use super::{Decompiled, Draw, Effect, Kind, Param, Survey};
use crate::{Dimensionless, Physical};

#[derive(Debug)]
pub struct PositionTorque;

static PARAMS: [Param; 3] = [
    Param::real("position_torque.T_p", "t_p_nm", "N·m", (0.0, 0.1)),
    // k is chosen by discover's screen (one candidate per k), never refitted.
    Param {
        key: "position_torque.k",
        field: "k",
        unit: "1",
        fit_range: None,
        integer: true,
        unset: 1.0,
    },
    Param::real(
        "position_torque.phi_p",
        "phi_p_rad",
        "rad",
        (-std::f64::consts::PI, std::f64::consts::PI),
    ),
];

impl Effect for PositionTorque {
    fn name(&self) -> &'static str {
        "position_torque"
    }
    fn kind(&self) -> Kind {
        Kind::Dynamics
    }
    fn params(&self) -> &'static [Param] {
        &PARAMS
    }
    fn what(&self) -> &'static str {
        "torque that depends on the angle alone: cogging of a coupled motor (k large), bob imbalance (k = 1)"
    }
    fn term(&self) -> &'static str {
        "T_pos = T_p sin(k θ + φ_p)"
    }
    fn survey(&self) -> Survey {
        Survey {
            base: "reference",
            draws: &[
                ("position_torque.T_p", Draw::Uniform(0.015, 0.04)),
                ("position_torque.k", Draw::Int(1, 4)),
                ("position_torque.phi_p", Draw::Uniform(-3.0, 3.0)),
            ],
        }
    }
    fn compile(&self, v: &[f64], p: &Physical, d: &mut Dimensionless) {
        d.p = v[0] / p.torque_scale_nm();
        d.k = v[1] as u32;
        d.phi_p = v[2];
    }
    fn decompile(&self, d: &Dimensionless, p: &Physical) -> Decompiled {
        Decompiled::Set((d.p != 0.0).then(|| vec![d.p * p.torque_scale_nm(), d.k as f64, d.phi_p]))
    }
}
