//! The Parquet tables and plots of `identify` / `validate` (and the parts `discover` shares).
//!
//! Tables (zstd, one folder per invocation, units in field metadata, the pipeline definition and
//! versions in the key-value metadata): `params.parquet`, `initial_conditions.parquet`,
//! `residuals.parquet`, `convergence.parquet`, `runs.parquet`, `validation.parquet`.

use std::collections::BTreeSet;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use pendulum_model::Effects;
use pendulum_plot::{floor_span, Figure, Panel, Series, SeriesStyle};
use pendulum_process::fit::{FitParam, ModelSpec};
use pendulum_process::identify::{FitOutcome, ResidualSeries, RunFit};
use pendulum_process::pipeline::Context;
use pendulum_process::{RigParams, Role};
use pendulum_report::{Column, ColumnData, TableOptions};

/// The catalogue's parameters no fit varies (`position_torque.k`: the screen's lobe count), with
/// their units: `params.parquet` carries them beside the refitted ones, from the model's held
/// values, so that a reader (`validate`, `replay`, the maps) rebuilds the same model. Without
/// the column a position torque of k = 50 was read back as k = 1.
fn held_params() -> impl Iterator<Item = (&'static str, &'static str)> {
    pendulum_model::CATALOGUE.iter().flat_map(|e| {
        e.params()
            .iter()
            .filter(|p| p.fit_range.is_none())
            .map(|p| (p.key, p.unit))
    })
}

use crate::identify::{residuals_of, segment_residuals_of};
use crate::inputs::Inputs;
use crate::JobError;

/// What was written, and a printable summary.
#[derive(Debug, Clone)]
pub struct OutputSummary {
    pub out_dir: PathBuf,
    pub tables: Vec<PathBuf>,
    pub plots: Vec<PathBuf>,
    pub text: String,
}

impl std::fmt::Display for OutputSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.text)
    }
}

/// Makes OUT ready for a command that writes there, before its long work: creates it, proves it
/// writable (a probe file created and removed: an unwritable OUT used to fail only after the
/// fit), and removes this program's stale temporary files from it ([`remove_stale_temps`]).
/// Returns the files removed.
///
/// The folder's completion marker ([`COMPLETE_MARKER`]) goes first: from here until the command
/// writes its own ([`mark_complete`]) the folder is recognisably incomplete. PNGs written from
/// here on carry the invocation id ([`stamp_plots`]).
pub fn prepare_out_dir(out: &Path) -> Result<Vec<PathBuf>, JobError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| JobError::Io { path, source }
    };
    std::fs::create_dir_all(out).map_err(io(out))?;
    // Named like a writer's temporary file, so that a crash between these two lines leaves a
    // file the next sweep removes.
    let probe = out.join(format!(".write-check.{}-0.tmp", std::process::id()));
    std::fs::File::create_new(&probe).map_err(io(out))?;
    std::fs::remove_file(&probe).map_err(io(&probe))?;
    stamp_plots();
    remove_marker(out)?;
    remove_stale_temps(out)
}

/// The file a result folder holds once the command that wrote it has finished: JSON with the
/// invocation id its tables (key-value metadata) and PNGs (`tEXt`) carry, the command and the
/// files it wrote. Written last, atomically; removed first when a command starts writing into
/// the folder. A folder without it is incomplete (a command was killed, failed, or is still
/// running there); a table or plot whose invocation id is not the marker's is stale.
pub const COMPLETE_MARKER: &str = "complete.json";

/// Every PNG this process writes from now on carries its invocation id (`tEXt` chunk
/// `invocation_id`), as its tables do.
pub fn stamp_plots() {
    // The id is ASCII digits, '.' and '-': always valid PNG text.
    let _ = pendulum_plot::set_png_text("invocation_id", &pendulum_report::invocation().id);
}

/// Removes `out`'s completion marker, if any.
pub fn remove_marker(out: &Path) -> Result<(), JobError> {
    let path = out.join(COMPLETE_MARKER);
    match std::fs::remove_file(&path) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(source) => Err(JobError::Io { path, source }),
    }
}

/// Writes `out`'s completion marker ([`COMPLETE_MARKER`]) naming `files` (those under `out`,
/// relative to it): call it last, once every output is in place.
pub fn mark_complete(out: &Path, command: &str, files: &[PathBuf]) -> Result<PathBuf, JobError> {
    let mut names: Vec<String> = files
        .iter()
        .filter_map(|f| f.strip_prefix(out).ok())
        .map(|f| f.to_string_lossy().into_owned())
        .collect();
    names.sort();
    names.dedup();
    let json = serde_json::json!({
        "invocation_id": pendulum_report::invocation().id,
        "command": command,
        "pendulum_version": env!("CARGO_PKG_VERSION"),
        "files": names,
    });
    let path = out.join(COMPLETE_MARKER);
    let mut text = serde_json::to_string_pretty(&json).unwrap_or_default();
    text.push('\n');
    write_atomic(&path, text.as_bytes())?;
    Ok(path)
}

/// Writes `bytes` to `path` through this program's temporary name (`.NAME.<pid>-<n>.tmp`,
/// created only if new), synced, then renamed over `path`; the temporary file is removed on
/// failure.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), JobError> {
    use std::io::Write as _;
    static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let name = path
        .file_name()
        .map(|f| f.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.{}-{n}.tmp", std::process::id()));
    let io = |source| JobError::Io {
        path: path.to_path_buf(),
        source,
    };
    let result = std::fs::File::create_new(&tmp)
        .and_then(|mut f| {
            f.write_all(bytes)?;
            f.sync_all()
        })
        .and_then(|()| std::fs::rename(&tmp, path));
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(io(e));
    }
    Ok(())
}

/// Removes from `dir` this program's stale temporary files ([`remove_stale_temps`]'s rule) of
/// the files `names` only: a command writing one file (or a known set) into a folder that is
/// not its own (`simulate --out ~/x.parquet`) sweeps its own leftovers, nothing else there.
pub fn remove_stale_temps_of(dir: &Path, names: &[String]) -> Result<Vec<PathBuf>, JobError> {
    // `.NAME.<pid>-<n>.tmp[.png]`: the NAME (the pid and counter were checked by the sweep).
    let target = |temp: &str| -> Option<String> {
        let stem = temp
            .strip_suffix(".tmp.png")
            .or_else(|| temp.strip_suffix(".tmp"))?;
        let (base, _) = stem.strip_prefix('.')?.rsplit_once('.')?;
        Some(base.to_string())
    };
    if !dir.is_dir() {
        // Nothing there yet: nothing left behind.
        return Ok(Vec::new());
    }
    remove_stale_temps_where(dir, |name| {
        target(name).is_some_and(|base| names.contains(&base))
    })
}

/// [`remove_stale_temps_of`] for the folder of one output file `path` and that file alone.
pub fn remove_stale_temps_of_file(path: &Path) -> Result<Vec<PathBuf>, JobError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let Some(name) = path.file_name() else {
        return Ok(Vec::new());
    };
    remove_stale_temps_of(dir, &[name.to_string_lossy().into_owned()])
}

/// Removes from `dir` (not its subfolders) this program's temporary files
/// ([`pendulum_report::temp_writer_pid`]) left by an earlier, interrupted process: last modified
/// before this process started, of another process id, and (where `/proc` shows which processes
/// run) of a process no longer running, so that a concurrent writer's file is never taken. A
/// killed `identify` used to leave them for good (up to 116 MB each).
pub fn remove_stale_temps(dir: &Path) -> Result<Vec<PathBuf>, JobError> {
    remove_stale_temps_where(dir, |_| true)
}

fn remove_stale_temps_where(
    dir: &Path,
    wanted: impl Fn(&str) -> bool,
) -> Result<Vec<PathBuf>, JobError> {
    let started = pendulum_report::invocation().started;
    let own = std::process::id();
    let proc_known = Path::new("/proc/self").exists();
    let entries = std::fs::read_dir(dir).map_err(|source| JobError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut removed = Vec::new();
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(pid) = pendulum_report::temp_writer_pid(&name) else {
            continue;
        };
        if !wanted(&name) {
            continue;
        }
        let Ok(md) = e.metadata() else { continue };
        let old = md.modified().is_ok_and(|t| t < started);
        let running = proc_known && Path::new(&format!("/proc/{pid}")).exists();
        if md.is_file() && pid != own && old && !running {
            let path = e.path();
            std::fs::remove_file(&path).map_err(|source| JobError::Io {
                path: path.clone(),
                source,
            })?;
            removed.push(path);
        }
    }
    removed.sort();
    Ok(removed)
}

/// A note for a command's summary naming the stale temporary files removed from OUT.
pub fn removed_note(removed: &[PathBuf]) -> Option<String> {
    let names: Vec<String> = removed
        .iter()
        .filter_map(|p| p.file_name())
        .map(|n| n.to_string_lossy().into_owned())
        .collect();
    (!names.is_empty()).then(|| {
        format!(
            "removed {} temporary file(s) an interrupted earlier run left in the output folder: {}",
            names.len(),
            names.join(", ")
        )
    })
}

fn meta(pipeline: &str, command: &str) -> TableOptions {
    TableOptions::new()
        .meta("command", command)
        .meta("pipeline", pipeline)
        .meta("pendulum_version", env!("CARGO_PKG_VERSION"))
}

fn f64s(name: &str, unit: &str, v: Vec<f64>) -> Column {
    Column::f64(name, unit, v)
}

fn strs(name: &str, v: Vec<String>) -> Column {
    Column::new(name, ColumnData::Str(v))
}

fn ints(name: &str, v: Vec<i64>) -> Column {
    Column::new(name, ColumnData::I64(v))
}

/// Issue 16 item 4: `runs.parquet`'s columns of each run's own fit (free decays whose ω0 differ
/// are also fitted one by one, [`pendulum_process::identify::per_run_fits`]): its ω0, its swing
/// centre (hanging angle, `encoder_offset`), its damping per unit inertia and its E_θ. NaN for a
/// run without one (runs that share ω0, shaker campaigns) and for a term its model lacks.
fn own_fit_columns(ctx: &Context, first: Option<&FitOutcome>) -> Vec<Column> {
    let own = first.and_then(|m| ctx.per_run.get(&m.spec.name));
    let offset = FitParam::of("encoder_offset");
    let terms = [
        ("omega0_own_rad_s", "rad/s", Some(FitParam::Omega0)),
        ("theta_hang_own_rad", "rad", Some(offset)),
        ("beta_own", FitParam::Beta.unit(), Some(FitParam::Beta)),
        ("alpha_own", FitParam::Alpha.unit(), Some(FitParam::Alpha)),
        ("M_own", FitParam::MBearing.unit(), Some(FitParam::MBearing)),
        ("c_own", FitParam::DryC.unit(), Some(FitParam::DryC)),
        ("e_theta_own", "rad", None),
    ];
    terms
        .iter()
        .map(|&(name, unit, p)| {
            let vals = ctx
                .runs
                .iter()
                .map(|r| {
                    own.and_then(|o| o.get(&r.id))
                        .and_then(|f| match p {
                            Some(p) => f.spec.value_of(p, &f.params),
                            None => Some(f.e_theta),
                        })
                        .unwrap_or(f64::NAN)
                })
                .collect();
            f64s(name, unit, vals)
        })
        .collect()
}

/// Which quantities a free decay's fit could not separate (the `not_separable` column and the
/// printed summary): θ(t) gives ω0 and torques per unit inertia only; the campaign's m and l
/// (pivot to centre of mass), when given, turn them into an inertia and SI torques.
pub fn not_separable(rig: &RigParams) -> String {
    if rig.m_kg.is_finite() && rig.l_m.is_finite() {
        "m and l from the campaign give I = m g l/omega0^2 (pivot), hence SI torques; J = I - m l^2 \
         only as good as m and l; mu and r_b not separable (only M = mu r_b m g/(I omega0^2))"
            .into()
    } else {
        "m, l, J not separable: only omega0 and damping/inertia ratios (beta = viscous/(I omega0), \
         alpha = quadratic/I, M and c = dry torque/(I omega0^2)); give m_kg and l_m for SI torques"
            .into()
    }
}

/// Rows of params.parquet: one per fitted (or given) model, dimensionless values for the first
/// identify run's rig and crank speed (`scope = shared`, `run_id` empty). A free-decay model
/// (excitation off) has its fitted ω0 and ratios; the crank's columns and the SI damping (a, b,
/// μ) are NaN, and its `not_separable` says why; with the campaign's m and l it also has the
/// pivot inertia and SI torques.
///
/// Issue 16: free decays whose ω0 differ are also fitted one by one
/// ([`pendulum_process::identify::per_run_fits`]); each such fit is one more row after the
/// shared ones, same `model`, `scope = run` and the run's id in `run_id`, on that run's rig. A
/// reader that takes the first row of a model (validate, design, bifurcate) keeps the shared
/// fit; campaigns without per-run fits (shaker runs, runs sharing ω0) have the shared rows only.
pub fn params_columns(ctx: &Context, fits: &[FitOutcome]) -> Vec<Column> {
    let first = ctx
        .runs
        .iter()
        .find(|r| r.role == Role::Identify)
        .or(ctx.runs.first());
    // (fit, the run it is its own fit of, or None for the shared fit, the rig it is read on).
    let mut rows: Vec<(&FitOutcome, Option<&str>, &pendulum_process::RunData)> = Vec::new();
    if let Some(r) = first {
        rows.extend(fits.iter().map(|f| (f, None, r)));
        for f in fits {
            let Some(own) = ctx.per_run.get(&f.spec.name) else {
                continue;
            };
            for run in &ctx.runs {
                if let Some(o) = own.get(&run.id) {
                    rows.push((o, Some(run.id.as_str()), run));
                }
            }
        }
    }
    let mut model = Vec::new();
    let (mut scope, mut run_id) = (Vec::new(), Vec::new());
    let (mut excitation, mut separable) = (Vec::new(), Vec::new());
    let mut cols: Vec<(String, String, Vec<f64>)> = Vec::new();
    let mut push = |name: &str, unit: &str, v: f64, row: usize| {
        if let Some(c) = cols.iter_mut().find(|c| c.0 == name) {
            c.2.resize(row, f64::NAN);
            c.2.push(v);
        } else {
            let mut vals = vec![f64::NAN; row];
            vals.push(v);
            cols.push((name.to_string(), unit.to_string(), vals));
        }
    };
    for (row, &(fit, own, r)) in rows.iter().enumerate() {
        model.push(fit.spec.name.clone());
        scope.push(if own.is_some() { "run" } else { "shared" }.to_string());
        run_id.push(own.unwrap_or_default().to_string());
        let rig = r.rig.clone();
        let omega_hz = ctx
            .alignments
            .get(&r.id)
            .map_or(r.rig.omega_hz.unwrap_or(0.0), |a| a.omega_hz);
        if fit.spec.is_free_decay() {
            excitation.push("none".to_string());
            separable.push(not_separable(&rig));
            free_decay_row(&mut push, fit, &rig, row);
            continue;
        }
        excitation.push("crank".to_string());
        separable.push(String::new());
        let phys = fit.spec.physical(&rig, omega_hz, &fit.params);
        let d = phys.to_dimensionless();
        push("a", "kg/m", phys.a_kg_m, row);
        push("b", "N·s/m", phys.b_n_s_m, row);
        push("mu", "1", phys.mu, row);
        push("alpha", "1", d.alpha, row);
        push("beta", "1", d.beta, row);
        push("M", "1", d.m_coulomb, row);
        push("R", "1", d.r, row);
        push("lambda", "1", d.lambda, row);
        push("omega", "1", d.omega, row);
        push("m_kg", "kg", rig.m_kg, row);
        push("l_m", "m", rig.l_m, row);
        push("crank_r_m", "m", rig.crank_r_m, row);
        push("rod_L_m", "m", rig.rod_l_m, row);
        push("r_b_m", "m", rig.r_b_m, row);
        push("g_m_s2", "m/s²", rig.g_m_s2, row);
        push("omega_hz", "Hz", omega_hz, row);
        // One column per refitted parameter of the catalogue, in its order.
        for p in FitParam::all_effects() {
            let v = if fit.spec.params.contains(&p) {
                fit.param(p)
            } else {
                f64::NAN
            };
            push(p.name(), p.unit(), v, row);
        }
        for (key, unit) in held_params() {
            push(
                key,
                unit,
                fit.spec.fixed.value(key).unwrap_or(f64::NAN),
                row,
            );
        }
        fit_stats(&mut push, fit, row);
    }
    let n_rows = model.len();
    let mut out = vec![strs("model", model)];
    for (name, unit, mut vals) in cols {
        vals.resize(n_rows, f64::NAN);
        let col = match name.as_str() {
            "n_runs" | "generations" | "evaluations" | "abandoned" | "seed" | "np" => {
                ints(&name, vals.iter().map(|v| *v as i64).collect())
            }
            _ => f64s(&name, &unit, vals),
        };
        out.push(col);
    }
    out.push(strs("excitation", excitation));
    out.push(strs("not_separable", separable));
    out.push(strs("scope", scope));
    out.push(strs("run_id", run_id));
    out
}

/// The columns every row has: the fit's objective and budget.
fn fit_stats(push: &mut impl FnMut(&str, &str, f64, usize), fit: &FitOutcome, row: usize) {
    push("f_obj", "rad", fit.f_obj, row);
    push("e_theta", "rad", fit.e_theta, row);
    push("n_runs", "1", fit.runs.len() as f64, row);
    push("generations", "1", fit.generations as f64, row);
    push("evaluations", "1", fit.evaluations as f64, row);
    push("abandoned", "1", fit.abandoned as f64, row);
    push("wall_s", "s", fit.wall_s, row);
    push("seed", "1", fit.seed as f64, row);
    push("np", "1", fit.np as f64, row);
    push(
        "polished_f_obj",
        "rad",
        fit.polished.as_ref().map_or(f64::NAN, |p| p.1),
        row,
    );
}

/// A free-decay row: the same columns (crank and SI damping NaN: no shaker, not separable),
/// the fitted ratios, and the pivot inertia and SI torques when the campaign gives m and l.
fn free_decay_row(
    push: &mut impl FnMut(&str, &str, f64, usize),
    fit: &FitOutcome,
    rig: &RigParams,
    row: usize,
) {
    let val = |p: FitParam| fit.spec.value_of(p, &fit.params);
    let term = |p: FitParam| val(p).unwrap_or(0.0);
    let w0 = val(FitParam::Omega0).unwrap_or(f64::NAN);
    let nan = f64::NAN;
    push("a", "kg/m", nan, row);
    push("b", "N·s/m", nan, row);
    push("mu", "1", nan, row);
    push("alpha", "1", term(FitParam::Alpha), row);
    push("beta", "1", term(FitParam::Beta), row);
    push("M", "1", term(FitParam::MBearing), row);
    push("R", "1", nan, row);
    push("lambda", "1", nan, row);
    push("omega", "1", nan, row);
    push("m_kg", "kg", rig.m_kg, row);
    push("l_m", "m", rig.l_m, row);
    push("crank_r_m", "m", nan, row);
    push("rod_L_m", "m", nan, row);
    push("r_b_m", "m", rig.r_b_m, row);
    push("g_m_s2", "m/s²", rig.g_m_s2, row);
    push("omega_hz", "Hz", nan, row);
    for p in FitParam::all_effects() {
        push(p.name(), p.unit(), val(p).unwrap_or(nan), row);
    }
    for (key, unit) in held_params() {
        push(key, unit, fit.spec.fixed.value(key).unwrap_or(nan), row);
    }
    push("omega0_rad_s", "rad/s", w0, row);
    push("c", "rad", val(FitParam::DryC).unwrap_or(nan), row);
    push("small_swing_period_s", "s", std::f64::consts::TAU / w0, row);
    // I ω0² = m g l (pivot to centre of mass): with m and l known, torques come out in SI.
    let mgl = rig.m_kg * rig.g_m_s2 * rig.l_m;
    let inertia = mgl / (w0 * w0);
    push("inertia_pivot_kg_m2", "kg·m²", inertia, row);
    push(
        "viscous_n_m_s",
        "N·m·s",
        term(FitParam::Beta) * w0 * inertia,
        row,
    );
    push(
        "quadratic_n_m_s2",
        "N·m·s²",
        term(FitParam::Alpha) * inertia,
        row,
    );
    push(
        "dry_torque_n_m",
        "N·m",
        (term(FitParam::DryC) + term(FitParam::MBearing)) * mgl,
        row,
    );
    fit_stats(push, fit, row);
}

/// Reads one model back from a params.parquet (the first row, or the row named `model`).
pub fn read_params(path: &Path, model: Option<&str>) -> Result<FitOutcome, JobError> {
    let bad = |m: String| JobError::Invalid(format!("{}: {m}", path.display()));
    // One reader of the table for every command (`design` reads it the same way): any numeric
    // column type, and tables saved again by pandas, pyarrow or DuckDB.
    let rows = pendulum_maps::params_file::read_params(path)?;
    let Some(row) = rows
        .into_iter()
        .find(|r| model.is_none_or(|m| m == r.model))
    else {
        return Err(bad(match model {
            Some(m) => format!("no model named {m:?}"),
            None => "no rows".into(),
        }));
    };
    let name = row.model.clone();
    let get = |col: &str| row.get(col);
    let base = if name.starts_with("linear") {
        ModelSpec::linear()
    } else if name.starts_with("dry") {
        ModelSpec::dry()
    } else {
        ModelSpec::reference()
    };
    let mut spec = ModelSpec {
        name: name.clone(),
        params: base.params.clone(),
        fixed: Effects::default(),
        ranges: Default::default(),
    };
    let given = |p: FitParam| get(p.name()).is_some();
    // One column per refitted parameter of the catalogue, in its order.
    for p in FitParam::all_effects() {
        if given(p) {
            spec.params.push(p);
        }
    }
    for (key, _) in held_params() {
        if let Some(v) = get(key) {
            spec.fixed.set_value(key, v);
        }
    }
    // A free-decay row (it has ω0): the same model in identifiable terms.
    if given(FitParam::Omega0) {
        if given(FitParam::DryC) {
            spec.params.push(FitParam::of("coulomb_constant"));
        }
        spec = spec
            .free_decay()
            .map_err(|e| bad(format!("model {name}: {e}")))?;
    }
    let params = spec
        .params
        .iter()
        .map(|p| get(p.name()).ok_or_else(|| bad(format!("model {name}: no column {}", p.name()))))
        .collect::<Result<Vec<f64>, _>>()?;
    // A fit may have widened a search range past the catalogue's: its values hold.
    for (&p, &v) in spec.params.clone().iter().zip(&params) {
        spec.hold(p, v);
    }
    Ok(FitOutcome {
        spec,
        params,
        f_obj: get("f_obj").unwrap_or(f64::NAN),
        e_theta: get("e_theta").unwrap_or(f64::NAN),
        generations: get("generations").unwrap_or(0.0) as u64,
        evaluations: get("evaluations").unwrap_or(0.0) as u64,
        abandoned: 0,
        stop_reason: "given".into(),
        wall_s: 0.0,
        seed: get("seed").unwrap_or(0.0) as u64,
        np: get("np").unwrap_or(0.0) as usize,
        convergence: Vec::new(),
        runs: Vec::new(),
        polished: None,
        alignments: Default::default(),
    })
}

fn validation_of<'a>(ctx: &'a Context, model: &str) -> Option<&'a [RunFit]> {
    ctx.validations
        .iter()
        .find(|(m, _)| m == model)
        .map(|(_, v)| v.as_slice())
}

/// Every fitted or given model in the context.
pub fn models_of(ctx: &Context) -> Vec<FitOutcome> {
    if ctx.fits.is_empty() {
        ctx.given.clone().into_iter().collect()
    } else {
        ctx.fits.clone()
    }
}

/// `out/name` for a file name built from a model name and a run id. `validate` reads the model
/// name from a params.parquet and the run ids may come from MCAP metadata: whoever wrote those
/// files must not be able to place a plot outside `out` (a name like `../../x`).
///
/// Nor may a plot replace one of the command's input files.
fn out_file(out: &Path, name: &str, inputs: &Inputs) -> Result<PathBuf, JobError> {
    pendulum_rig::names::check_file_name(name).map_err(|problem| {
        JobError::Invalid(format!(
            "{}: refusing to write the plot {name:?}: the name (built from a model name and a \
             run id read from the input) {problem}",
            out.display()
        ))
    })?;
    let path = out.join(name);
    inputs.check_output("the output", &path)?;
    Ok(path)
}

/// Writes every table and plot for the context's results into `out`.
pub fn write_outputs(
    ctx: &Context,
    out: &Path,
    pipeline: &str,
    command: &str,
    wall_s: f64,
) -> Result<OutputSummary, JobError> {
    write_outputs_checked(ctx, out, pipeline, command, wall_s, &Inputs::new())
}

/// The tables `write_outputs` writes whatever the results (plots are named after models and
/// runs): a command checks them against its inputs before a long fit.
pub const TABLES: [&str; 5] = [
    "params.parquet",
    "runs.parquet",
    "initial_conditions.parquet",
    "convergence.parquet",
    "residuals.parquet",
];

/// [`write_outputs`], refusing (before writing it) any table or plot that would replace one of
/// the command's `inputs`.
pub fn write_outputs_checked(
    ctx: &Context,
    out: &Path,
    pipeline: &str,
    command: &str,
    wall_s: f64,
    inputs: &Inputs,
) -> Result<OutputSummary, JobError> {
    std::fs::create_dir_all(out).map_err(|source| JobError::Io {
        path: out.to_path_buf(),
        source,
    })?;
    let opts = meta(pipeline, command);
    let mut tables = Vec::new();
    let mut plots = Vec::new();
    let models = models_of(ctx);
    let mut text = String::new();

    // params.parquet
    if !models.is_empty() {
        let p = out.join("params.parquet");
        let mut o = opts.clone();
        if models.iter().any(|m| m.spec.is_free_decay()) {
            o = o.meta(
                "free_decay",
                "excitation off; omega0 (rad/s) and damping per unit inertia in t = omega0 tau \
                 (beta, alpha, M, c) are fitted; a, b, mu and the crank columns are NaN: see \
                 column not_separable",
            );
        }
        inputs.check_output("the output", &p)?;
        o.write(&p, &params_columns(ctx, &models))?;
        tables.push(p);
    }

    // runs.parquet
    {
        let first = models.first();
        let fitted: Vec<&RunFit> = first
            .map(|m| {
                m.runs
                    .iter()
                    .chain(validation_of(ctx, &m.spec.name).unwrap_or(&[]))
                    .collect()
            })
            .unwrap_or_default();
        let mut c: Vec<Vec<f64>> = vec![Vec::new(); 17];
        let mut kinds = Vec::new();
        let (mut ids, mut roles, mut meas, mut sim, mut agree) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let mut meas_p = Vec::new();
        let mut sim_p = Vec::new();
        for r in &ctx.runs {
            ids.push(r.id.clone());
            roles.push(r.role.as_str().to_string());
            let al = ctx.alignments.get(&r.id);
            let ic = ctx.initial.get(&r.id);
            kinds.push(al.map_or("-", |a| a.kind.as_str()).to_string());
            let vals = [
                r.rig.omega_hz.unwrap_or(f64::NAN),
                al.map_or(f64::NAN, |a| a.omega_hz),
                al.map_or(f64::NAN, |a| a.omega_sigma_hz),
                al.map_or(f64::NAN, |a| a.shaker_start_s),
                al.map_or(f64::NAN, |a| a.t0_s),
                al.map_or(f64::NAN, |a| a.t0_sigma_s),
                al.map_or(f64::NAN, |a| a.accel_gain),
                al.map_or(f64::NAN, |a| a.residual_rms_m_s2),
                al.map_or(f64::NAN, |a| a.free_segment_s.0),
                al.map_or(f64::NAN, |a| a.free_segment_s.1),
                ic.map_or(f64::NAN, |i| i.theta_rad),
                ic.map_or(f64::NAN, |i| i.theta_dot_rad_s),
                ctx.hanging
                    .get(&r.id)
                    .copied()
                    .flatten()
                    .unwrap_or(f64::NAN),
                fitted
                    .iter()
                    .find(|f| f.id == r.id)
                    .map_or(f64::NAN, |f| f.e_theta),
                al.map_or(f64::NAN, |a| a.omega0_est_rad_s),
                al.map_or(f64::NAN, |a| a.accel_noise_m_s2),
                al.map_or(f64::NAN, |a| a.forcing_residual_rms_m_s2),
            ];
            for (col, v) in c.iter_mut().zip(vals) {
                col.push(v);
            }
            let m = ctx.steady.get(&r.id);
            meas.push(m.map_or("-".to_string(), |s| s.class.as_str().to_string()));
            meas_p.push(m.map_or(0, |s| s.period as i64));
            let f = fitted.iter().find(|f| f.id == r.id);
            let s = f.and_then(|f| f.simulated);
            sim.push(s.map_or("-".to_string(), |s| s.class.as_str().to_string()));
            sim_p.push(s.map_or(0, |s| s.period as i64));
            agree.push(f.is_some_and(|f| f.steady_agrees()));
        }
        let names = [
            ("omega_set_hz", "Hz"),
            ("omega_hz", "Hz"),
            ("omega_sigma_hz", "Hz"),
            ("shaker_start_s", "s"),
            ("t0_s", "s"),
            ("t0_sigma_s", "s"),
            ("accel_gain", "1"),
            ("align_residual_rms_m_s2", "m/s²"),
            ("free_start_s", "s"),
            ("free_end_s", "s"),
            ("theta0_est", "rad"),
            ("theta_dot0_est", "rad/s"),
            ("hanging_theta", "rad"),
            ("e_theta", "rad"),
            ("omega0_est_rad_s", "rad/s"),
            ("accel_noise_m_s2", "m/s²"),
            ("forcing_residual_rms_m_s2", "m/s²"),
        ];
        let mut cols = vec![
            strs("run_id", ids),
            strs("role", roles),
            strs("alignment", kinds),
        ];
        for ((n, u), v) in names.iter().zip(c) {
            cols.push(f64s(n, u, v));
        }
        cols.push(strs("measured_steady", meas));
        cols.push(ints("measured_period", meas_p));
        cols.push(strs("simulated_steady", sim));
        cols.push(ints("simulated_period", sim_p));
        cols.push(Column::new("steady_agrees", ColumnData::Bool(agree)));
        // The crank-rod model explains the accelerometer along the whole forced segment
        // (tracked residual within a few times the sensor's noise).
        cols.push(Column::new(
            "forcing_understood",
            ColumnData::Bool(
                ctx.runs
                    .iter()
                    .map(|r| {
                        ctx.alignments
                            .get(&r.id)
                            .is_none_or(|a| a.forcing_understood())
                    })
                    .collect(),
            ),
        ));
        cols.extend(own_fit_columns(ctx, first));
        let p = out.join("runs.parquet");
        inputs.check_output("the output", &p)?;
        opts.clone()
            .meta(
                "simulated_model",
                first.map_or("-".to_string(), |m| m.spec.name.clone()),
            )
            .write(&p, &cols)?;
        tables.push(p);
    }

    // initial_conditions, convergence, residuals
    let (mut ic_run, mut ic_model, mut ic_role) = (Vec::new(), Vec::new(), Vec::new());
    let mut icv: Vec<Vec<f64>> = vec![Vec::new(); 4];
    let (mut cv_model, mut cv_gen) = (Vec::new(), Vec::new());
    let mut cvv: Vec<Vec<f64>> = vec![Vec::new(); 3];
    let (mut rs_run, mut rs_model, mut rs_role) = (Vec::new(), Vec::new(), Vec::new());
    let (mut rs_mode, mut rs_segment, mut rs_scope) = (Vec::new(), Vec::new(), Vec::new());
    let mut rsv: Vec<Vec<f64>> = vec![Vec::new(); 7];
    for m in &models {
        let val = validation_of(ctx, &m.spec.name);
        for rf in m.runs.iter().chain(val.unwrap_or(&[])) {
            // The unit of the fitted rates: a free decay's period-derived ω0, else sqrt(g/l).
            let w0 = match ctx.alignments.get(&rf.id) {
                Some(a) if a.is_free() => a.omega0_est_rad_s,
                _ => ctx
                    .runs
                    .iter()
                    .find(|r| r.id == rf.id)
                    .map_or(1.0, |r| r.rig.omega0_rad_s()),
            };
            ic_run.push(rf.id.clone());
            ic_model.push(m.spec.name.clone());
            ic_role.push(rf.role.as_str().to_string());
            for (col, v) in icv.iter_mut().zip([
                rf.ic_est[0],
                rf.ic_est[1] * w0,
                rf.ic_fit[0],
                rf.ic_fit[1] * w0,
            ]) {
                col.push(v);
            }
        }
        for &(g, b, w, mean) in &m.convergence {
            cv_model.push(m.spec.name.clone());
            cv_gen.push(g as i64);
            cvv[0].push(b);
            cvv[1].push(w);
            cvv[2].push(mean);
        }
        // The residual the fit minimised (mode `segments`), then the free run (mode `free_run`);
        // scope `shared` for the model's fit, `run` for a run's own fit (issue 16).
        let mut push_rows = |id: &str,
                             role: Role,
                             mode: &str,
                             scope: &str,
                             s: &ResidualSeries,
                             segment: &dyn Fn(usize) -> i64| {
            for k in 0..s.t.len() {
                rs_run.push(id.to_string());
                rs_model.push(m.spec.name.clone());
                rs_role.push(role.as_str().to_string());
                rs_mode.push(mode.to_string());
                rs_scope.push(scope.to_string());
                rs_segment.push(segment(k));
                let v = [
                    s.t[k],
                    s.tau_s[k],
                    s.theta_meas[k],
                    s.theta_sim[k],
                    s.theta_meas[k] - s.theta_sim[k],
                    s.theta_dot_meas[k],
                    s.theta_dot_sim[k],
                ];
                for (col, x) in rsv.iter_mut().zip(v) {
                    col.push(x);
                }
            }
        };
        let x_label = if m.spec.is_free_decay() {
            "time from the first turning point (s)"
        } else {
            "time from the first at-speed peak (s)"
        };
        for (id, role, s, segments) in segment_residuals_of(ctx, m, val)? {
            push_rows(&id, role, "segments", "shared", &s, &|k| segments[k] as i64);
        }
        let free_runs = residuals_of(ctx, m, val, 60.0)?;
        for (id, role, s) in &free_runs {
            push_rows(id, *role, "free_run", "shared", s, &|_| -1);
        }
        for (id, role, s) in free_runs {
            let png = out_file(
                out,
                &format!("history_{}_{}.png", m.spec.name.replace('+', "_"), id),
                inputs,
            )?;
            history_plot(&png, &id, &m.spec.name, role, &s, x_label)?;
            plots.push(png);
        }
        // Each run's own fit (free decays whose ω0 differ), on that run alone: the same two
        // modes, scope `run`, and its own history plot (`history_<model>_<run>_alone.png`).
        let alone = ctx.per_run.get(&m.spec.name);
        for own in ctx
            .runs
            .iter()
            .filter_map(|r| alone.and_then(|o| o.get(&r.id)))
        {
            for (id, role, s, segments) in segment_residuals_of(ctx, own, None)? {
                push_rows(&id, role, "segments", "run", &s, &|k| segments[k] as i64);
            }
            for (id, role, s) in residuals_of(ctx, own, None, 60.0)? {
                push_rows(&id, role, "free_run", "run", &s, &|_| -1);
                let png = out_file(
                    out,
                    &format!("history_{}_{}_alone.png", m.spec.name.replace('+', "_"), id),
                    inputs,
                )?;
                let title = format!("{} (fitted alone)", m.spec.name);
                history_plot(&png, &id, &title, role, &s, x_label)?;
                plots.push(png);
            }
        }
        if m.convergence.len() > 1 {
            let png = out_file(
                out,
                &format!("convergence_{}.png", m.spec.name.replace('+', "_")),
                inputs,
            )?;
            convergence_plot(&png, m)?;
            plots.push(png);
        }
    }
    if !ic_run.is_empty() {
        let p = out.join("initial_conditions.parquet");
        let mut cols = vec![
            strs("run_id", ic_run),
            strs("model", ic_model),
            strs("role", ic_role),
        ];
        for ((n, u), v) in [
            ("theta0_est", "rad"),
            ("theta_dot0_est", "rad/s"),
            ("theta0_fit", "rad"),
            ("theta_dot0_fit", "rad/s"),
        ]
        .iter()
        .zip(icv)
        {
            cols.push(f64s(n, u, v));
        }
        inputs.check_output("the output", &p)?;
        opts.write(&p, &cols)?;
        tables.push(p);
    }
    if !cv_gen.is_empty() {
        let p = out.join("convergence.parquet");
        let mut cols = vec![strs("model", cv_model), ints("generation", cv_gen)];
        for (n, v) in ["best", "worst", "mean"].iter().zip(cvv) {
            cols.push(f64s(n, "rad", v));
        }
        inputs.check_output("the output", &p)?;
        opts.write(&p, &cols)?;
        tables.push(p);
    }
    if !rs_run.is_empty() {
        let p = out.join("residuals.parquet");
        let mut cols = vec![
            strs("run_id", rs_run),
            strs("model", rs_model),
            strs("role", rs_role),
            strs("mode", rs_mode),
            ints("segment", rs_segment),
            strs("scope", rs_scope),
        ];
        let names = [
            ("t", "1 (t = ω0·τ)"),
            ("tau_s", "s"),
            ("theta_meas", "rad"),
            ("theta_sim", "rad"),
            ("residual", "rad"),
            ("theta_dot_meas", "rad/s"),
            ("theta_dot_sim", "rad/s"),
        ];
        for ((n, u), v) in names.iter().zip(rsv) {
            cols.push(f64s(n, u, v));
        }
        inputs.check_output("the output", &p)?;
        opts.write(&p, &cols)?;
        tables.push(p);
    }

    // Printed summary.
    let _ = writeln!(
        text,
        "{} runs; outputs in {} ({wall_s:.1} s)",
        ctx.runs.len(),
        out.display()
    );
    for m in &models {
        let free = m.spec.is_free_decay();
        let label = if free {
            format!("{} (free decay)", m.spec.name)
        } else {
            m.spec.name.clone()
        };
        let _ = write!(text, "model {label:<28}");
        for (p, v) in m.spec.params.iter().zip(&m.params) {
            let _ = write!(text, " {}={:.5}", p.name(), v);
        }
        let _ = writeln!(
            text,
            "  f_obj={:.4} E_θ={:.4} gens={} evals={} ({} abandoned) {:.1} s, stop: {}",
            m.f_obj, m.e_theta, m.generations, m.evaluations, m.abandoned, m.wall_s, m.stop_reason
        );
        if let Some((x, f, n)) = &m.polished {
            let _ = writeln!(text, "  polished: {:?} f_obj={f:.4} ({n} evals)", x);
        }
        if free {
            if let Some(r) = ctx
                .runs
                .iter()
                .find(|r| r.role == Role::Identify)
                .or(ctx.runs.first())
            {
                let _ = writeln!(
                    text,
                    "  excitation off; t = 0 at each run's first turning point; {}",
                    not_separable(&r.rig)
                );
            }
        }
        for rf in m
            .runs
            .iter()
            .chain(validation_of(ctx, &m.spec.name).unwrap_or(&[]))
        {
            let _ = writeln!(
                text,
                "  {:<8} {:<8} E_θ={:>9.4}  measured {:<22} simulated {:<22} {}",
                rf.id,
                rf.role.as_str(),
                rf.e_theta,
                rf.measured.to_string(),
                rf.simulated.map_or("-".into(), |s| s.to_string()),
                if rf.steady_agrees() {
                    "agree"
                } else {
                    "DIFFER"
                }
            );
        }
        per_run_summary(&mut text, ctx, m);
    }
    for n in &ctx.notes {
        let _ = writeln!(text, "note: {n}");
    }
    let _ = BTreeSet::<String>::new();
    Ok(OutputSummary {
        out_dir: out.to_path_buf(),
        tables,
        plots,
        text,
    })
}

/// The printed summary's block of each run's own fit, when the model has them (issue 16: free
/// decays whose ω0 differ, where the shared fit forces one ω0 and one damping on all): its
/// values, its E_θ beside the shared fit's on that run, and its decay-law verdict. When a shared
/// ω0 is refused these are the answer, and the block says so.
fn per_run_summary(text: &mut String, ctx: &Context, m: &FitOutcome) {
    let Some(own) = ctx.per_run.get(&m.spec.name) else {
        return;
    };
    let num = |v: f64| {
        if v != 0.0 && v.abs() < 0.1 {
            format!("{v:.3e}")
        } else {
            format!("{v:.5}")
        }
    };
    let _ = writeln!(
        text,
        "  the runs do not share one omega0 (see the notes): each run's own fit below is its \
         answer, the shared fit above is forced (params.parquet and residuals.parquet: scope = run)"
    );
    for r in &ctx.runs {
        let Some(f) = own.get(&r.id) else { continue };
        let values: Vec<String> = f
            .spec
            .params
            .iter()
            .zip(&f.params)
            .map(|(p, v)| format!("{}={}", p.name(), num(*v)))
            .collect();
        let shared_e = m
            .runs
            .iter()
            .find(|rf| rf.id == r.id)
            .map_or(f64::NAN, |rf| rf.e_theta);
        let verdict = pendulum_process::identify::per_run_verdict(&ctx.notes, &r.id)
            .unwrap_or("no decay-law verdict: no envelope in the fit's window");
        let beyond = format!(
            "{}, run {}:",
            pendulum_process::identify::BEYOND_WINDOW,
            r.id
        );
        let window_only = if ctx.notes.iter().any(|n| n.starts_with(&beyond)) {
            " (over the fit window's swings; the whole recording resolves another law: see the \
             note `decay law beyond the fit window`)"
        } else {
            ""
        };
        let _ = writeln!(
            text,
            "  {:<8} alone {}  E_θ={:.4} (shared fit {shared_e:.4}); {verdict}{window_only}",
            r.id,
            values.join(" "),
            f.e_theta
        );
    }
}

/// The least span of a history plot's angle axis, rad (about 33 counts of a 4096-count encoder,
/// 3°): a pendulum at rest is drawn as the flat line it is, its measured and simulated angles a
/// fraction of a count apart side by side, not magnified into two lines across the panel.
const HISTORY_MIN_SPAN_RAD: f64 = 0.05;

/// The least span of a history plot's rate axis, rad/s (see [`HISTORY_MIN_SPAN_RAD`]).
const HISTORY_MIN_SPAN_RAD_S: f64 = 0.5;

fn history_plot(
    path: &Path,
    id: &str,
    model: &str,
    role: Role,
    s: &pendulum_process::identify::ResidualSeries,
    x_label: &str,
) -> Result<(), JobError> {
    let series = |label: &str, y: &[f64], color: usize| Series {
        label: label.into(),
        x: s.tau_s.clone(),
        y: y.to_vec(),
        style: SeriesStyle::Line,
        color: Some(color),
    };
    let fig = Figure {
        title: format!("Run {id} ({}) — measured vs {model} model", role.as_str()),
        panels: vec![
            Panel {
                title: "Angle".into(),
                x_label: x_label.into(),
                y_label: "θ (rad)".into(),
                series: vec![
                    series("measured", &s.theta_meas, 0),
                    series("simulated", &s.theta_sim, 1),
                ],
                y_range: floor_span(
                    s.theta_meas.iter().chain(&s.theta_sim).copied(),
                    HISTORY_MIN_SPAN_RAD,
                ),
                ..Panel::default()
            },
            Panel {
                title: "Angular velocity".into(),
                x_label: x_label.into(),
                y_label: "dθ/dt (rad/s)".into(),
                series: vec![
                    series("measured", &s.theta_dot_meas, 0),
                    series("simulated", &s.theta_dot_sim, 1),
                ],
                y_range: floor_span(
                    s.theta_dot_meas.iter().chain(&s.theta_dot_sim).copied(),
                    HISTORY_MIN_SPAN_RAD_S,
                ),
                ..Panel::default()
            },
        ],
        width: 1200,
        height: 800,
    };
    fig.save_png(path)?;
    Ok(())
}

fn convergence_plot(path: &Path, m: &FitOutcome) -> Result<(), JobError> {
    let x: Vec<f64> = m.convergence.iter().map(|c| c.0 as f64).collect();
    let mk = |label: &str, y: Vec<f64>, color: usize| Series {
        label: label.into(),
        x: x.clone(),
        y,
        style: SeriesStyle::Line,
        color: Some(color),
    };
    let fig = Figure {
        title: format!("Differential Evolution convergence — {} model", m.spec.name),
        panels: vec![Panel {
            title: format!("Np = {}, seed {}, stop: {}", m.np, m.seed, m.stop_reason),
            x_label: "generation".into(),
            y_label: "objective f (rad)".into(),
            series: vec![
                mk("best", m.convergence.iter().map(|c| c.1).collect(), 0),
                mk("mean", m.convergence.iter().map(|c| c.3).collect(), 2),
                mk("worst", m.convergence.iter().map(|c| c.2).collect(), 1),
            ],
            log_y: true,
            ..Panel::default()
        }],
        width: 1200,
        height: 600,
    };
    fig.save_png(path)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A model name read from someone's params.parquet (validate) cannot place a plot outside
    /// the output folder.
    #[test]
    fn issue_13_plot_names_from_inputs_stay_in_out() {
        let out = Path::new("/data/out");
        assert_eq!(
            out_file(out, "history_reference_r01.png", &Inputs::new()).unwrap(),
            out.join("history_reference_r01.png")
        );
        for name in [
            "history_../../x_r01.png",
            "history_/etc/cron.d/x_r01.png",
            "history_a\u{1b}[2J_r01.png",
        ] {
            let e = out_file(out, name, &Inputs::new()).unwrap_err().to_string();
            assert!(e.contains("refusing to write the plot"), "{e}");
            assert!(!e.contains('\u{1b}'), "{e:?}");
        }
    }
}

#[cfg(test)]
mod read_params_tests {
    use super::*;

    /// A params table saved again with 32-bit floats (pandas after `astype("float32")`, or a
    /// tool that narrows) is the same model to `validate`: before the reader was shared with
    /// `design`'s, such a table was refused ("model reference: no column a").
    #[test]
    fn a_table_with_32_bit_floats_is_the_same_model() {
        use arrow_array::{ArrayRef, Float32Array, RecordBatch, StringArray};
        use std::sync::Arc;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("params.parquet");
        let f32col = |v: f32| Arc::new(Float32Array::from(vec![v])) as ArrayRef;
        let batch = RecordBatch::try_from_iter(vec![
            (
                "model",
                Arc::new(StringArray::from(vec!["reference+coulomb_constant"])) as ArrayRef,
            ),
            ("a", f32col(0.05)),
            ("b", f32col(0.5)),
            ("mu", f32col(0.15)),
            ("coulomb_constant.T_c", f32col(0.004)),
        ])
        .unwrap();
        let mut w = parquet::arrow::ArrowWriter::try_new(
            std::fs::File::create(&path).unwrap(),
            batch.schema(),
            None,
        )
        .unwrap();
        w.write(&batch).unwrap();
        w.close().unwrap();
        let m = read_params(&path, None).unwrap();
        let names: Vec<&str> = m.spec.params.iter().map(|p| p.name()).collect();
        assert_eq!(names, ["a", "b", "mu", "coulomb_constant.T_c"]);
        for (v, want) in m.params.iter().zip([0.05, 0.5, 0.15, 0.004]) {
            assert!(
                (v - want).abs() <= 1e-7 * want.max(1.0),
                "{v} against {want}"
            );
        }
        let err = read_params(&path, Some("linear")).unwrap_err().to_string();
        assert!(err.contains("no model named \"linear\""), "{err}");
    }
}
