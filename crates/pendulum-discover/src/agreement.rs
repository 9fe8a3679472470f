//! Whether views of one effect agree on its size: the screen's and the trajectory refit's, the
//! identify runs' rows and the validate runs' (a catalogue effect is one constant of the rig),
//! one size at every speed and in every run, and the free segments' pooled envelopes.

use crate::screen::{ols, Candidate};
use crate::weak::WeakRow;

/// Relative accuracy the product promises for an estimate; the two views of an effect must agree
/// at least this well.
pub(crate) const AGREEMENT_REL: f64 = 0.10;

/// Whether the validate runs' own estimate of a candidate's size (`heldout`, its 95 %
/// half-width `heldout_half`) puts it elsewhere than the identify runs' (`identify`,
/// `identify_half`): their intervals apart, and the two further apart than [`AGREEMENT_REL`] of
/// the identify runs' value (the accuracy promised for any estimate, so that two tight
/// intervals a few per cent apart are not a disagreement). Two independent sets of runs that
/// do not overlap on a size the catalogue says is one constant of the rig have not found that
/// constant: the departure's size follows the run.
pub(crate) fn sizes_disagree(
    identify: f64,
    identify_half: f64,
    heldout: f64,
    heldout_half: f64,
) -> bool {
    let d = (heldout - identify).abs();
    d > identify_half + heldout_half && d > AGREEMENT_REL * identify.abs()
}

/// Chance below which a candidate is refused for not holding one size at every speed
/// ([`one_size_at_every_speed`]) or in every run ([`one_size_in_every_run`]): one in a thousand
/// on either set of rows. On the every-effect survey's twenty drawn position torques of seeds
/// 28–31 (`SURVEY_DAMPING=drawn`), all named, each set's speed split p ran from 5.5e-3 (seed 30,
/// k=4, its validate rows) to 0.99. Split by run, the torques and inertias named at seed 32 ran
/// down to 1.0e-5 (a k = 3 position torque, its identify runs' amplitudes 2.95e-2 to 3.02e-2
/// N·m: their phases differ by a few counts' zeroing) and 1.6e-4 (an inertia, its validate runs'
/// sizes within 0.7 %): significant, and within the accuracy promised, which the second clause
/// of [`OneSize::refuses`] asks.
pub(crate) const ONE_SIZE_P: f64 = 1e-3;

/// The most lobes a torque of the angle may have for its size in the fast windows to be asked
/// ([`one_size_at_every_speed`]): a weak-form window (0.32 s) of a pendulum turning at 5 rad/s
/// sweeps 8 lobes of a k = 31 torque, whose column there is then a small remainder of sin kθ
/// averaged over them, at the mercy of the angle's own errors (k times an encoder count) and
/// of whatever the model misses; up to 4 lobes a window sweeps about two at that speed, and
/// an off-centre code disc, the departure the split tells apart, reads as k = 1. A hidden
/// 3.64e-2 N·m k = 31 torque beside a 7.7e-3 N·m constant dry torque (the every-effect
/// survey's pair 0 at `SURVEY_DAMPING=drawn SURVEY_SEED=33`) split at p = 8.6e-5 on its
/// identify rows, the fast windows' torque 5.0e-2 ± 1.3e-2 N·m apart from the slow ones', and
/// was refused. (The sparse description's library holds sin/cos kθ to the same k.)
pub(crate) const ONE_SIZE_AT_EVERY_SPEED_MAX_K: u32 = 4;

/// A candidate's rows split by speed ([`one_size_at_every_speed`]) or by run
/// ([`one_size_in_every_run`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct OneSize {
    /// Chow's F test: the chance of a fall as large from the groups' own sizes by chance alone.
    pub p: f64,
    /// How far apart the groups' sizes (SI) are: the fast windows' torque less the slow ones';
    /// the spread (weighted standard deviation) of the runs' own sizes.
    pub apart: f64,
    /// The standard error of the speed split's difference (NaN for the runs' spread).
    pub apart_se: f64,
}

impl OneSize {
    /// Whether the sizes differ beyond chance ([`ONE_SIZE_P`]) and by more than
    /// [`AGREEMENT_REL`] of the size named (`named`): with a precise screen, a difference
    /// of a few per cent is significant and means nothing (`i10_pair`'s 0.03 N·m k = 2 torque
    /// beside a 0.01 kg·m² inertia, its validate runs r03–r05, split at p = 2.4e-4 on its
    /// identify rows, the fast and slow torques 9.3e-4 N·m apart, 3 % of its size, while both
    /// sets of runs put it within 0.5 % of the truth).
    pub fn refuses(&self, named: f64) -> bool {
        self.p < ONE_SIZE_P && self.apart > AGREEMENT_REL * named.abs()
    }
}

/// Chow's F test of one size at every speed: how often columns `c.add` (a candidate's), given a
/// second size of their own in the windows where the pendulum moves fast (|θ̇| at the window's
/// centre above the rows' median), would take as much off the rows' weighted equation error as
/// they do by chance alone, the other `cols` shared by both halves (`c.add.len()` degrees of
/// freedom); and how far apart the two torques are. A torque of the angle alone has one size at
/// every speed; an off-centre code disc reads θ + ε(sin(θ − φ) + sin φ), whose second
/// derivative carries ε θ̇² sin(θ − φ), so the k = 1 columns take a size that grows with the
/// speed (a 3.3e-3 rad disc, the departure survey's `encoder_eccentricity` k=0 at
/// `DEPARTURE_SEED=25`, was named a 2.5e-3 N·m k = 1 position torque; its validate rows split
/// at p = 4e-14, their fast windows' torque 1.54e-2 N·m apart from the slow ones'). The
/// fast half's copies carry the extra inertia's divisor at the one-size fit's J (a dynamics
/// column is divided by 1 + J/(m l²) per run). None where the rows cannot tell (a column empty
/// on them, a fit that fails, or more lobes than the fast windows resolve,
/// [`ONE_SIZE_AT_EVERY_SPEED_MAX_K`]).
pub(crate) fn one_size_at_every_speed(
    rows: &[WeakRow],
    cols: &[usize],
    c: &Candidate,
) -> Option<OneSize> {
    if c.k > ONE_SIZE_AT_EVERY_SPEED_MAX_K {
        return None;
    }
    let mut speeds: Vec<f64> = rows.iter().map(|r| r.theta_dot_rad_s.abs()).collect();
    speeds.sort_by(f64::total_cmp);
    let median = *speeds.get(speeds.len() / 2)?;
    let split = sizes_by_group(rows, cols, c, &|r| {
        usize::from(r.theta_dot_rad_s.abs() > median)
    })?;
    let [(_, fast)] = split.groups.as_slice() else {
        return None;
    };
    let difference: Vec<(f64, f64)> = split
        .base
        .iter()
        .zip(fast)
        .map(|(&(s, ss), &(f, sf))| (f - s, ss.hypot(sf)))
        .collect();
    let (apart, apart_se) = pendulum_model::effects::by_name(&c.effect)?.estimate(&difference);
    Some(OneSize {
        p: split.p,
        apart: apart.abs(),
        apart_se,
    })
}

/// Chow's F test of one size in every run: how often columns `c.add` (a candidate's), given a
/// size of their own in each run, would take as much off the rows' weighted equation error as
/// they do by chance alone ([`sizes_by_group`]); and the spread of the runs' own sizes (SI,
/// weighted by their inverse variances, so that a run that barely sees the term counts for
/// little). The catalogue's torques and inertias are constants of the rig; a size that follows
/// the run is a departure the catalogue does not hold (a bearing whose μ differs from run to
/// run, `DEPARTURE_SEED=31` `mu_run_spread` k=4, was named a 3.58e-3 N·m·s/rad generator whose
/// identify runs' own sizes ran from −4.8e-3 to 2.0e-3, p = 8.7e-6).
pub(crate) fn one_size_in_every_run(
    rows: &[WeakRow],
    cols: &[usize],
    c: &Candidate,
) -> Option<OneSize> {
    let split = sizes_by_group(rows, cols, c, &|r| r.run)?;
    let effect = pendulum_model::effects::by_name(&c.effect)?;
    let sizes: Vec<(f64, f64)> = std::iter::once(&split.base)
        .chain(split.groups.iter().map(|(_, g)| g))
        .map(|g| effect.estimate(g))
        .filter(|(v, s)| v.is_finite() && s.is_finite() && *s > 0.0)
        .collect();
    let w: f64 = sizes.iter().map(|(_, s)| s.powi(-2)).sum();
    let mean = sizes.iter().map(|(v, s)| v / (s * s)).sum::<f64>() / w;
    let var = sizes
        .iter()
        .map(|(v, s)| (v - mean).powi(2) / (s * s))
        .sum::<f64>()
        / w;
    (sizes.len() >= 2 && var.is_finite()).then_some(OneSize {
        p: split.p,
        apart_se: f64::NAN,
        apart: var.sqrt(),
    })
}

/// A candidate's columns fitted with a size of their own in each group of rows (`group`: the
/// group of a row), the other `cols` shared by all (Chow's F test).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct GroupSizes {
    /// The chance of a fall as large from the groups' own sizes by chance alone.
    pub p: f64,
    /// The first group's coefficients (value, standard error), one per candidate column: the
    /// group of the lowest number among those where the candidate's columns live.
    pub base: Vec<(f64, f64)>,
    /// Every other group where the candidate's columns live: its number and coefficients.
    pub groups: Vec<(usize, Vec<(f64, f64)>)>,
}

/// The fewest rows of a run whose weights [`sizes_by_group`] scales to its own residuals.
const MIN_ROWS_TO_SCALE: usize = 8;

/// Chow's F test of one size in every group of rows: how often columns `c.add` (a
/// candidate's), given a size of their own in each group but the first (`group`), would take
/// as much off the rows' weighted equation error as they do by chance alone. A group where
/// none of the candidate's columns live keeps the first group's size (it has none of its
/// own to tell). The groups' copies of a dynamics column carry the extra inertia's divisor at
/// the one-size fit's J (a dynamics column is divided by 1 + J/(m l²) per run). None where the
/// rows cannot tell (a column empty on them, fewer than two groups, or a fit that fails).
pub(crate) fn sizes_by_group(
    rows: &[WeakRow],
    cols: &[usize],
    c: &Candidate,
    group: &dyn Fn(&WeakRow) -> usize,
) -> Option<GroupSizes> {
    let (_, split, two) = split_fit(rows, cols, c, group)?;
    // The rows' weights were set on another fit's residuals ([`crate::weak::set_weights`]): the
    // whole catalogue's, or where that fit is singular (a validate view of three runs) the
    // base's own, which carry a missing term's torque, more in some runs than in others. So
    // they can be off by a different factor in each run, while the F test pools one variance. So each run's rows are first scaled to a mean
    // weighted square residual of 1 under the split fit (the size free in each group, so that
    // a departure the split describes does not count as its run's noise), as `set_weights`
    // does per run, and the test is made on the rows so weighted. Without it a hidden
    // 6.69e-2 kg/m quadratic drag on a drawn design (`SURVEY_DAMPING=drawn SURVEY_SEED=48`,
    // `viscous_quadratic` k=0, `--base linear`) was refused as following the run: its
    // validate rows' weighted square residuals were 0.005, 0.25 and 0.003 a row in their three
    // runs, and the one whose 13 free-decay windows swung below 0.13 rad, 50 times noisier than
    // the others by its weights, put the size at 1.03 ± 0.10 (p = 1.5e-16 over the three);
    // with the sensors ideal, 0.56 ± 0.12 (p = 3.6e-4), and its value moved from −0.08 to 0.80
    // as its windows' start moved by 0.5 s.
    let res = two.residuals(&split);
    let mut per_run: std::collections::BTreeMap<usize, (f64, usize)> = Default::default();
    for (r, e) in split.iter().zip(&res) {
        let s = per_run.entry(r.run).or_default();
        s.0 += r.weight * e * e;
        s.1 += 1;
    }
    // (As `set_weights`, not a run of fewer than 8 rows: its own size could leave it next to
    // nothing, and a weight to match; such a run takes the scale of all the rows together.)
    let (ss_all, n_all) = per_run
        .values()
        .fold((0.0, 0), |(s, n), &(ss, k)| (s + ss, n + k));
    let scale_of = |run: usize| match per_run.get(&run) {
        Some(&(ss, n)) if ss > 0.0 && n >= MIN_ROWS_TO_SCALE => n as f64 / ss,
        _ if ss_all > 0.0 => n_all as f64 / ss_all,
        _ => 1.0,
    };
    let scaled: Vec<WeakRow> = rows
        .iter()
        .map(|r| WeakRow {
            weight: r.weight * scale_of(r.run),
            ..r.clone()
        })
        .collect();
    split_fit(&scaled, cols, c, group).map(|(sizes, _, _)| sizes)
}

/// [`sizes_by_group`] on the rows as weighted: the split rows, and the split fit.
fn split_fit(
    rows: &[WeakRow],
    cols: &[usize],
    c: &Candidate,
    group: &dyn Fn(&WeakRow) -> usize,
) -> Option<(GroupSizes, Vec<WeakRow>, crate::screen::Ols)> {
    let add = &c.add;
    let live = |k: usize, r: &WeakRow| r.x.get(k).is_some_and(|v| *v != 0.0);
    if add.is_empty()
        || !add
            .iter()
            .all(|&k| cols.contains(&k) && rows.iter().any(|r| live(k, r)))
    {
        return None;
    }
    let cols: Vec<usize> = cols
        .iter()
        .copied()
        .filter(|&k| rows.iter().any(|r| live(k, r)))
        .collect();
    let mut ids: Vec<usize> = rows
        .iter()
        .filter(|r| add.iter().any(|&k| live(k, r)))
        .map(group)
        .collect();
    ids.sort_unstable();
    ids.dedup();
    let (_, others) = ids.split_first()?;
    if others.is_empty() {
        return None;
    }
    let one = ols(rows, &cols)?;
    let width = rows.iter().map(|r| r.x.len()).max()?;
    let q = add.len();
    let split: Vec<WeakRow> = rows
        .iter()
        .map(|r| {
            let mut r = r.clone();
            r.x.resize(width + q * others.len(), 0.0);
            if let Some(g) = others.iter().position(|&id| id == group(&r)) {
                let divisor = crate::screen::inertia_divisor(&r, one.inertia_kg_m2);
                for (j, &k) in add.iter().enumerate() {
                    let v = std::mem::take(&mut r.x[k]);
                    r.x[width + q * g + j] = if crate::weak::is_dynamics(k) {
                        v * divisor
                    } else {
                        v
                    };
                }
            }
            r
        })
        .collect();
    let mut all = cols.clone();
    all.extend(width..width + q * others.len());
    let two = ols(&split, &all)?;
    let extra = (q * others.len()) as f64;
    let df = two.n as f64 - two.columns.len() as f64;
    if df < 1.0 || !(two.rss > 0.0) || !one.rss.is_finite() {
        return None;
    }
    let f = ((one.rss - two.rss).max(0.0) / extra) / (two.rss / df);
    let coefs = |at: &dyn Fn(usize) -> usize| -> Vec<(f64, f64)> {
        (0..q)
            .map(|j| two.coef_of(at(j)).unwrap_or((f64::NAN, f64::NAN)))
            .collect()
    };
    let sizes = GroupSizes {
        p: pendulum_numerics::f_sf(f, extra, df),
        base: coefs(&|j| add[j]),
        groups: others
            .iter()
            .enumerate()
            .map(|(g, &id)| (id, coefs(&|j| width + q * g + j)))
            .collect(),
    };
    Some((sizes, split, two))
}

/// Whether, beside the first round's other candidates, both the identify and the validate rows
/// put a candidate's size at less than [`AGREEMENT_REL`] of the value it would be named at
/// (`named`), each interval (value, 95 % half-width) excluding that value: what it explains, the
/// others explain, and it only stands in for them where they are missing. Where the others are
/// collinear with it (an offset and a k = 1 position torque on runs that hang still) the
/// intervals beside them are wide and hold the named value, and this does not refuse it.
pub(crate) fn stands_in_for_others(named: f64, identify: (f64, f64), heldout: (f64, f64)) -> bool {
    let far =
        |(v, half): (f64, f64)| (named - v).abs() > half && v.abs() < AGREEMENT_REL * named.abs();
    named.is_finite() && named != 0.0 && far(identify) && far(heldout)
}

/// Whether the screen (equation error) and the trajectory refit (output error) agree on an
/// effect: the same sign, and each estimate inside the other's interval. The refit's value is
/// inside the screen's when it lies within the screen's 95 % interval or within
/// [`AGREEMENT_REL`] of its estimate, whichever is wider (10 % is the accuracy claimed for any
/// estimate); the screen's value is inside the refit's when the profile through it (the other
/// parameters refitted with the effect's held at the screen's value) does not make the identify
/// runs' trajectories significantly worse than the refit
/// (`screen_fits_trajectories`, a paired test on their 0.5 s segments: trajectories often pin a
/// dry torque's size poorly, trading it against μ). Two views that disagree on the sign have
/// not found the effect: a 16 µs "accelerometer lag" the refit put at −47 µs was one.
pub(crate) fn views_agree(
    screen: f64,
    half_width: f64,
    refit: f64,
    screen_fits_trajectories: bool,
) -> bool {
    if !(refit.is_finite() && refit * screen > 0.0) {
        return false;
    }
    refit_within_band(screen, half_width, refit) || screen_fits_trajectories
}

/// Whether the pooled free-segment losses `free_losses` name `effect` and hold `refit` inside
/// their 95 % interval or [`AGREEMENT_REL`] of their estimate, whichever is wider.
pub(crate) fn envelope_measures(
    free_losses: &[crate::envelope::PooledTerm],
    effect: &str,
    refit: f64,
) -> bool {
    refit.is_finite()
        && refit > 0.0
        && free_losses.iter().any(|t| {
            t.name == effect && refit_within_band(t.estimate, 0.5 * (t.ci_high - t.ci_low), refit)
        })
}

/// The refit's value inside the screen's: within its half-width or [`AGREEMENT_REL`] of its
/// estimate, whichever is wider (the first way [`views_agree`] holds).
pub(crate) fn refit_within_band(screen: f64, half_width: f64, refit: f64) -> bool {
    (refit - screen).abs() <= half_width.max(AGREEMENT_REL * screen.abs())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The free segments measure a loss's size only where they name that loss and hold the
    /// trajectories' value: inside their interval or 10 % of their estimate, never at or below 0.
    #[test]
    fn the_free_segments_measure_only_the_loss_they_name_at_the_value_they_hold() {
        let t = |name, estimate: f64, half: f64| crate::envelope::PooledTerm {
            name,
            estimate,
            ci_low: estimate - half,
            ci_high: estimate + half,
            unit: "N·m",
        };
        let losses = [
            t("coulomb_bearing", 0.2, 0.002),
            t("coulomb_constant", 8.84e-3, 2.0e-4),
        ];
        assert!(envelope_measures(&losses, "coulomb_constant", 8.48e-3));
        // Beyond 10 % and the interval: another size.
        assert!(!envelope_measures(&losses, "coulomb_constant", 7.9e-3));
        assert!(!envelope_measures(&losses, "coulomb_constant", 0.0));
        assert!(!envelope_measures(&losses, "coulomb_constant", f64::NAN));
        // A loss the envelope does not name, though a named one's value is near.
        assert!(!envelope_measures(&losses, "viscous_linear", 0.2));
        assert!(!envelope_measures(&[], "coulomb_constant", 8.84e-3));
        // A wide interval holds what 10 % would not.
        assert!(envelope_measures(
            &[t("coulomb_constant", 8.84e-3, 2.0e-3)],
            "coulomb_constant",
            7.0e-3
        ));
    }

    /// The every-effect survey's offset + inertia pair at `SURVEY_SEED=3`: a k = 1 position
    /// torque named at 0.41 N·m, which beside the two the identify rows put at 3.5e-4 [0.9e-4,
    /// 6.0e-4] and the validate rows at 3.8e-4 [−3.7e-4, 11.3e-4], stands in for them (the draw
    /// itself is the slow-set test
    /// `a_position_torque_standing_in_for_an_offset_and_an_inertia_is_not_named`).
    #[test]
    fn a_candidate_stands_in_only_where_both_sets_put_it_under_a_tenth_of_its_named_size() {
        assert!(stands_in_for_others(
            0.41,
            (3.5e-4, 2.55e-4),
            (3.8e-4, 7.5e-4)
        ));
        // A set whose interval holds the named value (others collinear with it: wide) does not
        // refuse it.
        assert!(!stands_in_for_others(
            0.41,
            (3.5e-4, 2.55e-4),
            (3.8e-4, 0.5)
        ));
        // Nor one that puts it at more than a tenth of that value.
        assert!(!stands_in_for_others(0.41, (0.2, 0.01), (3.8e-4, 7.5e-4)));
        // Nothing named, nothing stood in for; symmetric in the sign.
        assert!(!stands_in_for_others(0.0, (0.0, 1e-4), (0.0, 1e-4)));
        assert!(stands_in_for_others(
            -0.41,
            (-3.5e-4, 2.55e-4),
            (3.8e-4, 7.5e-4)
        ));
    }

    /// Two sets of runs disagree on a size only when their intervals are apart and the values
    /// more than the promised 10 % apart: a bouncing bob's 7.18e-3 against 2.48e-2 kg·m² do;
    /// overlapping intervals do not, nor do two tight ones 3 % apart (a systematic difference
    /// within the accuracy promised), nor a wide held-out interval that cannot say.
    #[test]
    fn sizes_disagree_only_apart_beyond_both_intervals_and_the_promised_accuracy() {
        assert!(sizes_disagree(7.18e-3, 2.81e-3, 2.48e-2, 8.61e-3));
        assert!(sizes_disagree(8.21e-2, 0.119, 0.817, 0.583));
        assert!(!sizes_disagree(0.2115, 0.053, 0.30, 0.04));
        assert!(!sizes_disagree(0.1635, 0.0004, 0.1684, 0.0004));
        assert!(sizes_disagree(0.1635, 0.0004, 0.185, 0.0004));
        assert!(!sizes_disagree(5e-3, 1e-3, 2e-2, 1.6e-2));
        // Symmetric in the sign of the difference, and in the sign of the size.
        assert!(sizes_disagree(-3.75e-3, 0.93e-3, -1.80e-2, 2.87e-3));
        assert!(sizes_disagree(1.80e-2, 0.93e-3, 3.75e-3, 2.87e-3));
    }
}
