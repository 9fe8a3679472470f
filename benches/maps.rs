//! Bifurcation sweep throughput: the benchmark, a 301-point ω sweep (0.5..3.5, step 0.01)
//! with 16 initial states each (4×4 grid), 300 transient + 50 recorded forcing periods, for the
//! study's two models, on 1 thread and on 2 threads; the target is under 30 s on 2 cores.
//!
//! Run: `cargo bench --bench maps` (`-- reference` or `-- linear` for one model). Prints wall
//! times, forcing periods simulated per second, the 1 → 2 thread speed-up, and (on Linux) the
//! CPU time the process got: CPU/wall below the thread count means other processes competed for
//! the cores (the load average printed first shows it too), and periods per CPU-second equal
//! across thread counts mean the parallel sweep costs nothing extra per core. Checks that both
//! thread counts give identical results. Asserts nothing about time.

use std::time::Instant;

use pendulum_maps::bifurcation::{self, BifurcationConfig};
use pendulum_maps::{IcSpec, Sweep};
use pendulum_model::Dimensionless;

fn study(name: &str) -> Dimensionless {
    let mut d = Dimensionless::conservative();
    d.r = 0.7;
    d.lambda = 0.126;
    match name {
        "reference" => {
            d.beta = 0.109;
            d.m_coulomb = 0.007;
        }
        _ => d.beta = 0.066,
    }
    d
}

/// CPU time of this process (all threads) in seconds, from /proc (Linux; USER_HZ = 100).
fn cpu_s() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = stat.rsplit_once(')')?.1;
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

fn main() {
    let models: Vec<String> = {
        let args: Vec<String> = std::env::args()
            .skip(1)
            .filter(|a| a == "reference" || a == "linear")
            .collect();
        if args.is_empty() {
            vec!["reference".into(), "linear".into()]
        } else {
            args
        }
    };
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!("ω 0.5..3.5 step 0.01 (301 values) × 16 starts (4×4), 300 + 50 periods; {cores} cores available; load average {}",
        load.split_whitespace().take(3).collect::<Vec<_>>().join(" "));
    println!("model        threads   wall [s]   periods/s   speed-up   CPU/wall   periods/CPU-s   target (< 30 s on 2 cores)");
    for name in &models {
        let mut cfg = BifurcationConfig::new(
            study(name),
            Sweep::parse("omega=0.5:3.5:0.01").expect("sweep"),
            IcSpec::parse_grid("4x4", 3.0).expect("grid").starts(),
        );
        cfg.transient_periods = 300;
        cfg.record_periods = 50;
        let periods = cfg.tasks() as f64 * f64::from(cfg.transient_periods + cfg.record_periods);
        let mut t1 = None;
        let mut first = None;
        for threads in [1usize, 2] {
            cfg.threads = Some(threads);
            let cpu0 = cpu_s();
            let start = Instant::now();
            let result = bifurcation::run(&cfg, &|_| {}).expect("sweep runs");
            let wall = start.elapsed().as_secs_f64();
            let (cpu, per_cpu) = match (cpu0, cpu_s()) {
                (Some(a), Some(b)) if b > a => (
                    format!("{:.2}", (b - a) / wall),
                    format!("{:.0}", periods / (b - a)),
                ),
                _ => ("n/a".to_string(), "n/a".to_string()),
            };
            let speedup = t1.map_or(1.0, |t: f64| t / wall);
            t1.get_or_insert(wall);
            println!(
                "{name:<12} {threads:>7} {wall:>10.2} {:>11.0} {speedup:>10.2} {cpu:>10} {per_cpu:>15}   {}",
                periods / wall,
                if threads == 2 {
                    if wall < 30.0 {
                        "met"
                    } else {
                        "MISSED"
                    }
                } else {
                    ""
                }
            );
            match &first {
                None => first = Some(result.outcomes),
                Some(f) => assert!(
                    *f == result.outcomes,
                    "1 and 2 threads gave different results"
                ),
            }
        }
    }
}
