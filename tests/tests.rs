//! The integration test binary: one module per area (ripgrep-style). Unit tests live inline.

mod cli;
mod design;
mod discover;
mod hostile;
mod identify;
mod independent;
mod ingest;
mod maps;
mod real;
mod real_decays;
mod shard;
mod suite;
mod twin_decays;
mod unexplained;
mod util;
