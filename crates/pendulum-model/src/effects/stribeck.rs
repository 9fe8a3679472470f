//! `stribeck`: breakaway. Ball bearings and seals hold more at rest than they drag when moving;
//! the excess T_s fades within a few v_s: T_s e^{−(θ'/v_s)²} sgn θ' in T_fric, and T_s in the
//! sticking capacity (`effects.md`).

use super::{Decompiled, Draw, Effect, Kind, Param, RateShape, Survey};
use crate::{Dimensionless, Physical};

#[derive(Debug)]
pub struct Stribeck;

static PARAMS: [Param; 2] = [
    Param::real("stribeck.T_s", "t_s_nm", "N·m", (0.0, 0.05)),
    Param {
        key: "stribeck.v_s",
        field: "v_s_rad_s",
        unit: "rad/s",
        // effects.md's typical 0.05–0.5 rad/s, with room on both sides; never 0 (the term's
        // speed scale).
        fit_range: Some((0.01, 2.0)),
        integer: false,
        // Switched on by its torque alone (a refit of T_s): a mid-range speed scale.
        unset: 0.2,
    },
];

/// Discover's column: e^{−(θ'/v_s)²} sgn θ' (0 at rest), profiled over v_s geometrically across
/// the refit range (the breakaway fades within a few v_s, so its scale matters in ratio).
static SHAPE: RateShape = RateShape {
    key: "stribeck.v_s",
    default: 0.2,
    grid: &[
        0.01, 0.015, 0.022, 0.033, 0.05, 0.075, 0.11, 0.16, 0.24, 0.36, 0.54, 0.8, 1.2, 2.0,
    ],
    f: |w, v_s| {
        if w == 0.0 {
            0.0
        } else {
            (-(w / v_s).powi(2)).exp() * w.signum()
        }
    },
};

impl Effect for Stribeck {
    fn rate_shape(&self) -> Option<&'static RateShape> {
        Some(&SHAPE)
    }
    fn positive(&self) -> bool {
        true
    }
    fn sets_sticking_capacity(&self) -> bool {
        true
    }
    fn generalises(&self) -> Option<&'static str> {
        Some("coulomb_constant")
    }
    fn name(&self) -> &'static str {
        "stribeck"
    }
    fn kind(&self) -> Kind {
        Kind::Dynamics
    }
    fn params(&self) -> &'static [Param] {
        &PARAMS
    }
    fn what(&self) -> &'static str {
        "breakaway: bearings and seals hold more at rest than they drag when moving; the excess fades within a few v_s"
    }
    fn term(&self) -> &'static str {
        "T_s e^{−(θ'/v_s)²} sgn θ' in T_fric, and T_s in the sticking capacity"
    }
    fn survey(&self) -> Survey {
        // Sizes as effects.md's typical ones: T_s up to the kinetic dry torque's size.
        Survey {
            base: "reference",
            draws: &[
                ("stribeck.T_s", Draw::Uniform(0.006, 0.015)),
                ("stribeck.v_s", Draw::Uniform(0.05, 0.5)),
            ],
        }
    }
    fn compile(&self, v: &[f64], p: &Physical, d: &mut Dimensionless) {
        d.s_break = v[0] / p.torque_scale_nm();
        d.v_break = v[1] / p.omega0_rad_s();
    }
    fn decompile(&self, d: &Dimensionless, p: &Physical) -> Decompiled {
        Decompiled::Set((d.s_break != 0.0).then(|| {
            vec![
                d.s_break * p.torque_scale_nm(),
                d.v_break * p.omega0_rad_s(),
            ]
        }))
    }
}

#[cfg(test)]
mod tests {
    use crate::{Excitation, Model, Physical, SimOptions};

    /// Through the catalogue alone: `stribeck.T_s`/`stribeck.v_s` reach the simulator as the
    /// fading dry torque, and a free decay with it comes to rest where the kinetic dry torque
    /// alone could not hold the pendulum.
    #[test]
    fn stribeck_holds_at_rest_what_it_does_not_drag_in_motion() {
        let spec = crate::ParamSpec::parse(&[
            "b=0",
            "mu=0",
            "coulomb_constant.T_c=0.02",
            "stribeck.T_s=0.04",
            "stribeck.v_s=0.3",
        ])
        .unwrap();
        let (p, d) = spec.resolve(&Physical::default()).unwrap();
        let scale = p.torque_scale_nm();
        assert!((d.s_break - 0.04 / scale).abs() < 1e-15);
        assert!((d.v_break - 0.3 / p.omega0_rad_s()).abs() < 1e-15);
        assert_eq!(p.effects.get("stribeck"), Some(&[0.04, 0.3][..]));
        // TOML as twin cases write it.
        let e: crate::Effects =
            toml::from_str("stribeck = { t_s_nm = 0.04, v_s_rad_s = 0.3 }").unwrap();
        assert_eq!(e.get("stribeck"), p.effects.get("stribeck"));

        let m = Model::with_excitation(d, Excitation::None);
        let tr = crate::simulate(
            &m,
            &SimOptions::with_tol(1e-10),
            [0.5, 0.0],
            0.0,
            400.0,
            0.01,
        )
        .unwrap();
        assert!(tr.stats.ended_stuck);
        let rest = tr.theta.last().unwrap().sin().abs();
        let (c, s) = (d.c, d.s_break);
        assert!(rest <= c + s + 1e-12, "rest at sin θ = {rest}");
        // The same decay without stribeck: a different (kinetic-only) history.
        let mut d0 = d;
        d0.s_break = 0.0;
        let tr0 = crate::simulate(
            &Model::with_excitation(d0, Excitation::None),
            &SimOptions::with_tol(1e-10),
            [0.5, 0.0],
            0.0,
            400.0,
            0.01,
        )
        .unwrap();
        assert!((tr0.theta.last().unwrap() - tr.theta.last().unwrap()).abs() > 1e-3);
    }
}
