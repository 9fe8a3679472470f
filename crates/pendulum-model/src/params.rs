//! Physical (SI) and dimensionless parameters, with the conversions of `rig.md`.
//!
//! The study works in dimensionless time t = ω0·τ with ω0 = sqrt(g/l). Dividing the full equation
//! of `effects.md` by m·l·g gives
//!
//! ```text
//! (1 + j) θ̈ = −(1 + A_y) sin θ − A_x cos θ − β θ̇ − α θ̇|θ̇| − (M·N + c) sgn θ̇ − p sin(kθ + φ_p)
//! ```
//!
//! with A_y = ÿ/g, A_x = ẍ/g, N = |θ̇² + cos θ| (reference) or |θ̇² + (1 + A_y) cos θ − A_x sin θ|
//! (`bearing_load_base_accel`), j = J/(m l²), c = T_c/(m g l), p = T_p/(m g l).

use serde::{Deserialize, Serialize};

use crate::ModelError;

/// Standard gravity used when a campaign does not state its own, m/s².
pub const G_STANDARD_M_S2: f64 = 9.81;

/// Effects of `effects.md` beyond the reference model, in SI units. `None`/`false` = absent.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Effects {
    /// `coulomb_constant`: load-independent dry torque T_c, N·m.
    pub coulomb_constant_t_c_nm: Option<f64>,
    /// `position_torque`: T_p sin(kθ + φ_p) with amplitude T_p (N·m), integer k ≥ 1, phase φ_p (rad).
    pub position_torque: Option<PositionTorque>,
    /// `horizontal_base`: guide tilted δ (rad) from vertical, so x = y·tan δ.
    pub horizontal_base_delta_rad: Option<f64>,
    /// `extra_inertia`: rotating inertia J besides the bob, kg·m².
    pub extra_inertia_j_kg_m2: Option<f64>,
    /// `bearing_load_base_accel`: the bearing load carries the base acceleration too.
    pub bearing_load_base_accel: bool,
    /// `encoder_offset`: measured angle = θ + θ_off, rad (a sensor effect).
    pub encoder_offset_rad: Option<f64>,
    /// `accel_delay`: accelerometer samples lag the true motion by Δ, s (a sensor effect).
    pub accel_delay_s: Option<f64>,
    /// `accel_gain`: accelerometer sensitivity is (1 + k_a) × nominal (a sensor effect).
    pub accel_gain_k_a: Option<f64>,
    /// `speed_drift`: crank speed Ω + (dΩ/dτ)·τ from the moment the shaker is at speed, Hz/s.
    pub speed_drift_hz_per_s: Option<f64>,
}

/// `position_torque` parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PositionTorque {
    pub t_p_nm: f64,
    pub k: u32,
    pub phi_p_rad: f64,
}

/// The catalogue names of `effects.md`, in its order. Outputs use exactly these strings.
pub const EFFECT_NAMES: [&str; 12] = [
    "viscous_linear",
    "viscous_quadratic",
    "coulomb_bearing",
    "bearing_load_base_accel",
    "coulomb_constant",
    "position_torque",
    "horizontal_base",
    "extra_inertia",
    "encoder_offset",
    "accel_delay",
    "accel_gain",
    "speed_drift",
];

/// The rig and the reference model's damping, in SI units (`rig.md`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Physical {
    /// Bob mass m, kg.
    pub m_kg: f64,
    /// Axis to bob centre of mass l, m.
    pub l_m: f64,
    /// Crank radius r, m.
    pub crank_r_m: f64,
    /// Connecting-rod length L, m.
    pub rod_l_m: f64,
    /// Bearing bore radius r_b, m.
    pub r_b_m: f64,
    /// Crank speed Ω, Hz.
    pub omega_hz: f64,
    /// Local gravity g, m/s².
    pub g_m_s2: f64,
    /// Quadratic drag a, kg/m.
    pub a_kg_m: f64,
    /// Linear viscous drag b, N·s/m.
    pub b_n_s_m: f64,
    /// Bearing friction coefficient μ.
    pub mu: f64,
    pub effects: Effects,
}

impl Default for Physical {
    /// The study's rig (Table 1, heavy bob) with its representative fit a = 0, b = 0.5, μ = 0.15.
    fn default() -> Self {
        Self {
            m_kg: 1.46,
            l_m: 0.265,
            crank_r_m: 0.0725,
            rod_l_m: 0.575,
            r_b_m: 0.01225,
            omega_hz: 1.54,
            g_m_s2: G_STANDARD_M_S2,
            a_kg_m: 0.0,
            b_n_s_m: 0.5,
            mu: 0.15,
            effects: Effects::default(),
        }
    }
}

impl Physical {
    /// Natural frequency ω0 = sqrt(g/l), rad/s: the unit of dimensionless time.
    pub fn omega0_rad_s(&self) -> f64 {
        (self.g_m_s2 / self.l_m).sqrt()
    }

    /// Torque scale m·g·l, N·m: dimensionless torques are SI torques divided by it.
    pub fn torque_scale_nm(&self) -> f64 {
        self.m_kg * self.g_m_s2 * self.l_m
    }

    /// Checks that every quantity is finite and in its physical range.
    pub fn validate(&self) -> Result<(), ModelError> {
        let positive = [
            ("m_kg", self.m_kg),
            ("l_m", self.l_m),
            ("rod_L_m", self.rod_l_m),
            ("g_m_s2", self.g_m_s2),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(ModelError::OutOfRange {
                    name: name.into(),
                    value: v,
                    expected: "a finite value > 0".into(),
                });
            }
        }
        let non_negative = [
            ("crank_r_m", self.crank_r_m),
            ("r_b_m", self.r_b_m),
            ("omega_hz", self.omega_hz),
            ("a", self.a_kg_m),
            ("b", self.b_n_s_m),
            ("mu", self.mu),
        ];
        for (name, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(ModelError::OutOfRange {
                    name: name.into(),
                    value: v,
                    expected: "a finite value ≥ 0".into(),
                });
            }
        }
        if self.crank_r_m >= self.rod_l_m {
            return Err(ModelError::OutOfRange {
                name: "crank_r_m".into(),
                value: self.crank_r_m,
                expected: format!("less than rod_L_m = {}", self.rod_l_m),
            });
        }
        Ok(())
    }

    /// The study's dimensionless set (Eq. 5–6) plus the dimensionless effect terms.
    pub fn to_dimensionless(&self) -> Dimensionless {
        let w0 = self.omega0_rad_s();
        let omega = 2.0 * std::f64::consts::PI * self.omega_hz / w0;
        let scale = self.torque_scale_nm();
        let e = &self.effects;
        let (p, k, phi_p) = match e.position_torque {
            Some(pt) => (pt.t_p_nm / scale, pt.k, pt.phi_p_rad),
            None => (0.0, 1, 0.0),
        };
        Dimensionless {
            omega,
            r: self.crank_r_m * omega * omega / self.l_m,
            lambda: self.crank_r_m / self.rod_l_m,
            alpha: self.a_kg_m * self.l_m / self.m_kg,
            beta: self.b_n_s_m / (self.m_kg * w0),
            m_coulomb: self.mu * self.r_b_m / self.l_m,
            c: e.coulomb_constant_t_c_nm.unwrap_or(0.0) / scale,
            p,
            k,
            phi_p,
            tan_delta: e.horizontal_base_delta_rad.unwrap_or(0.0).tan(),
            j: e.extra_inertia_j_kg_m2.unwrap_or(0.0) / (self.m_kg * self.l_m * self.l_m),
            base_load: e.bearing_load_base_accel,
            // dω/dt = 2π (dΩ/dτ) / ω0²: Hz/s → (rad per dimensionless time) per dimensionless time.
            omega_drift: 2.0 * std::f64::consts::PI * e.speed_drift_hz_per_s.unwrap_or(0.0)
                / (w0 * w0),
            kappa: 0.0,
        }
    }

    /// Inverse of [`Physical::to_dimensionless`] for the damping and drive: keeps m, l, g, r_b and
    /// L of `self` and sets Ω, r, a, b, μ and the effects so that they map to `d`.
    pub fn with_dimensionless(&self, d: &Dimensionless) -> Physical {
        let mut p = self.clone();
        let w0 = self.omega0_rad_s();
        let scale = self.torque_scale_nm();
        p.omega_hz = d.omega * w0 / (2.0 * std::f64::consts::PI);
        p.crank_r_m = if d.omega > 0.0 {
            d.r * self.l_m / (d.omega * d.omega)
        } else {
            self.crank_r_m
        };
        p.rod_l_m = if d.lambda > 0.0 {
            p.crank_r_m / d.lambda
        } else {
            self.rod_l_m
        };
        p.a_kg_m = d.alpha * self.m_kg / self.l_m;
        p.b_n_s_m = d.beta * self.m_kg * w0;
        p.mu = d.m_coulomb * self.l_m / self.r_b_m;
        let e = &mut p.effects;
        e.coulomb_constant_t_c_nm = (d.c != 0.0).then_some(d.c * scale);
        e.position_torque = (d.p != 0.0).then_some(PositionTorque {
            t_p_nm: d.p * scale,
            k: d.k,
            phi_p_rad: d.phi_p,
        });
        e.horizontal_base_delta_rad = (d.tan_delta != 0.0).then_some(d.tan_delta.atan());
        e.extra_inertia_j_kg_m2 = (d.j != 0.0).then_some(d.j * self.m_kg * self.l_m * self.l_m);
        e.bearing_load_base_accel = d.base_load;
        e.speed_drift_hz_per_s = (d.omega_drift != 0.0)
            .then_some(d.omega_drift * w0 * w0 / (2.0 * std::f64::consts::PI));
        p
    }
}

/// Dimensionless parameters of the equation of motion (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Dimensionless {
    /// Forcing frequency ω = 2πΩ/ω0.
    pub omega: f64,
    /// Forcing amplitude R = r ω²/l.
    pub r: f64,
    /// Crank ratio λ = r/L.
    pub lambda: f64,
    /// Quadratic drag α = a l/m.
    pub alpha: f64,
    /// Linear drag β = b/(m ω0).
    pub beta: f64,
    /// Bearing friction M = μ r_b/l.
    pub m_coulomb: f64,
    /// Constant dry torque c = T_c/(m g l).
    pub c: f64,
    /// Position torque amplitude p = T_p/(m g l).
    pub p: f64,
    /// Position torque harmonic k.
    pub k: u32,
    /// Position torque phase φ_p, rad.
    pub phi_p: f64,
    /// tan δ of the guide's tilt (`horizontal_base`).
    pub tan_delta: f64,
    /// Extra inertia j = J/(m l²).
    pub j: f64,
    /// `bearing_load_base_accel` switched on.
    pub base_load: bool,
    /// Crank speed drift dω/dt in dimensionless units.
    pub omega_drift: f64,
    /// Linear restoring stiffness κ = k/(m g l) of a torque −k θ besides gravity (a torsion
    /// spring, a cable): free decays of spring-loaded pendulums (issue 16). Absent = 0.
    #[serde(default)]
    pub kappa: f64,
}

impl Default for Dimensionless {
    fn default() -> Self {
        Physical::default().to_dimensionless()
    }
}

impl Dimensionless {
    /// A free pendulum with no damping and no base motion.
    pub fn conservative() -> Self {
        Self {
            omega: 0.0,
            r: 0.0,
            lambda: 0.0,
            alpha: 0.0,
            beta: 0.0,
            m_coulomb: 0.0,
            c: 0.0,
            p: 0.0,
            k: 1,
            phi_p: 0.0,
            tan_delta: 0.0,
            j: 0.0,
            base_load: false,
            omega_drift: 0.0,
            kappa: 0.0,
        }
    }

    /// Forcing period 2π/ω in dimensionless time (∞ without forcing).
    pub fn forcing_period(&self) -> f64 {
        if self.omega > 0.0 {
            2.0 * std::f64::consts::PI / self.omega
        } else {
            f64::INFINITY
        }
    }

    /// Checks ranges: damping ≥ 0, λ < 1, j > −1.
    pub fn validate(&self) -> Result<(), ModelError> {
        let checks = [
            ("omega", self.omega, self.omega >= 0.0),
            ("R", self.r, self.r >= 0.0),
            ("lambda", self.lambda, (0.0..1.0).contains(&self.lambda)),
            ("alpha", self.alpha, self.alpha >= 0.0),
            ("beta", self.beta, self.beta >= 0.0),
            ("M", self.m_coulomb, self.m_coulomb >= 0.0),
            ("c", self.c, self.c >= 0.0),
            ("j", self.j, self.j > -1.0),
            ("kappa", self.kappa, self.kappa >= 0.0),
        ];
        for (name, v, ok) in checks {
            if !(v.is_finite() && ok) {
                return Err(ModelError::OutOfRange {
                    name: name.into(),
                    value: v,
                    expected: match name {
                        "lambda" => "0 ≤ λ < 1".into(),
                        "j" => "j > −1".into(),
                        _ => "a finite value ≥ 0".into(),
                    },
                });
            }
        }
        if self.k == 0 {
            return Err(ModelError::OutOfRange {
                name: "position_torque.k".into(),
                value: 0.0,
                expected: "an integer ≥ 1".into(),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, rel: f64) -> bool {
        (a - b).abs() <= rel * b.abs()
    }

    /// The study's Table 1 dimensionless values, from its physical ones.
    #[test]
    fn table1_beta() {
        let p = Physical {
            m_kg: 1.46,
            l_m: 0.265,
            b_n_s_m: 0.525,
            ..Physical::default()
        };
        let d = p.to_dimensionless();
        assert!(close(d.beta, 0.059, 0.01), "beta = {}", d.beta);
    }

    #[test]
    fn table1_m() {
        let p = Physical {
            l_m: 0.265,
            mu: 0.157,
            r_b_m: 0.01225,
            ..Physical::default()
        };
        let d = p.to_dimensionless();
        assert!(close(d.m_coulomb, 0.0073, 0.01), "M = {}", d.m_coulomb);
    }

    #[test]
    fn table1_alpha() {
        let p = Physical {
            m_kg: 0.745,
            l_m: 0.26,
            a_kg_m: 0.003,
            ..Physical::default()
        };
        let d = p.to_dimensionless();
        // 0.003·0.26/0.745 = 0.00105, which the study rounds to 0.001.
        assert!(close(d.alpha, 0.001, 0.06), "alpha = {}", d.alpha);
        assert!(close(d.alpha, 0.003 * 0.26 / 0.745, 1e-12));
    }

    #[test]
    fn table1_lambda_and_omega() {
        let p = Physical {
            l_m: 0.26,
            crank_r_m: 0.0725,
            rod_l_m: 0.575,
            omega_hz: 1.54,
            ..Physical::default()
        };
        let d = p.to_dimensionless();
        assert!(close(d.lambda, 0.126, 0.001), "lambda = {}", d.lambda);
        assert!(close(d.omega, 1.57, 0.005), "omega = {}", d.omega);
        // R = r ω²/l
        assert!(close(d.r, 0.0725 * d.omega * d.omega / 0.26, 1e-12));
    }

    #[test]
    fn dimensionless_round_trip() {
        let mut p = Physical {
            a_kg_m: 0.01,
            ..Physical::default()
        };
        p.effects.coulomb_constant_t_c_nm = Some(0.004);
        p.effects.position_torque = Some(PositionTorque {
            t_p_nm: 0.01,
            k: 3,
            phi_p_rad: 0.2,
        });
        p.effects.horizontal_base_delta_rad = Some(0.03);
        p.effects.extra_inertia_j_kg_m2 = Some(0.002);
        p.effects.speed_drift_hz_per_s = Some(-0.001);
        let d = p.to_dimensionless();
        let back = p.with_dimensionless(&d);
        for (a, b) in [
            (back.omega_hz, p.omega_hz),
            (back.crank_r_m, p.crank_r_m),
            (back.rod_l_m, p.rod_l_m),
            (back.a_kg_m, p.a_kg_m),
            (back.b_n_s_m, p.b_n_s_m),
            (back.mu, p.mu),
            (back.effects.coulomb_constant_t_c_nm.unwrap(), 0.004),
            (back.effects.position_torque.unwrap().t_p_nm, 0.01),
            (back.effects.horizontal_base_delta_rad.unwrap(), 0.03),
            (back.effects.extra_inertia_j_kg_m2.unwrap(), 0.002),
            (back.effects.speed_drift_hz_per_s.unwrap(), -0.001),
        ] {
            assert!(close(a, b, 1e-12), "{a} vs {b}");
        }
    }

    #[test]
    fn validate_rejects_nonsense() {
        let p = Physical {
            l_m: -1.0,
            ..Physical::default()
        };
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains("l_m"), "{e}");
        let d = Dimensionless {
            lambda: 1.5,
            ..Dimensionless::default()
        };
        assert!(d.validate().is_err());
    }
}
