//! Harvester design: for a fitted model on its rig, the generator load (c_g, ω_d) and the
//! operating point (crank speed Ω, crank radius r) that maximise the expected mean power into
//! the load over a set of starts, searched on a grid.
//!
//! * A **cell** is one (Ω, r, load) with all its starts and every model: cell
//!   `(i_Ω·n_r + i_r)·n_load + i_load` (the load varies fastest), the unit a sharded run deals out
//!   ([`crate::shard`]), and the table lists model by model, cell by cell, like `zones`.
//! * Each start is simulated past its transient and its steady state classified; its mean powers
//!   over one orbit of its steady state come from `pendulum_model::power` ([`crate::power`]). The
//!   cell reports the mean over the starts (the **expected** power when the starting state is
//!   unknown), their spread, standard error and worst start, and the fraction that rotate.
//! * Physical axes, because a designer buys a crank and a generator, not a dimensionless R: the
//!   rig (m, l, L, r_b, g) and the damping come from the model; Ω, r and the generator are set
//!   per cell and made dimensionless through the effect catalogue as `--param` would.

use std::path::Path;

use pendulum_model::{ClassifyOptions, Dimensionless, MeanPowers, Model, Physical, SimOptions};
use pendulum_plot::{save_heatmaps_side_by_side, Figure, Heatmap, Panel, Series, SeriesStyle};
use pendulum_report::{Column, ColumnData};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::style::fmt_num;
use crate::sweep::{Sweep, SweepParam};
use crate::{with_pool, MapsError};

/// The generator's name in the effect catalogue.
const GENERATOR: &str = "generator_rectified";

/// A generator load: the torque c_g (|θ'| − ω_d)⁺ sgn θ' (`effects.md`), and the electrical
/// (k_e, V_d, R) it was given as, if it was.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Load {
    pub c_g_nm_s_rad: f64,
    pub omega_d_rad_s: f64,
    /// (k_e V·s/rad, V_d V, R Ω) when given electrically: c_g = k_e²/R, ω_d = V_d/k_e.
    pub electrical: Option<[f64; 3]>,
}

impl Load {
    pub fn new(c_g_nm_s_rad: f64, omega_d_rad_s: f64) -> Self {
        Self {
            c_g_nm_s_rad,
            omega_d_rad_s,
            electrical: None,
        }
    }

    /// From the electrical parameters; refused unless k_e > 0, V_d ≥ 0, R > 0.
    pub fn electrical(k_e: f64, v_d: f64, r_ohm: f64) -> Result<Self, MapsError> {
        if !(k_e.is_finite() && k_e > 0.0) {
            return Err(MapsError::Invalid(format!(
                "k_e = {k_e} V·s/rad: expected > 0"
            )));
        }
        if !(v_d.is_finite() && v_d >= 0.0) {
            return Err(MapsError::Invalid(format!("V_d = {v_d} V: expected ≥ 0")));
        }
        if !(r_ohm.is_finite() && r_ohm > 0.0) {
            return Err(MapsError::Invalid(format!("R = {r_ohm} Ω: expected > 0")));
        }
        Ok(Self {
            c_g_nm_s_rad: k_e * k_e / r_ohm,
            omega_d_rad_s: v_d / k_e,
            electrical: Some([k_e, v_d, r_ohm]),
        })
    }

    /// `c_g = 0.02 N·m·s/rad, ω_d = 2 rad/s` (and `(k_e = 0.3 V·s/rad, V_d = 1.4 V, R = 5 Ω)`).
    pub fn describe(&self) -> String {
        let mut s = format!(
            "c_g = {} N·m·s/rad, ω_d = {} rad/s",
            fmt_num(self.c_g_nm_s_rad),
            fmt_num(self.omega_d_rad_s)
        );
        if let Some([k, v, r]) = self.electrical {
            s.push_str(&format!(
                " (k_e = {} V·s/rad, V_d = {} V, R = {} Ω)",
                fmt_num(k),
                fmt_num(v),
                fmt_num(r)
            ));
        }
        s
    }
}

/// A model to design for: its label and its rig and damping (the generator is the design's).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DesignModel {
    pub label: String,
    pub physical: Physical,
}

/// The search grid and the simulations per cell.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DesignConfig {
    /// Crank speeds Ω, Hz.
    pub omega_hz: Vec<f64>,
    /// Crank radii r, m.
    pub crank_r_m: Vec<f64>,
    pub loads: Vec<Load>,
    /// Initial states (θ0 rad, θ̇0 dimensionless), the same in every cell.
    pub starts: Vec<[f64; 2]>,
    pub transient_periods: u32,
    pub record_periods: u32,
    pub sim: SimOptions,
    pub classify: ClassifyOptions,
    pub threads: Option<usize>,
}

impl DesignConfig {
    /// Defaults: 200 transient and 32 recorded periods, tolerance 1e-8.
    pub fn new(
        omega_hz: Vec<f64>,
        crank_r_m: Vec<f64>,
        loads: Vec<Load>,
        starts: Vec<[f64; 2]>,
    ) -> Self {
        Self {
            omega_hz,
            crank_r_m,
            loads,
            starts,
            transient_periods: 200,
            record_periods: 32,
            sim: SimOptions::with_tol(1e-8),
            classify: ClassifyOptions::default(),
            threads: None,
        }
    }

    /// Cells: one (Ω, r, load) each, the load fastest.
    pub fn cells(&self) -> usize {
        self.omega_hz.len() * self.crank_r_m.len() * self.loads.len()
    }

    /// What one cell is, in words.
    pub fn cell_description(&self) -> &'static str {
        "one (omega_hz, crank_r_m, load) with all its starts and models; cell = (i_omega·n_r + i_r)·n_load + i_load"
    }

    /// Simulations per model.
    pub fn tasks(&self) -> u64 {
        (self.cells() * self.starts.len()) as u64
    }

    /// (i_Ω, i_r, i_load) of cell `c`.
    pub fn indices(&self, c: usize) -> (usize, usize, usize) {
        let nl = self.loads.len();
        let nr = self.crank_r_m.len();
        (c / (nr * nl), (c / nl) % nr, c % nl)
    }

    /// The model's rig at cell `c`: its Ω, crank radius and generator set, checked, and the
    /// dimensionless parameters the simulator takes.
    pub fn cell_params(
        &self,
        m: &DesignModel,
        c: usize,
    ) -> Result<(Physical, Dimensionless), MapsError> {
        let (io, ir, il) = self.indices(c);
        let mut p = m.physical.clone();
        p.omega_hz = self.omega_hz[io];
        p.crank_r_m = self.crank_r_m[ir];
        let load = &self.loads[il];
        // c_g = 0 is no generator at all (its band then means nothing).
        p.effects.set(
            GENERATOR,
            (load.c_g_nm_s_rad > 0.0).then(|| vec![load.c_g_nm_s_rad, load.omega_d_rad_s]),
        );
        let at = || {
            format!(
                "model {} at Ω = {} Hz, r = {} m, {}",
                m.label,
                self.omega_hz[io],
                self.crank_r_m[ir],
                load.describe()
            )
        };
        p.validate()
            .map_err(|e| MapsError::Invalid(format!("{}: {e}", at())))?;
        let d = p.to_dimensionless();
        d.validate()
            .map_err(|e| MapsError::Invalid(format!("{}: {e}", at())))?;
        Ok((p, d))
    }

    /// Checks the grid and every model at every cell; errors name the bad value.
    pub fn validate(&self, models: &[DesignModel]) -> Result<(), MapsError> {
        let list = |name: &str, v: &[f64], unit: &str, positive: bool| {
            if v.is_empty() {
                return Err(MapsError::Invalid(format!("{name}: no values")));
            }
            for x in v {
                let ok = x.is_finite() && if positive { *x > 0.0 } else { *x >= 0.0 };
                if !ok {
                    return Err(MapsError::Invalid(format!(
                        "{name} = {x} {unit}: expected a finite value {}",
                        if positive { "> 0" } else { "≥ 0" }
                    )));
                }
            }
            Ok(())
        };
        list("omega_hz", &self.omega_hz, "Hz", true)?;
        list("crank_r_m", &self.crank_r_m, "m", true)?;
        if self.loads.is_empty() {
            return Err(MapsError::Invalid("no generator loads".into()));
        }
        for l in &self.loads {
            list("c_g", &[l.c_g_nm_s_rad], "N·m·s/rad", false)?;
            list("omega_d", &[l.omega_d_rad_s], "rad/s", false)?;
        }
        crate::ics::check_starts(&self.starts, self.record_periods)?;
        if models.is_empty() {
            return Err(MapsError::Invalid("no models to design for".into()));
        }
        for m in models {
            for c in 0..self.cells() {
                self.cell_params(m, c)?;
            }
        }
        Ok(())
    }
}

/// One (Ω, r, load) of one model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DesignCell {
    pub cell: usize,
    pub omega_hz: f64,
    pub crank_r_m: f64,
    pub load: Load,
    /// The dimensionless forcing ω = 2πΩ/ω0 and amplitude R = rω²/l.
    pub omega: f64,
    pub r: f64,
    pub starts: usize,
    /// Starts ending in rotation (either way).
    pub rotating: usize,
    /// Mean powers over the starts, W.
    pub mean_power_w: MeanPowers,
    /// Over the starts, of the power into the load: sample standard deviation and smallest, W.
    pub load_power_sd_w: f64,
    pub load_power_min_w: f64,
}

impl DesignCell {
    pub fn rotation_fraction(&self) -> f64 {
        self.rotating as f64 / self.starts.max(1) as f64
    }

    /// Binomial standard error of the rotating fraction, √(p(1−p)/n).
    pub fn rotation_fraction_se(&self) -> f64 {
        let p = self.rotation_fraction();
        (p * (1.0 - p) / self.starts.max(1) as f64).sqrt()
    }

    /// Standard error of the expected power into the load: sd/√n over the starts.
    pub fn load_power_se_w(&self) -> f64 {
        self.load_power_sd_w / (self.starts.max(1) as f64).sqrt()
    }

    /// The expected power into the load, W.
    pub fn load_w(&self) -> f64 {
        self.mean_power_w.load
    }
}

/// One model's search.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Design {
    pub model: DesignModel,
    pub config: DesignConfig,
    /// In cell order (all cells after a full run or a merge; a shard's own otherwise).
    pub cells: Vec<DesignCell>,
}

impl Design {
    /// The cell of the largest expected power into the load (the first on ties; NaN never).
    pub fn best(&self) -> Option<&DesignCell> {
        self.cells.iter().filter(|c| c.load_w().is_finite()).fold(
            None,
            |b: Option<&DesignCell>, c| match b {
                Some(b) if b.load_w() >= c.load_w() => Some(b),
                _ => Some(c),
            },
        )
    }

    /// The cell with index `cell`.
    pub fn cell(&self, cell: usize) -> Option<&DesignCell> {
        self.cells
            .binary_search_by_key(&cell, |c| c.cell)
            .ok()
            .map(|i| &self.cells[i])
    }
}

/// Runs every model on the given cells (ascending), in parallel over (model, cell, start).
/// `progress` is called with 1 per finished simulation.
pub fn run_cells(
    models: &[DesignModel],
    cfg: &DesignConfig,
    cells: &[usize],
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Vec<Design>, MapsError> {
    cfg.validate(models)?;
    if let Some(&bad) = cells.iter().find(|&&c| c >= cfg.cells()) {
        return Err(MapsError::Invalid(format!(
            "cell {bad} is beyond the search's {} cells",
            cfg.cells()
        )));
    }
    let ns = cfg.starts.len();
    // Each (model, cell)'s parameters once.
    let params: Vec<Vec<(Physical, Dimensionless)>> = models
        .iter()
        .map(|m| {
            cells
                .iter()
                .map(|&c| cfg.cell_params(m, c))
                .collect::<Result<_, _>>()
        })
        .collect::<Result<_, _>>()?;
    let tasks: Vec<(usize, usize, usize)> = (0..models.len())
        .flat_map(|m| (0..cells.len()).flat_map(move |j| (0..ns).map(move |s| (m, j, s))))
        .collect();
    let results = with_pool(cfg.threads, || {
        tasks
            .par_iter()
            .map(|&(m, j, s)| {
                let (p, d) = &params[m][j];
                let r = crate::power::steady_with_power(
                    &Model::new(*d),
                    &cfg.sim,
                    cfg.starts[s],
                    cfg.transient_periods,
                    cfg.record_periods,
                    &cfg.classify,
                    p.power_scale_w(),
                )
                .map(|(st, _, _, pw)| (st.class.is_rotation(), pw));
                progress(1);
                r
            })
            .collect::<Result<Vec<_>, _>>()
    })??;
    let mut it = results.into_iter();
    let mut out = Vec::with_capacity(models.len());
    for (mi, m) in models.iter().enumerate() {
        let mut list = Vec::with_capacity(cells.len());
        for (j, &c) in cells.iter().enumerate() {
            let (io, ir, il) = cfg.indices(c);
            let mut rotating = 0;
            let mut powers = Vec::with_capacity(ns);
            for (rot, pw) in it.by_ref().take(ns) {
                rotating += usize::from(rot);
                powers.push(pw);
            }
            let loads: Vec<f64> = powers.iter().map(|p| p.load).collect();
            let d = &params[mi][j].1;
            list.push(DesignCell {
                cell: c,
                omega_hz: cfg.omega_hz[io],
                crank_r_m: cfg.crank_r_m[ir],
                load: cfg.loads[il],
                omega: d.omega,
                r: d.r,
                starts: ns,
                rotating,
                mean_power_w: crate::power::mean_of(&powers),
                load_power_sd_w: crate::power::sample_sd(&loads),
                load_power_min_w: loads.iter().copied().fold(f64::INFINITY, f64::min),
            });
        }
        out.push(Design {
            model: m.clone(),
            config: cfg.clone(),
            cells: list,
        });
    }
    Ok(out)
}

/// The whole search.
pub fn run(
    models: &[DesignModel],
    cfg: &DesignConfig,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Vec<Design>, MapsError> {
    let all: Vec<usize> = (0..cfg.cells()).collect();
    run_cells(models, cfg, &all, progress)
}

/// The search grid as one table: a row per (model, cell), model by model. `best` marks each
/// model's optimum (only meaningful on a whole search; a shard writes false and the merge
/// recomputes it, so that its table is the one-machine run's).
pub fn columns(designs: &[Design], whole: bool) -> Vec<Column> {
    let n: usize = designs.iter().map(|d| d.cells.len()).sum();
    let mut model = Vec::with_capacity(n);
    let mut cell = Vec::with_capacity(n);
    let (mut hz, mut rm, mut cg, mut wd) = (vec![], vec![], vec![], vec![]);
    let (mut ke, mut vd, mut ro) = (vec![], vec![], vec![]);
    let (mut om, mut rr, mut starts, mut rot) = (vec![], vec![], vec![], vec![]);
    let (mut frac, mut frac_se, mut sd, mut se, mut min) = (vec![], vec![], vec![], vec![], vec![]);
    let mut power = Vec::with_capacity(n);
    let mut best = Vec::with_capacity(n);
    for d in designs {
        let b = if whole {
            d.best().map(|c| c.cell)
        } else {
            None
        };
        for c in &d.cells {
            model.push(d.model.label.clone());
            cell.push(c.cell as i64);
            hz.push(c.omega_hz);
            rm.push(c.crank_r_m);
            cg.push(c.load.c_g_nm_s_rad);
            wd.push(c.load.omega_d_rad_s);
            let [k, v, r] = c.load.electrical.unwrap_or([f64::NAN; 3]);
            ke.push(k);
            vd.push(v);
            ro.push(r);
            om.push(c.omega);
            rr.push(c.r);
            starts.push(c.starts as i64);
            rot.push(c.rotating as i64);
            frac.push(c.rotation_fraction());
            frac_se.push(c.rotation_fraction_se());
            power.push(c.mean_power_w);
            sd.push(c.load_power_sd_w);
            se.push(c.load_power_se_w());
            min.push(c.load_power_min_w);
            best.push(b == Some(c.cell));
        }
    }
    let mut cols = vec![
        Column::new("model", ColumnData::Str(model)),
        Column::new("cell", ColumnData::I64(cell)).describe("(i_omega·n_r + i_r)·n_load + i_load"),
        Column::f64("omega_hz", "Hz", hz).describe("crank speed Ω"),
        Column::f64("crank_r_m", "m", rm).describe("crank radius r"),
        Column::f64("c_g_nm_s_rad", "N·m·s/rad", cg)
            .describe("generator load c_g = k_e²/R (T_gen = c_g (|θ'| − ω_d)⁺ sgn θ')"),
        Column::f64("omega_d_rad_s", "rad/s", wd).describe("generator dead band ω_d = V_d/k_e"),
        Column::f64("k_e_v_s_rad", "V·s/rad", ke)
            .describe("generator EMF constant, when the load was given electrically (else NaN)"),
        Column::f64("v_d_v", "V", vd)
            .describe("rectifier diode drop, when the load was given electrically (else NaN)"),
        Column::f64("r_ohm", "Ω", ro)
            .describe("load resistance, when the load was given electrically (else NaN)"),
        Column::f64("omega", "1 (ω/ω0)", om).describe("dimensionless forcing frequency 2πΩ/ω0"),
        Column::f64("R", "1", rr).describe("dimensionless forcing amplitude rω²/l"),
        Column::new("starts", ColumnData::I64(starts)).describe("initial states simulated"),
        Column::new("rotating_starts", ColumnData::I64(rot))
            .describe("starts ending in rotation (either way)"),
        Column::f64("rotation_fraction", "1", frac)
            .describe("fraction of starts ending in rotation"),
        Column::f64("rotation_fraction_se", "1", frac_se)
            .describe("binomial standard error of rotation_fraction, √(p(1−p)/starts)"),
    ];
    cols.extend(crate::power::columns(
        &power,
        "mean over the cell's starts of the ",
    ));
    cols.extend([
        Column::f64("load_power_sd_w", "W", sd)
            .describe("standard deviation over the starts of the power into the load, W"),
        Column::f64("load_power_se_w", "W", se)
            .describe("standard error of the expected power into the load (sd/√starts), W"),
        Column::f64("load_power_min_w", "W", min)
            .describe("power into the load of the worst start, W"),
        Column::new("best", ColumnData::Bool(best))
            .describe("this model's largest expected power into the load"),
    ]);
    cols
}

/// The table's key-value metadata: the grid and the models.
pub fn metadata(models: &[DesignModel], cfg: &DesignConfig) -> Vec<(String, String)> {
    let nums = |v: &[f64]| {
        v.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(",")
    };
    let mut md = vec![
        ("omega_hz".to_string(), nums(&cfg.omega_hz)),
        ("crank_r_m".to_string(), nums(&cfg.crank_r_m)),
        ("loads".to_string(), cfg.loads.len().to_string()),
        ("starts".to_string(), cfg.starts.len().to_string()),
        (
            "transient_periods".to_string(),
            cfg.transient_periods.to_string(),
        ),
        ("record_periods".to_string(), cfg.record_periods.to_string()),
        ("tol".to_string(), cfg.sim.rtol.to_string()),
    ];
    for m in models {
        md.push((
            format!("physical.{}", m.label),
            serde_json::to_string(&m.physical).unwrap_or_default(),
        ));
        md.push((
            format!("power_scale_w.{}", m.label),
            m.physical.power_scale_w().to_string(),
        ));
    }
    md
}

/// Merges the shards of a design run ([`crate::shard::read_shards`]): the table (the shards'
/// rows in the one-machine order, `best` recomputed over the whole grid) and the designs
/// rebuilt from it for the figures and the summary.
pub fn merge_shards(
    models: &[DesignModel],
    cfg: &DesignConfig,
    set: &crate::shard::ShardSet,
) -> Result<(Vec<Design>, Vec<Column>), MapsError> {
    use crate::shard::col;
    cfg.validate(models)?;
    let total = cfg.cells();
    set.check_cells(total, "the search")?;
    let owner = set.cell_owner();
    let ns = cfg.starts.len();
    let mut designs = Vec::with_capacity(models.len());
    for (mi, m) in models.iter().enumerate() {
        let mut cells = Vec::with_capacity(total);
        for (c, &(s, j)) in owner.iter().enumerate() {
            if s == usize::MAX {
                return Err(MapsError::Invalid(format!("no shard holds cell {c}")));
            }
            let man = &set.manifests[s];
            let r = mi * man.cells.len() + j;
            let part = &set.parts[s];
            let f = |name: &str| -> Result<f64, MapsError> {
                match col(part, name)? {
                    ColumnData::F64(v) if r < v.len() => Ok(v[r]),
                    _ => Err(MapsError::Invalid(format!(
                        "shard {}: column {name} has no f64 row {r}",
                        man.shard
                    ))),
                }
            };
            let i = |name: &str| -> Result<i64, MapsError> {
                match col(part, name)? {
                    ColumnData::I64(v) if r < v.len() => Ok(v[r]),
                    _ => Err(MapsError::Invalid(format!(
                        "shard {}: column {name} has no integer row {r}",
                        man.shard
                    ))),
                }
            };
            let label_ok =
                matches!(col(part, "model")?, ColumnData::Str(v) if v.get(r) == Some(&m.label));
            if !label_ok || i("cell")? != c as i64 || i("starts")? != ns as i64 {
                return Err(MapsError::Invalid(format!(
                    "shard {}: row {r} is not model {}'s cell {c} with {ns} starts",
                    man.shard, m.label
                )));
            }
            let (io, ir, il) = cfg.indices(c);
            let (_, d) = cfg.cell_params(m, c)?;
            let rotating = usize::try_from(i("rotating_starts")?)
                .map_err(|_| MapsError::Invalid("negative rotating_starts".into()))?;
            cells.push(DesignCell {
                cell: c,
                omega_hz: cfg.omega_hz[io],
                crank_r_m: cfg.crank_r_m[ir],
                load: cfg.loads[il],
                omega: d.omega,
                r: d.r,
                starts: ns,
                rotating,
                mean_power_w: crate::power::read_row(part, r)?,
                load_power_sd_w: f("load_power_sd_w")?,
                load_power_min_w: f("load_power_min_w")?,
            });
        }
        designs.push(Design {
            model: m.clone(),
            config: cfg.clone(),
            cells,
        });
    }
    let cols = columns(&designs, true);
    Ok((designs, cols))
}

/// The cells of `d` at the best cell's Ω and r and band ω_d, by c_g (the power-versus-load
/// curve a designer reads the optimum from).
fn load_curve<'a>(d: &'a Design, at: &DesignCell) -> Vec<&'a DesignCell> {
    let mut v: Vec<&DesignCell> = d
        .cells
        .iter()
        .filter(|c| {
            c.omega_hz == at.omega_hz
                && c.crank_r_m == at.crank_r_m
                && c.load.omega_d_rad_s == at.load.omega_d_rad_s
        })
        .collect();
    v.sort_by(|a, b| a.load.c_g_nm_s_rad.total_cmp(&b.load.c_g_nm_s_rad));
    v
}

/// `design.png`: at the first model's optimum (Ω, r, ω_d), the expected power into the load
/// against c_g with ± one standard error, and the fraction of starts that rotate, every model
/// on the same axes.
pub fn plot_curves(designs: &[Design], path: &Path) -> Result<(), MapsError> {
    let Some(best) = designs.first().and_then(|d| d.best()).cloned() else {
        return Err(MapsError::Invalid("no design to plot".into()));
    };
    let mut power = Vec::new();
    let mut rot = Vec::new();
    for (k, d) in designs.iter().enumerate() {
        let curve = load_curve(d, &best);
        let x: Vec<f64> = curve.iter().map(|c| c.load.c_g_nm_s_rad).collect();
        let color = Some(k);
        power.push(Series {
            label: format!("{}: expected power into the load", d.model.label),
            x: x.clone(),
            y: curve.iter().map(|c| c.load_w()).collect(),
            style: SeriesStyle::LinePoints,
            color,
        });
        for sign in [1.0, -1.0] {
            power.push(Series {
                label: if sign > 0.0 {
                    format!("{}: ± one standard error over the starts", d.model.label)
                } else {
                    String::new()
                },
                x: x.clone(),
                y: curve
                    .iter()
                    .map(|c| c.load_w() + sign * c.load_power_se_w())
                    .collect(),
                style: SeriesStyle::Line,
                color,
            });
        }
        rot.push(Series {
            label: d.model.label.clone(),
            x,
            y: curve
                .iter()
                .map(|c| 100.0 * c.rotation_fraction())
                .collect(),
            style: SeriesStyle::LinePoints,
            color,
        });
    }
    let title = format!(
        "Design, {}: c_g = {} N·m·s/rad, ω_d = {} rad/s, Ω = {} Hz, r = {} m: {} W ± {} W",
        designs[0].model.label,
        fmt_num(best.load.c_g_nm_s_rad),
        fmt_num(best.load.omega_d_rad_s),
        fmt_num(best.omega_hz),
        fmt_num(best.crank_r_m),
        fmt_w(best.load_w()),
        fmt_w(best.load_power_se_w()),
    );
    Figure {
        width: 1400.max(title.chars().count() as u32 * 21 + 100).min(4000),
        height: 900,
        title,
        panels: vec![
            Panel {
                title: format!(
                    "power into the load at the optimum's Ω, r, ω_d: mean ± one standard error over {} starts",
                    best.starts,
                ),
                x_label: "generator load c_g = k_e²/R (N·m·s/rad)".into(),
                y_label: "mean electrical power into the load (W)".into(),
                series: power,
                log_y: false,
                y_range: None,
            },
            Panel {
                title: "starts that end rotating".into(),
                x_label: "generator load c_g = k_e²/R (N·m·s/rad)".into(),
                y_label: "starts ending in rotation (%)".into(),
                series: rot,
                log_y: false,
                y_range: Some((0.0, 100.0)),
            },
        ],
    }
    .save_png(path)?;
    Ok(())
}

/// `design_map.png`: per model, over Ω × r, the expected power into the load of the best load at
/// each operating point (W); a dot marks the model's optimum.
pub fn plot_map(designs: &[Design], path: &Path) -> Result<(), MapsError> {
    let Some(first) = designs.first() else {
        return Err(MapsError::Invalid("no design to plot".into()));
    };
    let cfg = &first.config;
    let (no, nr, nl) = (cfg.omega_hz.len(), cfg.crank_r_m.len(), cfg.loads.len());
    let edges = |v: &[f64]| {
        Sweep {
            param: SweepParam::Omega,
            values: v.to_vec(),
        }
        .edges()
    };
    let best_per_point = |d: &Design| -> Vec<Vec<f64>> {
        (0..nr)
            .map(|ir| {
                (0..no)
                    .map(|io| {
                        (0..nl)
                            .filter_map(|il| d.cell((io * nr + ir) * nl + il))
                            .map(DesignCell::load_w)
                            .filter(|v| v.is_finite())
                            .fold(f64::NAN, f64::max)
                    })
                    .collect()
            })
            .collect()
    };
    let hi = designs
        .iter()
        .flat_map(|d| best_per_point(d).into_iter().flatten())
        .filter(|v| v.is_finite())
        .fold(0.0f64, f64::max);
    let maps: Vec<Heatmap> = designs
        .iter()
        .map(|d| {
            let marks = d
                .best()
                .map(|b| {
                    let (io, ir, _) = cfg.indices(b.cell);
                    vec![(io, ir)]
                })
                .unwrap_or_default();
            Heatmap {
                title: format!(
                    "{}: best load at each operating point{}",
                    d.model.label,
                    d.best()
                        .map(|b| format!(" (dot: optimum, {} W)", fmt_num(b.load_w())))
                        .unwrap_or_default()
                ),
                x_label: "crank speed Ω (Hz)".into(),
                y_label: "crank radius r (m)".into(),
                x_edges: edges(&cfg.omega_hz),
                y_edges: edges(&cfg.crank_r_m),
                values: best_per_point(d),
                value_label: "expected power into the load (W)".into(),
                vmin: Some(0.0),
                vmax: Some(if hi > 0.0 { hi } else { 1.0 }),
                marks,
                diverging: false,
                width: 800,
                height: 650,
            }
        })
        .collect();
    save_heatmaps_side_by_side(
        &maps,
        &format!(
            "Expected power into the load over the operating points, the best of {nl} loads at each ({} starts)",
            cfg.starts.len()
        ),
        path,
    )?;
    Ok(())
}

/// Watts to 4 significant digits, in scientific notation below 1 mW (a standard error of
/// 2e-9 W is numerical noise, and reads as such).
pub fn fmt_w(v: f64) -> String {
    if v != 0.0 && v.is_finite() && v.abs() < 1e-3 {
        format!("{v:.1e}")
    } else {
        fmt_num(v)
    }
}

/// The rig's largest crank speed set point and crank radius (rig.md's tables): an optimum there
/// is at what the rig can do, not at the edge of a search that could be widened.
pub const RIG_MAX_OMEGA_HZ: f64 = 2.36;
pub const RIG_MAX_CRANK_R_M: f64 = 0.205;

/// Where `b` lies on an edge of the searched grid, in words (an optimum there may lie beyond),
/// and, apart, where it lies at the rig's own limits (rig.md's largest Ω and r).
pub fn edges_of(cfg: &DesignConfig, b: &DesignCell) -> Vec<String> {
    edges_and_limits(cfg, b).0
}

/// ([`edges_of`], the rig's limits the optimum sits at).
pub fn edges_and_limits(cfg: &DesignConfig, b: &DesignCell) -> (Vec<String>, Vec<String>) {
    let (mut out, mut limits) = (Vec::new(), Vec::new());
    let mut edge = |name: &str, v: f64, all: Vec<f64>, rig_max: Option<(f64, &str)>| {
        let lo = all.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = all.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if lo < hi && v == hi {
            match rig_max {
                Some((m, unit)) if (v - m).abs() <= 1e-9 * m => {
                    limits.push(format!("the rig's largest {name} ({} {unit})", fmt_num(m)));
                }
                _ => out.push(format!("the largest {name} searched")),
            }
        } else if lo < hi && v == lo {
            out.push(format!("the smallest {name} searched"));
        }
    };
    edge(
        "Ω",
        b.omega_hz,
        cfg.omega_hz.clone(),
        Some((RIG_MAX_OMEGA_HZ, "Hz")),
    );
    edge(
        "r",
        b.crank_r_m,
        cfg.crank_r_m.clone(),
        Some((RIG_MAX_CRANK_R_M, "m")),
    );
    edge(
        "c_g",
        b.load.c_g_nm_s_rad,
        cfg.loads.iter().map(|l| l.c_g_nm_s_rad).collect(),
        None,
    );
    (out, limits)
}

/// `design.md`: the answer in words (this load, this speed, this many watts, this sure), each
/// model's optimum and what the other models predict there, and each model's five best cells.
pub fn summary_markdown(designs: &[Design]) -> String {
    let mut s = String::from("# Harvester design\n\n");
    let Some(first) = designs.first() else {
        s.push_str("No model.\n");
        return s;
    };
    let cfg = &first.config;
    s.push_str(&format!(
        "Searched {} crank speeds × {} crank radii × {} generator loads = {} operating points per model, {} starts each, classified over the last {} of {} + {} forcing periods, mean powers over one orbit of each start's steady state (all recorded periods when chaotic).\n\n",
        cfg.omega_hz.len(),
        cfg.crank_r_m.len(),
        cfg.loads.len(),
        cfg.cells(),
        cfg.starts.len(),
        cfg.record_periods,
        cfg.transient_periods,
        cfg.record_periods
    ));
    for d in designs {
        s.push_str(&format!("## {}\n\n", d.model.label));
        let Some(b) = d.best() else {
            s.push_str("No cell gave a finite power.\n\n");
            continue;
        };
        s.push_str(&format!(
            "**This load, this speed, this many watts, this sure:** {} at Ω = {} Hz with a crank of r = {} m: **{} W** into the load (± {} W, standard error over {} starts; spread {} W, worst start {} W); {} of {} starts rotate ({:.0} % ± {:.0} %).\n\n",
            b.load.describe(),
            fmt_num(b.omega_hz),
            fmt_num(b.crank_r_m),
            fmt_w(b.load_w()),
            fmt_w(b.load_power_se_w()),
            b.starts,
            fmt_w(b.load_power_sd_w),
            fmt_w(b.load_power_min_w),
            b.rotating,
            b.starts,
            100.0 * b.rotation_fraction(),
            100.0 * b.rotation_fraction_se()
        ));
        s.push_str(&format!(
            "Where the power goes there (W): input {} = viscous {} + quadratic {} + dry {} + generator {} (load {}, diodes {}) + stored {}.\n\n",
            fmt_w(b.mean_power_w.base),
            fmt_w(b.mean_power_w.viscous),
            fmt_w(b.mean_power_w.quadratic),
            fmt_w(b.mean_power_w.dry),
            fmt_w(b.mean_power_w.generator),
            fmt_w(b.mean_power_w.load),
            fmt_w(b.mean_power_w.diodes),
            fmt_w(b.mean_power_w.stored)
        ));
        let edges = edges_of(cfg, b);
        if !edges.is_empty() {
            s.push_str(&format!(
                "The optimum is at {}: the best may lie beyond the grid; widen the search there.\n\n",
                edges.join(" and ")
            ));
        }
        let (_, limits) = edges_and_limits(cfg, b);
        if !limits.is_empty() {
            s.push_str(&format!(
                "The optimum is at {}: as hard as this rig can shake (rig.md's set points), not an edge of the search.\n\n",
                limits.join(" and ")
            ));
        }
        for other in designs.iter().filter(|o| o.model.label != d.model.label) {
            if let Some(c) = other.cell(b.cell) {
                s.push_str(&format!(
                    "Model {} at this point: {} W ± {} W, {:.0} % of starts rotate.\n\n",
                    other.model.label,
                    fmt_w(c.load_w()),
                    fmt_w(c.load_power_se_w()),
                    100.0 * c.rotation_fraction()
                ));
            }
        }
        let mut top: Vec<&DesignCell> = d.cells.iter().filter(|c| c.load_w().is_finite()).collect();
        top.sort_by(|a, b| b.load_w().total_cmp(&a.load_w()).then(a.cell.cmp(&b.cell)));
        s.push_str("| Ω (Hz) | r (m) | c_g (N·m·s/rad) | ω_d (rad/s) | load power (W) | ± se (W) | rotating |\n|---|---|---|---|---|---|---|\n");
        for c in top.iter().take(5) {
            s.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {:.0} % |\n",
                fmt_num(c.omega_hz),
                fmt_num(c.crank_r_m),
                fmt_num(c.load.c_g_nm_s_rad),
                fmt_num(c.load.omega_d_rad_s),
                fmt_w(c.load_w()),
                fmt_w(c.load_power_se_w()),
                100.0 * c.rotation_fraction()
            ));
        }
        s.push('\n');
    }
    s.push_str("Figures: `design.png` (power and rotation against the load at the first model's optimum), `design_map.png` (the best load's power over the operating points). Table: `design.parquet`.\n");
    s
}
