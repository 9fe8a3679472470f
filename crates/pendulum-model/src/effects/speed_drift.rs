//! `speed_drift`: the motor slows or speeds up slowly, Ω + (dΩ/dτ)·τ.

use super::{Decompiled, Draw, Effect, Kind, Param, Survey};
use crate::{Dimensionless, Physical};

#[derive(Debug)]
pub struct SpeedDrift;

static PARAMS: [Param; 1] = [Param::real(
    "speed_drift.dOmega_dtau",
    "hz_per_s",
    "Hz/s",
    (-0.01, 0.01),
)];

impl Effect for SpeedDrift {
    fn name(&self) -> &'static str {
        "speed_drift"
    }
    fn kind(&self) -> Kind {
        Kind::Input
    }
    fn params(&self) -> &'static [Param] {
        &PARAMS
    }
    fn what(&self) -> &'static str {
        "the motor slows or speeds up slowly (belt slip, supply), from the moment the shaker is at speed"
    }
    fn term(&self) -> &'static str {
        "crank speed Ω + (dΩ/dτ)·τ"
    }
    fn survey(&self) -> Survey {
        Survey {
            base: "reference",
            draws: &[("speed_drift.dOmega_dtau", Draw::Signed(0.0005, 0.002))],
        }
    }
    // The drive itself drifts, so the crank excitation carries it (not the sensor transform).
    fn compile(&self, v: &[f64], p: &Physical, d: &mut Dimensionless) {
        // dω/dt = 2π (dΩ/dτ) / ω0²: Hz/s → (rad per dimensionless time) per dimensionless time.
        let w0 = p.omega0_rad_s();
        d.omega_drift = 2.0 * std::f64::consts::PI * v[0] / (w0 * w0);
    }
    fn decompile(&self, d: &Dimensionless, p: &Physical) -> Decompiled {
        let w0 = p.omega0_rad_s();
        Decompiled::Set(
            (d.omega_drift != 0.0)
                .then(|| vec![d.omega_drift * w0 * w0 / (2.0 * std::f64::consts::PI)]),
        )
    }
}
