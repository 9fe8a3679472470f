//! Issue 4: the study's identification on twin campaigns at realistic noise (both formats).

use std::path::Path;

use pendulum_jobs::identify::{run, FitOverrides, IdentifyJob};
use pendulum_rig::twin::{synthesize, TwinCase, TwinTruthFile};

use crate::util::{python_check, python_has};

/// A small campaign: three identify runs and two validate runs with mixed steady states, both
/// capture formats, the twin's default (realistic) sensors and glitches.
pub fn campaign_toml(seed: u64, a: f64, b: f64, mu: f64) -> String {
    let runs = [
        ("r01", 1.30, "identify", "serial", 0.6, 0.0),
        ("r02", 1.65, "identify", "sd", 1.5, 0.0),
        ("r03", 1.75, "identify", "serial", 1.0, -9.0),
        ("v01", 1.54, "validate", "sd", 0.3, 6.0),
        ("v02", 1.75, "validate", "serial", 0.5, 0.0),
    ];
    let mut s = format!(
        "name = \"id-test\"\nseed = {seed}\n[rig]\nm_kg = 1.46\nl_m = 0.265\ncrank_r_m = 0.0725\nrod_L_m = 0.575\nr_b_m = 0.01225\n[truth]\na_kg_m = {a}\nb_n_s_m = {b}\nmu = {mu}\n"
    );
    for (id, om, role, fmt, th, thd) in runs {
        s += &format!(
            "[[run]]\nid = \"{id}\"\nomega_hz = {om}\nrole = \"{role}\"\nformat = \"{fmt}\"\ntheta0_rad = {th}\ntheta_dot0_rad_s = {thd}\nfree_s = 3\nforced_s = 30\n"
        );
    }
    s
}

pub fn make_campaign(dir: &Path, toml: &str) -> TwinTruthFile {
    let case = TwinCase::from_toml(toml, Path::new("case.toml")).unwrap();
    synthesize(&case, dir).unwrap().truth_data
}

fn identify(dir: &Path, out: &Path, model: &str) -> pendulum_jobs::outputs::OutputSummary {
    identify_with(
        dir,
        out,
        FitOverrides {
            model: Some(model.into()),
            generations: Some(1000),
            ..FitOverrides::default()
        },
    )
}

/// `pendulum identify` of `dir` into `out` with `overrides`.
fn identify_with(
    dir: &Path,
    out: &Path,
    overrides: FitOverrides,
) -> pendulum_jobs::outputs::OutputSummary {
    run(&IdentifyJob {
        input: dir.to_path_buf(),
        out: out.to_path_buf(),
        pipeline: None,
        overrides,
        progress: false,
        free_segments: false,
    })
    .unwrap()
}

/// The reference model's a, b, μ from an identify run's `params.parquet` (its first row).
fn reference_params(out: &Path) -> (f64, f64, f64) {
    let p = out.join("params.parquet");
    (
        column_f64(&p, "a")[0],
        column_f64(&p, "b")[0],
        column_f64(&p, "mu")[0],
    )
}

/// The arrays of one column of a Parquet file, batch by batch (panics naming the file and the
/// column when it is missing).
fn column_arrays(path: &Path, name: &str) -> Vec<arrow_array::ArrayRef> {
    use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
    let f = std::fs::File::open(path).unwrap();
    ParquetRecordBatchReaderBuilder::try_new(f)
        .unwrap()
        .build()
        .unwrap()
        .map(|b| {
            b.unwrap()
                .column_by_name(name)
                .unwrap_or_else(|| panic!("{}: no column {name}", path.display()))
                .clone()
        })
        .collect()
}

/// A primitive column's values, every record batch in order.
fn column_values<T: arrow_array::ArrowPrimitiveType>(path: &Path, name: &str) -> Vec<T::Native> {
    column_arrays(path, name)
        .iter()
        .flat_map(|c| {
            let a = c
                .as_any()
                .downcast_ref::<arrow_array::PrimitiveArray<T>>()
                .unwrap();
            a.values().to_vec()
        })
        .collect()
}

pub(crate) fn column_f64(path: &Path, name: &str) -> Vec<f64> {
    column_values::<arrow_array::types::Float64Type>(path, name)
}

pub(crate) fn column_i64(path: &Path, name: &str) -> Vec<i64> {
    column_values::<arrow_array::types::Int64Type>(path, name)
}

pub(crate) fn column_bool(path: &Path, name: &str) -> Vec<bool> {
    use arrow_array::{Array, BooleanArray};
    column_arrays(path, name)
        .iter()
        .flat_map(|c| {
            let a = c.as_any().downcast_ref::<BooleanArray>().unwrap();
            (0..a.len()).map(|i| a.value(i)).collect::<Vec<_>>()
        })
        .collect()
}

pub(crate) fn column_str(path: &Path, name: &str) -> Vec<String> {
    use arrow_array::{Array, StringArray};
    column_arrays(path, name)
        .iter()
        .flat_map(|c| {
            let a = c.as_any().downcast_ref::<StringArray>().unwrap();
            (0..a.len())
                .map(|i| a.value(i).to_string())
                .collect::<Vec<_>>()
        })
        .collect()
}

/// Reference data (a = 0, b = 0.5, μ = 0.15): b and μ within 10 %, a < 0.05, the validate runs'
/// steady states agree; the alignment finds the twin's true peak time within one sample and Ω
/// within 0.1 %. Outputs open in pyarrow with the documented schemas.
#[test]
fn regression_issue_4_reference_damping_recovered() {
    let dir = tempfile::tempdir().unwrap();
    let camp = dir.path().join("campaign");
    let out = dir.path().join("out");
    let truth = make_campaign(&camp, &campaign_toml(41, 0.0, 0.5, 0.15));
    let summary = identify(&camp, &out, "reference");
    eprintln!("{summary}");
    let (a, b, mu) = reference_params(&out);
    assert!((b / 0.5 - 1.0).abs() < 0.10, "b = {b}");
    assert!((mu / 0.15 - 1.0).abs() < 0.10, "mu = {mu}");
    assert!(a < 0.05, "a = {a}");

    let runs = out.join("runs.parquet");
    let ids = column_str(&runs, "run_id");
    let roles = column_str(&runs, "role");
    let t0 = column_f64(&runs, "t0_s");
    let om = column_f64(&runs, "omega_hz");
    let meas = column_str(&runs, "measured_steady");
    let sim = column_str(&runs, "simulated_steady");
    for (i, id) in ids.iter().enumerate() {
        let tr = truth.runs.iter().find(|r| &r.id == id).unwrap();
        // One accelerometer sample is 5 ms.
        assert!(
            (t0[i] - tr.t0_s).abs() < 0.005,
            "{id}: t0 {} vs true {}",
            t0[i],
            tr.t0_s
        );
        assert!(
            (om[i] / tr.omega_real_hz - 1.0).abs() < 1e-3,
            "{id}: Ω {} vs {}",
            om[i],
            tr.omega_real_hz
        );
        if roles[i] == "validate" {
            assert_eq!(meas[i], sim[i], "{id}: validate steady state");
        }
    }
    // residuals.parquet holds the residual the fit minimised (issue 14 item 5): over each run's
    // `segments` rows, Σ|θ_meas − θ_sim| is that run's E_θ as the fit (identify runs) or the
    // validation (validate runs) computed it, and every segment restarts near the measurement.
    let res = out.join("residuals.parquet");
    let (r_id, r_mode, r_model) = (
        column_str(&res, "run_id"),
        column_str(&res, "mode"),
        column_str(&res, "model"),
    );
    let r_err = column_f64(&res, "residual");
    let e_theta = column_f64(&runs, "e_theta");
    for (i, id) in ids.iter().enumerate() {
        let rows: Vec<usize> = (0..r_id.len())
            .filter(|&k| &r_id[k] == id && r_mode[k] == "segments" && r_model[k] == "reference")
            .collect();
        assert!(!rows.is_empty(), "{id}: no `segments` residuals");
        let sum: f64 = rows.iter().map(|&k| r_err[k].abs()).sum();
        assert!(
            (sum - e_theta[i]).abs() <= 0.01 * e_theta[i].max(1e-3),
            "{id}: Σ|residual| of the segments {sum} vs E_θ {}",
            e_theta[i]
        );
    }
    assert!(
        r_mode.iter().any(|m| m == "free_run"),
        "the free run is the second mode"
    );
    if python_has("pyarrow") {
        python_check("check_outputs.py", &[&out]);
    }
}

/// Classic linear data (b = 0.3, μ = 0): the reference fit finds no dry friction.
#[test]
fn regression_issue_4_linear_data_gives_mu_near_zero() {
    let dir = tempfile::tempdir().unwrap();
    let camp = dir.path().join("campaign");
    let out = dir.path().join("out");
    make_campaign(&camp, &campaign_toml(43, 0.0, 0.3, 0.0));
    let summary = identify(&camp, &out, "reference");
    eprintln!("{summary}");
    let p = out.join("params.parquet");
    let (b, mu) = (column_f64(&p, "b")[0], column_f64(&p, "mu")[0]);
    // μ = 0.01 would already be 1/15 of the study's dry friction.
    assert!(mu < 0.01, "mu = {mu}");
    assert!((b / 0.3 - 1.0).abs() < 0.10, "b = {b}");
}

/// Issue 6 item 3: re-running on the MCAP files gives the same answer as on the raw captures
/// (ingest loses nothing the fit uses): identical fitted parameters, E_θ and steady states.
#[test]
fn regression_issue_6_identify_same_from_mcap_as_from_raw() {
    let dir = tempfile::tempdir().unwrap();
    let camp = dir.path().join("campaign");
    make_campaign(&camp, &campaign_toml(61, 0.0, 0.5, 0.15));
    let mcap = dir.path().join("mcap");
    pendulum_jobs::ingest::run(&camp, &mcap, false).unwrap();
    let job = |input: &Path, out: &Path| IdentifyJob {
        input: input.to_path_buf(),
        out: out.to_path_buf(),
        pipeline: None,
        overrides: FitOverrides {
            generations: Some(40),
            ..FitOverrides::default()
        },
        progress: false,
        free_segments: false,
    };
    let (out_raw, out_mcap) = (dir.path().join("raw-out"), dir.path().join("mcap-out"));
    run(&job(&camp, &out_raw)).unwrap();
    run(&job(&mcap, &out_mcap)).unwrap();
    for col in ["a", "b", "mu", "f_obj", "e_theta"] {
        let (x, y) = (
            column_f64(&out_raw.join("params.parquet"), col),
            column_f64(&out_mcap.join("params.parquet"), col),
        );
        assert!(
            !x.is_empty() && x.len() == y.len(),
            "{col}: {} vs {} rows",
            x.len(),
            y.len()
        );
        for (u, v) in x.iter().zip(&y) {
            assert!(u.to_bits() == v.to_bits(), "{col}: raw {u} vs mcap {v}");
        }
    }
    for col in ["measured_steady", "omega_hz"] {
        let f = |d: &Path| -> Vec<String> {
            let p = d.join("runs.parquet");
            if col == "omega_hz" {
                column_f64(&p, col).iter().map(|v| v.to_string()).collect()
            } else {
                column_str(&p, col)
            }
        };
        assert_eq!(f(&out_raw), f(&out_mcap), "runs.parquet {col}");
    }
}

/// `pendulum identify --free-segments` of `camp` into `out` at `generations`.
fn identify_with_free_segments(
    camp: std::path::PathBuf,
    out: &Path,
    generations: u64,
) -> pendulum_jobs::outputs::OutputSummary {
    run(&IdentifyJob {
        input: camp,
        out: out.to_path_buf(),
        pipeline: None,
        overrides: FitOverrides {
            generations: Some(generations),
            ..FitOverrides::default()
        },
        progress: false,
        free_segments: true,
    })
    .unwrap()
}

/// Issue 7 item 2: the free-motion segment before each shaker start goes through the same
/// stages as a free decay (excitation off, identifiable terms) and recovers the twin's truth:
/// ω0 = sqrt(g/l), β = b/(m ω0), M = μ r_b/l.
///
/// Known failure since the free segments end where the base starts to move (b5a5bf7): each
/// lost the 0.3–1 s it held of the shaker's spin-up, and on what is left (three identify
/// segments of a few swings) the fit trades M against β and α: M 5.94e-3 for 6.93e-3 (−14 %),
/// β +3.5 %, f_obj 0.865 at the 150-generation cap; at 600 generations f_obj 0.760 with M
/// +15 %, β −7.5 %, α 2.1e-3 (there is none): the lower optimum is further from the truth, so the
/// segments, not the search, are short of information. Before b5a5bf7 it passed (M −4.8 %,
/// f_obj 0.940) on segments that held base motion.
#[test]
#[ignore = "known failure since b5a5bf7: M −14 % on the honest (shorter) free segments, which cannot separate M, β and α; see the doc comment"]
fn regression_issue_7_free_segments_fitted_as_free_decays() {
    let dir = tempfile::tempdir().unwrap();
    let camp = dir.path().join("campaign");
    let (b, mu) = (0.5, 0.15);
    make_campaign(&camp, &campaign_toml(71, 0.0, b, mu));
    let out = dir.path().join("out");
    let s = identify_with_free_segments(camp, &out, 150);
    eprintln!("{s}");
    let p = out.join("free_segments").join("params.parquet");
    let (m, l, r_b, g): (f64, f64, f64, f64) = (1.46, 0.265, 0.01225, 9.81);
    let w0 = (g / l).sqrt();
    let omega0 = column_f64(&p, "omega0_rad_s")[0];
    let beta = column_f64(&p, "beta")[0];
    let m_dry = column_f64(&p, "M")[0];
    assert!((omega0 / w0 - 1.0).abs() < 0.01, "ω0 {omega0} vs {w0}");
    let beta_true = b / (m * w0);
    let m_true = mu * r_b / l;
    assert!(
        (beta / beta_true - 1.0).abs() < 0.1,
        "β {beta} vs {beta_true}"
    );
    assert!((m_dry / m_true - 1.0).abs() < 0.1, "M {m_dry} vs {m_true}");
    let ids = column_str(&out.join("free_segments").join("runs.parquet"), "run_id");
    assert!(ids.iter().all(|id| id.ends_with("-free")), "{ids:?}");
}

/// A drawn design whose second identify run is started by hand at −0.005 rad: its free segment
/// holds no swing, so it cannot be aligned as a free decay ("only 0 turning points"). That one
/// segment is left out, saying why, and the others are fitted; before, the whole
/// `--free-segments` fit failed with it (and discover's trajectory refits lost every free
/// segment, which let a nothing-hidden campaign's damping wander into another basin).
#[test]
fn a_free_segment_at_rest_is_left_out_alone() {
    let dir = tempfile::tempdir().unwrap();
    let camp = dir.path().join("campaign");
    make_campaign(
        &camp,
        &pendulum_jobs::demo::discovery_campaign(
            "hidden",
            5_204,
            0.0,
            0.4768914291264561,
            0.15,
            "",
        ),
    );
    let out = dir.path().join("out");
    let s = identify_with_free_segments(camp, &out, 60);
    let text = s.to_string();
    assert!(
        text.contains("free segment r02-free left out: ") && text.contains("turning points"),
        "{text}"
    );
    let ids = column_str(&out.join("free_segments").join("runs.parquet"), "run_id");
    assert!(!ids.iter().any(|id| id == "r02-free"), "{ids:?}");
    assert!(
        ids.len() >= 3 && ids.iter().all(|id| id.ends_with("-free")),
        "{ids:?}"
    );
}

/// A drawn design whose first serial capture's accelerometer never leaves its quiet level (its
/// `az` column held at the first sample's value: the shaker did not run, or its sensor was
/// unplugged). That run cannot be aligned; it is left out with a note naming it and why, and
/// the other runs are fitted. Before, the one run's alignment error failed the whole campaign.
/// With every run so damaged there is nothing to analyse: still an error, naming a run.
#[test]
fn a_run_that_cannot_be_aligned_is_left_out_not_the_campaign() {
    let dir = tempfile::tempdir().unwrap();
    let camp = dir.path().join("campaign");
    make_campaign(
        &camp,
        &pendulum_jobs::demo::discovery_campaign("flat", 5_205, 0.0, 0.5, 0.15, ""),
    );
    let mut csvs: Vec<_> = std::fs::read_dir(&camp)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "csv"))
        .collect();
    csvs.sort();
    assert!(!csvs.is_empty(), "the drawn design has no serial capture");
    // The `az` column (the last) held at its first sample's value.
    let flatten = |path: &Path| {
        let text = std::fs::read_to_string(path).unwrap();
        let mut first_az: Option<String> = None;
        let mut out = String::new();
        for line in text.lines() {
            let fields: Vec<&str> = line.split(',').collect();
            let data = fields.len() == 5 && fields[0].parse::<u64>().is_ok();
            if data {
                let az = first_az.get_or_insert_with(|| fields[4].to_string());
                out.push_str(&format!("{},{}", fields[..4].join(","), az));
            } else {
                out.push_str(line);
            }
            out.push('\n');
        }
        std::fs::write(path, out).unwrap();
    };
    flatten(&csvs[0]);
    let bad = csvs[0].file_stem().unwrap().to_str().unwrap().to_string();
    let out = dir.path().join("out");
    // Which runs are fitted is what is tested, not how well: a short fit.
    let s = identify_with(
        &camp,
        &out,
        FitOverrides {
            model: Some("reference".into()),
            generations: Some(40),
            ..FitOverrides::default()
        },
    );
    let text = s.to_string();
    assert!(
        text.contains(&format!(
            "run {bad} is left out of the analysis: it cannot be aligned ("
        )) && text.contains("did the shaker run?"),
        "{text}"
    );
    // The others are fitted (or left out for a reason of their own, which their note gives:
    // this design's r07 loses its initial-state window to a burst of lost samples).
    let ids = column_str(&out.join("runs.parquet"), "run_id");
    let campaign = std::fs::read_to_string(camp.join("campaign.toml")).unwrap();
    let n_runs = campaign.matches("[[run]]").count();
    let left_out = text.matches("is left out of the analysis").count();
    assert!(
        !ids.contains(&bad) && ids.len() == n_runs - left_out && left_out <= 2,
        "{ids:?} of {n_runs} runs, {left_out} left out"
    );

    // Every capture flattened (the binary ones rewritten as serial ones would not be the same
    // campaign, so only a campaign of this one run): the error names it.
    let one = dir.path().join("one");
    std::fs::create_dir_all(&one).unwrap();
    std::fs::copy(&csvs[0], one.join(csvs[0].file_name().unwrap())).unwrap();
    // The campaign file with that run's block alone.
    let mut blocks = campaign.split("[[run]]");
    let head = blocks.next().unwrap();
    let block = blocks
        .find(|b| b.contains(&format!("id = \"{bad}\"")))
        .unwrap();
    std::fs::write(one.join("campaign.toml"), format!("{head}[[run]]{block}")).unwrap();
    let err = run(&IdentifyJob {
        input: one,
        out: dir.path().join("out-one"),
        pipeline: None,
        overrides: FitOverrides::default(),
        progress: false,
        free_segments: false,
    })
    .expect_err("a campaign whose only run cannot be aligned has nothing to analyse");
    let msg = format!("{err:#}");
    assert!(msg.contains(&format!("run {bad}: cannot align")), "{msg}");
}

/// Dry friction past the study's search range (0 < μ < 0.25) on a drawn design (bob, crank,
/// speed, format, hand start per run): the fit widens the range it was pinned at, instead of
/// returning 0.25 with the other terms bent to make up the rest (before the ranges widened, this
/// campaign gave μ = 0.24999 at f_obj 8.04; widened, μ = 0.393 at 5.13). With this much
/// friction four of the five identify runs come to rest, so μ is known only to about a tenth:
/// the test asks that it be clearly past the old range and nearer the truth than the old bound
/// was, and b within 10 %. Run with a third of the pipeline's population (44 members for 13
/// variables, not 130; it cost 77 s of the suite): the widening is what is tested, and the
/// smaller population reaches the bound in a third of the evaluations. Measured (on 01d5b8e's
/// analysis): two rounds, 2001 generations, μ = 0.395, b = 0.478 at f_obj 5.08.
#[test]
#[ignore = "slow set (a drawn design fitted by differential evolution, 42 s beside other runs; moved out of the default suite in the sixty-second session, whose default suite took 15:16 alone): the default suite checks the widening on the pendulum-process unit test a_search_range_widens_where_the_data_push_and_never_past_physics; README, Tests"]
fn damping_past_the_studys_search_range_is_fitted_not_pinned() {
    const NP: usize = 44;
    let dir = tempfile::tempdir().unwrap();
    let camp = dir.path().join("campaign");
    let out = dir.path().join("out");
    make_campaign(
        &camp,
        &pendulum_jobs::demo::discovery_campaign("wide", 61, 0.0, 0.5, 0.35, ""),
    );
    let summary = identify_with(
        &camp,
        &out,
        FitOverrides {
            model: Some("reference".into()),
            generations: Some(1000),
            np: Some(NP),
            ..FitOverrides::default()
        },
    );
    eprintln!("{summary}");
    let (a, b, mu) = reference_params(&out);
    assert!(
        mu > 1.1 * 0.25 && (mu - 0.35).abs() < 0.35 - 0.25,
        "mu = {mu}"
    );
    assert!((b / 0.5 - 1.0).abs() < 0.10, "b = {b}");
    assert!(a < 0.05, "a = {a}");
    // Every DE round is in the cost reported: the rounds after a widening run on from the last
    // one's best, each with a new initial population (1000 generations at most per round).
    let p = out.join("params.parquet");
    let (gens, evals, np) = (
        column_i64(&p, "generations")[0],
        column_i64(&p, "evaluations")[0],
        column_i64(&p, "np")[0],
    );
    // μ past 0.25 needs a widened range, so at least two rounds ran (each capped at 1000).
    assert!(gens > 1000, "generations {gens}: one round's only");
    assert_eq!(evals, np * (gens + 1), "generations {gens}, np {np}");
    let conv = out.join("convergence.parquet");
    let g: Vec<i64> = column_str(&conv, "model")
        .iter()
        .zip(column_i64(&conv, "generation"))
        .filter(|(m, _)| *m == "reference")
        .map(|(_, g)| g)
        .collect();
    assert_eq!(g, (0..=gens).collect::<Vec<_>>());
}
