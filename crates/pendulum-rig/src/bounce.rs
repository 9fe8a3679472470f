//! A bob that bounces on a springy mount: a departure outside the catalogue (effects.md, last
//! paragraph: "a bob that wobbles"), for the twin only. The analysis has no name for it, so it is
//! not in the model's simulator; the twin integrates it here, with its own integrator, as an
//! independent simulator would.
//!
//! The bob (the model's point mass) sits on a mount that gives along the rod: its distance from
//! the axis is r = l ρ, held at ρ = 1 when hanging at rest (the mount's pretension carries its
//! weight), with a radial natural frequency ν ω0 and damping ratio ζ. Per m g l, in τ = ω0 t:
//!
//! ```text
//! (ρ² + j) θ'' + 2 ρ ρ' θ' = ρ (−(1 + A_y) sin θ − A_x cos θ) − friction(θ, θ') − T_pos − spring
//!           ρ'' − ρ θ'² = (1 + A_y) cos θ − A_x sin θ − 1 − ν² (ρ − 1) − 2 ζ ν ρ'
//! ```
//!
//! (the Lagrangian ½(ρ'² + ρ² θ'²) + ρ cos θ − ρ − ½ ν² (ρ − 1)² with the base's motion and the
//! shaft's losses). Drag acts on the bob, so its viscous and quadratic terms take ρ² and ρ³.
//! The shaft's dry friction is regularised within ±`V_EPS` of θ' = 0 (a stiff linear zone),
//! and the step is chosen so that zone stays stable where the shaft is near or in it. A shaft
//! that comes to rest there with the torque on it within the friction's static capacity sticks
//! exactly, as in the model's own simulator (θ held, θ' = 0, the bob still moving on its mount),
//! until that torque exceeds the capacity; while stuck the steps are coarse.

use std::ops::ControlFlow;

use pendulum_model::sim::breaks_loose;
use pendulum_model::{Model, Sample};

/// Half-width of the regularised dry friction's linear zone in θ' (per ω0).
const V_EPS: f64 = 1e-6;

/// The bob's mount: radial natural frequency per ω0 and damping ratio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mount {
    pub nu: f64,
    pub zeta: f64,
}

/// State (θ, θ', ρ, ρ').
type State = [f64; 4];

fn rhs(model: &Model, m: Mount, t: f64, y: State) -> State {
    let [theta, w, rho, rw] = y;
    let tq = model.torques(t, theta, w);
    let dry = if w.abs() < V_EPS {
        tq.dry * w.abs() / V_EPS
    } else {
        tq.dry
    };
    let (ay, ax) = model.excitation.accel(t);
    let (s, c) = theta.sin_cos();
    let q = rho * (tq.gravity + tq.base)
        + rho * rho * tq.viscous
        + rho * rho * rho * tq.quadratic
        + rho.powi(4) * tq.cubic
        + rho * rho * tq.eddy
        + dry
        + tq.generator
        + tq.position
        + tq.spring
        - 2.0 * rho * rw * w;
    let acc = q / (rho * rho + model.params.j);
    let racc = rho * w * w + (1.0 + ay) * c
        - ax * s
        - 1.0
        - m.nu * m.nu * (rho - 1.0)
        - 2.0 * m.zeta * m.nu * rw;
    [w, acc, rw, racc]
}

/// [`rhs`] with the shaft stuck: θ held (θ' = θ'' = 0), the bob moving on its mount.
fn rhs_stuck(model: &Model, m: Mount, t: f64, y: State) -> State {
    // The bob's radial equation at θ' = 0 (the shaft's own slope is set to zero).
    let [_, _, rw, racc] = rhs(model, m, t, [y[0], 0.0, y[2], y[3]]);
    [0.0, 0.0, rw, racc]
}

fn deriv(model: &Model, m: Mount, stuck: bool, t: f64, y: State) -> State {
    if stuck {
        rhs_stuck(model, m, t, y)
    } else {
        rhs(model, m, t, y)
    }
}

/// The shaft's static balance at rest at (t, y): the torque on it without friction (gravity and
/// the base's motion at the bob's distance ρ, the position torque, the spring) and the dry
/// friction's static capacity (the model's, [`Model::static_balance`]).
fn balance(model: &Model, t: f64, y: &State) -> (f64, f64) {
    let tq = model.torques(t, y[0], 0.0);
    let q = y[2] * (tq.gravity + tq.base) + tq.position + tq.spring;
    (q, model.static_balance(t, y[0]).1)
}

/// Whether the shaft is stuck after a step that ended at (t, y): a stuck shaft stays so until
/// the torque on it breaks it loose (the model's own test, [`breaks_loose`]); a moving one
/// sticks (θ' set to 0) once it is inside the friction's linear zone with the torque within the
/// capacity.
fn sticks(model: &Model, t: f64, y: &mut State, stuck: bool) -> bool {
    if !stuck && y[1].abs() >= V_EPS {
        return false;
    }
    let (q, cap) = balance(model, t, y);
    let holds = if stuck {
        !breaks_loose(q, cap)
    } else {
        q.abs() <= cap
    };
    if holds {
        y[1] = 0.0;
    }
    holds
}

/// The coarse step (per ω0): a fiftieth of the mount's period and of the forcing's.
fn coarse_step(model: &Model, m: Mount) -> f64 {
    let p = &model.params;
    let mut h = 1e-3f64.min(2.0 * std::f64::consts::PI / (50.0 * m.nu.max(1e-9)));
    if p.omega > 0.0 {
        h = h.min(2.0 * std::f64::consts::PI / (50.0 * p.omega));
    }
    h
}

/// The fine step (per ω0): the coarse one, within the stability of the friction's linear zone
/// (slope ≈ D/V_EPS for the largest dry torque D).
fn step(model: &Model, m: Mount, t_end: f64) -> f64 {
    let p = &model.params;
    let dry_max = p.m_coulomb * 3.0 + p.c + p.s_break + p.c_rate * t_end.max(0.0) + 2.0 * p.c_lobes;
    let h = coarse_step(model, m);
    if dry_max > 0.0 {
        h.min(1.5 * V_EPS / dry_max)
    } else {
        h
    }
}

/// The step from a state moving at θ' = `w` with θ'' = `acc`: the coarse one while a coarse step
/// cannot reach the friction's linear zone (|θ'| above three times the change a coarse step can
/// make, and far above V_EPS), the fine one near and inside it. Outside the zone the friction is
/// a constant torque and nothing is stiff; the fine step was taken everywhere before, and a run
/// cost ~300 times the steps it needed (half the time of the suite's bouncing-bob test).
fn step_at(fine: f64, coarse: f64, w: f64, acc: f64) -> f64 {
    if w.abs() > 3.0 * acc.abs() * coarse + 100.0 * V_EPS {
        coarse
    } else {
        fine
    }
}

/// One classic fourth-order Runge–Kutta step of `h` from (t, y), whose slope there is `k1`
/// ([`deriv`]: moving or `stuck`).
fn rk4(model: &Model, mount: Mount, stuck: bool, t: f64, y: &State, k1: &State, h: f64) -> State {
    let at = |k: &State, a: f64| -> State {
        [
            y[0] + a * k[0],
            y[1] + a * k[1],
            y[2] + a * k[2],
            y[3] + a * k[3],
        ]
    };
    let k2 = deriv(model, mount, stuck, t + 0.5 * h, at(k1, 0.5 * h));
    let k3 = deriv(model, mount, stuck, t + 0.5 * h, at(&k2, 0.5 * h));
    let k4 = deriv(model, mount, stuck, t + h, at(&k3, h));
    let mut out = *y;
    for i in 0..4 {
        out[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
    out
}

/// How [`integrate`] steps away from the friction's linear zone.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Steps {
    /// Coarse while the shaft moves, fine near and in the zone (`step_at`), the exact stick
    /// while it rests (coarse steps again): the twin's.
    Adaptive,
    /// The fine step everywhere, stuck or moving, as the twin integrated before the coarse
    /// steps: the reference they are checked against (a test, and `cargo bench --bench
    /// simulator -- bounce`). Its step is 1.5 V_EPS over the largest dry torque: with the
    /// surveys' μ ≈ 0.15 about 300 times fewer per unit time than a moving shaft needs; the
    /// bench's lighter friction, 14×.
    FineEverywhere,
}

/// Integrates from (θ0, θ'0) with the bob at rest on its mount (ρ = 1, ρ' = 0) over [t0, t_end]
/// in fourth-order Runge–Kutta steps (`steps`), handing `sink` the shaft's (θ, θ') at each of
/// `times` (ascending, in [t0, t_end]) by a partial step from the step's start before it.
#[allow(clippy::too_many_arguments)]
pub fn integrate<I, F>(
    model: &Model,
    mount: Mount,
    steps: Steps,
    t0: f64,
    y0: [f64; 2],
    t_end: f64,
    times: I,
    mut sink: F,
) where
    I: IntoIterator<Item = f64>,
    F: FnMut(Sample) -> ControlFlow<()>,
{
    let fine = step(model, mount, t_end);
    let coarse = match steps {
        Steps::Adaptive => coarse_step(model, mount),
        Steps::FineEverywhere => fine,
    };
    let mut t = t0;
    let mut y: State = [y0[0], y0[1], 1.0, 0.0];
    let mut stuck = sticks(model, t, &mut y, false);
    let mut f = deriv(model, mount, stuck, t, y);
    for tq in times {
        loop {
            let h = if stuck {
                coarse
            } else {
                step_at(fine, coarse, y[1], f[1])
            };
            if t + h >= tq {
                break;
            }
            y = rk4(model, mount, stuck, t, &y, &f, h);
            t += h;
            stuck = sticks(model, t, &mut y, stuck);
            f = deriv(model, mount, stuck, t, y);
        }
        // The last partial step to tq, taken on a copy (the steps go on from the last full one).
        let dt = tq - t;
        let [theta, w, _, _] = if dt <= 0.0 {
            y
        } else {
            rk4(model, mount, stuck, t, &y, &f, dt)
        };
        if sink(Sample {
            t: tq,
            theta,
            theta_dot: w,
        })
        .is_break()
        {
            return;
        }
        if t_end <= t {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pendulum_model::{simulate, Dimensionless, Excitation, Physical, SimOptions};

    fn free(d: Dimensionless) -> Model {
        Model::with_excitation(d, Excitation::None)
    }

    fn lossless() -> Dimensionless {
        let mut d = Physical::default().to_dimensionless();
        d.beta = 0.0;
        d.alpha = 0.0;
        d.m_coulomb = 0.0;
        d.c = 0.0;
        d
    }

    /// The shaft's samples at `times` from (θ0, θ'0) = `y0` at t = 0 to `t_end`.
    fn trace(
        model: &Model,
        mount: Mount,
        steps: Steps,
        y0: [f64; 2],
        t_end: f64,
        times: impl IntoIterator<Item = f64>,
    ) -> Vec<Sample> {
        let mut got = Vec::new();
        integrate(model, mount, steps, 0.0, y0, t_end, times, |s| {
            got.push(s);
            ControlFlow::Continue(())
        });
        got
    }

    /// Without losses the mount's energy ½(ρ'² + ρ²θ'²) − ρ cos θ + ρ + ½ν²(ρ − 1)² is kept:
    /// the conservation law the equations come from, checked on a swing that stretches the mount
    /// (over the top: the centrifugal load pulls the bob out).
    #[test]
    fn a_lossless_bouncing_bob_keeps_its_energy() {
        let model = free(lossless());
        let mount = Mount { nu: 4.0, zeta: 0.0 };
        let energy = |y: &State| {
            0.5 * (y[3] * y[3] + y[2] * y[2] * y[1] * y[1]) - y[2] * y[0].cos()
                + y[2]
                + 0.5 * mount.nu * mount.nu * (y[2] - 1.0).powi(2)
        };
        // The state along the way, stepped with the module's own step and size.
        let h = step(&model, mount, 50.0);
        let mut y: State = [0.0, 2.3, 1.0, 0.0];
        let e0 = energy(&y);
        let mut t = 0.0;
        let mut rho_max = 1.0f64;
        while t < 50.0 {
            let k1 = rhs(&model, mount, t, y);
            y = rk4(&model, mount, false, t, &y, &k1, h);
            t += h;
            rho_max = rho_max.max(y[2]);
        }
        assert!(y[0] > 2.0 * std::f64::consts::PI, "it goes over the top");
        assert!(rho_max > 1.1, "the mount gives: ρ reached {rho_max}");
        assert!((energy(&y) - e0).abs() < 1e-9, "{} vs {e0}", energy(&y));
    }

    /// A stiff mount is no mount: with ν = 1000 the shaft's trajectory is the model's own
    /// (exact stick/slip, adaptive steps) within a small fraction of the swing, with dry
    /// friction and drag: a free decay from over the top to rest, and a weakly forced swing
    /// (both regular, so trajectories can be compared point by point). Measured: 5.8e-4 rad of
    /// a 14.7 rad decay, and 2.2e-6 rad of the 0.61 rad swing (1.6e-5 before the exact stick,
    /// when a resting shaft crept through the friction's linear zone).
    #[test]
    fn a_stiff_mount_follows_the_models_own_simulator() {
        let p = Physical::default();
        let mut weak = p.to_dimensionless();
        weak.r *= 0.3;
        for (model, y0) in [
            (free(p.to_dimensionless()), [0.0, 2.5]),
            (Model::new(weak), [0.6, 0.0]),
        ] {
            let (theta, worst) = compare(&model, y0, 1000.0);
            let swing = theta.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            assert!(
                worst < 1e-3 * swing,
                "worst {worst} rad of a {swing} rad swing"
            );
            // And a soft mount is not: the same start moves the shaft differently.
            let (_, apart) = compare(&model, y0, 3.0);
            assert!(apart > 30.0 * worst, "soft {apart} vs stiff {worst}");
        }
    }

    /// The coarse steps taken while the shaft moves change nothing a fine step everywhere (the
    /// integrator before them) gives, beyond 1e-6 rad: a soft mount (ν = 3) on a weakly forced
    /// swing with dry friction that decays from 1.2 rad and comes to rest, 200 (per ω0) sampled
    /// every 0.05 (measured: 3.1e-7 rad at worst; 2553 of the 4001 samples near θ' = 0).
    #[test]
    fn coarse_steps_while_moving_agree_with_fine_steps_everywhere() {
        let p = Physical::default();
        let mut d = p.to_dimensionless();
        d.r *= 0.2;
        let model = Model::new(d);
        let mount = Mount { nu: 3.0, zeta: 0.2 };
        let times = || (0..=4000).map(|i| 0.05 * f64::from(i));
        let got: Vec<f64> = trace(&model, mount, Steps::Adaptive, [1.2, 0.0], 200.0, times())
            .iter()
            .map(|s| s.theta)
            .collect();
        let fine_run = trace(
            &model,
            mount,
            Steps::FineEverywhere,
            [1.2, 0.0],
            200.0,
            times(),
        );
        let fine: Vec<f64> = fine_run.iter().map(|s| s.theta).collect();
        // Samples in or near the friction's linear zone (stuck, or turning).
        let slow = fine_run
            .iter()
            .filter(|s| s.theta_dot.abs() < 100.0 * V_EPS)
            .count();
        assert_eq!(got.len(), fine.len());
        let worst = got
            .iter()
            .zip(&fine)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let swing = fine.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(swing > 0.5, "it swings: {swing}");
        assert!(slow > 1000, "it rests: {slow} samples of 4001 near θ' = 0");
        assert!(worst < 1e-6, "worst {worst} rad of a {swing} rad swing");
    }

    /// A shaft at rest off the vertical with the torque on it within the friction's capacity
    /// sticks exactly (θ held to the bit, θ' = 0) under the shaker while its bob bounces on a
    /// soft mount; twice as far out, past the capacity, it slips at once.
    #[test]
    fn a_stuck_shaft_holds_its_angle_exactly_while_the_bob_bounces() {
        let p = Physical::default();
        let mut d = p.to_dimensionless();
        d.r *= 0.3;
        let model = Model::new(d);
        let mount = Mount {
            nu: 3.0,
            zeta: 0.05,
        };
        // The angle whose gravity torque is a fifth of the capacity there.
        let cap = model.static_balance(0.0, 0.0).1;
        let theta0 = (0.2 * cap).asin();
        let run = |theta0: f64| {
            let times = (0..=1000).map(|i| 0.1 * f64::from(i));
            trace(&model, mount, Steps::Adaptive, [theta0, 0.0], 100.0, times)
        };
        let held = run(theta0);
        assert_eq!(held.len(), 1001);
        assert!(
            held.iter().all(|s| s.theta == theta0 && s.theta_dot == 0.0),
            "moved: {:?}",
            held.iter()
                .find(|s| s.theta != theta0 || s.theta_dot != 0.0)
        );
        let far = (2.0 * cap).asin();
        let slipped = run(far);
        assert!(slipped.iter().any(|s| (s.theta - far).abs() > 1e-3 * far));
    }

    /// The model's own trajectory from y0 over 100 (per ω0), and the largest distance of the
    /// bouncing bob's (mount ν, damping 0.3) from it.
    fn compare(model: &Model, y0: [f64; 2], nu: f64) -> (Vec<f64>, f64) {
        let reference =
            simulate(model, &SimOptions::with_tol(1e-11), y0, 0.0, 100.0, 0.25).unwrap();
        let got: Vec<f64> = trace(
            model,
            Mount { nu, zeta: 0.3 },
            Steps::Adaptive,
            y0,
            100.0,
            reference.t.iter().copied(),
        )
        .iter()
        .map(|s| s.theta)
        .collect();
        assert_eq!(got.len(), reference.theta.len());
        let worst = got
            .iter()
            .zip(&reference.theta)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        (reference.theta, worst)
    }
}
