//! pendulum-explain: what a damping model gets wrong, and which catalogue term (`effects.md`)
//! fixes it.
//!
//! [`decay`]: free decays (no base motion) of a pendulum whose inertia may be unknown — turning
//! points and the decay envelope, trajectory fits in the identifiable ratios (ω_n, damping per
//! unit inertia), candidate terms with intervals and held-out gains, and what stays unexplained.

pub mod decay;

pub use decay::{
    diagnose_decay, envelope, envelope_with, first_swing, loss_band_contradicts, omega_n_estimate,
    turning_points, turning_points_with, Candidate, Coef, DecayDiagnosis, DecayError, DecayOptions,
    EnvelopeFit, EnvelopeRow, Estimate, HeldOutScore, KnownRig, LossBand, ModelFit, PeriodLaw,
    ReferenceModel, Resolution, Term, TurningPoint, Unexplained, DECAY_RULE, LOSS_BAND_FACTOR,
    MIN_SWING_STEPS,
};
