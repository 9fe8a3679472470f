//! The parametric pendulum: parameters, base excitation, the simulator with stick/slip Coulomb
//! friction, and steady-state classes. Everything downstream (fits, discovery, maps) drives it.

pub mod effects;
pub mod excitation;
pub mod params;
pub mod power;
pub mod sim;
pub mod spec;
pub mod steady;

#[cfg(test)]
mod physics_tests;

pub use effects::{
    Effect, EffectParam, FreeDecay, RateShape, Regressor, Sensors, Tolerance, Variable, WeakSample,
    CATALOGUE,
};
pub use excitation::{CrankDrive, CrankTable, Excitation, MeasuredAccel};
pub use params::{Dimensionless, Effects, Physical};
pub use power::{mean_powers, MeanPowers};
pub use sim::{integrate, simulate, Model, Sample, SimOptions, SimStats, Torques, Trajectory};
pub use spec::ParamSpec;
pub use steady::{
    classify_history, classify_poincare, ClassifyOptions, PartialClass, SteadyClass, SteadyState,
};

/// Errors of the model crate.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    #[error("parameter {name} = {value} is out of range: expected {expected}")]
    OutOfRange {
        name: String,
        value: f64,
        expected: String,
    },
    #[error("unknown parameter {key:?}: expected one of {expected}")]
    UnknownParam { key: String, expected: String },
    #[error("parameter {key:?}: cannot read {value:?} as {expected}")]
    BadParamValue {
        key: String,
        value: String,
        expected: String,
    },
    #[error("invalid input: {0}")]
    BadInput(String),
    #[error("integration gave up after {steps} steps at t = {t}")]
    TooManySteps { steps: u64, t: f64 },
    #[error("step size underflow at t = {t} (stiff or non-finite right-hand side)")]
    StepUnderflow { t: f64 },
}
