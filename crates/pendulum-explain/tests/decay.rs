//! The free-decay analysis on decays made by the model crate's simulator (exact stick/slip) and
//! then measured the way an encoder does: an angle offset, a little noise, quantisation to
//! 40000 counts per revolution, a hand-held start. The truth is known, so the analysis must find
//! dry friction where it is and not where it is not.

use std::ops::ControlFlow;

use pendulum_explain::{diagnose_decay, envelope, DecayOptions, Term};
use pendulum_model::{integrate, Dimensionless, Excitation, Model, SimOptions};

/// A tiny deterministic normal generator (xorshift64* + Box–Muller): no dependency needed.
struct Noise(u64);

impl Noise {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let v = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        ((v >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

struct Truth {
    omega_n: f64,
    beta: f64,
    c: f64,
    theta0: f64,
    t_hold: f64,
    t_end: f64,
    offset: f64,
    sigma: f64,
    seed: u64,
}

/// θ(t) at 1 kHz: held at θ0 until `t_hold`, then a free decay; measured with an offset, noise
/// and 40000-count quantisation (bin centres).
fn measure(tr: &Truth) -> (Vec<f64>, Vec<f64>) {
    let mut d = Dimensionless::conservative();
    d.beta = tr.beta;
    d.c = tr.c;
    let model = Model::with_excitation(d, Excitation::None);
    let fs = 1000.0;
    let n = (tr.t_end * fs) as usize;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / fs).collect();
    let rel: Vec<f64> = t
        .iter()
        .filter(|&&x| x >= tr.t_hold)
        .map(|&x| (x - tr.t_hold) * tr.omega_n)
        .collect();
    let mut free = Vec::with_capacity(rel.len());
    integrate(
        &model,
        &SimOptions::with_tol(1e-10),
        0.0,
        [tr.theta0, 0.0],
        rel.last().copied().unwrap_or(0.0) + 1e-9,
        rel.iter().copied(),
        |s| {
            free.push(s.theta);
            ControlFlow::Continue(())
        },
    )
    .expect("simulates");
    assert_eq!(free.len(), rel.len());
    let q = std::f64::consts::TAU / 40000.0;
    let mut noise = Noise(tr.seed);
    let held = n - free.len();
    let theta = (0..n)
        .map(|i| {
            let v = if i < held { tr.theta0 } else { free[i - held] };
            let m = v + tr.offset + tr.sigma * noise.normal();
            (m / q).floor() * q + 0.5 * q
        })
        .collect();
    (t, theta)
}

fn rel_err(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn viscous_only_decay_does_not_get_dry_friction() {
    let tr = Truth {
        omega_n: 8.0,
        beta: 0.02,
        c: 0.0,
        theta0: 0.3,
        t_hold: 0.3,
        t_end: 24.0,
        offset: 0.0012,
        sigma: 2e-5,
        seed: 7,
    };
    let (t, th) = measure(&tr);
    let env = envelope(&t, &th).expect("envelope");
    assert!(
        env.polynomial_best.iter().any(|c| c.name == "c1")
            && !env.polynomial_best.iter().any(|c| c.name == "c0"),
        "viscous decay should look exponential: {:?} {}",
        env.polynomial_best,
        env.shape
    );
    let d = diagnose_decay(&t, &th, &DecayOptions::default()).expect("diagnosis");
    println!("{d}");
    assert!(
        !d.is_accepted(Term::CoulombConstant),
        "no dry friction in the data, yet: {:?}",
        d.candidate(Term::CoulombConstant)
    );
    assert!(d.accepted.is_empty(), "accepted {:?}", d.accepted);
    let c = d.candidate(Term::CoulombConstant).expect("tried");
    assert!(
        c.ci_low <= 0.0 || c.heldout_gain <= c.heldout_noise.max(0.02),
        "{c:?}"
    );
    let beta = d.best.term_value(Term::ViscousLinear);
    assert!(rel_err(beta, tr.beta) < 0.05, "beta {beta} vs {}", tr.beta);
    assert!(rel_err(d.best.omega_n(), tr.omega_n) < 1e-3);
    assert!((d.best.offset_rad() - tr.offset).abs() < 2e-4);
    // The model is right: nothing should be left unexplained at these amplitudes.
    assert!(
        !d.unexplained.iter().any(|u| u.what == "period_drift"),
        "{:?}",
        d.unexplained
    );
}

#[test]
fn dry_friction_is_found_with_its_size() {
    let tr = Truth {
        omega_n: 8.0,
        beta: 0.008,
        c: 0.0025,
        theta0: 0.2,
        t_hold: 0.25,
        t_end: 16.0,
        offset: -0.0008,
        sigma: 2e-5,
        seed: 11,
    };
    let (t, th) = measure(&tr);
    let d = diagnose_decay(&t, &th, &DecayOptions::default()).expect("diagnosis");
    println!("{d}");
    assert!(d.is_accepted(Term::CoulombConstant), "{d}");
    let c = d.candidate(Term::CoulombConstant).expect("tried");
    assert!(c.accepted && c.ci_low > 0.0, "{c:?}");
    assert!(
        rel_err(c.estimate, tr.c) < 0.10,
        "c = {} vs {}",
        c.estimate,
        tr.c
    );
    assert!(c.ci_low <= tr.c * 1.02 && c.ci_high >= tr.c * 0.98, "{c:?}");
    assert!(
        c.heldout_gain > c.heldout_noise && c.heldout_gain > 0.1,
        "{c:?}"
    );
    let beta = d.best.term_value(Term::ViscousLinear);
    assert!(rel_err(beta, tr.beta) < 0.3, "beta {beta} vs {}", tr.beta);
    // The envelope sees the constant loss 4c per cycle.
    assert!(
        d.envelope.polynomial_best.iter().any(|k| k.name == "c0"),
        "{:?}",
        d.envelope.polynomial_best
    );
    // Serialisable, for the discover report.
    let json = serde_json::to_string(&d).expect("serialises");
    assert!(json.contains("\"coulomb_constant\""));
}
