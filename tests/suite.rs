//! The suite's own rules, read from the test sources: every ignored test says which kind it is
//! (a survey, a known failure, the slow set), and one moved out of the default suite, or known to
//! fail, names default tests that still check its property. Tests moved to the slow set as the
//! suite outgrew CI's 15 minutes named their default stand-ins; later moves and failures left 23
//! of those names pointing at tests that no longer ran by default (an offset "named on" a known
//! failure, breakaways "named on" another slow-set draw), which nothing caught.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A `#[test]` function: where it is, and its `#[ignore]` reason if it has one.
#[derive(Debug)]
struct TestFn {
    file: PathBuf,
    ignore: Option<String>,
}

/// The `#[test]` functions of one source file, by name: a `fn` line after a run of attribute lines
/// holding `#[test]`, and the names an `independent! { name: "…", base; … }` table makes.
fn tests_in(file: &Path, out: &mut BTreeMap<String, TestFn>) {
    let src = std::fs::read_to_string(file).unwrap();
    let mut attrs: Vec<&str> = Vec::new();
    let mut in_table = false;
    for line in src.lines() {
        let t = line.trim();
        if in_table {
            if t == "}" {
                in_table = false;
            } else if let Some((name, _)) = t.split_once(": \"") {
                out.insert(
                    name.to_string(),
                    TestFn {
                        file: file.to_path_buf(),
                        ignore: None,
                    },
                );
            }
            continue;
        }
        if t == "independent! {" {
            in_table = true;
        } else if t.starts_with("#[") {
            attrs.push(t);
        } else if let Some(rest) = t.strip_prefix("fn ").or_else(|| t.strip_prefix("pub fn ")) {
            if attrs.contains(&"#[test]") {
                let name = rest.split(['(', '<']).next().unwrap().to_string();
                let ignore = attrs.iter().find_map(|a| {
                    a.strip_prefix("#[ignore").map(|r| {
                        r.trim_start_matches(" = \"")
                            .trim_end_matches("\"]")
                            .to_string()
                    })
                });
                out.insert(
                    name,
                    TestFn {
                        file: file.to_path_buf(),
                        ignore,
                    },
                );
            }
            attrs.clear();
        } else if !t.starts_with("//") {
            attrs.clear();
        }
    }
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Every test of the workspace (integration tests under `tests/`, unit and crate tests under
/// `crates/`), by name.
fn all_tests() -> BTreeMap<String, TestFn> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&root.join("tests"), &mut files);
    rust_files(&root.join("crates"), &mut files);
    let mut tests = BTreeMap::new();
    for f in files {
        tests_in(&f, &mut tests);
    }
    tests
}

/// The test names a reason mentions (`module::name` or `name`), in order.
fn named_tests<'a>(reason: &str, tests: &'a BTreeMap<String, TestFn>) -> Vec<&'a str> {
    reason
        .split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
        .filter_map(|tok| tok.rsplit("::").next())
        .filter_map(|name| tests.get_key_value(name).map(|(k, _)| k.as_str()))
        .collect()
}

#[test]
fn the_parser_finds_this_files_tests_and_the_independent_table() {
    let tests = all_tests();
    for name in [
        "the_parser_finds_this_files_tests_and_the_independent_table",
        "issue_12_independent_i06_encoder_offset",
        "issue_12_independent_i11_linear_truth_dry",
    ] {
        let t = tests
            .get(name)
            .unwrap_or_else(|| panic!("{name} not found"));
        assert!(t.ignore.is_none(), "{name}: {t:?}");
    }
    let ignored = tests.values().filter(|t| t.ignore.is_some()).count();
    assert!(ignored >= 50, "only {ignored} ignored tests found");
    assert_eq!(
        named_tests(
            "checks it on independent::issue_12_independent_i06_encoder_offset and nowhere else",
            &tests
        ),
        ["issue_12_independent_i06_encoder_offset"]
    );
}

#[test]
fn every_ignored_test_says_whether_it_is_a_survey_a_known_failure_or_the_slow_set() {
    let wrong: Vec<String> = all_tests()
        .into_iter()
        .filter_map(|(name, t)| {
            let reason = t.ignore?;
            let kind = ["survey", "known failure", "slow set"]
                .iter()
                .any(|k| reason.starts_with(k));
            (!kind).then(|| format!("{} {name}: {reason:?}", t.file.display()))
        })
        .collect();
    assert!(wrong.is_empty(), "{wrong:#?}");
}

#[test]
fn a_slow_set_test_or_a_known_failure_names_default_tests_that_check_its_property() {
    let tests = all_tests();
    let mut wrong = Vec::new();
    for (name, t) in &tests {
        let Some(reason) = &t.ignore else { continue };
        if !(reason.starts_with("slow set") || reason.starts_with("known failure")) {
            continue;
        }
        let named: Vec<&str> = named_tests(reason, &tests)
            .into_iter()
            .filter(|n| n != name)
            .collect();
        // A known failure says what fails and why; one moved for time must say what stands in.
        if named.is_empty() && reason.starts_with("slow set") {
            wrong.push(format!("{name}: names no test"));
        }
        for n in named {
            if let Some(r) = &tests[n].ignore {
                wrong.push(format!(
                    "{name}: names {n}, itself ignored ({})",
                    r.chars().take(40).collect::<String>()
                ));
            }
        }
    }
    assert!(wrong.is_empty(), "{} wrong: {wrong:#?}", wrong.len());
}
