//! The crate's single error type: structured so callers (CLI, job runner) can point at the
//! offending config field, variable or point instead of parsing a message.

/// Everything that can go wrong while setting up or running a fit.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FitError {
    /// A solver / driver setting is out of its valid range.
    #[error("invalid setting `{field}` = {value}: expected {expected}")]
    BadConfig {
        field: &'static str,
        value: String,
        expected: &'static str,
    },
    /// The problem's bounds for variable `index` are not finite with `lo < hi`.
    #[error("bounds of variable {index} are [{lo}, {hi}]: expected finite lo < hi")]
    BadBounds { index: usize, lo: f64, hi: f64 },
    /// `Problem::bounds()` does not have `Problem::dim()` entries (or `dim()` is 0).
    #[error("problem has dim {dim} but {got} bounds (dim must be ≥ 1)")]
    BadDimension { dim: usize, got: usize },
    /// A seeded initial member has the wrong length or lies outside the bounds.
    #[error("initial member {member}: {reason}")]
    BadInit { member: usize, reason: String },
    /// The problem returned a NaN or infinite exact cost; return a large finite penalty instead.
    #[error("cost {value} at x = {x:?} is not finite")]
    NonFiniteCost { x: Vec<f64>, value: f64 },
    /// The problem abandoned an evaluation without proving `cost > bound`; accepting it could
    /// change a selection, so it is a contract violation rather than a silent rejection.
    #[error(
        "evaluation at x = {x:?} was abandoned at {value}, which does not exceed the bound {bound}"
    )]
    AbandonBelowBound { x: Vec<f64>, value: f64, bound: f64 },
    /// A least-squares problem's box for variable `index` has `lo > hi` or a NaN side (infinite
    /// sides are allowed there).
    #[error("bounds of variable {index} are [{lo}, {hi}]: expected lo ≤ hi")]
    BadBox { index: usize, lo: f64, hi: f64 },
    /// A least-squares start point has the wrong length or a non-finite entry.
    #[error("start point {x:?}: {reason}")]
    BadStart { x: Vec<f64>, reason: &'static str },
    /// A least-squares problem's residuals could not be evaluated at a point the solver cannot
    /// back off from (the start, or any point for Gauss–Newton), or came back with a changed
    /// length.
    #[error("residuals cannot be evaluated at x = {x:?}")]
    ResidualsFailed { x: Vec<f64> },
    /// A least-squares problem's Jacobian could not be evaluated at an accepted point.
    #[error("Jacobian cannot be evaluated at x = {x:?}")]
    JacobianFailed { x: Vec<f64> },
    /// Gauss–Newton's normal matrix JᵀJ is not positive definite at `x` (iteration `iteration`,
    /// counted from 1): some direction is not determined by the residuals.
    #[error("the normal matrix is singular at x = {x:?} (iteration {iteration})")]
    Singular { x: Vec<f64>, iteration: usize },
    /// The local rayon pool could not be built.
    #[error("cannot build a thread pool: {0}")]
    ThreadPool(String),
}
