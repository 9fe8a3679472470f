//! Harvester design and power on the maps (issue 15 items 2 and 3): `pendulum design` finds the
//! load that a brute-force evaluation confirms, reports no generator power without a generator,
//! refuses bad input, and merges its shards to the one-machine bytes; `zones` and `bifurcate`
//! report powers that balance over whole periods.

use std::path::{Path, PathBuf};

use clap::Parser;
use pendulum_jobs::design::DesignArgs;
use pendulum_jobs::merge::{MergeArgs, Ran};
use pendulum_maps::shard::read_columns;
use pendulum_model::power::mean_powers;
use pendulum_model::{Model, ParamSpec, Physical, SimOptions};
use pendulum_report::{Column, ColumnData, TableOptions};

#[derive(Parser)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(clap::Subcommand)]
enum Cmd {
    Design(Box<DesignArgs>),
    Merge(MergeArgs),
}

/// A params.parquet as `pendulum identify` writes it (the columns design reads): the study's
/// rig with its representative dry-friction fit and the classic linear model.
fn params_file(dir: &Path) -> PathBuf {
    let path = dir.join("params.parquet");
    let f = |name: &str, v: [f64; 2]| Column::f64(name, "1", v.to_vec());
    let cols = vec![
        Column::new(
            "model",
            ColumnData::Str(vec!["reference".into(), "linear".into()]),
        ),
        f("m_kg", [1.46, 1.46]),
        f("l_m", [0.265, 0.265]),
        f("crank_r_m", [0.0725, 0.0725]),
        f("rod_L_m", [0.575, 0.575]),
        f("r_b_m", [0.01225, 0.01225]),
        f("g_m_s2", [9.81, 9.81]),
        f("omega_hz", [1.54, 1.54]),
        f("a", [0.0, 0.0]),
        f("b", [0.5, 0.3]),
        f("mu", [0.15, 0.0]),
        f("f_obj", [1.0, 2.0]),
    ];
    TableOptions::new().write(&path, &cols).unwrap();
    path
}

fn run(argv: &[String]) -> Result<String, pendulum_jobs::JobError> {
    let cli = Cli::try_parse_from(std::iter::once("pendulum".to_string()).chain(argv.to_vec()))
        .unwrap_or_else(|e| panic!("{argv:?}: {e}"));
    match cli.cmd {
        Cmd::Design(a) => pendulum_jobs::design::run(&a).map(|r| match r {
            Ran::Full(s) => s.to_string(),
            Ran::Shard(s) => s.to_string(),
        }),
        Cmd::Merge(a) => pendulum_jobs::merge::run(&a).map(|s| s.to_string()),
    }
}

fn argv(params: &Path, extra: &[&str]) -> Vec<String> {
    ["design", "--params", params.to_str().unwrap(), "--quiet"]
        .iter()
        .chain(extra)
        .map(|s| s.to_string())
        .collect()
}

/// The design search of the tests: one operating point where the generator load decides
/// everything, loads on both sides of the optimum, two starts (one spinning, one hanging).
const SEARCH: &[&str] = &[
    "--omega-hz",
    "2.36",
    "--crank-r-m",
    "0.1065",
    "--c-g",
    "0,0.04,0.08,0.16,0.32,0.64",
    "--omega-d",
    "0",
    "--ic",
    "0,2.5",
    "--ic",
    "0.5,0",
    "--transient",
    "60",
    "--record",
    "16",
];

fn f64_col(cols: &[Column], name: &str) -> Vec<f64> {
    match &cols.iter().find(|c| c.name == name).unwrap().data {
        ColumnData::F64(v) => v.clone(),
        other => panic!("{name}: {other:?}"),
    }
}

/// The mean power into the load over `starts`, W, evaluated apart from the design code: the
/// model resolved from `--param`-style assignments (the generator through the catalogue) and
/// `mean_powers` integrated from t = 0 through the transient (design restarts at the first
/// Poincaré point), over the same whole periods.
fn brute_force_load_w(c_g: f64, starts: &[[f64; 2]], transient: u32, record: u32) -> f64 {
    let a: Vec<String> = [
        "m_kg=1.46",
        "l_m=0.265",
        "rod_L_m=0.575",
        "r_b_m=0.01225",
        "g_m_s2=9.81",
        "a=0",
        "b=0.5",
        "mu=0.15",
        "omega_hz=2.36",
        "crank_r_m=0.1065",
    ]
    .iter()
    .map(|s| s.to_string())
    .chain([
        format!("generator_rectified.c_g={c_g}"),
        "generator_rectified.omega_d=0".to_string(),
    ])
    .collect();
    let (phys, d) = ParamSpec::parse(&a)
        .unwrap()
        .resolve(&Physical::default())
        .unwrap();
    let model = Model::new(d);
    let period = d.forcing_period();
    let opts = SimOptions::with_tol(1e-8);
    let total: f64 = starts
        .iter()
        .map(|&y0| {
            mean_powers(
                &model,
                &opts,
                0.0,
                y0,
                f64::from(transient) * period,
                f64::from(transient + record) * period,
            )
            .unwrap()
            .load
        })
        .sum();
    total / starts.len() as f64 * phys.power_scale_w()
}

/// The reported optimum is the load a brute-force evaluation of it and of its neighbouring
/// loads (each side) confirms: its power is the brute-force one, and both neighbours deliver
/// less. With c_g = 0 the generator takes and delivers exactly nothing; the balance holds in
/// every cell; the summary says which load, speed, watts and how sure.
#[test]
fn issue_15_design_optimum_beats_its_neighbouring_loads_by_brute_force() {
    let dir = tempfile::tempdir().unwrap();
    let params = params_file(dir.path());
    let out = dir.path().join("out");
    let text = run(&argv(
        &params,
        &[
            SEARCH,
            &["--model", "reference", "--out", out.to_str().unwrap()],
        ]
        .concat(),
    ))
    .unwrap();
    assert!(text.contains("reference: c_g = "), "{text}");
    let cols = read_columns(&out.join("design.parquet")).unwrap();
    let c_g = f64_col(&cols, "c_g_nm_s_rad");
    let load = f64_col(&cols, "mean_power_load_w");
    let gen = f64_col(&cols, "mean_power_generator_w");
    let best = match &cols.iter().find(|c| c.name == "best").unwrap().data {
        ColumnData::Bool(v) => v.iter().position(|b| *b).unwrap(),
        other => panic!("{other:?}"),
    };
    // An interior optimum (else there would be no neighbour on one side).
    assert!(
        best > 0 && best + 1 < c_g.len(),
        "optimum at {best}: {load:?}"
    );
    let starts = [[0.0, 2.5], [0.5, 0.0]];
    let at_best = brute_force_load_w(c_g[best], &starts, 60, 16);
    assert!(
        (at_best - load[best]).abs() < 1e-4 * at_best,
        "design {} W, brute force {at_best} W",
        load[best]
    );
    for nb in [best - 1, best + 1] {
        let p = brute_force_load_w(c_g[nb], &starts, 60, 16);
        assert!(
            p < at_best,
            "neighbouring load c_g = {} gives {p} W ≥ the optimum's {at_best} W at c_g = {}",
            c_g[nb],
            c_g[best]
        );
    }
    // No generator, no generator power: exactly zero, not just small.
    assert_eq!(c_g[0], 0.0);
    assert_eq!((gen[0], load[0]), (0.0, 0.0));
    assert!(load[best] > 1.0, "{load:?}");
    // Input = losses + stored in every cell (the cells' means of per-start balances).
    let base = f64_col(&cols, "mean_power_base_w");
    let stored = f64_col(&cols, "mean_power_stored_w");
    let lost: Vec<f64> = (0..base.len())
        .map(|r| {
            ["viscous", "quadratic", "dry", "generator"]
                .iter()
                .map(|k| f64_col(&cols, &format!("mean_power_{k}_w"))[r])
                .sum()
        })
        .collect();
    for r in 0..base.len() {
        assert!(
            (base[r] - lost[r] - stored[r]).abs() <= 2e-5 * base[r].abs().max(1e-3),
            "cell {r}: base {} vs lost {} + stored {}",
            base[r],
            lost[r],
            stored[r]
        );
    }
    let md = std::fs::read_to_string(out.join("design.md")).unwrap();
    assert!(
        md.contains("this many watts") && md.contains("Ω = 2.36 Hz"),
        "{md}"
    );
}

/// `design --shard i/n` then `merge`: the one-machine run's files, byte for byte (one process,
/// one invocation id), for two models and a shard count that does not divide the cells; the
/// loads given electrically.
#[test]
fn issue_15_design_shards_merge_to_the_one_machine_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let params = params_file(dir.path());
    let search: &[&str] = &[
        "--omega-hz",
        "1.54,2.36",
        "--crank-r-m",
        "0.0725,0.1065",
        "--k-e",
        "0.3",
        "--v-d",
        "0,1.4",
        "--r-ohm",
        "2,5",
        "--ic",
        "0,2.5",
        "--ic",
        "0.5,0",
        "--transient",
        "40",
        "--record",
        "8",
        "--compare-model",
        "linear",
    ];
    let one = dir.path().join("one");
    let sharded = dir.path().join("sharded");
    run(&argv(
        &params,
        &[search, &["--out", one.to_str().unwrap()]].concat(),
    ))
    .unwrap();
    let n = 3;
    for i in 0..n {
        let t = run(&argv(
            &params,
            &[
                search,
                &[
                    "--shard",
                    &format!("{i}/{n}"),
                    "--out",
                    sharded.to_str().unwrap(),
                ],
            ]
            .concat(),
        ))
        .unwrap();
        assert!(t.contains(&format!("design shard {i}/{n}")), "{t}");
    }
    // Shards write only their folders.
    let top: Vec<String> = std::fs::read_dir(&sharded)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    assert!(top.iter().all(|n| n.starts_with("shard=")), "{top:?}");
    let merged = run(&["merge".to_string(), sharded.display().to_string()]).unwrap();
    assert!(merged.contains("merged 3 shards"), "{merged}");
    for name in [
        "design.parquet",
        "design.md",
        "design.png",
        "design_map.png",
    ] {
        let a = std::fs::read(one.join(name)).unwrap();
        let b = std::fs::read(sharded.join(name)).unwrap();
        assert!(a == b, "{name} differs after the merge");
    }
    // Not vacuous: 16 cells (2 Ω × 2 r × 4 loads) × 2 models, one best per model.
    let cols = read_columns(&one.join("design.parquet")).unwrap();
    let best = match &cols.iter().find(|c| c.name == "best").unwrap().data {
        ColumnData::Bool(v) => v.clone(),
        other => panic!("{other:?}"),
    };
    assert_eq!(best.len(), 32);
    assert_eq!(best.iter().filter(|b| **b).count(), 2);
    // The electrical form reached the table: c_g = k_e²/R.
    let (ke, r, cg) = (
        f64_col(&cols, "k_e_v_s_rad"),
        f64_col(&cols, "r_ohm"),
        f64_col(&cols, "c_g_nm_s_rad"),
    );
    assert!((0..32).all(|i| (cg[i] - ke[i] * ke[i] / r[i]).abs() < 1e-15));
}

/// Bad input is refused before any work, naming what is wrong, and nothing is written.
#[test]
fn issue_15_design_refuses_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let params = params_file(dir.path());
    let out = dir.path().join("out");
    let o = out.to_str().unwrap();
    for (extra, expect) in [
        (vec!["--c-g", "-0.01"], "c_g"),
        (vec!["--omega-hz", "0"], "omega_hz"),
        (vec!["--omega-hz", "1:2:0"], "step"),
        (vec!["--crank-r-m", "0.6"], "crank_r_m"),
        (vec!["--model", "quadratic"], "reference, linear"),
        (vec!["--k-e", "0", "--v-d", "1", "--r-ohm", "5"], "k_e"),
        (vec!["--shard", "200/300"], "only"),
        (vec!["--record", "1"], "record"),
    ] {
        let e = run(&argv(&params, &[&extra[..], &["--out", o]].concat()))
            .unwrap_err()
            .to_string();
        assert!(e.contains(expect), "{extra:?}: {e}");
        assert!(!out.exists(), "{extra:?} wrote {}", out.display());
    }
    let e = run(&argv(&dir.path().join("nope.parquet"), &["--out", o]))
        .unwrap_err()
        .to_string();
    assert!(e.contains("nope.parquet"), "{e}");
}

/// `zones` with a generator: per cell, the mean input power equals the mean dissipated power
/// plus the stored energy's rate, the generator's load + diodes is its whole power, and the
/// power maps and the two models' power gap are drawn; `bifurcate` per start balances too.
#[test]
fn issue_15_zones_and_bifurcate_powers_balance_per_cell_and_start() {
    use pendulum_maps::bifurcation::{self, BifurcationConfig};
    use pendulum_maps::zones::{self, ZoneConfig};
    use pendulum_maps::Sweep;
    let base = |extra: &[&str]| {
        let a: Vec<String> = ["omega_hz=1.54", "b=0.5", "mu=0.15"]
            .iter()
            .chain(extra)
            .map(|s| s.to_string())
            .collect();
        ParamSpec::parse(&a)
            .unwrap()
            .resolve(&Physical::default())
            .unwrap()
    };
    let (phys, with_gen) = base(&[
        "generator_rectified.c_g=0.02",
        "generator_rectified.omega_d=2",
    ]);
    let (_, without) = base(&[]);
    let mut cfg = ZoneConfig::new(
        Sweep::parse("omega=1.4:2.2:0.4").unwrap(),
        Sweep::parse("R=0.6,0.9").unwrap(),
        vec![[0.0, 2.5], [0.5, 0.0]],
    );
    cfg.transient_periods = 60;
    cfg.record_periods = 16;
    cfg.power_scale_w = phys.power_scale_w();
    let maps = zones::run(
        &[
            ("generator".to_string(), with_gen),
            ("none".to_string(), without),
        ],
        &cfg,
        &|_| {},
    )
    .unwrap();
    let mut some_load = false;
    for c in &maps[0].cells {
        let p = &c.mean_power_w;
        assert!(
            (p.base - p.dissipated() - p.stored).abs() <= 2e-5 * p.base.abs().max(1e-3),
            "{c:?}"
        );
        assert!((p.load + p.diodes - p.generator).abs() <= 1e-9 * p.generator.max(1e-9));
        some_load |= p.load > 0.1;
    }
    assert!(some_load, "no cell delivered power: {:?}", maps[0].cells);
    assert!(maps[1]
        .cells
        .iter()
        .all(|c| c.mean_power_w.generator == 0.0 && c.mean_power_w.load == 0.0));
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("gap.png");
    let (gap_load, _) = zones::plot_power_comparison(&maps[0], &maps[1], &png).unwrap();
    assert!(gap_load > 0.1 && png.exists());
    maps[0].plot_power(&dir.path().join("p.png")).unwrap();

    let mut bcfg = BifurcationConfig::new(
        with_gen,
        Sweep::parse("omega=1.5,2.0").unwrap(),
        vec![[0.0, 2.5], [0.5, 0.0]],
    );
    bcfg.transient_periods = 60;
    bcfg.record_periods = 16;
    bcfg.power_scale_w = phys.power_scale_w();
    let b = bifurcation::run(&bcfg, &|_| {}).unwrap();
    for o in &b.outcomes {
        let p = &o.power_w;
        assert!(
            (p.base - p.dissipated() - p.stored).abs() <= 2e-5 * p.base.abs().max(1e-3),
            "{o:?}"
        );
        if o.steady.class.is_rotation() {
            assert!(p.generator > 0.0 && p.base > 0.0, "{o:?}");
        }
    }
    // The table carries them per start, in W.
    let cols = b.columns();
    let c = cols.iter().find(|c| c.name == "mean_power_load_w").unwrap();
    assert_eq!(c.unit.as_deref(), Some("W"));
}
