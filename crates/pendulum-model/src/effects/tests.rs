//! The catalogue's own consistency: names and keys unique, conversions inverse, the serialized
//! form the twin cases were written in still read, the README's table in step.

use super::*;

#[test]
fn names_keys_and_serial_keys_are_unique() {
    let mut names = names();
    let n = names.len();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), n, "duplicate effect name");
    let mut keys = param_keys();
    let k = keys.len();
    keys.sort_unstable();
    keys.dedup();
    assert_eq!(keys.len(), k, "duplicate --param key");
    let mut serial: Vec<String> = CATALOGUE.iter().map(|e| serial_key(*e)).collect();
    serial.sort_unstable();
    serial.dedup();
    assert_eq!(serial.len(), n, "duplicate serialized key");
    // Every survey draws keys that exist, starting with one of the effect's own (its truth) or
    // a reference term it changes.
    for e in CATALOGUE {
        for (key, _) in e.survey().draws {
            assert!(
                EffectParam::find(key).is_some(),
                "{}: survey key {key}",
                e.name()
            );
        }
        assert!(["reference", "linear", "dry"].contains(&e.survey().base));
    }
}

/// Values inside every refit range, per effect.
fn sample_values(e: &dyn Effect) -> Vec<f64> {
    e.params()
        .iter()
        .map(|p| match (p.integer, p.fit_range) {
            (true, _) => 3.0,
            (false, Some((lo, hi))) => lo + 0.37 * (hi - lo) + 1e-4,
            (false, None) => 0.03,
        })
        .collect()
}

#[test]
fn compile_and_decompile_are_inverse() {
    for e in CATALOGUE {
        let mut p = Physical::default();
        let v = sample_values(*e);
        e.set(&mut p, Some(&v));
        let d = p.to_dimensionless();
        match e.decompile(&d, &p) {
            Decompiled::Keep => {
                // A sensor effect: the coefficients must not change with it.
                let mut bare = p.clone();
                e.set(&mut bare, None);
                assert_eq!(bare.to_dimensionless(), d, "{}", e.name());
                assert!(
                    e.kind() == Kind::Input || e.kind() == Kind::Observation,
                    "{}",
                    e.name()
                );
            }
            Decompiled::Set(back) => {
                let back = back.unwrap_or_else(|| panic!("{}: lost", e.name()));
                for (a, b) in back.iter().zip(&v) {
                    assert!(
                        (a - b).abs() <= 1e-12 * b.abs().max(1e-3),
                        "{}: {a} vs {b}",
                        e.name()
                    );
                }
                let q = Physical::default().with_dimensionless(&d);
                let got = e.get(&q).expect("present after the round trip");
                for (a, b) in got.iter().zip(&v) {
                    assert!(
                        (a - b).abs() <= 1e-12 * b.abs().max(1e-3),
                        "{}: {a} vs {b}",
                        e.name()
                    );
                }
            }
        }
    }
}

#[test]
fn twin_cases_written_before_the_catalogue_still_read() {
    let text = r#"
coulomb_constant_t_c_nm = 0.004
position_torque = { t_p_nm = 0.02, k = 3, phi_p_rad = -1.5 }
horizontal_base_delta_rad = 0.04
extra_inertia_j_kg_m2 = 0.002
bearing_load_base_accel = true
encoder_offset_rad = 0.05
accel_delay_s = 0.01
accel_gain_k_a = -0.03
speed_drift_hz_per_s = 0.001
"#;
    let e: Effects = toml::from_str(text).unwrap();
    assert_eq!(e.value("coulomb_constant.T_c"), Some(0.004));
    assert_eq!(e.get("position_torque"), Some(&[0.02, 3.0, -1.5][..]));
    assert!(e.has("bearing_load_base_accel"));
    assert_eq!(e.value("accel_gain.k_a"), Some(-0.03));
    // toml_lines writes the same form back.
    let again: Effects = toml::from_str(&e.toml_lines()).unwrap();
    assert_eq!(again, e);
    // serde's own form too.
    let s = toml::to_string(&e).unwrap();
    assert_eq!(toml::from_str::<Effects>(&s).unwrap(), e);
    // JSON as truth files have it: every effect, absent ones null (read back the same).
    let json = serde_json::to_string(&e).unwrap();
    assert_eq!(serde_json::from_str::<Effects>(&json).unwrap(), e);
    let none = serde_json::to_value(Effects::default()).unwrap();
    assert_eq!(none["coulomb_constant_t_c_nm"], serde_json::Value::Null);
    assert_eq!(
        none["bearing_load_base_accel"],
        serde_json::Value::Bool(false)
    );
    assert_eq!(
        serde_json::from_value::<Effects>(none).unwrap(),
        Effects::default()
    );
    // A switch set to false is absent.
    let off: Effects = toml::from_str("bearing_load_base_accel = false").unwrap();
    assert!(off.is_empty());
}

#[test]
fn bad_effect_tables_are_refused_with_what_was_expected() {
    let err = toml::from_str::<Effects>("coulomb_constant = 0.1")
        .unwrap_err()
        .to_string();
    assert!(err.contains("coulomb_constant_t_c_nm"), "{err}");
    let err = toml::from_str::<Effects>("position_torque = { t_p_nm = 0.02, k = 3 }")
        .unwrap_err()
        .to_string();
    assert!(err.contains("phi_p_rad"), "{err}");
    let err =
        toml::from_str::<Effects>("position_torque = { t_p_nm = 0.02, k = 0.5, phi_p_rad = 0 }")
            .unwrap_err()
            .to_string();
    assert!(err.contains("integer"), "{err}");
}

#[test]
fn sensors_come_from_the_input_and_observation_effects() {
    let mut p = Physical::default();
    assert_eq!(Sensors::of(&p), Sensors::default());
    p.effects.set("encoder_offset", Some(vec![0.05]));
    p.effects.set("accel_delay", Some(vec![0.01]));
    p.effects.set("accel_gain", Some(vec![-0.03]));
    let s = Sensors::of(&p);
    assert_eq!(s.encoder_offset_rad, 0.05);
    assert_eq!(s.accel_delay_s, 0.01);
    assert_eq!(s.accel_gain_k_a, -0.03);
    assert_eq!(s.theta_true(s.theta_measured(1.25)), 1.25);
    assert!((s.accel_measured(2.0) - 1.94).abs() < 1e-15);
    assert_eq!(s.accel_shows_s(1.0), 0.99);
}

#[test]
fn fit_parameters_are_named_as_specs_write_them() {
    assert_eq!(
        EffectParam::of("coulomb_constant").def().key,
        "coulomb_constant.T_c"
    );
    assert_eq!(
        EffectParam::of("coulomb_constant").spec_name(),
        "coulomb_constant"
    );
    assert_eq!(
        EffectParam::of("position_torque.phi_p").spec_name(),
        "position_torque.phi_p"
    );
    assert_eq!(EffectParam::of("b").spec_name(), "b");
    // k is chosen, not refitted.
    assert!(!EffectParam::all_fitted().contains(&EffectParam::of("position_torque.k")));
    let mut p = Physical::default();
    EffectParam::of("position_torque.phi_p").apply(0.5, &mut p);
    // Switching an effect on by one parameter gives the others their unset values (k = 1).
    assert_eq!(p.effects.get("position_torque"), Some(&[0.0, 1.0, 0.5][..]));
}

/// README.md's effect table is the catalogue's (regenerate it from `markdown_table()`).
#[test]
fn readme_effect_table_is_the_catalogues() {
    let readme = include_str!("../../../../README.md");
    let begin =
        "<!-- effects table: generated from pendulum_model::effects::markdown_table() -->\n";
    let end = "<!-- end of effects table -->";
    let start = readme
        .find(begin)
        .expect("README has the effects table marker")
        + begin.len();
    let stop = readme[start..].find(end).expect("end marker") + start;
    let table = markdown_table();
    assert!(
        readme[start..stop] == table,
        "README.md's effect table is out of date; replace it with:\n{table}"
    );
}
