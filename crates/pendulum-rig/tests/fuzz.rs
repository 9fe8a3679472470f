//! Fuzzing of the two readers `formats.rs` does not cover (issue 13: a fuzz target per reader):
//! the generic time-series reader and the campaign parser. Bounded proptest runs (fixed seed
//! unless `PROPTEST_RNG_SEED` is set) so that CI runs them; the capture readers' fuzzing is in
//! `formats.rs`, the MCAP reader's every-byte corruption tests in `pendulum-log`.

use std::collections::BTreeMap;
use std::path::Path;

use pendulum_rig::capture::{ReadOptions, Sample};
use pendulum_rig::timeseries::{TimeseriesReader, TimeseriesSpec};
use pendulum_rig::Campaign;
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed};

fn fixed(cases: u32) -> Config {
    Config {
        cases,
        rng_seed: match std::env::var("PROPTEST_RNG_SEED") {
            Ok(s) => RngSeed::Fixed(s.parse().unwrap_or(0x5eed_2026)),
            Err(_) => RngSeed::Fixed(0x5eed_2026),
        },
        failure_persistence: None,
        ..Config::default()
    }
}

fn spec(keys: &str) -> TimeseriesSpec {
    let t: toml::Table = toml::from_str(keys).unwrap();
    let keys: BTreeMap<String, toml::Value> = t.into_iter().collect();
    TimeseriesSpec::from_keys(&keys, Path::new("c/campaign.toml"), "r1").unwrap()
}

/// Reads everything; a damaged line is data (skipped and counted), never an error or a panic.
/// Returns the encoder samples' times.
fn read_all(text: &[u8], s: TimeseriesSpec) -> Option<Vec<u64>> {
    let mut r = TimeseriesReader::new(text, "x.csv", s, ReadOptions::default()).ok()?;
    let mut t = Vec::new();
    while let Some(x) = r.next_sample().expect("damage is data, not an error") {
        if let Sample::Encoder(e) = x {
            t.push(e.t_us);
        }
    }
    Some(t)
}

/// A clean file: `n` rows at 1 kHz (optionally with bursty stamps, 16 rows per stamp as a host
/// reading a serial buffer every 16 ms writes them), angle in counts.
fn clean_csv(n: usize, bursty: bool) -> String {
    let mut s = String::from("t_s,count\n");
    for i in 0..n {
        let t = if bursty {
            (i / 16) as f64 * 0.016
        } else {
            i as f64 * 0.001
        };
        let count = (300.0 * (i as f64 * 0.02).cos()).round() as i64;
        s.push_str(&format!("{t:.4},{count}\n"));
    }
    s
}

const TS_KEYS: &str = "time_column = \"t_s\"\nangle_column = \"count\"\nangle_unit = \"counts\"\ncounts_per_rev = 4096\nhanging_angle = 0";

proptest! {
    #![proptest_config(fixed(192))]

    /// Any bytes after a good column line: no panic, no error from `next_sample`, and the kept
    /// samples' times never go backwards.
    #[test]
    fn timeseries_random_bodies_never_panic(body in prop::collection::vec(any::<u8>(), 0..4000)) {
        let mut text = b"t_s,count\n".to_vec();
        const ALPHABET: &[u8] = b"0123456789.,-e\n\r \t#x";
        text.extend(body.iter().map(|b| ALPHABET[usize::from(*b) % ALPHABET.len()]));
        if let Some(t) = read_all(&text, spec(TS_KEYS)) {
            prop_assert!(t.windows(2).all(|w| w[0] <= w[1]), "time went backwards");
        }
        // Raw bytes too (invalid UTF-8, NULs, no line ends).
        let _ = read_all(&body, spec(TS_KEYS));
    }

    /// A clean file (steady or bursty stamps) with bytes overwritten, deleted or duplicated:
    /// no panic, no error, times non-decreasing, and never more samples than rows written.
    #[test]
    fn timeseries_damaged_files_never_invent_rows(
        n in 50usize..1500,
        bursty in any::<bool>(),
        edits in prop::collection::vec((any::<usize>(), 0u8..3, any::<u8>()), 0..6),
    ) {
        let mut bytes = clean_csv(n, bursty).into_bytes();
        if edits.is_empty() && !bursty {
            // The undamaged file reads whole (the check that the reader sees the rows at all).
            prop_assert_eq!(read_all(&bytes, spec(TS_KEYS)).map(|t| t.len()), Some(n));
        }
        for (at, kind, b) in edits {
            if bytes.len() <= 10 {
                break;
            }
            // Keep the column line: without it the file is refused, not read.
            let at = 10 + at % (bytes.len() - 10);
            match kind {
                0 => bytes[at] = b,
                1 => {
                    bytes.remove(at);
                }
                _ => {
                    let end = (at + 40).min(bytes.len());
                    let chunk = bytes[at..end].to_vec();
                    bytes.splice(at..at, chunk);
                }
            }
        }
        if let Some(t) = read_all(&bytes, spec(TS_KEYS)) {
            prop_assert!(t.windows(2).all(|w| w[0] <= w[1]), "time went backwards");
            let rows = bytes.iter().filter(|&&c| c == b'\n').count();
            prop_assert!(t.len() <= rows, "{} samples from {rows} lines", t.len());
        }
    }

    /// A campaign.toml with characters overwritten or removed: parsing returns a campaign or an
    /// error, never panics; every id of a parsed campaign is a safe file name.
    #[test]
    fn campaign_mutations_never_panic(
        edits in prop::collection::vec((any::<usize>(), any::<bool>(), prop::sample::select(
            vec!['"', '=', '[', ']', '\n', '.', '/', '\\', '0', 'x', ' ', '#', '\u{1b}', '-'],
        )), 1..10),
    ) {
        let good = "name = \"fuzz\"\n[rig]\nm_kg = 1.46\nl_m = 0.265\ncrank_r_m = 0.0725\nrod_L_m = 0.575\nr_b_m = 0.01225\n\n[[run]]\nid = \"r01\"\nfile = \"r01.csv\"\nomega_hz = 1.5\nrole = \"identify\"\n\n[[run]]\nid = \"r02\"\nfile = \"r02.bin\"\nrole = \"validate\"\nformat = \"sd-v2\"\n";
        let mut chars: Vec<char> = good.chars().collect();
        for (at, replace, c) in edits {
            let at = at % chars.len();
            if replace {
                chars[at] = c;
            } else {
                chars.remove(at);
            }
        }
        let text: String = chars.into_iter().collect();
        if let Ok(c) = Campaign::parse(&text, "fuzz/campaign.toml") {
            for r in &c.runs {
                prop_assert!(
                    !r.id.is_empty()
                        && !r.id.contains(['/', '\\', '\u{1b}'])
                        && r.id != ".."
                        && r.id != ".",
                    "unsafe id {:?} accepted", r.id
                );
            }
        }
    }
}

/// The harness reads what it is given: a clean file, steady and bursty, reads every row.
#[test]
fn clean_files_read_whole() {
    assert_eq!(
        read_all(clean_csv(800, false).as_bytes(), spec(TS_KEYS)).map(|t| t.len()),
        Some(800)
    );
    let bursty =
        read_all(clean_csv(800, true).as_bytes(), spec(TS_KEYS)).expect("bursty file read");
    assert_eq!(bursty.len(), 800);
    assert!(
        bursty.windows(2).all(|w| w[0] < w[1]),
        "bursty stamps rebuilt strictly increasing"
    );
}
