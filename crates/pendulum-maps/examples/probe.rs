use pendulum_maps::*;
use pendulum_model::{Dimensionless, SteadyClass};
use std::time::Instant;

fn models() -> Vec<(&'static str, Dimensionless)> {
    let mut d = Dimensionless::conservative();
    d.r = 0.7;
    d.lambda = 0.126;
    let mut a = d;
    a.beta = 0.109;
    a.m_coulomb = 0.007;
    let mut b = d;
    b.beta = 0.066;
    vec![("reference", a), ("linear", b)]
}

fn main() {
    let spec = std::env::args()
        .nth(1)
        .unwrap_or("omega=2.6:3.0:0.05".into());
    let grid = std::env::args().nth(2).unwrap_or("8x8".into());
    let tr: u32 = std::env::args()
        .nth(3)
        .map(|s| s.parse().unwrap())
        .unwrap_or(300);
    let rec: u32 = std::env::args()
        .nth(4)
        .map(|s| s.parse().unwrap())
        .unwrap_or(50);
    for (name, d) in models() {
        let t = Instant::now();
        let mut cfg = BifurcationConfig::new(d, Sweep::parse(&spec).unwrap(), starts(&grid));
        cfg.transient_periods = tr;
        cfg.record_periods = rec;
        let b = bifurcation::run(&cfg, &|_| {}).unwrap();
        println!("{name}: {:.2} s", t.elapsed().as_secs_f64());
        for s in b.summary(None) {
            let mut periods = std::collections::BTreeMap::new();
            for o in b
                .outcomes
                .iter()
                .filter(|o| o.value == s.value && o.steady.class.is_rotation())
            {
                *periods.entry(o.steady.period).or_insert(0) += 1;
            }
            println!(
                "  {:.3} rot {:5.1}% {:?} counts {:?} periods {:?}",
                s.value,
                100.0 * s.rotation_fraction(),
                SteadyClass::ALL.map(|c| c.as_str().chars().take(5).collect::<String>()),
                s.counts,
                periods
            );
        }
    }
}

fn starts(g: &str) -> Vec<[f64; 2]> {
    if let Some(n) = g.strip_prefix("demo") {
        let n: usize = n.parse().unwrap();
        let mut v = vec![];
        for i in 0..n {
            for j in 0..n {
                v.push([
                    -std::f64::consts::PI + 2.0 * std::f64::consts::PI * i as f64 / n as f64,
                    -3.0 + 6.0 * j as f64 / n as f64,
                ]);
            }
        }
        return v;
    }
    if let Some(n) = g.strip_prefix("rand") {
        return IcSpec::Random {
            n: n.parse().unwrap(),
            seed: 1,
            theta_dot_max: 3.0,
        }
        .starts();
    }
    IcSpec::parse_grid(g, 3.0).unwrap().starts()
}
