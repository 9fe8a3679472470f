//! `key=value` parameter assignments as the CLI takes them (`--param omega=1.585`,
//! `--param m_kg=1.46`, `--param coulomb_constant.T_c=0.004`).
//!
//! Resolution order: start from the study's rig ([`Physical::default`]); apply physical keys
//! (rig.md names); derive the dimensionless set; then dimensionless keys (`omega`, `R`, `lambda`,
//! `alpha`, `beta`, `M`) replace the derived values. Effect parameters are SI (effects.md) and are
//! made dimensionless with the resolved m, l and g.

use crate::{Dimensionless, ModelError, Physical};

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
/// Older spelling of a key, kept readable: (alias, key).
const ALIASES: [(&str, &str); 1] = [("viscous_quadratic.a", "a")];

/// Effect keys, `effect.parameter` with effects.md's symbols, from the catalogue (plus the
/// older `viscous_quadratic.a` for `a`).
pub fn effect_keys() -> Vec<&'static str> {
    let mut keys = crate::effects::param_keys();
    keys.extend(ALIASES.iter().map(|(alias, _)| *alias));
    keys
}

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
                && !effect_keys().contains(&k)
            {
                return Err(ModelError::UnknownParam {
                    key: k.to_string(),
                    expected: format!(
                        "{}, {} or {}",
                        DIMENSIONLESS_KEYS.join(", "),
                        PHYSICAL_KEYS.join(", "),
                        effect_keys().join(", ")
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

    /// Applies the physical and effect keys to `p` in order (no validation, no dimensionless
    /// keys): the survey's designs are built with it.
    pub fn apply_physical(&self, p: &mut Physical) -> Result<(), ModelError> {
        // Another form of an effect's parameters (the generator's k_e, V_d, R) is converted
        // once all of it is read, after the rest.
        let mut alternatives: Vec<(&str, f64)> = Vec::new();
        for (k, v) in &self.assignments {
            if crate::effects::alternative_key(k).is_some() {
                alternatives.push((k.as_str(), *v));
                continue;
            }
            let v = *v;
            let k = ALIASES
                .iter()
                .find(|(alias, _)| alias == k)
                .map_or(k.as_str(), |(_, key)| *key);
            match k {
                "m_kg" => p.m_kg = v,
                "l_m" => p.l_m = v,
                "crank_r_m" => p.crank_r_m = v,
                "rod_L_m" => p.rod_l_m = v,
                "r_b_m" => p.r_b_m = v,
                "omega_hz" => p.omega_hz = v,
                "g_m_s2" => p.g_m_s2 = v,
                "a" => p.a_kg_m = v,
                "b" => p.b_n_s_m = v,
                "mu" => p.mu = v,
                // Effect keys; dimensionless keys are applied by `resolve`.
                _ => {
                    crate::effects::apply_key(p, k, v)?;
                }
            }
        }
        let own: Vec<&str> = self.assignments.iter().map(|(k, _)| k.as_str()).collect();
        crate::effects::apply_alternatives(p, &alternatives, &own)
    }

    /// Resolves onto `base` (see the module docs). Returns the physical set (with the
    /// dimensionless overrides mapped back) and the dimensionless set.
    pub fn resolve(&self, base: &Physical) -> Result<(Physical, Dimensionless), ModelError> {
        let mut p = base.clone();
        self.apply_physical(&mut p)?;
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
