//! `position_torque`: a torque of the angle alone, T_p sin(kθ + φ_p) (cogging, bob imbalance).

use super::{Decompiled, Draw, Effect, Kind, Param, Regressor, Survey, Tolerance, Variable};
use crate::{Dimensionless, Physical};

#[derive(Debug)]
pub struct PositionTorque;

/// The largest lobe count discover screens: effects.md's position torque includes "cogging of a
/// coupled motor (k large)", and small motors' cogging periods per turn (slots and poles over
/// their common factors) run from a dozen to several dozen. The encoder's 4096 counts resolve a
/// lobe of 2π/64 with 64 counts, and the screen stays cheap (on a drawn campaign discover took
/// 7.6 s with k ≤ 48 against 7.5 s with k ≤ 24); hidden k = 32 and 48 cogging torques that
/// k ≤ 24 could not see were then named with the right k, within 4 %.
const K_MAX: u32 = 64;

/// Two columns per lobe count k: T_p sin(kθ + φ_p) = a sin kθ + b cos kθ.
macro_rules! lobes {
    ($($k:literal)*) => {
        [$(
            Regressor {
                name: concat!("pos", stringify!($k), "_sin"),
                group: $k,
                lobes: $k,
                term: |s| ($k as f64 * s.theta).sin(),
                per_si: TORQUE,
            },
            Regressor {
                name: concat!("pos", stringify!($k), "_cos"),
                group: $k,
                lobes: $k,
                term: |s| ($k as f64 * s.theta).cos(),
                per_si: TORQUE,
            },
        )*]
    };
}

/// Discover's columns: sin kθ and cos kθ for k = 1…[`K_MAX`], one candidate per k
/// (p = T_p/(m g l)).
static REGRESSORS: [Regressor; 2 * K_MAX as usize] = lobes!(1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24 25 26 27 28 29 30 31 32 33 34 35 36 37 38 39 40 41 42 43 44 45 46 47 48 49 50 51 52 53 54 55 56 57 58 59 60 61 62 63 64);

const TORQUE: fn(&Physical) -> f64 = |p| 1.0 / (p.m_kg * p.g_m_s2 * p.l_m);

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
    fn follows(&self) -> &'static [Variable] {
        &[Variable::Angle, Variable::AngleInTurn]
    }
    fn torque_of_the_angle_alone(&self) -> bool {
        true
    }
    /// Under what tilts the lightest-hung bob's rest by one encoder count (T_p ≤ m g l · 2π/4096):
    /// at the hanging position any lobe count pulls by at most T_p, which moves the rest by
    /// T_p/(m g l), and each run's count is zeroed by hand to within a few counts. (On a drawn
    /// nothing-hidden campaign, `SURVEY_DAMPING=drawn SURVEY_SEED=33` campaign 48, a 1.6e-4 N·m
    /// k = 1 torque, 0.06 of a count on its lightest bob, was named on an E_θ fall of
    /// 2.1 % ± 1.9 % against a 2.0 % bar; the survey's smallest, 0.015 N·m on the heaviest
    /// longest bob, tilts its rest 2.5 counts.)
    fn tolerance(&self) -> Option<Tolerance> {
        Some(Tolerance::RestTilt(1.0))
    }
    fn regressors(&self) -> &'static [Regressor] {
        &REGRESSORS
    }
    /// T_p = √(a² + b²) of T_p sin(kθ + φ_p) = a sin kθ + b cos kθ.
    fn estimate(&self, coef: &[(f64, f64)]) -> (f64, f64) {
        let (a, ea) = coef[0];
        let (b, eb) = coef[1];
        let p = a.hypot(b);
        let se = ((a * ea).powi(2) + (b * eb).powi(2)).sqrt() / p.max(1e-300);
        (p, se)
    }
    /// T_p, the candidate's k (not refitted) and φ_p = atan2(b, a).
    fn refit_start(&self, size: f64, coef: &[f64], group: u32) -> Vec<f64> {
        vec![size, group as f64, coef[1].atan2(coef[0])]
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
                ("position_torque.k", Draw::Int(1, K_MAX as i32)),
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
