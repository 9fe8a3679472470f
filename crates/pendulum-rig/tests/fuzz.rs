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

// ---- Issue 13 item 2: blocks off the timeline of any length, through the second reading. ----

/// `n` rows every 5 ms from `t0`: a swing of ±500 counts and a table acceleration.
fn swing_rows(n: usize, t0: u32) -> Vec<(u32, i16, [i16; 3])> {
    (0..n)
        .map(|k| {
            let t = k as f64 * 0.005;
            let enc = (500.0 * (std::f64::consts::TAU * 1.5 * t).sin()).round() as i16;
            let az = 8192 + (2000.0 * (std::f64::consts::TAU * 1.54 * t).cos()).round() as i16;
            (t0.wrapping_add(5000 * k as u32), enc, [12, -7, az])
        })
        .collect()
}

/// Reads a capture as ingest does (again with the plan while a reading finds blocks off the
/// timeline): the kept encoder samples `(raw t, raw count, unwrapped t)` and the stats.
fn read_planned(bytes: &[u8], sd: bool) -> (Vec<(u32, i16, u64)>, pendulum_rig::IngestStats) {
    use pendulum_rig::{SdReader, SerialReader, TimelinePlan};
    let mut plan: Option<TimelinePlan> = None;
    let o = ReadOptions::default();
    for reading in 1..=pendulum_rig::capture::MAX_READINGS {
        let mut out = Vec::new();
        let mut push = |s: Sample| {
            if let Sample::Encoder(e) = s {
                out.push((e.t_us_raw, e.count_raw, e.t_us));
            }
        };
        let (stats, more) = if sd {
            let mut r = SdReader::new(bytes, "f.bin", o).unwrap();
            if let Some(p) = &plan {
                r.set_timeline_plan(p.clone());
            }
            while let Some(s) = r.next_sample().unwrap() {
                push(s);
            }
            (r.stats().clone(), r.timeline_plan())
        } else {
            let mut r = SerialReader::new(bytes, "f.csv", o).unwrap();
            if let Some(p) = &plan {
                r.set_timeline_plan(p.clone());
            }
            while let Some(s) = r.next_sample().unwrap() {
                push(s);
            }
            (r.stats().clone(), r.timeline_plan())
        };
        match more {
            Some(m) if reading < pendulum_rig::capture::MAX_READINGS => match &mut plan {
                Some(p) => p.merge(m),
                None => plan = Some(m),
            },
            _ => return (out, stats),
        }
    }
    unreachable!()
}

proptest! {
    #![proptest_config(fixed(24))]

    /// One block of any length up to a third of the run (a few records to far beyond the
    /// 512-record read-ahead), stamped seconds to half an hour ahead or behind, inserted anywhere
    /// after the first 100 rows: every good record is kept on its own time base and the block's
    /// records are all dropped as off the timeline. With several such blocks, or blocks that
    /// replaced good rows, the readers never keep a record that was not written, and time
    /// always increases.
    #[test]
    fn blocks_off_the_timeline_never_win(
        n in 1500usize..4000,
        sd in any::<bool>(),
        blocks in prop::collection::vec(
            (0.05f64..0.95, 0.001f64..0.33, prop_oneof![-1800i64..-5, 5i64..1800], any::<bool>()),
            1..3,
        ),
    ) {
        use pendulum_rig::{Header, SdWriter, SerialWriter};
        let good = swing_rows(n, 2_000_000_000);
        let mut rows = good.clone();
        let mut shifted_total = 0usize;
        let single_insert = blocks.len() == 1 && !blocks[0].3;
        // Insert from the end so earlier positions stay valid.
        let mut bs = blocks.clone();
        bs.sort_by(|a, b| b.0.total_cmp(&a.0));
        for &(at, len, shift_s, replace) in &bs {
            let at = 100 + ((n - 200) as f64 * at) as usize;
            let len = ((n as f64 * len) as usize).max(1).min(n - at);
            let block: Vec<_> = good[at..at + len]
                .iter()
                .map(|&(t, e, a)| (t.wrapping_add((shift_s * 1_000_000) as u32), e, a))
                .collect();
            let end = if replace { at + len } else { at };
            rows.splice(at..end, block);
            shifted_total += len;
        }
        let bytes = if sd {
            let mut w = SdWriter::new(
                Vec::new(),
                &Header::sd_v2().with("encoder_hz", "200").with("accel_hz", "200"),
            )
            .unwrap();
            for &(t, e, a) in &rows {
                w.write_encoder(t, e).unwrap();
                w.write_accel(t, a).unwrap();
            }
            w.finish().unwrap()
        } else {
            let mut w = SerialWriter::new(Vec::new(), &Header::serial_v1()).unwrap();
            for &(t, e, a) in &rows {
                w.write_sample(t, e, a).unwrap();
            }
            w.finish().unwrap()
        };
        let (kept, st) = read_planned(&bytes, sd);
        let written: std::collections::HashSet<(u32, i16)> = rows.iter().map(|r| (r.0, r.1)).collect();
        prop_assert!(kept.iter().all(|k| written.contains(&(k.0, k.1))), "a record not written was kept");
        prop_assert!(kept.windows(2).all(|w| w[0].2 < w[1].2), "time must increase");
        if single_insert {
            let want: Vec<(u32, i16)> = good.iter().map(|r| (r.0, r.1)).collect();
            let got: Vec<(u32, i16)> = kept.iter().map(|k| (k.0, k.1)).collect();
            prop_assert_eq!(got.len(), want.len(), "{:?}", st.warnings);
            prop_assert!(got == want, "every good record kept");
            let per_row = if sd { 2 } else { 1 };
            prop_assert_eq!(st.off_timeline, (shifted_total * per_row) as u64);
            prop_assert_eq!((st.gap_count, st.new_segments), (0, 0));
        }
    }
}
