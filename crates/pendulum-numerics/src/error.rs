//! The crate's single error type.

/// Why a numerical routine could not give an answer.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NumericsError {
    /// Lengths that must agree do not (rows against targets or weights, a row against the
    /// first row, a matrix against its order).
    #[error("shape mismatch: {what} has {got} entries, expected {expected}")]
    Shape {
        what: &'static str,
        got: usize,
        expected: usize,
    },
    /// Fewer rows than unknowns (or no unknowns at all).
    #[error("{rows} rows for {unknowns} unknowns")]
    TooFewRows { rows: usize, unknowns: usize },
    /// A weight is negative or not finite.
    #[error("weight {index} is {value}: expected finite and ≥ 0")]
    BadWeight { index: usize, value: f64 },
    /// The (normal) matrix is singular to working precision.
    #[error("singular {n}×{n} system")]
    Singular { n: usize },
    /// A distribution parameter (degrees of freedom, probability) is out of range.
    #[error("invalid argument `{what}` = {value}")]
    BadArgument { what: &'static str, value: f64 },
}
