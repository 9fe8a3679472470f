//! `discover` on an 8-run twin campaign (5 identify + 3 validate, both formats, realistic
//! sensors) with a hidden constant dry torque, with the built-in pipeline (base fit to its
//! default generation cap), timed on all cores. `cargo bench --bench discover`. Prints only:
//! the time, and its ratio to a baseline measured in the same run, `identify` on the same
//! campaign with the same model and generation cap (the base fit discover starts from), so the
//! ratio is discover's own cost on top of it whatever the machine.

use std::time::Instant;

use pendulum_discover::Base;
use pendulum_jobs::discover::{run, DiscoverJob};
use pendulum_rig::twin::{synthesize, TwinCase};

fn main() {
    let case = pendulum_jobs::demo::discovery_campaign(
        "bench",
        3,
        0.0,
        0.5,
        0.15,
        "coulomb_constant_t_c_nm = 0.01",
    );
    let dir = tempfile::tempdir().expect("tempdir");
    let case = TwinCase::from_toml(&case, std::path::Path::new("bench.toml")).expect("case");
    synthesize(&case, &dir.path().join("c")).expect("twin");
    let t = Instant::now();
    let s = run(&DiscoverJob {
        input: dir.path().join("c"),
        out: dir.path().join("out"),
        base: Base::Reference,
        pipeline: None,
        generations: None,
        seed: None,
        progress: false,
    })
    .expect("discover");
    let t_discover = t.elapsed().as_secs_f64();
    let t = Instant::now();
    pendulum_jobs::identify::run(&pendulum_jobs::identify::IdentifyJob {
        input: dir.path().join("c"),
        out: dir.path().join("identify"),
        pipeline: None,
        overrides: pendulum_jobs::identify::FitOverrides {
            model: Some("reference".into()),
            // discover.toml's cap.
            generations: Some(400),
            ..Default::default()
        },
        progress: false,
        free_segments: false,
    })
    .expect("identify");
    let t_identify = t.elapsed().as_secs_f64();
    println!(
        "discover, 8 runs, {} threads: {t_discover:.1} s; baseline identify (same model and cap): {t_identify:.1} s; ratio {:.2}",
        rayon::current_num_threads(),
        t_discover / t_identify
    );
    let accepted = s.discovery.accepted();
    println!("accepted: {accepted:?} (hidden: coulomb_constant 0.01 N·m)");
}
