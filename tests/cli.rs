//! The binary's commands, end to end.

use crate::util::{pendulum, python_check, python_has, run};

#[test]
fn every_subcommand_has_help() {
    let out = run(&["--help"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    let subcommands: Vec<String> = text
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .filter(|c| c != "help")
        .collect();
    assert!(subcommands.contains(&"simulate".to_string()), "{text}");
    for c in subcommands {
        let out = run(&[&c, "--help"]);
        assert!(out.status.success(), "{c} --help");
        assert!(
            String::from_utf8_lossy(&out.stdout).contains("Usage"),
            "{c} --help"
        );
    }
}

/// The issue's own example command: Parquet with t, theta, theta_dot and the class in metadata.
#[test]
fn simulate_writes_parquet_with_steady_state() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("sim.parquet");
    let out = pendulum()
        .args([
            "simulate",
            "--param",
            "omega=1.585",
            "--param",
            "R=0.7",
            "--param",
            "lambda=0.126",
            "--param",
            "alpha=0",
            "--param",
            "beta=0.109",
            "--param",
            "M=0.007",
            "--theta0",
            "0.5",
            "--theta-dot0",
            "0",
            "--t-end",
            "300",
            "--dt-out",
            "0.05",
            "--out",
        ])
        .arg(&out_path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let line = String::from_utf8_lossy(&out.stdout);
    assert_eq!(line.lines().count(), 1, "one-line summary: {line}");

    use arrow_array::Float64Array;
    use parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder;
    let file = std::fs::File::open(&out_path).unwrap();
    let builder = ParquetRecordBatchReaderBuilder::try_new(file).unwrap();
    let kv: std::collections::HashMap<String, String> = builder
        .metadata()
        .file_metadata()
        .key_value_metadata()
        .unwrap()
        .iter()
        .map(|k| (k.key.clone(), k.value.clone().unwrap_or_default()))
        .collect();
    let class = kv["steady_state"].clone();
    assert!(
        [
            "rest",
            "oscillation",
            "rotation_ccw",
            "rotation_cw",
            "chaos"
        ]
        .contains(&class.as_str()),
        "{class}"
    );
    assert!(line.contains(&class), "summary names the class: {line}");
    let batch = builder
        .with_batch_size(1 << 20)
        .build()
        .unwrap()
        .next()
        .unwrap()
        .unwrap();
    assert_eq!(batch.num_rows(), 6001);
    let t = batch
        .column(0)
        .as_any()
        .downcast_ref::<Float64Array>()
        .unwrap();
    assert_eq!(t.value(0), 0.0);
    assert!((t.value(6000) - 300.0).abs() < 1e-9);
    let theta = batch
        .column(1)
        .as_any()
        .downcast_ref::<Float64Array>()
        .unwrap();
    assert_eq!(theta.value(0), 0.5);

    if python_has("pyarrow") {
        let spec = dir.path().join("spec.json");
        std::fs::write(
            &spec,
            format!(
                r#"{{"rows": 6001, "columns": {{"t": "double", "theta": "double", "theta_dot": "double"}},
                   "units": {{"theta": "rad"}}, "metadata": {{"steady_state": "{class}", "period": "{}"}},
                   "values": {{"t": [[0, 0.0]], "theta": [[0, 0.5]], "theta_dot": [[0, 0.0]]}}}}"#,
                kv["period"]
            ),
        )
        .unwrap();
        python_check("check_parquet.py", &[&out_path, &spec]);
    }
}

#[test]
fn bad_parameters_fail_with_a_clear_message() {
    let out = run(&["simulate", "--param", "omgea=1.5"]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("omgea") && err.contains("omega"), "{err}");
    let out = run(&["simulate", "--param", "beta=fast"]);
    assert!(String::from_utf8_lossy(&out.stderr).contains("a number"));
    let out = run(&["simulate", "--dt-out", "0"]);
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn demo_prints_the_study_contrast() {
    let out = run(&["demo", "--grid", "2", "--quick"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("reference") && text.contains("linear"),
        "{text}"
    );
}

/// Every stage config in pipelines/ parses, validates and builds; a misspelled key is an error
/// that names the line.
#[test]
fn pipeline_files_parse_and_build() {
    use pendulum_process::pipeline::PipelineConfig;
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("pipelines");
    for name in ["identify.toml", "validate.toml"] {
        let p = PipelineConfig::load(&dir.join(name)).unwrap();
        assert!(!p.stages.is_empty(), "{name}");
        for s in &p.stages {
            s.build().unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }
    let text = std::fs::read_to_string(dir.join("discover.toml")).unwrap();
    let d: pendulum_jobs::discover::DiscoverPipeline = toml::from_str(&text).unwrap();
    for s in &d.stages {
        s.build().unwrap();
    }
    let bad = "name = \"x\"\n[[stage]]\ntype = \"align\"\nfit_windw_s = 3.0\n";
    let e = PipelineConfig::from_toml(bad, std::path::Path::new("bad.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("bad.toml:") && e.contains("fit_windw_s"), "{e}");
}

/// Issue 13: `pendulum … | head` used to panic when `head` had what it wanted and closed the
/// pipe ("failed printing to stdout: Broken pipe", exit 101). A reader that goes away is not
/// the job's failure: the rest of the report is dropped quietly and the exit code is the job's
/// own (0 here; a failed job still exits 1, its error on stderr). The pipe is closed before
/// the binary writes anything (it prints after its work).
#[test]
fn issue_13_a_closed_stdout_is_no_panic() {
    use std::process::Stdio;
    for args in [
        &["demo", "--quick", "--grid", "2"][..],
        &["simulate", "--t-end", "100"][..],
    ] {
        let mut child = pendulum()
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
        assert!(stderr.is_empty(), "{args:?}: quiet, got {stderr}");
    }
    // A failing job keeps its failure.
    let mut child = pendulum()
        .args(["simulate", "--param", "nonsense=1"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("error:") && stderr.contains("nonsense"),
        "{stderr}"
    );
}
