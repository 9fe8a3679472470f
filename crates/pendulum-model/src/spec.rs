//! `key=value` parameter assignments as the CLI takes them (`--param omega=1.585`,
//! `--param m_kg=1.46`, `--param coulomb_constant.T_c=0.004`).
//!
//! Resolution order: start from the study's rig ([`Physical::default`]); apply physical keys
//! (rig.md names); derive the dimensionless set; then dimensionless keys (`omega`, `R`, `lambda`,
//! `alpha`, `beta`, `M`) replace the derived values. Effect parameters are SI (effects.md) and are
//! made dimensionless with the resolved m, l and g.

use crate::{Dimensionless, ModelError, Physical, PositionTorque};

/// Physical keys, by their `rig.md`/`effects.md` names.
pub const PHYSICAL_KEYS: [&str; 10] = [
    "m_kg",
    "l_m",
    "crank_r_m",
    "rod_L_m",
    "r_b_m",
    "omega_hz",
    "g_m_s2",
    "a",
    "b",
    "mu",
];
/// Dimensionless keys, the study's Eq. 5–6 names.
pub const DIMENSIONLESS_KEYS: [&str; 6] = ["omega", "R", "lambda", "alpha", "beta", "M"];
/// Effect keys, `effect.parameter` with effects.md's symbols.
pub const EFFECT_KEYS: [&str; 12] = [
    "coulomb_constant.T_c",
    "position_torque.T_p",
    "position_torque.k",
    "position_torque.phi_p",
    "horizontal_base.delta",
    "extra_inertia.J",
    "bearing_load_base_accel.on",
    "encoder_offset.theta_off",
    "accel_delay.Delta",
    "accel_gain.k_a",
    "speed_drift.dOmega_dtau",
    "viscous_quadratic.a",
];

/// A list of `key=value` assignments, resolved into parameters.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ParamSpec {
    pub assignments: Vec<(String, f64)>,
}

impl ParamSpec {
    /// Parses `key=value` strings; errors name the offending text and what was expected.
    pub fn parse<S: AsRef<str>>(items: &[S]) -> Result<Self, ModelError> {
        let mut assignments = Vec::new();
        for item in items {
            let item = item.as_ref();
            let (k, v) = item
                .split_once('=')
                .ok_or_else(|| ModelError::BadParamValue {
                    key: item.to_string(),
                    value: String::new(),
                    expected: "key=value".into(),
                })?;
            let k = k.trim();
            if !PHYSICAL_KEYS.contains(&k)
                && !DIMENSIONLESS_KEYS.contains(&k)
                && !EFFECT_KEYS.contains(&k)
            {
                return Err(ModelError::UnknownParam {
                    key: k.to_string(),
                    expected: format!(
                        "{}, {} or {}",
                        DIMENSIONLESS_KEYS.join(", "),
                        PHYSICAL_KEYS.join(", "),
                        EFFECT_KEYS.join(", ")
                    ),
                });
            }
            let value: f64 = v.trim().parse().map_err(|_| ModelError::BadParamValue {
                key: k.to_string(),
                value: v.to_string(),
                expected: "a number".into(),
            })?;
            if !value.is_finite() {
                return Err(ModelError::BadParamValue {
                    key: k.to_string(),
                    value: v.to_string(),
                    expected: "a finite number".into(),
                });
            }
            assignments.push((k.to_string(), value));
        }
        Ok(Self { assignments })
    }

    fn get(&self, key: &str) -> Option<f64> {
        self.assignments
            .iter()
            .rev()
            .find(|(k, _)| k == key)
            .map(|(_, v)| *v)
    }

    /// Resolves onto `base` (see the module docs). Returns the physical set (with the
    /// dimensionless overrides mapped back) and the dimensionless set.
    pub fn resolve(&self, base: &Physical) -> Result<(Physical, Dimensionless), ModelError> {
        let mut p = base.clone();
        for (k, v) in &self.assignments {
            let v = *v;
            match k.as_str() {
                "m_kg" => p.m_kg = v,
                "l_m" => p.l_m = v,
                "crank_r_m" => p.crank_r_m = v,
                "rod_L_m" => p.rod_l_m = v,
                "r_b_m" => p.r_b_m = v,
                "omega_hz" => p.omega_hz = v,
                "g_m_s2" => p.g_m_s2 = v,
                "a" | "viscous_quadratic.a" => p.a_kg_m = v,
                "b" => p.b_n_s_m = v,
                "mu" => p.mu = v,
                "coulomb_constant.T_c" => p.effects.coulomb_constant_t_c_nm = Some(v),
                "position_torque.T_p" | "position_torque.k" | "position_torque.phi_p" => {
                    let mut pt = p.effects.position_torque.unwrap_or(PositionTorque {
                        t_p_nm: 0.0,
                        k: 1,
                        phi_p_rad: 0.0,
                    });
                    match k.as_str() {
                        "position_torque.T_p" => pt.t_p_nm = v,
                        "position_torque.k" => {
                            if v < 1.0 || v.fract() != 0.0 {
                                return Err(ModelError::BadParamValue {
                                    key: k.clone(),
                                    value: v.to_string(),
                                    expected: "an integer ≥ 1".into(),
                                });
                            }
                            pt.k = v as u32
                        }
                        _ => pt.phi_p_rad = v,
                    }
                    p.effects.position_torque = Some(pt);
                }
                "horizontal_base.delta" => p.effects.horizontal_base_delta_rad = Some(v),
                "extra_inertia.J" => p.effects.extra_inertia_j_kg_m2 = Some(v),
                "bearing_load_base_accel.on" => p.effects.bearing_load_base_accel = v != 0.0,
                "encoder_offset.theta_off" => p.effects.encoder_offset_rad = Some(v),
                "accel_delay.Delta" => p.effects.accel_delay_s = Some(v),
                "accel_gain.k_a" => p.effects.accel_gain_k_a = Some(v),
                "speed_drift.dOmega_dtau" => p.effects.speed_drift_hz_per_s = Some(v),
                _ => {} // dimensionless keys: below
            }
        }
        p.validate()?;
        let mut d = p.to_dimensionless();
        if let Some(v) = self.get("omega") {
            // Keep R fixed unless given: changing ω at fixed R is how the study sweeps.
            d.omega = v;
        }
        if let Some(v) = self.get("R") {
            d.r = v;
        }
        if let Some(v) = self.get("lambda") {
            d.lambda = v;
        }
        if let Some(v) = self.get("alpha") {
            d.alpha = v;
        }
        if let Some(v) = self.get("beta") {
            d.beta = v;
        }
        if let Some(v) = self.get("M") {
            d.m_coulomb = v;
        }
        d.validate()?;
        let p = p.with_dimensionless(&d);
        Ok((p, d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dimensionless_overrides_and_effects() {
        let spec = ParamSpec::parse(&[
            "omega=1.585",
            "R=0.7",
            "lambda=0.126",
            "alpha=0",
            "beta=0.109",
            "M=0.007",
            "coulomb_constant.T_c=0.004",
        ])
        .unwrap();
        let (p, d) = spec.resolve(&Physical::default()).unwrap();
        assert_eq!(
            (d.omega, d.r, d.lambda, d.beta, d.m_coulomb),
            (1.585, 0.7, 0.126, 0.109, 0.007)
        );
        let c_expected = 0.004 / (p.m_kg * p.g_m_s2 * p.l_m);
        assert!((d.c - c_expected).abs() < 1e-15);
        // The physical set maps back to the same dimensionless one.
        let d2 = p.to_dimensionless();
        for (a, b) in [
            (d2.omega, 1.585),
            (d2.r, 0.7),
            (d2.lambda, 0.126),
            (d2.beta, 0.109),
            (d2.m_coulomb, 0.007),
        ] {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
    }

    #[test]
    fn physical_keys() {
        let spec = ParamSpec::parse(&["m_kg=0.745", "l_m=0.26", "a=0.003"]).unwrap();
        let (_, d) = spec.resolve(&Physical::default()).unwrap();
        assert!((d.alpha - 0.003 * 0.26 / 0.745).abs() < 1e-15);
    }

    #[test]
    fn errors_name_the_key() {
        let e = ParamSpec::parse(&["omgea=1"]).unwrap_err().to_string();
        assert!(e.contains("omgea") && e.contains("omega"), "{e}");
        let e = ParamSpec::parse(&["beta=x"]).unwrap_err().to_string();
        assert!(e.contains("beta") && e.contains("number"), "{e}");
        let e = ParamSpec::parse(&["beta"]).unwrap_err().to_string();
        assert!(e.contains("key=value"), "{e}");
        let e = ParamSpec::parse(&["lambda=2"])
            .unwrap()
            .resolve(&Physical::default())
            .unwrap_err();
        assert!(e.to_string().contains("lambda"));
    }
}
