use pendulum_maps::*;
use pendulum_model::Dimensionless;
use std::time::Instant;

fn main() {
    let mut d = Dimensionless::conservative();
    d.r = 0.7;
    d.lambda = 0.126;
    let lin = std::env::args().nth(2).is_some();
    if lin {
        d.beta = 0.066
    } else {
        d.beta = 0.109;
        d.m_coulomb = 0.007;
    }
    let spec = std::env::args().nth(1).unwrap();
    let t = Instant::now();
    let mut cfg = BifurcationConfig::new(
        d,
        Sweep::parse(&spec).unwrap(),
        IcSpec::parse_grid("4x4", 3.0).unwrap().starts(),
    );
    cfg.mode = Mode::Continuation;
    cfg.transient_periods = 100;
    cfg.record_periods = 32;
    let b = bifurcation::run(&cfg, &|_| {}).unwrap();
    println!("{:.2} s", t.elapsed().as_secs_f64());
    for dir in [Direction::Up, Direction::Down] {
        print!("{dir:?}: ");
        for s in b.summary(Some(dir)) {
            print!("{:.2}:{:.0}% ", s.value, 100.0 * s.rotation_fraction());
        }
        println!();
    }
}
