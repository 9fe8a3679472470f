//! Issue 14 item 3: departures outside the catalogue (effects.md, last paragraph) are reported as
//! `unexplained`, with the variable the remaining torque follows and its shape, and nothing from
//! the catalogue is named for them. The twin hides each departure in campaigns whose design
//! (bobs, rods, cranks, speeds, formats, hand starts, durations) is drawn per run; the analysis
//! is not told what was hidden.

use pendulum_discover::sparse::{Variable, LIBRARY};
use pendulum_discover::Base;
use pendulum_jobs::discover::{run, DiscoverJob, DiscoverSummary};
use rand::{RngExt, SeedableRng};

use crate::identify::make_campaign;

fn discover_with(seed: u64, b: f64, mu: f64, departure: &str) -> DiscoverSummary {
    let dir = tempfile::tempdir().unwrap();
    let camp = dir.path().join("campaign");
    // An empty catalogue table, then the departure's own.
    let toml = pendulum_jobs::demo::discovery_campaign(
        "departure",
        seed,
        0.0,
        b,
        mu,
        &format!("\n[truth.departures]\n{departure}"),
    );
    make_campaign(&camp, &toml);
    if let Ok(keep) = std::env::var("KEEP_DEP") {
        std::fs::write(format!("{keep}-{seed}.toml"), &toml).unwrap();
    }
    let s = run(&DiscoverJob {
        input: camp,
        out: dir.path().join("out"),
        base: Base::Reference,
        pipeline: None,
        generations: Some(300),
        seed: None,
        progress: false,
    })
    .unwrap();
    eprintln!("{s}");
    s
}

fn rng(tag: u64) -> rand_chacha::ChaCha8Rng {
    rand_chacha::ChaCha8Rng::seed_from_u64(0x1414_0000 + tag)
}

/// The `case`-th value `draw` makes from [`rng`]`(tag)`, after the `case` draws before it: a
/// multi-draw test's draws, one test each, as they were when one test looped over them.
fn nth_draw<T>(tag: u64, case: u64, draw: impl Fn(&mut rand_chacha::ChaCha8Rng) -> T) -> T {
    let mut r = rng(tag);
    for _ in 0..case {
        draw(&mut r);
    }
    draw(&mut r)
}

/// A cable acting as a linear torsion spring (−k θ, θ unwrapped): `position_torque` k = 1 fits
/// it on small swings (sin θ ≈ θ), but it is not the cause. The answer must be `unexplained`,
/// following the unwrapped θ, linear, with k within 10 %, and nothing named.
#[test]
fn regression_issue_14_torsion_spring_is_unexplained() {
    torsion_spring_case(0);
}

/// [`regression_issue_14_torsion_spring_is_unexplained`]'s second drawn spring.
#[test]
#[ignore = "slow set (a second drawn spring; the departure survey draws five): the default suite checks the same on the first draw, regression_issue_14_torsion_spring_is_unexplained, and a weak spring on a_weak_torsion_spring_is_not_named_a_position_torque; README, Tests"]
fn regression_issue_14_torsion_spring_is_unexplained_second_draw() {
    torsion_spring_case(1);
}

/// The `case`-th of the drawn torsion springs (a draw made after the ones before it).
fn torsion_spring_case(case: u64) {
    let (k, b, mu) = nth_draw(1, case, |r| {
        (
            r.random_range(0.05..0.15),
            r.random_range(0.3..0.7),
            r.random_range(0.08..0.2),
        )
    });
    let s = discover_with(
        7100 + case,
        b,
        mu,
        &format!("torsion_spring_nm_per_rad = {k}"),
    );
    let d = &s.discovery;
    assert!(
        d.accepted().is_empty(),
        "case {case}: named {:?} for a torsion spring",
        d.accepted()
    );
    let desc = d
        .unexplained_description
        .as_ref()
        .unwrap_or_else(|| panic!("case {case}: no description ({:?})", d.unexplained));
    assert_eq!(desc.variable, Variable::Angle, "case {case}: {desc:?}");
    // The library's coefficient is the target's (what damping and the effects must
    // explain), +k θ for a restoring −k θ.
    let theta = desc
        .terms
        .iter()
        .find(|(j, _, _)| LIBRARY[*j].name == "θ")
        .unwrap_or_else(|| panic!("case {case}: no linear θ term in {desc:?}"));
    assert!(
        (theta.1 - k).abs() < 0.1 * k,
        "case {case}: spring {:.4e} N·m/rad described as {:.4e}",
        k,
        theta.1
    );
    let words = d.unexplained.as_deref().unwrap_or_default();
    assert!(
        words.contains("θ (unwrapped)") && words.contains("a spring"),
        "{words}"
    );
}

/// An encoder whose real counts per revolution (4200–4400) are not the 4096 its header says:
/// every angle is scaled, and the catalogue's nearest entries (an extra inertia, a position
/// torque) fit it only in part or with impossible values. The answer must be `unexplained`,
/// following θ, and nothing named. On swings the departure is a cubic in the unwrapped θ
/// (s sin(θ/s) − sin θ ≈ (1 − 1/s²) θ³/6); through rotations the measured angle's gravity
/// torque drifts out of step turn by turn, which no fixed shape describes: then the words say
/// where (θ) without a confirmed shape.
#[test]
fn regression_issue_14_mislabelled_encoder_is_unexplained() {
    mislabelled_encoder_case(0);
}

/// [`regression_issue_14_mislabelled_encoder_is_unexplained`]'s second drawn encoder.
#[test]
#[ignore = "slow set (a second drawn encoder, 28 s; the departure survey draws encoders 2–8 % off): the default suite checks the same on the first draw, regression_issue_14_mislabelled_encoder_is_unexplained, and an_encoder_under_its_header_is_not_named_an_inertia_the_refit_cannot_reach; README, Tests"]
fn regression_issue_14_mislabelled_encoder_is_unexplained_second_draw() {
    mislabelled_encoder_case(1);
}

/// The `case`-th of the drawn mislabelled encoders (a draw made after the ones before it).
fn mislabelled_encoder_case(case: u64) {
    let (cpr, b, mu) = nth_draw(2, case, |r| {
        (
            r.random_range(4200.0..4400.0),
            r.random_range(0.3..0.7),
            r.random_range(0.08..0.2),
        )
    });
    let s = discover_with(7200 + case, b, mu, &format!("encoder_cpr_true = {cpr}"));
    let d = &s.discovery;
    assert!(
        d.accepted().is_empty(),
        "case {case}: named {:?} for a mislabelled encoder",
        d.accepted()
    );
    let words = d
        .unexplained
        .as_deref()
        .unwrap_or_else(|| panic!("case {case}: no `unexplained`"));
    // θ itself, not dθ/dt.
    assert!(
        words.contains("θ (unwrapped)") || words.contains("θ (mod 2π)"),
        "case {case}: {words}"
    );
    if let Some(desc) = &d.unexplained_description {
        assert!(
            matches!(desc.variable, Variable::Angle | Variable::AngleInTurn),
            "case {case}: {desc:?}"
        );
    }
}

/// A dry torque that grows as the rig runs (a bearing heating up, a seal drying out: T_c = r·t
/// from the capture's start, sgn θ'). A constant dry torque fits its mean, but the runs disagree
/// on it by when their windows fall. Over four drawn campaigns nothing may be named, and every
/// description must follow time as "a friction growing with time" with its rate (the t sgn θ̇
/// term) within a factor of two; at least three of the four must be described. Measured: all
/// four, rates −0.5 %, −30.0 %, −1.0 % and −3.1 %. The −30 % draw (the slowest growth,
/// 2.56e-4 N·m/s) sits 2.4 of its standard errors off: the overlapping windows' errors are
/// correlated, so the regression's interval understates its scatter; when its weights came from
/// a fit with position torques up to k = 64 its validate runs did not confirm it at all (fall
/// 30 % against a noise of 37 %), and then nothing was named and nothing said.
#[test]
#[ignore = "slow set (four drawn growths, 66 s on 2 cores beside another test; the departure survey draws five): the default suite checks the same on a_fast_growing_dry_torque_is_not_named_a_constant_one (nothing named, following time, the t sgn θ̇ rate within 25 %) and a_growing_dry_torque_is_not_credited_with_the_damping_its_refit_repairs; README, Tests"]
fn regression_issue_12_growing_dry_torque_is_unexplained() {
    let mut r = rng(3);
    let mut described = 0;
    for case in 0..4 {
        let rate = r.random_range(2e-4..4e-4);
        let (b, mu) = (r.random_range(0.3..0.7), r.random_range(0.08..0.2));
        let s = discover_with(
            7300 + case,
            b,
            mu,
            &format!("dry_torque_growth_nm_per_s = {rate}"),
        );
        let d = &s.discovery;
        assert!(
            d.accepted().is_empty(),
            "case {case}: named {:?} for a growing dry torque",
            d.accepted()
        );
        let Some(desc) = d.unexplained_description.as_ref() else {
            eprintln!(
                "case {case}: growth {rate:.4e} N·m/s not described ({:?})",
                d.unexplained
            );
            continue;
        };
        assert_eq!(desc.variable, Variable::Time, "case {case}: {desc:?}");
        let growth = desc
            .terms
            .iter()
            .find(|(j, _, _)| LIBRARY[*j].name == "t sgn θ̇")
            .unwrap_or_else(|| panic!("case {case}: no t sgn θ̇ term in {desc:?}"));
        eprintln!(
            "case {case}: growth {rate:.4e} N·m/s described as {:.4e} ({:+.1} %)",
            growth.1,
            100.0 * (growth.1 / rate - 1.0)
        );
        assert!(
            growth.1 > 0.5 * rate && growth.1 < 2.0 * rate,
            "case {case}: growth {rate:.4e} N·m/s described as {:.4e}",
            growth.1
        );
        let words = d.unexplained.as_deref().unwrap_or_default();
        assert!(words.contains("growing with time"), "{words}");
        described += 1;
    }
    assert!(described >= 3, "described {described} of 4");
}

/// Play between the shaft and the encoder (a loose coupling, 0.005–0.03 rad): the measured angle
/// lags the shaft by half the play in the direction of motion and stands still at every
/// turn-around. The gravity torque of the lagging angle looks to the equation error like a
/// torque stepping at θ̇ = 0, but one that would feed energy in (the trajectories, which lose no
/// energy to it, refit a dry torque near 0). Nothing may be named on two drawn campaigns, and the
/// `unexplained` words must say it follows dθ/dt. Measured (CLI, two kept designs of the growth
/// test): a 0.02 rad play came back as a step at dθ/dt = 0 of −1.4e-2 and −4.7e-2 N·m, the
/// screen's `coulomb_constant` refused as physically impossible; 0.006 rad as −1.4e-2 N·m on
/// one and nothing at all on the other.
///
/// Known failure since the free segments end where the base starts to move (b5a5bf7): nothing
/// is named on either case, but case 0's `unexplained` is only the refusal of its best
/// candidate, a negative accelerometer lag (−1.25e-3 s [−1.44e-3, −1.05e-3], ΔBIC −111.8,
/// refit −1.07e-3 s: the measured angle lags the shaft, which reads as an accelerometer that
/// leads), with no variable named: neither the generic description nor the binned variables
/// single out dθ/dt on the shorter free segments. It passes again on 0550d28's build and on
/// c72164d (checked in the forty-fourth session), so it is in the slow set.
#[test]
#[ignore = "slow set (two drawn backlashes; a known failure from b5a5bf7, passing again on 0550d28's build and on c72164d, checked in the forty-fourth session): the default suite checks a backlash on an_encoder_backlash_is_not_named_an_accelerometer_lead; README, Tests"]
fn encoder_backlash_is_unexplained_and_follows_the_rate() {
    let mut r = rng(4);
    for case in 0..2 {
        let play = r.random_range(0.005..0.03);
        let (b, mu) = (r.random_range(0.3..0.7), r.random_range(0.08..0.2));
        let s = discover_with(
            7400 + case,
            b,
            mu,
            &format!("encoder_backlash_rad = {play}"),
        );
        let d = &s.discovery;
        assert!(
            d.accepted().is_empty(),
            "case {case}: named {:?} for a {play:.4} rad encoder backlash",
            d.accepted()
        );
        if let Some(words) = d.unexplained.as_deref() {
            assert!(words.contains("dθ/dt"), "case {case}: {words}");
        }
        if let Some(desc) = &d.unexplained_description {
            assert_eq!(desc.variable, Variable::Rate, "case {case}: {desc:?}");
        }
    }
}

/// Bearing friction that differs from run to run (μ × (1 ± up to 30 %), drawn per run): the
/// reference model's one μ fits the campaign's mean, and what each run keeps is a dry torque of
/// either sign that no catalogue entry of one campaign-wide size describes. Nothing may be
/// named on two drawn campaigns. Measured (CLI, two kept designs of the growth test, ± 30 %):
/// nothing named on either; one came back `unexplained` (`coulomb_constant` explains only 59 %
/// of the freer shape in θ̇), the other with nothing said.
#[test]
#[ignore = "slow set (two fixed twin draws; the departure survey draws five): the default suite checks the same on another draw, a_friction_that_differs_on_the_validate_runs_is_not_named_a_generator (nothing named, the words say the torque follows the run); README, Tests"]
fn friction_that_differs_from_run_to_run_names_nothing() {
    let mut r = rng(5);
    for case in 0..2 {
        let spread = r.random_range(0.15..0.35);
        let (b, mu) = (r.random_range(0.3..0.7), r.random_range(0.08..0.2));
        let s = discover_with(7500 + case, b, mu, &format!("mu_run_spread = {spread}"));
        assert!(
            s.discovery.accepted().is_empty(),
            "case {case}: named {:?} for a bearing friction spread ± {spread:.2} over runs",
            s.discovery.accepted()
        );
        let words = s.discovery.unexplained.as_deref().unwrap_or_default();
        assert!(
            words.contains("a torque that follows the run"),
            "case {case}: {words}"
        );
    }
}

/// A cable that hangs slack near the hanging position and pulls as a spring beyond ± its slack
/// (a dead band in the unwrapped θ; k 0.1–0.3 N·m/rad, slack 0.3–1 rad): nothing may be named
/// on two drawn campaigns, and where `unexplained` speaks it must say the torque follows the
/// unwrapped θ. Measured (CLI, two kept designs of the growth test, k = 0.2, slack 0.6): both
/// `unexplained` following θ (unwrapped), "linear in the unwrapped θ (a spring), cubic", the
/// linear term 0.17 N·m/rad; one refused `extra_inertia` as impossible (−2.1e-3 kg·m²).
#[test]
#[ignore = "slow set (two drawn cables, 66 s on 2 cores beside another test; the departure survey draws five): the default suite checks that a cable is not named and that the words follow θ (unwrapped) on a_cable_whose_rest_an_offset_takes_up_is_not_named_one_beside_the_spring_left, and a spring on regression_issue_14_torsion_spring_is_unexplained; README, Tests"]
fn slack_cable_is_unexplained_and_follows_the_angle() {
    let mut r = rng(6);
    for case in 0..2 {
        let k = r.random_range(0.1..0.3);
        let slack = r.random_range(0.3..1.0);
        let (b, mu) = (r.random_range(0.3..0.7), r.random_range(0.08..0.2));
        let s = discover_with(
            7600 + case,
            b,
            mu,
            &format!("torsion_spring_nm_per_rad = {k}\ncable_slack_rad = {slack}"),
        );
        let d = &s.discovery;
        assert!(
            d.accepted().is_empty(),
            "case {case}: named {:?} for a {k:.3} N·m/rad cable slack by ± {slack:.2} rad",
            d.accepted()
        );
        let words = d
            .unexplained
            .as_deref()
            .unwrap_or_else(|| panic!("case {case}: no `unexplained`"));
        assert!(words.contains("θ (unwrapped)"), "case {case}: {words}");
    }
}

/// A bob that bounces on a springy mount along its rod (effects.md's "a bob that wobbles"; the
/// twin integrates it with its own integrator, [`pendulum_rig::bounce`]): as the pendulum speeds
/// up the bob moves out, and its gravity torque and inertia grow with θ̇². The survey's first
/// draw (a 10.5 Hz mount) was named `extra_inertia` (the screen 1.78e-3 kg·m², its refit
/// 8.1e-4) with a k = 3 `position_torque` of 0.050 N·m before the library held that shape; its
/// third (a soft 4.3 Hz mount) was described as sin θ alone. Both must name nothing and say that
/// the torque follows dθ/dt, with the gravity torque growing as θ̇² (a negative coefficient:
/// more restoring torque, as a longer pendulum has).
#[test]
fn a_bouncing_bob_is_unexplained_and_follows_the_rate() {
    for k in [0, 2] {
        let (seed, b, mu, departure) = drawn_departure("bob_bounce", k, 0);
        let s = discover_with(seed, b, mu, &departure);
        let d = &s.discovery;
        assert!(
            d.accepted().is_empty(),
            "draw {k}: named {:?} for a bouncing bob ({departure})",
            d.accepted()
        );
        let words = d
            .unexplained
            .as_deref()
            .unwrap_or_else(|| panic!("draw {k}: no `unexplained`"));
        let desc = d
            .unexplained_description
            .as_ref()
            .unwrap_or_else(|| panic!("draw {k}: no description: {words}"));
        assert_eq!(desc.variable, Variable::Rate, "draw {k}: {words}");
        let (_, c, _) = desc
            .terms
            .iter()
            .find(|(j, _, _)| LIBRARY[*j].name == "θ̇² (1 + A_y) sin θ")
            .unwrap_or_else(|| panic!("draw {k}: no θ̇² sin θ term in {words}"));
        assert!(
            *c < 0.0,
            "draw {k}: the gravity torque shrinks with speed? {words}"
        );
        assert!(
            words.contains("moves out as it speeds up"),
            "draw {k}: {words}"
        );
    }
}

/// A bouncing bob whose screen route named an extra inertia and a position torque (the
/// departure survey's `bob_bounce` k = 3 at `DEPARTURE_SEED=1`, k = 2 at `DEPARTURE_SEED=5`):
/// the validate runs' own rows put each size far from the identify runs' (with the first
/// round's other candidates beside it: the inertia 2.48e-2 kg·m² against 7.18e-3; the torque
/// 0.817 N·m against 0.082), so one size does not
/// describe the departure and nothing may be named; the refused row's note gives both values.
/// Since c6865ca a rule asked before that one refuses a candidate of each draw for the same
/// reason, one size not describing it: the validate runs' E_θ falls at the refit's size but not
/// at the screen's (the inertia of draw 3, the torque of draw 2), and the row says so instead.
#[test]
#[ignore = "slow set (two kept draws, 50 s on 2 cores): the default suite checks a bouncing bob on a_bouncing_bob_is_unexplained_and_follows_the_rate and the rule on the unit test sizes_disagree_only_apart_beyond_both_intervals_and_the_promised_accuracy; docs/discovery.md, A partial explanation is not a cause"]
fn a_bouncing_bob_whose_validate_runs_size_it_elsewhere_is_not_named() {
    for (k, off) in [(3, 100_000), (2, 500_000)] {
        let (seed, b, mu, departure) = drawn_departure("bob_bounce", k, off);
        let s = discover_with(seed, b, mu, &departure);
        let d = &s.discovery;
        assert!(
            d.accepted().is_empty(),
            "draw {k} (+{off}): named {:?} for a bouncing bob ({departure})",
            d.accepted()
        );
        assert!(
            d.unexplained.is_some(),
            "draw {k} (+{off}): nothing said for a bouncing bob"
        );
        assert!(
            d.rows.iter().any(|r| r
                .note
                .contains("validate runs' own rows put its size elsewhere")
                || r.note
                    .contains("at the refit's value but not at the screen's")),
            "draw {k} (+{off}): no candidate refused for its held-out size: {:#?}",
            d.rows
                .iter()
                .map(|r| (&r.effect, &r.note))
                .collect::<Vec<_>>()
        );
    }
}

/// A bouncing bob named an accelerometer lag (the departure survey's `bob_bounce` k = 1 at
/// `DEPARTURE_SEED=1`): a 64 ms "lag" took 31 % off the resting validate runs' equation error
/// while their E_θ went 0.237 → 2.654 (+1020 % ± 139 %). Their E_θ does not respond to the lag
/// itself, so the rise is the other terms' trade with it on the identify runs; a trade that
/// makes the extended model ten times worse on the runs the fit never saw is not excused, and
/// nothing may be named. The refused row says why.
#[test]
#[ignore = "slow set (one kept draw, 50 s on 2 cores): the default suite checks a bouncing bob on a_bouncing_bob_is_unexplained_and_follows_the_rate and the excused trade on a_lag_the_validate_runs_e_theta_cannot_see_is_judged_on_their_equation_error; docs/discovery.md, A partial explanation is not a cause"]
fn a_bouncing_bob_whose_lag_makes_the_held_out_runs_worse_is_not_named() {
    let (seed, b, mu, departure) = drawn_departure("bob_bounce", 1, 100_000);
    let s = discover_with(seed, b, mu, &departure);
    let d = &s.discovery;
    assert!(
        d.accepted().is_empty(),
        "named {:?} for a bouncing bob ({departure})",
        d.accepted()
    );
    assert!(d.unexplained.is_some(), "nothing said for a bouncing bob");
    let lag = d.row("accel_delay").expect("the lag was screened");
    assert!(
        lag.note
            .contains("the other terms' trade with it makes the extended model worse"),
        "{}",
        lag.note
    );
}

/// A dry torque growing with time (the departure survey's `dry_torque_growth` k = 0 at
/// `DEPARTURE_SEED=5`; 3.6e-4 N·m/s, on a design whose one moving identify run carries it) was
/// named a 0.25 ms accelerometer lag: screen and refit agreed (2.49e-4, 2.35e-4 s), the resting
/// validate runs' equation error fell 28.7 % against 24.1 % needed, and their E_θ, which does
/// not respond to the lag itself, moved −164 % ± 230 %. The equation error was the one view that
/// judged it, and one view's bare pass is not two views agreeing: nothing may be named, and the
/// lag's row says why.
#[test]
#[ignore = "slow set (one kept draw, 25 s on 2 cores): the default suite checks the lone view's margin on a_lag_the_validate_runs_e_theta_cannot_see_is_judged_on_their_equation_error (a true lag through it) and a growing friction on a_fast_growing_dry_torque_is_not_named_a_constant_one; docs/discovery.md, An input effect the validate runs' E_θ cannot see"]
fn a_growing_friction_is_not_named_a_lag_on_one_views_bare_pass() {
    let (seed, b, mu, departure) = drawn_departure("dry_torque_growth", 0, 500_000);
    let s = discover_with(seed, b, mu, &departure);
    let d = &s.discovery;
    assert!(
        d.accepted().is_empty(),
        "named {:?} for a growing friction ({departure})",
        d.accepted()
    );
    let lag = d.row("accel_delay").expect("the lag was screened");
    assert!(
        lag.note.contains("their equation error judges it alone"),
        "{}",
        lag.note
    );
}

/// An encoder decoded at twice its counts (8192 a turn under a 4096 header, the quadrature
/// mistake): every angle is doubled, far outside what a small correction describes. Nothing may
/// be named and `unexplained` must speak. Measured: on two kept CLI designs of the growth test
/// nothing was named and nothing said, μ pinned at its search bound 0.25 (now: "the base
/// model's own fit is cut short by its search range"); on this test's first draw nothing was
/// said either, with no bound hit but a chaotic validate run whose segment predictions missed
/// 62 % of how far its angle moved (now: "the model in hand does not follow runs r08"; 0.06–8.5 %
/// on campaigns with nothing hidden or with run-to-run friction).
#[test]
#[ignore = "slow set (two drawn designs, 33 s on 2 cores beside another test; the departure survey draws encoders 2–8 % off): the default suite checks a mislabelled encoder on regression_issue_14_mislabelled_encoder_is_unexplained and an_encoder_under_its_header_is_not_named_an_inertia_the_refit_cannot_reach; README, Tests"]
fn encoder_at_twice_its_counts_is_unexplained() {
    let mut r = rng(7);
    for case in 0..2 {
        let (b, mu) = (r.random_range(0.3..0.7), r.random_range(0.08..0.2));
        let s = discover_with(7700 + case, b, mu, "encoder_cpr_true = 8192");
        let d = &s.discovery;
        assert!(
            d.accepted().is_empty(),
            "case {case}: named {:?} for an encoder at twice its counts",
            d.accepted()
        );
        assert!(d.unexplained.is_some(), "case {case}: nothing said");
    }
}

/// A departure outside its physical range is refused when the case is read, naming its key: a
/// negative friction growth (or spring) would feed energy in, which no rig does.
#[test]
fn departures_outside_their_range_are_refused_by_key() {
    for (departure, key) in [
        (
            "dry_torque_growth_nm_per_s = -3e-4",
            "dry_torque_growth_nm_per_s",
        ),
        (
            "torsion_spring_nm_per_rad = -0.1",
            "torsion_spring_nm_per_rad",
        ),
        ("encoder_cpr_true = 0.0", "encoder_cpr_true"),
        ("encoder_backlash_rad = -0.01", "encoder_backlash_rad"),
        ("mu_run_spread = 1.5", "mu_run_spread"),
        (
            "torsion_spring_nm_per_rad = 0.1\ncable_slack_rad = -0.2",
            "cable_slack_rad",
        ),
        ("cable_slack_rad = 0.5", "cable_slack_rad"),
        ("cable_anchor_rad = 0.3", "cable_anchor_rad"),
        ("bob_bounce_hz = 0.0", "bob_bounce_hz"),
        (
            "bob_bounce_hz = 5.0\nbob_bounce_damping_ratio = -0.1",
            "bob_bounce_damping_ratio",
        ),
        ("bob_bounce_damping_ratio = 0.1", "bob_bounce_damping_ratio"),
        (
            "torsion_spring_nm_per_rad = 0.1\ncable_anchor_rad = 4.0",
            "cable_anchor_rad",
        ),
        (
            "encoder_eccentricity_rad = -0.01",
            "encoder_eccentricity_rad",
        ),
        ("dry_torque_lobes_nm = -0.01", "dry_torque_lobes_nm"),
        ("axis_sway_ratio = 0.7", "axis_sway_ratio"),
        (
            "cubic_drag_nm_s3_per_rad3 = -1e-4",
            "cubic_drag_nm_s3_per_rad3",
        ),
        ("eddy_brake_nm_s_per_rad = -0.01", "eddy_brake_nm_s_per_rad"),
        ("eddy_brake_phase_rad = 1.0", "eddy_brake_phase_rad"),
        (
            "dry_torque_lobes_nm = 0.01\ndry_torque_lobes_k = 0",
            "dry_torque_lobes_k",
        ),
        ("dry_torque_lobes_k = 2", "dry_torque_lobes_k"),
        (
            "encoder_eccentricity_rad = 0.01\nencoder_eccentricity_phase_rad = 9.0",
            "encoder_eccentricity_phase_rad",
        ),
        (
            "encoder_eccentricity_phase_rad = 1.0",
            "encoder_eccentricity_phase_rad",
        ),
    ] {
        let toml = pendulum_jobs::demo::discovery_campaign(
            "departure",
            1,
            0.0,
            0.5,
            0.15,
            &format!("\n[truth.departures]\n{departure}"),
        );
        let err = pendulum_rig::twin::TwinCase::from_toml(&toml, std::path::Path::new("case.toml"))
            .expect_err(departure)
            .to_string();
        assert!(
            err.contains(&format!("truth.departures.{key}")),
            "{departure}: {err}"
        );
    }
}

/// A departure drawn for [`survey_departures_name_nothing`]: the table's draw of it.
type DrawDeparture = fn(&mut rand_chacha::ChaCha8Rng) -> String;

/// The survey's departures, each with how its size is drawn: wider than the regression tests
/// above (springs from barely felt to stiff, encoders mislabelled on either side of their
/// header, plays, growths and run spreads from small to large).
const DEPARTURES: [(&str, DrawDeparture); 13] = [
    ("torsion_spring", |r| {
        let k = (r.random_range(0.02f64.ln()..0.3f64.ln())).exp();
        format!("torsion_spring_nm_per_rad = {k}")
    }),
    ("slack_cable", |r| {
        let k = r.random_range(0.05..0.3);
        let slack = r.random_range(0.2..1.0);
        format!("torsion_spring_nm_per_rad = {k}\ncable_slack_rad = {slack}")
    }),
    ("encoder_cpr", |r| {
        // 2–8 % off its header, either side.
        let off = r.random_range(0.02..0.08) * if r.random_bool(0.5) { 1.0 } else { -1.0 };
        format!("encoder_cpr_true = {}", 4096.0 * (1.0 + off))
    }),
    ("dry_torque_growth", |r| {
        let rate = (r.random_range(1e-4f64.ln()..6e-4f64.ln())).exp();
        format!("dry_torque_growth_nm_per_s = {rate}")
    }),
    ("encoder_backlash", |r| {
        format!("encoder_backlash_rad = {}", r.random_range(0.004..0.04))
    }),
    ("mu_run_spread", |r| {
        format!("mu_run_spread = {}", r.random_range(0.1..0.4))
    }),
    ("anchored_cable", |r| {
        // A cable anchored to one side: a spring plus a constant torque k·anchor.
        let k = (r.random_range(0.03f64.ln()..0.3f64.ln())).exp();
        let anchor = r.random_range(0.1..0.6) * if r.random_bool(0.5) { 1.0 } else { -1.0 };
        format!("torsion_spring_nm_per_rad = {k}\ncable_anchor_rad = {anchor}")
    }),
    ("bob_bounce", |r| {
        // A bob on a springy mount, from soft (3 Hz, near the crank's second harmonic) to stiff
        // (12 Hz), lightly to well damped.
        let hz = (r.random_range(3f64.ln()..12f64.ln())).exp();
        let zeta = r.random_range(0.02..0.2);
        format!("bob_bounce_hz = {hz}\nbob_bounce_damping_ratio = {zeta}")
    }),
    ("encoder_eccentricity", |r| {
        // A code disc off its shaft's centre: e/R from a fine mount (0.003 rad, 2 counts) to a
        // sloppy one (0.02 rad), its peak anywhere on the turn.
        let phi = r.random_range(-std::f64::consts::PI..std::f64::consts::PI);
        let eps = (r.random_range(0.003f64.ln()..0.02f64.ln())).exp();
        format!("encoder_eccentricity_phase_rad = {phi}\nencoder_eccentricity_rad = {eps}")
    }),
    ("dry_torque_lobes", |r| {
        // A bent shaft (1 lobe) or an oval seal (2, 3) dragging 0 to 2T around the turn, T from
        // a seal's 3e-3 N·m to 1.5e-2 N·m.
        let k = r.random_range(1..=3u32);
        let phi = r.random_range(-std::f64::consts::PI..std::f64::consts::PI);
        let t = (r.random_range(3e-3f64.ln()..1.5e-2f64.ln())).exp();
        format!(
            "dry_torque_lobes_k = {k}\ndry_torque_lobes_phase_rad = {phi}\ndry_torque_lobes_nm = {t}"
        )
    }),
    ("axis_sway", |r| {
        // A bearing bracket swaying with the table as a tilted guide of 0.02–0.08 rad would move
        // the axis (the catalogue's own tilt draws), either side, unseen by the accelerometer.
        let s = r.random_range(0.02..0.08) * if r.random_bool(0.5) { 1.0 } else { -1.0 };
        format!("axis_sway_ratio = {s}")
    }),
    ("cubic_drag", |r| {
        // A drag c θ̇³ from a twelfth of the viscous drag's torque at 5 rad/s (b 0.5 N·s/m on a
        // 0.25 m bob: 0.16 N·m) to as much as it (1e-4 to 1.3e-3 N·m·s³/rad³), which the
        // catalogue's viscous and quadratic drags only approximate.
        let c = (r.random_range(1e-4f64.ln()..1.3e-3f64.ln())).exp();
        format!("cubic_drag_nm_s3_per_rad3 = {c}")
    }),
    ("eddy_brake", |r| {
        // A magnet beside the swing, anywhere on the turn, braking from a sixth of the viscous
        // drag's torque coefficient (b 0.5 N·s/m on a 0.25 m bob: 0.031 N·m·s/rad) to one and a
        // half times it where it is strongest.
        let phi = r.random_range(-std::f64::consts::PI..std::f64::consts::PI);
        let c = (r.random_range(0.005f64.ln()..0.05f64.ln())).exp();
        format!("eddy_brake_phase_rad = {phi}\neddy_brake_nm_s_per_rad = {c}")
    }),
];

/// The survey's campaign `k` of departure `name`: (campaign seed, b, μ, the departure's lines).
/// `off` shifts every tag and seed (the survey's `DEPARTURE_SEED` × 100 000; 0 for the
/// regression tests).
fn drawn_departure(name: &str, k: u64, off: u64) -> (u64, f64, f64, String) {
    let d_idx = DEPARTURES.iter().position(|(n, _)| *n == name).unwrap();
    let mut r = rng(100 + d_idx as u64 + off);
    let mut out = None;
    for _ in 0..=k {
        let departure = (DEPARTURES[d_idx].1)(&mut r);
        let (b, mu) = (r.random_range(0.3..0.7), r.random_range(0.08..0.2));
        out = Some((b, mu, departure));
    }
    let (b, mu, departure) = out.unwrap();
    (9000 + 100 * d_idx as u64 + k + off, b, mu, departure)
}

/// Survey (slow, by hand with `--ignored`): every twin departure outside the catalogue over
/// `DEPARTURE_N` drawn campaigns each (default 3), at sizes drawn as [`DEPARTURES`] says,
/// damping drawn as the false-alarm survey draws it. Prints what each names and says; asserts
/// that none names a catalogue effect (effects.md: the nearest catalogue entry is not the
/// cause). `DEPARTURE_ONE=name:k` re-runs one (`KEEP_DEP=PREFIX` keeps its case);
/// `DEPARTURE_SEED=s` draws other campaigns.
#[test]
#[ignore = "survey for issue 14 item 3: 13 departures × DEPARTURE_N (default 3) drawn campaigns; DEPARTURE_N=5 took 1247 s on 2 cores beside another run (1c00f79)"]
fn survey_departures_name_nothing() {
    let n: u64 = std::env::var("DEPARTURE_N")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3);
    let one = std::env::var("DEPARTURE_ONE").ok();
    let off = 100_000
        * std::env::var("DEPARTURE_SEED")
            .ok()
            .and_then(|v| v.parse::<u64>().ok())
            .unwrap_or(0);
    let (mut named, mut said, mut total) = (0, 0, 0);
    let mut wrong = Vec::new();
    for (name, _) in DEPARTURES {
        for k in 0..n {
            if one.as_deref().is_some_and(|o| o != format!("{name}:{k}")) {
                continue;
            }
            let (seed, b, mu, departure) = drawn_departure(name, k, off);
            let s = discover_with(seed, b, mu, &departure);
            let d = &s.discovery;
            total += 1;
            named += usize::from(!d.accepted().is_empty());
            said += usize::from(d.unexplained.is_some());
            let line = format!(
                "survey-departure {name} k={k} ({}) b={b:.3} mu={mu:.3} accepted={:?} variable={:?} unexplained={:?}",
                departure.replace('\n', ", "),
                d.accepted(),
                d.unexplained_description.as_ref().map(|x| x.variable),
                d.unexplained
            );
            eprintln!("{line}");
            if !d.accepted().is_empty() {
                wrong.push(line);
            }
        }
    }
    eprintln!(
        "survey-departure: a catalogue effect named in {named} of {total}; `unexplained` said in {said} of {total}"
    );
    assert!(wrong.is_empty(), "{wrong:#?}");
}

/// Runs the departure survey's campaign `k` of `name`, whose last drawn number is the size
/// `term` must describe, and checks that nothing is named and that `unexplained` describes it
/// following `variable`, with `term`'s coefficient within `rel` of that size; returns the words.
fn described_within(name: &str, k: u64, variable: Variable, term: &str, rel: f64) -> String {
    let (seed, b, mu, departure) = drawn_departure(name, k, 0);
    let size: f64 = departure.rsplit(' ').next().unwrap().parse().unwrap();
    let s = discover_with(seed, b, mu, &departure);
    let d = &s.discovery;
    assert!(d.accepted().is_empty(), "named {:?}", d.accepted());
    let desc = d.unexplained_description.as_ref().expect("a description");
    assert_eq!(desc.variable, variable, "{desc:?}");
    let v = coefficient_of(desc, term);
    assert!(
        (v - size).abs() < rel * size,
        "{departure}: described as {v:.4e} × {term}"
    );
    d.unexplained.clone().unwrap_or_default()
}

/// The coefficient of the library term named `term` in a description (N·m per its unit).
fn coefficient_of(desc: &pendulum_discover::sparse::Description, term: &str) -> f64 {
    desc.terms
        .iter()
        .find(|(j, _, _)| LIBRARY[*j].name == term)
        .map(|&(_, v, _)| v)
        .unwrap_or_else(|| panic!("no {term} term in {desc:?}"))
}

/// A torsion spring too weak to tell from a `position_torque` k = 1 by the share it leaves
/// (0.028 N·m/rad, the departure survey's draw 2): sin θ and cos θ took ΔBIC −414 of it and the
/// one term θ did 75 better (a share of 0.85, above the partial rule's 0.75). It was named, and
/// a k = 2 position torque beside it. A shape no freer than the candidate's that fits clearly
/// better makes the candidate the wrong shape: `unexplained`, following the unwrapped θ, a
/// spring, its k within 10 %.
/// A bearing bracket that sways with the table (the axis moves x = s·y relative to the worktable,
/// the departure survey's `axis_sway` draw 0): the pendulum feels it exactly as a tilted guide,
/// so the screen fits `horizontal_base` at about atan s, and before the accelerometer's reading
/// was asked every check of the pendulum's own views agreed. But effects.md's tilt moves the
/// worktable, which the accelerometer's x axis sees; here it reads no tilt. Nothing may be
/// named, `unexplained` must be said, and the tilt's row must say what the accelerometer read.
#[test]
fn a_swaying_bracket_is_not_named_a_tilt_the_accelerometer_does_not_see() {
    let (seed, b, mu, departure) = drawn_departure("axis_sway", 0, 0);
    let s = discover_with(seed, b, mu, &departure);
    let d = &s.discovery;
    assert!(
        d.accepted().is_empty(),
        "named {:?} for a swaying bracket ({departure}): {:#?}",
        d.accepted(),
        d.rows
    );
    let words = d
        .unexplained
        .as_deref()
        .unwrap_or_else(|| panic!("no `unexplained` for {departure}: {:#?}", d.rows));
    let tilt = d.row("horizontal_base").expect("a tilt row");
    assert!(
        tilt.note.contains("the accelerometer's horizontal axis")
            && words.contains("the guide is not tilted so"),
        "{}\n{words}",
        tilt.note
    );
}

#[test]
fn a_weak_torsion_spring_is_not_named_a_position_torque() {
    let words = described_within("torsion_spring", 2, Variable::Angle, "θ", 0.1);
    assert!(words.contains("a spring"), "{words}");
}

/// A drag growing as the cube of the speed (2.59e-4 N·m·s³/rad³, the departure survey's
/// `cubic_drag` draw 1), a shape between the catalogue's drags: the generator's dead band
/// (a torque that starts beyond a speed and then grows) screens at ΔBIC −205 on it, and the
/// viscous and quadratic drags of the base take up the rest. None of them is the cause:
/// nothing named, `unexplained` following dθ/dt, cubic, its coefficient within 10 %.
#[test]
fn a_cubic_drag_is_described_not_named_a_generator() {
    let words = described_within("cubic_drag", 1, Variable::Rate, "θ̇³", 0.1);
    assert!(words.contains("cubic in dθ/dt"), "{words}");
}

/// A viscous drag over part of the turn (an eddy-current brake, 8.6e-3 N·m·s/rad where it is
/// strongest, at φ −1.42 rad: the departure survey's `eddy_brake` draw 1), which no catalogue
/// drag (the same all around the turn) describes: nothing named, and `unexplained` follows dθ/dt
/// in the brake's own shape, c (1 + cos(θ − φ))/2 θ̇ = c/2 θ̇ + c/2 cos φ θ̇ cos θ + c/2 sin φ
/// θ̇ sin θ, its two larger coefficients within 10 % (the library holds θ̇ sin θ and θ̇ cos θ since
/// the seventy-first session; before, its words were a dry friction's).
#[test]
fn an_eddy_brake_is_described_in_its_own_shape_not_named() {
    let (departure, s) = discovered_naming_nothing("eddy_brake", 1, 0);
    let value = |key: &str| -> f64 {
        departure
            .lines()
            .find_map(|l| l.strip_prefix(key)?.strip_prefix(" = ")?.parse().ok())
            .unwrap_or_else(|| panic!("no {key} in {departure}"))
    };
    let (c, phi) = (
        value("eddy_brake_nm_s_per_rad"),
        value("eddy_brake_phase_rad"),
    );
    let d = &s.discovery;
    let words = d.unexplained.clone().expect("`unexplained` said");
    assert!(
        words.contains("a torque that follows dθ/dt")
            && words.contains("a viscous drag that varies around the turn"),
        "{words}"
    );
    let desc = d.unexplained_description.as_ref().expect("a description");
    for (term, truth) in [("θ̇", c / 2.0), ("θ̇ sin θ", c / 2.0 * phi.sin())] {
        let v = coefficient_of(desc, term);
        assert!(
            (v - truth).abs() < 0.1 * truth.abs(),
            "{departure}: described as {v:.4e} × {term}, truth {truth:.4e}"
        );
    }
}

/// A dry torque growing fast (4.5e-4 N·m/s, the departure survey's draw 0) fitted well enough
/// as a constant one that both views agreed on it: `coulomb_constant` was named. Its size
/// following time is a freer shape of the same torque (t sgn θ̇ beside sgn θ̇), which no
/// catalogue entry of one fixed size is: `unexplained`, following time, growing, the rate
/// within 25 %.
#[test]
fn a_fast_growing_dry_torque_is_not_named_a_constant_one() {
    let words = described_within("dry_torque_growth", 0, Variable::Time, "t sgn θ̇", 0.25);
    assert!(words.contains("growing with time"), "{words}");
}

/// A 0.029 rad encoder backlash (the departure survey's draw 0) was named a −0.74 ms
/// accelerometer "delay": a lead, which no filter or read latency makes. Refused as physically
/// impossible, and said.
#[test]
fn an_encoder_backlash_is_not_named_an_accelerometer_lead() {
    let words = named_nothing_and_said("encoder_backlash", 0, 0);
    assert!(words.contains("physically impossible"), "{words}");
}

/// An encoder counting 7 % under its header (3804 a turn, the departure survey's draw 1 at
/// `DEPARTURE_SEED=1`) was named a 0.032 kg·m² extra inertia, its trajectory refit stopped at its
/// widened search bound (0.04): a value the bound set, not the data. Nothing is named, and
/// `unexplained` speaks of the angle itself (not only of dθ/dt). The identify runs, swinging
/// gently, show no structure (the angle's scale error is third order in a swing); the chaotic
/// validate run the model does not follow carries it, and its own rows' equation error varies
/// with θ (mod 2π). (From 57f7ff3 to this test's commit only "does not follow run r07" was said:
/// the sparse description that had named θ no longer cleared its entry bar.)
#[test]
fn an_encoder_under_its_header_is_not_named_an_inertia_the_refit_cannot_reach() {
    let words = named_nothing_and_said("encoder_cpr", 1, 100_000);
    assert!(
        words.contains("θ (mod 2π)")
            || words.contains("unwrapped θ")
            || words.contains("θ (unwrapped)"),
        "{words}"
    );
}

/// A 0.022 rad encoder backlash through chaos (the departure survey's draw 3 at
/// `DEPARTURE_SEED=1`, μ 0.086) was named `bearing_load_base_accel`: the screen's μ 0.117
/// [0.106, 0.129], the refit's 0.090, and the screen's value passed as "fitting the trajectories
/// as well as the refit" where the trajectories could not tell the switch from its absence (the
/// held-out E_θ fall was 3.1 % ± 7.2 %). A switch's trajectory check now compares with the
/// model without it. Nothing is named, and `unexplained` speaks of dθ/dt.
#[test]
#[ignore = "slow set (the departure survey's draw 3 at DEPARTURE_SEED=1, 47 s): the default suite checks a backlash on an_encoder_backlash_is_not_named_an_accelerometer_lead, and a switch the trajectories cannot tell from its absence on a_bearing_load_the_trajectories_cannot_tell_from_its_absence_is_named_at_the_screens_value; README, Tests"]
fn an_encoder_backlash_is_not_named_a_bearing_load_the_trajectories_cannot_see() {
    let words = named_nothing_and_said("encoder_backlash", 3, 100_000);
    assert!(words.contains("dθ/dt"), "{words}");
}

/// A dry torque growing slowly (1.4e-4 N·m/s, the departure survey's draw 4) beside a base fit
/// stuck at a = 0.73 kg/m, b = 0.020 N·s/m (the truth: 0, 0.60) was named a 3.7e-4 N·m constant
/// dry torque on the second look: its refit, started from the screen's damping, left the stuck
/// basin and took 14.3 % ± 4.9 % off the validate runs' E_θ, while the current model's own
/// refits stayed there. The same model refitted from the candidate's refit with the torque at 0
/// does as well, so the fall was the damping's: nothing is named.
#[test]
fn a_growing_dry_torque_is_not_credited_with_the_damping_its_refit_repairs() {
    named_nothing("dry_torque_growth", 4, 0);
}

/// A bearing whose μ differs from run to run (`mu_run_spread` 0.18, the departure survey's
/// draw 4 at `DEPARTURE_SEED=4`): on the second look a breakaway refitted at 9.2e-4 N·m with
/// v_s 1.23 rad/s (past effects.md's typical 0.05–0.5: over most swings a constant dry torque)
/// took 9.4 % ± 4.3 % off the validate runs' E_θ, and the identify runs' equation error at that
/// shape held 5.9e-4 ± 4.3e-4 N·m; beside a constant dry torque its interval reaches below 0. A
/// breakaway the equation error cannot tell from the effect it generalises is not named on it.
#[test]
#[ignore = "slow set (the departure survey's draw 4 at DEPARTURE_SEED=4): the default suite checks a friction that differs from run to run on a_friction_that_differs_on_the_validate_runs_is_not_named_a_generator, and a breakaway refused where it generalises a constant dry torque on a_constant_dry_torque_is_not_named_as_a_breakaway_it_equals; README, Tests"]
fn a_run_to_run_friction_is_not_named_a_breakaway_that_is_a_constant_dry_torque() {
    named_nothing("mu_run_spread", 4, 400_000);
}

/// A cable anchored 0.50 rad off the hanging position (a 0.103 N·m/rad spring −κ(θ − θ_a),
/// the departure survey's draw 0 at `DEPARTURE_SEED=3`) shifts the rest angle as an encoder
/// offset would, and was named a −0.016 rad `encoder_offset` on the second look (E_θ fall
/// 32 % ± 5 %, freeing the pinned base) while the validate runs' equation error rose 7.5 %
/// (noise 5.7 %) and a spring in the unwrapped θ took 89 % off it. Freeing the base stands in
/// for that view's confirmation, not against it: nothing named, the words speak of θ.
#[test]
#[ignore = "slow set (the departure survey's draw 0 at DEPARTURE_SEED=3, 49 s on 2 cores): the default suite checks a cable's rest not named an offset on a_cable_whose_rest_an_offset_takes_up_is_not_named_one_beside_the_spring_left; README, Tests"]
fn a_cable_anchored_off_the_vertical_is_not_named_an_encoder_offset() {
    let words = named_nothing_and_said("anchored_cable", 0, 300_000);
    assert!(words.contains("θ (unwrapped)"), "{words}");
}

/// A 0.0586 N·m/rad torsion spring on a drawn design (the departure survey's `torsion_spring`
/// k=2 at `DEPARTURE_SEED=24`) was named a 1.2e-2 N·m breakaway on the second look: the validate
/// runs' E_θ fell 22.5 % ± 10.1 %, their equation error 0.8 % (5 % needed), and the spring was
/// described beside it at +5.857e-2 N·m/rad (its held-out equation-error fall 99.5 %). A
/// candidate that view does not confirm, with what remains following the unwrapped θ, is a
/// partial explanation of that torque, whatever the effect: nothing named, the words speak of θ.
#[test]
fn a_spring_is_not_named_a_breakaway_the_validate_equation_error_does_not_confirm() {
    refused_and_said(
        "torsion_spring",
        2,
        2_400_000,
        "stribeck",
        "still follows the unwrapped angle",
        "θ (unwrapped)",
    );
}

/// The same departure drawn at `DEPARTURE_SEED=13` (draw 1: 0.242 N·m/rad anchored at −0.106 rad,
/// on mixed bobs) was named a −0.0118 rad `encoder_offset` on the second look: E_θ fell 57.1 % ±
/// 14.8 %, the validate runs' equation error 0.2 % (an offset's own column is blind there), and
/// an unexplained spring was described beside it at +0.242 N·m/rad. With the offset's columns in,
/// what remains still follows the unwrapped θ, which no offset makes: the offset is a partial
/// explanation of that torque. Nothing named, the offset's row says why, the words speak of θ.
#[test]
fn a_cable_whose_rest_an_offset_takes_up_is_not_named_one_beside_the_spring_left() {
    refused_and_said(
        "anchored_cable",
        1,
        1_300_000,
        "encoder_offset",
        "still follows the unwrapped angle",
        "θ (unwrapped)",
    );
}

/// The same departure drawn at `DEPARTURE_SEED=42` (draw 1: 0.252 N·m/rad anchored at +0.348 rad,
/// eight mixed bobs of m g l 1.29 to 3.67 N·m) was named a 3.8e-2 rad `encoder_offset` on the
/// second look: E_θ fell 10.2 % ± 9.0 %, the validate runs' equation error 3.0 %, and the runs'
/// free decays, hanging at 0.064 down to 0.026 rad (about 0.08 N·m over each bob's m g l),
/// "confirmed" it as an offset of the reading. Centres that hang by their bobs read a torque the
/// rig carries, not an offset: nothing named, the offset's row says why, the words speak of θ.
#[test]
#[ignore = "slow set (the departure survey's draw 1 at DEPARTURE_SEED=42): the default suite checks the rule on readings::tests::a_torque_the_bob_balances_hangs_by_the_bob_an_offset_does_not and a cable's rest not named an offset on a_cable_whose_rest_an_offset_takes_up_is_not_named_one_beside_the_spring_left; README, Tests"]
fn a_cable_whose_bobs_hang_by_their_weight_is_not_named_an_encoder_offset() {
    refused_and_said(
        "anchored_cable",
        1,
        4_200_000,
        "encoder_offset",
        "hang by their bobs",
        "θ (mod 2π)",
    );
}

/// A bearing whose μ differs from run to run by up to 24 % (the departure survey's draw 0 at
/// `DEPARTURE_SEED=3`) was named a 3.5e-3 N·m constant dry torque on the second look (E_θ
/// fall 33 % ± 22 %), while with that torque in each run's own damping factor still took
/// 35.6 % ± 12.2 % off the other blocks' equation error. A loss that leaves the runs
/// disagreeing beyond twice the bar explains the departure only in part: nothing named, and the
/// words say the torque follows the run.
#[test]
#[ignore = "slow set (the departure survey's draw 0 at DEPARTURE_SEED=3): the default suite checks a friction that differs from run to run on a_friction_that_differs_on_the_validate_runs_is_not_named_a_generator (nothing named, the words say the torque follows the run); README, Tests"]
fn a_friction_that_differs_from_run_to_run_is_not_named_a_constant_dry_torque() {
    let words = named_nothing_and_said("mu_run_spread", 0, 300_000);
    assert!(words.contains("follows the run"), "{words}");
}

/// The same departure drawn at `DEPARTURE_SEED=4` (draw 3: μ × up to 1.24 per run), whose four
/// identify runs happened to agree on their damping (factors within 3 %), was named a 6.5e-4
/// N·m·s/rad `generator_rectified` (ω_d 0.28 rad/s: 1.6 % more viscous damping; E_θ fall 14.3 %
/// ± 13.1 %, equation error 24.3 %). The runs' disagreement is asked of every run, each judged
/// on the blocks its factor was not fitted to: with the validate runs the factors took 29.1 % ±
/// 10.3 % off. Nothing named, and the words say the torque follows the run.
#[test]
fn a_friction_that_differs_on_the_validate_runs_is_not_named_a_generator() {
    let words = named_nothing_and_said("mu_run_spread", 3, 400_000);
    assert!(words.contains("follows the run"), "{words}");
}

/// The same departure drawn at `DEPARTURE_SEED=31` (draw 4: μ × up to 1.25 per run) was named a
/// 3.58e-3 N·m·s/rad `generator_rectified` on evidence short everywhere of twice its bar (E_θ
/// fall 8.1 % ± 5.9 %; the validate runs' equation error 10.5 %, confirmed by its signed ranks;
/// the runs' own damping factors, with it in, 29.3 % ± 27.9 %). Given a size of its own in each
/// run, the generator's identify runs read −4.8e-3 to 2.0e-3 (Chow's F test p = 8.7e-6), its
/// validate runs p = 2.6e-6: a torque of the rig has one size in every run. Nothing named, the
/// generator's row says why, and the words say the torque follows the run.
#[test]
fn a_friction_whose_size_follows_the_run_is_not_named_a_generator() {
    refused_and_said(
        "mu_run_spread",
        4,
        3_100_000,
        "generator_rectified",
        "its size differs from run to run",
        "follows the run",
    );
}

/// The same departure drawn at `DEPARTURE_SEED=13` (draw 4: μ × up to 1.30 per run, on mixed
/// bobs), whose run factors with a generator in agreed (the other blocks' equation error rose
/// 11 % with them), was named a 5.5e-3 N·m·s/rad `generator_rectified` whose refit put its dead
/// band at ω_d = 0, the range's bottom: a linear viscous torque c_g θ̇ on every run, the
/// reference's own b l² θ̇ freed from each run's l². A shape refitted to an end of its range was
/// set by the bound, and a shape at 0 is no absence. Nothing named, and the generator's row says
/// why.
#[test]
fn a_friction_that_differs_from_run_to_run_is_not_named_a_generator_at_zero_dead_band() {
    let d = refused(
        "mu_run_spread",
        4,
        1_300_000,
        "generator_rectified",
        "stops at its search range's bound",
    );
    assert!(d.unexplained.is_some(), "nothing said");
}

/// An off-centre code disc (ε 9.3e-3 rad, its peak at φ 1.43 rad: the departure survey's draw 0
/// at `DEPARTURE_SEED=4`) reads θ + ε(sin(θ − φ) + sin φ), zeroed hanging: on the rotating runs
/// its mean over a turn, ε sin φ, looks like an encoder offset, on the resting ones there is
/// none. It was named a 7.7e-3 rad `encoder_offset` (refit 4.4e-3) on an E_θ fall of 9.3 % ±
/// 8.6 % while the validate runs' equation error rose 2.6 %: an offset's linearised column
/// was exempt from that view's contradiction. Nothing named, and the words say the error
/// follows θ (mod 2π).
#[test]
#[ignore = "slow set (the departure survey's draw 0 at DEPARTURE_SEED=4, 28 s): the default suite checks a code disc named nothing on an_off_centre_code_disc_is_not_named_a_position_torque_on_the_equation_error_alone; README, Tests"]
fn an_off_centre_code_disc_is_not_named_an_encoder_offset() {
    let words = named_nothing_and_said("encoder_eccentricity", 0, 400_000);
    assert!(words.contains("θ (mod 2π)"), "{words}");
}

/// A code disc mounted 0.0156 rad off centre (its peak at φ 2.56 rad: the departure survey's draw
/// 3 at `DEPARTURE_SEED=6`) reads, on swings about the bottom, like an inertia growing with each
/// run's bob: the identify runs' screen put it at 2.24e-4 kg·m² (1.04 % of the lightest bob's
/// m l², whose 1 % is the rig's own tolerance), their trajectories at 1.31e-4, which they told
/// from 0; it was named an `extra_inertia` on the validate runs' equation error (30.6 %) while
/// their E_θ fell 8.0 % ± 10.2 %. An inertia one view puts within the tolerance is not named;
/// the remaining error is reported.
#[test]
#[ignore = "slow set (the departure survey's draw 3 at DEPARTURE_SEED=6, 24 s): the default suite checks a code disc named nothing on an_off_centre_code_disc_is_not_named_a_position_torque_on_the_equation_error_alone; README, Tests"]
fn an_off_centre_code_disc_is_not_named_an_inertia_its_trajectories_put_within_the_tolerance() {
    named_nothing_and_said("encoder_eccentricity", 3, 600_000);
}

/// A code disc mounted 0.0068 rad off centre (its peak at φ 2.92 rad: the departure survey's draw
/// 4 at `DEPARTURE_SEED=10`, first drawn on 3f6da80) was named a k = 1 position torque: screened
/// at 6.7e-3 N·m [5.7e-3, 8.2e-3], refitted at 3.9e-3, the two "agreeing" only because the
/// trajectories fit the screen's value as well as their own, and confirmed by the validate runs'
/// equation error (22.6 % against 6.6 %) while their E_θ fell 3.7 % ± 6.4 %: a size measured by
/// the equation error alone. Nothing named, the position torque's row says why, and the words
/// say the error follows θ (mod 2π).
#[test]
fn an_off_centre_code_disc_is_not_named_a_position_torque_on_the_equation_error_alone() {
    disc_refused_as_a_torque_and_said(4, 1_000_000, "rests on the equation error alone");
}

/// [`refused`] for the departure survey's off-centre code disc `k` (draws shifted by `off`), the
/// position torque's row saying `why`, and the words saying the error follows θ (mod 2π).
fn disc_refused_as_a_torque_and_said(k: u64, off: u64, why: &str) {
    refused_and_said(
        "encoder_eccentricity",
        k,
        off,
        "position_torque",
        why,
        "θ (mod 2π)",
    );
}

/// A code disc mounted 6.9e-3 rad off centre (its peak at φ 2.04 rad: the departure survey's
/// draw 2 at `DEPARTURE_SEED=28`, first drawn on 4d5daef) was named a 7.1e-3 N·m k = 1 position
/// torque on the validate runs' E_θ (38.2 % ± 30.5 %; their equation error, blind to it, rose
/// 6.1 %), its screen's interval [2.2e-4, 1.39e-2] barely leaving out 0. The disc's reading
/// carries ε θ̇² sin(θ − φ), so the k = 1 columns take one size in the windows where the
/// pendulum moves fast and another where it moves slowly: the identify rows' split stands at
/// p = 8.8e-6 (a torque of the angle alone has one size at every speed). Nothing named, the
/// torque's row says why.
#[test]
#[ignore = "slow set (a departure survey draw, about a minute; added in the sixty-second session): the default suite checks the rule on the pendulum-discover unit test a_torque_of_the_angle_alone_holds_one_size_at_every_speed and a code disc on an_off_centre_code_disc_is_not_named_a_position_torque_on_the_equation_error_alone; README, Tests"]
fn an_off_centre_code_disc_is_not_named_a_position_torque_whose_size_follows_the_speed() {
    refused(
        "encoder_eccentricity",
        2,
        2_800_000,
        "position_torque",
        "a torque of the angle alone has one size at every speed",
    );
}

/// A code disc mounted 3.3e-3 rad off centre (its peak at φ −0.78 rad: the departure survey's
/// draw 0 at `DEPARTURE_SEED=25`, first drawn on e34d710) was named a 2.5e-3 N·m k = 1 position
/// torque (1.3 counts on its lightest bob) on the validate runs' equation error (13.4 % against
/// 5.9 %) while their E_θ fell 1.8 % ± 11.2 %. Its validate rows split by speed at p = 4e-14,
/// their fast windows' torque 1.54e-2 N·m apart from the slow ones' (a torque of the angle alone
/// has one size at every speed). Nothing named, and the words say the remaining error follows θ
/// (mod 2π).
#[test]
#[ignore = "slow set (a departure survey draw, about a minute; added in the sixty-second session): the default suite checks the rule on the pendulum-discover unit test a_torque_of_the_angle_alone_holds_one_size_at_every_speed and a code disc on an_off_centre_code_disc_is_not_named_a_position_torque_on_the_equation_error_alone; README, Tests"]
fn an_off_centre_code_disc_whose_fast_windows_read_a_larger_torque_is_unexplained() {
    disc_refused_as_a_torque_and_said(
        0,
        2_500_000,
        "a torque of the angle alone has one size at every speed",
    );
}

/// A dry torque growing with time, 5.7e-4 N·m/s (the departure survey's draw 4 at
/// `DEPARTURE_SEED=11`, first drawn on 5fc8793), was named a k = 1 position torque: screened at
/// 3.4e-3 N·m [1.8e-3, 5.0e-3], refitted at 1.1e-3, the two "agreeing" only because the
/// trajectories fit the screen's value as well as their own, and confirmed by the validate runs'
/// E_θ at the refit's value (11.1 % ± 10.1 %) but not at the screen's (19.9 % ± 22.9 %): the two
/// views put it at different sizes. Since 06aecc1 the refit's 1.1e-3 N·m is read first as
/// within the rig's tolerance: under one encoder count of tilt on any bob rig.md allows (the
/// lightest's m g l, 1.24 N·m, makes a count 1.9e-3 N·m), and the row says so, the validate
/// runs' E_θ at the screen's value beside it. Nothing named, the position torque's row says why,
/// and the words say the remaining torque follows dθ/dt and grows with time (t sgn θ̇).
#[test]
fn a_growing_dry_torque_is_not_named_a_position_torque_its_refit_puts_within_the_tolerance() {
    let d = refused(
        "dry_torque_growth",
        4,
        1_100_000,
        "position_torque",
        "tilts no bob's rest by an encoder count",
    );
    let note = &d.row("position_torque").unwrap().note;
    assert!(
        note.contains("with its size held at the screen's value"),
        "{note}"
    );
    let words = d.unexplained.as_deref().expect("`unexplained` said");
    assert!(
        words.contains("follows dθ/dt") && words.contains("t sgn θ̇"),
        "{words}"
    );
}

/// Runs the departure survey's campaign `k` of `name` (draws shifted by `off`) and checks that
/// nothing is named and that `effect`'s row gives `why` it was not; returns the discovery.
fn refused(name: &str, k: u64, off: u64, effect: &str, why: &str) -> pendulum_discover::Discovery {
    let (seed, b, mu, departure) = drawn_departure(name, k, off);
    let d = discover_with(seed, b, mu, &departure).discovery;
    assert!(
        d.accepted().is_empty(),
        "{departure}: named {:?}",
        d.accepted()
    );
    let row = d.row(effect).unwrap_or_else(|| panic!("no {effect} row"));
    assert!(row.note.contains(why), "{}", row.note);
    d
}

/// [`refused`], and `unexplained` must speak, its words holding `said`.
fn refused_and_said(name: &str, k: u64, off: u64, effect: &str, why: &str, said: &str) {
    let d = refused(name, k, off, effect, why);
    let words = d.unexplained.expect("`unexplained` said");
    assert!(words.contains(said), "{words}");
}

/// Runs the departure survey's campaign `k` of `name` (draws shifted by `off`) and checks that
/// nothing is named; returns its `unexplained` words, if any.
fn named_nothing(name: &str, k: u64, off: u64) -> Option<String> {
    discovered_naming_nothing(name, k, off)
        .1
        .discovery
        .unexplained
}

/// The departure survey's draw `k` of `name` (seed offset `off`), discovered: nothing may be
/// named. Returns the departure's words (as the twin's case has them) and the summary.
fn discovered_naming_nothing(name: &str, k: u64, off: u64) -> (String, DiscoverSummary) {
    let (seed, b, mu, departure) = drawn_departure(name, k, off);
    let s = discover_with(seed, b, mu, &departure);
    let d = &s.discovery;
    assert!(
        d.accepted().is_empty(),
        "{departure}: named {:?}",
        d.accepted()
    );
    (departure, s)
}

/// [`named_nothing`], and `unexplained` must speak; returns its words.
fn named_nothing_and_said(name: &str, k: u64, off: u64) -> String {
    named_nothing(name, k, off).expect("`unexplained` said")
}
