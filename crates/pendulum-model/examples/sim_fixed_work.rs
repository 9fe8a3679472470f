//! Fixed-work simulator harness for instruction counts: N integrations of 20 forcing periods on
//! an attractor of the simulator bench's model (tolerance 1e-8, output at the end only).
//!
//! Run: `cargo run --release -p pendulum-model --example sim_fixed_work -- CASE TERMS N` with
//! CASE `rotating` | `oscillating`, TERMS `plain` | `gen` | `stribeck`, N integrations. Under
//! `valgrind --tool=callgrind`, (instructions at N − instructions at 0) / N is the cost of one
//! integration: the setup (finding the attractor) cancels, and the count does not depend on the
//! machine's load as a time does. The extra terms are set through serde so that the same file
//! builds on commits that predate them (there TERMS other than `plain` exits with an error).
//! Prints the end state's bits and the step counts, so two builds can be checked to agree.

use std::hint::black_box;
use std::ops::ControlFlow;

use pendulum_model::sim::integrate;
use pendulum_model::steady::steady_state_of;
use pendulum_model::{ClassifyOptions, Dimensionless, Model, SimOptions, SteadyClass};

/// The end state and step count of one integration from y0 over [0, t_end].
fn end_state(model: &Model, tol: f64, y0: [f64; 2], t_end: f64) -> ([f64; 2], u64) {
    let mut out = [0.0; 2];
    let stats = integrate(
        model,
        &SimOptions::with_tol(tol),
        0.0,
        y0,
        t_end,
        [t_end],
        |s| {
            out = [s.theta, s.theta_dot];
            ControlFlow::Continue(())
        },
    )
    .expect("integration");
    (out, stats.steps)
}

/// A state on the attractor of the wanted kind, from the bench's grid of starts.
fn attractor(model: &Model, want: fn(SteadyClass) -> bool) -> Option<[f64; 2]> {
    for i in 0..12 {
        for j in 0..6 {
            let y0 = [-3.0 + 0.5 * i as f64, -3.0 + j as f64];
            let (s, th, w) = steady_state_of(
                model,
                &SimOptions::with_tol(1e-10),
                y0,
                0.0,
                300,
                8,
                &ClassifyOptions::default(),
            )
            .ok()?;
            if want(s.class) {
                return Some([th[0].rem_euclid(2.0 * std::f64::consts::PI), w[0]]);
            }
        }
    }
    None
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        eprintln!("usage: sim_fixed_work rotating|oscillating plain|gen|stribeck N");
        std::process::exit(2);
    }
    let n: u64 = args[3].parse().expect("N: a count");
    // The simulator bench's model.
    let mut d = Dimensionless::conservative();
    d.r = 0.7;
    d.lambda = 0.126;
    d.beta = 0.109;
    d.m_coulomb = 0.007;
    let want: fn(SteadyClass) -> bool = match args[1].as_str() {
        "rotating" => {
            d.omega = 1.585;
            |c| c.is_rotation()
        }
        "oscillating" => {
            d.omega = 2.0;
            |c| c == SteadyClass::Oscillation
        }
        other => panic!("unknown case {other}"),
    };
    // A generator whose dead band the motion crosses (w below the peak speeds), or a breakaway.
    let extra: &[(&str, f64)] = match args[2].as_str() {
        "plain" => &[],
        "gen" => &[("gen_c", 0.02), ("gen_w", 0.5)],
        "stribeck" => &[("s_break", 0.005), ("v_break", 0.3)],
        other => panic!("unknown terms {other}"),
    };
    if !extra.is_empty() {
        let mut v = serde_json::to_value(d).expect("serialise");
        for (k, x) in extra {
            v[*k] = serde_json::json!(x);
        }
        d = match serde_json::from_value(v) {
            Ok(d) => d,
            Err(e) => {
                eprintln!("this build has no {}: {e}", args[2]);
                std::process::exit(3);
            }
        };
    }
    let model = Model::new(d);
    let Some(y0) = attractor(&model, want) else {
        eprintln!("no {} attractor on the start grid", args[1]);
        std::process::exit(4);
    };
    let t_end = 20.0 * d.forcing_period();
    let mut last = ([0.0; 2], 0);
    for _ in 0..n {
        last = black_box(end_state(&model, 1e-8, black_box(y0), t_end));
    }
    println!(
        "{} {} N={n} y0=[{:#018x}, {:#018x}] end=[{:#018x}, {:#018x}] steps={}",
        args[1],
        args[2],
        y0[0].to_bits(),
        y0[1].to_bits(),
        last.0[0].to_bits(),
        last.0[1].to_bits(),
        last.1
    );
}
