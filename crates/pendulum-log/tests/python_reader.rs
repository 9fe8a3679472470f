//! The official Python `mcap` reader (an independent client, like Foxglove) reads our run files:
//! runs `tests/python/check_mcap.py` on a written run and its expected content.
//!
//! Skips loudly when `python3` with the `mcap` package is missing, unless
//! `PENDULUM_REQUIRE_PYTHON=1` (CI sets it), in which case that is a failure.

mod common;

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

use pendulum_log::{
    parse_rfc3339_utc_ns, read_run, schemas, RunLogOptions, TOPIC_ACCEL, TOPIC_ENCODER,
    TOPIC_INGEST_STATS, TOPIC_SIMULATED,
};
use serde::Serialize;
use serde_json::{json, Value};

fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/python/check_mcap.py")
}

/// True if the check can run; false (after a loud message) if it must be skipped.
fn python_available() -> bool {
    let ok = Command::new("python3")
        .args(["-c", "import mcap"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !ok {
        if std::env::var("PENDULUM_REQUIRE_PYTHON").as_deref() == Ok("1") {
            panic!(
                "PENDULUM_REQUIRE_PYTHON=1 but `python3 -c 'import mcap'` fails: pip install mcap"
            );
        }
        // Written to the real stderr, not via eprintln!, which the test harness captures.
        let _ = std::io::stderr().write_all(
            b"\n==================== SKIP ====================\n\
              python_reader: python3 with the `mcap` package is not available\n\
              (pip install mcap; set PENDULUM_REQUIRE_PYTHON=1 to make this fatal)\n\
              ==============================================\n\n",
        );
    }
    ok
}

/// First, last and every `stride`-th message with its log time.
fn samples<T: Serialize>(msgs: &[T], log_times: &[u64], stride: usize) -> Vec<Value> {
    let mut idx: Vec<usize> = (0..msgs.len()).step_by(stride).collect();
    if let Some(last) = msgs.len().checked_sub(1) {
        idx.push(last);
    }
    idx.dedup();
    idx.into_iter()
        .map(|i| json!({"index": i, "log_time": log_times[i], "data": msgs[i]}))
        .collect()
}

fn run_check(mcap: &Path, expected: &Value, dir: &Path) -> (bool, String) {
    let expected_path = dir.join("expected.json");
    std::fs::write(&expected_path, serde_json::to_vec_pretty(expected).unwrap()).unwrap();
    let out = Command::new("python3")
        .arg(script())
        .arg(mcap)
        .arg(&expected_path)
        .output()
        .expect("run python3");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out.status.success(), text)
}

#[test]
fn python_mcap_reader_agrees() {
    if !python_available() {
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r01.mcap");
    let fx = common::fixture(3000, 300);
    let start_ns = parse_rfc3339_utc_ns(common::STARTED).unwrap();
    let opts = RunLogOptions::new()
        .library("pendulum/0.1")
        .chunk_size(64 * 1024)
        .start_ns(Some(start_ns));
    common::write(&fx, &path, &opts).unwrap();

    // The expected values come from what was written; log times from the documented formula.
    let enc_t: Vec<u64> = fx
        .encoder
        .iter()
        .map(|m| start_ns + (m.t_us - common::FIRST_T_US) * 1000)
        .collect();
    let acc_t: Vec<u64> = fx
        .accel
        .iter()
        .map(|m| start_ns + (m.t_us - common::FIRST_T_US) * 1000)
        .collect();
    let sim_t: Vec<u64> = fx
        .simulated
        .iter()
        .map(|m| start_ns + (m.t_s * 1e9).round() as u64)
        .collect();
    // And the Rust reader agrees with them.
    let run = read_run(&path).unwrap();
    assert_eq!(run.encoder_log_time_ns, enc_t);
    assert_eq!(run.accel_log_time_ns, acc_t);
    assert_eq!(run.simulated_log_time_ns, sim_t);

    let expected = json!({
        "library": "pendulum/0.1",
        "topics": {
            TOPIC_ENCODER: {
                "count": fx.encoder.len(),
                "schema_name": schemas::ENCODER_NAME,
                "messages": samples(&fx.encoder, &enc_t, 97),
            },
            TOPIC_ACCEL: {
                "count": fx.accel.len(),
                "schema_name": schemas::ACCEL_NAME,
                "messages": samples(&fx.accel, &acc_t, 41),
            },
            TOPIC_SIMULATED: {
                "count": fx.simulated.len(),
                "schema_name": schemas::SIMULATED_NAME,
                "messages": samples(&fx.simulated, &sim_t, 29),
            },
            TOPIC_INGEST_STATS: {
                "count": 1,
                "schema_name": schemas::INGEST_STATS_NAME,
                "messages": [{"index": 0, "log_time": start_ns, "data": fx.stats}],
            },
        },
        "metadata": fx.metadata,
    });
    let (ok, text) = run_check(&path, &expected, dir.path());
    println!("{text}");
    assert!(ok, "check_mcap.py failed:\n{text}");

    // The checker is not vacuous: a wrong expected value fails it...
    let mut wrong = expected.clone();
    wrong["topics"][TOPIC_ENCODER]["messages"][1]["data"]["theta_rad"] = json!(123.456);
    let (ok, text) = run_check(&path, &wrong, dir.path());
    assert!(
        !ok && text.contains("FAIL /encoder[97]: fields equal"),
        "{text}"
    );

    // ...and so does a corrupt chunk (validate_crcs=True).
    let mut bytes = std::fs::read(&path).unwrap();
    let (start, len) = common::first_chunk_records(&bytes).unwrap();
    bytes[start + len / 2] ^= 0x20;
    let bad = dir.path().join("bad.mcap");
    std::fs::write(&bad, &bytes).unwrap();
    let (ok, text) = run_check(&bad, &expected, dir.path());
    assert!(!ok && text.contains("FAIL read"), "{text}");
    println!("corrupt file: {}", text.lines().next().unwrap_or(""));
}
