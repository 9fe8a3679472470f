//! Issue 6: bifurcation diagrams, rotation-zone maps and the model replay of a run.
//!
//! The physics assertions reproduce the study's Fig. 8 vs Fig. 9 contrast at R = 0.700,
//! λ = 0.126 against an independent integration (8×8 starts, θ0 ∈ [−π, π), θ̇0 ∈ [−3, 3],
//! 300 transient periods): the linear model (β = 0.066) rotates from 14–25 % of starts at every
//! ω in [2.6, 3.0]; the dry-friction model's (β = 0.109, M = 0.007) period-1 rotation branch
//! ends near ω ≈ 2.69 and nothing rotates from 2.70 to 3.0; at ω = 1.57 only the dry-friction
//! model rotates (period 2, about 40 % of starts); at ω = 1.585 both do (period 1 and period 4).
//! Basins near 1.57 are fractal, so fractions are compared, never single starts there.

use std::collections::BTreeMap;
use std::path::Path;

use pendulum_maps::bifurcation::{self, Bifurcation, BifurcationConfig, Direction, Mode};
use pendulum_maps::zones::{self, ZoneConfig};
use pendulum_maps::{IcSpec, Sweep};
use pendulum_model::{Dimensionless, SteadyClass};

use crate::util::{pendulum, python_check, python_has};

fn study(name: &str) -> Dimensionless {
    pendulum_jobs::demo::study_models(1.0)
        .into_iter()
        .find(|(n, _)| *n == name)
        .unwrap()
        .1
}

fn grid(n: usize) -> Vec<[f64; 2]> {
    IcSpec::Grid {
        n_theta: n,
        n_theta_dot: n,
        theta_dot_max: 3.0,
    }
    .starts()
}

fn sweep(model: &str, spec: &str, starts: Vec<[f64; 2]>, record: u32) -> Bifurcation {
    let mut cfg = BifurcationConfig::new(study(model), Sweep::parse(spec).unwrap(), starts);
    cfg.transient_periods = 300;
    cfg.record_periods = record;
    bifurcation::run(&cfg, &|_| {}).unwrap()
}

/// Rotating simulations at sweep value `i` by period.
fn rotation_periods(b: &Bifurcation, i: usize) -> BTreeMap<u32, usize> {
    let mut m = BTreeMap::new();
    for o in b.outcomes.iter().filter(|o| o.value_index == i) {
        if o.steady.class.is_rotation() {
            *m.entry(o.steady.period).or_insert(0) += 1;
        }
    }
    m
}

/// Period-1 rotations turn a whole number of times per forcing period: mean dθ/dt = n·ω.
fn check_period1_speeds(b: &Bifurcation, model: &str) {
    for o in &b.outcomes {
        if o.steady.class.is_rotation() && o.steady.period == 1 {
            let omega = b.config.sweep.apply(&b.config.base, o.value_index).omega;
            let turns = o.steady.mean_theta_dot / omega;
            assert!(
                (turns - turns.round()).abs() < 1e-6 && turns.round() != 0.0,
                "{model} ω = {omega}: period-1 rotation at mean dθ/dt {} is not n·ω",
                o.steady.mean_theta_dot
            );
            assert_eq!(
                turns > 0.0,
                o.steady.class == SteadyClass::RotationCcw,
                "{model} ω = {omega}: direction vs sign of the mean speed"
            );
        }
    }
}

/// Figs. 8–9 at high ω: the linear model rotates everywhere in [2.6, 3.0], the dry-friction
/// model from at most 2 of 64 starts below 2.70 and from none at or above it.
#[test]
fn fig8_vs_fig9_high_omega_rotation_contrast() {
    let spec = "omega=2.6:3.0:0.05";
    let lin = sweep("linear", spec, grid(8), 32);
    let dry = sweep("reference", spec, grid(8), 32);
    let mut report = String::new();
    for (i, (l, d)) in lin.summary(None).iter().zip(dry.summary(None)).enumerate() {
        let w = l.value;
        report += &format!(
            "ω = {w:.2}: linear {:.1} % {:?}, reference {:.1} % {:?}\n",
            100.0 * l.rotation_fraction(),
            rotation_periods(&lin, i),
            100.0 * d.rotation_fraction(),
            rotation_periods(&dry, i)
        );
        assert_eq!(l.total, 64);
        // Linear: 14–25 % in the independent integration; a margin for the grid.
        let f = l.rotation_fraction();
        assert!(
            (0.10..=0.30).contains(&f),
            "linear at ω = {w}: {f}\n{report}"
        );
        assert_eq!(
            rotation_periods(&lin, i)
                .keys()
                .copied()
                .collect::<Vec<_>>(),
            vec![1],
            "linear at ω = {w}: period-1 rotations only\n{report}"
        );
        // The model and the grid are symmetric under (θ, θ̇) → (−θ, −θ̇).
        let (ccw, cw) = (
            l.counts[pendulum_maps::class_index(SteadyClass::RotationCcw)],
            l.counts[pendulum_maps::class_index(SteadyClass::RotationCw)],
        );
        assert!(
            ccw.abs_diff(cw) <= 2,
            "linear at ω = {w}: ccw {ccw} vs cw {cw}"
        );
        // Dry friction.
        let n_rot = (d.rotation_fraction() * 64.0).round() as usize;
        if w < 2.70 - 1e-9 {
            assert!(
                n_rot <= 2,
                "reference at ω = {w}: {n_rot} of 64 rotate\n{report}"
            );
        } else {
            assert_eq!(n_rot, 0, "reference at ω = {w} rotates\n{report}");
        }
    }
    check_period1_speeds(&lin, "linear");
    check_period1_speeds(&dry, "reference");
    eprintln!("{report}");
}

/// Continuation makes the end of the dry-friction branch exact: swept up from every start of a
/// 4×4 grid in steps of 0.01, the last ω that still rotates is 2.67–2.69; swept down from 2.75
/// nothing rotates. The linear model's branch, followed the same way, lasts through 3.0.
#[test]
fn dry_friction_rotation_branch_ends_near_2_69() {
    let mut cfg = BifurcationConfig::new(
        study("reference"),
        Sweep::parse("omega=2.6:2.75:0.01").unwrap(),
        grid(4),
    );
    cfg.mode = Mode::Continuation;
    cfg.transient_periods = 100;
    cfg.record_periods = 32;
    let dry = bifurcation::run(&cfg, &|_| {}).unwrap();
    let up = dry.summary(Some(Direction::Up));
    let rotating: Vec<f64> = up
        .iter()
        .filter(|s| s.rotation_fraction() > 0.0)
        .map(|s| s.value)
        .collect();
    assert!(rotating.first() == Some(&2.6), "up: {rotating:?}");
    let last = *rotating.last().unwrap();
    assert!(
        (2.67..=2.69).contains(&last),
        "branch ends at {last}: {rotating:?}"
    );
    // Contiguous: a branch, not scattered starts.
    assert_eq!(rotating.len(), ((last - 2.6) / 0.01).round() as usize + 1);
    for s in &up {
        if s.rotation_fraction() > 0.0 {
            assert_eq!(s.rotation_periods, vec![1], "ω = {}", s.value);
        }
    }
    for s in dry.summary(Some(Direction::Down)) {
        assert_eq!(s.rotation_fraction(), 0.0, "down at ω = {}", s.value);
    }

    cfg.base = study("linear");
    cfg.sweep = Sweep::parse("omega=2.6:3.0:0.05").unwrap();
    let lin = bifurcation::run(&cfg, &|_| {}).unwrap();
    for s in lin.summary(Some(Direction::Up)) {
        assert!(s.rotation_fraction() > 0.0, "linear up at ω = {}", s.value);
    }
}

/// ω = 1.57: the dry-friction model rotates (period 2) from about 40 % of starts, the linear
/// model from none; ω = 1.585: both rotate, period 1 and period 4. Fractal basins: a 16×16
/// grid, fractions only.
#[test]
fn fig8_vs_fig9_low_omega_rotation_contrast() {
    let dry = sweep("reference", "omega=1.57,1.585", grid(16), 50);
    let lin = sweep("linear", "omega=1.57,1.585", grid(16), 50);
    let (d, l) = (dry.summary(None), lin.summary(None));
    let dominant = |m: &BTreeMap<u32, usize>| {
        let total: usize = m.values().sum();
        m.iter()
            .max_by_key(|(_, n)| **n)
            .map(|(p, n)| (*p, *n as f64 / total as f64))
    };
    let text = format!(
        "1.57: reference {:.1} % {:?}, linear {:.1} % {:?}; 1.585: reference {:.1} % {:?}, linear {:.1} % {:?}",
        100.0 * d[0].rotation_fraction(),
        rotation_periods(&dry, 0),
        100.0 * l[0].rotation_fraction(),
        rotation_periods(&lin, 0),
        100.0 * d[1].rotation_fraction(),
        rotation_periods(&dry, 1),
        100.0 * l[1].rotation_fraction(),
        rotation_periods(&lin, 1)
    );
    eprintln!("{text}");
    let f = d[0].rotation_fraction();
    assert!((0.30..=0.50).contains(&f), "{text}");
    let (p, share) = dominant(&rotation_periods(&dry, 0)).unwrap();
    assert!(p == 2 && share >= 0.9, "{text}");
    assert_eq!(l[0].rotation_fraction(), 0.0, "{text}");

    assert!(d[1].rotation_fraction() >= 0.1, "{text}");
    assert!(l[1].rotation_fraction() >= 0.1, "{text}");
    let (p, share) = dominant(&rotation_periods(&dry, 1)).unwrap();
    assert!(p == 1 && share >= 0.9, "{text}");
    let (p, share) = dominant(&rotation_periods(&lin, 1)).unwrap();
    assert!(p == 4 && share >= 0.9, "{text}");
}

/// Single starts whose fate is not in doubt (far from fractal basin boundaries).
#[test]
fn classes_of_known_points() {
    let run = |model: &str, omega: f64, y0: [f64; 2]| {
        let mut cfg = BifurcationConfig::new(
            study(model),
            Sweep::parse(&format!("omega={omega}")).unwrap(),
            vec![y0],
        );
        cfg.record_periods = 48;
        bifurcation::run(&cfg, &|_| {}).unwrap().outcomes.remove(0)
    };
    // Hanging still is an equilibrium of vertical forcing.
    for model in ["reference", "linear"] {
        for omega in [1.0, 1.57, 2.0, 2.8] {
            let o = run(model, omega, [0.0, 0.0]);
            assert_eq!(o.steady.class, SteadyClass::Rest, "{model} ω = {omega}");
        }
    }
    // Principal parametric resonance (ω ≈ 2): a small swing grows into a period-2 oscillation.
    for model in ["reference", "linear"] {
        let o = run(model, 2.0, [0.3, 0.0]);
        assert_eq!(
            (o.steady.class, o.steady.period),
            (SteadyClass::Oscillation, 2),
            "{model}"
        );
    }
    // Well below resonance the dry-friction pendulum comes to rest from anywhere.
    assert_eq!(
        run("reference", 1.0, [3.0, 0.0]).steady.class,
        SteadyClass::Rest
    );
    // ω = 2.8, thrown at θ̇0 = ±3: the linear model rotates (period 1, one turn per forcing
    // period), the dry-friction model stops.
    let ccw = run("linear", 2.8, [0.0, 3.0]);
    let cw = run("linear", 2.8, [0.0, -3.0]);
    assert_eq!(
        (ccw.steady.class, ccw.steady.period),
        (SteadyClass::RotationCcw, 1)
    );
    assert_eq!(
        (cw.steady.class, cw.steady.period),
        (SteadyClass::RotationCw, 1)
    );
    assert!((ccw.steady.mean_theta_dot - 2.8).abs() < 1e-9);
    assert!((cw.steady.mean_theta_dot + 2.8).abs() < 1e-9);
    // Mirror images: (θ, θ̇) → (−θ, −θ̇).
    for (a, b) in ccw.theta_dot.iter().zip(&cw.theta_dot) {
        assert!((a + b).abs() < 1e-9, "{a} vs {b}");
    }
    assert_eq!(
        run("reference", 2.8, [0.0, 3.0]).steady.class,
        SteadyClass::Rest
    );
}

/// Same inputs, same numbers: whatever the thread count, and for random starts with the same
/// seed; another seed gives other starts.
#[test]
fn sweeps_are_deterministic() {
    let mut cfg = BifurcationConfig::new(
        study("linear"),
        Sweep::parse("omega=1.57,1.585,2.8").unwrap(),
        IcSpec::Random {
            n: 6,
            seed: 42,
            theta_dot_max: 3.0,
        }
        .starts(),
    );
    cfg.transient_periods = 100;
    cfg.record_periods = 16;
    cfg.threads = Some(1);
    let a = bifurcation::run(&cfg, &|_| {}).unwrap();
    cfg.threads = Some(2);
    let b = bifurcation::run(&cfg, &|_| {}).unwrap();
    assert_eq!(a.outcomes, b.outcomes);
    cfg.starts = IcSpec::Random {
        n: 6,
        seed: 42,
        theta_dot_max: 3.0,
    }
    .starts();
    assert_eq!(
        bifurcation::run(&cfg, &|_| {}).unwrap().outcomes,
        a.outcomes
    );
    let other = IcSpec::Random {
        n: 6,
        seed: 43,
        theta_dot_max: 3.0,
    }
    .starts();
    assert_ne!(other, cfg.starts);

    // The command line too: two runs, the same Parquet values.
    let dir = tempfile::tempdir().unwrap();
    let mut tables = Vec::new();
    for (k, threads) in ["1", "2"].iter().enumerate() {
        let out = dir.path().join(format!("b{k}"));
        let o = pendulum()
            .args([
                "bifurcate",
                "--study",
                "linear",
                "--sweep",
                "omega=2.7,2.8",
                "--ic-random",
                "5",
                "--seed",
                "9",
                "--transient",
                "100",
                "--record",
                "16",
                "--quiet",
                "--threads",
                threads,
                "--out",
            ])
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        tables.push(read_table(&out.join("bifurcation.parquet")));
    }
    assert_eq!(tables[0], tables[1]);
}

/// Every column of a Parquet file as strings (floats via their bits), for exact comparisons.
fn read_table(path: &Path) -> BTreeMap<String, Vec<String>> {
    use arrow_array::{Array, BooleanArray, Float64Array, Int64Array, StringArray};
    use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
    let f = std::fs::File::open(path).unwrap();
    let mut out: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for batch in ParquetRecordBatchReaderBuilder::try_new(f)
        .unwrap()
        .build()
        .unwrap()
    {
        let batch = batch.unwrap();
        for (field, col) in batch.schema().fields().iter().zip(batch.columns()) {
            let v = out.entry(field.name().clone()).or_default();
            let any = col.as_any();
            for i in 0..col.len() {
                v.push(if let Some(a) = any.downcast_ref::<Float64Array>() {
                    format!("{:x}", a.value(i).to_bits())
                } else if let Some(a) = any.downcast_ref::<Int64Array>() {
                    a.value(i).to_string()
                } else if let Some(a) = any.downcast_ref::<StringArray>() {
                    a.value(i).to_string()
                } else if let Some(a) = any.downcast_ref::<BooleanArray>() {
                    a.value(i).to_string()
                } else {
                    panic!("{}: unexpected type of {}", path.display(), field.name())
                });
            }
        }
    }
    out
}

fn is_png(path: &Path) -> bool {
    std::fs::read(path).is_ok_and(|b| b.len() > 1000 && b.starts_with(b"\x89PNG\r\n\x1a\n"))
}

/// A model row: name, a (kg/m), b (N·s/m), μ.
type Row<'a> = (&'a str, f64, f64, f64);

/// A params.parquet as `pendulum identify` writes it: one row per model.
fn write_params(path: &Path, rows: &[Row]) {
    write_params_with(path, rows, &[]);
}

/// [`write_params`] with extra columns (one value for every row), e.g. an effect's parameter.
fn write_params_with(path: &Path, rows: &[Row], extra: &[(&str, f64)]) {
    use pendulum_model::Physical;
    use pendulum_report::{Column, ColumnData, TableOptions};
    let rig = Physical::default();
    let mut cols = vec![Column::new(
        "model",
        ColumnData::Str(rows.iter().map(|r| r.0.to_string()).collect()),
    )];
    let mut f = |name: &str, v: &dyn Fn(&Row) -> f64| {
        cols.push(Column::f64(name, "1", rows.iter().map(v).collect()));
    };
    let dimless = |r: &Row| {
        Physical {
            a_kg_m: r.1,
            b_n_s_m: r.2,
            mu: r.3,
            ..Physical::default()
        }
        .to_dimensionless()
    };
    f("a", &|r| r.1);
    f("b", &|r| r.2);
    f("mu", &|r| r.3);
    f("alpha", &|r| dimless(r).alpha);
    f("beta", &|r| dimless(r).beta);
    f("M", &|r| dimless(r).m_coulomb);
    f("R", &|r| dimless(r).r);
    f("lambda", &|r| dimless(r).lambda);
    f("omega", &|r| dimless(r).omega);
    f("m_kg", &|_| rig.m_kg);
    f("l_m", &|_| rig.l_m);
    f("crank_r_m", &|_| rig.crank_r_m);
    f("rod_L_m", &|_| rig.rod_l_m);
    f("r_b_m", &|_| rig.r_b_m);
    f("g_m_s2", &|_| rig.g_m_s2);
    f("omega_hz", &|_| rig.omega_hz);
    f("f_obj", &|_| 1.0);
    f("e_theta", &|_| 1.0);
    for (name, v) in extra {
        f(name, &|_| *v);
    }
    TableOptions::new().write(path, &cols).unwrap();
}

/// `pendulum bifurcate` end to end: the documented columns, PNGs; `--params FILE --model NAME`
/// gives the same numbers as the same parameters by `--param`.
#[test]
fn bifurcate_cli_writes_table_and_figures() {
    let dir = tempfile::tempdir().unwrap();
    let params = dir.path().join("params.parquet");
    // The study's dry-friction model in physical units on the default rig.
    let p = pendulum_model::Physical::default();
    let d = study("reference");
    let b = d.beta * p.m_kg * p.omega0_rad_s();
    let mu = d.m_coulomb * p.l_m / p.r_b_m;
    write_params(
        &params,
        &[("linear", 0.0, 0.4, 0.0), ("reference", 0.0, b, mu)],
    );
    let common = [
        "--sweep",
        "omega=1.5:1.6:0.05",
        "--ic-grid",
        "3x2",
        "--transient",
        "60",
        "--record",
        "16",
        "--quiet",
    ];
    let run = |extra: &[&str], out: &Path| {
        let o = pendulum()
            .arg("bifurcate")
            .args(extra)
            .args(common)
            .arg("--out")
            .arg(out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8_lossy(&o.stdout).into_owned()
    };
    let a = dir.path().join("a");
    let text = run(
        &[
            "--params",
            params.to_str().unwrap(),
            "--model",
            "reference",
            "--param",
            "R=0.7",
            "--param",
            "lambda=0.126",
        ],
        &a,
    );
    assert!(text.contains("bifurcate reference model"), "{text}");
    assert!(text.contains("bifurcation.parquet"), "{text}");
    let t = read_table(&a.join("bifurcation.parquet"));
    for c in [
        "omega",
        "ic",
        "direction",
        "k",
        "theta",
        "theta_dot",
        "class",
        "period",
    ] {
        assert!(t.contains_key(c), "column {c}: {:?}", t.keys());
    }
    // 3 values × 6 starts × 17 points.
    assert_eq!(t["omega"].len(), 3 * 6 * 17);
    assert!(t["direction"].iter().all(|d| d == "grid"));
    assert!(is_png(&a.join("bifurcation.png")));
    assert!(is_png(&a.join("bifurcation_classes.png")));

    // The same dimensionless set by --param (the file's β and M, which went through SI and
    // back, so that fractal basins see bit-identical parameters).
    let file_d = pendulum_model::Physical {
        b_n_s_m: b,
        mu,
        ..pendulum_model::Physical::default()
    }
    .to_dimensionless();
    let b_dir = dir.path().join("b");
    run(
        &[
            "--param",
            "R=0.7",
            "--param",
            "lambda=0.126",
            "--param",
            &format!("beta={}", file_d.beta),
            "--param",
            &format!("M={}", file_d.m_coulomb),
        ],
        &b_dir,
    );
    let t2 = read_table(&b_dir.join("bifurcation.parquet"));
    for c in ["theta", "theta_dot", "class", "period"] {
        assert_eq!(t[c], t2[c], "column {c}");
    }

    // Continuation: up and down chains.
    let c_dir = dir.path().join("c");
    run(&["--study", "linear", "--continuation"], &c_dir);
    let t3 = read_table(&c_dir.join("bifurcation.parquet"));
    assert_eq!(t3["omega"].len(), 2 * 3 * 6 * 17);
    assert!(t3["direction"].iter().any(|d| d == "up"));
    assert!(t3["direction"].iter().any(|d| d == "down"));

    if python_has("pyarrow") {
        let spec = dir.path().join("spec.json");
        std::fs::write(
            &spec,
            serde_json::json!({
                "rows": 3 * 6 * 17,
                "columns": {"omega": "double", "ic": "int64", "direction": "string", "k": "int64",
                            "theta": "double", "theta_dot": "double", "class": "string",
                            "period": "int64"},
                "units": {"theta": "rad"},
                "metadata": {"command": "pendulum bifurcate", "model": "reference",
                             "sweep_param": "omega"}
            })
            .to_string(),
        )
        .unwrap();
        python_check("check_parquet.py", &[&a.join("bifurcation.parquet"), &spec]);
    }

    // Errors name what is wrong.
    let o = pendulum()
        .args([
            "bifurcate",
            "--study",
            "linear",
            "--sweep",
            "omgea=1:2:0.1",
            "--out",
        ])
        .arg(dir.path().join("e"))
        .output()
        .unwrap();
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("omgea") && err.contains("omega"), "{err}");
    let o = pendulum()
        .args(["bifurcate", "--params"])
        .arg(&params)
        .args(["--model", "quadratic", "--sweep", "omega=1", "--out"])
        .arg(dir.path().join("e"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && err.contains("linear, reference"),
        "{err}"
    );
}

/// Two models on one small ω × R grid: where the linear model rotates and the dry-friction model
/// does not (ω = 2.8), and the reverse (ω = 1.57), the cells are flagged.
#[test]
fn zone_maps_flag_where_models_disagree() {
    let mut cfg = ZoneConfig::new(
        Sweep::parse("omega=1.57,2.0,2.8").unwrap(),
        Sweep::parse("R=0.7,0.75").unwrap(),
        grid(8),
    );
    cfg.transient_periods = 300;
    cfg.record_periods = 32;
    let maps = zones::run(
        &[
            ("reference".to_string(), study("reference")),
            ("linear".to_string(), study("linear")),
        ],
        &cfg,
        &|_| {},
    )
    .unwrap();
    let cmp = zones::compare(&maps[0], &maps[1]).unwrap();
    assert!(cmp.only_a.contains(&(0, 0)), "{cmp:?}");
    assert!(cmp.only_b.contains(&(2, 0)), "{cmp:?}");
    let lin = maps[1].cell(2, 0);
    assert!(lin.rotation_fraction() > 0.1);
    // Period-1 rotation at ω = 2.8: mean speed ω.
    assert!((lin.mean_rotation_speed - 2.8).abs() < 1e-6, "{lin:?}");
    assert!(maps[0].cell(2, 0).mean_rotation_speed.is_nan());
    let total: f64 = SteadyClass::ALL.iter().map(|c| lin.fraction(*c)).sum();
    assert!((total - 1.0).abs() < 1e-12);

    // The command line: a table, one PNG per model and the comparison.
    let dir = tempfile::tempdir().unwrap();
    let o = pendulum()
        .args([
            "zones",
            "--study",
            "reference",
            "--compare-param",
            "beta=0.066",
            "--compare-param",
            "M=0",
            "--x",
            "omega=1.57,2.8",
            "--y",
            "R=0.7",
            "--ic-grid",
            "4x4",
            "--transient",
            "150",
            "--record",
            "32",
            "--quiet",
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(text.contains("rotates where"), "{text}");
    let t = read_table(&dir.path().join("zones.parquet"));
    for c in [
        "model",
        "omega",
        "R",
        "rotation_fraction",
        "mean_rotation_speed",
        "disagree",
    ] {
        assert!(t.contains_key(c), "column {c}");
    }
    assert_eq!(
        t["model"],
        vec!["reference", "reference", "compare", "compare"]
    );
    assert!(t["disagree"].iter().all(|d| d == "true"), "{t:?}");
    for f in ["zones_reference.png", "zones_compare.png"] {
        assert!(is_png(&dir.path().join(f)), "{f}");
    }
}

/// The demo's closing comparison: a printable summary and its files.
#[test]
fn demo_zone_comparison() {
    let dir = tempfile::tempdir().unwrap();
    let s = pendulum_jobs::zones::demo_comparison(dir.path(), false).unwrap();
    let text = s.to_string();
    assert!(
        text.contains("linear rotates where reference does not"),
        "{text}"
    );
    let cmp = s.comparison.as_ref().unwrap();
    // At R = 0.7 the linear model rotates at ω = 2.8 and the dry-friction model does not.
    let (a, b) = (&s.maps[0], &s.maps[1]);
    let ix = a.config.x.values.iter().position(|v| *v == 2.8).unwrap();
    let iy = a.config.y.values.iter().position(|v| *v == 0.7).unwrap();
    assert!(!a.cell(ix, iy).rotates() && b.cell(ix, iy).rotates());
    assert!(cmp.only_b.contains(&(ix, iy)));
    for f in ["zones.parquet", "zones_compare.png"] {
        assert!(dir.path().join(f).is_file(), "{f}");
    }
}

const CASE: &str = r#"name = "replay-test"
seed = 11
[rig]
m_kg = 1.46
l_m = 0.265
crank_r_m = 0.0725
rod_L_m = 0.575
r_b_m = 0.01225
[truth]
a_kg_m = 0.0
b_n_s_m = 0.5
mu = 0.15
[[run]]
id = "r01"
omega_hz = 1.54
role = "identify"
format = "sd"
theta0_rad = 0.8
free_s = 3
forced_s = 16
"#;

/// `pendulum replay`: measured channels copied, /sim/theta on the run's time axis (each
/// simulated sample shares t_s and log time with its encoder sample), the true model tracks the
/// measurement; the file reads in the Python `mcap` reader.
#[test]
fn replay_overlays_simulation_on_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let case = dir.path().join("case.toml");
    std::fs::write(&case, CASE).unwrap();
    let campaign = dir.path().join("campaign");
    let mcap_dir = dir.path().join("mcap");
    for args in [
        vec![
            "synth".to_string(),
            case.display().to_string(),
            campaign.display().to_string(),
        ],
        vec![
            "ingest".to_string(),
            campaign.display().to_string(),
            "--out".to_string(),
            mcap_dir.display().to_string(),
            "--quiet".to_string(),
        ],
    ] {
        let o = pendulum().args(&args).output().unwrap();
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(campaign.join("truth.json")).unwrap())
            .unwrap();
    let params = dir.path().join("params.parquet");
    write_params(
        &params,
        &[("reference", 0.0, 0.5, 0.15), ("linear", 0.0, 0.9, 0.0)],
    );
    let run_path = mcap_dir.join("r01.mcap");
    let mut rms10 = BTreeMap::new();
    for model in ["reference", "linear"] {
        let out = dir.path().join(format!("overlay_{model}.mcap"));
        let o = pendulum()
            .arg("replay")
            .arg(&run_path)
            .arg("--params")
            .arg(&params)
            .args(["--model", model, "--out"])
            .arg(&out)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let text = String::from_utf8_lossy(&o.stdout).into_owned();
        eprintln!("{text}");

        let src = pendulum_log::read_run(&run_path).unwrap();
        let ov = pendulum_log::read_run(&out).unwrap();
        assert_eq!(ov.encoder, src.encoder);
        assert_eq!(ov.encoder_log_time_ns, src.encoder_log_time_ns);
        assert_eq!(ov.accel, src.accel);
        assert_eq!(ov.accel_log_time_ns, src.accel_log_time_ns);
        assert_eq!(ov.stats, src.stats);
        assert_eq!(ov.metadata["run"], src.metadata["run"]);
        let replay = &ov.metadata["replay"];
        assert_eq!(replay["model"], model);
        let t0: f64 = replay["t0_s"].parse().unwrap();
        let t0_true = truth["runs"][0]["t0_s"].as_f64().unwrap();
        assert!((t0 - t0_true).abs() < 0.01, "t0 {t0} vs truth {t0_true}");

        // One simulated sample per encoder sample from t0 on, at the same time.
        let first = src.encoder.partition_point(|e| e.t_s < t0);
        let sim = &ov.simulated;
        assert_eq!(sim.len(), src.encoder.len() - first);
        for (k, s) in sim.iter().enumerate() {
            let e = &src.encoder[first + k];
            assert_eq!(s.t_s, e.t_s);
            assert_eq!(
                ov.simulated_log_time_ns[k],
                src.encoder_log_time_ns[first + k]
            );
            assert_eq!(s.residual_rad, e.theta_rad - s.theta_rad);
        }
        // The simulation starts where the measurement is.
        assert!(sim[0].residual_rad.abs() < 0.02, "{:?}", sim[0]);
        let (ss, n) = sim
            .iter()
            .filter(|s| s.t_s - t0 <= 10.0)
            .fold((0.0, 0usize), |(a, n), s| {
                (a + s.residual_rad.powi(2), n + 1)
            });
        rms10.insert(model, (ss / n as f64).sqrt());

        if model == "reference" && python_has("mcap") {
            let e0 = &src.encoder[first];
            let expected = serde_json::json!({
                "library": concat!("pendulum replay/", env!("CARGO_PKG_VERSION")),
                "topics": {
                    "/encoder": {"count": src.encoder.len(), "schema_name": "pendulum.Encoder",
                                  "messages": [{"index": first,
                                                "log_time": src.encoder_log_time_ns[first],
                                                "data": serde_json::to_value(e0).unwrap()}]},
                    "/accel": {"count": src.accel.len(), "schema_name": "pendulum.Accel"},
                    "/ingest_stats": {"count": 1},
                    "/sim/theta": {"count": sim.len(), "schema_name": "pendulum.Simulated",
                                    "messages": [
                                        {"index": 0, "log_time": src.encoder_log_time_ns[first],
                                         "data": serde_json::to_value(sim[0]).unwrap()},
                                        {"index": sim.len() - 1,
                                         "log_time": src.encoder_log_time_ns[src.encoder.len() - 1],
                                         "data": serde_json::to_value(sim[sim.len() - 1]).unwrap()}
                                    ]}
                },
                "metadata": serde_json::to_value(&ov.metadata).unwrap()
            });
            let spec = dir.path().join("expected.json");
            std::fs::write(&spec, expected.to_string()).unwrap();
            python_check("check_mcap.py", &[&out, &spec]);
        }
    }
    // The true model tracks the run better than a wrong one.
    eprintln!("residual RMS over 10 s: {rms10:?}");
    assert!(rms10["reference"] < 0.1, "{rms10:?}");
    assert!(rms10["reference"] < rms10["linear"], "{rms10:?}");
}

/// Issue 14: `replay` simulates a model the way the fit and discover do (the shared sensor
/// transform, `Model::measured`): a fitted `accel_delay` shifts the forcing. Replay used to build
/// its model with `Model::new`, which dropped the delay, so a fitted delay was silently ignored.
#[test]
fn issue_14_replay_of_a_model_with_accel_delay_matches_the_fits_simulation() {
    use pendulum_process::fit::{model_for, FitParam, ModelSpec};
    let dir = tempfile::tempdir().unwrap();
    let case = dir.path().join("case.toml");
    let delay_s = 0.012;
    // The effects table belongs to [truth]: inserted right after it.
    let text = CASE.replace(
        "mu = 0.15\n",
        &format!("mu = 0.15\n[truth.effects]\naccel_delay_s = {delay_s}\n"),
    );
    std::fs::write(&case, text).unwrap();
    let campaign = dir.path().join("campaign");
    let mcap_dir = dir.path().join("mcap");
    for args in [
        vec![
            "synth".to_string(),
            case.display().to_string(),
            campaign.display().to_string(),
        ],
        vec![
            "ingest".to_string(),
            campaign.display().to_string(),
            "--out".to_string(),
            mcap_dir.display().to_string(),
            "--quiet".to_string(),
        ],
    ] {
        let o = pendulum().args(&args).output().unwrap();
        assert!(
            o.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let params = dir.path().join("params.parquet");
    write_params_with(
        &params,
        &[("reference", 0.0, 0.5, 0.15)],
        &[("accel_delay.Delta", delay_s)],
    );
    let run_path = mcap_dir.join("r01.mcap");
    let out = dir.path().join("overlay.mcap");
    let o = pendulum()
        .arg("replay")
        .arg(&run_path)
        .arg("--params")
        .arg(&params)
        .args(["--model", "reference", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let ov = pendulum_log::read_run(&out).unwrap();
    let meta = &ov.metadata["replay"];
    let num = |k: &str| -> f64 { meta[k].parse().unwrap() };
    let (t0, omega_hz) = (num("t0_s"), num("omega_hz"));
    let y0 = [num("theta0_rad"), num("theta_dot0_rad_s")];
    let tol = num("tol");

    // The fit's (and discover's) model of the same row on the same run.
    let log = pendulum_log::read_run(&run_path).unwrap();
    let rig = pendulum_jobs::runs::run_data_from_log(&log).unwrap().rig;
    let mut spec = ModelSpec::reference();
    spec.params.push(FitParam::of("accel_delay"));
    let phys = spec.physical(&rig, omega_hz, &[0.0, 0.5, 0.15, delay_s]);
    let w0 = phys.omega0_rad_s();
    let simulate = |model: &pendulum_model::Model| -> Vec<f64> {
        let times: Vec<f64> = ov.simulated.iter().map(|s| w0 * (s.t_s - t0)).collect();
        let mut th = Vec::new();
        pendulum_model::integrate(
            model,
            &pendulum_model::SimOptions::with_tol(tol),
            0.0,
            [y0[0], y0[1] / w0],
            *times.last().unwrap(),
            times.iter().copied(),
            |s| {
                th.push(s.theta);
                std::ops::ControlFlow::Continue(())
            },
        )
        .unwrap();
        th
    };
    let fit_theta = simulate(&model_for(&phys));
    let no_delay = simulate(&pendulum_model::Model::new(phys.to_dimensionless()));
    // Over the first 10 s after t0 (later a chaotic run may amplify rounding).
    let n = ov.simulated.iter().filter(|s| s.t_s - t0 <= 10.0).count();
    let max_diff = |th: &[f64]| {
        ov.simulated[..n]
            .iter()
            .zip(th)
            .map(|(s, t)| (s.theta_rad - t).abs())
            .fold(0.0, f64::max)
    };
    let (d_fit, d_none) = (max_diff(&fit_theta), max_diff(&no_delay));
    eprintln!(
        "replay vs fit's model {d_fit:.3e} rad, vs the model without its delay {d_none:.3e} rad"
    );
    assert!(
        d_fit < 1e-9,
        "replay departs from the fit's simulation by {d_fit} rad"
    );
    // The delay matters on this run: dropping it (the old replay) is visibly different.
    assert!(d_none > 1e-3, "the delay changed nothing ({d_none} rad)");
}
