//! The catalogue of `effects.md`: every effect is one definition (one file in this folder, one
//! entry in [`CATALOGUE`]) from which the rest of the project derives what it needs: parameter
//! keys, units, refit ranges, the SI ↔ dimensionless conversion, `--param`/TOML keys, the
//! simulator's coefficients, the sensor and forcing transform, the survey's designs, report
//! labels and the README's table.
//!
//! Why a trait object list and not an enum: adding an effect must not touch a `match` in other
//! files. The list is walked only when a model is built (once per simulation), never inside the
//! integrator: [`Effect::compile`] writes plain numbers into [`Dimensionless`], the flat
//! coefficient struct the right-hand side reads.
//!
//! Four kinds (`effects.md`): dynamics (a torque in the equation of motion), mass (inertia),
//! input (the forcing as the accelerometer and motor give it: delay, gain, drift) and observation
//! (the encoder's reading: offset). Input and observation effects act through one transform,
//! [`Sensors`], shared by the twin, the fit, discover and replay.

use std::collections::BTreeMap;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::{Dimensionless, ModelError, Physical};

mod accel_delay;
mod accel_gain;
mod bearing_load_base_accel;
mod coulomb_bearing;
mod coulomb_constant;
mod encoder_offset;
mod extra_inertia;
mod generator_rectified;
mod horizontal_base;
mod position_torque;
mod speed_drift;
mod stribeck;
mod viscous_linear;
mod viscous_quadratic;

/// Every effect, in the order of `effects.md` (outputs, reports and the README follow it).
pub static CATALOGUE: &[&dyn Effect] = &[
    &viscous_linear::ViscousLinear,
    &viscous_quadratic::ViscousQuadratic,
    &coulomb_bearing::CoulombBearing,
    &bearing_load_base_accel::BearingLoadBaseAccel,
    &coulomb_constant::CoulombConstant,
    &position_torque::PositionTorque,
    &stribeck::Stribeck,
    &generator_rectified::GeneratorRectified,
    &horizontal_base::HorizontalBase,
    &extra_inertia::ExtraInertia,
    &encoder_offset::EncoderOffset,
    &accel_delay::AccelDelay,
    &accel_gain::AccelGain,
    &speed_drift::SpeedDrift,
];

/// What an effect acts on (`effects.md`'s two tables, the first split by where the term goes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A torque of the equation of motion.
    Dynamics,
    /// Inertia beside the bob's.
    Mass,
    /// The forcing as measured or driven: the accelerometer's delay and gain, the motor's drift.
    Input,
    /// The encoder's reading.
    Observation,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::Dynamics => "dynamics",
            Kind::Mass => "mass",
            Kind::Input => "input",
            Kind::Observation => "observation",
        }
    }
}

/// How the survey (tests/discover.rs) draws a parameter's hidden value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Draw {
    /// Uniform in [lo, hi).
    Uniform(f64, f64),
    /// Uniform in [lo, hi), then a random sign (drawn after the size).
    Signed(f64, f64),
    /// An integer in lo..=hi.
    Int(i32, i32),
}

/// A survey design: the base model discover starts from and the `--param` keys drawn (in this
/// order; the first is the truth discover's estimate is judged against).
#[derive(Debug, Clone, Copy)]
pub struct Survey {
    /// `reference`, `linear` or `dry`: the model in hand that lacks the effect.
    pub base: &'static str,
    pub draws: &'static [(&'static str, Draw)],
}

/// One parameter of an effect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Param {
    /// `effect.symbol` as `--param`, the outputs' columns and reports spell it (the reference
    /// model's own terms use their rig.md names `a`, `b`, `mu`).
    pub key: &'static str,
    /// Its part of the serialized name: `coulomb_constant` + `t_c_nm` is written
    /// `coulomb_constant_t_c_nm` (one parameter) or `t_c_nm` inside the effect's table.
    pub field: &'static str,
    /// SI unit (`1` for a pure number).
    pub unit: &'static str,
    /// Refit search range in SI units; `None`: not refitted (an integer such as k).
    pub fit_range: Option<(f64, f64)>,
    /// Only integers ≥ 1 are valid.
    pub integer: bool,
    /// Value of a parameter not given when another of the effect's is (position_torque's k = 1).
    pub unset: f64,
}

impl Param {
    /// A refitted real parameter.
    pub const fn real(
        key: &'static str,
        field: &'static str,
        unit: &'static str,
        range: (f64, f64),
    ) -> Self {
        Self {
            key,
            field,
            unit,
            fit_range: Some(range),
            integer: false,
            unset: 0.0,
        }
    }
}

/// Another way to give an effect's parameters, converted to its own on reading (the
/// generator's electrical k_e, V_d, R for its c_g, ω_d). Given in full or not at all, and never
/// together with the effect's own parameters (`--param` and TOML alike).
#[derive(Debug, Clone, Copy)]
pub struct Alternative {
    /// Its parameters: `--param` key, serialized field (inside the effect's table), SI unit.
    pub params: &'static [Param],
    /// Their values (in `params`' order) → the effect's own, or what is wrong with them.
    pub convert: fn(&[f64]) -> Result<Vec<f64>, String>,
}

/// How discover's equation-error screen writes a torque that follows θ' through a speed scale
/// that is no coefficient (stribeck's v_s, the generator's ω_d): T = size · f(θ', shape). The
/// screen profiles the shape over `grid` (each value one weighted fit), so the effect needs no
/// column of its own in discover.
#[derive(Debug, Clone, Copy)]
pub struct RateShape {
    /// The shape parameter's key (one of the effect's [`Param`]s), SI.
    pub key: &'static str,
    /// The shape a column holds until profiled (mid-range).
    pub default: f64,
    /// The profile grid, SI, increasing, spanning the parameter's refit range.
    pub grid: &'static [f64],
    /// The torque per unit of the effect's first parameter at speed θ' (rad/s), N·m.
    pub f: fn(f64, f64) -> f64,
}

/// One sample of the measured motion as a weak-form regressor sees it, in the run's
/// dimensionless units (time in 1/ω0, so θ' in units of ω0; accelerations in g).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WeakSample {
    /// θ, rad (unwrapped).
    pub theta: f64,
    /// θ', dimensionless.
    pub theta_dot: f64,
    /// The base's vertical acceleration A_y, in g (0 in a free segment).
    pub a_y: f64,
    /// Its rate dA_y/dτ (dimensionless time).
    pub a_y_dot: f64,
}

impl WeakSample {
    /// sgn θ' (0 at exactly 0).
    pub fn sgn(&self) -> f64 {
        if self.theta_dot > 0.0 {
            1.0
        } else if self.theta_dot < 0.0 {
            -1.0
        } else {
            0.0
        }
    }
}

/// A column of discover's weak-form equation error: the effect's term of the dimensionless
/// equation θ'' = … per unit of its dimensionless coefficient, evaluated at each sample and
/// integrated against the test function, times the run's factor from the SI parameter to that
/// coefficient, so that the regression's coefficient is the SI parameter (the same for every run
/// of a campaign that mixes bobs and cranks). An observation or input effect's column is its
/// first-order change of the equation error (the encoder offset, the accelerometer's lag).
#[derive(Debug, Clone, Copy)]
pub struct Regressor {
    /// A short name for tables and messages.
    pub name: &'static str,
    /// The candidate it belongs to: columns sharing a group enter the regression together
    /// (position_torque's harmonic k: sin kθ and cos kθ); 0 for an effect with one candidate.
    pub group: u32,
    /// Lobes per turn of a term that is one harmonic of θ times a slowly varying factor
    /// (position_torque's sin kθ and cos kθ: k; (1 + A_y) sin θ, A_y cos θ: 1); 0 for a term
    /// that is not. The weak form integrates such a term over each sample's share of its
    /// window exactly (see `pendulum_discover::weak::hat_factor`), where sampling it at the
    /// samples alone aliases a many-lobed torque on a fast-turning run into a slow one, and
    /// biases even a one-lobed one by (θ̇Δt)²/12.
    pub lobes: u32,
    /// The term at one sample.
    pub term: fn(&WeakSample) -> f64,
    /// Dimensionless coefficient per unit of the SI parameter, for a run's m, l, r_b, g.
    pub per_si: fn(&Physical) -> f64,
}

/// A variable a torque can follow (effects.md's list for `unexplained`): discover's generic
/// library describes departures in these, and an effect whose regressor is a function of some of
/// them alone says so ([`Effect::follows`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Variable {
    /// θ̇.
    Rate,
    /// θ, unwrapped (not periodic in a turn).
    Angle,
    /// θ modulo 2π.
    AngleInTurn,
    /// The forcing (crank) phase.
    Phase,
    /// Time along the run.
    Time,
}

impl Variable {
    pub fn label(self) -> &'static str {
        match self {
            Variable::Rate => "dθ/dt",
            Variable::Angle => "θ (unwrapped)",
            Variable::AngleInTurn => "θ (mod 2π)",
            Variable::Phase => "forcing phase",
            Variable::Time => "time",
        }
    }
}

/// A size within the rig's normal tolerances (rig.md), below which discover does not name the
/// effect: the rig itself, not a departure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tolerance {
    /// |size| ≤ this many encoder counts at 4096 per turn (rad): the count is zeroed by hand to
    /// within a few counts at every power-on.
    EncoderCounts(f64),
    /// |size| ≤ this many standard deviations of one accelerometer stamp's timing error (s, as
    /// measured on the campaign): the stamps' own accuracy.
    StampJitter(f64),
    /// |size| ≤ this fraction of the lightest run's m l² (kg·m²): what the point-mass model
    /// itself leaves out (the bob's own moment about its centre, the rod's and the shaft's).
    BobInertia(f64),
    /// |size| ≤ the torque that tilts the lightest-hung run's rest (the smallest m g l over the
    /// campaign's runs, N·m) by this many encoder counts: a torque of the angle that moves no
    /// bob's hanging position by a count is one the encoder cannot place apart from each run's
    /// own hand zeroing, which is good to a few counts.
    RestTilt(f64),
}

impl Tolerance {
    /// The bound, given the campaign's stamp jitter (s), lightest bob inertia (kg·m²) and
    /// smallest gravity torque m g l (N·m).
    pub fn bound(
        self,
        stamp_jitter_s: f64,
        bob_inertia_kg_m2: f64,
        gravity_torque_n_m: f64,
    ) -> f64 {
        let count_rad = 2.0 * std::f64::consts::PI / 4096.0;
        match self {
            Tolerance::EncoderCounts(n) => n * count_rad,
            Tolerance::StampJitter(k) => k * stamp_jitter_s,
            Tolerance::BobInertia(f) => f * bob_inertia_kg_m2,
            Tolerance::RestTilt(n) => n * count_rad * gravity_torque_n_m,
        }
    }
}

/// What [`Effect::decompile`] finds in the coefficients.
#[derive(Debug, Clone, PartialEq)]
pub enum Decompiled {
    /// The coefficients do not carry this effect (a sensor effect): keep the physical value.
    Keep,
    /// The effect's SI values (`None`: absent).
    Set(Option<Vec<f64>>),
}

/// How a damping effect shows in a free decay (no shaker), for `pendulum-explain`'s decay
/// analysis: its dimensionless parameter on the decay's own scale (the torque over I ω_n² =
/// m g a, a the pivot-to-centre-of-mass distance, time in 1/ω_n) and the friction torque it adds
/// per unit of that parameter.
#[derive(Debug)]
pub struct FreeDecay {
    /// The parameter's symbol in the decay's tables.
    pub symbol: &'static str,
    /// Its unit, as reported.
    pub unit: &'static str,
    /// What the parameter is, in words.
    pub meaning: &'static str,
    /// |friction torque| per unit parameter at angle θ with θ'² = `w2` (a free pendulum): the
    /// integrand of the energy it takes over a half swing.
    pub friction: fn(theta: f64, w2: f64) -> f64,
    /// Sets the parameter in the simulator's parameters.
    pub set: fn(&mut Dimensionless, f64),
    /// Finite-difference step floor of its fit.
    pub fd_floor: f64,
}

/// One effect of `effects.md`. Implementations are unit structs in this folder.
pub trait Effect: Sync + std::fmt::Debug {
    /// The stable name of `effects.md`; outputs use exactly this string.
    fn name(&self) -> &'static str;
    fn kind(&self) -> Kind;
    /// Parameters in `effects.md`'s order (none: a switch, such as bearing_load_base_accel).
    fn params(&self) -> &'static [Param];
    /// What it is, one line (the README's table).
    fn what(&self) -> &'static str;
    /// The term it adds, in effects.md's notation (the README's table).
    fn term(&self) -> &'static str;
    /// The survey's design for this effect hidden alone.
    fn survey(&self) -> Survey;

    /// Another way to give its parameters (see [`Alternative`]); stored and written in its own.
    fn alternative(&self) -> Option<&'static Alternative> {
        None
    }

    /// How it shows in a free decay (`None`: not a damping term a decay can resolve).
    fn free_decay(&self) -> Option<&'static FreeDecay> {
        None
    }

    /// Whether its values live in [`Physical`] itself (the reference model's a, b, μ) rather
    /// than in [`Effects`].
    fn in_physical(&self) -> bool {
        false
    }

    /// The effect's SI values in `p` (`None`: absent). The reference model's own terms override
    /// this: their values live in [`Physical`]'s a, b, μ.
    fn get(&self, p: &Physical) -> Option<Vec<f64>> {
        p.effects.get(self.name()).map(<[f64]>::to_vec)
    }

    /// Sets (or, with `None`, removes) the effect's SI values in `p`.
    fn set(&self, p: &mut Physical, values: Option<&[f64]>) {
        p.effects.set(self.name(), values.map(<[f64]>::to_vec));
    }

    /// Adds the effect's term to the simulator's coefficients (`values` SI, from [`Effect::get`]).
    /// Called once per model, never per step.
    fn compile(&self, values: &[f64], p: &Physical, d: &mut Dimensionless) {
        let _ = (values, p, d);
    }

    /// The inverse of [`Effect::compile`] with `p`'s m, l, g, r_b.
    fn decompile(&self, d: &Dimensionless, p: &Physical) -> Decompiled {
        let _ = (d, p);
        Decompiled::Keep
    }

    /// Adds the effect to the sensor and forcing transform (input and observation effects).
    fn sense(&self, values: &[f64], s: &mut Sensors) {
        let _ = (values, s);
    }

    /// Whether its size (first parameter) is physically positive: a loss that takes energy out
    /// (a negative one would feed energy in) or an inertia. Discover never accepts such an
    /// effect with a size ≤ 0.
    fn positive(&self) -> bool {
        false
    }

    /// Whether it adds to the dry friction's sticking capacity (what holds the pendulum at
    /// rest), which discover's trajectory refit judges without the runs' still tails.
    fn sets_sticking_capacity(&self) -> bool {
        false
    }

    /// A torque following θ' through a speed scale (see [`RateShape`]).
    fn rate_shape(&self) -> Option<&'static RateShape> {
        None
    }

    /// Its columns in discover's weak-form equation error (see [`Regressor`]); none: not
    /// discovered by regression (a shaped torque gets its column from [`Effect::rate_shape`]).
    fn regressors(&self) -> &'static [Regressor] {
        &[]
    }

    /// The SI estimate and standard error of its size (the first parameter, or what
    /// [`Effect::size_key`] names) from its group's regression coefficients `(value, se)`, in
    /// [`Effect::regressors`]' order. Default: the one coefficient itself.
    fn estimate(&self, coef: &[(f64, f64)]) -> (f64, f64) {
        coef.first().copied().unwrap_or((f64::NAN, f64::NAN))
    }

    /// The parameter its size is judged by: its first, or (a switch without parameters, such as
    /// bearing_load_base_accel) the reference parameter it changes.
    fn size_key(&self) -> Option<&'static str> {
        self.params().first().map(|p| p.key)
    }

    /// Whether `size` is in its physical range (default: a [`Effect::positive`] size must be
    /// above 0; any other finite). Outside it, discover has found a departure the effect does
    /// not describe.
    fn possible(&self, size: f64) -> bool {
        if self.positive() {
            size > 0.0
        } else {
            size.is_finite()
        }
    }

    /// The rig's own tolerance on its size, if any (see [`Tolerance`]).
    fn tolerance(&self) -> Option<Tolerance> {
        None
    }

    /// Whether its size is read directly by where each run's free decay hangs (the centre of its
    /// swings: the hanging position as the encoder reports it). Only a shift of the reading
    /// itself is: a torque that moves the equilibrium shifts it by its size over each run's
    /// m g l, which differs from bob to bob. Default: no.
    fn reads_hanging_position(&self) -> bool {
        false
    }

    /// Whether its torque is a function of the angle alone (no rate, no forcing, no time, no
    /// sensor): then one size holds in the windows where the pendulum moves fast and in those
    /// where it moves slowly. A reading error of the angle (an off-centre code disc: its
    /// reading's second derivative carries θ̇² sin(θ − φ)) or a torque of the rate that the
    /// angle's columns only approximate does not hold one size there (discover's
    /// `one_size_at_every_speed`). Default: no.
    fn torque_of_the_angle_alone(&self) -> bool {
        false
    }

    /// Whether the accelerometer's x axis reads its size directly: the slope of the horizontal
    /// acceleration on the vertical one over a forced run is the tangent of the size, whether
    /// the pendulum moves or not (rig.md: x horizontal in the pendulum's plane, fixed to the
    /// worktable). Only a tilt of the guide's motion itself is. Default: no.
    fn reads_horizontal_slope(&self) -> bool {
        false
    }

    /// The variables its torque follows when its regressor is a function of them alone (so that
    /// discover's generic library can describe the same departure in them with a freer shape);
    /// empty for effects coupled to the forcing or the sensors. Default: θ̇ for a shaped torque.
    fn follows(&self) -> &'static [Variable] {
        if self.rate_shape().is_some() {
            &[Variable::Rate]
        } else {
            &[]
        }
    }

    /// The SI unit of its size.
    fn size_unit(&self) -> &'static str {
        self.params().first().map_or("1", |p| p.unit)
    }

    /// A reference-model term whose column this effect's replaces in the regression
    /// (bearing_load_base_accel: the bearing load with the base's acceleration in it). Offered
    /// only where the model in hand has that term.
    fn replaces(&self) -> Option<&'static str> {
        None
    }

    /// The catalogue effect this one becomes in a limit of its extra parameters (stribeck, as
    /// v_s grows past the swings' speeds: a constant dry torque, coulomb_constant). Where the
    /// two describe the data about equally well, the simpler one is the finding.
    fn generalises(&self) -> Option<&'static str> {
        None
    }

    /// The start of its refit from the screen, in [`Effect::params`]' order: given the size
    /// (already inside its range), its group's coefficients and the group. Default: the size,
    /// then each further parameter's `unset` value.
    fn refit_start(&self, size: f64, coef: &[f64], group: u32) -> Vec<f64> {
        let _ = (coef, group);
        let mut values: Vec<f64> = self.params().iter().map(|p| p.unset).collect();
        if let Some(v) = values.first_mut() {
            *v = size;
        }
        values
    }
}

/// The effect called `name`.
pub fn by_name(name: &str) -> Option<&'static dyn Effect> {
    CATALOGUE.iter().copied().find(|e| e.name() == name)
}

/// The catalogue's names, in its order.
pub fn names() -> Vec<&'static str> {
    CATALOGUE.iter().map(|e| e.name()).collect()
}

/// A parameter of the catalogue, by position: Copy, comparable and hashable, for fit specs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EffectParam {
    effect: u16,
    param: u16,
}

impl EffectParam {
    /// The parameter whose key is `key` (`coulomb_constant.T_c`, `b`), or whose effect is `key`
    /// (its first refitted parameter: `coulomb_constant`, `position_torque`).
    pub fn find(key: &str) -> Option<Self> {
        for (ei, e) in CATALOGUE.iter().enumerate() {
            for (pi, p) in e.params().iter().enumerate() {
                if p.key == key {
                    return Some(Self {
                        effect: ei as u16,
                        param: pi as u16,
                    });
                }
            }
            if e.name() == key {
                let pi = e.params().iter().position(|p| p.fit_range.is_some())?;
                return Some(Self {
                    effect: ei as u16,
                    param: pi as u16,
                });
            }
        }
        None
    }

    /// Like [`EffectParam::find`], for keys the code names: panics on a key the catalogue lacks.
    pub fn of(key: &str) -> Self {
        Self::find(key).unwrap_or_else(|| panic!("no catalogue parameter {key:?}"))
    }

    /// Every refitted parameter of the catalogue, in its order.
    pub fn all_fitted() -> Vec<Self> {
        let mut out = Vec::new();
        for (ei, e) in CATALOGUE.iter().enumerate() {
            for (pi, p) in e.params().iter().enumerate() {
                if p.fit_range.is_some() {
                    out.push(Self {
                        effect: ei as u16,
                        param: pi as u16,
                    });
                }
            }
        }
        out
    }

    pub fn effect(self) -> &'static dyn Effect {
        CATALOGUE[self.effect as usize]
    }

    pub fn index(self) -> usize {
        self.param as usize
    }

    pub fn def(self) -> &'static Param {
        &self.effect().params()[self.param as usize]
    }

    /// The name a fit spec is written with: the effect's name for its first refitted parameter
    /// (`effects = ["coulomb_constant"]`), else the parameter's key.
    pub fn spec_name(self) -> &'static str {
        let e = self.effect();
        let first = e.params().iter().position(|p| p.fit_range.is_some());
        if first == Some(self.index()) && self.def().key.contains('.') {
            e.name()
        } else {
            self.def().key
        }
    }

    /// The value in `p` (0 when the effect is absent).
    pub fn value(self, p: &Physical) -> f64 {
        self.effect()
            .get(p)
            .map_or(0.0, |v| v.get(self.index()).copied().unwrap_or(0.0))
    }

    /// Sets the value in `p`, switching the effect on (its other parameters at their `unset`
    /// value) when it was absent.
    pub fn apply(self, v: f64, p: &mut Physical) {
        let e = self.effect();
        let mut vals = e
            .get(p)
            .unwrap_or_else(|| e.params().iter().map(|q| q.unset).collect());
        vals[self.index()] = v;
        e.set(p, Some(&vals));
    }
}

/// Effects of `effects.md` beyond the reference model, in SI units, by catalogue name; an
/// absent name is an absent effect. The reference model's own terms (a, b, μ) live in
/// [`Physical`], not here.
///
/// Serialized as before the catalogue (twin cases, parameter files): a switch as
/// `name = true`, a one-parameter effect as `name_field = value`, others as a table
/// `name = { field = value, … }`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Effects {
    values: BTreeMap<&'static str, Vec<f64>>,
}

impl Effects {
    /// The SI values of effect `name` (empty for a switch), if present.
    pub fn get(&self, name: &str) -> Option<&[f64]> {
        self.values.get(name).map(Vec::as_slice)
    }

    /// Parameter `key` (`coulomb_constant.T_c`) if its effect is present.
    pub fn value(&self, key: &str) -> Option<f64> {
        let ep = EffectParam::find(key)?;
        self.get(ep.effect().name())?.get(ep.index()).copied()
    }

    /// Whether effect `name` is present.
    pub fn has(&self, name: &str) -> bool {
        self.values.contains_key(name)
    }

    /// Sets or removes effect `name` (panics on a name the catalogue lacks: a programming error).
    pub fn set(&mut self, name: &str, values: Option<Vec<f64>>) {
        let e = by_name(name).unwrap_or_else(|| panic!("no catalogue effect {name:?}"));
        match values {
            Some(v) => {
                assert_eq!(v.len(), e.params().len(), "{name}: parameter count");
                self.values.insert(e.name(), v);
            }
            None => {
                self.values.remove(e.name());
            }
        }
    }

    /// Sets parameter `key`, switching its effect on when absent.
    pub fn set_value(&mut self, key: &str, v: f64) {
        let ep = EffectParam::of(key);
        let e = ep.effect();
        let vals = self
            .values
            .entry(e.name())
            .or_insert_with(|| e.params().iter().map(|q| q.unset).collect());
        vals[ep.index()] = v;
    }

    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    pub fn clear(&mut self) {
        self.values.clear();
    }

    /// Present effects with their values, in the catalogue's order.
    pub fn iter(&self) -> impl Iterator<Item = (&'static dyn Effect, &[f64])> + '_ {
        CATALOGUE
            .iter()
            .filter_map(|e| self.values.get(e.name()).map(|v| (*e, v.as_slice())))
    }

    /// `[truth.effects]` lines of a twin case, one per effect (TOML inline tables).
    pub fn toml_lines(&self) -> String {
        let num = |p: &Param, v: f64| {
            if p.integer {
                format!("{}", v as i64)
            } else {
                format!("{v}")
            }
        };
        let mut out = Vec::new();
        for (e, v) in self.iter() {
            let ps = e.params();
            out.push(match ps.len() {
                0 => format!("{} = true", e.name()),
                1 => format!("{}_{} = {}", e.name(), ps[0].field, num(&ps[0], v[0])),
                _ => {
                    let fields: Vec<String> = ps
                        .iter()
                        .zip(v)
                        .map(|(p, &x)| format!("{} = {}", p.field, num(p, x)))
                        .collect();
                    format!("{} = {{ {} }}", e.name(), fields.join(", "))
                }
            });
        }
        out.join("\n")
    }
}

/// One serialized entry: a switch, a number or a table of numbers.
#[derive(Serialize, Deserialize)]
#[serde(untagged)]
enum Raw {
    Switch(bool),
    Number(f64),
    Table(BTreeMap<String, f64>),
}

impl Serialize for Effects {
    /// Every stored effect in the catalogue's order, an absent one as `null` (a switch as
    /// `false`): the form truth files had before the catalogue, which readers of them expect.
    /// TOML leaves the nulls out.
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let stored: Vec<&dyn Effect> = CATALOGUE
            .iter()
            .copied()
            .filter(|e| !e.in_physical())
            .collect();
        let mut map = s.serialize_map(Some(stored.len()))?;
        for e in stored {
            let ps = e.params();
            let v = self.get(e.name());
            let key = serial_key(e);
            match (ps.len(), v) {
                (0, v) => map.serialize_entry(&key, &Raw::Switch(v.is_some()))?,
                (_, None) => map.serialize_entry(&key, &Option::<Raw>::None)?,
                (1, Some(v)) => map.serialize_entry(&key, &Raw::Number(v[0]))?,
                (_, Some(v)) => map.serialize_entry(
                    &key,
                    &Raw::Table(
                        ps.iter()
                            .map(|p| p.field.to_string())
                            .zip(v.iter().copied())
                            .collect(),
                    ),
                )?,
            }
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for Effects {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let raw = BTreeMap::<String, Option<Raw>>::deserialize(d)?;
        let mut out = Effects::default();
        for (key, value) in raw {
            let found = CATALOGUE.iter().copied().find(|e| serial_key(*e) == key);
            let Some(e) = found else {
                let expected: Vec<String> = CATALOGUE.iter().map(|e| serial_key(*e)).collect();
                return Err(D::Error::custom(format!(
                    "unknown effect {key:?}: expected one of {}",
                    expected.join(", ")
                )));
            };
            let ps = e.params();
            // `null`: absent (truth files list every effect).
            let Some(value) = value else { continue };
            let value = match (value, e.alternative()) {
                (Raw::Table(t), Some(alt))
                    if alt.params.iter().any(|q| t.contains_key(q.field)) =>
                {
                    let own: Vec<&str> = ps.iter().map(|q| q.field).collect();
                    let other: Vec<&str> = alt.params.iter().map(|q| q.field).collect();
                    let both_forms = || {
                        format!(
                            "{key}: give either {} or {}, not both",
                            own.join(", "),
                            other.join(", ")
                        )
                    };
                    if let Some(extra) = t.keys().find(|k| !other.contains(&k.as_str())) {
                        return Err(D::Error::custom(if own.contains(&extra.as_str()) {
                            both_forms()
                        } else {
                            format!(
                                "{key}: unknown field {extra:?}: expected {} or {}",
                                own.join(", "),
                                other.join(", ")
                            )
                        }));
                    }
                    let mut v = Vec::with_capacity(other.len());
                    for f in &other {
                        v.push(*t.get(*f).ok_or_else(|| {
                            D::Error::custom(format!(
                                "{key}: missing field {f:?} (given as {})",
                                other.join(", ")
                            ))
                        })?);
                    }
                    let own_values =
                        (alt.convert)(&v).map_err(|m| D::Error::custom(format!("{key}: {m}")))?;
                    Raw::Table(own.iter().map(|f| f.to_string()).zip(own_values).collect())
                }
                (value, _) => value,
            };
            let vals = match (value, ps.len()) {
                (Raw::Switch(on), 0) => on.then(Vec::new),
                (Raw::Number(v), 1) => Some(vec![v]),
                (Raw::Table(mut t), n) if n > 1 => {
                    let mut v = Vec::with_capacity(n);
                    for p in ps {
                        v.push(t.remove(p.field).ok_or_else(|| {
                            D::Error::custom(format!("{key}: missing field {:?}", p.field))
                        })?);
                    }
                    if let Some(extra) = t.keys().next() {
                        return Err(D::Error::custom(format!(
                            "{key}: unknown field {extra:?}: expected {}",
                            ps.iter().map(|p| p.field).collect::<Vec<_>>().join(", ")
                        )));
                    }
                    Some(v)
                }
                _ => {
                    return Err(D::Error::custom(format!(
                        "{key}: expected {}",
                        match ps.len() {
                            0 => "true or false".to_string(),
                            1 => "a number".to_string(),
                            _ => "a table".to_string(),
                        }
                    )))
                }
            };
            if let Some(v) = vals {
                for (p, x) in ps.iter().zip(&v) {
                    if !x.is_finite() || (p.integer && (*x < 1.0 || x.fract() != 0.0)) {
                        return Err(D::Error::custom(format!(
                            "{key}.{}: {x} is not {}",
                            p.field,
                            if p.integer {
                                "an integer ≥ 1"
                            } else {
                                "a finite number"
                            }
                        )));
                    }
                }
                out.values.insert(e.name(), v);
            }
        }
        Ok(out)
    }
}

/// The serialized key of an effect (see [`Effects`]).
fn serial_key(e: &dyn Effect) -> String {
    match e.params() {
        [p] => format!("{}_{}", e.name(), p.field),
        _ => e.name().to_string(),
    }
}

/// Every `--param` key of the effects (`coulomb_constant.T_c`, a switch's `name.on`), in the
/// catalogue's order; the reference model's own `a`, `b`, `mu` are physical keys.
pub fn param_keys() -> Vec<&'static str> {
    let mut out = Vec::new();
    for e in CATALOGUE {
        if e.params().is_empty() {
            out.push(switch_key(*e));
        }
        out.extend(e.params().iter().map(|p| p.key).filter(|k| k.contains('.')));
        if let Some(alt) = e.alternative() {
            out.extend(alt.params.iter().map(|p| p.key));
        }
    }
    out
}

/// The effect whose [`Alternative`] has `--param` key `key`, and the key's position in it.
pub fn alternative_key(key: &str) -> Option<(&'static dyn Effect, usize)> {
    CATALOGUE.iter().copied().find_map(|e| {
        let i = e.alternative()?.params.iter().position(|p| p.key == key)?;
        Some((e, i))
    })
}

/// Applies the [`Alternative`] assignments of one `--param` list to `p`, effect by effect:
/// `given` holds (key, value) in order (the last of a repeated key wins), `own_given` the
/// effect's own keys the same list assigns. Refuses both forms at once and an incomplete one.
pub fn apply_alternatives(
    p: &mut Physical,
    given: &[(&str, f64)],
    own_given: &[&str],
) -> Result<(), ModelError> {
    for e in CATALOGUE {
        let Some(alt) = e.alternative() else { continue };
        let mut vals: Vec<Option<f64>> = vec![None; alt.params.len()];
        for (k, v) in given {
            if let Some(i) = alt.params.iter().position(|q| q.key == *k) {
                vals[i] = Some(*v);
            }
        }
        if vals.iter().all(Option::is_none) {
            continue;
        }
        let own: Vec<&str> = e.params().iter().map(|q| q.key).collect();
        let other: Vec<&str> = alt.params.iter().map(|q| q.key).collect();
        if let Some(k) = own_given.iter().find(|k| own.contains(k)) {
            return Err(ModelError::BadInput(format!(
                "{}: {k} given together with {}: give either {} or {}, not both",
                e.name(),
                other.join(", "),
                own.join(", "),
                other.join(", ")
            )));
        }
        let missing: Vec<&str> = other
            .iter()
            .zip(&vals)
            .filter(|(_, v)| v.is_none())
            .map(|(k, _)| *k)
            .collect();
        if !missing.is_empty() {
            return Err(ModelError::BadInput(format!(
                "{}: {} missing (its parameters given as {} need all of them)",
                e.name(),
                missing.join(", "),
                other.join(", ")
            )));
        }
        let v: Vec<f64> = vals.into_iter().flatten().collect();
        let own_values =
            (alt.convert)(&v).map_err(|m| ModelError::BadInput(format!("{}: {m}", e.name())))?;
        e.set(p, Some(&own_values));
    }
    Ok(())
}

/// The `--param` key of a switch: `name.on`.
fn switch_key(e: &dyn Effect) -> &'static str {
    static KEYS: std::sync::OnceLock<Vec<(&'static str, String)>> = std::sync::OnceLock::new();
    let keys = KEYS.get_or_init(|| {
        CATALOGUE
            .iter()
            .map(|e| (e.name(), format!("{}.on", e.name())))
            .collect()
    });
    keys.iter()
        .find(|(n, _)| *n == e.name())
        .map(|(_, k)| k.as_str())
        .expect("every effect has a switch key")
}

/// Applies one `--param` effect assignment to `p`. Returns `Ok(false)` when `key` is no effect
/// key (a physical or dimensionless one).
pub fn apply_key(p: &mut Physical, key: &str, v: f64) -> Result<bool, ModelError> {
    for e in CATALOGUE {
        if e.params().is_empty() && key == switch_key(*e) {
            e.set(p, (v != 0.0).then_some(&[]));
            return Ok(true);
        }
        if let Some(i) = e.params().iter().position(|q| q.key == key) {
            if e.params()[i].integer && (v < 1.0 || v.fract() != 0.0) {
                return Err(ModelError::BadParamValue {
                    key: key.to_string(),
                    value: v.to_string(),
                    expected: "an integer ≥ 1".into(),
                });
            }
            EffectParam {
                effect: CATALOGUE
                    .iter()
                    .position(|x| x.name() == e.name())
                    .expect("in the catalogue") as u16,
                param: i as u16,
            }
            .apply(v, p);
            return Ok(true);
        }
    }
    Ok(false)
}

/// The input and observation effects as one transform between the pendulum and what the
/// sensors report: used by the twin to make captures, and by the fit, discover and replay to
/// compare a model with them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sensors {
    /// `encoder_offset`: measured θ = true θ + this, rad.
    pub encoder_offset_rad: f64,
    /// `accel_delay`: the accelerometer's sample stamped τ shows the motion at τ − this, s.
    pub accel_delay_s: f64,
    /// `accel_gain`: measured acceleration = (1 + this) × true.
    pub accel_gain_k_a: f64,
}

impl Default for Sensors {
    fn default() -> Self {
        Self {
            encoder_offset_rad: 0.0,
            accel_delay_s: 0.0,
            accel_gain_k_a: 0.0,
        }
    }
}

impl Sensors {
    /// The transform of `p`'s input and observation effects.
    pub fn of(p: &Physical) -> Self {
        let mut s = Sensors::default();
        for e in CATALOGUE {
            if let Some(v) = e.get(p) {
                e.sense(&v, &mut s);
            }
        }
        s
    }

    /// The encoder's angle for the true θ, rad.
    pub fn theta_measured(&self, theta_rad: f64) -> f64 {
        theta_rad + self.encoder_offset_rad
    }

    /// The true θ for the encoder's angle, rad.
    pub fn theta_true(&self, theta_measured_rad: f64) -> f64 {
        theta_measured_rad - self.encoder_offset_rad
    }

    /// The time whose motion the accelerometer's sample stamped `t_s` shows, s.
    pub fn accel_shows_s(&self, t_s: f64) -> f64 {
        t_s - self.accel_delay_s
    }

    /// The accelerometer's reading of a true acceleration (any unit).
    pub fn accel_measured(&self, a: f64) -> f64 {
        a * (1.0 + self.accel_gain_k_a)
    }

    /// Crank phase by which the true forcing leads a clock aligned on the accelerometer's peak,
    /// rad, for dimensionless crank speed `omega` and ω0 in rad/s.
    pub fn forcing_lead_rad(&self, omega: f64, omega0_rad_s: f64) -> f64 {
        omega * self.accel_delay_s * omega0_rad_s
    }
}

/// The README's effect table (checked against README.md by a test).
pub fn markdown_table() -> String {
    let mut s = String::from(
        "| name | kind | parameters (`--param` key, SI unit) | what it is | term |\n|---|---|---|---|---|\n",
    );
    for e in CATALOGUE {
        let params = if e.params().is_empty() {
            format!("`{}` (switch)", switch_key(*e))
        } else {
            let list = |ps: &[Param]| {
                ps.iter()
                    .map(|p| format!("`{}` {}", p.key, p.unit))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            match e.alternative() {
                None => list(e.params()),
                Some(alt) => format!("{}; or {}", list(e.params()), list(alt.params)),
            }
        };
        s.push_str(&format!(
            "| `{}` | {} | {} | {} | {} |\n",
            e.name(),
            e.kind().name(),
            params,
            e.what(),
            e.term()
        ));
    }
    s
}

#[cfg(test)]
mod tests;
