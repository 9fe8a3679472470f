//! Bifurcation diagrams: one parameter swept, the Poincaré points (one per forcing period,
//! at t = k·T, the acceleration peak of the crank) after a transient, classified.
//!
//! [`Mode::Grid`]: every sweep value from every initial state (independent simulations).
//! [`Mode::Continuation`]: from each initial state, the sweep is walked up (first value to
//! last) and down (last to first); each value starts from the last Poincaré point the previous
//! value reached, so the diagram follows attractors as they persist and shows hysteresis.

use std::path::Path;

use pendulum_model::{
    ClassifyOptions, Dimensionless, MeanPowers, Model, SimOptions, SteadyClass, SteadyState,
};
use pendulum_plot::{CategoryScatter, Figure, Panel, Series, SeriesStyle};
use pendulum_report::{Column, ColumnData, TableOptions, TableSummary};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::style::{class_color, class_palette_index, describe_params, draw_index, DRAW_ORDER};
use crate::sweep::{Sweep, SweepParam};
use crate::{class_index, with_pool, wrap_pi, MapsError};

/// How the initial states are used along the sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Mode {
    /// Every value from every initial state.
    Grid,
    /// Each initial state starts a chain swept up and one swept down.
    Continuation,
}

/// Which way a result was reached.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Direction {
    /// Grid mode (no direction).
    Grid,
    /// Continuation from the first sweep value to the last.
    Up,
    /// Continuation from the last sweep value to the first.
    Down,
}

impl Direction {
    pub fn as_str(self) -> &'static str {
        match self {
            Direction::Grid => "grid",
            Direction::Up => "up",
            Direction::Down => "down",
        }
    }
}

/// What to sweep and how.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BifurcationConfig {
    /// The model's parameters; the swept one is replaced by each sweep value.
    pub base: Dimensionless,
    pub sweep: Sweep,
    /// Initial states (θ0 rad, θ̇0 dimensionless); chain starts in continuation mode.
    pub starts: Vec<[f64; 2]>,
    pub mode: Mode,
    /// Forcing periods simulated before recording.
    pub transient_periods: u32,
    /// Forcing periods recorded (record + 1 Poincaré points, k = 0..=record).
    pub record_periods: u32,
    pub sim: SimOptions,
    pub classify: ClassifyOptions,
    /// Worker threads; `None` = rayon's global pool.
    pub threads: Option<usize>,
    /// m g l ω0 of the rig, W: the mean powers' unit (dimensionless powers times it).
    #[serde(default = "crate::power::default_scale_w")]
    pub power_scale_w: f64,
}

impl BifurcationConfig {
    /// Defaults: grid mode, 300 transient and 50 recorded periods, tolerance 1e-8.
    pub fn new(base: Dimensionless, sweep: Sweep, starts: Vec<[f64; 2]>) -> Self {
        Self {
            base,
            sweep,
            starts,
            mode: Mode::Grid,
            transient_periods: 300,
            record_periods: 50,
            sim: SimOptions::with_tol(1e-8),
            classify: ClassifyOptions::default(),
            threads: None,
            power_scale_w: crate::power::default_scale_w(),
        }
    }

    /// Number of simulations (the progress total).
    pub fn tasks(&self) -> u64 {
        let n = (self.sweep.len() * self.starts.len()) as u64;
        match self.mode {
            Mode::Grid => n,
            Mode::Continuation => 2 * n,
        }
    }

    /// Cells: the units a sharded run deals out ([`crate::shard`]), in table order. Grid mode:
    /// one (value, start) simulation, cell `v·starts + i`; continuation: one chain, cell
    /// `2·i + d` (d = 0 up, 1 down), each of `values` simulations.
    pub fn cells(&self) -> usize {
        match self.mode {
            Mode::Grid => self.sweep.len() * self.starts.len(),
            Mode::Continuation => 2 * self.starts.len(),
        }
    }

    /// What one cell is, in words.
    pub fn cell_description(&self) -> &'static str {
        match self.mode {
            Mode::Grid => "one (sweep value, start) simulation; cell = value_index·starts + ic",
            Mode::Continuation => {
                "one continuation chain (a start swept up or down); cell = 2·ic + (0 up, 1 down)"
            }
        }
    }

    /// The simulations of a cell, in table order: (value index, start index, direction).
    fn cell_outcomes(&self, cell: usize) -> Vec<(usize, usize, Direction)> {
        let (nv, ns) = (self.sweep.len(), self.starts.len());
        match self.mode {
            Mode::Grid => vec![(cell / ns, cell % ns, Direction::Grid)],
            Mode::Continuation => {
                let (i, dir) = (
                    cell / 2,
                    if cell.is_multiple_of(2) {
                        Direction::Up
                    } else {
                        Direction::Down
                    },
                );
                (0..nv)
                    .map(|step| {
                        let v = if dir == Direction::Up {
                            step
                        } else {
                            nv - 1 - step
                        };
                        (v, i, dir)
                    })
                    .collect()
            }
        }
    }

    pub fn validate(&self) -> Result<(), MapsError> {
        if self.sweep.is_empty() {
            return Err(MapsError::Invalid("the sweep has no values".into()));
        }
        crate::ics::check_starts(&self.starts, self.record_periods)?;
        if !(self.power_scale_w.is_finite() && self.power_scale_w > 0.0) {
            return Err(MapsError::Invalid(format!(
                "power scale {} W: expected m g l ω0 > 0",
                self.power_scale_w
            )));
        }
        for i in 0..self.sweep.len() {
            let d = self.sweep.apply(&self.base, i);
            d.validate()?;
            if d.omega <= 0.0 {
                return Err(MapsError::Invalid(format!(
                    "omega = {} at sweep value {}: a Poincaré section needs forcing (omega > 0)",
                    d.omega, self.sweep.values[i]
                )));
            }
        }
        Ok(())
    }
}

/// One simulation's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// Index into the sweep's values, and the value.
    pub value_index: usize,
    pub value: f64,
    /// Index of the initial state (grid) or of the chain's start (continuation).
    pub ic: usize,
    pub direction: Direction,
    /// The state this simulation started from.
    pub start: [f64; 2],
    pub steady: SteadyState,
    /// Poincaré points, θ unwrapped (rad) and θ̇ (dimensionless), k = 0..=record.
    pub theta: Vec<f64>,
    pub theta_dot: Vec<f64>,
    /// Mean powers over the recorded periods, W ([`crate::power`]).
    pub power_w: MeanPowers,
}

/// A finished sweep.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bifurcation {
    pub config: BifurcationConfig,
    /// In a fixed order: grid mode by (value, ic); continuation by (ic, direction, step).
    pub outcomes: Vec<Outcome>,
}

fn simulate_one(
    cfg: &BifurcationConfig,
    value_index: usize,
    ic: usize,
    direction: Direction,
    start: [f64; 2],
) -> Result<Outcome, MapsError> {
    let d = cfg.sweep.apply(&cfg.base, value_index);
    let model = Model::new(d);
    let (steady, theta, theta_dot, power_w) = crate::power::steady_with_power(
        &model,
        &cfg.sim,
        start,
        cfg.transient_periods,
        cfg.record_periods,
        &cfg.classify,
        cfg.power_scale_w,
    )?;
    Ok(Outcome {
        value_index,
        value: cfg.sweep.values[value_index],
        ic,
        direction,
        start,
        steady,
        theta,
        theta_dot,
        power_w,
    })
}

/// Runs the sweep. `progress` is called with the number of simulations finished (1 at a time,
/// from the worker threads).
pub fn run(
    cfg: &BifurcationConfig,
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Bifurcation, MapsError> {
    let all: Vec<usize> = (0..cfg.cells()).collect();
    run_cells(cfg, &all, progress)
}

/// Runs the given cells ([`BifurcationConfig::cells`], ascending) of the sweep: the outcomes are
/// those of [`run`] for these cells, in the same order (a shard's share of the map).
pub fn run_cells(
    cfg: &BifurcationConfig,
    cells: &[usize],
    progress: &(dyn Fn(u64) + Sync),
) -> Result<Bifurcation, MapsError> {
    cfg.validate()?;
    let total = cfg.cells();
    if let Some(&bad) = cells.iter().find(|&&c| c >= total) {
        return Err(MapsError::Invalid(format!(
            "cell {bad} is beyond the sweep's {total} cells"
        )));
    }
    let nv = cfg.sweep.len();
    let ns = cfg.starts.len();
    let outcomes = with_pool(cfg.threads, || -> Result<Vec<Outcome>, MapsError> {
        match cfg.mode {
            Mode::Grid => cells
                .par_iter()
                .map(|&c| {
                    let (v, i) = (c / ns, c % ns);
                    let o = simulate_one(cfg, v, i, Direction::Grid, cfg.starts[i]);
                    progress(1);
                    o
                })
                .collect(),
            Mode::Continuation => {
                let per_chain: Vec<Vec<Outcome>> = cells
                    .par_iter()
                    .map(|&c| {
                        let (i, dir) = (
                            c / 2,
                            if c.is_multiple_of(2) {
                                Direction::Up
                            } else {
                                Direction::Down
                            },
                        );
                        let mut y = cfg.starts[i];
                        let mut out = Vec::with_capacity(nv);
                        for step in 0..nv {
                            let v = if dir == Direction::Up {
                                step
                            } else {
                                nv - 1 - step
                            };
                            let o = simulate_one(cfg, v, i, dir, y)?;
                            progress(1);
                            if let (Some(&th), Some(&w)) = (o.theta.last(), o.theta_dot.last()) {
                                y = [wrap_pi(th), w];
                            }
                            out.push(o);
                        }
                        Ok(out)
                    })
                    .collect::<Result<_, MapsError>>()?;
                Ok(per_chain.into_iter().flatten().collect())
            }
        }
    })??;
    Ok(Bifurcation {
        config: cfg.clone(),
        outcomes,
    })
}

/// Merges the shards of a sweep ([`crate::shard::read_shards`]): the table, the shards' rows in
/// the one-machine order (byte for byte the values [`Bifurcation::columns`] gives), and the
/// sweep rebuilt from them for the figures and summaries. The rebuilt outcomes hold θ wrapped
/// to [−π, π) as the table does (the figures use θ̇ alone).
pub fn merge_shards(
    cfg: &BifurcationConfig,
    set: &crate::shard::ShardSet,
) -> Result<(Bifurcation, Vec<Column>), MapsError> {
    use crate::shard::col;
    cfg.validate()?;
    set.check_cells(cfg.cells(), "the sweep")?;
    // Each part's rows split into outcomes (a new one starts at k = 0), grouped by cell.
    // Per cell: the shard holding it and its simulations' row ranges in that shard's table.
    type CellRows = Option<(usize, Vec<(usize, usize)>)>;
    let mut cell_rows: Vec<CellRows> = vec![None; cfg.cells()];
    for (s, (m, part)) in set.manifests.iter().zip(&set.parts).enumerate() {
        let ColumnData::I64(k) = col(part, "k")? else {
            return Err(MapsError::Invalid("column k is not an integer".into()));
        };
        let mut starts: Vec<usize> = (0..k.len()).filter(|&r| k[r] == 0).collect();
        starts.push(k.len());
        let outcomes: Vec<(usize, usize)> = starts.windows(2).map(|w| (w[0], w[1])).collect();
        let per_cell = match cfg.mode {
            Mode::Grid => 1,
            Mode::Continuation => cfg.sweep.len(),
        };
        if outcomes.len() != m.cells.len() * per_cell || starts[0] != 0 && !k.is_empty() {
            return Err(MapsError::Invalid(format!(
                "shard {}: {} simulations in its table, {} expected for its {} cells",
                m.shard,
                outcomes.len(),
                m.cells.len() * per_cell,
                m.cells.len()
            )));
        }
        for (j, &c) in m.cells.iter().enumerate() {
            cell_rows[c] = Some((s, outcomes[j * per_cell..(j + 1) * per_cell].to_vec()));
        }
    }
    let mut order = Vec::new();
    let mut outcomes = Vec::new();
    for (c, entry) in cell_rows.iter().enumerate() {
        let Some((s, ranges)) = entry else {
            return Err(MapsError::Invalid(format!("no shard holds cell {c}")));
        };
        let part = &set.parts[*s];
        let (
            ColumnData::I64(ic),
            ColumnData::Str(dir),
            ColumnData::F64(th0),
            ColumnData::F64(w0),
            ColumnData::F64(th),
            ColumnData::F64(w),
            ColumnData::Str(class),
            ColumnData::I64(period),
            ColumnData::F64(speed),
        ) = (
            col(part, "ic")?,
            col(part, "direction")?,
            col(part, "theta0")?,
            col(part, "theta_dot0")?,
            col(part, "theta")?,
            col(part, "theta_dot")?,
            col(part, "class")?,
            col(part, "period")?,
            col(part, "mean_theta_dot")?,
        )
        else {
            return Err(MapsError::Invalid(
                "the shard tables' columns are not of the bifurcation table's types".into(),
            ));
        };
        for (&(r0, r1), (v, i, d)) in ranges.iter().zip(cfg.cell_outcomes(c)) {
            if ic[r0] != i as i64 || dir[r0] != d.as_str() {
                return Err(MapsError::Invalid(format!(
                    "shard {}: row {r0} is start {} ({}), cell {c} expects start {i} ({})",
                    set.manifests[*s].shard,
                    ic[r0],
                    dir[r0],
                    d.as_str()
                )));
            }
            let class_of = SteadyClass::ALL
                .into_iter()
                .find(|k| k.as_str() == class[r0])
                .ok_or_else(|| {
                    MapsError::Invalid(format!("unknown steady class {:?}", class[r0]))
                })?;
            outcomes.push(Outcome {
                value_index: v,
                value: cfg.sweep.values[v],
                ic: i,
                direction: d,
                start: [th0[r0], w0[r0]],
                steady: SteadyState {
                    class: class_of,
                    period: u32::try_from(period[r0]).unwrap_or(0),
                    mean_theta_dot: speed[r0],
                },
                theta: th[r0..r1].to_vec(),
                theta_dot: w[r0..r1].to_vec(),
                power_w: crate::power::read_row(part, r0)?,
            });
            order.extend((r0..r1).map(|r| (*s, r)));
        }
    }
    let columns = crate::shard::gather(&set.parts, &order)?;
    Ok((
        Bifurcation {
            config: cfg.clone(),
            outcomes,
        },
        columns,
    ))
}

/// 1400 px, wider when the title would not fit (about 14 px per character at that size).
fn figure_width(title: &str) -> u32 {
    1400.max(title.chars().count() as u32 * 14 + 80).min(4000)
}

/// Class counts at one sweep value.
#[derive(Debug, Clone, PartialEq)]
pub struct ValueSummary {
    pub value: f64,
    /// Simulations per class, in [`SteadyClass::ALL`] order.
    pub counts: [usize; 5],
    pub total: usize,
    /// Rotation periods seen (sorted, distinct).
    pub rotation_periods: Vec<u32>,
}

impl ValueSummary {
    pub fn fraction(&self, c: SteadyClass) -> f64 {
        if self.total == 0 {
            0.0
        } else {
            self.counts[class_index(c)] as f64 / self.total as f64
        }
    }

    /// Fraction of simulations ending in rotation (either way).
    pub fn rotation_fraction(&self) -> f64 {
        self.fraction(SteadyClass::RotationCcw) + self.fraction(SteadyClass::RotationCw)
    }
}

impl Bifurcation {
    /// Per sweep value (in sweep order), the classes reached by the outcomes of `direction`
    /// (`None` = all).
    pub fn summary(&self, direction: Option<Direction>) -> Vec<ValueSummary> {
        let mut out: Vec<ValueSummary> = self
            .config
            .sweep
            .values
            .iter()
            .map(|&value| ValueSummary {
                value,
                counts: [0; 5],
                total: 0,
                rotation_periods: Vec::new(),
            })
            .collect();
        for o in &self.outcomes {
            if direction.is_some_and(|d| d != o.direction) {
                continue;
            }
            let s = &mut out[o.value_index];
            s.counts[class_index(o.steady.class)] += 1;
            s.total += 1;
            if o.steady.class.is_rotation() && !s.rotation_periods.contains(&o.steady.period) {
                s.rotation_periods.push(o.steady.period);
            }
        }
        for s in &mut out {
            s.rotation_periods.sort_unstable();
        }
        out
    }

    /// The Poincaré table: one row per recorded point.
    pub fn columns(&self) -> Vec<Column> {
        let p = self.config.sweep.param;
        let n: usize = self.outcomes.iter().map(|o| o.theta.len()).sum();
        let mut value = Vec::with_capacity(n);
        let mut omega = Vec::with_capacity(n);
        let mut ic = Vec::with_capacity(n);
        let mut dir = Vec::with_capacity(n);
        let mut th0 = Vec::with_capacity(n);
        let mut w0 = Vec::with_capacity(n);
        let mut k = Vec::with_capacity(n);
        let mut th = Vec::with_capacity(n);
        let mut w = Vec::with_capacity(n);
        let mut class = Vec::with_capacity(n);
        let mut period = Vec::with_capacity(n);
        let mut speed = Vec::with_capacity(n);
        let mut power = Vec::with_capacity(n);
        for o in &self.outcomes {
            let om = self
                .config
                .sweep
                .apply(&self.config.base, o.value_index)
                .omega;
            for (kk, (&t, &wd)) in o.theta.iter().zip(&o.theta_dot).enumerate() {
                value.push(o.value);
                omega.push(om);
                ic.push(o.ic as i64);
                dir.push(o.direction.as_str().to_string());
                th0.push(o.start[0]);
                w0.push(o.start[1]);
                k.push(kk as i64);
                th.push(wrap_pi(t));
                w.push(wd);
                class.push(o.steady.class.as_str().to_string());
                period.push(i64::from(o.steady.period));
                speed.push(o.steady.mean_theta_dot);
                power.push(o.power_w);
            }
        }
        let mut cols = vec![Column::f64("omega", "1 (ω/ω0)", omega)
            .describe("dimensionless forcing frequency ω = 2πΩ/ω0")];
        if p != SweepParam::Omega {
            cols.push(Column::f64(p.name(), "1", value).describe("the swept parameter"));
        }
        cols.extend([
            Column::new("ic", ColumnData::I64(ic))
                .describe("index of the initial state (of the chain's start in continuation)"),
            Column::new("direction", ColumnData::Str(dir))
                .describe("grid, or up / down for continuation"),
            Column::f64("theta0", "rad", th0)
                .describe("angle this simulation started from (wrapped)"),
            Column::f64("theta_dot0", "1 (dθ/dt)", w0)
                .describe("dimensionless angular velocity this simulation started from"),
            Column::new("k", ColumnData::I64(k))
                .describe("Poincaré point index after the transient (t = (transient + k)·T)"),
            Column::f64("theta", "rad", th)
                .describe("angle at the Poincaré point, wrapped to [−π, π)"),
            Column::f64("theta_dot", "1 (dθ/dt)", w)
                .describe("dimensionless angular velocity at the Poincaré point"),
            Column::new("class", ColumnData::Str(class))
                .describe("steady state: rest, oscillation, rotation_ccw, rotation_cw, chaos"),
            Column::new("period", ColumnData::I64(period))
                .describe("period in forcing periods (0 for rest and chaos)"),
            Column::f64("mean_theta_dot", "1 (dθ/dt)", speed)
                .describe("mean dimensionless rotation speed (0 for rest and oscillation)"),
        ]);
        // Per start (repeated on each of its Poincaré rows, like its class).
        cols.extend(crate::power::columns(&power, "per start: "));
        cols
    }

    /// Key-value metadata describing the sweep.
    pub fn metadata(&self) -> Vec<(String, String)> {
        let c = &self.config;
        vec![
            ("sweep".into(), c.sweep.describe()),
            ("sweep_param".into(), c.sweep.param.name().into()),
            (
                "mode".into(),
                match c.mode {
                    Mode::Grid => "grid",
                    Mode::Continuation => "continuation",
                }
                .into(),
            ),
            ("starts".into(), c.starts.len().to_string()),
            ("transient_periods".into(), c.transient_periods.to_string()),
            ("record_periods".into(), c.record_periods.to_string()),
            ("tol".into(), c.sim.rtol.to_string()),
            ("power_scale_w".into(), c.power_scale_w.to_string()),
            (
                "params".into(),
                serde_json::to_string(&c.base).unwrap_or_default(),
            ),
        ]
    }

    /// Writes the Poincaré table to Parquet, with [`Bifurcation::metadata`] plus `extra`.
    pub fn write_parquet(
        &self,
        path: &Path,
        extra: &[(String, String)],
    ) -> Result<TableSummary, MapsError> {
        let mut opts = TableOptions::new();
        for (k, v) in self.metadata().iter().chain(extra) {
            opts = opts.meta(k, v.clone());
        }
        Ok(opts.write(path, &self.columns())?)
    }

    /// The diagram: θ̇ at the Poincaré points against the swept value, coloured by class.
    /// Points that would land on the same spot (a rest point recorded 51 times, a periodic
    /// orbit's repeats, the same attractor reached from many starts) are drawn once, so the
    /// figure stays light enough for dots that are easy to see.
    pub fn plot(&self, path: &Path, title: &str) -> Result<(), MapsError> {
        let (lo, hi) = self
            .outcomes
            .iter()
            .flat_map(|o| o.theta_dot.iter().copied())
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        let dy = if hi > lo { (hi - lo) / 1500.0 } else { 1.0 };
        let mut seen = std::collections::HashSet::new();
        let mut x = Vec::new();
        let mut y = Vec::new();
        let mut cat = Vec::new();
        let mut sims = [0usize; 5];
        for o in &self.outcomes {
            let c = draw_index(o.steady.class);
            sims[c] += 1;
            for &w in &o.theta_dot {
                if !w.is_finite() || !seen.insert((o.value_index, (w / dy).round() as i64, c)) {
                    continue;
                }
                x.push(o.value);
                y.push(w);
                cat.push(c);
            }
        }
        let total: usize = sims.iter().sum();
        let p = self.config.sweep.param;
        CategoryScatter {
            title: title.to_string(),
            x_label: p.label().to_string(),
            y_label: "dθ/dt at the Poincaré section (t = kT)".to_string(),
            x,
            y,
            category: cat,
            category_names: DRAW_ORDER
                .iter()
                .zip(sims)
                .map(|(c, n)| format!("{} ({n} of {total})", c.as_str()))
                .collect(),
            category_colors: Some(DRAW_ORDER.iter().map(|c| class_color(*c)).collect()),
            width: figure_width(title),
            height: 800,
        }
        .save_png(path)?;
        Ok(())
    }

    /// Percentage of simulations ending in rotation (either way), oscillation, rest and chaos
    /// against the swept value.
    pub fn plot_fractions(&self, path: &Path, title: &str) -> Result<(), MapsError> {
        let s = self.summary(None);
        let x: Vec<f64> = s.iter().map(|v| v.value).collect();
        let style = if x.len() > 60 {
            SeriesStyle::Line
        } else {
            SeriesStyle::LinePoints
        };
        let mut series = vec![Series {
            label: "rotation (either way)".to_string(),
            x: x.clone(),
            y: s.iter().map(|v| 100.0 * v.rotation_fraction()).collect(),
            style,
            color: Some(class_palette_index(SteadyClass::RotationCcw)),
        }];
        for c in [
            SteadyClass::Oscillation,
            SteadyClass::Rest,
            SteadyClass::Chaos,
        ] {
            series.push(Series {
                label: c.as_str().to_string(),
                x: x.clone(),
                y: s.iter().map(|v| 100.0 * v.fraction(c)).collect(),
                style,
                color: Some(class_palette_index(c)),
            });
        }
        // Rotation drawn last, on top.
        series.rotate_left(1);
        Figure {
            title: title.to_string(),
            panels: vec![Panel {
                title: String::new(),
                x_label: self.config.sweep.param.label().to_string(),
                y_label: "simulations ending in the class (%)".to_string(),
                series,
                log_y: false,
                y_range: Some((0.0, 100.0)),
            }],
            width: figure_width(title),
            height: 600,
        }
        .save_png(path)?;
        Ok(())
    }

    /// A title like the study's figures: the model's parameters and the sweep settings.
    pub fn default_title(&self, label: &str) -> String {
        let c = &self.config;
        let mode = match c.mode {
            Mode::Grid => format!("{} starts", c.starts.len()),
            Mode::Continuation => {
                format!("continued up and down from {} starts", c.starts.len())
            }
        };
        format!(
            "{}{}: {} ({mode}, {} + {} periods)",
            label,
            if label.is_empty() { "" } else { " model" },
            describe_params(&c.base, Some(c.sweep.param.name())),
            c.transient_periods,
            c.record_periods
        )
    }
}
