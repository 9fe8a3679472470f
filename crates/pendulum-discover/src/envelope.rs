//! The free segments before the shakers start, read as free decays: each run's envelope
//! (turning points, loss per cycle against amplitude) and the losses pooled over runs. The
//! report shows them; discovery asks the identify runs' pooled losses as one more view of a
//! loss's size where the forced windows cannot see it.

use pendulum_process::pipeline::Context;
use pendulum_process::Role;

/// Shortest free segment whose envelope is read, s (about three swings).
pub const ENVELOPE_MIN_S: f64 = 2.5;

/// A run's free-decay segment (before its shaker starts) and its envelope.
#[derive(Debug, Clone)]
pub struct SegmentEnvelope {
    pub run: String,
    pub role: Role,
    pub env: Result<pendulum_explain::EnvelopeFit, String>,
}

/// The envelope of every run's free segment of at least [`ENVELOPE_MIN_S`]: the turning points'
/// amplitudes, the loss per cycle against amplitude and what its shape says (linear decay = dry
/// friction, exponential = viscous, 1/n-like = quadratic drag). A segment with too few swings
/// keeps the reason instead.
pub fn free_segment_envelopes(ctx: &Context) -> Vec<SegmentEnvelope> {
    let mut out = Vec::new();
    for run in &ctx.runs {
        let Some(al) = ctx.alignments.get(&run.id) else {
            continue;
        };
        let Some(seg) = al.free_segment_samples(run, ENVELOPE_MIN_S) else {
            continue;
        };
        let env = pendulum_explain::envelope(&run.enc_t_s[seg.clone()], &run.theta_rad[seg])
            .map_err(|e| e.to_string());
        out.push(SegmentEnvelope {
            run: run.id.clone(),
            role: run.role,
            env,
        });
    }
    out
}

/// One term of the pooled envelope fit: catalogue name, SI estimate, 95 % interval, unit.
#[derive(Debug, Clone, PartialEq)]
pub struct PooledTerm {
    pub name: &'static str,
    pub estimate: f64,
    pub ci_low: f64,
    pub ci_high: f64,
    pub unit: &'static str,
}

/// The envelopes that could be read, each with its run's rig.
pub fn envelope_fits<'a>(
    envs: &'a [SegmentEnvelope],
    ctx: &'a Context,
) -> Vec<(
    &'a pendulum_explain::EnvelopeFit,
    &'a pendulum_process::RigParams,
)> {
    envs.iter()
        .filter_map(|e| {
            let rig = &ctx.runs.iter().find(|r| r.id == e.run)?.rig;
            Some((e.env.as_ref().ok()?, rig))
        })
        .collect()
}

/// A loss term's SI parameter → the run's dimensionless one (the weak form's factors), and its
/// SI unit.
fn term_si(t: pendulum_explain::Term, rig: &pendulum_process::RigParams) -> (f64, &'static str) {
    use crate::weak::{column_of, si_factors};
    let f = si_factors(rig);
    match pendulum_model::effects::by_name(t.name()) {
        Some(e) => (
            column_of(e.name()).map_or(f64::NAN, |c| f[c]),
            e.size_unit(),
        ),
        // κ = k/(m g l): a torque per radian (no catalogue effect), scaled as the torques are.
        None => (
            column_of("coulomb_constant").map_or(f64::NAN, |c| f[c]),
            "N·m/rad",
        ),
    }
}

/// The loss per cycle of every run's free segment, pooled (a 4 s segment alone has 5–7 cycles,
/// too few to tell the terms apart), as a non-negative sum of the catalogue's exact pendulum loss
/// curves: the subset with the lowest BIC whose every term's 95 % interval excludes zero. Each
/// run's curves carry its own SI factors (as the weak form's columns do), so a campaign that
/// mixes bobs pools one SI parameter per term, not dimensionless ones that differ by bob. Empty
/// with fewer than 8 cycles.
pub fn pooled_envelope(
    envs: &[(&pendulum_explain::EnvelopeFit, &pendulum_process::RigParams)],
) -> Vec<PooledTerm> {
    use pendulum_explain::Term;
    let pts: Vec<(f64, f64, &pendulum_process::RigParams)> = envs
        .iter()
        .flat_map(|(e, rig)| e.rows.iter().map(move |r| (r, *rig)))
        .filter_map(|(r, rig)| Some((r.mid_amplitude_rad?, r.loss_per_cycle_rad?, rig)))
        .filter(|(a, l, _)| a.is_finite() && l.is_finite())
        .collect();
    if pts.len() < 8 {
        return Vec::new();
    }
    let y: Vec<f64> = pts.iter().map(|p| p.1).collect();
    let mut best: Option<(f64, Vec<PooledTerm>)> = None;
    for mask in 1u32..(1 << Term::ALL.len()) {
        let sub: Vec<Term> = (0..Term::ALL.len())
            .filter(|j| mask & (1 << j) != 0)
            .map(|j| Term::ALL[j])
            .collect();
        let x: Vec<Vec<f64>> = pts
            .iter()
            .map(|p| {
                sub.iter()
                    .map(|t| t.loss_per_cycle(p.0) * term_si(*t, p.2).0)
                    .collect()
            })
            .collect();
        // A term whose SI factor is unknown for some run (r_b not given: the bearing load) is
        // not pooled.
        if x.iter().flatten().any(|v| !v.is_finite()) {
            continue;
        }
        let Ok(fit) = pendulum_numerics::ols(&x, &y) else {
            continue;
        };
        let (b, cov) = (&fit.coef, &fit.cov);
        let m = sub.len();
        let terms: Vec<PooledTerm> = sub
            .iter()
            .enumerate()
            .map(|(q, t)| {
                let half = 1.96 * cov[q * m + q].max(0.0).sqrt();
                PooledTerm {
                    name: t.name(),
                    estimate: b[q],
                    ci_low: b[q] - half,
                    ci_high: b[q] + half,
                    unit: term_si(*t, pts[0].2).1,
                }
            })
            .collect();
        if terms.iter().any(|t| t.ci_low <= 0.0) {
            continue;
        }
        let bic = pendulum_numerics::bic(fit.rss, pts.len(), m);
        if best.as_ref().is_none_or(|(s, _)| bic < *s) {
            best = Some((bic, terms));
        }
    }
    best.map(|b| b.1).unwrap_or_default()
}
