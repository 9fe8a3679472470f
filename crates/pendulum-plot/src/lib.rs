//! PNG figures for the pendulum reports.
//!
//! Three figure kinds, all plain data in and a PNG file out:
//!
//! * [`Figure`]: one or more stacked [`Panel`]s of line / point [`Series`] (time series,
//!   spectra, decay envelopes, with an optional logarithmic y axis);
//! * [`CategoryScatter`]: points coloured by a category index (bifurcation diagrams);
//! * [`Heatmap`]: values on a grid of cells with a colour bar (zone maps), and
//!   [`save_heatmaps_side_by_side`] to compare several maps in one image.
//!
//! The crate knows nothing about pendulums. It ships its own font (DejaVu Sans, see
//! `assets/DejaVuSans-LICENSE.txt`), so it renders the same on a machine with no system
//! fonts. Colours come from the Okabe–Ito palette ([`PALETTE`]) and heat maps use viridis,
//! both readable with the common forms of colour blindness.
//!
//! Bad data never panics: NaN / infinite values are skipped (they split lines), empty
//! series render as an axis frame saying "no data", constant data gets a padded range.
//! Long series are decimated to a few points per pixel column before drawing, so a
//! million-point series renders in well under a second. Files are written atomically
//! (a temporary file next to the target, then a rename).

mod axis;
mod common;
mod heatmap;
mod lines;
mod scatter;

use std::path::{Path, PathBuf};

pub use common::{floor_span, png_text_of, set_png_text};
pub use heatmap::save_heatmaps_side_by_side;

/// Okabe–Ito colour-blind-safe palette, in the order series are coloured by default
/// (blue, vermillion, bluish green, orange, reddish purple, sky blue, black, yellow).
/// [`Series::color`] indexes into it (modulo its length).
pub const PALETTE: [(u8, u8, u8); 8] = common::OKABE_ITO;

/// Default image size of every figure kind (pixels).
pub const DEFAULT_SIZE: (u32, u32) = (1200, 700);

/// How a [`Series`] is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SeriesStyle {
    /// Points joined by a line; NaN / infinite values break the line.
    #[default]
    Line,
    /// Unjoined dots.
    Points,
    /// A line with a dot on every point.
    LinePoints,
}

/// One data series of a [`Panel`]: `y[i]` against `x[i]` (extra elements of the longer
/// vector are ignored).
#[derive(Debug, Clone, Default)]
pub struct Series {
    /// Legend text; an empty label keeps the series out of the legend.
    pub label: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    pub style: SeriesStyle,
    /// Index into [`PALETTE`]; `None` = the series' position in its panel.
    pub color: Option<usize>,
}

/// One set of axes.
#[derive(Debug, Clone, Default)]
pub struct Panel {
    pub title: String,
    /// Axis label, with its unit, e.g. `"time (s)"`.
    pub x_label: String,
    pub y_label: String,
    pub series: Vec<Series>,
    /// Logarithmic y axis (values <= 0 are skipped).
    pub log_y: bool,
    /// Fixed y range `(low, high)`; `None` = fit the data. Data outside is clipped.
    pub y_range: Option<(f64, f64)>,
}

/// Panels stacked vertically (each with its own axes) under a common title.
#[derive(Debug, Clone)]
pub struct Figure {
    pub title: String,
    pub panels: Vec<Panel>,
    /// Image size in pixels (the whole image, all panels).
    pub width: u32,
    pub height: u32,
}

impl Default for Figure {
    fn default() -> Self {
        Self {
            title: String::new(),
            panels: Vec::new(),
            width: DEFAULT_SIZE.0,
            height: DEFAULT_SIZE.1,
        }
    }
}

impl Figure {
    /// Render to a PNG file (written to a temporary file first, then renamed over `path`).
    pub fn save_png(&self, path: &Path) -> Result<(), PlotError> {
        lines::save(self, path)
    }
}

/// Scatter of points coloured by category, with the legend outside the plot
/// (bifurcation diagrams: x = drive frequency, y = a steady-state value, category = class).
#[derive(Debug, Clone)]
pub struct CategoryScatter {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x: Vec<f64>,
    pub y: Vec<f64>,
    /// Category index of each point (same length as `x` and `y`; each below 1000).
    pub category: Vec<usize>,
    /// Legend name of each category index; missing names show as "category N".
    pub category_names: Vec<String>,
    /// RGB colour per category index; `None` (or too short) = [`PALETTE`] order.
    pub category_colors: Option<Vec<(u8, u8, u8)>>,
    pub width: u32,
    pub height: u32,
}

impl Default for CategoryScatter {
    fn default() -> Self {
        Self {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            x: Vec::new(),
            y: Vec::new(),
            category: Vec::new(),
            category_names: Vec::new(),
            category_colors: None,
            width: DEFAULT_SIZE.0,
            height: DEFAULT_SIZE.1,
        }
    }
}

impl CategoryScatter {
    /// Render to a PNG file (atomically, like [`Figure::save_png`]).
    pub fn save_png(&self, path: &Path) -> Result<(), PlotError> {
        scatter::save(self, path)
    }
}

/// Heat map on a grid of cells: cell `(ix, iy)` spans `x_edges[ix]..x_edges[ix + 1]` by
/// `y_edges[iy]..y_edges[iy + 1]` and has the value `values[iy][ix]` (NaN = no data, drawn
/// grey). Colours follow viridis from `vmin` to `vmax` (or, with `diverging`, a blue–white–red
/// scale whose white is the middle, for differences centred on 0), shown on a colour bar
/// labelled `value_label`.
#[derive(Debug, Clone)]
pub struct Heatmap {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    /// `nx + 1` cell edges along x.
    pub x_edges: Vec<f64>,
    /// `ny + 1` cell edges along y.
    pub y_edges: Vec<f64>,
    /// `ny` rows of `nx` values: `values[iy][ix]`.
    pub values: Vec<Vec<f64>>,
    /// Colour-bar label, with its unit.
    pub value_label: String,
    /// Colour-scale ends; `None` = the data's min / max. Values outside are clamped.
    pub vmin: Option<f64>,
    pub vmax: Option<f64>,
    /// Cells that get a marker dot, as `(ix, iy)` (same order as the edges, i.e. the cell
    /// holding `values[iy][ix]`). Out-of-range entries are ignored.
    pub marks: Vec<(usize, usize)>,
    /// A diverging colour scale (blue below the middle of `vmin..vmax`, white at it, red above)
    /// instead of viridis: for signed differences, where 0 must read as "no difference".
    pub diverging: bool,
    pub width: u32,
    pub height: u32,
}

impl Default for Heatmap {
    fn default() -> Self {
        Self {
            title: String::new(),
            x_label: String::new(),
            y_label: String::new(),
            x_edges: Vec::new(),
            y_edges: Vec::new(),
            values: Vec::new(),
            value_label: String::new(),
            vmin: None,
            vmax: None,
            marks: Vec::new(),
            diverging: false,
            width: 1000,
            height: DEFAULT_SIZE.1,
        }
    }
}

impl Heatmap {
    /// Render to a PNG file (atomically, like [`Figure::save_png`]).
    pub fn save_png(&self, path: &Path) -> Result<(), PlotError> {
        heatmap::save(self, path)
    }
}

/// Why a figure could not be written. Every variant names the target file.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The input cannot be drawn (mismatched lengths, bad grid shape, absurd image size).
    #[error("cannot plot {path}: {what}")]
    InvalidData { path: PathBuf, what: String },
    /// The drawing library failed (rendering or PNG encoding).
    #[error("drawing {path} failed: {what}")]
    Draw { path: PathBuf, what: String },
    /// Creating the directory, or moving the finished file into place, failed.
    #[error("{what} for {path} failed: {source}")]
    Io {
        path: PathBuf,
        what: String,
        #[source]
        source: std::io::Error,
    },
}
