//! Simulator throughput: forcing periods simulated per second on one core at tolerance 1e-8, for
//! a rotating and an oscillating steady state, next to a plain fixed-step RK4 loop whose step is
//! tuned (in this same run) to reach at least the same accuracy against a 1e-13 reference.
//!
//! Run: `cargo bench --bench simulator`. Prints ratios; asserts nothing about time.
//!
//! `cargo bench --bench simulator -- bounce`: the twin's bouncing bob (`pendulum_rig::bounce`),
//! forcing periods per second with its coarse steps while the shaft moves against the fine step
//! everywhere (the baseline, as before the coarse steps), on the rotating and the oscillating
//! case on a 5 Hz mount, and the largest distance between the two trajectories.

use std::hint::black_box;
use std::ops::ControlFlow;
use std::time::Instant;

use pendulum_model::sim::{integrate, rk4_fixed};
use pendulum_model::steady::steady_state_of;
use pendulum_model::{ClassifyOptions, Dimensionless, Model, SimOptions, SteadyClass};

fn end_state(model: &Model, tol: f64, y0: [f64; 2], t_end: f64) -> [f64; 2] {
    let mut out = [0.0; 2];
    integrate(
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
    out
}

/// A state on the attractor of the wanted kind, found from a grid of starts.
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

fn time_it<F: FnMut()>(mut f: F, min_s: f64) -> f64 {
    let start = Instant::now();
    let mut n = 0u64;
    while start.elapsed().as_secs_f64() < min_s {
        f();
        n += 1;
    }
    start.elapsed().as_secs_f64() / n as f64
}

/// Periods per second of the bouncing bob's integrator with coarse steps and with the fine step
/// everywhere, over `periods` forcing periods from `y0`, and the largest |Δθ| between them.
fn bounce_case(model: &Model, y0: [f64; 2], periods: f64) {
    use pendulum_rig::bounce::{integrate, Mount, Steps};
    let omega = model.params.omega;
    let t_end = periods * 2.0 * std::f64::consts::PI / omega;
    // A 5 Hz mount on the study's pendulum (ω0 ≈ 6.1 rad/s).
    let mount = Mount {
        nu: 2.0 * std::f64::consts::PI * 5.0 / 6.1,
        zeta: 0.1,
    };
    let times = || (0..=1000).map(move |i| t_end * f64::from(i) / 1000.0);
    let run = |fine: bool| {
        let mut th = Vec::with_capacity(1001);
        let sink = |s: pendulum_model::Sample| {
            th.push(s.theta);
            ControlFlow::Continue(())
        };
        let steps = if fine {
            Steps::FineEverywhere
        } else {
            Steps::Adaptive
        };
        integrate(model, mount, steps, 0.0, y0, t_end, times(), sink);
        th
    };
    let (a, b) = (run(false), run(true));
    let apart = a
        .iter()
        .zip(&b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let t_coarse = time_it(|| drop(black_box(run(false))), 1.0);
    let t_fine = time_it(|| drop(black_box(run(true))), 1.0);
    println!(
        "{:>8.0}  {:>12.0}  {:>12.0}  {:>8.1}  {apart:.1e}",
        periods,
        periods / t_coarse,
        periods / t_fine,
        t_fine / t_coarse
    );
}

fn main() {
    let mut d = Dimensionless::conservative();
    d.r = 0.7;
    d.lambda = 0.126;
    d.beta = 0.109;
    d.m_coulomb = 0.007;
    type Case = (&'static str, f64, fn(SteadyClass) -> bool);
    let cases: [Case; 2] = [
        ("rotating", 1.585, |c| c.is_rotation()),
        ("oscillating", 2.0, |c| c == SteadyClass::Oscillation),
    ];
    let bounce = std::env::args().any(|a| a == "bounce");
    if bounce {
        println!("case         periods  coarse [periods/s]  fine [periods/s]  fine/coarse  max |Δθ| [rad]");
    } else {
        println!("case         periods  dopri5@1e-8 [periods/s]  err      rk4 h     err      rk4 [periods/s]  dopri5/rk4");
    }
    for (name, omega, want) in cases {
        let mut p = d;
        p.omega = omega;
        let model = Model::new(p);
        let Some(y0) = attractor(&model, want) else {
            println!("{name:<12} no such attractor found on the start grid");
            continue;
        };
        if bounce {
            print!("{name:<12} ");
            bounce_case(&model, y0, 20.0);
            continue;
        }
        let periods = 20.0;
        let t_end = periods * p.forcing_period();
        let reference = end_state(&model, 1e-13, y0, t_end);
        let ours = end_state(&model, 1e-8, y0, t_end);
        let err = (ours[0] - reference[0])
            .abs()
            .max((ours[1] - reference[1]).abs());
        // Largest RK4 step (period/n) that is at least as accurate.
        let mut n = 16usize;
        let (h, rk_err) = loop {
            let h = p.forcing_period() / n as f64;
            let r = rk4_fixed(&model, y0, 0.0, t_end, h);
            let e = (r[0] - reference[0]).abs().max((r[1] - reference[1]).abs());
            if e <= err || n > 1 << 16 {
                break (h, e);
            }
            n = (n as f64 * 1.25).ceil() as usize;
        };
        let t_dopri = time_it(
            || {
                black_box(end_state(&model, 1e-8, black_box(y0), t_end));
            },
            1.0,
        );
        let t_rk4 = time_it(
            || {
                black_box(rk4_fixed(&model, black_box(y0), 0.0, t_end, h));
            },
            1.0,
        );
        println!(
            "{name:<12} {periods:>7} {:>24.0} {err:>8.1e} {h:>8.5} {rk_err:>8.1e} {:>16.0} {:>11.2}",
            periods / t_dopri,
            periods / t_rk4,
            t_rk4 / t_dopri
        );
    }
    println!("(dopri5/rk4 > 1 means the adaptive simulator is faster than the tuned plain loop)");
}
