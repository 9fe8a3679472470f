//! Numerical helpers shared by the workspace, at its bottom (no workspace dependencies): one
//! least-squares routine with one result type, the Student-t / F / normal quantiles and tails
//! (from `statrs`, not hand-typed tables or approximations), one BIC, one median, one angle
//! wrap and one trapezoid rule. A routine needed by two crates lives here, once.

mod error;
mod ls;
mod misc;
mod stats;

pub use error::NumericsError;
pub use ls::{inverse_spd, ols, solve_spd, wls, LsFit};
pub use misc::{golden_section, median, trapezoid, trapezoid_weight, wrap_pi, Golden};
pub use stats::{bic, f_sf, normal_quantile, normal_sf, signed_rank_z, t_quantile};
