use pendulum_maps::*;
use pendulum_model::Dimensionless;

fn main() {
    let mut d = Dimensionless::conservative();
    d.r = 0.7;
    d.lambda = 0.126;
    let mut r = d;
    r.beta = 0.109;
    r.m_coulomb = 0.007;
    let mut l = d;
    l.beta = 0.066;
    let starts = vec![
        [0.0, 0.0],
        [0.3, 0.0],
        [0.0, 3.0],
        [0.0, -3.0],
        [1.0, 2.0],
        [3.0, 0.0],
        [0.1, 0.0],
    ];
    for (name, m) in [("reference", r), ("linear", l)] {
        for w in [1.0, 1.57, 1.585, 2.0, 2.8] {
            let mut cfg = BifurcationConfig::new(
                m,
                Sweep::parse(&format!("omega={w}")).unwrap(),
                starts.clone(),
            );
            cfg.record_periods = 50;
            let b = bifurcation::run(&cfg, &|_| {}).unwrap();
            print!("{name} {w}: ");
            for o in &b.outcomes {
                print!(
                    "{:?}/{}:{}({:.4}) ",
                    o.start, o.steady.class, o.steady.period, o.steady.mean_theta_dot
                );
            }
            println!();
        }
    }
}
