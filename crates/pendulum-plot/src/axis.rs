//! Axes with our own tick choices. Plotters' f64 axis gives a single tick for short axes
//! (it asks for five or more), and its log axis labels only powers of ten (none at all
//! when the range holds none); these always give a few well-spaced, readable ticks.

use std::ops::Range;

use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter};

use crate::common::{format_log, TickFmt};

/// "Nice" ticks (1, 2, 2.5, 5 × 10ⁿ steps) inside lo..=hi: at most `max_ticks` of them,
/// and at least two whenever the range allows.
pub fn nice_ticks(lo: f64, hi: f64, max_ticks: usize) -> Vec<f64> {
    let span = hi - lo;
    if !(span > 0.0 && span.is_finite()) {
        return vec![lo];
    }
    let max_ticks = max_ticks.max(2);
    let make = |step: f64| -> Vec<f64> {
        let k0 = (lo / step - 1e-9).ceil() as i64;
        let k1 = (hi / step + 1e-9).floor() as i64;
        // Round to the step's precision so 12 × 0.2 is 2.4, not 2.4000000000000004.
        let d = (2.0 - step.log10().floor()).clamp(0.0, 300.0) as i32;
        let f = 10f64.powi(d);
        (k0..=k1)
            .map(|k| {
                let v = k as f64 * step;
                let r = (v * f).round() / f;
                if r.is_finite() {
                    r
                } else {
                    v
                }
            })
            .collect()
    };
    let mag = 10f64.powf((span / max_ticks as f64).log10().floor());
    let mut steps: Vec<f64> = Vec::new();
    for e in [-2.0, -1.0, 0.0, 1.0] {
        for m in [1.0, 2.0, 2.5, 5.0] {
            steps.push(m * mag * 10f64.powf(e));
        }
    }
    // Largest-count candidate that still fits, but at least two ticks.
    let mut best: Option<Vec<f64>> = None;
    for &step in steps.iter().rev() {
        let t = make(step);
        if t.len() > max_ticks {
            break;
        }
        if t.len() >= 2 || best.is_none() {
            best = Some(t);
        }
    }
    best.filter(|t| !t.is_empty())
        .unwrap_or_else(|| vec![lo, hi])
}

/// A linear axis over lo..hi with ticks from [`nice_ticks`].
#[derive(Debug, Clone)]
pub struct LinAxis {
    lo: f64,
    hi: f64,
    ticks: Vec<f64>,
    pub fmt: TickFmt,
}

impl LinAxis {
    pub fn new(lo: f64, hi: f64, max_ticks: usize) -> Self {
        let ticks = nice_ticks(lo, hi, max_ticks);
        let fmt = TickFmt::for_ticks(&ticks);
        Self { lo, hi, ticks, fmt }
    }

    pub fn label(&self, v: f64) -> String {
        self.fmt.format(v)
    }

    pub fn labels(&self) -> Vec<String> {
        self.ticks.iter().map(|&v| self.label(v)).collect()
    }
}

impl Ranged for LinAxis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let f = ((*v - self.lo) / (self.hi - self.lo)).clamp(-1e3, 1e3);
        let f = if f.is_finite() { f } else { 0.5 };
        limit.0 + (f64::from(limit.1 - limit.0) * f).round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() || hint.max_num_points() == 0 {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

impl ValueFormatter<f64> for LinAxis {
    fn format(value: &f64) -> String {
        format!("{value}")
    }
}

#[derive(Debug, Clone)]
pub struct LogAxis {
    lo: f64,
    hi: f64,
    tlo: f64,
    thi: f64,
    /// Labelled ticks (bold grid lines).
    labelled: Vec<f64>,
    /// Minor grid lines.
    minor: Vec<f64>,
    fmt: LogLabels,
}

#[derive(Debug, Clone, Copy)]
enum LogLabels {
    /// m×10ⁿ labels; `true` = superscript powers of ten.
    Mantissa(bool),
    /// A range narrower than the 1-2-5 steps: plain linear ticks.
    Linear(TickFmt),
}

/// All m×10ᵏ (m in `ms`) inside lo..=hi, every `step`-th decade.
fn ticks(lo: f64, hi: f64, ms: &[u32], step: i32) -> Vec<f64> {
    let k0 = lo.log10().floor() as i32 - 1;
    let k1 = hi.log10().ceil() as i32 + 1;
    let mut out = Vec::new();
    for k in k0..=k1 {
        if k.rem_euclid(step) != 0 {
            continue;
        }
        for &m in ms {
            let v = f64::from(m) * 10f64.powi(k);
            if v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9) {
                out.push(v);
            }
        }
    }
    out
}

impl LogAxis {
    /// `lo..hi` (both > 0, lo < hi) drawn over about `pixels` pixels, labels at least
    /// `min_gap` pixels apart.
    pub fn new(lo: f64, hi: f64, pixels: f64, min_gap: f64) -> Self {
        let (tlo, thi) = (lo.log10(), hi.log10());
        let px_per_decade = pixels.max(1.0) / (thi - tlo).max(1e-12);
        let fits = |ts: &[f64]| {
            ts.windows(2)
                .all(|w| (w[1] / w[0]).log10() * px_per_decade >= min_gap)
        };
        let sets: [&[u32]; 5] = [
            &[1, 2, 3, 4, 5, 6, 7, 8, 9],
            &[1, 2, 3, 5],
            &[1, 2, 5],
            &[1, 3],
            &[1],
        ];
        let mut labelled = Vec::new();
        for ms in sets {
            let ts = ticks(lo, hi, ms, 1);
            if fits(&ts) {
                labelled = ts;
                break;
            }
        }
        if labelled.is_empty() {
            // Wide ranges: every 2nd, 3rd, ... decade.
            for step in [2, 3, 4, 5, 10, 20, 50, 100] {
                let ts = ticks(lo, hi, &[1], step);
                if fits(&ts) {
                    labelled = ts;
                    break;
                }
            }
        }
        let sup = labelled.iter().any(|&v| !(1e-2..1e4).contains(&v));
        let mut fmt = LogLabels::Mantissa(sup);
        if labelled.len() < 2 {
            // Narrow range inside one decade: linear ticks read best.
            let n = ((pixels / min_gap) as usize).clamp(2, 8);
            labelled = nice_ticks(lo, hi, n);
            fmt = LogLabels::Linear(TickFmt::for_ticks(&labelled));
        }
        let decades = thi - tlo;
        let minor = if decades <= 6.0 {
            ticks(lo, hi, &[1, 2, 3, 4, 5, 6, 7, 8, 9], 1)
        } else if decades <= 200.0 {
            ticks(lo, hi, &[1], 1)
        } else {
            Vec::new()
        };
        Self {
            lo,
            hi,
            tlo,
            thi,
            labelled,
            minor,
            fmt,
        }
    }

    pub fn label(&self, v: f64) -> String {
        match self.fmt {
            LogLabels::Mantissa(sup) => format_log(v, sup),
            LogLabels::Linear(f) => f.format(v),
        }
    }

    pub fn labels(&self) -> Vec<String> {
        self.labelled.iter().map(|&v| self.label(v)).collect()
    }
}

impl Ranged for LogAxis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let t = if *v > 0.0 { v.log10() } else { self.tlo - 1e3 };
        let f = ((t - self.tlo) / (self.thi - self.tlo)).clamp(-1e3, 1e3);
        limit.0 + (f64::from(limit.1 - limit.0) * f).round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.minor.clone()
        } else {
            self.labelled.clone()
        }
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

impl ValueFormatter<f64> for LogAxis {
    fn format(value: &f64) -> String {
        format!("{value}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_ticks_are_nice() {
        assert_eq!(nice_ticks(2.25, 2.75, 3), vec![2.4, 2.6]);
        assert_eq!(nice_ticks(0.0, 1.0, 6), vec![0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
        assert_eq!(nice_ticks(0.0, 100.0, 10).len(), 6);
        assert!(nice_ticks(0.0, 100.0, 12).len() <= 12);
        let t = nice_ticks(-1e-7, 3e-7, 5);
        assert!(t.len() >= 2 && t.len() <= 5, "{t:?}");
        assert_eq!(nice_ticks(1.0, 1.0, 5), vec![1.0]);
    }

    #[test]
    fn one_decade_gets_125_labels() {
        let a = LogAxis::new(0.08, 0.85, 400.0, 30.0);
        let l = a.labels();
        assert!(l.len() >= 3, "{l:?}");
        assert!(
            l.contains(&"0.1".to_string()) && l.contains(&"0.2".to_string()),
            "{l:?}"
        );
    }

    #[test]
    fn no_decade_inside_still_has_ticks() {
        let a = LogAxis::new(0.31, 0.39, 300.0, 30.0);
        assert!(a.labels().len() >= 2, "{:?}", a.labels());
    }

    #[test]
    fn many_decades_skip() {
        let a = LogAxis::new(1e-12, 1e3, 300.0, 30.0);
        let l = a.labels();
        assert!(l.len() >= 3 && l.len() <= 10, "{l:?}");
        assert!(l.iter().all(|s| s.starts_with("10")), "{l:?}");
    }
}
