//! `generator_rectified`: a harvesting generator on the shaft (EMF k_e θ') through a diode
//! rectifier into a resistive load R. Current flows only once the EMF exceeds the diodes' drop
//! V_d: T_gen = c_g (|θ'| − ω_d)⁺ sgn θ' in T_fric, c_g = k_e²/R, ω_d = V_d/k_e (`effects.md`).
//!
//! Given either as (c_g, ω_d), the form stored, written and refitted, or as the electrical
//! (k_e, V_d, R), converted on reading:
//!
//! ```text
//! --param generator_rectified.c_g=0.018 --param generator_rectified.omega_d=4.67
//! --param generator_rectified.k_e=0.3 --param generator_rectified.V_d=1.4 --param generator_rectified.R=5
//! generator_rectified = { c_g_nm_s_rad = 0.018, omega_d_rad_s = 4.67 }
//! generator_rectified = { k_e_v_s_rad = 0.3, v_d_v = 1.4, r_ohm = 5 }
//! ```
//!
//! Its power: the current is I = (k_e|θ'| − V_d)⁺/R, so the generator takes T_gen·|θ'| = EMF·I
//! from the pendulum, of which the load gets I²R = c_g ((|θ'| − ω_d)⁺)² and the diodes V_d·I =
//! c_g ω_d (|θ'| − ω_d)⁺: the split needs c_g and ω_d only (R and k_e set the current and
//! voltage, not the powers).

use super::{Alternative, Decompiled, Draw, Effect, Kind, Param, RateShape, Survey};
use crate::{Dimensionless, Physical};

#[derive(Debug)]
pub struct GeneratorRectified;

static PARAMS: [Param; 2] = [
    // Up to about three times the reference model's linear drag b l² (0.035 N·m·s at the
    // study's rig): a load that would stop the pendulum rotating is no harvester.
    Param::real(
        "generator_rectified.c_g",
        "c_g_nm_s_rad",
        "N·m·s/rad",
        (0.0, 0.1),
    ),
    // Two silicon diodes (about 1.4 V) on generators of k_e 0.1 to 1 V·s/rad: 1.4 to 14 rad/s,
    // around the pendulum's own speeds (ω0 ≈ 6 rad/s).
    Param::real(
        "generator_rectified.omega_d",
        "omega_d_rad_s",
        "rad/s",
        (0.0, 20.0),
    ),
];

static ELECTRICAL: [Param; 3] = [
    Param {
        fit_range: None,
        ..Param::real(
            "generator_rectified.k_e",
            "k_e_v_s_rad",
            "V·s/rad",
            (0.0, 0.0),
        )
    },
    Param {
        fit_range: None,
        ..Param::real("generator_rectified.V_d", "v_d_v", "V", (0.0, 0.0))
    },
    Param {
        fit_range: None,
        ..Param::real("generator_rectified.R", "r_ohm", "Ω", (0.0, 0.0))
    },
];

/// (k_e, V_d, R) → (c_g, ω_d).
fn from_electrical(v: &[f64]) -> Result<Vec<f64>, String> {
    let (k_e, v_d, r) = (v[0], v[1], v[2]);
    if !(k_e > 0.0 && k_e.is_finite()) {
        return Err(format!("k_e = {k_e} V·s/rad: expected > 0"));
    }
    if !(v_d >= 0.0 && v_d.is_finite()) {
        return Err(format!("V_d = {v_d} V: expected ≥ 0"));
    }
    if !(r > 0.0 && r.is_finite()) {
        return Err(format!("R = {r} Ω: expected > 0"));
    }
    Ok(vec![k_e * k_e / r, v_d / k_e])
}

static ALTERNATIVE: Alternative = Alternative {
    params: &ELECTRICAL,
    convert: from_electrical,
};

/// Discover's column: (|θ'| − ω_d)⁺ sgn θ', profiled over ω_d linearly across 0.25–16 rad/s
/// (the band's edge is a speed the motion crosses; at ω_d → 0 the column is θ', the viscous
/// term, so 0 itself is left out).
static SHAPE: RateShape = RateShape {
    key: "generator_rectified.omega_d",
    default: 2.0,
    grid: &[
        0.25, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0, 12.0, 16.0,
    ],
    f: |w, omega_d| (w.abs() - omega_d).max(0.0) * w.signum(),
};

impl Effect for GeneratorRectified {
    fn rate_shape(&self) -> Option<&'static RateShape> {
        Some(&SHAPE)
    }
    fn positive(&self) -> bool {
        true
    }
    fn name(&self) -> &'static str {
        "generator_rectified"
    }
    fn kind(&self) -> Kind {
        Kind::Dynamics
    }
    fn params(&self) -> &'static [Param] {
        &PARAMS
    }
    fn alternative(&self) -> Option<&'static Alternative> {
        Some(&ALTERNATIVE)
    }
    fn what(&self) -> &'static str {
        "a harvesting generator on the shaft (EMF k_e θ') through a diode rectifier into a load R: current flows once the EMF exceeds the diodes' drop V_d, so c_g = k_e²/R, ω_d = V_d/k_e"
    }
    fn term(&self) -> &'static str {
        "c_g (\\|θ'\\| − ω_d)⁺ sgn θ' in T_fric"
    }
    fn survey(&self) -> Survey {
        // A load about the size of the reference model's linear drag, its band below the
        // forced motion's speeds (else it would show nothing).
        Survey {
            base: "reference",
            draws: &[
                ("generator_rectified.c_g", Draw::Uniform(0.01, 0.04)),
                ("generator_rectified.omega_d", Draw::Uniform(1.0, 5.0)),
            ],
        }
    }
    fn compile(&self, v: &[f64], p: &Physical, d: &mut Dimensionless) {
        // T/(m g l) with θ' = ω0 θ̇.
        d.gen_c = v[0] * p.omega0_rad_s() / p.torque_scale_nm();
        d.gen_w = v[1] / p.omega0_rad_s();
    }
    fn decompile(&self, d: &Dimensionless, p: &Physical) -> Decompiled {
        Decompiled::Set((d.gen_c != 0.0).then(|| {
            vec![
                d.gen_c * p.torque_scale_nm() / p.omega0_rad_s(),
                d.gen_w * p.omega0_rad_s(),
            ]
        }))
    }
}

#[cfg(test)]
mod tests {
    use crate::{Excitation, Model, ParamSpec, Physical, SimOptions};

    /// Both forms, `--param` and TOML, reach the simulator as the same dead-band torque:
    /// c_g = k_e²/R, ω_d = V_d/k_e, made dimensionless with ω0 and m g l.
    #[test]
    fn generator_given_as_c_g_omega_d_or_as_k_e_v_d_r() {
        let (k_e, v_d, r) = (0.3, 1.4, 5.0);
        let (c_g, w_d) = (k_e * k_e / r, v_d / k_e);
        let own = ParamSpec::parse(&[
            format!("generator_rectified.c_g={c_g}"),
            format!("generator_rectified.omega_d={w_d}"),
        ])
        .unwrap();
        let electrical = ParamSpec::parse(&[
            "generator_rectified.k_e=0.3",
            "generator_rectified.V_d=1.4",
            "generator_rectified.R=5",
        ])
        .unwrap();
        let (p1, d1) = own.resolve(&Physical::default()).unwrap();
        let (p2, d2) = electrical.resolve(&Physical::default()).unwrap();
        let w0 = p1.omega0_rad_s();
        assert!((d1.gen_c - c_g * w0 / p1.torque_scale_nm()).abs() < 1e-15);
        assert!((d1.gen_w - w_d / w0).abs() < 1e-15);
        assert!((d2.gen_c - d1.gen_c).abs() < 1e-15 && (d2.gen_w - d1.gen_w).abs() < 1e-15);
        let g = p2.effects.get("generator_rectified").unwrap();
        assert!((g[0] - 0.018).abs() < 1e-15 && (g[1] - 1.4 / 0.3).abs() < 1e-14);
        assert_eq!(
            p1.effects.get("generator_rectified").map(<[f64]>::len),
            Some(2)
        );

        let a: crate::Effects =
            toml::from_str("generator_rectified = { k_e_v_s_rad = 0.3, v_d_v = 1.4, r_ohm = 5 }")
                .unwrap();
        let b: crate::Effects = toml::from_str(&format!(
            "generator_rectified = {{ c_g_nm_s_rad = {c_g}, omega_d_rad_s = {w_d} }}"
        ))
        .unwrap();
        assert_eq!(a, b);
        // Written back in its own form, read the same.
        assert_eq!(
            toml::from_str::<crate::Effects>(&a.toml_lines()).unwrap(),
            a
        );
        assert!(a.toml_lines().contains("c_g_nm_s_rad"));
    }

    /// Both forms at once, or an incomplete electrical one, are refused with what to give.
    #[test]
    fn generator_refuses_both_forms_and_half_an_electrical_one() {
        let e = ParamSpec::parse(&[
            "generator_rectified.c_g=0.02",
            "generator_rectified.k_e=0.3",
            "generator_rectified.V_d=1.4",
            "generator_rectified.R=5",
        ])
        .unwrap()
        .resolve(&Physical::default())
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("not both") && e.contains("generator_rectified.c_g"),
            "{e}"
        );
        let e = ParamSpec::parse(&["generator_rectified.k_e=0.3", "generator_rectified.R=5"])
            .unwrap()
            .resolve(&Physical::default())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("generator_rectified.V_d") && e.contains("missing"),
            "{e}"
        );
        let e = ParamSpec::parse(&[
            "generator_rectified.k_e=0",
            "generator_rectified.V_d=1",
            "generator_rectified.R=5",
        ])
        .unwrap()
        .resolve(&Physical::default())
        .unwrap_err()
        .to_string();
        assert!(e.contains("k_e") && e.contains("> 0"), "{e}");
        let e = toml::from_str::<crate::Effects>(
            "generator_rectified = { c_g_nm_s_rad = 0.02, omega_d_rad_s = 1, r_ohm = 5, k_e_v_s_rad = 0.3, v_d_v = 1 }",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("not both"), "{e}");
        let e = toml::from_str::<crate::Effects>(
            "generator_rectified = { k_e_v_s_rad = 0.3, r_ohm = 5 }",
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("v_d_v"), "{e}");
    }

    /// Through the catalogue alone: a free decay with the generator loses energy only while
    /// |θ'| > ω_d, so its peak speed creeps down to the band's edge (in SI) from above.
    #[test]
    fn generator_decay_ends_at_the_dead_band() {
        let spec = ParamSpec::parse(&[
            "b=0",
            "mu=0",
            "generator_rectified.c_g=0.05",
            "generator_rectified.omega_d=3",
        ])
        .unwrap();
        let (p, d) = spec.resolve(&Physical::default()).unwrap();
        let m = Model::with_excitation(d, Excitation::None);
        let tr = crate::simulate(
            &m,
            &SimOptions::with_tol(1e-10),
            [2.5, 0.0],
            0.0,
            400.0,
            0.01,
        )
        .unwrap();
        let tail = &tr.theta_dot[tr.theta_dot.len() - 2000..];
        let peak_si = tail.iter().fold(0.0_f64, |a, v| a.max(v.abs())) * p.omega0_rad_s();
        assert!(peak_si > 3.0 && peak_si < 3.1, "peak θ' {peak_si} rad/s");
        let start_si = (2.0 * (1.0 - 2.5_f64.cos())).sqrt() * p.omega0_rad_s();
        assert!(start_si > 10.0, "{start_si}");
    }
}
