//! The integration test binary: one module per area (ripgrep-style). Unit tests live inline.

mod cli;
mod util;
