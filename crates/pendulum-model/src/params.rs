//! Physical (SI) and dimensionless parameters, with the conversions of `rig.md`.
//!
//! The study works in dimensionless time t = ω0·τ with ω0 = sqrt(g/l). Dividing the full equation
//! of `effects.md` by m·l·g gives
//!
//! ```text
//! (1 + j) θ̈ = −(1 + A_y) sin θ − A_x cos θ − β θ̇ − α θ̇|θ̇| − (M·N + c) sgn θ̇ − p sin(kθ + φ_p)
//!              − g (|θ̇| − w)⁺ sgn θ̇
//! ```
//!
//! with A_y = ÿ/g, A_x = ẍ/g, N = |θ̇² + cos θ| (reference) or |θ̇² + (1 + A_y) cos θ − A_x sin θ|
//! (`bearing_load_base_accel`), j = J/(m l²), c = T_c/(m g l), p = T_p/(m g l).

use serde::{Deserialize, Serialize};

use crate::effects::{Decompiled, CATALOGUE};
use crate::ModelError;

/// Standard gravity used when a campaign does not state its own, m/s².
pub const G_STANDARD_M_S2: f64 = 9.81;

pub use crate::effects::Effects;

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

    /// Power scale m·g·l·ω0, W: dimensionless powers (torque per m g l × dθ/dt) times it.
    pub fn power_scale_w(&self) -> f64 {
        self.torque_scale_nm() * self.omega0_rad_s()
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

    /// The study's dimensionless set (Eq. 5–6) plus the dimensionless effect terms: the drive's
    /// geometry here, every term (the reference model's a, b, μ included) from its catalogue entry.
    pub fn to_dimensionless(&self) -> Dimensionless {
        let w0 = self.omega0_rad_s();
        let omega = 2.0 * std::f64::consts::PI * self.omega_hz / w0;
        let mut d = Dimensionless {
            omega,
            r: self.crank_r_m * omega * omega / self.l_m,
            lambda: self.crank_r_m / self.rod_l_m,
            ..Dimensionless::conservative()
        };
        for e in CATALOGUE {
            if let Some(v) = e.get(self) {
                e.compile(&v, self, &mut d);
            }
        }
        d
    }

    /// Inverse of [`Physical::to_dimensionless`] for the damping and drive: keeps m, l, g, r_b and
    /// L of `self` and sets Ω, r, a, b, μ and the effects so that they map to `d` (sensor effects,
    /// which `d` does not carry, are kept).
    pub fn with_dimensionless(&self, d: &Dimensionless) -> Physical {
        let mut p = self.clone();
        let w0 = self.omega0_rad_s();
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
        for e in CATALOGUE {
            // Scales from `self`: m, l, g and r_b are the same, Ω and r are not used by any term.
            if let Decompiled::Set(v) = e.decompile(d, self) {
                e.set(&mut p, v.as_deref());
            }
        }
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
    /// Dry torque fading with speed, s·e^{−(θ̇/v)²} sgn θ̇, held in full at rest: its size
    /// s (a torque per m g l) and speed scale v (dimensionless, > 0 when s ≠ 0). Absent = 0.
    #[serde(default)]
    pub s_break: f64,
    #[serde(default)]
    pub v_break: f64,
    /// Torque with a dead band, g·(|θ̇| − w)⁺ sgn θ̇ (a generator through a rectifier): its slope
    /// g = c_g ω0/(m g l) and dead-band speed w = ω_d/ω0 (both ≥ 0). Zero at rest, so it never
    /// enters the sticking capacity. Absent = 0.
    #[serde(default)]
    pub gen_c: f64,
    #[serde(default)]
    pub gen_w: f64,
    /// Linear restoring stiffness κ = k/(m g l) of a torque −k θ besides gravity (a torsion
    /// spring, a cable): free decays of spring-loaded pendulums (issue 16). Absent = 0.
    #[serde(default)]
    pub kappa: f64,
    /// Half-width of the spring's slack, rad: a cable that hangs slack while |θ| ≤ this and
    /// pulls, as −κ(θ ∓ slack), beyond it (a departure outside the catalogue for tests of an
    /// honest `unexplained`). Absent = 0: the spring acts everywhere.
    #[serde(default)]
    pub kappa_slack: f64,
    /// Where the spring is unstretched, rad: a cable anchored off the hanging position pulls
    /// as −κ(θ − anchor) (a spring plus a constant torque; a departure outside the catalogue
    /// for tests of an honest `unexplained`). Absent = 0.
    #[serde(default)]
    pub kappa_anchor: f64,
    /// Growth rate of the constant dry torque, dc/dt per dimensionless time (c + c_rate·t, t
    /// from the simulation's start): a bearing whose drag grows as it runs (heating, a seal
    /// drying out), a departure outside the catalogue for tests of an honest `unexplained`.
    /// Absent = 0.
    #[serde(default)]
    pub c_rate: f64,
    /// A dry torque that varies around the turn, c_lobes·(1 + cos(k θ − φ)) sgn θ̇ with k =
    /// `c_lobes_k` and φ = `c_lobes_phase` (a bent shaft or an oval seal dragging more over
    /// part of each turn; ≥ 0 everywhere, held in full at rest): a departure outside the
    /// catalogue for tests of an honest `unexplained`. Absent = 0.
    #[serde(default)]
    pub c_lobes: f64,
    #[serde(default)]
    pub c_lobes_k: u32,
    #[serde(default)]
    pub c_lobes_phase: f64,
    /// A drag growing as the cube of the speed, −γ θ̇³ with γ = c ω0³/(m g l) for a torque
    /// c θ̇³ in N·m (a paddle whose wake turns turbulent, a grease that thickens with shear):
    /// a departure outside the catalogue, whose viscous and quadratic drags only approximate
    /// it, for tests of an honest `unexplained`. Absent = 0.
    #[serde(default)]
    pub cubic_drag: f64,
    /// A viscous drag acting over part of the turn, −β_e θ̇ (1 + cos(θ − φ_e))/2 with β_e =
    /// c_e ω0/(m g l) for a torque c_e θ̇ in N·m·s/rad where it is strongest (an eddy-current
    /// brake: a magnet beside the swing at φ_e): a departure outside the catalogue, whose drag
    /// is the same all around the turn, for tests of an honest `unexplained`. Absent = 0.
    #[serde(default)]
    pub eddy_brake: f64,
    #[serde(default)]
    pub eddy_brake_phase: f64,
}

impl Default for Dimensionless {
    fn default() -> Self {
        Physical::default().to_dimensionless()
    }
}

/// One coefficient slot of [`Dimensionless`] (see [`Dimensionless::slots`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slot {
    pub name: &'static str,
    pub symbol: &'static str,
    pub value: f64,
    /// Printed in titles even when 0.
    pub always: bool,
    /// Whether the value is in its range, and the range in words (`None`: any value).
    pub valid: Option<(bool, &'static str)>,
}

impl Dimensionless {
    /// The spring's stretch at θ: θ − `kappa_anchor` itself, or beyond a slack of
    /// ±`kappa_slack` what lies past it (torque −κ·stretch, energy κ·stretch²/2).
    #[inline]
    pub fn spring_stretch(&self, theta: f64) -> f64 {
        let x = theta - self.kappa_anchor;
        x - x.clamp(-self.kappa_slack, self.kappa_slack)
    }

    /// The lobed dry torque's size at θ, c_lobes·(1 + cos(k θ − φ)) (0 without one).
    #[inline]
    pub fn lobed_dry(&self, theta: f64) -> f64 {
        if self.c_lobes == 0.0 {
            return 0.0;
        }
        self.c_lobes * (1.0 + (f64::from(self.c_lobes_k) * theta - self.c_lobes_phase).cos())
    }

    /// The share of the eddy brake's full drag acting at θ, (1 + cos(θ − φ_e))/2.
    #[inline]
    pub fn eddy_share(&self, theta: f64) -> f64 {
        0.5 * (1.0 + (theta - self.eddy_brake_phase).cos())
    }

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
            s_break: 0.0,
            v_break: 0.0,
            gen_c: 0.0,
            gen_w: 0.0,
            kappa: 0.0,
            kappa_slack: 0.0,
            kappa_anchor: 0.0,
            c_rate: 0.0,
            c_lobes: 0.0,
            c_lobes_k: 1,
            c_lobes_phase: 0.0,
            cubic_drag: 0.0,
            eddy_brake: 0.0,
            eddy_brake_phase: 0.0,
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

    /// Every coefficient slot, in one table: its name (as `--param` and the error messages say
    /// it), the symbol titles print, its value, whether titles print it when it is 0, and its
    /// valid range (`None`: any value). [`Dimensionless::validate`] checks the ranges and map
    /// titles list the slots (`pendulum_maps::style::describe_params`), so a new slot is
    /// declared here once. A slot that only means something beside another (k and φ_p of a
    /// position torque, v_s of a breakaway, ω_d of a generator) is left out while that one is 0.
    pub fn slots(&self) -> Vec<Slot> {
        let slot = |name, symbol, value: f64, always, range: Option<(bool, &'static str)>| Slot {
            name,
            symbol,
            value,
            always,
            valid: range.map(|(ok, expected)| (ok && value.is_finite(), expected)),
        };
        const NON_NEG: &str = "a finite value ≥ 0";
        let mut out = vec![
            slot(
                "omega",
                "ω",
                self.omega,
                true,
                Some((self.omega >= 0.0, NON_NEG)),
            ),
            slot("R", "R", self.r, true, Some((self.r >= 0.0, NON_NEG))),
            slot(
                "lambda",
                "λ",
                self.lambda,
                true,
                Some(((0.0..1.0).contains(&self.lambda), "0 ≤ λ < 1")),
            ),
            slot(
                "alpha",
                "α",
                self.alpha,
                false,
                Some((self.alpha >= 0.0, NON_NEG)),
            ),
            slot(
                "beta",
                "β",
                self.beta,
                true,
                Some((self.beta >= 0.0, NON_NEG)),
            ),
            slot(
                "M",
                "M",
                self.m_coulomb,
                true,
                Some((self.m_coulomb >= 0.0, NON_NEG)),
            ),
            slot("c", "c", self.c, false, Some((self.c >= 0.0, NON_NEG))),
            slot(
                "c_rate",
                "dc/dt",
                self.c_rate,
                false,
                Some((self.c_rate >= 0.0, NON_NEG)),
            ),
            slot(
                "c_lobes",
                "c_lobes",
                self.c_lobes,
                false,
                Some((self.c_lobes >= 0.0, NON_NEG)),
            ),
            slot(
                "cubic_drag",
                "γ",
                self.cubic_drag,
                false,
                Some((self.cubic_drag >= 0.0, NON_NEG)),
            ),
            slot(
                "eddy_brake",
                "β_e",
                self.eddy_brake,
                false,
                Some((self.eddy_brake >= 0.0, NON_NEG)),
            ),
            slot("p", "p", self.p, false, None),
        ];
        if self.eddy_brake != 0.0 {
            out.push(slot(
                "eddy_brake_phase",
                "φ_e",
                self.eddy_brake_phase,
                true,
                None,
            ));
        }
        if self.c_lobes != 0.0 {
            out.push(slot(
                "c_lobes_k",
                "k_c",
                f64::from(self.c_lobes_k),
                true,
                None,
            ));
            out.push(slot("c_lobes_phase", "φ_c", self.c_lobes_phase, true, None));
        }
        if self.p != 0.0 {
            out.push(slot("k", "k", f64::from(self.k), true, None));
            out.push(slot("phi_p", "φ_p", self.phi_p, true, None));
        }
        out.push(slot(
            "s_break",
            "s",
            self.s_break,
            false,
            Some((self.s_break >= 0.0, NON_NEG)),
        ));
        let v_ok = self.v_break >= 0.0 && (self.s_break == 0.0 || self.v_break > 0.0);
        let v_break = slot(
            "v_break",
            "v_s",
            self.v_break,
            true,
            Some((v_ok, "v > 0 when s > 0")),
        );
        if self.s_break != 0.0 || !v_break.valid.is_none_or(|v| v.0) {
            out.push(v_break);
        }
        out.push(slot(
            "gen_c",
            "c_g",
            self.gen_c,
            false,
            Some((self.gen_c >= 0.0, NON_NEG)),
        ));
        let gen_w = slot(
            "gen_w",
            "ω_d",
            self.gen_w,
            true,
            Some((self.gen_w >= 0.0, NON_NEG)),
        );
        if self.gen_c != 0.0 || !gen_w.valid.is_none_or(|v| v.0) {
            out.push(gen_w);
        }
        out.extend([
            slot(
                "kappa",
                "κ",
                self.kappa,
                false,
                Some((self.kappa >= 0.0, NON_NEG)),
            ),
            slot(
                "kappa_slack",
                "θ_slack",
                self.kappa_slack,
                false,
                Some((self.kappa_slack >= 0.0, NON_NEG)),
            ),
            slot("kappa_anchor", "θ_anchor", self.kappa_anchor, false, None),
            slot("tan_delta", "tan δ", self.tan_delta, false, None),
            slot("j", "j", self.j, false, Some((self.j > -1.0, "j > −1"))),
            slot("omega_drift", "dω/dt", self.omega_drift, false, None),
        ]);
        out
    }

    /// Checks ranges: damping ≥ 0, λ < 1, j > −1 (the ranges of [`Dimensionless::slots`]).
    pub fn validate(&self) -> Result<(), ModelError> {
        for slot in self.slots() {
            if let Some((false, expected)) = slot.valid {
                return Err(ModelError::OutOfRange {
                    name: slot.name.into(),
                    value: slot.value,
                    expected: expected.into(),
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
        p.effects.set("coulomb_constant", Some(vec![0.004]));
        p.effects.set("position_torque", Some(vec![0.01, 3.0, 0.2]));
        p.effects.set("horizontal_base", Some(vec![0.03]));
        p.effects.set("extra_inertia", Some(vec![0.002]));
        p.effects.set("speed_drift", Some(vec![-0.001]));
        p.effects.set("encoder_offset", Some(vec![0.05]));
        let d = p.to_dimensionless();
        let back = p.with_dimensionless(&d);
        for (a, b) in [
            (back.omega_hz, p.omega_hz),
            (back.crank_r_m, p.crank_r_m),
            (back.rod_l_m, p.rod_l_m),
            (back.a_kg_m, p.a_kg_m),
            (back.b_n_s_m, p.b_n_s_m),
            (back.mu, p.mu),
            (back.effects.value("coulomb_constant.T_c").unwrap(), 0.004),
            (back.effects.value("position_torque.T_p").unwrap(), 0.01),
            (back.effects.value("position_torque.k").unwrap(), 3.0),
            (back.effects.value("position_torque.phi_p").unwrap(), 0.2),
            (back.effects.value("horizontal_base.delta").unwrap(), 0.03),
            (back.effects.value("extra_inertia.J").unwrap(), 0.002),
            (
                back.effects.value("speed_drift.dOmega_dtau").unwrap(),
                -0.001,
            ),
            // A sensor effect: not in the dimensionless set, kept.
            (
                back.effects.value("encoder_offset.theta_off").unwrap(),
                0.05,
            ),
        ] {
            assert!(close(a, b, 1e-12), "{a} vs {b}");
        }
        // Every effect the physical set holds comes back, and no other.
        let names = |p: &Physical| p.effects.iter().map(|(e, _)| e.name()).collect::<Vec<_>>();
        assert_eq!(names(&back), names(&p));
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

    /// The slot table's ranges are what `validate` enforces, each error naming its slot and
    /// range; a slot that means something only beside another is listed only then.
    #[test]
    fn slots_carry_the_ranges_validate_enforces() {
        let err = |d: Dimensionless| d.validate().unwrap_err().to_string();
        let d0 = Dimensionless::default();
        assert!(d0.validate().is_ok());
        let e = err(Dimensionless { lambda: 1.0, ..d0 });
        assert!(e.contains("lambda") && e.contains("0 ≤ λ < 1"), "{e}");
        let e = err(Dimensionless {
            c_rate: -1e-6,
            ..d0
        });
        assert!(e.contains("c_rate"), "{e}");
        let e = err(Dimensionless {
            s_break: 0.01,
            v_break: 0.0,
            ..d0
        });
        assert!(
            e.contains("v_break") && e.contains("v > 0 when s > 0"),
            "{e}"
        );
        let e = err(Dimensionless {
            beta: f64::NAN,
            ..d0
        });
        assert!(e.contains("beta"), "{e}");
        let names = |d: &Dimensionless| d.slots().iter().map(|s| s.name).collect::<Vec<_>>();
        assert!(!names(&d0).contains(&"k") && !names(&d0).contains(&"v_break"));
        let with = Dimensionless {
            p: 0.01,
            s_break: 0.01,
            v_break: 0.1,
            ..d0
        };
        for n in ["k", "phi_p", "v_break"] {
            assert!(names(&with).contains(&n), "{n}");
        }
    }
}
