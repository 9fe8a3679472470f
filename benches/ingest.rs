//! Ingest throughput (issue 3, item 8): MB of raw capture per second and messages per second on
//! one core, for both capture formats, (a) the streaming capture reader alone and (b) the full
//! ingest of one run to MCAP (reader + JSON + zstd chunks + atomic rename).
//!
//! The captures are made once by the digital twin with its default (realistic) sensor model:
//! a few minutes of a run each, with noise, jitter, serial glitches and SD corruption.
//!
//! Run: `cargo bench --bench ingest`. Prints a table; asserts nothing about time.

use std::hint::black_box;
use std::path::Path;
use std::time::Instant;

use pendulum_jobs::ingest;
use pendulum_rig::twin::{synthesize, SensorModel, TwinCase};
use pendulum_rig::{CaptureReader, ReadOptions};

const CASE: &str = r#"
name = "bench"
seed = 42

[rig]
m_kg = 1.46
l_m = 0.265
crank_r_m = 0.0725
rod_L_m = 0.575
r_b_m = 0.01225

[truth]
b_n_s_m = 0.5
mu = 0.15

[[run]]
id = "serial"
omega_hz = 1.54
role = "identify"
format = "serial"
theta0_rad = 0.8
free_s = 4
forced_s = 236

[[run]]
id = "sd"
omega_hz = 1.54
role = "identify"
format = "sd"
theta0_rad = 0.8
free_s = 4
forced_s = 236
"#;

/// Best of `reps` timings of `f` (s), after one warm-up call.
fn best_of<T>(reps: usize, mut f: impl FnMut() -> T) -> f64 {
    black_box(f());
    (0..reps)
        .map(|_| {
            let t = Instant::now();
            black_box(f());
            t.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Reads every sample of a capture; returns the number of samples.
fn read_all(path: &Path) -> u64 {
    let mut r = CaptureReader::open(path, ReadOptions::default()).expect("capture opens");
    let mut n = 0u64;
    while let Some(s) = r.next_sample().expect("read") {
        black_box(s);
        n += 1;
    }
    n
}

fn main() {
    let dir = tempfile::tempdir().expect("temp dir");
    let camp = dir.path().join("campaign");
    let mut case = TwinCase::from_toml(CASE, Path::new("bench.toml")).expect("case");
    case.sensors = SensorModel::default();
    let t = Instant::now();
    let truth = synthesize(&case, &camp).expect("twin").truth_data;
    println!(
        "twin: {} runs of {} s written in {:.2} s",
        truth.runs.len(),
        case.runs[0].free_s + case.runs[0].forced_s,
        t.elapsed().as_secs_f64()
    );

    // One campaign per format, so that a full ingest job runs exactly one run (one core: rayon
    // has nothing to run in parallel).
    let mut rows = Vec::new();
    for r in &truth.runs {
        let single = dir.path().join(format!("only-{}", r.id));
        std::fs::create_dir_all(&single).expect("dir");
        let src = camp.join(&r.file);
        std::fs::copy(&src, single.join(&r.file)).expect("copy");
        let toml = std::fs::read_to_string(camp.join("campaign.toml")).expect("campaign");
        // Keep the header and this run's table only.
        let head_end = toml.find("[[run]]").expect("runs");
        let table = toml[head_end..]
            .split("[[run]]")
            .find(|t| t.contains(&format!("id = \"{}\"", r.id)))
            .expect("run table");
        std::fs::write(
            single.join("campaign.toml"),
            format!("{}[[run]]{}", &toml[..head_end], table),
        )
        .expect("write campaign");

        let mb = std::fs::metadata(&src).expect("stat").len() as f64 / 1e6;
        let samples = read_all(&src);
        let reps = 5;
        let t_read = best_of(reps, || read_all(&src));
        let out = dir.path().join(format!("out-{}", r.id));
        let t_ingest = best_of(reps, || {
            let s = ingest::run(&single, &out, false).expect("ingest");
            assert_eq!(s.failed(), 0);
            s
        });
        let mcap_mb = std::fs::metadata(out.join(format!("{}.mcap", r.id)))
            .expect("mcap")
            .len() as f64
            / 1e6;
        rows.push((r.id.clone(), mb, samples, t_read, t_ingest, mcap_mb));
    }

    println!();
    println!(
        "{:<7} {:>8} {:>9} | {:>14} {:>14} | {:>14} {:>14} {:>8}",
        "format",
        "raw MB",
        "messages",
        "read MB/s",
        "read msg/s",
        "ingest MB/s",
        "ingest msg/s",
        "MCAP MB"
    );
    for (id, mb, n, t_read, t_ingest, mcap_mb) in rows {
        println!(
            "{:<7} {:>8.2} {:>9} | {:>14.1} {:>14.0} | {:>14.1} {:>14.0} {:>8.2}",
            id,
            mb,
            n,
            mb / t_read,
            n as f64 / t_read,
            mb / t_ingest,
            n as f64 / t_ingest,
            mcap_mb
        );
    }
    println!(
        "\nOne core each (a single run per ingest job); best of 5 after a warm-up. The full ingest \
         reads the capture twice (a short first pass finds the earliest stamp) and writes JSON \
         messages in zstd chunks."
    );
}
