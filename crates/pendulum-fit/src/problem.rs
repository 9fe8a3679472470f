//! What an optimiser needs from a problem, and nothing else: its box and a cost.

/// Result of one cost evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cost {
    /// The full cost.
    Exact(f64),
    /// The evaluation stopped once the cost provably exceeded the caller's `bound`; the value is
    /// a lower bound of the true cost and must be `> bound` (a tie would select the point).
    AtLeast(f64),
}

impl Cost {
    /// The carried number: the cost, or a lower bound of it.
    pub fn value(self) -> f64 {
        match self {
            Cost::Exact(v) | Cost::AtLeast(v) => v,
        }
    }

    /// Whether the evaluation ran to completion.
    pub fn is_exact(self) -> bool {
        matches!(self, Cost::Exact(_))
    }
}

/// A bounded minimisation problem. `Sync` because trials are costed in parallel.
pub trait Problem: Sync {
    /// Number of variables.
    fn dim(&self) -> usize;

    /// Per-variable box `(lo, hi)`, finite with `lo < hi`; `dim()` entries.
    fn bounds(&self) -> Vec<(f64, f64)>;

    /// Cost of `x` (always inside the bounds).
    ///
    /// `bound`: the caller only needs to know whether `cost <= bound`, so the problem MAY stop
    /// early (e.g. a sum of non-negative residuals whose partial sum already exceeds it) and
    /// return [`Cost::AtLeast`]`(v)` with `v > bound`. `f64::INFINITY` means the exact value is
    /// needed. An exact cost must not depend on `bound`, otherwise early abandon would change
    /// the optimiser's trajectory.
    fn cost(&self, x: &[f64], bound: f64) -> Cost;
}

/// Lets callers hand a borrowed problem to the driver and keep using it afterwards.
impl<P: Problem + ?Sized> Problem for &P {
    fn dim(&self) -> usize {
        (**self).dim()
    }
    fn bounds(&self) -> Vec<(f64, f64)> {
        (**self).bounds()
    }
    fn cost(&self, x: &[f64], bound: f64) -> Cost {
        (**self).cost(x, bound)
    }
}
