//! The crank's speed drifting along a run (`speed_drift`): read from the accelerometer's crank
//! tracks, the runs realigned under it, and its row judged on the validate runs' tracks.

use pendulum_process::align::fit_speed_drift;
use pendulum_process::fit::{FitParam, PreparedRun};
use pendulum_process::identify::{validate, FitOutcome, RunFit};
use pendulum_process::pipeline::Context;
use pendulum_process::{ProcessError, Role};

use crate::agreement::views_agree;
use crate::discover::{DiagnosisRow, DiscoverConfig};
use crate::heldout::{e_total, heldout_gain};
use crate::readings::{per_role, per_run_mean, pool_readings, sensor_heldout, SENSOR_HELDOUT_GAIN};
use crate::trajectories::{
    is_moving, moving_runs, refit_objective, refit_profile, refit_zeroed_on, substitution_segments,
    trajectory_substitution,
};

/// What the accelerometer says about a drifting crank speed (see [`speed_drift_row`]).
pub(crate) struct DriftEvidence {
    pub(crate) fits: std::collections::BTreeMap<String, pendulum_process::align::DriftFit>,
    /// Identify runs used.
    pub(crate) n: usize,
    /// Mean dΩ/dτ, Hz/s, and the half-width of its 95 % interval.
    pub(crate) est: f64,
    pub(crate) half: f64,
    pub(crate) delta_bic: f64,
    /// Interval excludes 0 and ΔBIC beats the screen threshold.
    pub(crate) significant: bool,
    /// The validate runs' own drifts, Hz/s (the accelerometer's held-out view).
    pub(crate) val: Vec<f64>,
    /// The identify runs' own drifts, Hz/s.
    pub(crate) id: Vec<f64>,
}

/// Each shaker run's crank model refitted with a linearly drifting speed
/// ([`fit_speed_drift`]); dΩ/dτ is the identify runs' mean (interval from their scatter,
/// Student's t; ΔBIC over the runs' values against 0).
pub(crate) fn drift_evidence(ctx: &Context, cfg: &DiscoverConfig) -> Option<DriftEvidence> {
    let mut fits = std::collections::BTreeMap::new();
    for run in &ctx.runs {
        if let Some(f) = ctx
            .alignments
            .get(&run.id)
            .filter(|al| al.forcing_understood())
            .and_then(|al| fit_speed_drift(run, al))
        {
            fits.insert(run.id.clone(), f);
        }
    }
    let (d_id, val) = per_role(ctx, |r| fits.get(&r.id).map(|f| f.drift_hz_per_s));
    let n = d_id.len();
    if n < 3 {
        return None;
    }
    let (est, half, delta_bic) = per_run_mean(&d_id, 0.0);
    let excludes_zero = est - half > 0.0 || est + half < 0.0;
    Some(DriftEvidence {
        fits,
        n,
        est,
        half,
        delta_bic,
        significant: excludes_zero && delta_bic < cfg.screen_threshold,
        val,
        id: d_id,
    })
}

/// The runs re-aligned on their drifting crank phase (t0, Ω at t0, dΩ/dτ), initial states
/// re-estimated at the new t0.
pub(crate) fn realigned(ctx: &Context, ev: &DriftEvidence) -> Result<Context, ProcessError> {
    let mut ctx2 = Context::new(ctx.runs.clone());
    ctx2.steady = ctx.steady.clone();
    ctx2.steady_cfg = ctx.steady_cfg.clone();
    ctx2.hanging = ctx.hanging.clone();
    for run in &ctx.runs {
        let (Some(al), Some(ic)) = (ctx.alignments.get(&run.id), ctx.initial.get(&run.id)) else {
            continue;
        };
        let mut al2 = al.clone();
        let mut ic2 = *ic;
        if let Some(f) = ev.fits.get(&run.id) {
            al2.t0_s = f.t0_s;
            al2.omega_hz = f.omega_hz;
            al2.speed_drift_hz_per_s = f.drift_hz_per_s;
            // A constant-speed fit of a drifting crank biases its amplitude too.
            al2.accel_gain = f.accel_gain;
            ic2 = pendulum_process::ic::estimate_state(run, f.t0_s, &Default::default())?;
        }
        ctx2.alignments.insert(run.id.clone(), al2);
        ctx2.initial.insert(run.id.clone(), ic2);
    }
    Ok(ctx2)
}

/// The relative change of the crank's speed over a run beyond which a drift the tracks confirm
/// is material where the pendulum cannot judge it: a tenth of the 1 % by which rig.md lets the
/// motor's real speed differ from its set point.
pub(crate) const DRIFT_MATERIAL_SPEED_CHANGE: f64 = 1e-3;

/// `speed_drift` shows in the accelerometer before it shows in the pendulum ([`drift_evidence`]).
/// When that evidence is significant, the extended model (the runs re-aligned on the drifting
/// phase, dΩ/dτ a fitted parameter) is refitted on the identify runs and validated like any
/// candidate against the base refitted the same way; it is accepted when the validate runs'
/// E_θ falls by more than the candidates' noise rule. Accepted, it becomes the model the other
/// candidates extend, with its re-aligned runs (`FitOutcome::alignments`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn speed_drift_row(
    ev: &DriftEvidence,
    ctx2: Option<&Context>,
    cfg: &DiscoverConfig,
    base_fit: &FitOutcome,
    id_runs: &[PreparedRun],
    val_runs: &[PreparedRun],
    ics: &[f64],
) -> Result<(DiagnosisRow, Option<DriftModel>), ProcessError> {
    let (n, est, half) = (ev.n, ev.est, ev.half);
    let mut row = DiagnosisRow {
        estimate: est,
        identify_estimate: est,
        ci_low: est - half,
        ci_high: est + half,
        delta_bic: ev.delta_bic,
        screen_estimate: est,
        ..DiagnosisRow::words_only(
            "speed_drift",
            "Hz/s",
            format!("crank fits with a drifting speed on {n} identify runs; screened out"),
        )
    };
    let Some(ctx2) = ctx2.filter(|_| ev.significant && !base_fit.spec.params.is_empty()) else {
        return Ok((row, None));
    };
    let id2 = ctx2.prepared(Role::Identify, &cfg.validate.window, "discover")?;
    let val2 = ctx2.prepared(Role::Validate, &cfg.validate.window, "discover")?;
    let ics2: Vec<f64> = id2
        .iter()
        .flat_map(|r| [r.ic_est[0], r.ic_est[1]])
        .collect();
    let mut spec = base_fit.spec.clone();
    spec.params.push(FitParam::of("speed_drift"));
    spec.name = format!("{}+speed_drift", spec.name);
    let mut x0 = base_fit.params.clone();
    x0.push(est);
    // Trajectories that leave rest (see `moving_runs`) judge the drift, as they do any effect,
    // each run's encoder zeroing error held as a nuisance, as for every forcing effect's refit
    // ([`refit_zeroed_on`]). Left as measured, a run's few counts outweigh a drift's trace on
    // runs that soon come to rest: a −7.54e-4 Hz/s drift on a drawn design whose identify runs
    // all rest after their hand starts (`SURVEY_DAMPING=drawn SURVEY_SEED=16`, `speed_drift`
    // k=1), tracked within 0.01 %, was refitted at −7.3e-3, a tenfold drift the trajectories
    // preferred to the tracks' value, and the model carrying it scored 364 % worse on the
    // validate runs; the same campaign with the twin's zeroing error off was refitted at
    // −6.7e-4 and named.
    let (traj2, traj_ics2) = moving_runs(&id2, &ics2, false);
    let (x_refit, f, traj2) = refit_zeroed_on(&traj2, &spec, &x0, &traj_ics2, cfg.refit_evals);
    let i_drift = spec.params.len() - 1;
    // The profile through the tracks' value: the damping refitted with the drift held there.
    let x_track = refit_profile(&traj2, &spec, &x0, &traj_ics2, cfg.refit_evals, i_drift);
    // Whether the trajectories feel the tracks' drift at all: the profile through no drift
    // significantly worse on their segments (paired 0.5 s segments, each run's zero refitted
    // for each model). Where they do not, their refit of the drift is one point of a flat
    // profile and says nothing (nor does it disagree): they cannot judge it. A 1.02e-3 Hz/s
    // drift on a drawn design whose runs all rest (`SURVEY_DAMPING=drawn SURVEY_SEED=11`,
    // `speed_drift` k=4) was refitted at −5.6e-3 once the runs' zeros were held, and at −1.0e-2,
    // the end of its search range, before.
    let moving = id2.iter().any(is_moving);
    let without = moving.then(|| {
        let mut start = x_track.clone();
        start[i_drift] = 0.0;
        let x_zero = refit_profile(&traj2, &spec, &start, &traj_ics2, cfg.refit_evals, i_drift);
        let seg = substitution_segments(&traj2, &spec, &x_track, &traj_ics2, true);
        trajectory_substitution(&traj2, &spec, &seg, &x_zero, &traj_ics2, true)
    });
    let feels = without.is_some_and(|(g0, n0)| g0 < -n0);
    // Where no identify run leaves rest, their trajectories cannot judge the drift: a resting
    // pendulum's error under the shaker is its quantised rest angle, which no crank speed
    // moves. Nor where their refit stops at an end of its search range: the bound set it, not
    // the data. Nor where they do not feel it (above). Their refit then says nothing (nor does
    // it disagree), and the model judged on the held-out runs carries the tracks' value, the
    // damping refitted with it held there. A 1.20e-3 Hz/s drift tracked within 0.02 % on a
    // drawn design whose identify runs all rest (`SURVEY_DAMPING=drawn SURVEY_SEED=11`,
    // `speed_drift` k=0) was refitted to −1.0e-2, the end of its search range, and the model
    // carrying that value scored 60 % worse on the validate runs.
    let traj_blind = !moving
        || spec
            .at_end(spec.params[i_drift], x_refit[i_drift])
            .is_some()
        || !feels;
    let x = if traj_blind {
        x_track.clone()
    } else {
        x_refit.clone()
    };
    let val = validate(&val2, &spec, &x, &cfg.validate)?;
    let (traj_b, traj_ics_b) = moving_runs(id_runs, ics, false);
    let (xb, _, _) = refit_zeroed_on(
        &traj_b,
        &base_fit.spec,
        &base_fit.params,
        &traj_ics_b,
        cfg.refit_evals,
    );
    let val_b = validate(val_runs, &base_fit.spec, &xb, &cfg.validate)?;
    let (before, after) = (e_total(&val_b), e_total(&val));
    let (gain, noise) = heldout_gain(&val_b, &val);
    let gain_needed = cfg.gain_min.max(noise);
    let refit_est = x_refit.last().copied().unwrap_or(f64::NAN);
    row.refit_estimate = refit_est;
    // The track's value is inside the trajectories' interval when the profile through it is not
    // significantly worse than the refit. (Not where the trajectories cannot judge it: no view
    // of theirs is asked then.)
    let screen_fits = traj_blind || {
        let seg_x = substitution_segments(&traj2, &spec, &x_refit, &traj_ics2, true);
        let (g, n) = trajectory_substitution(&traj2, &spec, &seg_x, &x_track, &traj_ics2, true);
        g >= -n
    };
    // Two held-out views, as for a torque: the validate runs' E_θ, or their own accelerometer
    // (each run's crank track drifting as the identify runs' do) while E_θ falls at all, once
    // the drift is material (below). A small drift barely moves the pendulum: a 3.4e-4 Hz/s
    // drift, tracked within 0.01 %, was refused on an E_θ fall of 37.5 % ± 51.9 %. But a drift
    // the tracks confirm and the pendulum's predictions do not feel is a fact about the motor,
    // not a cause of what the model gets wrong: another simulator's crank, 3 ppm slower at the
    // end of a run than at its start (−1.1e-7 Hz/s on a campaign hiding nothing), was named on
    // the tracks' 90 % while E_θ moved −0.2 % ± 0.2 % (three of `i01_none_quadratic`'s identify
    // runs and two of its validate runs), and again, by +0.1 %, once each run's zero was held.
    //
    // Where the validate runs cannot tell (all at rest: their errors then follow how well a
    // model holds a quantised rest angle, which favours more friction, not the crank), the
    // identify runs' trajectories say whether the pendulum feels the drift (`feels`): their
    // drift was never fitted to them (it is the accelerometers'), only the damping was, with
    // the drift and without it. A 7.6e-4 Hz/s drift tracked within 0.02 %, without which the
    // identify runs' error rose 1100 %, was refused because the validate runs, all resting,
    // rose 10.5 % ± 8.3 % as μ went from 0.156 to the truth's 0.150.
    let (sensor_gain, _, _) = sensor_heldout(&ev.val, 0.0, est);
    let tracks_confirm = sensor_gain > SENSOR_HELDOUT_GAIN;
    let felt = tracks_confirm && gain <= 0.0 && !traj_blind;
    // And where the trajectories cannot judge it, a drift the tracks confirm is a fact about the
    // forcing, measured on every run, once it is material: it changes the crank's speed over an
    // identify run's forced segment by more than a tenth of the 1 % by which rig.md lets the
    // motor's real speed differ from its set point (the accelerometer measures that offset; a
    // tenth of it is what a constant-speed alignment would leave unremarked). The validate runs'
    // E_θ need then only not contradict it (below). The 1.20e-3 Hz/s drift above changed its
    // runs' speed by several percent; another simulator's 3 ppm crank (`i01_none_quadratic`,
    // −1.1e-7 Hz/s) changes it by 0.0003 %.
    let speed_change = id2
        .iter()
        .filter(|r| !r.free && r.omega_hz > 0.0 && r.t.len() > 1)
        .map(|r| est.abs() * (r.t[r.t.len() - 1] - r.t[0]) / r.omega_hz)
        .fold(0.0, f64::max);
    let material = speed_change > DRIFT_MATERIAL_SPEED_CHANGE;
    // What contradicts it is the drift itself making the validate runs' predictions worse: the
    // model with the drift against the same model with it set to 0, the damping as refitted with
    // it. Against the base refitted alone, the two models differ in a damping that resting
    // identify runs cannot tell either: a 1.66e-3 Hz/s drift (`SURVEY_DAMPING=drawn
    // SURVEY_SEED=12`, `speed_drift` k=1; identify runs resting, validate runs chaotic) "rose"
    // the validate runs' E_θ 74.7 % ± 19.0 % that way.
    let mut own: Option<(f64, f64)> = None;
    if tracks_confirm && traj_blind && material {
        let mut x_none = x.clone();
        x_none[i_drift] = 0.0;
        let none = validate(&val2, &spec, &x_none, &cfg.validate)?;
        own = Some(heldout_gain(&none, &val));
    }
    let held_out = gain > gain_needed
        || (tracks_confirm && material && (gain > 0.0 || felt))
        || own.is_some_and(|(g, n)| g > -n);
    row.accepted = held_out && (traj_blind || views_agree(est, half, refit_est, screen_fits));
    row.heldout_gain = gain;
    row.heldout_noise = noise;
    row.e_validate_before = before;
    row.e_validate_after = after;
    row.note = format!(
        "crank fits with a drifting speed on {n} identify runs; trajectory refit dΩ/dτ {:.4e} Hz/s (f_obj {f:.4}) on the re-aligned runs; E_θ gain needed > {:.3} (max of {:.3} and the paired held-out noise {:.3}); the validate runs' own crank tracks: Σ(dΩ/dτ − ·)² falls {:.1} % from 0 to the estimate (confirms above {:.0} %)",
        refit_est,
        gain_needed,
        cfg.gain_min,
        noise,
        100.0 * sensor_gain,
        100.0 * SENSOR_HELDOUT_GAIN
    );
    if traj_blind {
        row.note.push_str(&format!(
            "; the identify runs' trajectories cannot judge the drift (none leaves rest, or their refit stops at its search range's end): the model judged on the validate runs carries the tracks' value, the damping refitted with it; over an identify run the drift changes the crank's speed by up to {:.2} % (material above {:.2} %)",
            100.0 * speed_change,
            100.0 * DRIFT_MATERIAL_SPEED_CHANGE
        ));
        if let Some((g, n)) = own {
            row.note.push_str(&format!(
                "; the validate runs' E_θ with the drift against the same model without it: gain {:+.1} % ± {:.1} % ({})",
                100.0 * g,
                100.0 * n,
                if g > -n { "no contradiction" } else { "the drift makes them worse" }
            ));
        }
    }
    if let Some((g0, n0)) = without {
        row.note.push_str(&format!(
            "; the identify runs' trajectories without the drift (damping refitted): E_θ {:+.1} % ± {:.1} % ({})",
            -100.0 * g0,
            100.0 * n0,
            if feels { "the pendulum feels it" } else { "not significantly different" }
        ));
    }
    if !row.accepted {
        return Ok((row, None));
    }
    pool_readings(&mut row, &ev.id, &ev.val, 0.0);
    let objective = refit_objective(&id2, &spec);
    let mut full = x.clone();
    full.extend_from_slice(&ics2);
    let eval = objective.evaluate(&full);
    let outcome = FitOutcome {
        spec: spec.clone(),
        params: x,
        f_obj: eval.f_obj,
        e_theta: eval.e_theta,
        runs: eval
            .update_runs(&base_fit.runs)
            .into_iter()
            .zip(&id2)
            .map(|(r, p)| RunFit {
                ic_est: p.ic_est,
                ic_fit: p.ic_est,
                ..r
            })
            .collect(),
        convergence: Vec::new(),
        stop_reason: "refit (Nelder–Mead, runs re-aligned on the drifting crank speed)".into(),
        alignments: ctx2.alignments.clone(),
        ..base_fit.clone()
    };
    Ok((
        row,
        Some(DriftModel {
            outcome,
            id_runs: id2,
            val_runs: val2,
            ics: ics2,
            validation: val,
        }),
    ))
}

/// The model extended with `speed_drift` and the re-aligned runs it was fitted on.
pub(crate) struct DriftModel {
    pub(crate) outcome: FitOutcome,
    pub(crate) id_runs: Vec<PreparedRun>,
    pub(crate) val_runs: Vec<PreparedRun>,
    pub(crate) ics: Vec<f64>,
    pub(crate) validation: Vec<RunFit>,
}
