//! Hostile and damaged inputs (issue 13): what a campaign folder, a twin case or an MCAP written
//! by someone else may not make the program do. Each test reproduces one of the issue's
//! reproduction scripts (`shared/repro/reliability/`) and fails on the code before its fix.

use std::collections::BTreeMap;
use std::f64::consts::TAU;
use std::path::{Path, PathBuf};
use std::process::Output;

use pendulum_log::{EncoderMsg, RunLogOptions, METADATA_RUN};
use pendulum_rig::{
    Campaign, Header, IngestStats, Location, ReadOptions, Sample, SdReader, SdWriter, SerialReader,
    SerialWriter, TimelinePlan,
};

use crate::ingest::{tiny_capture, GOOD_RIG};
use crate::util::pendulum;

fn text(o: &Output) -> (String, String) {
    (
        String::from_utf8_lossy(&o.stdout).into_owned(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
    )
}

fn ingest(camp: &Path, out: &Path) -> Output {
    pendulum()
        .arg("ingest")
        .arg(camp)
        .arg("--out")
        .arg(out)
        .arg("--quiet")
        .output()
        .unwrap()
}

/// Every file under `dir`, relative, sorted.
fn tree(dir: &Path) -> Vec<String> {
    fn walk(base: &Path, dir: &Path, out: &mut Vec<String>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(base, &p, out);
            } else {
                out.push(p.strip_prefix(base).unwrap().display().to_string());
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// A campaign folder `root/camp` with `r01.csv` and the given `[[run]]` tables.
fn campaign(root: &Path, runs: &str) -> PathBuf {
    let camp = root.join("camp");
    std::fs::create_dir_all(&camp).unwrap();
    std::fs::write(camp.join("r01.csv"), tiny_capture()).unwrap();
    std::fs::write(camp.join("campaign.toml"), format!("{GOOD_RIG}{runs}")).unwrap();
    camp
}

/// Script 01: run ids and `file` keys that would lead outside the campaign folder (reads) or
/// the output folder (writes) are refused before anything is read or written, with an error
/// naming campaign.toml, the run and what an id must look like; the escape codes of a hostile
/// id never reach the terminal. Before the fix `id = "../escaped"` wrote `escaped.mcap` beside
/// OUT, and a failing run with an absolute id deleted `<id>.mcap` wherever it pointed.
#[test]
fn issue_13_campaign_ids_and_files_cannot_leave_their_folders() {
    let root = tempfile::tempdir().unwrap();
    let victim = root.path().join("victim");
    std::fs::create_dir_all(&victim).unwrap();
    std::fs::write(victim.join("precious.mcap"), "precious").unwrap();
    let precious = victim.join("precious");
    let run = |id: &str, file: &str| {
        format!("[[run]]\nid = \"{id}\"\nfile = \"{file}\"\nrole = \"identify\"\n")
    };
    let cases: Vec<(&str, String, Vec<&str>)> = vec![
        (
            "relative id",
            run("../escaped", "r01.csv"),
            vec![
                "run `run #1`",
                "key `id`",
                "\"../escaped\"",
                "path separator",
            ],
        ),
        (
            "absolute id of a run that fails",
            format!(
                "{}{}",
                run("r01", "r01.csv"),
                run(&precious.display().to_string(), "missing.csv")
            ),
            vec!["run `run #2`", "key `id`", "path separator"],
        ),
        (
            "escape codes in the id",
            run("r01\\u001b]0;owned\\u0007\\u001b[2J", "r01.csv"),
            vec!["run `run #1`", "control character", "\\u{1b}"],
        ),
        ("dot-dot id", run("..", "r01.csv"), vec!["starts with '.'"]),
        (
            "reserved id",
            run("NUL", "r01.csv"),
            vec!["reserved device name"],
        ),
        (
            "file outside the folder",
            run("r01", "../camp/r01.csv"),
            vec!["run `r01`", "key `file`", "contains '..'"],
        ),
        (
            "absolute file",
            run(
                "r01",
                &root.path().join("camp/r01.csv").display().to_string(),
            ),
            vec!["run `r01`", "key `file`", "absolute path"],
        ),
    ];
    for (what, runs, needles) in cases {
        let dir = root.path().join(what.replace(' ', "_"));
        let camp = campaign(&dir, &runs);
        let out = dir.join("out").join("inner");
        let o = ingest(&camp, &out);
        let (stdout, stderr) = text(&o);
        assert_eq!(o.status.code(), Some(1), "{what}: {stdout}{stderr}");
        assert!(stderr.contains("campaign.toml"), "{what}: {stderr}");
        for n in needles.iter().chain(&["expected"]) {
            assert!(stderr.contains(n), "{what}: {n:?} in {stderr}");
        }
        assert!(
            !stdout.contains('\u{1b}') && !stderr.contains('\u{1b}'),
            "{what}: an escape code reached the terminal: {stderr:?}"
        );
        // Nothing written anywhere: the campaign is refused as a whole.
        assert_eq!(tree(&dir), ["camp/campaign.toml", "camp/r01.csv"], "{what}");
        assert_eq!(
            std::fs::read_to_string(victim.join("precious.mcap")).unwrap(),
            "precious",
            "{what}"
        );
    }
}

/// Script 01's clean-up half: a run that fails must not delete an `<id>.mcap` this ingest did
/// not write (before the fix it removed any earlier or concurrent file of that name). The
/// failure says that the file there is not from this ingest.
#[test]
fn issue_13_a_failed_run_deletes_nothing_it_did_not_create() {
    let root = tempfile::tempdir().unwrap();
    let camp = campaign(
        root.path(),
        "[[run]]\nid = \"r01\"\nfile = \"r01.csv\"\nrole = \"identify\"\n\
         [[run]]\nid = \"r02\"\nfile = \"missing.csv\"\nrole = \"identify\"\n",
    );
    let out = root.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("r02.mcap"), "an earlier ingest's").unwrap();
    let o = ingest(&camp, &out);
    let (stdout, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{stdout}{stderr}");
    assert_eq!(
        std::fs::read_to_string(out.join("r02.mcap")).unwrap(),
        "an earlier ingest's"
    );
    let row = stdout.lines().find(|l| l.starts_with("r02")).unwrap();
    assert!(
        row.contains("FAILED") && row.contains("r02.mcap is NOT from this ingest"),
        "{row}"
    );
    assert!(out.join("r01.mcap").is_file());
}

/// A twin case whose run id is not a safe file name is refused before anything is simulated
/// or written (the twin names its captures `<id>.csv`).
#[test]
fn issue_13_synth_refuses_unsafe_run_ids() {
    let root = tempfile::tempdir().unwrap();
    let case = root.path().join("case.toml");
    std::fs::write(
        &case,
        "name = \"bad\"\nseed = 1\n[rig]\nm_kg = 1.46\nl_m = 0.265\ncrank_r_m = 0.0725\n\
         rod_L_m = 0.575\nr_b_m = 0.01225\n[truth]\nb_n_s_m = 0.5\nmu = 0.15\n\
         [[run]]\nid = \"ok\"\nomega_hz = 1.54\nrole = \"identify\"\nformat = \"serial\"\n\
         theta0_rad = 0.5\nfree_s = 0.5\nforced_s = 3\n\
         [[run]]\nid = \"../../escaped\"\nomega_hz = 1.54\nrole = \"identify\"\n\
         format = \"serial\"\ntheta0_rad = 0.5\nfree_s = 0.5\nforced_s = 3\n",
    )
    .unwrap();
    let out = root.path().join("a").join("b");
    let o = pendulum()
        .arg("synth")
        .arg(&case)
        .arg(&out)
        .output()
        .unwrap();
    let (stdout, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{stdout}{stderr}");
    for n in [
        "case.toml",
        "run `run #2`",
        "key `id`",
        "\"../../escaped\"",
        "path separator",
        "expected",
    ] {
        assert!(stderr.contains(n), "{n:?} in {stderr}");
    }
    assert_eq!(tree(root.path()), ["case.toml"]);
}

/// An MCAP's `run.id` names output files of identify and validate as a campaign's id does: the
/// same rule applies when a folder of MCAP files is read.
#[test]
fn issue_13_mcap_run_ids_are_checked_too() {
    let root = tempfile::tempdir().unwrap();
    let dir = root.path().join("mcap");
    std::fs::create_dir_all(&dir).unwrap();
    let mut meta = BTreeMap::new();
    for (k, v) in [
        ("id", "../../outside"),
        ("role", "identify"),
        ("m_kg", "1.46"),
        ("l_m", "0.265"),
        ("crank_r_m", "0.0725"),
        ("rod_L_m", "0.575"),
        ("r_b_m", "0.01225"),
        ("g_m_s2", "9.81"),
    ] {
        meta.insert(k.to_string(), v.to_string());
    }
    let mut w = RunLogOptions::new().create(&dir.join("r01.mcap")).unwrap();
    w.write_metadata(METADATA_RUN, meta).unwrap();
    for k in 0..10u64 {
        w.write_encoder(&EncoderMsg {
            t_s: k as f64 * 0.005,
            t_us: k * 5000,
            count: 0,
            count_raw: 0,
            theta_rad: 0.0,
        })
        .unwrap();
    }
    w.finish().unwrap();
    let e = match pendulum_jobs::runs::load_runs(&dir) {
        Ok(_) => panic!("a hostile run.id was accepted"),
        Err(e) => e.to_string(),
    };
    for n in ["r01.mcap", "run.id", "\"../../outside\"", "path separator"] {
        assert!(e.contains(n), "{n:?} in {e}");
    }
}

/// The small twin campaign of the reproduction scripts (3 runs of 10 s), ingested into `mc`
/// and identified (a short fit) into `idr`, under `root`.
fn identified_campaign(root: &Path) -> (PathBuf, PathBuf) {
    std::fs::create_dir_all(root).unwrap();
    let case = root.join("small.toml");
    std::fs::write(
        &case,
        "name = \"small-twin\"\nseed = 7\n[rig]\nm_kg = 1.46\nl_m = 0.265\ncrank_r_m = 0.0725\n\
         rod_L_m = 0.575\nr_b_m = 0.01225\n[truth]\nb_n_s_m = 0.5\nmu = 0.15\n\
         [[run]]\nid = \"r01\"\nomega_hz = 1.54\nrole = \"identify\"\nformat = \"serial\"\n\
         theta0_rad = 0.5\nfree_s = 2\nforced_s = 8\n\
         [[run]]\nid = \"v01\"\nomega_hz = 1.54\nrole = \"validate\"\nformat = \"sd\"\n\
         theta0_rad = 0.3\ntheta_dot0_rad_s = 6\nfree_s = 2\nforced_s = 8\n",
    )
    .unwrap();
    let camp = root.join("camp");
    let mc = root.join("mc");
    let idr = root.join("idr");
    for args in [
        vec!["synth".as_ref(), case.as_os_str(), camp.as_os_str()],
        vec![
            "ingest".as_ref(),
            camp.as_os_str(),
            "--out".as_ref(),
            mc.as_os_str(),
            "--quiet".as_ref(),
        ],
        vec![
            "identify".as_ref(),
            mc.as_os_str(),
            "--out".as_ref(),
            idr.as_os_str(),
            "--np".as_ref(),
            "10".as_ref(),
            "--generations".as_ref(),
            "2".as_ref(),
            "--quiet".as_ref(),
        ],
    ] {
        let o = pendulum().args(&args).output().unwrap();
        assert!(o.status.success(), "{args:?}: {:?}", text(&o));
    }
    (mc, idr)
}

/// Asserts that `o` failed with the "same file" refusal naming both paths' roles.
fn assert_refused(o: &Output, what_out: &str, what_in: &str) {
    let (stdout, stderr) = text(o);
    assert_eq!(o.status.code(), Some(1), "{stdout}{stderr}");
    for n in [
        what_out,
        what_in,
        "is the same file as",
        "refusing to overwrite an input",
    ] {
        assert!(stderr.contains(n), "{n:?} in {stderr}");
    }
}

/// Script 08: an output path that is one of the command's inputs is refused before anything is
/// written, and the input is left byte for byte. Before the fix `replay --out P --params P`
/// replaced params.parquet with an MCAP (exit 0), `validate --params OUT/params.parquet --out
/// OUT` rewrote it, and ingest into the campaign folder replaced a capture named `<id>.mcap`.
#[test]
fn issue_13_an_output_never_overwrites_an_input() {
    let root = tempfile::tempdir().unwrap();
    let (mc, idr) = identified_campaign(root.path());
    let params = idr.join("params.parquet");
    let params_bytes = std::fs::read(&params).unwrap();
    let run = mc.join("r01.mcap");
    let run_bytes = std::fs::read(&run).unwrap();

    // replay: --out is --params (spelled differently), or RUN itself.
    let other_spelling = idr.join("..").join("idr").join("params.parquet");
    let o = pendulum()
        .arg("replay")
        .arg(&run)
        .arg("--params")
        .arg(&params)
        .args(["--model", "reference", "--out"])
        .arg(&other_spelling)
        .output()
        .unwrap();
    assert_refused(&o, "--out", "--params");
    let o = pendulum()
        .arg("replay")
        .arg(&run)
        .arg("--params")
        .arg(&params)
        .args(["--model", "reference", "--out"])
        .arg(&run)
        .output()
        .unwrap();
    assert_refused(&o, "--out", "RUN");

    // validate into the folder that holds its --params: params.parquet would be rewritten.
    let o = pendulum()
        .arg("validate")
        .arg(&mc)
        .arg("--params")
        .arg(&params)
        .arg("--out")
        .arg(&idr)
        .output()
        .unwrap();
    assert_refused(&o, "the output", "--params");

    // bifurcate: its table over the --params file.
    let bif = root.path().join("bif");
    std::fs::create_dir_all(&bif).unwrap();
    std::fs::copy(&params, bif.join("bifurcation.parquet")).unwrap();
    let o = pendulum()
        .arg("bifurcate")
        .arg("--params")
        .arg(bif.join("bifurcation.parquet"))
        .args(["--model", "reference", "--sweep", "omega=1.0", "--out"])
        .arg(&bif)
        .output()
        .unwrap();
    assert_refused(&o, "the output", "--params");
    assert_eq!(
        std::fs::read(bif.join("bifurcation.parquet")).unwrap(),
        params_bytes
    );

    assert_eq!(
        std::fs::read(&params).unwrap(),
        params_bytes,
        "params.parquet changed"
    );
    assert_eq!(std::fs::read(&run).unwrap(), run_bytes, "r01.mcap changed");

    // ingest with OUT = the campaign folder, where a capture is named like a run's output.
    let camp = root.path().join("camp2");
    std::fs::create_dir_all(&camp).unwrap();
    std::fs::write(camp.join("r01.mcap"), tiny_capture()).unwrap();
    std::fs::write(
        camp.join("campaign.toml"),
        format!("{GOOD_RIG}[[run]]\nid = \"r01\"\nfile = \"r01.mcap\"\nrole = \"identify\"\n"),
    )
    .unwrap();
    let o = ingest(&camp, &camp);
    assert_refused(&o, "the output of run r01", "run r01's capture");
    assert_eq!(
        std::fs::read(camp.join("r01.mcap")).unwrap(),
        tiny_capture()
    );

    // discover with OUT = the campaign folder, where a capture is named like a report.
    let camp3 = root.path().join("camp3");
    std::fs::create_dir_all(&camp3).unwrap();
    std::fs::write(camp3.join("report.md"), tiny_capture()).unwrap();
    std::fs::write(
        camp3.join("campaign.toml"),
        format!("{GOOD_RIG}[[run]]\nid = \"r01\"\nfile = \"report.md\"\nformat = \"serial-v1\"\nrole = \"identify\"\n"),
    )
    .unwrap();
    let o = pendulum()
        .arg("discover")
        .arg(&camp3)
        .arg("--out")
        .arg(&camp3)
        .output()
        .unwrap();
    assert_refused(&o, "the output", "run r01's capture");
    assert_eq!(
        std::fs::read(camp3.join("report.md")).unwrap(),
        tiny_capture()
    );

    // synth: a case file in OUT under a name the twin writes.
    let out = root.path().join("twin");
    std::fs::create_dir_all(&out).unwrap();
    let case = std::fs::read(root.path().join("small.toml")).unwrap();
    std::fs::write(out.join("campaign.toml"), &case).unwrap();
    let o = pendulum()
        .arg("synth")
        .arg(out.join("campaign.toml"))
        .arg(&out)
        .output()
        .unwrap();
    assert_refused(&o, "the output", "the case file");
    assert_eq!(std::fs::read(out.join("campaign.toml")).unwrap(), case);
}

/// Issue 13, item 10 (messages): an empty capture says "file is empty"; an implausible
/// `accel_lsb_per_g` names the capture's header key (it used to name the output MCAP's field
/// `ax_m_s2`); `--np` below the smallest population says it was raised.
#[test]
fn issue_13_messages_name_the_cause() {
    let root = tempfile::tempdir().unwrap();
    let capture = String::from_utf8(tiny_capture()).unwrap();
    let camp = campaign(
        root.path(),
        "[[run]]\nid = \"r01\"\nfile = \"r01.csv\"\nrole = \"identify\"\n\
         [[run]]\nid = \"empty\"\nfile = \"empty.csv\"\nrole = \"identify\"\n\
         [[run]]\nid = \"lsb\"\nfile = \"lsb.csv\"\nrole = \"identify\"\n",
    );
    std::fs::write(camp.join("empty.csv"), "").unwrap();
    std::fs::write(
        camp.join("lsb.csv"),
        capture.replace("accel_lsb_per_g=8192", "accel_lsb_per_g=1e-320"),
    )
    .unwrap();
    let out = root.path().join("out");
    let o = ingest(&camp, &out);
    let (stdout, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{stdout}{stderr}");
    let row = |id: &str| {
        stdout
            .lines()
            .find(|l| l.starts_with(id))
            .unwrap_or_else(|| panic!("row {id} in {stdout}"))
            .to_string()
    };
    let empty = row("empty");
    assert!(
        empty.contains("empty.csv") && empty.contains("file is empty"),
        "{empty}"
    );
    let lsb = row("lsb");
    assert!(
        lsb.contains("lsb.csv")
            && lsb.contains("header key `accel_lsb_per_g`")
            && lsb.contains("1e-320")
            && !lsb.contains(".mcap"),
        "{lsb}"
    );

    // The same for a generic time series.
    let ts = root.path().join("ts");
    std::fs::create_dir_all(&ts).unwrap();
    std::fs::write(ts.join("e.csv"), "").unwrap();
    std::fs::write(
        ts.join("campaign.toml"),
        "[rig]\nformat = \"timeseries\"\ntime_column = \"t\"\nangle_column = \"a\"\n\
         angle_unit = \"rad\"\nrole = \"identify\"\n[[run]]\nid = \"e\"\nfile = \"e.csv\"\n",
    )
    .unwrap();
    let (stdout, _) = text(&ingest(&ts, &root.path().join("ts_out")));
    assert!(
        stdout.contains("e.csv: not a rig capture (line 1): file is empty"),
        "{stdout}"
    );

    let (mc, _) = identified_campaign(&root.path().join("twin"));
    let o = pendulum()
        .arg("identify")
        .arg(&mc)
        .arg("--out")
        .arg(root.path().join("np"))
        .args(["--np", "2", "--generations", "1", "--quiet"])
        .output()
        .unwrap();
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stdout}{stderr}");
    assert!(
        stdout.contains("note: --np 2 raised to 4"),
        "{stdout}{stderr}"
    );
}

// ---- Issue 13, items 2–5: the timeline follows the majority of the evidence, values obey
// physics, a run that keeps almost nothing fails, a misspelt campaign key is named. ----

/// One line / frame pair of a capture: raw time, raw encoder count, raw accelerometer.
type Row = (u32, i16, [i16; 3]);

/// `n` records every 5 ms from `t0_us`: a swing of ±500 counts at 1.5 Hz (1.2 rev/s at its
/// fastest) and the table's acceleration at 1.54 Hz.
fn swing(n: usize, t0_us: u32) -> Vec<Row> {
    (0..n)
        .map(|k| {
            let t = k as f64 * 0.005;
            let enc = (500.0 * (TAU * 1.5 * t).sin()).round() as i16;
            let az = 8192 + (2000.0 * (TAU * 1.54 * t).cos()).round() as i16;
            (t0_us.wrapping_add(5000 * k as u32), enc, [12, -7, az])
        })
        .collect()
}

fn serial_bytes(rows: &[Row], header: &Header) -> Vec<u8> {
    let mut w = SerialWriter::new(Vec::new(), header).unwrap();
    for &(t, e, a) in rows {
        w.write_sample(t, e, a).unwrap();
    }
    w.finish().unwrap()
}

/// The SD twin of [`serial_bytes`]: an encoder and an accelerometer frame per row (both
/// streams at 200 Hz, as the header says).
fn sd_bytes(rows: &[Row], header: &Header) -> Vec<u8> {
    let mut w = SdWriter::new(Vec::new(), header).unwrap();
    for &(t, e, a) in rows {
        w.write_encoder(t, e).unwrap();
        w.write_accel(t, a).unwrap();
    }
    w.finish().unwrap()
}

fn sd_header_200() -> Header {
    Header::sd_v2()
        .with("encoder_hz", "200")
        .with("accel_hz", "200")
}

/// Every sample and the stats of a serial (`sd = false`) or SD capture.
fn read_capture(bytes: &[u8], sd: bool) -> (Vec<Sample>, IngestStats) {
    let mut out = Vec::new();
    if sd {
        let mut r = SdReader::new(bytes, "t.bin", ReadOptions::default()).unwrap();
        while let Some(s) = r.next_sample().unwrap() {
            out.push(s);
        }
        (out, r.stats().clone())
    } else {
        let mut r = SerialReader::new(bytes, "t.csv", ReadOptions::default()).unwrap();
        while let Some(s) = r.next_sample().unwrap() {
            out.push(s);
        }
        (out, r.stats().clone())
    }
}

/// The kept encoder samples as `(raw t, raw count)`.
fn encoder_rows(samples: &[Sample]) -> Vec<(u32, i16)> {
    samples
        .iter()
        .filter_map(|s| match s {
            Sample::Encoder(e) => Some((e.t_us_raw, e.count_raw)),
            _ => None,
        })
        .collect()
}

fn assert_time_increases(samples: &[Sample], what: &str) {
    let enc: Vec<u64> = samples
        .iter()
        .filter_map(|s| match s {
            Sample::Encoder(e) => Some(e.t_us),
            _ => None,
        })
        .collect();
    assert!(
        enc.windows(2).all(|w| w[0] < w[1]),
        "{what}: encoder time must increase"
    );
}

/// Script 02: 40 valid frames stamped 10 minutes ahead in the middle of an SD capture (under
/// one bad SD sector) used to be believed and make the reader drop the REST of the run
/// (6,000 of 12,000 frames) as "time goes backwards". The 40 are dropped and reported, every
/// good frame is kept, and no 10-minute gap appears. The same for a serial capture.
#[test]
fn regression_issue_13_a_short_stale_block_does_not_discard_the_rest() {
    let good = swing(3000, 1_000_000);
    for sd in [false, true] {
        let mut rows = good[..1500].to_vec();
        rows.extend(
            good[1500..1540]
                .iter()
                .map(|&(t, e, a)| (t.wrapping_add(600_000_000), e, a)),
        );
        rows.extend_from_slice(&good[1500..]);
        let bytes = if sd {
            sd_bytes(&rows, &sd_header_200())
        } else {
            serial_bytes(&rows, &Header::serial_v1())
        };
        let (samples, st) = read_capture(&bytes, sd);
        let what = if sd { "sd" } else { "serial" };
        let want: Vec<(u32, i16)> = good.iter().map(|r| (r.0, r.1)).collect();
        assert_eq!(
            encoder_rows(&samples),
            want,
            "{what}: every good record kept"
        );
        assert_eq!(st.accel_samples, 3000, "{what}");
        assert_eq!(st.gap_count, 0, "{what}: no 10-minute gap: {:?}", st.gaps);
        // One record per stream per row in the SD capture.
        let per_row = if sd { 2 } else { 1 };
        assert_eq!(st.off_timeline, 40 * per_row, "{what}: {:?}", st.skips);
        assert_eq!(st.skipped_lines_or_frames, 40 * per_row, "{what}");
        assert!(
            st.skips[0]
                .reason
                .contains("+600.005000 s off the timeline")
                && st.skips[0].reason.contains("resumes at"),
            "{what}: {:?}",
            st.skips[0]
        );
        assert_time_increases(&samples, what);
    }
}

/// Duplicated serial chunks (a terminal program repeating its buffer): a copy of a LATER chunk
/// inserted early used to be believed as a jump ahead and make everything up to its original
/// "go backwards" (up to 80 % of a run lost); a copy of an earlier chunk repeated later was
/// dropped without saying it was a copy. Both copies are recognised (same stamps and values),
/// dropped and counted; every original line is kept.
#[test]
fn regression_issue_13_duplicated_serial_chunks_lose_no_good_data() {
    let good = swing(3000, 1_000_000);
    let mut rows = good[..500].to_vec();
    rows.extend_from_slice(&good[2400..2500]); // a later chunk, early
    rows.extend_from_slice(&good[500..1000]);
    rows.extend_from_slice(&good[100..200]); // an earlier chunk, again
    rows.extend_from_slice(&good[1000..]);
    let (samples, st) = read_capture(&serial_bytes(&rows, &Header::serial_v1()), false);
    let want: Vec<(u32, i16)> = good.iter().map(|r| (r.0, r.1)).collect();
    assert_eq!(encoder_rows(&samples), want, "every original line kept");
    assert_eq!(st.skipped_lines_or_frames, 200);
    assert_eq!(st.off_timeline, 200);
    assert_eq!(st.duplicates, 200, "both copies recognised as copies");
    assert_eq!(st.gap_count, 0, "{:?}", st.gaps);
    assert_eq!(st.new_segments, 0);
    // The early copy starts at line 506 (4 header lines and the column line): off the timeline
    // that resumes right after it (its original, 1,900 lines on, makes it a duplicate later).
    assert!(
        st.skips[0].at == Location::Line(506)
            && st.skips[0]
                .reason
                .contains("+9.505000 s off the timeline, which resumes at line 606"),
        "{:?}",
        st.skips[0]
    );
    assert_time_increases(&samples, "serial");

    // A chunk repeated right after itself: named a copy of the line it repeats.
    let mut rows = good[..1000].to_vec();
    rows.extend_from_slice(&good[900..1000]);
    rows.extend_from_slice(&good[1000..]);
    let (samples, st) = read_capture(&serial_bytes(&rows, &Header::serial_v1()), false);
    assert_eq!(encoder_rows(&samples), want);
    assert_eq!((st.off_timeline, st.duplicates), (100, 100));
    assert!(
        st.skips[0].at == Location::Line(1006)
            && st.skips[0]
                .reason
                .contains("repeats the record kept at line 906 (a duplicated chunk"),
        "{:?}",
        st.skips[0]
    );
}

/// A board reset mid-capture: the clock restarts near zero (and the count at the power-on
/// zero). Everything after it used to be dropped as "time goes backwards". Both readers keep
/// it as a new segment placed after the old one, and say so.
#[test]
fn regression_issue_13_a_board_reset_starts_a_new_segment() {
    // Before the reset the clock is well past 2^31 µs, so that the restart also looks like a
    // forward wrap: 21 minutes ahead, not a wrap.
    let before = swing(1000, 3_000_000_000);
    let after = swing(1000, 400_000);
    for sd in [false, true] {
        let rows: Vec<Row> = before.iter().chain(&after).copied().collect();
        let bytes = if sd {
            sd_bytes(&rows, &sd_header_200())
        } else {
            serial_bytes(&rows, &Header::serial_v1())
        };
        let (samples, st) = read_capture(&bytes, sd);
        let what = if sd { "sd" } else { "serial" };
        let want: Vec<(u32, i16)> = rows.iter().map(|r| (r.0, r.1)).collect();
        assert_eq!(encoder_rows(&samples), want, "{what}: both segments kept");
        assert_eq!(st.new_segments, 1, "{what}");
        assert_eq!(st.skipped_lines_or_frames, 0, "{what}: {:?}", st.skips);
        assert_eq!(st.clock_wraps, 0, "{what}: a reset is no wrap");
        assert!(
            st.warnings.iter().any(|w| w.contains("board reset")),
            "{what}: {:?}",
            st.warnings
        );
        assert_time_increases(&samples, what);
        // The new segment starts 0.4 s (the time since the reset) after the old one's end.
        let enc: Vec<u64> = samples
            .iter()
            .filter_map(|s| match s {
                Sample::Encoder(e) => Some(e.t_us),
                _ => None,
            })
            .collect();
        assert_eq!(enc[1000] - enc[999], 400_000, "{what}");
    }

    // A jump back to a timeline that does not come back, not near zero: also a new segment.
    let later = swing(1000, 2_000_000_000);
    let rows: Vec<Row> = before.iter().chain(&later).copied().collect();
    let (samples, st) = read_capture(&serial_bytes(&rows, &Header::serial_v1()), false);
    assert_eq!(samples.len(), 4000);
    assert_eq!(st.new_segments, 1);
    assert!(
        st.warnings[0].contains("moved back for good"),
        "{:?}",
        st.warnings
    );
}

/// Reads a capture as `pendulum ingest` and `identify` do: when the first pass shows a block
/// off the timeline longer than the reader's read-ahead window, the capture is read again with
/// that block dropped ([`SdReader::timeline_plan`]).
fn read_capture_whole(bytes: &[u8], sd: bool) -> (Vec<Sample>, IngestStats) {
    let mut out = Vec::new();
    let mut plan: Option<TimelinePlan> = None;
    for reading in 1..=pendulum_rig::capture::MAX_READINGS {
        out.clear();
        let (stats, more) = if sd {
            let mut r = SdReader::new(bytes, "t.bin", ReadOptions::default()).unwrap();
            if let Some(p) = &plan {
                r.set_timeline_plan(p.clone());
            }
            while let Some(s) = r.next_sample().unwrap() {
                out.push(s);
            }
            (r.stats().clone(), r.timeline_plan())
        } else {
            let mut r = SerialReader::new(bytes, "t.csv", ReadOptions::default()).unwrap();
            if let Some(p) = &plan {
                r.set_timeline_plan(p.clone());
            }
            while let Some(s) = r.next_sample().unwrap() {
                out.push(s);
            }
            (r.stats().clone(), r.timeline_plan())
        };
        match more {
            Some(more) if reading < pendulum_rig::capture::MAX_READINGS => match &mut plan {
                Some(p) => p.merge(more),
                None => plan = Some(more),
            },
            _ => return (out, stats),
        }
    }
    unreachable!("the last reading returns")
}

/// Where two lists differ first, and their records there.
type Diff = (usize, Option<(u32, i16)>, Option<(u32, i16)>);

/// Where two lists of kept records first differ (for short failure messages).
fn first_diff(a: &[(u32, i16)], b: &[(u32, i16)]) -> Option<Diff> {
    (0..a.len().max(b.len()))
        .find(|&i| a.get(i) != b.get(i))
        .map(|i| (i, a.get(i).copied(), b.get(i).copied()))
}

/// Issue 13, item 2 (the remainder): a stale block LONGER than the read-ahead window (512
/// records) was still believed: 1,000 rows stamped 10 minutes ahead among 12,000 were kept
/// behind a 10-minute gap and the rest of the run became a "new segment" re-anchored after
/// them. The timeline on either side of such a block continues across it and outnumbers it,
/// so the block is dropped and counted, whatever its length; every good record is kept, with
/// no gap and no new segment. The same for a block stamped in the past, a block that replaced
/// good rows (then one gap, as long as what it replaced), and a repeated later chunk of 1,000
/// serial lines inserted early (recognised as copies when their originals come).
#[test]
fn regression_issue_13_a_long_stale_block_is_still_a_minority() {
    let good = swing(12_000, 1_000_000_000);
    let want: Vec<(u32, i16)> = good.iter().map(|r| (r.0, r.1)).collect();
    let shifted = |rows: &[Row], by: i64| -> Vec<Row> {
        rows.iter()
            .map(|&(t, e, a)| (t.wrapping_add(by as u32), e, a))
            .collect()
    };
    for sd in [false, true] {
        let what = if sd { "sd" } else { "serial" };
        let per_row = if sd { 2 } else { 1 };
        let encode = |rows: &[Row]| {
            if sd {
                sd_bytes(rows, &sd_header_200())
            } else {
                serial_bytes(rows, &Header::serial_v1())
            }
        };
        // Inserted: 1,000 stale rows 10 minutes ahead, then 1,000 stamped 10 minutes back.
        for by in [600_000_000i64, -600_000_000] {
            let mut rows = good[..6000].to_vec();
            rows.extend(shifted(&good[6000..7000], by));
            rows.extend_from_slice(&good[6000..]);
            let (samples, st) = read_capture_whole(&encode(&rows), sd);
            let case = format!("{what}, 1,000 rows shifted by {by} µs");
            let got = encoder_rows(&samples);
            assert!(
                got == want,
                "{case}: every good record kept; {} kept, first difference {:?}",
                got.len(),
                first_diff(&got, &want)
            );
            assert_eq!(st.accel_samples, 12_000, "{case}");
            assert_eq!(st.off_timeline, 1000 * per_row, "{case}: {:?}", st.skips);
            assert_eq!(st.skipped_lines_or_frames, 1000 * per_row, "{case}");
            assert_eq!(st.gap_count, 0, "{case}: no 10-minute gap: {:?}", st.gaps);
            assert_eq!(st.new_segments, 0, "{case}: {:?}", st.warnings);
            assert!(
                st.skips[0].reason.contains("off the timeline")
                    && st.skips[0].reason.contains("resumes at"),
                "{case}: {:?}",
                st.skips[0]
            );
            assert_time_increases(&samples, &case);
        }
        // Replaced: the block overwrote 1,000 good rows; the rest is kept after one gap of
        // their length, on the original time base.
        let mut rows = good[..6000].to_vec();
        rows.extend(shifted(&good[6000..7000], 600_000_000));
        rows.extend_from_slice(&good[7000..]);
        let (samples, st) = read_capture_whole(&encode(&rows), sd);
        let mut kept = want[..6000].to_vec();
        kept.extend_from_slice(&want[7000..]);
        let got = encoder_rows(&samples);
        assert!(
            got == kept,
            "{what}, replaced: good rows kept; first difference {:?}",
            first_diff(&got, &kept)
        );
        assert_eq!(st.off_timeline, 1000 * per_row, "{what}, replaced");
        assert_eq!(st.new_segments, 0, "{what}, replaced: {:?}", st.warnings);
        let t: Vec<u64> = samples
            .iter()
            .filter_map(|s| match s {
                Sample::Encoder(e) => Some(e.t_us),
                _ => None,
            })
            .collect();
        assert_eq!(
            t[6000] - t[5999],
            1001 * 5000,
            "{what}, replaced: the hole is 5.005 s"
        );
        assert_time_increases(&samples, what);
    }

    // Real gaps (bursts of lost records, short and long) are no block: every record is kept
    // (a first version of the fix took the records between two gaps for one).
    for sd in [false, true] {
        let rows: Vec<Row> = good
            .iter()
            .enumerate()
            .filter(|(k, _)| {
                !((1000..1010).contains(k)
                    || (3000..3600).contains(k)
                    || (5000..5040).contains(k)
                    || (8000..8700).contains(k))
            })
            .map(|(_, r)| *r)
            .collect();
        let bytes = if sd {
            sd_bytes(&rows, &sd_header_200())
        } else {
            serial_bytes(&rows, &Header::serial_v1())
        };
        let (samples, st) = read_capture_whole(&bytes, sd);
        let want_gaps: Vec<(u32, i16)> = rows.iter().map(|r| (r.0, r.1)).collect();
        let got = encoder_rows(&samples);
        assert!(
            got == want_gaps,
            "sd={sd}: real gaps keep every record; first difference {:?}",
            first_diff(&got, &want_gaps)
        );
        assert_eq!((st.off_timeline, st.new_segments), (0, 0), "sd={sd}");
        assert_eq!(
            st.gap_count,
            if sd { 8 } else { 4 },
            "sd={sd}: {:?}",
            st.gaps
        );
    }

    // A later chunk of 1,000 serial lines repeated early (a terminal program's buffer).
    let mut rows = good[..2000].to_vec();
    rows.extend_from_slice(&good[9000..10_000]);
    rows.extend_from_slice(&good[2000..]);
    let (samples, st) = read_capture_whole(&serial_bytes(&rows, &Header::serial_v1()), false);
    let got = encoder_rows(&samples);
    assert!(
        got == want,
        "the copy dropped, every original kept; first difference {:?}",
        first_diff(&got, &want)
    );
    assert_eq!(
        (st.off_timeline, st.duplicates),
        (1000, 1000),
        "{:?}",
        st.skips
    );
    assert_eq!((st.gap_count, st.new_segments), (0, 0), "{:?}", st.warnings);

    // A majority is never dropped: 7,000 rows after a board reset between 2,500 before and
    // 2,500 that would continue the first part stay (the reset is a new segment).
    let mut rows = good[..2500].to_vec();
    rows.extend(swing(7000, 300_000));
    rows.extend_from_slice(&good[2500..5000]);
    let (samples, st) = read_capture_whole(&serial_bytes(&rows, &Header::serial_v1()), false);
    assert_eq!(samples.len(), 2 * 12_000, "nothing dropped: {:?}", st.skips);
    assert_eq!(st.off_timeline, 0);
    assert_eq!(st.new_segments, 1, "{:?}", st.warnings);
}

/// Script 03: a garbled digit that stays a digit (an 8,000-count encoder jump in 5 ms) was kept
/// and multiplied a run's E_θ by 100. Both readers drop values that move faster than the
/// pendulum (25 rev/s) or the shaker (2,000 m/s³) can, and report them; fast but physical
/// motion is kept.
#[test]
fn regression_issue_13_values_physics_forbids_are_dropped_by_both_readers() {
    let good = swing(2000, 1_000_000);
    let mut rows = good.clone();
    for k in [300, 500, 700] {
        rows[k].1 = rows[k].1.wrapping_add(8000);
    }
    rows[900].2[0] = rows[900].2[0].wrapping_add(20_000); // 2.4 g in 5 ms on x
    for sd in [false, true] {
        let bytes = if sd {
            sd_bytes(&rows, &sd_header_200())
        } else {
            serial_bytes(&rows, &Header::serial_v1())
        };
        let (samples, st) = read_capture(&bytes, sd);
        let what = if sd { "sd" } else { "serial" };
        assert_eq!(st.implausible, 4, "{what}: {:?}", st.skips);
        assert_eq!(st.skipped_lines_or_frames, 4, "{what}");
        assert!(
            st.skips[0].reason.contains(" counts in 5000 µs")
                && st.skips[0].reason.contains("faster than the pendulum"),
            "{what}: {:?}",
            st.skips[0]
        );
        assert!(
            st.skips[3].reason.contains("faster than the shaker"),
            "{what}: {:?}",
            st.skips[3]
        );
        let kept = encoder_rows(&samples);
        let spikes = kept.iter().filter(|(t, e)| {
            let k = ((t - 1_000_000) / 5000) as usize;
            *e != good[k].1
        });
        assert_eq!(spikes.count(), 0, "{what}: no spike kept");
        // Serial drops the whole line; SD only the frame that is wrong.
        let want_enc = if sd { 1997 } else { 1996 };
        assert_eq!(kept.len(), want_enc, "{what}");
    }

    // Fast but physical: a hand spin of 19.5 rev/s (400 counts per 5 ms) is kept whole, in
    // both readers.
    let spin: Vec<Row> = (0..1000)
        .map(|k| {
            let c = (400 * k as i64).rem_euclid(65536) as u16 as i16;
            (1_000_000 + 5000 * k as u32, c, [0, 0, 8192])
        })
        .collect();
    for sd in [false, true] {
        let bytes = if sd {
            sd_bytes(&spin, &sd_header_200())
        } else {
            serial_bytes(&spin, &Header::serial_v1())
        };
        let (samples, st) = read_capture(&bytes, sd);
        assert_eq!(encoder_rows(&samples).len(), 1000, "{:?}", st.skips);
        assert_eq!(st.implausible, 0);
    }
}

/// Script 04: a header rate 5× the real one made the serial reader drop every line but one as
/// "time jumps ahead" and ingest exit 0 with a near-empty MCAP. The header rate is checked
/// against the median step (both readers, one rule): the stamps win, with a warning. A run that
/// still keeps almost nothing (a trailing blank on every line, a garbage body, a stream that is
/// mostly holes) fails: ingest names it, writes no MCAP for it and exits 1.
#[test]
fn regression_issue_13_rate_mismatch_is_named_and_near_empty_runs_fail() {
    let good = swing(400, 1_000_000);
    // The readers: the measured rate wins, both say so.
    let (samples, st) = read_capture(
        &serial_bytes(&good, &Header::serial_v1().with("sample_hz", "1000")),
        false,
    );
    assert_eq!(encoder_rows(&samples).len(), 400, "{:?}", st.skips);
    assert_eq!(st.encoder_period_us, 5000);
    assert!(
        st.warnings[0].contains("sample_hz=1000") && st.warnings[0].contains("5000 µs"),
        "{:?}",
        st.warnings
    );
    let (samples, st) = read_capture(
        &sd_bytes(&good, &sd_header_200().with("encoder_hz", "1000")),
        true,
    );
    assert_eq!(encoder_rows(&samples).len(), 400, "{:?}", st.skips);
    assert_eq!(st.gap_count, 0, "{:?}", st.gaps);
    assert!(
        st.warnings.len() == 1
            && st.warnings[0].contains("encoder_hz=1000")
            && st.warnings[0].contains("5000 µs"),
        "{:?}",
        st.warnings
    );
    // Within the factor: no warning.
    let (_, st) = read_capture(
        &serial_bytes(&good, &Header::serial_v1().with("sample_hz", "150")),
        false,
    );
    assert!(st.warnings.is_empty(), "{:?}", st.warnings);

    // Ingest.
    let root = tempfile::tempdir().unwrap();
    let camp = campaign(
        root.path(),
        "[[run]]\nid = \"rate\"\nfile = \"rate.csv\"\nrole = \"identify\"\n\
         [[run]]\nid = \"trail\"\nfile = \"trail.csv\"\nrole = \"identify\"\n\
         [[run]]\nid = \"junk\"\nfile = \"junk.csv\"\nrole = \"identify\"\n\
         [[run]]\nid = \"holes\"\nfile = \"holes.csv\"\nrole = \"identify\"\n",
    );
    let text_of = |rows: &[Row], h: &Header| String::from_utf8(serial_bytes(rows, h)).unwrap();
    let plain = text_of(&good, &Header::serial_v1());
    std::fs::write(
        camp.join("rate.csv"),
        text_of(&good, &Header::serial_v1().with("sample_hz", "1000")),
    )
    .unwrap();
    let (head, body) = plain.split_once("t_us,enc,ax,ay,az\n").unwrap();
    let trailing: String = body.lines().map(|l| format!("{l} \n")).collect();
    std::fs::write(
        camp.join("trail.csv"),
        format!("{head}t_us,enc,ax,ay,az\n{trailing}"),
    )
    .unwrap();
    let junk: String = (0..400).map(|k| format!("@#{k}%&*\n")).collect();
    std::fs::write(
        camp.join("junk.csv"),
        format!("{head}t_us,enc,ax,ay,az\n{junk}"),
    )
    .unwrap();
    // 10 lines kept, then 190 lost, over and over: 5 % of what 200 Hz implies.
    let long = swing(8000, 1_000_000);
    let holes: Vec<Row> = long
        .iter()
        .enumerate()
        .filter(|(k, _)| k % 200 < 10)
        .map(|(_, r)| *r)
        .collect();
    std::fs::write(
        camp.join("holes.csv"),
        text_of(&holes, &Header::serial_v1()),
    )
    .unwrap();
    let out = root.path().join("out");
    let o = ingest(&camp, &out);
    let (stdout, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{stdout}{stderr}");
    assert!(
        stderr.contains("3 of 4 runs could not be ingested"),
        "{stderr}"
    );
    let row = |id: &str| {
        stdout
            .lines()
            .find(|l| l.starts_with(&format!("{id} ")))
            .unwrap_or_else(|| panic!("row {id} in {stdout}"))
            .to_string()
    };
    assert!(row("rate").contains(" 400 "), "{stdout}");
    assert!(
        stdout.contains("rate: warning: header sample_hz=1000"),
        "{stdout}"
    );
    for (id, why) in [
        ("trail", "kept 0 encoder samples"),
        ("junk", "kept 0 encoder samples"),
        ("holes", "the stream is mostly holes"),
    ] {
        let r = row(id);
        assert!(
            r.contains("FAILED") && r.contains("failed run") && r.contains(why),
            "{id}: {r}"
        );
        assert!(!out.join(format!("{id}.mcap")).exists(), "{id}: no MCAP");
    }
    assert!(out.join("rate.mcap").exists());
}

/// Script 05: a misspelt `omgea_hz` was kept as metadata without a word, and the shaker run
/// analysed as a free decay. The key is still kept (rig.md), but a warning names the run, the
/// key and the key it is probably meant to be; ordinary metadata keys get none.
#[test]
fn regression_issue_13_a_misspelt_campaign_key_is_named() {
    let root = tempfile::tempdir().unwrap();
    let camp = campaign(
        root.path(),
        "[[run]]\nid = \"r01\"\nfile = \"r01.csv\"\nrole = \"identify\"\nomgea_hz = 1.54\n\
         note = \"fresh grease\"\noperator = \"ann\"\n",
    );
    let c = Campaign::load(&camp).unwrap();
    assert_eq!(c.runs[0].omega_hz, None);
    assert_eq!(c.runs[0].extra["omgea_hz"].as_float(), Some(1.54));
    assert_eq!(c.warnings.len(), 1, "{:?}", c.warnings);
    let out = root.path().join("out");
    let o = ingest(&camp, &out);
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stdout}{stderr}");
    assert!(
        stdout.contains(
            "run `r01`: unknown key `omgea_hz` (kept as metadata): did you mean `omega_hz`?"
        ),
        "{stdout}"
    );
    assert!(
        !stdout.contains("`note`") && !stdout.contains("`operator`"),
        "{stdout}"
    );
    // In the [rig] table too, named as such.
    std::fs::write(
        camp.join("campaign.toml"),
        format!("{GOOD_RIG}rod_l_m = 0.575\n[[run]]\nid = \"r01\"\nfile = \"r01.csv\"\nrole = \"identify\"\n"),
    )
    .unwrap();
    let c = Campaign::load(&camp).unwrap();
    assert!(
        c.warnings.len() == 1
            && c.warnings[0].contains("[rig]: unknown key `rod_l_m`")
            && c.warnings[0].contains("`rod_L_m`"),
        "{:?}",
        c.warnings
    );
}

// ---- Issue 13, item 9: sizes the machine cannot hold are refused up front. ----

/// Asserts a size refusal: exit 1 (not an allocation abort, 134), the error naming each of
/// `names` (the option, its value, the limit) and saying what a unit costs, and nothing written
/// under `root` besides `keep`.
fn assert_too_large(o: &Output, names: &[&str], root: &Path, keep: &[&str]) {
    let (stdout, stderr) = text(o);
    assert_eq!(o.status.code(), Some(1), "{stdout}{stderr}");
    for n in names.iter().chain(&["limit", "bytes"]) {
        assert!(stderr.contains(n), "{n:?} in {stderr}");
    }
    assert_eq!(tree(root), keep, "{stderr}");
}

/// `simulate --t-end 1e9` (2·10¹⁰ samples at the default spacing) used to grow until the
/// integrator's step cap, `--dt-out 1e-9` to abort on a 4 GB allocation, `identify --np 1e8`
/// to abort on the population's allocation, a twin case with `forced_s = 1e9` on its sample
/// instants': each is now refused before any work, naming the option, the value and the limit.
#[test]
fn regression_issue_13_sizes_are_bounded_up_front() {
    let root = tempfile::tempdir().unwrap();
    let sim = |args: &[&str]| {
        pendulum()
            .arg("simulate")
            .args(args)
            .arg("--out")
            .arg(root.path().join("sim.parquet"))
            .output()
            .unwrap()
    };
    assert_too_large(
        &sim(&["--t-end", "1e9"]),
        &["--t-end 1000000000", "--dt-out 0.05", "20000000"],
        root.path(),
        &[],
    );
    assert_too_large(
        &sim(&["--dt-out", "1e-9"]),
        &["--dt-out 0.000000001", "3.000e11", "20000000"],
        root.path(),
        &[],
    );
    // The default still runs, and a long one within the limit.
    let o = sim(&["--t-end", "2000", "--dt-out", "0.5"]);
    assert!(o.status.success(), "{:?}", text(&o));

    let camp = campaign(
        &root.path().join("c"),
        "[[run]]\nid = \"r01\"\nfile = \"r01.csv\"\nrole = \"identify\"\n",
    );
    let o = pendulum()
        .arg("identify")
        .arg(&camp)
        .arg("--out")
        .arg(root.path().join("id"))
        .args(["--np", "100000000", "--generations", "1", "--quiet"])
        .output()
        .unwrap();
    assert_too_large(
        &o,
        &["--np 100000000", "100000"],
        root.path(),
        &["c/camp/campaign.toml", "c/camp/r01.csv", "sim.parquet"],
    );

    let case = root.path().join("case.toml");
    std::fs::write(
        &case,
        "name = \"long\"\nseed = 1\n[rig]\nm_kg = 1.46\nl_m = 0.265\ncrank_r_m = 0.0725\n\
         rod_L_m = 0.575\nr_b_m = 0.01225\n[truth]\nb_n_s_m = 0.5\nmu = 0.15\n\
         [[run]]\nid = \"long\"\nomega_hz = 1.54\nrole = \"identify\"\nformat = \"sd\"\n\
         theta0_rad = 0.5\nfree_s = 2\nforced_s = 1e9\n",
    )
    .unwrap();
    let o = pendulum()
        .arg("synth")
        .arg(&case)
        .arg(root.path().join("twin"))
        .output()
        .unwrap();
    assert_too_large(
        &o,
        &[
            "case.toml",
            "run `long`",
            "forced_s",
            "1000000000",
            "14400 s",
        ],
        root.path(),
        &[
            "c/camp/campaign.toml",
            "c/camp/r01.csv",
            "case.toml",
            "sim.parquet",
        ],
    );
}

// ---- Issue 13, item 6: an output folder is one unit. ----

/// `invocation_id` of every Parquet table directly in `dir`, by file name.
fn invocation_ids(dir: &Path) -> BTreeMap<String, String> {
    let mut ids = BTreeMap::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "parquet") {
            continue;
        }
        let file = std::fs::File::open(&p).unwrap();
        let r = parquet::file::reader::SerializedFileReader::new(file).unwrap();
        let kv = parquet::file::reader::FileReader::metadata(&r)
            .file_metadata()
            .key_value_metadata()
            .cloned()
            .unwrap_or_default();
        let id = kv
            .iter()
            .find(|k| k.key == "invocation_id")
            .and_then(|k| k.value.clone())
            .unwrap_or_else(|| panic!("{}: no invocation_id in {kv:?}", p.display()));
        ids.insert(p.file_name().unwrap().to_string_lossy().into_owned(), id);
    }
    ids
}

/// Script 07: `identify` killed over an earlier result left new tables beside stale ones with
/// nothing to tell them apart, and temporary files (PID-named) for good. Now every table of one
/// invocation carries one `invocation_id` (another invocation's differ), and a command writing
/// into OUT removes this program's temporary files there that are older than its start and
/// whose writer no longer runs, and nothing else: not a running writer's, not a fresh one, not
/// a user's own dot-file.
#[test]
fn regression_issue_13_tables_carry_one_invocation_id_and_stale_temps_go() {
    let root = tempfile::tempdir().unwrap();
    let (mc, idr) = identified_campaign(&root.path().join("twin"));
    let first = invocation_ids(&idr);
    assert!(first.len() >= 5, "{first:?}");
    let a = first.values().next().unwrap().clone();
    assert!(first.values().all(|v| *v == a), "{first:?}");

    // A process that has ended, and one that runs (this test).
    let mut done = std::process::Command::new("true").spawn().unwrap();
    let dead = done.id();
    done.wait().unwrap();
    let own = std::process::id();
    let hour = std::time::Duration::from_secs(3600);
    let seed = |name: &str, modified: std::time::SystemTime| {
        let p = idr.join(name);
        std::fs::write(&p, "left behind").unwrap();
        let f = std::fs::File::options().write(true).open(&p).unwrap();
        f.set_modified(modified).unwrap();
    };
    let now = std::time::SystemTime::now();
    let stale = [
        format!(".residuals.parquet.{dead}-3.tmp"),
        format!(".history_reference_r01.png.{dead}-0.tmp.png"),
    ];
    let kept = [
        format!(".runs.parquet.{own}-0.tmp"),    // its writer still runs
        format!(".params.parquet.{dead}-9.tmp"), // newer than the command's start
        ".notes.txt".to_string(),                // not this program's
        format!(".r01.mcap.{dead}.tmp"),         // not this program's pattern
    ];
    for n in &stale {
        seed(n, now - hour);
    }
    for (i, n) in kept.iter().enumerate() {
        seed(n, if i == 1 { now + hour } else { now - hour });
    }

    let o = pendulum()
        .arg("identify")
        .arg(&mc)
        .arg("--out")
        .arg(&idr)
        .args(["--np", "10", "--generations", "2", "--seed", "5", "--quiet"])
        .output()
        .unwrap();
    let (stdout, stderr) = text(&o);
    assert!(o.status.success(), "{stdout}{stderr}");
    assert!(
        stdout.contains("removed 2 temporary file(s)") && stdout.contains(&stale[0]),
        "{stdout}"
    );
    for n in &stale {
        assert!(!idr.join(n).exists(), "{n} left");
    }
    for n in &kept {
        assert!(idr.join(n).exists(), "{n} removed");
    }
    let second = invocation_ids(&idr);
    assert_eq!(
        second.keys().collect::<Vec<_>>(),
        first.keys().collect::<Vec<_>>()
    );
    let b = second.values().next().unwrap().clone();
    assert!(second.values().all(|v| *v == b), "{second:?}");
    assert_ne!(a, b, "two invocations share an id");
}

// ---- Issue 13, item 10: messages. ----

/// An OUT that cannot be written is found before the runs are loaded and fitted, not after the
/// fit: with a campaign that has no identify run, the OUT error comes first (before the fix,
/// OUT was first created when the tables were written, after the fit). The cause of an error
/// naming a file is said once: it used to read "Not a directory (os error 20)" twice, once in
/// the message and again as "caused by".
#[test]
fn regression_issue_13_out_checked_before_the_fit_and_causes_said_once() {
    let root = tempfile::tempdir().unwrap();
    let camp = campaign(
        root.path(),
        "[[run]]\nid = \"r01\"\nfile = \"r01.csv\"\nrole = \"validate\"\n",
    );
    let file = root.path().join("a_file");
    std::fs::write(&file, "not a folder").unwrap();
    let out = file.join("out");
    let o = pendulum()
        .arg("identify")
        .arg(&camp)
        .arg("--out")
        .arg(&out)
        .args(["--generations", "1", "--quiet"])
        .output()
        .unwrap();
    let (stdout, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{stdout}{stderr}");
    assert!(
        stderr.contains(&format!("{}: Not a directory", out.display()))
            && !stderr.contains("no run has role"),
        "{stderr}"
    );
    assert_eq!(stderr.matches("Not a directory").count(), 1, "{stderr}");

    let o = pendulum()
        .arg("simulate")
        .arg("--out")
        .arg(file.join("s.parquet"))
        .output()
        .unwrap();
    let (stdout, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{stdout}{stderr}");
    assert_eq!(stderr.matches("Not a directory").count(), 1, "{stderr}");
}

/// The `tEXt` entries of a PNG file (keyword → text), read by hand: chunk by chunk from the
/// signature, checking each chunk's CRC-32 as a PNG reader does.
fn png_text(path: &Path) -> BTreeMap<String, String> {
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in bytes {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    (c >> 1) ^ 0xEDB8_8320
                } else {
                    c >> 1
                };
            }
        }
        !c
    }
    let png = std::fs::read(path).unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"), "{}", path.display());
    let mut out = BTreeMap::new();
    let mut i = 8;
    while i + 12 <= png.len() {
        let len = u32::from_be_bytes(png[i..i + 4].try_into().unwrap()) as usize;
        let body = &png[i + 4..i + 8 + len];
        let crc = u32::from_be_bytes(png[i + 8 + len..i + 12 + len].try_into().unwrap());
        assert_eq!(crc, crc32(body), "{}: chunk CRC", path.display());
        if &body[..4] == b"tEXt" {
            let data = &body[4..];
            let z = data.iter().position(|&b| b == 0).unwrap();
            out.insert(
                String::from_utf8_lossy(&data[..z]).into_owned(),
                String::from_utf8_lossy(&data[z + 1..]).into_owned(),
            );
        }
        if &body[..4] == b"IEND" {
            break;
        }
        i += 12 + len;
    }
    out
}

/// The completion marker of `dir`: its invocation id and the files it names.
fn marker(dir: &Path) -> Option<(String, Vec<String>)> {
    let text = std::fs::read_to_string(dir.join("complete.json")).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let files = v["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap().to_string())
        .collect();
    Some((v["invocation_id"].as_str().unwrap().to_string(), files))
}

/// Seeds `dir/name` as a file last modified an hour ago.
fn seed_old(dir: &Path, name: &str) {
    let p = dir.join(name);
    std::fs::write(&p, "left behind").unwrap();
    let f = std::fs::File::options().write(true).open(&p).unwrap();
    f.set_modified(std::time::SystemTime::now() - std::time::Duration::from_secs(3600))
        .unwrap();
}

/// Script 07 (the rest of issue 13 item 6): a result folder is one unit. Every PNG carries the
/// invocation id of the tables beside it (a `tEXt` chunk); `identify`, `ingest` and `synth`
/// write `complete.json` last, with that id and the files written; a command starting in the
/// folder removes it first, so a folder it was killed or failed in is recognisably incomplete
/// (here a failing `identify` over a finished result: before, the result looked complete).
/// `simulate` and `replay` write one file, whole, carrying the id; each sweeps only its own
/// stale temporary files from the folder it writes into, nothing else.
#[test]
fn regression_issue_13_a_result_folder_is_complete_or_recognisably_incomplete() {
    let root = tempfile::tempdir().unwrap();
    let (mc, idr) = identified_campaign(&root.path().join("twin"));
    let ids = invocation_ids(&idr);
    let (id, files) = marker(&idr).expect("identify wrote complete.json");
    assert!(ids.values().all(|v| *v == id), "{id} vs {ids:?}");
    let pngs: Vec<String> = files
        .iter()
        .filter(|f| f.ends_with(".png"))
        .cloned()
        .collect();
    assert!(pngs.len() >= 2, "{files:?}");
    for p in &pngs {
        assert_eq!(
            png_text(&idr.join(p)).get("invocation_id"),
            Some(&id),
            "{p}"
        );
    }
    for t in ids.keys() {
        assert!(files.contains(t), "{t} not in {files:?}");
    }
    for f in &files {
        assert!(idr.join(f).is_file(), "{f} listed but missing");
    }
    let (mc_id, mc_files) = marker(&mc).expect("ingest wrote complete.json");
    assert_eq!(mc_files, ["r01.mcap", "v01.mcap"]);
    assert_ne!(mc_id, id);
    let (twin_id, twin_files) =
        marker(&root.path().join("twin/camp")).expect("synth wrote complete.json");
    assert_eq!(
        twin_files,
        ["campaign.toml", "r01.csv", "truth.json", "v01.bin"]
    );
    assert_ne!(twin_id, mc_id);

    // A later identify into the same folder that fails (no identify run) after it started
    // writing there: the marker is gone, the folder is recognisably incomplete.
    let camp = campaign(
        &root.path().join("v"),
        "[[run]]\nid = \"r01\"\nfile = \"r01.csv\"\nrole = \"validate\"\n",
    );
    let o = pendulum()
        .arg("identify")
        .arg(&camp)
        .arg("--out")
        .arg(&idr)
        .args(["--np", "10", "--generations", "2", "--quiet"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(1), "{:?}", text(&o));
    assert!(!idr.join("complete.json").exists(), "a stale marker stayed");
    assert!(
        idr.join("params.parquet").exists(),
        "the earlier tables stay"
    );

    // simulate: one file; its own stale temporaries go, another output's stay.
    let sims = root.path().join("sims");
    std::fs::create_dir_all(&sims).unwrap();
    let mut done = std::process::Command::new("true").spawn().unwrap();
    let dead = done.id();
    done.wait().unwrap();
    let own = format!(".sim.parquet.{dead}-0.tmp");
    let others = [
        format!(".other.parquet.{dead}-0.tmp"),
        format!(".sim.parquet.bak.{dead}-0.tmp"),
    ];
    for n in others.iter().chain([&own]) {
        seed_old(&sims, n);
    }
    let o = pendulum()
        .args(["simulate", "--t-end", "20", "--out"])
        .arg(sims.join("sim.parquet"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{:?}", text(&o));
    assert!(
        !sims.join(&own).exists(),
        "simulate's own stale temp stayed"
    );
    for n in &others {
        assert!(sims.join(n).exists(), "{n} is not simulate's to remove");
    }
    let sim_ids = invocation_ids(&sims);
    assert_eq!(sim_ids.len(), 1);

    // replay: one MCAP carrying the id; its own stale temporaries go.
    let overlay = sims.join("overlay.mcap");
    let own = format!(".overlay.mcap.{dead}-2.tmp");
    seed_old(&sims, &own);
    let o = pendulum()
        .arg("replay")
        .arg(mc.join("r01.mcap"))
        .arg("--params")
        .arg(idr.join("params.parquet"))
        .args(["--model", "reference", "--out"])
        .arg(&overlay)
        .output()
        .unwrap();
    assert!(o.status.success(), "{:?}", text(&o));
    assert!(!sims.join(&own).exists(), "replay's own stale temp stayed");
    for n in &others {
        assert!(sims.join(n).exists(), "{n} is not replay's to remove");
    }
    let log = pendulum_log::read_run(&overlay).unwrap();
    let replay_id = log.metadata["replay"]["invocation_id"].clone();
    assert!(
        !replay_id.is_empty() && replay_id != id && Some(&replay_id) != sim_ids.values().next(),
        "{replay_id}"
    );
}

/// Issue 13 item 7 (the rest): `synth` wrote `campaign.toml` and `truth.json` through the fixed
/// names `campaign.tmp` and `truth.tmp`, so two synths into one folder truncated and renamed
/// away each other's, and a user's `campaign.tmp` was taken. Its temporary names are now unique
/// to the process (`.campaign.toml.<pid>-<n>.tmp`), it leaves none, and it removes only its own
/// stale ones: not a user's `campaign.tmp`, not another program output's temporary file.
#[test]
fn regression_issue_13_synth_temporary_names_are_its_own() {
    let root = tempfile::tempdir().unwrap();
    let out = root.path().join("twin");
    std::fs::create_dir_all(&out).unwrap();
    let mut done = std::process::Command::new("true").spawn().unwrap();
    let dead = done.id();
    done.wait().unwrap();
    let users = ["campaign.tmp", "truth.tmp"];
    for n in users {
        std::fs::write(out.join(n), "mine").unwrap();
    }
    let stale = [
        format!(".campaign.toml.{dead}-0.tmp"),
        format!(".r01.csv.{dead}-3.tmp"),
    ];
    let foreign = format!(".params.parquet.{dead}-0.tmp");
    for n in stale.iter().chain([&foreign]) {
        seed_old(&out, n);
    }
    let case = root.path().join("case.toml");
    std::fs::write(
        &case,
        "name = \"t\"\nseed = 3\n[rig]\nm_kg = 1.46\nl_m = 0.265\ncrank_r_m = 0.0725\n\
         rod_L_m = 0.575\nr_b_m = 0.01225\n[truth]\nb_n_s_m = 0.5\nmu = 0.15\n\
         [[run]]\nid = \"r01\"\nomega_hz = 1.54\nrole = \"identify\"\nformat = \"serial\"\n\
         theta0_rad = 0.5\nfree_s = 1\nforced_s = 4\n",
    )
    .unwrap();
    let o = pendulum()
        .arg("synth")
        .arg(&case)
        .arg(&out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{:?}", text(&o));
    for n in users {
        assert_eq!(
            std::fs::read_to_string(out.join(n)).unwrap(),
            "mine",
            "{n} is not synth's"
        );
    }
    for n in &stale {
        assert!(!out.join(n).exists(), "{n}: synth's own stale temp stayed");
    }
    assert!(out.join(&foreign).exists(), "not synth's to remove");
    assert_eq!(
        tree(&out),
        [
            format!(".params.parquet.{dead}-0.tmp"),
            "campaign.tmp".to_string(),
            "campaign.toml".to_string(),
            "complete.json".to_string(),
            "r01.csv".to_string(),
            "truth.json".to_string(),
            "truth.tmp".to_string(),
        ],
        "no temporary file of synth's left"
    );
}

/// Issue 13 item 10 (the rest): MCAP files of two campaigns in one folder were fitted together
/// without a word (one set of damping parameters for two rigs or days). `identify` and
/// `validate` refuse them, naming both campaigns and their files, before any fit or output;
/// `--mix-campaigns` asks for it on purpose.
#[test]
fn regression_issue_13_mcaps_of_two_campaigns_are_not_fitted_together_unless_asked() {
    let root = tempfile::tempdir().unwrap();
    let mixed = root.path().join("mixed");
    std::fs::create_dir_all(&mixed).unwrap();
    for (name, id, role) in [
        ("day-one", "r01", "identify"),
        ("day-two", "v01", "validate"),
    ] {
        let case = root.path().join(format!("{name}.toml"));
        std::fs::write(
            &case,
            format!(
                "name = \"{name}\"\nseed = 3\n[rig]\nm_kg = 1.46\nl_m = 0.265\n\
                 crank_r_m = 0.0725\nrod_L_m = 0.575\nr_b_m = 0.01225\n[truth]\nb_n_s_m = 0.5\n\
                 mu = 0.15\n[[run]]\nid = \"{id}\"\nomega_hz = 1.54\nrole = \"{role}\"\n\
                 format = \"serial\"\ntheta0_rad = 0.5\nfree_s = 2\nforced_s = 8\n"
            ),
        )
        .unwrap();
        let camp = root.path().join(name);
        let mc = root.path().join(format!("{name}-mc"));
        let o = pendulum()
            .arg("synth")
            .arg(&case)
            .arg(&camp)
            .output()
            .unwrap();
        assert!(o.status.success(), "{:?}", text(&o));
        let o = pendulum()
            .arg("ingest")
            .arg(&camp)
            .arg("--out")
            .arg(&mc)
            .arg("--quiet")
            .output()
            .unwrap();
        assert!(o.status.success(), "{:?}", text(&o));
        let f = format!("{id}.mcap");
        std::fs::copy(mc.join(&f), mixed.join(&f)).unwrap();
    }
    let identify = |extra: &[&str]| {
        pendulum()
            .arg("identify")
            .arg(&mixed)
            .arg("--out")
            .arg(root.path().join("out"))
            .args(["--np", "10", "--generations", "2", "--quiet"])
            .args(extra)
            .output()
            .unwrap()
    };
    let o = identify(&[]);
    let (stdout, stderr) = text(&o);
    assert_eq!(o.status.code(), Some(1), "{stdout}{stderr}");
    for s in [
        "`day-one` (r01.mcap)",
        "`day-two` (v01.mcap)",
        "--mix-campaigns",
    ] {
        assert!(stderr.contains(s), "{s:?} in {stderr}");
    }
    assert!(
        !root.path().join("out/params.parquet").exists(),
        "nothing fitted"
    );
    let o = identify(&["--mix-campaigns"]);
    assert!(o.status.success(), "{:?}", text(&o));
    assert!(root.path().join("out/params.parquet").exists());
}

/// Issue 13 item 9 (the rest): a capture with 19 MB of header lines was read into memory
/// (94 MB for ingest), a `campaign.toml` with a 19 MB name took 170 MB. The serial header is
/// bounded (64 KiB, a firmware header is ~150 bytes), so is a header line (1 KiB) and
/// `campaign.toml` (1 MiB, lines of 64 KiB): each refused before it is held, naming the file,
/// the line and the byte offset.
#[test]
fn regression_issue_13_huge_headers_are_refused_up_front() {
    let rows = swing(100, 1_000_000);
    let good = serial_bytes(&rows, &Header::serial_v1());
    let mut huge = Vec::new();
    for i in 0..19_000 {
        huge.extend_from_slice(format!("# k{i}={}\n", "x".repeat(1000)).as_bytes());
    }
    huge.extend_from_slice(&good);
    let e = SerialReader::new(&huge[..], "huge.csv", ReadOptions::default())
        .err()
        .expect("refused")
        .to_string();
    assert!(
        e.contains("huge.csv") && e.contains("65536") && e.contains("line 66, byte 66"),
        "{e}"
    );
    // One line too long: its number and where it starts.
    let text = String::from_utf8(good.clone()).unwrap();
    let long = text.replacen(
        "# encoder_cpr=4096",
        &format!("# note={}", "y".repeat(5000)),
        1,
    );
    let e = SerialReader::new(long.as_bytes(), "long.csv", ReadOptions::default())
        .err()
        .expect("refused")
        .to_string();
    assert!(
        e.contains("long.csv") && e.contains("header line 2 (from byte 21)"),
        "{e}"
    );
    // A long header within the bound still reads.
    let notes = text.replacen(
        "# encoder_cpr=4096",
        &format!("# note={}\n# encoder_cpr=4096", "z".repeat(900)),
        1,
    );
    let (samples, _) = read_capture(notes.as_bytes(), false);
    assert_eq!(samples.len(), 200);

    let root = tempfile::tempdir().unwrap();
    let camp = campaign(
        root.path(),
        "[[run]]\nid = \"r01\"\nfile = \"r01.csv\"\nrole = \"identify\"\n",
    );
    let toml = camp.join("campaign.toml");
    let base = std::fs::read_to_string(&toml).unwrap();
    std::fs::write(&toml, format!("{base}# {}\n", "n".repeat(2 << 20))).unwrap();
    let e = Campaign::load(&camp).expect_err("refused").to_string();
    assert!(
        e.contains("campaign.toml") && e.contains("more than 1048576 bytes"),
        "{e}"
    );
    let lines = base.lines().count();
    std::fs::write(&toml, format!("{base}# {}\n", "n".repeat(100_000))).unwrap();
    let e = Campaign::load(&camp).expect_err("refused").to_string();
    assert!(
        e.contains(&format!("line {}, byte {}", lines + 1, base.len()))
            && e.contains("100002 bytes"),
        "{e}"
    );
    std::fs::write(&toml, format!("{base}# {}\n", "n".repeat(1000))).unwrap();
    assert!(
        Campaign::load(&camp).is_ok(),
        "a long comment within the bound loads"
    );
}
