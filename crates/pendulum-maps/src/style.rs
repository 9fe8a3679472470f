//! Colours and names of the steady-state classes in the figures, shared by every map.

use pendulum_model::SteadyClass;

/// Legend order of the classes in scatter plots, which is also the drawing order (later ones
/// on top): chaos clouds are sparse and stay visible over the rotation branches.
pub const DRAW_ORDER: [SteadyClass; 5] = [
    SteadyClass::RotationCcw,
    SteadyClass::RotationCw,
    SteadyClass::Oscillation,
    SteadyClass::Rest,
    SteadyClass::Chaos,
];

/// The class's colour (Okabe–Ito: rotations vermillion / blue, oscillation bluish green,
/// rest black, chaos reddish purple).
pub fn class_color(c: SteadyClass) -> (u8, u8, u8) {
    match c {
        SteadyClass::RotationCcw => (213, 94, 0),
        SteadyClass::RotationCw => (0, 114, 178),
        SteadyClass::Oscillation => (0, 158, 115),
        SteadyClass::Rest => (0, 0, 0),
        SteadyClass::Chaos => (204, 121, 167),
    }
}

/// Index of the class's colour in [`pendulum_plot::PALETTE`] (for line figures).
pub fn class_palette_index(c: SteadyClass) -> usize {
    match c {
        SteadyClass::RotationCcw => 1,
        SteadyClass::RotationCw => 0,
        SteadyClass::Oscillation => 2,
        SteadyClass::Rest => 6,
        SteadyClass::Chaos => 4,
    }
}

/// Position of a class in [`DRAW_ORDER`].
pub fn draw_index(c: SteadyClass) -> usize {
    DRAW_ORDER.iter().position(|x| *x == c).unwrap_or(0)
}

/// `β = 0.109, M = 0.007, R = 0.7, λ = 0.126` (α and the effect terms when non-zero: every
/// slot of the simulator's coefficients, so that a map of a model with a breakaway or a
/// generator says so in its title).
pub fn describe_params(d: &pendulum_model::Dimensionless, skip: Option<&str>) -> String {
    let parts: Vec<String> = d
        .slots()
        .into_iter()
        .filter(|s| skip != Some(s.name) && (s.always || s.value != 0.0))
        .map(|s| format!("{} = {}", s.symbol, fmt_num(s.value)))
        .collect();
    let mut out = parts.join(", ");
    if d.base_load && skip != Some("base_load") {
        out.push_str(", bearing load with the base's acceleration");
    }
    out
}

/// Up to 4 significant digits, no trailing zeros.
pub fn fmt_num(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (3 - v.abs().log10().floor() as i32).clamp(0, 10) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}
