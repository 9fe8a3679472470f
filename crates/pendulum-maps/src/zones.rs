//! Rotation-zone maps: two parameters swept on a grid (e.g. ω × R); per cell, the fraction of
//! initial states that end in rotation and the mean rotation speed. Several models run on the
//! same grid and starts, so two of them can be compared cell by cell.

use std::path::Path;

use pendulum_model::{ClassifyOptions, Dimensionless, MeanPowers, Model, SimOptions, SteadyClass};
use pendulum_plot::{save_heatmaps_side_by_side, Heatmap};
use pendulum_report::{Column, ColumnData, TableOptions, TableSummary};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::style::describe_params;
use crate::sweep::Sweep;
use crate::{class_index, with_pool, MapsError};

/// The grid and the simulations per cell.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ZoneConfig {
    /// Swept along the map's x axis.
    pub x: Sweep,
    /// Swept along the map's y axis.
    pub y: Sweep,
    /// Initial states simulated in every cell.
    pub starts: Vec<[f64; 2]>,
    pub transient_periods: u32,
    pub record_periods: u32,
    pub sim: SimOptions,
    pub classify: ClassifyOptions,
    pub threads: Option<usize>,
    /// m g l ω0 of the rig, W: the mean powers' unit. One rig for every model of the map (the
    /// first model's, when a job compares two), so that their watts compare.
    #[serde(default = "crate::power::default_scale_w")]
    pub power_scale_w: f64,
}

impl ZoneConfig {
    /// Defaults: 200 transient and 32 recorded periods, tolerance 1e-8.
    pub fn new(x: Sweep, y: Sweep, starts: Vec<[f64; 2]>) -> Self {
        Self {
            x,
            y,
            starts,
            transient_periods: 200,
            record_periods: 32,
            sim: SimOptions::with_tol(1e-8),
            classify: ClassifyOptions::default(),
            threads: None,
            power_scale_w: crate::power::default_scale_w(),
        }
    }

    /// Simulations per model (the progress total is this times the number of models).
    pub fn tasks(&self) -> u64 {
        (self.x.len() * self.y.len() * self.starts.len()) as u64
    }

    fn validate(&self, models: &[(String, Dimensionless)]) -> Result<(), MapsError> {
        if self.x.param == self.y.param {
            return Err(MapsError::Invalid(format!(
                "the x and y sweeps are both {}: choose two different parameters",
                self.x.param.name()
            )));
        }
        if self.x.is_empty() || self.y.is_empty() {
            return Err(MapsError::Invalid("a sweep has no values".into()));
        }
        crate::ics::check_starts(&self.starts, self.record_periods)?;
        if models.is_empty() {
            return Err(MapsError::Invalid("no models to map".into()));
        }
        if !(self.power_scale_w.is_finite() && self.power_scale_w > 0.0) {
            return Err(MapsError::Invalid(format!(
                "power scale {} W: expected m g l ω0 > 0",
                self.power_scale_w
            )));
        }
        for (name, base) in models {
            for ix in 0..self.x.len() {
                for iy in 0..self.y.len() {
                    let d = self.cell_params(base, ix, iy);
                    d.validate().map_err(|e| {
                        MapsError::Invalid(format!(
                            "model {name} at {}={}, {}={}: {e}",
                            self.x.param.name(),
                            self.x.values[ix],
                            self.y.param.name(),
                            self.y.values[iy]
                        ))
                    })?;
                    if d.omega <= 0.0 {
                        return Err(MapsError::Invalid(format!(
                            "model {name}: omega = {} has no forcing period",
                            d.omega
                        )));
                    }
                }
            }
        }
        Ok(())
    }

    /// Cells of the map, `nx·ny`; cell `iy·nx + ix` is (ix, iy), the table's order. The unit a
    /// sharded run deals out ([`crate::shard`]), with all its starts and all models.
    pub fn cells(&self) -> usize {
        self.x.len() * self.y.len()
    }

    /// `base` with both swept parameters set to cell (ix, iy).
    pub fn cell_params(&self, base: &Dimensionless, ix: usize, iy: usize) -> Dimensionless {
        let d = self.x.apply(base, ix);
        self.y.apply(&d, iy)
    }
}

/// One cell of a map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ZoneCell {
    pub ix: usize,
    pub iy: usize,
    pub x: f64,
    pub y: f64,
    /// Starts per class, in [`SteadyClass::ALL`] order.
    pub counts: [usize; 5],
    pub starts: usize,
    /// Mean |dθ/dt| (dimensionless) over the starts that rotate; NaN when none does.
    pub mean_rotation_speed: f64,
    /// Mean powers over the starts (each over its recorded periods), W.
    pub mean_power_w: MeanPowers,
    /// Sample standard deviation over the starts of the power into the load, W.
    pub load_power_sd_w: f64,
}

impl ZoneCell {
    pub fn fraction(&self, c: SteadyClass) -> f64 {
        if self.starts == 0 {
            0.0
        } else {
            self.counts[class_index(c)] as f64 / self.starts as f64
        }
    }

    pub fn rotation_fraction(&self) -> f64 {
        self.fraction(SteadyClass::RotationCcw) + self.fraction(SteadyClass::RotationCw)
    }

    /// Whether any start rotates.
    pub fn rotates(&self) -> bool {
        self.counts[class_index(SteadyClass::RotationCcw)]
            + self.counts[class_index(SteadyClass::RotationCw)]
            > 0
    }
}

/// One model's map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ZoneMap {
    pub label: String,
    pub base: Dimensionless,
    pub config: ZoneConfig,
    /// Row-major by y: cell (ix, iy) is `cells[iy * nx + ix]`.
    pub cells: Vec<ZoneCell>,
}

impl ZoneMap {
    pub fn cell(&self, ix: usize, iy: usize) -> &ZoneCell {
        &self.cells[iy * self.config.x.len() + ix]
    }

    /// Cells where some start rotates.
    pub fn rotating_cells(&self) -> usize {
        self.cells.iter().filter(|c| c.rotates()).count()
    }

    fn grid(&self, f: impl Fn(&ZoneCell) -> f64) -> Vec<Vec<f64>> {
        (0..self.config.y.len())
            .map(|iy| {
                (0..self.config.x.len())
                    .map(|ix| f(self.cell(ix, iy)))
                    .collect()
            })
            .collect()
    }

    fn heatmap(&self, title: String, marks: Vec<(usize, usize)>) -> Heatmap {
        let c = &self.config;
        Heatmap {
            title,
            x_label: c.x.param.label().to_string(),
            y_label: c.y.param.label().to_string(),
            x_edges: c.x.edges(),
            y_edges: c.y.edges(),
            values: self.grid(|cell| 100.0 * cell.rotation_fraction()),
            value_label: "starts ending in rotation (%)".to_string(),
            vmin: Some(0.0),
            vmax: Some(100.0),
            marks,
            diverging: false,
            width: 900,
            height: 700,
        }
    }

    /// `reference model (λ = 0.126, β = 0.109, M = 0.007)`: the label and the parameters that
    /// are not swept.
    pub fn describe(&self) -> String {
        let mut d = describe_params(&self.base, Some(self.config.x.param.name()));
        // Drop the y parameter too.
        let y = self.config.y.param.symbol();
        d = d
            .split(", ")
            .filter(|p| !p.starts_with(&format!("{y} =")))
            .collect::<Vec<_>>()
            .join(", ");
        format!("{} model ({d})", self.label)
    }

    /// Two heat maps side by side: the fraction of starts ending in rotation and the mean
    /// rotation speed.
    pub fn plot(&self, path: &Path) -> Result<(), MapsError> {
        let frac = self.heatmap("starts ending in rotation".into(), Vec::new());
        let speed_vals = self.grid(|cell| cell.mean_rotation_speed);
        let vmax = speed_vals
            .iter()
            .flatten()
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0f64, f64::max);
        let speed = Heatmap {
            title: "mean rotation speed of the rotating starts".into(),
            values: speed_vals,
            value_label: "mean |dθ/dt| (dimensionless; grey: no rotation)".into(),
            vmin: Some(0.0),
            vmax: Some(if vmax > 0.0 { vmax } else { 1.0 }),
            ..frac.clone()
        };
        save_heatmaps_side_by_side(
            &[frac, speed],
            &format!(
                "Rotation zones, {}: {} starts per cell, {} + {} periods",
                self.describe(),
                self.config.starts.len(),
                self.config.transient_periods,
                self.config.record_periods
            ),
            path,
        )?;
        Ok(())
    }
}

impl ZoneMap {
    /// A heat map of `f` over the grid (W), from 0 to its largest value.
    fn power_heatmap(
        &self,
        title: &str,
        value_label: &str,
        f: impl Fn(&ZoneCell) -> f64,
    ) -> Heatmap {
        let values = self.grid(f);
        let hi = values
            .iter()
            .flatten()
            .copied()
            .filter(|v| v.is_finite())
            .fold(0.0f64, f64::max);
        Heatmap {
            title: title.to_string(),
            values,
            value_label: value_label.to_string(),
            vmin: Some(0.0),
            vmax: Some(if hi > 0.0 { hi } else { 1.0 }),
            ..self.heatmap(String::new(), Vec::new())
        }
    }

    /// Where the power goes on the map: the mean power into the generator's load and the mean
    /// power the base's motion feeds in (which the losses dissipate), W, over the starts.
    pub fn plot_power(&self, path: &Path) -> Result<(), MapsError> {
        let load = self.power_heatmap(
            "mean power into the generator's load",
            "mean electrical power into the load over the starts (W)",
            |c| c.mean_power_w.load,
        );
        let base = self.power_heatmap(
            "mean power fed in by the base's motion",
            "mean input power over the starts (W) = the losses' sum",
            |c| c.mean_power_w.base,
        );
        save_heatmaps_side_by_side(
            &[load, base],
            &format!(
                "Power, {}: {} starts per cell, classified over the last {} of {} + {} periods, powers over one orbit (rig m g l ω0 = {} W)",
                self.describe(),
                self.config.starts.len(),
                self.config.record_periods,
                self.config.transient_periods,
                self.config.record_periods,
                crate::style::fmt_num(self.config.power_scale_w)
            ),
            path,
        )?;
        Ok(())
    }
}

/// Where two models disagree in power, W: the first's mean power into the load minus the
/// second's, and the same for the input power, each on a range symmetric about 0 (the middle of
/// the colour bar is agreement). Returns the largest |difference| of each (W).
pub fn plot_power_comparison(
    a: &ZoneMap,
    b: &ZoneMap,
    path: &Path,
) -> Result<(f64, f64), MapsError> {
    compare(a, b)?;
    let diff = |f: fn(&ZoneCell) -> f64| -> Vec<Vec<f64>> {
        (0..a.config.y.len())
            .map(|iy| {
                (0..a.config.x.len())
                    .map(|ix| f(a.cell(ix, iy)) - f(b.cell(ix, iy)))
                    .collect()
            })
            .collect()
    };
    let span = |v: &[Vec<f64>]| {
        v.iter()
            .flatten()
            .copied()
            .filter(|x| x.is_finite())
            .fold(0.0f64, |m, x| m.max(x.abs()))
    };
    let load = diff(|c| c.mean_power_w.load);
    let base = diff(|c| c.mean_power_w.base);
    let (sl, sb) = (span(&load), span(&base));
    let map = |title: String, values: Vec<Vec<f64>>, s: f64| Heatmap {
        title,
        values,
        value_label: format!("{} − {} (W)", a.label, b.label),
        vmin: Some(-if s > 0.0 { s } else { 1.0 }),
        vmax: Some(if s > 0.0 { s } else { 1.0 }),
        diverging: true,
        ..a.heatmap(String::new(), Vec::new())
    };
    let input = map(
        format!(
            "input power, {} minus {} (mean over {} starts per cell)",
            a.label,
            b.label,
            a.config.starts.len()
        ),
        base,
        sb,
    );
    // Without a generator in either model the load panel is 0 everywhere: say so and draw the
    // input power alone.
    let no_load = load.iter().flatten().all(|v| *v == 0.0);
    let panels = if no_load {
        vec![input]
    } else {
        vec![
            map(
                format!("power into the load, {} minus {}", a.label, b.label),
                load,
                sl,
            ),
            input,
        ]
    };
    save_heatmaps_side_by_side(
        &panels,
        &if no_load {
            // One panel is narrower than two: a short title (the starts are in the panel's).
            format!(
                "Input power, {} − {}: no generator in either model; largest gap {} W",
                a.label,
                b.label,
                crate::style::fmt_num(sb)
            )
        } else {
            format!(
                "Where {} and {} disagree in power (W; mean over {} starts per cell): largest gap {} W into the load, {} W input",
                a.label,
                b.label,
                a.config.starts.len(),
                crate::style::fmt_num(sl),
                crate::style::fmt_num(sb)
            )
        },
        path,
    )?;
    Ok((sl, sb))
}

/// Runs every model on the same grid and starts, in parallel over (model, cell, start).
/// `progress` is called with 1 per finished simulation.
pub fn run(
    models: &[(String, Dimensionless)],
    cfg: &ZoneConfig,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Vec<ZoneMap>, MapsError> {
    let all: Vec<usize> = (0..cfg.cells()).collect();
    run_cells(models, cfg, &all, progress)
}

/// Runs the given cells (`iy·nx + ix`, ascending) of every model: maps holding just these
/// cells, each as [`run`] computes it (a shard's share of the map).
pub fn run_cells(
    models: &[(String, Dimensionless)],
    cfg: &ZoneConfig,
    cell_list: &[usize],
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Vec<ZoneMap>, MapsError> {
    cfg.validate(models)?;
    let (nx, ns) = (cfg.x.len(), cfg.starts.len());
    if let Some(&bad) = cell_list.iter().find(|&&c| c >= cfg.cells()) {
        return Err(MapsError::Invalid(format!(
            "cell {bad} is beyond the map's {} cells",
            cfg.cells()
        )));
    }
    let tasks: Vec<(usize, usize, usize, usize)> = (0..models.len())
        .flat_map(|m| {
            cell_list
                .iter()
                .flat_map(move |&c| (0..ns).map(move |s| (m, c % nx, c / nx, s)))
        })
        .collect();
    let results = with_pool(cfg.threads, || {
        tasks
            .par_iter()
            .map(|&(m, ix, iy, s)| {
                let d = cfg.cell_params(&models[m].1, ix, iy);
                let r = crate::power::steady_with_power(
                    &Model::new(d),
                    &cfg.sim,
                    cfg.starts[s],
                    cfg.transient_periods,
                    cfg.record_periods,
                    &cfg.classify,
                    cfg.power_scale_w,
                )
                .map(|(st, _, _, pw)| (st, pw));
                progress(1);
                r
            })
            .collect::<Result<Vec<_>, _>>()
    })??;
    let mut maps = Vec::with_capacity(models.len());
    let mut it = results.into_iter();
    for (label, base) in models {
        let mut cells = Vec::with_capacity(cell_list.len());
        for &c in cell_list {
            let (ix, iy) = (c % nx, c / nx);
            let mut counts = [0usize; 5];
            let (mut speed_sum, mut n_rot) = (0.0, 0usize);
            let mut powers = Vec::with_capacity(ns);
            for (st, pw) in it.by_ref().take(ns) {
                powers.push(pw);
                counts[class_index(st.class)] += 1;
                if st.class.is_rotation() {
                    speed_sum += st.mean_theta_dot.abs();
                    n_rot += 1;
                }
            }
            cells.push(ZoneCell {
                ix,
                iy,
                x: cfg.x.values[ix],
                y: cfg.y.values[iy],
                counts,
                starts: ns,
                mean_rotation_speed: if n_rot > 0 {
                    speed_sum / n_rot as f64
                } else {
                    f64::NAN
                },
                mean_power_w: crate::power::mean_of(&powers),
                load_power_sd_w: crate::power::sample_sd(
                    &powers.iter().map(|p| p.load).collect::<Vec<_>>(),
                ),
            });
        }
        maps.push(ZoneMap {
            label: label.clone(),
            base: *base,
            config: cfg.clone(),
            cells,
        });
    }
    Ok(maps)
}

/// Where two maps on the same grid disagree about rotation.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Comparison {
    /// Cells (ix, iy) where the first map rotates and the second does not.
    pub only_a: Vec<(usize, usize)>,
    /// Cells where the second rotates and the first does not.
    pub only_b: Vec<(usize, usize)>,
    /// Cells where both rotate.
    pub both: usize,
    /// Cells where neither does.
    pub neither: usize,
}

impl Comparison {
    /// All disagreeing cells.
    pub fn disagree(&self) -> Vec<(usize, usize)> {
        let mut v = self.only_a.clone();
        v.extend(&self.only_b);
        v.sort_unstable();
        v
    }
}

/// Compares two maps on the same grid cell by cell.
pub fn compare(a: &ZoneMap, b: &ZoneMap) -> Result<Comparison, MapsError> {
    if a.config.x != b.config.x || a.config.y != b.config.y || a.cells.len() != b.cells.len() {
        return Err(MapsError::Invalid(format!(
            "maps {} and {} are not on the same grid",
            a.label, b.label
        )));
    }
    let mut c = Comparison::default();
    for (ca, cb) in a.cells.iter().zip(&b.cells) {
        match (ca.rotates(), cb.rotates()) {
            (true, false) => c.only_a.push((ca.ix, ca.iy)),
            (false, true) => c.only_b.push((ca.ix, ca.iy)),
            (true, true) => c.both += 1,
            (false, false) => c.neither += 1,
        }
    }
    Ok(c)
}

/// The two maps' rotation fractions side by side; on each, a dot marks the cells where that
/// model rotates and the other does not.
pub fn plot_comparison(a: &ZoneMap, b: &ZoneMap, path: &Path) -> Result<Comparison, MapsError> {
    let cmp = compare(a, b)?;
    let maps = [
        a.heatmap(a.describe(), cmp.only_a.clone()),
        b.heatmap(b.describe(), cmp.only_b.clone()),
    ];
    save_heatmaps_side_by_side(
        &maps,
        &format!(
            "Rotation zones, {} vs {} ({} starts per cell). Dots: this model rotates, the other does not ({} cells {}, {} cells {})",
            a.label,
            b.label,
            a.config.starts.len(),
            cmp.only_a.len(),
            a.label,
            cmp.only_b.len(),
            b.label
        ),
        path,
    )?;
    Ok(cmp)
}

/// The maps as one table: a row per (model, cell). With two maps, `disagree` marks the cells
/// where exactly one of them rotates.
pub fn columns(maps: &[ZoneMap]) -> Result<Vec<Column>, MapsError> {
    let Some(first) = maps.first() else {
        return Err(MapsError::Invalid("no maps to write".into()));
    };
    let disagree: Option<Vec<(usize, usize)>> = match maps {
        [a, b] => Some(compare(a, b)?.disagree()),
        _ => None,
    };
    let (xp, yp) = (first.config.x.param, first.config.y.param);
    let mut model = Vec::new();
    let (mut x, mut y) = (Vec::new(), Vec::new());
    let mut starts = Vec::new();
    let mut frac = Vec::new();
    let mut per_class: [Vec<f64>; 5] = Default::default();
    let mut speed = Vec::new();
    let mut power = Vec::new();
    let mut load_sd = Vec::new();
    let mut dis = Vec::new();
    for m in maps {
        if m.config.x.param != xp || m.config.y.param != yp {
            return Err(MapsError::Invalid(format!(
                "map {} sweeps other parameters than {}",
                m.label, first.label
            )));
        }
        for c in &m.cells {
            model.push(m.label.clone());
            x.push(c.x);
            y.push(c.y);
            starts.push(c.starts as i64);
            frac.push(c.rotation_fraction());
            for (k, cl) in SteadyClass::ALL.iter().enumerate() {
                per_class[k].push(c.fraction(*cl));
            }
            speed.push(c.mean_rotation_speed);
            power.push(c.mean_power_w);
            load_sd.push(c.load_power_sd_w);
            if let Some(d) = &disagree {
                dis.push(d.binary_search(&(c.ix, c.iy)).is_ok());
            }
        }
    }
    let mut cols = vec![
        Column::new("model", ColumnData::Str(model)),
        Column::f64(xp.name(), "1", x).describe(xp.label()),
        Column::f64(yp.name(), "1", y).describe(yp.label()),
        Column::new("starts", ColumnData::I64(starts)).describe("initial states simulated"),
        Column::f64("rotation_fraction", "1", frac)
            .describe("fraction of starts ending in rotation (either direction)"),
    ];
    for (k, cl) in SteadyClass::ALL.iter().enumerate() {
        cols.push(
            Column::f64(
                &format!("{}_fraction", cl.as_str()),
                "1",
                std::mem::take(&mut per_class[k]),
            )
            .describe("fraction of starts ending in this class"),
        );
    }
    cols.push(
        Column::f64("mean_rotation_speed", "1 (dθ/dt)", speed)
            .describe("mean |dθ/dt| of the rotating starts, dimensionless; NaN if none"),
    );
    cols.extend(crate::power::columns(
        &power,
        "mean over the cell's starts of the ",
    ));
    cols.push(
        Column::f64("load_power_sd_w", "W", load_sd)
            .describe("standard deviation over the cell's starts of the mean power into the load, W (its standard error: divide by √starts)"),
    );
    if disagree.is_some() {
        cols.push(
            Column::new("disagree", ColumnData::Bool(dis))
                .describe("exactly one of the two models rotates in this cell"),
        );
    }
    Ok(cols)
}

/// The table's key-value metadata: the grid's description, the models' parameters, `extra`.
pub fn metadata(
    maps: &[ZoneMap],
    extra: &[(String, String)],
) -> Result<Vec<(String, String)>, MapsError> {
    let Some(first) = maps.first() else {
        return Err(MapsError::Invalid("no maps to write".into()));
    };
    let c = &first.config;
    let mut md = vec![
        ("x".to_string(), c.x.describe()),
        ("y".to_string(), c.y.describe()),
        ("starts".to_string(), c.starts.len().to_string()),
        (
            "transient_periods".to_string(),
            c.transient_periods.to_string(),
        ),
        ("record_periods".to_string(), c.record_periods.to_string()),
        ("tol".to_string(), c.sim.rtol.to_string()),
        ("power_scale_w".to_string(), c.power_scale_w.to_string()),
    ];
    for m in maps {
        md.push((
            format!("params.{}", m.label),
            serde_json::to_string(&m.base).unwrap_or_default(),
        ));
    }
    md.extend(extra.iter().cloned());
    Ok(md)
}

/// Writes [`columns`] to Parquet with [`metadata`] (the grid's description and `extra`).
pub fn write_parquet(
    maps: &[ZoneMap],
    path: &Path,
    extra: &[(String, String)],
) -> Result<TableSummary, MapsError> {
    let cols = columns(maps)?;
    let mut opts = TableOptions::new();
    for (k, v) in metadata(maps, extra)? {
        opts = opts.meta(&k, v);
    }
    Ok(opts.write(path, &cols)?)
}

/// Merges the shards of a zones run ([`crate::shard::read_shards`]): the table, the shards' rows
/// in the one-machine order (model by model, cell by cell), and the maps rebuilt from them for
/// the figures and summaries. Each cell's class counts are recovered from its fractions and
/// checked to give them back bit for bit.
pub fn merge_shards(
    models: &[(String, Dimensionless)],
    cfg: &ZoneConfig,
    set: &crate::shard::ShardSet,
) -> Result<(Vec<ZoneMap>, Vec<Column>), MapsError> {
    use crate::shard::col;
    cfg.validate(models)?;
    let total = cfg.cells();
    set.check_cells(total, "the map")?;
    let owner = set.cell_owner();
    let (nx, ns) = (cfg.x.len(), cfg.starts.len());
    let mut order = Vec::with_capacity(models.len() * total);
    let mut maps = Vec::with_capacity(models.len());
    for (mi, (label, base)) in models.iter().enumerate() {
        let mut cells = Vec::with_capacity(total);
        for (c, &(s, j)) in owner.iter().enumerate() {
            if s == usize::MAX {
                return Err(MapsError::Invalid(format!("no shard holds cell {c}")));
            }
            let m = &set.manifests[s];
            let r = mi * m.cells.len() + j;
            let part = &set.parts[s];
            let (
                ColumnData::Str(model),
                ColumnData::I64(starts),
                ColumnData::F64(speed),
                ColumnData::F64(rot),
            ) = (
                col(part, "model")?,
                col(part, "starts")?,
                col(part, "mean_rotation_speed")?,
                col(part, "rotation_fraction")?,
            )
            else {
                return Err(MapsError::Invalid(
                    "the shard tables' columns are not of the zones table's types".into(),
                ));
            };
            if r >= model.len() || model[r] != *label || starts[r] != ns as i64 {
                return Err(MapsError::Invalid(format!(
                    "shard {}: row {r} is not model {label}'s cell {c} with {ns} starts",
                    m.shard
                )));
            }
            let mut counts = [0usize; 5];
            for (k, cl) in SteadyClass::ALL.iter().enumerate() {
                let ColumnData::F64(f) = col(part, &format!("{}_fraction", cl.as_str()))? else {
                    return Err(MapsError::Invalid("a fraction column is not f64".into()));
                };
                counts[k] = (f[r] * ns as f64).round() as usize;
            }
            let cell = ZoneCell {
                ix: c % nx,
                iy: c / nx,
                x: cfg.x.values[c % nx],
                y: cfg.y.values[c / nx],
                counts,
                starts: ns,
                mean_rotation_speed: speed[r],
                mean_power_w: crate::power::read_row(part, r)?,
                load_power_sd_w: match col(part, "load_power_sd_w")? {
                    ColumnData::F64(v) => v[r],
                    _ => {
                        return Err(MapsError::Invalid(
                            "column load_power_sd_w is not f64".into(),
                        ))
                    }
                },
            };
            let same = SteadyClass::ALL.iter().all(|cl| {
                matches!(col(part, &format!("{}_fraction", cl.as_str())),
                    Ok(ColumnData::F64(f)) if f[r].to_bits() == cell.fraction(*cl).to_bits())
            }) && rot[r].to_bits() == cell.rotation_fraction().to_bits();
            if !same {
                return Err(MapsError::Invalid(format!(
                    "shard {}: row {r}'s fractions are not counts out of {ns} starts",
                    m.shard
                )));
            }
            cells.push(cell);
            order.push((s, r));
        }
        maps.push(ZoneMap {
            label: label.clone(),
            base: *base,
            config: cfg.clone(),
            cells,
        });
    }
    let columns = crate::shard::gather(&set.parts, &order)?;
    Ok((maps, columns))
}
