//! Hostile and damaged inputs (issue 13): what a campaign folder, a twin case or an MCAP written
//! by someone else may not make the program do. Each test reproduces one of the issue's
//! reproduction scripts (`shared/repro/reliability/`) and fails on the code before its fix.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Output;

use pendulum_log::{EncoderMsg, RunLogOptions, METADATA_RUN};

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
