//! Base excitation: the exact crank-rod motion of `rig.md` (the study's Eq. 2) or a measured
//! acceleration signal. Everything here is dimensionless: time t = ω0·τ, accelerations divided by g.

use std::sync::{Arc, Mutex};

use serde::{Deserialize, Serialize};

use crate::ModelError;

/// Crank-rod displacement over crank radius, f(φ) = y/r = (1 − cos φ) + (1 − sqrt(1 − λ² sin² φ))/λ.
pub fn crank_f(phi: f64, lambda: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    if lambda == 0.0 {
        return 1.0 - c;
    }
    (1.0 - c) + (1.0 - (1.0 - lambda * lambda * s * s).sqrt()) / lambda
}

/// df/dφ = sin φ + λ sin φ cos φ / sqrt(1 − λ² sin² φ).
pub fn crank_f1(phi: f64, lambda: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    let q = (1.0 - lambda * lambda * s * s).sqrt();
    s + lambda * s * c / q
}

/// d²f/dφ² = cos φ + λ [cos 2φ / q + λ² sin² 2φ / (4 q³)], q = sqrt(1 − λ² sin² φ).
/// At φ = 0 it is 1 + λ: the largest upward acceleration, the "positive peak".
pub fn crank_f2(phi: f64, lambda: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    let q2 = 1.0 - lambda * lambda * s * s;
    let q = q2.sqrt();
    let s2 = 2.0 * s * c;
    let c2 = c * c - s * s;
    c + lambda * (c2 / q + lambda * lambda * s2 * s2 / (4.0 * q2 * q))
}

/// Intervals per crank turn of a [`CrankTable`].
const TABLE_N: usize = 256;

/// f'(φ) and f''(φ) of one crank ratio λ, tabulated over a turn as piecewise quintics.
///
/// Why: the exact f'' costs a sin/cos, a square root and two divisions, and was a third of a
/// fit's time (the right-hand side is evaluated ~10⁹ times). Each of the 256 intervals holds the
/// quintic interpolating f at its six Chebyshev points: the error is below 1e-13 for λ ≤ 0.5,
/// far under any integrator tolerance (see the test).
#[derive(Debug)]
pub struct CrankTable {
    lambda: f64,
    /// Monomial coefficients in v ∈ [−1, 1] over each interval, of f'' and of f'. Interval i is
    /// centred on φ = i·h, h = 2π/TABLE_N.
    f2: Box<[[f64; 6]; TABLE_N]>,
    f1: Box<[[f64; 6]; TABLE_N]>,
}

/// Tables depend on λ alone, so equal λ means equal tables.
impl PartialEq for CrankTable {
    fn eq(&self, other: &Self) -> bool {
        self.lambda.to_bits() == other.lambda.to_bits()
    }
}

impl CrankTable {
    /// Builds the table of crank ratio λ (|λ| < 1).
    pub fn new(lambda: f64) -> Self {
        let h = 2.0 * std::f64::consts::PI / TABLE_N as f64;
        let fit = |g: &dyn Fn(f64) -> f64, i: usize| -> [f64; 6] {
            // Chebyshev coefficients from the values at the 6 Chebyshev points, then monomials.
            let n = 6;
            let nodes: Vec<f64> = (0..n)
                .map(|k| (std::f64::consts::PI * (k as f64 + 0.5) / n as f64).cos())
                .collect();
            let vals: Vec<f64> = nodes.iter().map(|v| g(h * (i as f64 + 0.5 * v))).collect();
            let mut c = [0.0; 6];
            for (j, cj) in c.iter_mut().enumerate() {
                let s: f64 = (0..n)
                    .map(|k| {
                        vals[k]
                            * (std::f64::consts::PI * j as f64 * (k as f64 + 0.5) / n as f64).cos()
                    })
                    .sum();
                *cj = s * if j == 0 { 1.0 } else { 2.0 } / n as f64;
            }
            // T0 = 1, T1 = v, T2 = 2v² − 1, T3 = 4v³ − 3v, T4 = 8v⁴ − 8v² + 1, T5 = 16v⁵ − 20v³ + 5v.
            [
                c[0] - c[2] + c[4],
                c[1] - 3.0 * c[3] + 5.0 * c[5],
                2.0 * c[2] - 8.0 * c[4],
                4.0 * c[3] - 20.0 * c[5],
                8.0 * c[4],
                16.0 * c[5],
            ]
        };
        let mut f2 = Box::new([[0.0; 6]; TABLE_N]);
        let mut f1 = Box::new([[0.0; 6]; TABLE_N]);
        for i in 0..TABLE_N {
            f2[i] = fit(&|phi| crank_f2(phi, lambda), i);
            f1[i] = fit(&|phi| crank_f1(phi, lambda), i);
        }
        Self { lambda, f2, f1 }
    }

    /// The table of λ, shared: built once per λ a process uses (a handful: one per rig).
    pub fn shared(lambda: f64) -> Arc<Self> {
        static CACHE: Mutex<Vec<Arc<CrankTable>>> = Mutex::new(Vec::new());
        let mut cache = CACHE.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(t) = cache
            .iter()
            .find(|t| t.lambda.to_bits() == lambda.to_bits())
        {
            return t.clone();
        }
        let t = Arc::new(Self::new(lambda));
        // Bounded, in case a caller sweeps λ: the oldest table is dropped.
        if cache.len() >= 16 {
            cache.remove(0);
        }
        cache.push(t.clone());
        t
    }

    /// The crank ratio λ tabulated.
    pub fn lambda(&self) -> f64 {
        self.lambda
    }

    #[inline(always)]
    fn eval(coef: &[[f64; 6]; TABLE_N], phi: f64) -> f64 {
        // Round to the nearest interval centre without a float-to-int conversion: adding 1.5·2⁵²
        // leaves the integer in the low bits (two's complement, so negative φ works too).
        const SHIFT: f64 = 6_755_399_441_055_744.0;
        let x = phi * (TABLE_N as f64 / (2.0 * std::f64::consts::PI));
        let y = x + SHIFT;
        let c = &coef[(y.to_bits() & (TABLE_N as u64 - 1)) as usize];
        let v = 2.0 * (x - (y - SHIFT));
        // Estrin's scheme: a shorter dependency chain than Horner's.
        let v2 = v * v;
        (c[0] + v * c[1]) + v2 * ((c[2] + v * c[3]) + v2 * (c[4] + v * c[5]))
    }

    /// f''(φ), as [`crank_f2`].
    #[inline(always)]
    pub fn f2(&self, phi: f64) -> f64 {
        Self::eval(&self.f2, phi)
    }

    /// f'(φ), as [`crank_f1`].
    #[inline(always)]
    pub fn f1(&self, phi: f64) -> f64 {
        Self::eval(&self.f1, phi)
    }
}

/// Crank angle as a function of time: at rest at `phi0` until `t_start`, a smooth spin-up to
/// `omega` over `spinup` (φ̈ continuous), then constant speed plus an optional linear drift.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrankDrive {
    /// Crank radius over pendulum length r/l (so that R = (r/l)·ω²).
    pub r_over_l: f64,
    /// Crank ratio λ = r/L.
    pub lambda: f64,
    /// tan δ of the guide tilt: x = y·tan δ (`horizontal_base`).
    pub tan_delta: f64,
    /// Speed at the set point, dimensionless (2πΩ/ω0).
    pub omega: f64,
    /// Crank angle at t = t_start (or at t = 0 when there is no spin-up), rad.
    pub phi0: f64,
    /// Time the shaker is switched on; `None` = already at speed for all t.
    pub t_start: Option<f64>,
    /// Spin-up duration (dimensionless time).
    pub spinup: f64,
    /// dω/dt after reaching speed (`speed_drift`), counted from the end of the spin-up (or t = 0).
    pub omega_drift: f64,
}

impl CrankDrive {
    /// Already at speed, φ(t) = ω t: t = 0 is a positive acceleration peak (the study's alignment).
    pub fn at_speed(r_big: f64, lambda: f64, omega: f64) -> Self {
        Self {
            r_over_l: if omega > 0.0 {
                r_big / (omega * omega)
            } else {
                0.0
            },
            lambda,
            tan_delta: 0.0,
            omega,
            phi0: 0.0,
            t_start: None,
            spinup: 0.0,
            omega_drift: 0.0,
        }
    }

    /// Time at which the crank runs at speed (drift counts from here).
    pub fn t_at_speed(&self) -> f64 {
        self.t_start.map_or(0.0, |t| t + self.spinup)
    }

    /// Crank angle φ, its rate φ̇ and φ̈ at time t.
    pub fn phase(&self, t: f64) -> (f64, f64, f64) {
        let (t_ref, phi_ref) = match self.t_start {
            None => (0.0, self.phi0),
            Some(ts) => {
                if t <= ts {
                    return (self.phi0, 0.0, 0.0);
                }
                let tu = self.spinup;
                if t < ts + tu {
                    // φ̇ = ω s(u), s = 3u² − 2u³, u = (t − ts)/tu; ∫s du = u³ − u⁴/2.
                    let u = (t - ts) / tu;
                    let s = u * u * (3.0 - 2.0 * u);
                    let ds = 6.0 * u * (1.0 - u) / tu;
                    let int = tu * (u * u * u - 0.5 * u * u * u * u);
                    return (
                        self.phi0 + self.omega * int,
                        self.omega * s,
                        self.omega * ds,
                    );
                }
                (ts + tu, self.phi0 + self.omega * 0.5 * tu)
            }
        };
        let dt = t - t_ref;
        let phi = phi_ref + self.omega * dt + 0.5 * self.omega_drift * dt * dt;
        (phi, self.omega + self.omega_drift * dt, self.omega_drift)
    }

    /// Base accelerations (ÿ/g, ẍ/g) at time t: ÿ/g = (r/l)(f''(φ) φ̇² + f'(φ) φ̈).
    #[inline]
    pub fn accel(&self, t: f64) -> (f64, f64) {
        let (phi, dphi, ddphi) = self.phase(t);
        let mut ay = self.r_over_l * crank_f2(phi, self.lambda) * dphi * dphi;
        if ddphi != 0.0 {
            ay += self.r_over_l * crank_f1(phi, self.lambda) * ddphi;
        }
        (ay, ay * self.tan_delta)
    }

    /// As [`accel`](Self::accel), with f' and f'' from `table` (which must be of this λ).
    #[inline(always)]
    pub fn accel_tabulated(&self, table: &CrankTable, t: f64) -> (f64, f64) {
        let (phi, dphi, ddphi) = self.phase(t);
        let mut ay = self.r_over_l * table.f2(phi) * dphi * dphi;
        if ddphi != 0.0 {
            ay += self.r_over_l * table.f1(phi) * ddphi;
        }
        (ay, ay * self.tan_delta)
    }

    /// Base displacement y/l at time t.
    pub fn displacement(&self, t: f64) -> f64 {
        self.r_over_l * crank_f(self.phase(t).0, self.lambda)
    }
}

/// A measured base acceleration, resampled on a uniform grid and interpolated with cubic
/// Catmull–Rom splines (C¹, so the integrator's error control is not upset at sample points).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MeasuredAccel {
    /// Time of the first sample (dimensionless).
    pub t0: f64,
    /// Uniform spacing (dimensionless).
    pub dt: f64,
    /// ÿ/g at each grid point.
    pub ay: Vec<f64>,
    /// ẍ/g at each grid point.
    pub ax: Vec<f64>,
}

impl MeasuredAccel {
    /// Builds from possibly jittered samples (t strictly increasing) by linear resampling at `dt`.
    pub fn from_samples(t: &[f64], ay: &[f64], ax: &[f64], dt: f64) -> Result<Self, ModelError> {
        if t.len() < 4 || ay.len() != t.len() || ax.len() != t.len() {
            return Err(ModelError::BadInput(format!(
                "measured acceleration needs ≥ 4 samples and equal lengths (t {}, ay {}, ax {})",
                t.len(),
                ay.len(),
                ax.len()
            )));
        }
        if !(dt > 0.0) {
            return Err(ModelError::BadInput(format!(
                "resampling step {dt} must be > 0"
            )));
        }
        if let Some(i) = t.windows(2).position(|w| !(w[1] > w[0])) {
            return Err(ModelError::BadInput(format!(
                "measured acceleration time not increasing at sample {} ({} → {})",
                i + 1,
                t[i],
                t[i + 1]
            )));
        }
        let n = ((t[t.len() - 1] - t[0]) / dt).floor() as usize + 1;
        let mut ry = Vec::with_capacity(n);
        let mut rx = Vec::with_capacity(n);
        let mut j = 0;
        for i in 0..n {
            let ti = t[0] + i as f64 * dt;
            while j + 2 < t.len() && t[j + 1] < ti {
                j += 1;
            }
            let w = ((ti - t[j]) / (t[j + 1] - t[j])).clamp(0.0, 1.0);
            ry.push(ay[j] + w * (ay[j + 1] - ay[j]));
            rx.push(ax[j] + w * (ax[j + 1] - ax[j]));
        }
        Ok(Self {
            t0: t[0],
            dt,
            ay: ry,
            ax: rx,
        })
    }

    /// Last time covered.
    pub fn t_end(&self) -> f64 {
        self.t0 + (self.ay.len() - 1) as f64 * self.dt
    }

    #[inline]
    fn cr(p0: f64, p1: f64, p2: f64, p3: f64, u: f64) -> f64 {
        0.5 * (2.0 * p1
            + (p2 - p0) * u
            + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u * u
            + (3.0 * p1 - p0 - 3.0 * p2 + p3) * u * u * u)
    }

    /// (ÿ/g, ẍ/g) at time t; held at the end values outside the record.
    #[inline]
    pub fn accel(&self, t: f64) -> (f64, f64) {
        let n = self.ay.len();
        let x = ((t - self.t0) / self.dt).clamp(0.0, (n - 1) as f64);
        let i = (x.floor() as usize).min(n - 2);
        let u = x - i as f64;
        let i0 = i.saturating_sub(1);
        let i3 = (i + 2).min(n - 1);
        (
            Self::cr(self.ay[i0], self.ay[i], self.ay[i + 1], self.ay[i3], u),
            Self::cr(self.ax[i0], self.ax[i], self.ax[i + 1], self.ax[i3], u),
        )
    }
}

/// What moves the pendulum's axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Excitation {
    /// No base motion: a free decay.
    None,
    /// The exact crank-rod motion.
    Crank(CrankDrive),
    /// What the accelerometer saw.
    Measured(MeasuredAccel),
}

impl Excitation {
    /// (ÿ/g, ẍ/g) at dimensionless time t.
    #[inline]
    pub fn accel(&self, t: f64) -> (f64, f64) {
        match self {
            Excitation::None => (0.0, 0.0),
            Excitation::Crank(c) => c.accel(t),
            Excitation::Measured(m) => m.accel(t),
        }
    }

    /// Whether the base is still (lets a stuck pendulum stay stuck forever).
    pub fn is_still(&self) -> bool {
        matches!(self, Excitation::None)
    }

    /// The constant-speed crank drive φ = ωt, phase 0 at t = 0, from the dimensionless set.
    pub fn from_dimensionless(d: &crate::Dimensionless) -> Self {
        if d.omega <= 0.0 || d.r == 0.0 {
            return Excitation::None;
        }
        let mut c = CrankDrive::at_speed(d.r, d.lambda, d.omega);
        c.tan_delta = d.tan_delta;
        c.omega_drift = d.omega_drift;
        Excitation::Crank(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The analytic derivatives agree with central differences of f (an independent check).
    #[test]
    fn crank_derivatives_match_finite_differences() {
        for &lambda in &[0.0, 0.126, 0.185, 0.36] {
            for i in 0..200 {
                let phi = -7.0 + i as f64 * 0.07;
                let h = 1e-4;
                let d1 = (crank_f(phi + h, lambda) - crank_f(phi - h, lambda)) / (2.0 * h);
                let d2 = (crank_f(phi + h, lambda) - 2.0 * crank_f(phi, lambda)
                    + crank_f(phi - h, lambda))
                    / (h * h);
                assert!((d1 - crank_f1(phi, lambda)).abs() < 1e-7, "f' at {phi}");
                assert!((d2 - crank_f2(phi, lambda)).abs() < 1e-5, "f'' at {phi}");
            }
        }
    }

    /// The tables agree with the exact f', f'' to 1e-13 (relative to their scale), any φ sign.
    #[test]
    fn crank_table_matches_exact() {
        for &lambda in &[0.0, 0.126, 0.36, 0.5] {
            let tab = CrankTable::new(lambda);
            let mut worst: f64 = 0.0;
            for i in 0..20_000 {
                let phi = -300.0 + i as f64 * 0.0301;
                worst = worst
                    .max((tab.f2(phi) - crank_f2(phi, lambda)).abs())
                    .max((tab.f1(phi) - crank_f1(phi, lambda)).abs());
            }
            assert!(worst < 1e-13 * (1.0 + lambda), "λ = {lambda}: {worst:e}");
        }
        assert!(Arc::ptr_eq(
            &CrankTable::shared(0.126),
            &CrankTable::shared(0.126)
        ));
    }

    #[test]
    fn peak_is_at_phi_zero() {
        let lambda = 0.126;
        assert!((crank_f2(0.0, lambda) - (1.0 + lambda)).abs() < 1e-15);
        for i in 1..1000 {
            let phi = i as f64 * 2.0 * std::f64::consts::PI / 1000.0;
            assert!(crank_f2(phi, lambda) < 1.0 + lambda);
        }
    }

    /// The accelerations of the spin-up profile equal second differences of the displacement.
    #[test]
    fn drive_accel_is_second_derivative_of_displacement() {
        let drive = CrankDrive {
            r_over_l: 0.28,
            lambda: 0.126,
            tan_delta: 0.02,
            omega: 1.6,
            phi0: 0.4,
            t_start: Some(3.0),
            spinup: 8.0,
            omega_drift: 1e-3,
        };
        let h = 1e-3;
        for i in 0..400 {
            let t = i as f64 * 0.071;
            if (t - 3.0).abs() < 2.0 * h || (t - 11.0).abs() < 2.0 * h {
                continue; // φ⃛ jumps at the ends of the spin-up
            }
            let fd = (drive.displacement(t + h) - 2.0 * drive.displacement(t)
                + drive.displacement(t - h))
                / (h * h);
            let (ay, ax) = drive.accel(t);
            assert!((fd - ay).abs() < 1e-5, "t={t}: {fd} vs {ay}");
            assert!((ax - 0.02 * ay).abs() < 1e-15);
        }
        // Continuity of φ and φ̇ across the end of the spin-up.
        let (p1, w1, _) = drive.phase(11.0 - 1e-9);
        let (p2, w2, _) = drive.phase(11.0 + 1e-9);
        assert!((p1 - p2).abs() < 1e-8 && (w1 - w2).abs() < 1e-8);
    }

    #[test]
    fn measured_interpolation_reproduces_smooth_signal() {
        let n = 2000;
        let t: Vec<f64> = (0..n)
            .map(|i| i as f64 * 0.01 + 0.000_3 * ((i * 7 % 5) as f64))
            .collect();
        let ay: Vec<f64> = t.iter().map(|&x| (1.3 * x).sin()).collect();
        let ax: Vec<f64> = t.iter().map(|&x| 0.1 * (1.3 * x).cos()).collect();
        let m = MeasuredAccel::from_samples(&t, &ay, &ax, 0.01).unwrap();
        for i in 10..1900 {
            let x = i as f64 * 0.0103;
            let (y, xx) = m.accel(x);
            assert!((y - (1.3 * x).sin()).abs() < 2e-4, "{x}");
            assert!((xx - 0.1 * (1.3 * x).cos()).abs() < 2e-5);
        }
        assert!(
            MeasuredAccel::from_samples(&[0.0, 1.0, 1.0, 2.0], &[0.0; 4], &[0.0; 4], 0.1).is_err()
        );
    }
}
