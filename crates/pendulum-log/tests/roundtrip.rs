//! Write → read round trips, and the ways a run file must refuse to be wrong.

mod common;

use std::collections::BTreeMap;
use std::ops::ControlFlow;

use common::{fixture, write, Fixture, FIRST_T_US, STARTED};
use pendulum_log::{
    for_each_message, parse_rfc3339_utc_ns, read_run, EncoderMsg, LogError, RunLog, RunLogOptions,
    RunMessage, SimulatedMsg, TOPIC_ACCEL, TOPIC_ENCODER, TOPIC_INGEST_STATS, TOPIC_SIMULATED,
};

fn assert_same_bits(a: f64, b: f64, what: &str) {
    assert_eq!(a.to_bits(), b.to_bits(), "{what}: {a:e} vs {b:e}");
}

fn assert_run_equals(run: &RunLog, fx: &Fixture) {
    assert_eq!(run.encoder, fx.encoder);
    assert_eq!(run.accel, fx.accel);
    assert_eq!(run.simulated, fx.simulated);
    // PartialEq on f64 hides -0.0 vs 0.0 and nothing else; check bits too.
    for (a, b) in run.encoder.iter().zip(&fx.encoder) {
        assert_same_bits(a.t_s, b.t_s, "encoder t_s");
        assert_same_bits(a.theta_rad, b.theta_rad, "encoder theta_rad");
    }
    for (a, b) in run.accel.iter().zip(&fx.accel) {
        assert_same_bits(a.az_m_s2, b.az_m_s2, "accel az_m_s2");
        assert_same_bits(a.t_s, b.t_s, "accel t_s");
    }
    for (a, b) in run.simulated.iter().zip(&fx.simulated) {
        assert_same_bits(a.residual_rad, b.residual_rad, "sim residual_rad");
        assert_same_bits(a.theta_dot_rad_s, b.theta_dot_rad_s, "sim theta_dot_rad_s");
    }
    assert_eq!(run.metadata, fx.metadata);
    assert_eq!(run.stats.as_ref(), Some(&fx.stats));
    assert!(run.other_topics.is_empty());
}

#[test]
fn round_trip_board_clock() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r01.mcap");
    let fx = fixture(3000, 200);
    let summary = write(&fx, &path, &RunLogOptions::new().library("pendulum/0.1")).unwrap();

    assert_eq!(summary.path, path);
    assert_eq!(
        summary.messages,
        BTreeMap::from([
            (TOPIC_ENCODER.to_string(), 3000),
            (TOPIC_ACCEL.to_string(), 600),
            (TOPIC_INGEST_STATS.to_string(), 1),
            (TOPIC_SIMULATED.to_string(), 200),
        ])
    );
    assert_eq!(summary.bytes, std::fs::metadata(&path).unwrap().len());
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(names, ["r01.mcap"], "no temporary file left behind");

    let run = read_run(&path).unwrap();
    assert_run_equals(&run, &fx);
    assert_eq!(run.library, "pendulum/0.1");
    assert_eq!(run.path, path);
    // Board clock: log time = unwrapped t_us · 1000 (beyond u32 after the wrap).
    let expected: Vec<u64> = fx.encoder.iter().map(|m| m.t_us * 1000).collect();
    assert_eq!(run.encoder_log_time_ns, expected);
    assert!(fx.encoder.last().unwrap().t_us > u64::from(u32::MAX));
    let expected: Vec<u64> = fx.accel.iter().map(|m| m.t_us * 1000).collect();
    assert_eq!(run.accel_log_time_ns, expected);
    let expected: Vec<u64> = fx
        .simulated
        .iter()
        .map(|m| FIRST_T_US * 1000 + (m.t_s * 1e9).round() as u64)
        .collect();
    assert_eq!(run.simulated_log_time_ns, expected);
}

#[test]
fn round_trip_wall_clock_uncompressed_small_chunks() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r02.mcap");
    let fx = fixture(2000, 50);
    let start_ns = parse_rfc3339_utc_ns(STARTED).unwrap();
    let opts = RunLogOptions::new()
        .compression_zstd(false)
        .chunk_size(4096)
        .start_ns(Some(start_ns));
    write(&fx, &path, &opts).unwrap();
    let run = read_run(&path).unwrap();
    assert_run_equals(&run, &fx);
    let expected: Vec<u64> = fx
        .encoder
        .iter()
        .map(|m| start_ns + (m.t_us - FIRST_T_US) * 1000)
        .collect();
    assert_eq!(run.encoder_log_time_ns, expected);
    assert_eq!(run.encoder_log_time_ns[0], 1_773_483_725_000_000_000);
    let expected: Vec<u64> = fx
        .accel
        .iter()
        .map(|m| start_ns + (m.t_us - FIRST_T_US) * 1000)
        .collect();
    assert_eq!(run.accel_log_time_ns, expected);

    // The streaming reader sees the same messages.
    let (mut enc, mut acc, mut sim, mut stats) = (vec![], vec![], vec![], vec![]);
    for_each_message(&path, |m| {
        match m {
            RunMessage::Encoder { msg, .. } => enc.push(msg),
            RunMessage::Accel { msg, .. } => acc.push(msg),
            RunMessage::Simulated { msg, .. } => sim.push(msg),
            RunMessage::Stats {
                stats: s,
                log_time_ns,
            } => {
                assert_eq!(log_time_ns, start_ns, "stats stamped at the run's start");
                stats.push(s)
            }
        }
        ControlFlow::Continue(())
    })
    .unwrap();
    assert_eq!(
        (enc, acc, sim, stats),
        (run.encoder, run.accel, run.simulated, vec![fx.stats])
    );

    let mut seen = 0;
    for_each_message(&path, |_| {
        seen += 1;
        if seen == 10 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    })
    .unwrap();
    assert_eq!(seen, 10);
}

#[test]
fn set_start_ns_matches_option_and_rejects_late_change() {
    let dir = tempfile::tempdir().unwrap();
    let fx = fixture(10, 0);
    let start = parse_rfc3339_utc_ns(STARTED).unwrap();
    let path = dir.path().join("a.mcap");
    let mut w = RunLogOptions::new().create(&path).unwrap();
    w.set_start_ns(Some(start)).unwrap();
    w.write_encoder(&fx.encoder[0]).unwrap();
    w.set_start_ns(Some(start)).unwrap(); // unchanged: fine
    let err = w.set_start_ns(None).unwrap_err();
    assert!(
        matches!(err, LogError::StartAfterFirstMessage { .. }),
        "{err}"
    );
    w.finish().unwrap();
    assert_eq!(read_run(&path).unwrap().encoder_log_time_ns, [start]);
}

#[test]
fn empty_run_has_encoder_and_accel_channels() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("empty.mcap");
    let summary = RunLogOptions::new()
        .create(&path)
        .unwrap()
        .finish()
        .unwrap();
    assert_eq!(
        summary.messages,
        BTreeMap::from([(TOPIC_ENCODER.to_string(), 0), (TOPIC_ACCEL.to_string(), 0)])
    );
    let run = read_run(&path).unwrap();
    assert!(run.encoder.is_empty() && run.accel.is_empty() && run.stats.is_none());
}

#[test]
fn out_of_order_is_rejected_per_channel() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ooo.mcap");
    let fx = fixture(20, 0);
    let mut w = RunLogOptions::new().create(&path).unwrap();
    w.write_encoder(&fx.encoder[5]).unwrap();
    w.write_encoder(&fx.encoder[5]).unwrap(); // equal time is allowed
                                              // Another channel may go back in time: order is per channel.
    w.write_accel(&fx.accel[0]).unwrap();
    let err = w.write_encoder(&fx.encoder[4]).unwrap_err();
    match &err {
        LogError::OutOfOrder {
            topic,
            index,
            log_time_ns,
            previous_ns,
            path: p,
        } => {
            assert_eq!(*topic, TOPIC_ENCODER);
            assert_eq!(*index, 2);
            assert!(log_time_ns < previous_ns);
            assert_eq!(p, &path);
        }
        other => panic!("expected OutOfOrder, got {other:?}"),
    }
    assert!(err.to_string().contains("/encoder"), "{err}");
    // The writer is still usable after a rejected message.
    w.write_encoder(&fx.encoder[6]).unwrap();
    let sim = |t_s| SimulatedMsg {
        t_s,
        theta_rad: 0.0,
        theta_dot_rad_s: 0.0,
        residual_rad: 0.0,
    };
    w.write_simulated(&sim(1.0)).unwrap();
    assert!(matches!(
        w.write_simulated(&sim(0.5)).unwrap_err(),
        LogError::OutOfOrder {
            topic: TOPIC_SIMULATED,
            ..
        }
    ));
    w.finish().unwrap();
    assert_eq!(read_run(&path).unwrap().encoder.len(), 3);
}

#[test]
fn bad_values_are_rejected_with_structure() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.mcap");
    let fx = fixture(20, 0);
    let mut w = RunLogOptions::new().create(&path).unwrap();
    let nan = EncoderMsg {
        theta_rad: f64::NAN,
        ..fx.encoder[0]
    };
    assert!(matches!(
        w.write_encoder(&nan).unwrap_err(),
        LogError::NonFinite {
            topic: TOPIC_ENCODER,
            field: "theta_rad",
            ..
        }
    ));
    w.write_encoder(&fx.encoder[0]).unwrap();
    // t_s that disagrees with t_us (relative to the same first sample) by more than 1 µs.
    let skewed = EncoderMsg {
        t_s: fx.encoder[1].t_s + 5e-6,
        ..fx.encoder[1]
    };
    assert!(matches!(
        w.write_encoder(&skewed).unwrap_err(),
        LogError::InconsistentTime {
            topic: TOPIC_ENCODER,
            ..
        }
    ));
    assert!(matches!(
        w.write_stats(&serde_json::json!([1, 2])).unwrap_err(),
        LogError::Unexpected { .. }
    ));
    w.write_stats(&serde_json::json!({"format": "sd-v2"}))
        .unwrap();
    assert!(matches!(
        w.write_stats(&serde_json::json!({})).unwrap_err(),
        LogError::DuplicateStats { .. }
    ));
    w.write_metadata("run", BTreeMap::new()).unwrap();
    assert!(matches!(
        w.write_metadata("run", BTreeMap::new()).unwrap_err(),
        LogError::DuplicateMetadata { .. }
    ));
    let before_start = SimulatedMsg {
        t_s: -1e6,
        theta_rad: 0.0,
        theta_dot_rad_s: 0.0,
        residual_rad: 0.0,
    };
    let mut w2 = RunLogOptions::new()
        .create(&dir.path().join("b.mcap"))
        .unwrap();
    assert!(matches!(
        w2.write_simulated(&before_start).unwrap_err(),
        LogError::TimeOutOfRange { .. }
    ));
    drop(w2);
    w.finish().unwrap();
    assert!(matches!(
        RunLogOptions::new()
            .create(std::path::Path::new("/"))
            .err()
            .unwrap(),
        LogError::InvalidPath { .. }
    ));
}

/// Two writers of the same run in one folder (two `pendulum ingest` into one --out, script 06
/// of issue 13): each has its own temporary file, so one failing (dropped) neither deletes nor
/// truncates the other's, and the survivor's finish still renames its own file into place.
/// Before, both used `.r01.mcap.tmp`: the drop deleted the other's data and its finish failed.
#[test]
fn issue_13_two_writers_of_one_run_keep_their_own_temporary_files() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r01.mcap");
    let fx = fixture(100, 0);
    let mut a = RunLogOptions::new().create(&path).unwrap();
    let mut b = RunLogOptions::new().create(&path).unwrap();
    assert_ne!(a.tmp_path(), b.tmp_path());
    for m in &fx.encoder {
        a.write_encoder(m).unwrap();
        b.write_encoder(m).unwrap();
    }
    let b_tmp = b.tmp_path().to_path_buf();
    drop(a); // fails half-way
    assert!(
        b_tmp.exists(),
        "the other writer's temporary file was deleted"
    );
    let summary = b.finish().unwrap();
    assert_eq!(summary.messages["/encoder"], 100);
    let back = read_run(&path).unwrap();
    assert_eq!(back.encoder.len(), 100);
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["r01.mcap"]);
}

#[test]
fn dropped_writer_leaves_nothing_and_keeps_the_previous_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r01.mcap");
    let fx = fixture(100, 0);

    {
        let mut w = RunLogOptions::new().create(&path).unwrap();
        assert!(w.tmp_path().exists());
        let tmp_name = w
            .tmp_path()
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        assert!(
            tmp_name.starts_with(".r01.mcap.") && tmp_name.ends_with(".tmp"),
            "{tmp_name}"
        );
        for m in &fx.encoder {
            w.write_encoder(m).unwrap();
        }
        // dropped without finish(), as after an early `?`
    }
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "no file at all"
    );

    // A finished run, then a failed rewrite: the old file stays intact.
    write(&fx, &path, &RunLogOptions::new()).unwrap();
    let before = std::fs::read(&path).unwrap();
    {
        let mut w = RunLogOptions::new().create(&path).unwrap();
        w.write_encoder(&fx.encoder[0]).unwrap();
    }
    assert_eq!(std::fs::read(&path).unwrap(), before);
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn flipped_byte_in_a_chunk_is_an_error() {
    for zstd in [true, false] {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("r01.mcap");
        let fx = fixture(500, 0);
        write(&fx, &path, &RunLogOptions::new().compression_zstd(zstd)).unwrap();
        let good = std::fs::read(&path).unwrap();
        let (start, len) = common::first_chunk_records(&good).expect("a chunk");
        for at in [start, start + len / 3, start + len / 2, start + len - 1] {
            for mask in [0x01u8, 0x10, 0xff] {
                let mut bad = good.clone();
                bad[at] ^= mask;
                std::fs::write(&path, &bad).unwrap();
                let err = read_run(&path).expect_err("corrupt chunk must not read");
                assert!(
                    matches!(
                        err,
                        LogError::CrcMismatch {
                            section: "chunk",
                            ..
                        } | LogError::Corrupt { .. }
                    ),
                    "zstd={zstd} at={at}: {err:?}"
                );
                assert!(err.to_string().contains(&*path.to_string_lossy()), "{err}");
                // The streaming reader never hands out a message from the corrupt chunk.
                let mut n = 0;
                assert!(for_each_message(&path, |_| {
                    n += 1;
                    ControlFlow::Continue(())
                })
                .is_err());
                assert_eq!(
                    n, 0,
                    "zstd={zstd} at={at}: messages from a corrupt first chunk"
                );
            }
        }
        // In an uncompressed chunk a flipped digit is still valid JSON: only the CRC catches it.
        if !zstd {
            let mut bad = good.clone();
            let digit = (start..start + len).find(|&i| bad[i] == b'7').unwrap();
            bad[digit] = b'8';
            std::fs::write(&path, &bad).unwrap();
            assert!(matches!(
                read_run(&path).unwrap_err(),
                LogError::CrcMismatch {
                    section: "chunk",
                    ..
                }
            ));
        }
    }
}

/// A single-byte corruption anywhere in a file either fails or (where the byte is not covered by
/// any CRC and does not matter) reads back identical data. Every byte of the file's head and
/// tail (header, footer, summary offsets), every 3rd byte between (each read is a full read).
#[test]
fn any_flipped_byte_errors_or_reads_identically() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r01.mcap");
    let fx = fixture(40, 5);
    write(&fx, &path, &RunLogOptions::new().chunk_size(512)).unwrap();
    let good = std::fs::read(&path).unwrap();
    let reference = read_run(&path).unwrap();
    let mut silent = 0;
    for at in (0..good.len()).filter(|&i| i < 256 || i + 512 >= good.len() || i % 3 == 0) {
        let mut bad = good.clone();
        bad[at] ^= 0x04;
        std::fs::write(&path, &bad).unwrap();
        match read_run(&path) {
            Err(_) => {}
            Ok(run) => {
                assert_eq!(
                    run,
                    reference,
                    "byte {at} of {} changed the data silently",
                    good.len()
                );
                silent += 1;
            }
        }
    }
    eprintln!(
        "{} bytes flipped: {silent} harmless, the rest errors",
        good.len()
    );
}

#[test]
fn truncated_file_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r07.mcap");
    // Small, since every cut reads the file again (quadratic).
    let fx = fixture(60, 5);
    write(&fx, &path, &RunLogOptions::new().chunk_size(1024)).unwrap();
    let good = std::fs::read(&path).unwrap();
    for cut in (0..good.len()).filter(|&i| i < 256 || i + 512 >= good.len() || i % 3 == 0) {
        std::fs::write(&path, &good[..cut]).unwrap();
        let err = read_run(&path).expect_err("truncated file must not read");
        assert!(err.to_string().contains("r07.mcap"), "cut {cut}: {err}");
        assert!(
            matches!(err, LogError::Truncated { .. } | LogError::Corrupt { .. }),
            "cut {cut}: {err:?}"
        );
    }
    std::fs::write(&path, &good[..good.len() / 2]).unwrap();
    let err = read_run(&path).unwrap_err();
    assert!(
        matches!(err, LogError::Truncated { size_bytes, .. } if size_bytes == good.len() as u64 / 2),
        "{err:?}"
    );
    eprintln!("{err}");
    // Trailing junk after the end magic is also refused.
    let mut long = good.clone();
    long.extend_from_slice(b"junk");
    std::fs::write(&path, &long).unwrap();
    assert!(read_run(&path).is_err());
    // A missing file names the file too.
    let missing = dir.path().join("nope.mcap");
    let err = read_run(&missing).unwrap_err();
    assert!(matches!(err, LogError::Io { .. }) && err.to_string().contains("nope.mcap"));
}
