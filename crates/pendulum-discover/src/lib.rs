//! Discovery: show where the simulation departs from the rig (weak-form equation error), name
//! the catalogue effect responsible (or say `unexplained`), extend the model, and measure the
//! gain on runs the fit never saw.

mod agreement;
pub mod damping;
pub mod discover;
mod drift;
pub mod envelope;
mod heldout;
mod looks;
mod readings;
mod residual;
pub mod screen;
pub mod sparse;
mod trajectories;
mod unexplained;
pub mod weak;

pub use damping::{DampingCheck, DampingVerdict};
pub use discover::{discover, DiagnosisRow, DiscoverConfig, Discovery};
pub use residual::campaign_variables;
pub use screen::Base;
