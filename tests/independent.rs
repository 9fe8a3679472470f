//! Issue 12: discovery on campaigns the project did not make. `../shared/data/independent` holds
//! thirteen campaigns written by another simulator of the same rig (its own integrator, sensor
//! chain, spin-up, conventions; mixed bobs and cranks), with the truth beside each folder. Each
//! test runs `discover` on one of them and applies the rule of that folder's README (and of
//! `../shared/tools/score_discover.py`): the accepted effects are exactly the hidden ones (the
//! reference terms a, b, μ are fitted, not found), each estimate within 10 % (an offset within
//! 2 mrad, a delay within 0.5 ms). Skipped, saying so, where `../shared` is absent.
//!
//! These campaigns are a regression test, not a tuning set: no constant of the analysis was
//! chosen on them (the held-out set the project is judged on is built the same way).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use pendulum_discover::Base;
use pendulum_jobs::discover::{run, DiscoverJob};

/// The independent campaigns' folder, or `None` after saying the test is skipped.
fn independent_dir() -> Option<PathBuf> {
    let d = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/independent");
    if !d.is_dir() {
        eprintln!(
            "SKIPPED: ../shared/data/independent is absent (issue 12's independent campaigns)"
        );
        return None;
    }
    Some(d)
}

/// The effects the README expects `discover` to accept with `base`, from the truth file.
fn expected(truth: &serde_json::Value, base: Base) -> BTreeSet<String> {
    let hidden: BTreeSet<String> = truth["hidden_effects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap().to_string())
        .collect();
    let model = &truth["model"];
    let positive = |k: &str| model[k].as_f64().unwrap_or(0.0) > 0.0;
    let reference = ["viscous_linear", "viscous_quadratic", "coulomb_bearing"];
    let mut out = hidden;
    match base {
        Base::Reference => out.retain(|e| !reference.contains(&e.as_str())),
        Base::Linear | Base::Dry => {
            if positive("a") {
                out.insert("viscous_quadratic".into());
            }
            if base == Base::Linear && positive("mu") {
                out.insert("coulomb_bearing".into());
            }
            if base == Base::Dry && positive("b") {
                out.insert("viscous_linear".into());
            }
            out.remove(if base == Base::Linear {
                "viscous_linear"
            } else {
                "coulomb_bearing"
            });
        }
    }
    out
}

/// The truth's parameter for an accepted effect, and whether the error is absolute (else
/// relative) with its tolerance.
fn tolerance(effect: &str) -> Option<(&'static str, bool, f64)> {
    Some(match effect {
        "coulomb_constant" => ("T_c", false, 0.10),
        "position_torque" => ("T_p", false, 0.10),
        "horizontal_base" => ("delta", false, 0.10),
        "extra_inertia" => ("J", false, 0.10),
        "encoder_offset" => ("theta_off", true, 0.002),
        "accel_delay" => ("Delta", true, 0.0005),
        "speed_drift" => ("dOmega_dt", false, 0.10),
        "accel_gain" => ("k_a", false, 0.10),
        _ => return None,
    })
}

fn check(name: &str, base: Base) {
    let Some(root) = independent_dir() else {
        return;
    };
    if let Err(why) = judge(&root.join(name), &truth_of(&root, name), base) {
        panic!("{name}: {why}");
    }
}

fn truth_of(root: &Path, name: &str) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(root.join(format!("{name}.truth.json"))).unwrap())
        .unwrap()
}

/// Runs `discover` on the campaign in `dir` with `base` (defaults otherwise, outputs in a
/// temporary folder): its summary and the effects it accepted.
fn discover_on(
    dir: &Path,
    base: Base,
) -> (pendulum_jobs::discover::DiscoverSummary, BTreeSet<String>) {
    let out = tempfile::tempdir().unwrap();
    let s = run(&DiscoverJob {
        input: dir.to_path_buf(),
        out: out.path().join("out"),
        base,
        pipeline: None,
        generations: None,
        seed: None,
        progress: false,
    })
    .unwrap();
    eprintln!("{s}");
    let accepted = s
        .discovery
        .accepted()
        .into_iter()
        .map(String::from)
        .collect();
    (s, accepted)
}

/// Runs `discover` on the campaign in `dir` and applies the README's rule: `Err` says what was
/// wrong (the accepted set, or an estimate outside its tolerance).
fn judge(dir: &Path, truth: &serde_json::Value, base: Base) -> Result<(), String> {
    let (s, accepted) = discover_on(dir, base);
    let want = expected(truth, base);
    if accepted != want {
        return Err(format!("accepted {accepted:?}, expected {want:?}"));
    }
    let effects = truth["effects"].as_array().unwrap();
    for e in &accepted {
        let Some((key, absolute, tol)) = tolerance(e) else {
            continue;
        };
        let t = effects
            .iter()
            .find(|v| v["name"] == e.as_str())
            .and_then(|v| v[key].as_f64())
            .unwrap_or_else(|| panic!("no truth {key} for {e}"));
        let row = s.discovery.row(e).unwrap();
        let err = (row.estimate - t).abs();
        let err = if absolute { err } else { err / t.abs() };
        eprintln!("{e} {:.4e} vs truth {t:.4e}", row.estimate);
        if err > tol {
            return Err(format!("{e} estimate {} vs truth {t}", row.estimate));
        }
    }
    Ok(())
}

/// A copy of the independent campaign `src` in `dst` with another design drawn from its own
/// runs: `validate` (indices into its `[[run]]` list) become the validate runs, the rest of
/// `keep` the identify runs, and runs outside `keep` are left out (their files not copied).
fn redesign(src: &Path, dst: &Path, keep: &[usize], validate: &[usize]) {
    let text = std::fs::read_to_string(src.join("campaign.toml")).unwrap();
    let mut doc: toml::Table = toml::from_str(&text).unwrap();
    let runs = doc["run"].as_array().unwrap().clone();
    let mut kept = Vec::new();
    std::fs::create_dir_all(dst).unwrap();
    for (i, r) in runs.into_iter().enumerate() {
        if !keep.contains(&i) {
            continue;
        }
        let mut r = r.as_table().unwrap().clone();
        let role = if validate.contains(&i) {
            "validate"
        } else {
            "identify"
        };
        r.insert("role".into(), role.into());
        let file = r["file"].as_str().unwrap();
        std::fs::copy(src.join(file), dst.join(file)).unwrap();
        kept.push(toml::Value::Table(r));
    }
    doc.insert("run".into(), toml::Value::Array(kept));
    std::fs::write(dst.join("campaign.toml"), toml::to_string(&doc).unwrap()).unwrap();
}

/// `i01_none_quadratic` with three of its identify runs (r02–r04) and two of its validate runs
/// (r07, r08), a design the redesign survey drew: the crank tracks show the other simulator's
/// motor 3 ppm slower at the end of a run than at its start (−1.1e-7 Hz/s), and the validate
/// runs' tracks agree, but the pendulum's predictions do not improve with it (E_θ −0.2 % ±
/// 0.2 %). Nothing is hidden, so nothing may be named; it was named `speed_drift`.
#[test]
fn issue_12_independent_i01_fewer_runs_names_no_drift_the_pendulum_does_not_feel() {
    let Some(root) = independent_dir() else {
        return;
    };
    let name = "i01_none_quadratic";
    let dir = tempfile::tempdir().unwrap();
    redesign(&root.join(name), dir.path(), &[1, 2, 3, 6, 7], &[6, 7]);
    if let Err(why) = judge(dir.path(), &truth_of(&root, name), Base::Reference) {
        panic!("{name}, 3 + 2 runs: {why}");
    }
}

/// An independent campaign with its runs' roles rotated: run i takes the role run i + `shift`
/// (mod the number of runs) had, all runs kept.
fn rotated(name: &str, shift: usize, base: Base) {
    let Some(root) = independent_dir() else {
        return;
    };
    let doc: toml::Table =
        toml::from_str(&std::fs::read_to_string(root.join(name).join("campaign.toml")).unwrap())
            .unwrap();
    let runs = doc["run"].as_array().unwrap();
    let n = runs.len();
    let validate: Vec<usize> = (0..n)
        .filter(|&i| runs[(i + shift) % n]["role"].as_str() == Some("validate"))
        .collect();
    let dir = tempfile::tempdir().unwrap();
    redesign(
        &root.join(name),
        dir.path(),
        &(0..n).collect::<Vec<_>>(),
        &validate,
    );
    if let Err(why) = judge(dir.path(), &truth_of(&root, name), base) {
        panic!("{name}, roles rotated by {shift} (validate {validate:?}): {why}");
    }
}

/// `i10_pair` (a k = 2 position torque of 0.03 N·m and a 0.01 kg·m² inertia, bobs of m l² 0.103
/// and 0.050 kg·m²) with the validate runs r03–r05: the torque, judged beside the named
/// inertia, was refused as a partial explanation (sin θ and θ̇² (1 + A_y) sin θ 56 % ± 17 %
/// better on the validate rows) because the freer-shape comparison fitted the raw columns, not
/// each run's dynamics divided by 1 + J/(m l²). The unit test
/// `sparse::tests::beside_an_extra_inertia_each_model_is_fitted_at_its_own_inertia` checks the
/// same property in the default suite.
#[test]
#[ignore = "slow set (another simulator's campaign, roles rotated): the default suite checks the property on sparse::tests::beside_an_extra_inertia_each_model_is_fitted_at_its_own_inertia and the pair on independent::issue_12_independent_i10_pair; README, Tests"]
fn issue_12_independent_i10_pair_with_its_roles_rotated_names_both() {
    rotated("i10_pair", 3, Base::Reference);
}

/// `i11_linear_truth` with `--base dry` and the validate runs r03–r05: its viscous damping,
/// found at 0.3998 N·s/m (truth 0.4), was refused because the runs' own damping factors, within
/// 0.3 % of 1, still predicted their held-out blocks (a "departure that follows the run").
#[test]
#[ignore = "slow set (another simulator's campaign, roles rotated): the default suite checks the property on sparse::tests::runs_that_disagree_on_the_damping_are_told_apart_from_noise and the campaign on independent::issue_12_independent_i11_linear_truth_dry; README, Tests"]
fn issue_12_independent_i11_dry_with_its_roles_rotated_finds_the_viscous_damping() {
    rotated("i11_linear_truth", 3, Base::Dry);
}

/// Survey (slow, by hand with `--ignored`): the independent campaigns under designs their
/// simulator did not choose. Each campaign (and `i11` with `--base dry`) is run `RESAMPLE_N`
/// times (default 2) with a drawn identify/validate split of all its runs, and `RESAMPLE_N`
/// times with only 3 drawn identify and 2 drawn validate runs; the README's rule must hold on
/// every one. Data the project did not make, in designs no one tuned on. Seeded
/// (`RESAMPLE_SEED`, default 7).
#[test]
#[ignore = "survey for issue 12: 14 independent campaigns × 2 RESAMPLE_N redesigns; RESAMPLE_N=2 is ~15 minutes on 2 cores"]
fn survey_independent_campaigns_redesigned() {
    use rand::seq::SliceRandom;
    use rand::SeedableRng;
    let Some(root) = independent_dir() else {
        return;
    };
    let env = |k: &str, d: u64| {
        std::env::var(k)
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(d)
    };
    let n = env("RESAMPLE_N", 2);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(env("RESAMPLE_SEED", 7));
    let mut names: Vec<String> = std::fs::read_dir(&root)
        .unwrap()
        .filter_map(|e| {
            let e = e.unwrap();
            e.path()
                .is_dir()
                .then(|| e.file_name().into_string().unwrap())
        })
        .collect();
    names.sort();
    let mut cases = Vec::new();
    for name in &names {
        let doc: toml::Table = toml::from_str(
            &std::fs::read_to_string(root.join(name).join("campaign.toml")).unwrap(),
        )
        .unwrap();
        let runs = doc["run"].as_array().unwrap();
        let role = |r: &str| -> Vec<usize> {
            (0..runs.len())
                .filter(|&i| runs[i]["role"].as_str() == Some(r))
                .collect()
        };
        let (mut ids, mut vals) = (role("identify"), role("validate"));
        let mut bases = vec![Base::Reference];
        if name.starts_with("i11") {
            bases.push(Base::Dry);
        }
        for k in 0..n {
            // All runs, another split (as many validate runs as the campaign had).
            let mut all: Vec<usize> = (0..runs.len()).collect();
            all.shuffle(&mut rng);
            let split = (all.clone(), all[..vals.len()].to_vec());
            // Fewer runs: 3 identify and 2 validate, drawn from the campaign's own roles.
            ids.shuffle(&mut rng);
            vals.shuffle(&mut rng);
            let few: Vec<usize> = ids[..3].iter().chain(&vals[..2]).copied().collect();
            let small = (few, vals[..2].to_vec());
            for (tag, (keep, val)) in [("split", split), ("few", small)] {
                for &base in &bases {
                    cases.push((
                        name.clone(),
                        format!("{tag}{k}"),
                        keep.clone(),
                        val.clone(),
                        base,
                    ));
                }
            }
        }
    }
    // One after another: discover parallelises inside (an outer rayon loop around it stalled
    // on a one-thread pool).
    let results: Vec<(String, Result<(), String>)> = cases
        .iter()
        .map(|(name, tag, keep, val, base)| {
            let dir = tempfile::tempdir().unwrap();
            redesign(&root.join(name), dir.path(), keep, val);
            let label = format!("{name} {tag} keep={keep:?} validate={val:?} base={base:?}");
            let r = judge(dir.path(), &truth_of(&root, name), *base);
            eprintln!(
                "redesigned {label}: {}",
                r.as_ref()
                    .map_or_else(|e| format!("WRONG {e}"), |()| "RIGHT".into())
            );
            (label, r)
        })
        .collect();
    let wrong: Vec<_> = results.iter().filter(|(_, r)| r.is_err()).collect();
    eprintln!(
        "redesigned independent campaigns: right on {} of {}",
        results.len() - wrong.len(),
        results.len()
    );
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// `i01_none_quadratic` (quadratic drag a = 0.08 kg/m and bearing friction μ = 0.17 in its
/// truth) with `--base linear`, the study's model: both terms are missing from it, and each alone
/// is a partial explanation of their sum (the drag alone was refused because the bearing's shape
/// beside it did better, and that refusal ended the search with nothing named). The pair look
/// now starts from a partial explanation: both are named, each at its value beside the other.
#[test]
fn issue_12_independent_i01_with_the_linear_base_names_the_drag_and_the_bearing_friction() {
    let Some(root) = independent_dir() else {
        return;
    };
    let name = "i01_none_quadratic";
    let truth = truth_of(&root, name);
    let (s, accepted) = discover_on(&root.join(name), Base::Linear);
    assert_eq!(accepted, expected(&truth, Base::Linear));
    for (effect, key) in [("viscous_quadratic", "a"), ("coulomb_bearing", "mu")] {
        let want = truth["model"][key].as_f64().unwrap();
        let row = s.discovery.row(effect).unwrap();
        assert!(
            (row.estimate - want).abs() <= 0.10 * want,
            "{effect}: {} against the truth's {key} = {want}; {}",
            row.estimate,
            row.note
        );
    }
}

macro_rules! independent {
    ($($test:ident: $name:literal, $base:expr;)*) => {$(
        #[test]
        fn $test() {
            check($name, $base);
        }
    )*};
}

independent! {
    issue_12_independent_i00_none: "i00_none", Base::Reference;
    issue_12_independent_i01_none_quadratic: "i01_none_quadratic", Base::Reference;
    issue_12_independent_i02_coulomb_constant: "i02_coulomb_constant", Base::Reference;
    issue_12_independent_i03_position_torque: "i03_position_torque", Base::Reference;
    issue_12_independent_i04_horizontal_base: "i04_horizontal_base", Base::Reference;
    issue_12_independent_i05_extra_inertia: "i05_extra_inertia", Base::Reference;
    issue_12_independent_i06_encoder_offset: "i06_encoder_offset", Base::Reference;
    issue_12_independent_i07_accel_delay: "i07_accel_delay", Base::Reference;
    issue_12_independent_i08_speed_drift: "i08_speed_drift", Base::Reference;
    issue_12_independent_i09_accel_gain: "i09_accel_gain", Base::Reference;
    issue_12_independent_i10_pair: "i10_pair", Base::Reference;
    // With the study's linear base the pair and the bearing friction the base leaves out: three
    // names (the search stopped at two before `Base::left_out` counted the base's missing terms).
    issue_12_independent_i10_pair_linear: "i10_pair", Base::Linear;
    issue_12_independent_i11_linear_truth: "i11_linear_truth", Base::Reference;
    issue_12_independent_i11_linear_truth_dry: "i11_linear_truth", Base::Dry;
    issue_12_independent_i12_bearing_load: "i12_bearing_load", Base::Reference;
}
