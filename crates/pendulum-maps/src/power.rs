//! Where the power goes, on the maps: every simulation of `bifurcate`, `zones` and `design`
//! reports the mean powers of [`pendulum_model::power::mean_powers`] (the one power integrator;
//! nothing here integrates) over the whole forcing periods its class is read from, in W.
//!
//! The window: the first recorded forcing periods, as many as the steady state's own period (a
//! period-p orbit repeats after p forcing periods, so its mean over p periods is its mean over
//! any whole number of orbits; rest takes 1), or the whole recorded window for chaos, whose mean
//! only a long window estimates. Why not always the whole window: `mean_powers` samples 2000
//! points per period, which over 50 recorded periods made a map 4.6 times slower (`cargo bench
//! --bench maps -- generator`); one orbit costs a few per cent.
//!
//! Why the window starts at the first Poincaré point instead of re-running from t = 0: the
//! transient is most of a map's cost, and the state at t = transient·T is known exactly (it is
//! the first recorded point). The powers are those of the motion from that state, which is the
//! recorded motion to the integrator's tolerance.

use pendulum_model::power::mean_powers;
use pendulum_model::steady::steady_state_of;
use pendulum_model::{ClassifyOptions, MeanPowers, Model, SimOptions, SteadyClass, SteadyState};
use pendulum_report::Column;

use crate::MapsError;

/// The powers written per row, in [`MeanPowers::named`] order, with what each is.
pub const POWER_COLUMNS: [(&str, &str); 8] = [
    (
        "mean_power_base_w",
        "mean power the base's motion feeds the pendulum over one orbit of the steady state (p forcing periods; chaos: all recorded periods), W",
    ),
    (
        "mean_power_viscous_w",
        "mean power dissipated by linear viscous drag (b), W",
    ),
    (
        "mean_power_quadratic_w",
        "mean power dissipated by quadratic drag (a), W",
    ),
    (
        "mean_power_dry_w",
        "mean power dissipated by dry friction (bearing μ, constant T_c, stribeck T_s), W",
    ),
    (
        "mean_power_generator_w",
        "mean power the generator takes from the pendulum (T_gen·|dθ/dt|), W",
    ),
    (
        "mean_power_load_w",
        "of the generator's, the mean electrical power into the load (I²R), W",
    ),
    (
        "mean_power_diodes_w",
        "of the generator's, the mean power lost in the rectifier's diodes (V_d·I), W",
    ),
    (
        "mean_power_stored_w",
        "mean rate of change of the mechanical energy over the window (≈ 0 for a periodic motion), W",
    ),
];

/// Forcing periods the powers are averaged over (see the module docs).
pub fn power_periods(st: &SteadyState, record_periods: u32) -> u32 {
    match st.class {
        SteadyClass::Chaos => record_periods,
        _ => st.period.clamp(1, record_periods.max(1)),
    }
}

/// A simulation's steady state, its Poincaré points and its mean powers in W over
/// [`power_periods`] from the first recorded point (`scale_w` = m g l ω0 of the rig).
pub fn steady_with_power(
    model: &Model,
    sim: &SimOptions,
    start: [f64; 2],
    transient_periods: u32,
    record_periods: u32,
    classify: &ClassifyOptions,
    scale_w: f64,
) -> Result<(SteadyState, Vec<f64>, Vec<f64>, MeanPowers), MapsError> {
    let (st, th, thd) = steady_state_of(
        model,
        sim,
        start,
        0.0,
        transient_periods,
        record_periods,
        classify,
    )?;
    let period = model.params.forcing_period();
    let t_from = f64::from(transient_periods) * period;
    let t_to = t_from + f64::from(power_periods(&st, record_periods)) * period;
    let (Some(&th0), Some(&w0)) = (th.first(), thd.first()) else {
        return Err(MapsError::Invalid("no Poincaré point recorded".into()));
    };
    let pw = if th0.is_finite() && w0.is_finite() {
        mean_powers(model, sim, t_from, [th0, w0], t_from, t_to)?.si(scale_w)
    } else {
        nan_powers()
    };
    Ok((st, th, thd, pw))
}

/// Every power NaN (a motion that left the finite numbers).
pub fn nan_powers() -> MeanPowers {
    MeanPowers {
        base: f64::NAN,
        viscous: f64::NAN,
        quadratic: f64::NAN,
        dry: f64::NAN,
        generator: f64::NAN,
        load: f64::NAN,
        diodes: f64::NAN,
        stored: f64::NAN,
    }
}

/// The mean of several starts' powers, field by field.
pub fn mean_of(p: &[MeanPowers]) -> MeanPowers {
    let mut m = MeanPowers::default();
    for x in p {
        for (sum, v) in m.fields_mut().into_iter().zip(x.named()) {
            *sum += v.1;
        }
    }
    m.scaled(1.0 / p.len().max(1) as f64)
}

/// Sample standard deviation (n − 1) of `v`; 0 for fewer than two values.
pub fn sample_sd(v: &[f64]) -> f64 {
    if v.len() < 2 {
        return 0.0;
    }
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// The eight power columns, one row per element of `rows`, `what` prefixed to each description
/// (e.g. "per start: ").
pub fn columns(rows: &[MeanPowers], what: &str) -> Vec<Column> {
    let mut per: [Vec<f64>; 8] = Default::default();
    for r in rows {
        for (k, (_, v)) in r.named().iter().enumerate() {
            per[k].push(*v);
        }
    }
    POWER_COLUMNS
        .iter()
        .zip(per)
        .map(|((name, desc), v)| Column::f64(name, "W", v).describe(&format!("{what}{desc}")))
        .collect()
}

/// Row `r` of the eight power columns of a table (the inverse of [`columns`]).
pub fn read_row(cols: &[Column], r: usize) -> Result<MeanPowers, MapsError> {
    let mut v = [0.0; 8];
    for (k, (name, _)) in POWER_COLUMNS.iter().enumerate() {
        let pendulum_report::ColumnData::F64(x) = crate::shard::col(cols, name)? else {
            return Err(MapsError::Invalid(format!("column {name} is not f64")));
        };
        v[k] = *x
            .get(r)
            .ok_or_else(|| MapsError::Invalid(format!("column {name} has no row {r}")))?;
    }
    Ok(MeanPowers {
        base: v[0],
        viscous: v[1],
        quadratic: v[2],
        dry: v[3],
        generator: v[4],
        load: v[5],
        diodes: v[6],
        stored: v[7],
    })
}

/// The study's rig (m g l ω0 of [`pendulum_model::Physical::default`]), the power scale a
/// map uses when none is given.
pub fn default_scale_w() -> f64 {
    pendulum_model::Physical::default().power_scale_w()
}
