use pendulum_explain::*;
fn main() {
    let path = std::env::args().nth(1).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let mut t = Vec::new();
    let mut th = Vec::new();
    for l in text.lines().skip(1) {
        let mut it = l.split(',');
        t.push(it.next().unwrap().parse::<f64>().unwrap());
        th.push(it.next().unwrap().parse::<f64>().unwrap() - std::f64::consts::PI);
    }
    let i1 = 1.09e-4 + 0.1476 * 0.1478f64.powi(2);
    let w = (0.1476 * 9.81 * 0.1478 / i1).sqrt();
    let opts = DecayOptions {
        rig: Some(KnownRig {
            m_kg: 0.1476,
            a_m: 0.1478,
            g_m_s2: 9.81,
            r_b_m: None,
        }),
        reference: Some(ReferenceModel {
            name: "authors".into(),
            omega_n_rad_s: w,
            gamma_per_s: 2.24e-4 / i1,
            dry_rad_s2: 0.0,
        }),
        ..DecayOptions::default()
    };
    let t0 = std::time::Instant::now();
    let d = diagnose_decay(&t, &th, &opts).unwrap();
    eprintln!("took {:?}", t0.elapsed());
    println!("{d}");
    for c in &d.candidates {
        println!(
            "{} round {}: {} | seg gain {:.3} | phys {:?}",
            c.term,
            c.round,
            c.verdict,
            c.heldout_gain_segmented,
            c.physical
                .iter()
                .map(|p| format!(
                    "{} {:.4e} [{:.4e},{:.4e}]",
                    p.name, p.estimate, p.ci_low, p.ci_high
                ))
                .collect::<Vec<_>>()
        );
    }
    for n in &d.notes {
        println!("note: {n}");
    }
    for n in &d.envelope.notes {
        println!("env note: {n}");
    }
    println!(
        "base {:?} tau {:.1} rms {:.2e} iters {}",
        d.base
            .params
            .iter()
            .map(|p| format!("{} {:.5e}", p.name, p.estimate))
            .collect::<Vec<_>>(),
        d.base.tau_int,
        d.base.rms_rad,
        d.base.iterations
    );
    println!(
        "best {:?} tau {:.1} rms {:.2e} iters {}",
        d.best
            .params
            .iter()
            .map(|p| format!(
                "{} {:.5e} [{:.3e},{:.3e}]",
                p.name, p.estimate, p.ci_low, p.ci_high
            ))
            .collect::<Vec<_>>(),
        d.best.tau_int,
        d.best.rms_rad,
        d.best.iterations
    );
    for r in d.envelope.rows.iter().skip(60).step_by(1) {
        println!(
            "{:3} {:8.4} {:+.5} A={:.5} mid={:?} loss={:?}",
            r.n, r.t_s, r.theta_rad, r.amplitude_rad, r.mid_amplitude_rad, r.loss_per_cycle_rad
        );
    }
}
