//! `discover` on an 8-run twin campaign (5 identify + 3 validate, both formats, realistic
//! sensors) with a hidden constant dry torque, with the built-in pipeline (base fit to its
//! default generation cap), timed on all cores. `cargo bench --bench discover`. Prints only.

use std::time::Instant;

use pendulum_discover::Base;
use pendulum_jobs::discover::{run, DiscoverJob};
use pendulum_rig::twin::{synthesize, TwinCase};

fn main() {
    let runs = [
        ("r01", 1.30, "identify", "serial", 0.8, 0.0),
        ("r02", 1.54, "identify", "sd", 1.5, 0.0),
        ("r03", 1.65, "identify", "serial", 0.5, 0.0),
        ("r04", 1.75, "identify", "sd", 1.0, -9.0),
        ("r05", 1.75, "identify", "serial", 0.5, 0.0),
        ("v01", 1.54, "validate", "sd", 1.2, 0.0),
        ("v02", 1.65, "validate", "serial", 1.5, 0.0),
        ("v03", 1.30, "validate", "sd", 0.6, 3.0),
    ];
    let mut case = String::from(
        "name = \"bench\"\nseed = 3\n[rig]\nm_kg = 1.46\nl_m = 0.265\ncrank_r_m = 0.0725\nrod_L_m = 0.575\nr_b_m = 0.01225\n[truth]\nb_n_s_m = 0.5\nmu = 0.15\n[truth.effects]\ncoulomb_constant_t_c_nm = 0.01\n",
    );
    for (id, om, role, fmt, th, thd) in runs {
        case += &format!("[[run]]\nid = \"{id}\"\nomega_hz = {om}\nrole = \"{role}\"\nformat = \"{fmt}\"\ntheta0_rad = {th}\ntheta_dot0_rad_s = {thd}\nfree_s = 4\nforced_s = 30\n");
    }
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
    println!(
        "discover, 8 runs, {} threads: {:.1} s",
        rayon::current_num_threads(),
        t.elapsed().as_secs_f64()
    );
    let accepted: Vec<&str> = s
        .discovery
        .rows
        .iter()
        .filter(|r| r.accepted)
        .map(|r| r.effect.as_str())
        .collect();
    println!("accepted: {accepted:?} (hidden: coulomb_constant 0.01 N·m)");
}
