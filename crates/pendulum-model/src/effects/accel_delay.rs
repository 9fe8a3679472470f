//! `accel_delay`: the accelerometer's samples lag the true motion by Δ.

use super::{Draw, Effect, Kind, Param, Regressor, Sensors, Survey, Tolerance};

#[derive(Debug)]
pub struct AccelDelay;

/// Discover's column: A_y' sin θ, the equation error's first-order change with the
/// accelerometer's lag (Δ ω0 in dimensionless time).
static REGRESSORS: [Regressor; 1] = [Regressor {
    name: "delay",
    group: 0,
    lobes: 1,
    term: |s| s.a_y_dot * s.theta.sin(),
    per_si: |p| p.omega0_rad_s(),
}];

static PARAMS: [Param; 1] = [Param::real("accel_delay.Delta", "s", "s", (-0.05, 0.05))];

impl Effect for AccelDelay {
    fn name(&self) -> &'static str {
        "accel_delay"
    }
    fn kind(&self) -> Kind {
        Kind::Input
    }
    /// Within two standard deviations of one stamp's timing jitter: the firmware stamps each
    /// sample to within "tens of µs" (rig.md), and a low-pass filter whose delay is compensated
    /// for its DC group delay leaves a few tens of µs on the crank's harmonics; real lags are
    /// milliseconds.
    fn tolerance(&self) -> Option<Tolerance> {
        Some(Tolerance::StampJitter(2.0))
    }
    /// A lag, never a lead: a filter and a read latency both make the samples see the motion
    /// after it happens (effects.md: "lag the true motion by Δ"). A lead beyond the stamps'
    /// jitter is a departure the delay does not describe: a 0.029 rad encoder backlash, whose
    /// measured angle lags the shaft at every turn-around, was named a −0.74 ms "delay".
    fn possible(&self, size: f64) -> bool {
        size >= 0.0
    }
    fn regressors(&self) -> &'static [Regressor] {
        &REGRESSORS
    }
    fn params(&self) -> &'static [Param] {
        &PARAMS
    }
    fn what(&self) -> &'static str {
        "the accelerometer's samples lag the true motion by Δ (its low-pass filter, read latency)"
    }
    fn term(&self) -> &'static str {
        "the forcing leads the accelerometer-aligned clock by Δ"
    }
    fn survey(&self) -> Survey {
        Survey {
            base: "reference",
            draws: &[("accel_delay.Delta", Draw::Uniform(0.004, 0.015))],
        }
    }
    fn sense(&self, v: &[f64], s: &mut Sensors) {
        s.accel_delay_s = v[0];
    }
}

#[cfg(test)]
mod tests {
    use super::super::Effect;

    /// A lag is physically possible and a lead is not, however small: the tolerance for the
    /// stamps' jitter is discover's to apply, not the range's.
    #[test]
    fn a_lag_is_possible_and_a_lead_is_not() {
        let e = super::AccelDelay;
        assert!(e.possible(0.005) && e.possible(0.0));
        assert!(!e.possible(-1e-6) && !e.possible(-0.00074));
    }
}
