//! Helpers shared by the integration tests.

use std::path::Path;
use std::process::{Command, Output};

/// The `pendulum` binary under test.
pub fn pendulum() -> Command {
    Command::new(env!("CARGO_BIN_EXE_pendulum"))
}

/// Runs the binary and returns its output, panicking with stderr on a spawn failure.
pub fn run(args: &[&str]) -> Output {
    pendulum().args(args).output().expect("spawn pendulum")
}

/// Whether the independent Python readers are importable; CI requires them
/// (`PENDULUM_REQUIRE_PYTHON=1`), a developer machine may lack them (loud skip).
pub fn python_has(module: &str) -> bool {
    let ok = Command::new("python3")
        .args(["-c", &format!("import {module}")])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !ok {
        if std::env::var("PENDULUM_REQUIRE_PYTHON").as_deref() == Ok("1") {
            panic!("python3 module {module} is required (PENDULUM_REQUIRE_PYTHON=1)");
        }
        eprintln!("\n*** SKIP: python3 module {module} not installed; the independent-reader check did not run ***\n");
    }
    ok
}

/// Runs a checker script under tests/python with arguments; panics with its output on failure.
pub fn python_check(script: &str, args: &[&Path]) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/python")
        .join(script);
    let out = Command::new("python3")
        .arg(&path)
        .args(args)
        .output()
        .expect("spawn python3");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{script} failed:\n{text}");
}
