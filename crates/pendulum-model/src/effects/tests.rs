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

/// Every size a survey hides is one discover may name: beyond the rig's own tolerance
/// ([`Tolerance`]) on any campaign rig.md allows. The bounds scale with the campaign's lightest
/// bob, so the worst campaign hangs rig.md's heaviest (1.46 kg at l = 0.27 m) on every run; the
/// stamps' jitter is taken at 50 µs (the twin stamps with 20 µs, the independent simulator
/// with 30 µs). A survey drawing under its own effect's tolerance would count as misses what
/// discover is right to leave unnamed.
#[test]
fn every_surveyed_size_lies_beyond_the_rigs_tolerance() {
    let (m_kg, l_m, g_m_s2) = (1.46, 0.27, 9.81);
    let mut bounded = 0;
    for e in CATALOGUE {
        let Some(t) = e.tolerance() else { continue };
        bounded += 1;
        let bound = t.bound(50e-6, m_kg * l_m * l_m, m_kg * g_m_s2 * l_m);
        let (_, draw) = e.survey().draws[0];
        let smallest = match draw {
            Draw::Uniform(lo, hi) | Draw::Signed(lo, hi) => lo.abs().min(hi.abs()),
            Draw::Int(..) => panic!("{}: an integer size", e.name()),
        };
        assert!(
            smallest > bound,
            "{}: the survey draws from {smallest:e}, within the rig's tolerance {bound:e}",
            e.name()
        );
    }
    assert!(bounded >= 4, "{bounded} effects with a tolerance");
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

/// Every torque discover regresses on is the simulator's own term: for each dynamics effect
/// with weak-form columns, the torque it adds to a forced model (the simulator's `torques`, at
/// 200 drawn states) is fitted exactly by its columns times their per-run factors, and
/// `estimate` turns the fitted coefficients back into the size it was given (or, for a switch,
/// the μ it acts with). A wrong sign, factor or shape in a regressor fails here, not in a survey.
#[test]
fn weak_form_columns_reproduce_the_simulators_torque() {
    use crate::{Model, WeakSample};
    let mut rng = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = |lo: f64, hi: f64| {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        lo + (hi - lo) * (rng >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut checked = 0;
    for e in CATALOGUE {
        if e.regressors().is_empty() || e.kind() != Kind::Dynamics {
            continue;
        }
        // A light bob on a short rod, away from the defaults, so a factor that forgot m or l
        // shows.
        let p0 = Physical {
            m_kg: 0.745,
            l_m: 0.181,
            a_kg_m: 0.0,
            b_n_s_m: 0.0,
            mu: 0.0,
            ..Physical::default()
        };
        let mut p1 = p0.clone();
        let values = sample_values(*e);
        e.set(&mut p1, Some(&values));
        // The size discover judges: the first parameter, or the reference one a switch changes.
        let key = e.size_key().expect("a size");
        let size = match EffectParam::find(key) {
            Some(ep) if ep.effect().name() != e.name() => {
                ep.effect().set(&mut p1, Some(&[0.17]));
                0.17
            }
            _ => values[0],
        };
        if e.name() == "viscous_linear" {
            // The reference terms live in Physical: set() wrote b there; p0 keeps 0.
            assert_eq!(p1.b_n_s_m, values[0]);
        }
        let (m0, m1) = (Model::measured(&p0), Model::measured(&p1));
        let groups: Vec<u32> = {
            let mut g: Vec<u32> = e.regressors().iter().map(|r| r.group).collect();
            g.dedup();
            g
        };
        // The group the effect's parameters select (position_torque: its k).
        let k = e
            .params()
            .iter()
            .position(|p| p.integer)
            .map_or(groups[0], |i| values[i] as u32);
        let regs: Vec<&Regressor> = e.regressors().iter().filter(|r| r.group == k).collect();
        assert!(!regs.is_empty(), "{}: no group {k}", e.name());
        let mut rows = Vec::new();
        let mut target = Vec::new();
        for _ in 0..200 {
            let t = uniform(0.0, 40.0);
            let theta = uniform(-7.0, 7.0);
            let w = uniform(0.05, 2.5) * if uniform(0.0, 1.0) < 0.5 { -1.0 } else { 1.0 };
            let (q0, q1) = (m0.torques(t, theta, w), m1.torques(t, theta, w));
            // A_y from the bare model's base term, −A_y sin θ (no tilt there).
            let a_y = -q0.base / theta.sin();
            let s = WeakSample {
                theta,
                theta_dot: w,
                a_y,
                a_y_dot: 0.0,
            };
            rows.push(
                regs.iter()
                    .map(|r| (r.term)(&s) * (r.per_si)(&p1))
                    .collect::<Vec<f64>>(),
            );
            // The equation error's target is −θ̈ − (1 + A_y) sin θ: what the effect adds to it.
            target.push(q0.sum() - q1.sum());
        }
        let fit = pendulum_numerics::ols(&rows, &target).unwrap();
        let scale = target.iter().map(|v| v.abs()).fold(0.0, f64::max);
        assert!(scale > 1e-4, "{}: no torque", e.name());
        let worst = rows
            .iter()
            .zip(&target)
            .map(|(x, y)| (y - x.iter().zip(&fit.coef).map(|(a, b)| a * b).sum::<f64>()).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-9 * scale,
            "{}: misfit {worst} of {scale}",
            e.name()
        );
        let coef: Vec<(f64, f64)> = fit.coef.iter().map(|&c| (c, 0.0)).collect();
        let (est, _) = e.estimate(&coef);
        assert!(
            (est - size).abs() < 1e-9 * size.abs(),
            "{}: estimate {est} vs {size}",
            e.name()
        );
        // The refit starts where the regression says (position_torque: k and φ_p back).
        let start = e.refit_start(est, &fit.coef, k);
        for (i, (a, b)) in start.iter().zip(&values).enumerate() {
            assert!(
                (a - b).abs() < 1e-9 * b.abs().max(1.0),
                "{}: start[{i}] {a} vs {b}",
                e.name()
            );
        }
        checked += 1;
    }
    // viscous_linear, viscous_quadratic, coulomb_bearing, bearing_load_base_accel,
    // coulomb_constant, position_torque, horizontal_base.
    assert_eq!(checked, 7);
}
