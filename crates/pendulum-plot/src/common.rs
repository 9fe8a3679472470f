//! Shared pieces: font, colours, ranges, tick labels, decimation, clipping, atomic saving.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, OnceLock};

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;

use crate::PlotError;

/// The bundled font (DejaVu Sans 2.37, Bitstream Vera licence: assets/DejaVuSans-LICENSE.txt).
static FONT_BYTES: &[u8] = include_bytes!("../assets/DejaVuSans.ttf");

/// Family name the font is registered under; plotters' defaults also ask for "sans-serif".
pub const FONT: &str = "sans-serif";

pub type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// Okabe & Ito (2008), ordered so that the first colours are the most distinct on white.
pub const OKABE_ITO: [(u8, u8, u8); 8] = [
    (0, 114, 178),   // blue
    (213, 94, 0),    // vermillion
    (0, 158, 115),   // bluish green
    (230, 159, 0),   // orange
    (204, 121, 167), // reddish purple
    (86, 180, 233),  // sky blue
    (0, 0, 0),       // black
    (240, 228, 66),  // yellow
];

pub const TEXT: RGBColor = RGBColor(25, 25, 25);
pub const GRID: RGBColor = RGBColor(225, 225, 225);
pub const NO_DATA: RGBColor = RGBColor(200, 200, 200);

pub fn palette(i: usize) -> RGBColor {
    let (r, g, b) = OKABE_ITO[i % OKABE_ITO.len()];
    RGBColor(r, g, b)
}

/// Register the bundled font with plotters once per process.
fn ensure_font() -> Result<(), String> {
    static DONE: OnceLock<Result<(), String>> = OnceLock::new();
    DONE.get_or_init(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, FONT_BYTES)
            .map_err(|_| "the bundled font could not be parsed".to_string())
    })
    .clone()
}

/// Font size `px` scaled to the image (sizes are designed for 1200×700).
pub fn font(scale: f64, px: f64) -> TextStyle<'static> {
    (FONT, px * scale).into_font().color(&TEXT)
}

pub fn scale_for(width: u32, height: u32) -> f64 {
    let area = f64::from(width) * f64::from(height) / (1200.0 * 700.0);
    area.sqrt().clamp(0.85, 3.0)
}

pub fn check_size(path: &Path, width: u32, height: u32) -> Result<(), PlotError> {
    if !(64..=16384).contains(&width) || !(64..=16384).contains(&height) {
        return Err(invalid(
            path,
            format!("image size {width}x{height} is outside 64..=16384 pixels per side"),
        ));
    }
    Ok(())
}

pub fn invalid(path: &Path, what: impl Into<String>) -> PlotError {
    PlotError::InvalidData {
        path: path.to_path_buf(),
        what: what.into(),
    }
}

/// Draw with `render` into a temporary PNG beside `path`, then rename it over `path`.
pub fn save_atomic(
    path: &Path,
    size: (u32, u32),
    render: impl FnOnce(&Area<'_>) -> Result<(), String>,
) -> Result<(), PlotError> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let draw_err = |what: String| PlotError::Draw {
        path: path.to_path_buf(),
        what,
    };
    ensure_font().map_err(draw_err)?;
    let file_name = path
        .file_name()
        .ok_or_else(|| invalid(path, "the path has no file name"))?
        .to_string_lossy()
        .into_owned();
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).map_err(|source| PlotError::Io {
        path: path.to_path_buf(),
        what: format!("creating directory {}", dir.display()),
        source,
    })?;
    // The bitmap encoder picks the format from the extension, so the temporary file ends in .png.
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let tmp = dir.join(format!(".{file_name}.{}-{n}.tmp.png", std::process::id()));
    let result = {
        let root = BitMapBackend::new(&tmp, size).into_drawing_area();
        let drawn = root
            .fill(&WHITE)
            .map_err(|e| e.to_string())
            .and_then(|()| render(&root))
            .and_then(|()| root.present().map_err(|e| e.to_string()));
        // On failure, dropping `root` still writes the file; it is removed below.
        drop(root);
        drawn
    };
    if let Err(what) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(draw_err(what));
    }
    if let Err(source) = stamp_text(&tmp) {
        let _ = std::fs::remove_file(&tmp);
        return Err(PlotError::Io {
            path: path.to_path_buf(),
            what: format!("adding the text chunks to {}", tmp.display()),
            source,
        });
    }
    std::fs::rename(&tmp, path).map_err(|source| {
        let _ = std::fs::remove_file(&tmp);
        PlotError::Io {
            path: path.to_path_buf(),
            what: format!("renaming {} into place", tmp.display()),
            source,
        }
    })
}

/// The `tEXt` entries every PNG of this process carries ([`set_png_text`]).
static PNG_TEXT: Mutex<Vec<(String, String)>> = Mutex::new(Vec::new());

/// From now on every PNG this process writes carries a `tEXt` chunk `key` = `value` (replacing
/// an earlier value of `key`): the program stamps its plots with its invocation id, as its
/// tables, so that the files of one result folder can be told from an earlier run's. A key
/// PNG does not allow (1–79 printable Latin-1 characters without leading, trailing or double
/// spaces; here printable ASCII) or a value holding NUL is refused.
pub fn set_png_text(key: &str, value: &str) -> Result<(), String> {
    let key_ok = (1..=79).contains(&key.len())
        && key.bytes().all(|b| (0x20..0x7f).contains(&b))
        && !key.starts_with(' ')
        && !key.ends_with(' ')
        && !key.contains("  ");
    if !key_ok {
        return Err(format!("{key:?} is not a PNG text keyword"));
    }
    if value.contains('\0') || !value.is_ascii() {
        return Err(format!("{value:?} is not PNG text (ASCII without NUL)"));
    }
    let mut t = PNG_TEXT.lock().unwrap_or_else(|e| e.into_inner());
    match t.iter_mut().find(|(k, _)| k == key) {
        Some(e) => e.1 = value.to_string(),
        None => t.push((key.to_string(), value.to_string())),
    }
    Ok(())
}

/// CRC-32 of PNG chunks (ISO 3309, reflected 0xEDB88320).
fn crc32(parts: &[&[u8]]) -> u32 {
    let mut c = !0u32;
    for part in parts {
        for &b in *part {
            c ^= u32::from(b);
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    (c >> 1) ^ 0xEDB8_8320
                } else {
                    c >> 1
                };
            }
        }
    }
    !c
}

/// Inserts the [`set_png_text`] entries as `tEXt` chunks right after the IHDR chunk of the PNG
/// file at `path` (a no-op when there are none).
fn stamp_text(path: &Path) -> std::io::Result<()> {
    let entries = PNG_TEXT.lock().unwrap_or_else(|e| e.into_inner()).clone();
    if entries.is_empty() {
        return Ok(());
    }
    let png = std::fs::read(path)?;
    // Signature (8) and the IHDR chunk (length 4, type 4, 13 data bytes, CRC 4).
    const IHDR_END: usize = 8 + 4 + 4 + 13 + 4;
    if png.len() < IHDR_END || &png[12..16] != b"IHDR" {
        return Err(std::io::Error::other("the encoder's output is not a PNG"));
    }
    let mut out = Vec::with_capacity(png.len() + 64 * entries.len());
    out.extend_from_slice(&png[..IHDR_END]);
    for (k, v) in &entries {
        let mut data = Vec::with_capacity(k.len() + 1 + v.len());
        data.extend_from_slice(k.as_bytes());
        data.push(0);
        data.extend_from_slice(v.as_bytes());
        let len = u32::try_from(data.len()).map_err(std::io::Error::other)?;
        out.extend_from_slice(&len.to_be_bytes());
        out.extend_from_slice(b"tEXt");
        out.extend_from_slice(&data);
        out.extend_from_slice(&crc32(&[b"tEXt", &data]).to_be_bytes());
    }
    out.extend_from_slice(&png[IHDR_END..]);
    std::fs::write(path, out)
}

/// The `tEXt` entries of a PNG file's bytes, in file order (chunks whose CRC does not match
/// are left out).
pub fn png_text_of(png: &[u8]) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut i = 8;
    while i + 12 <= png.len() {
        let len = u32::from_be_bytes([png[i], png[i + 1], png[i + 2], png[i + 3]]) as usize;
        let Some(end) = (i + 8).checked_add(len).filter(|&e| e + 4 <= png.len()) else {
            break;
        };
        let (kind, data) = (&png[i + 4..i + 8], &png[i + 8..end]);
        let crc = u32::from_be_bytes([png[end], png[end + 1], png[end + 2], png[end + 3]]);
        if kind == b"tEXt" && crc == crc32(&[kind, data]) {
            if let Some(z) = data.iter().position(|&b| b == 0) {
                out.push((
                    String::from_utf8_lossy(&data[..z]).into_owned(),
                    String::from_utf8_lossy(&data[z + 1..]).into_owned(),
                ));
            }
        }
        if kind == b"IEND" {
            break;
        }
        i = end + 4;
    }
    out
}

/// Draw `text` centred at pixel (x, y) of `area`.
pub fn centered_text(
    area: &Area<'_>,
    text: &str,
    style: &TextStyle<'_>,
    x: i32,
    y: i32,
) -> Result<(), String> {
    let style = style.pos(Pos::new(HPos::Center, VPos::Center));
    area.draw_text(text, &style, (x, y))
        .map_err(|e| e.to_string())
}

/// Draw the figure title (if any) and return the area below it.
pub fn titled<'a>(area: &Area<'a>, title: &str, scale: f64) -> Result<Area<'a>, String> {
    if title.trim().is_empty() {
        return Ok(area.margin((8.0 * scale) as i32, 0, 0, 0));
    }
    let (w, _) = area.dim_in_pixel();
    let size = 26.0 * scale;
    let pad = (10.0 * scale) as i32;
    centered_text(
        area,
        title,
        &font(scale, 26.0),
        w as i32 / 2,
        pad + (size * 0.55) as i32,
    )?;
    let (_, below) = area.split_vertically(pad * 2 + size as i32);
    Ok(below)
}

/// Finite min / max of `values`, `None` when there is none.
pub fn finite_range(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// A fixed y range no narrower than `min_span` for `values` (their finite ones) that span less,
/// centred on them; `None` where they span at least that (fit the data as usual) or hold nothing
/// finite. Fitted to the data, a trace that hardly moves is magnified to its rounding: two flat
/// series 1.4e-7 apart filled a panel as two lines far apart.
pub fn floor_span(values: impl IntoIterator<Item = f64>, min_span: f64) -> Option<(f64, f64)> {
    let (lo, hi) = finite_range(values)?;
    let mid = 0.5 * (lo + hi);
    (hi - lo < min_span && min_span.is_finite())
        .then_some((mid - 0.5 * min_span, mid + 0.5 * min_span))
}

/// Widen a (finite) range by `frac` of its span on each side; an empty span gets a
/// span of its own so the axis still has ticks.
pub fn pad_range((lo, hi): (f64, f64), frac: f64) -> (f64, f64) {
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    let span = hi - lo;
    if span > f64::EPSILON * lo.abs().max(hi.abs()).max(f64::MIN_POSITIVE) * 16.0 {
        (lo - span * frac, hi + span * frac)
    } else {
        let half = if lo == 0.0 { 1.0 } else { lo.abs() * 0.1 };
        (lo - half, hi + half)
    }
}

/// A user-given range, if it is usable (finite, increasing, positive for log axes).
pub fn valid_range(r: Option<(f64, f64)>, log: bool) -> Option<(f64, f64)> {
    let (a, b) = r?;
    let (lo, hi) = if a <= b { (a, b) } else { (b, a) };
    let ok = lo.is_finite() && hi.is_finite() && hi > lo && (!log || lo > 0.0);
    ok.then_some((lo, hi))
}

// ---------------------------------------------------------------------------------------
// Tick labels

const MINUS: char = '\u{2212}';

fn superscript(n: i32) -> String {
    const DIGITS: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let mut s = String::new();
    if n < 0 {
        s.push('⁻');
    }
    for c in n.unsigned_abs().to_string().chars() {
        s.push(DIGITS[c.to_digit(10).unwrap_or(0) as usize]);
    }
    s
}

fn with_minus(s: String) -> String {
    match s.strip_prefix('-') {
        Some(rest) => format!("{MINUS}{rest}"),
        None => s,
    }
}

/// How the tick labels of one linear axis are written: the same number of decimals on
/// every label (the fewest that tell them apart), or ×10ⁿ notation for very large / small
/// magnitudes.
#[derive(Debug, Clone, Copy)]
pub enum TickFmt {
    Fixed(usize),
    Sci { exp: i32, decimals: usize },
}

impl TickFmt {
    /// The format for labelling exactly these ticks (sorted, evenly spaced).
    pub fn for_ticks(ticks: &[f64]) -> Self {
        let step = ticks
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(f64::INFINITY, f64::min);
        let step = if step.is_finite() && step > 0.0 {
            step
        } else {
            ticks.first().map_or(1.0, |v| v.abs().max(1e-300))
        };
        let big = ticks.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let decimals_for = |scale: f64| {
            (0..=9)
                .find(|&d| {
                    let f = 10f64.powi(d as i32);
                    ticks
                        .iter()
                        .all(|&v| ((v / scale * f).round() / f * scale - v).abs() <= step * 1e-6)
                })
                .unwrap_or(9)
        };
        if big >= 1e5 || (big < 1e-3 && big > 0.0) {
            let exp = big.log10().floor() as i32;
            TickFmt::Sci {
                exp,
                decimals: decimals_for(10f64.powi(exp)),
            }
        } else {
            TickFmt::Fixed(decimals_for(1.0))
        }
    }

    pub fn format(&self, v: f64) -> String {
        match *self {
            TickFmt::Fixed(d) => {
                let s = format!("{v:.d$}");
                // "-0.0" → "0.0"
                if s.trim_start_matches('-')
                    .chars()
                    .all(|c| c == '0' || c == '.')
                {
                    s.trim_start_matches('-').to_string()
                } else {
                    with_minus(s)
                }
            }
            TickFmt::Sci { exp, decimals } => {
                let m = v / 10f64.powi(exp);
                if m.abs() < 10f64.powi(-(decimals as i32)) / 2.0 {
                    return "0".to_string();
                }
                format!(
                    "{}×10{}",
                    with_minus(format!("{m:.decimals$}")),
                    superscript(exp)
                )
            }
        }
    }
}

/// Tick label for a logarithmic axis; `sup` = write decades as 10ⁿ (wide ranges).
pub fn format_log(v: f64, sup: bool) -> String {
    if !(v > 0.0 && v.is_finite()) {
        return String::new();
    }
    let e = v.log10().floor() as i32;
    let m = v / 10f64.powi(e);
    let (m, e) = if m >= 9.9995 { (1.0, e + 1) } else { (m, e) };
    if sup {
        if (m - 1.0).abs() < 1e-3 {
            format!("10{}", superscript(e))
        } else {
            format!("{}×10{}", trim_zeros(format!("{m:.2}")), superscript(e))
        }
    } else {
        let d = (-e).max(0) as usize + if (m - m.round()).abs() < 1e-3 { 0 } else { 1 };
        trim_zeros(format!("{v:.d$}"))
    }
}

fn trim_zeros(s: String) -> String {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Widest rendered width (pixels) of a set of labels.
pub fn max_text_width(
    area: &Area<'_>,
    labels: impl IntoIterator<Item = String>,
    style: &TextStyle<'_>,
) -> u32 {
    labels
        .into_iter()
        .filter_map(|l| area.estimate_text_size(&l, style).ok())
        .map(|(w, _)| w)
        .max()
        .unwrap_or(0)
}

// ---------------------------------------------------------------------------------------
// Decimation and clipping, in display space (y already log10'd for log axes).

/// M4 decimation: every run of consecutive points falling into the same pixel column is
/// reduced to its first, lowest, highest and last point (in their original order), which
/// draws the same line as the full data at that resolution.
pub fn decimate_m4(pts: &[(f64, f64)], x0: f64, x1: f64, columns: usize) -> Vec<(f64, f64)> {
    let columns = columns.max(1);
    if pts.len() <= 4 * columns || x1 <= x0 {
        return pts.to_vec();
    }
    let scale = columns as f64 / (x1 - x0);
    let col = |x: f64| ((x - x0) * scale).floor().clamp(-1.0, columns as f64) as i64;
    let mut out = Vec::with_capacity(4 * columns + 8);
    let mut start = 0;
    while start < pts.len() {
        let c = col(pts[start].0);
        let mut end = start + 1;
        let (mut imin, mut imax) = (start, start);
        while end < pts.len() && col(pts[end].0) == c {
            if pts[end].1 < pts[imin].1 {
                imin = end;
            }
            if pts[end].1 > pts[imax].1 {
                imax = end;
            }
            end += 1;
        }
        let mut idx = [start, imin, imax, end - 1];
        idx.sort_unstable();
        let mut last = usize::MAX;
        for i in idx {
            if i != last {
                out.push(pts[i]);
                last = i;
            }
        }
        start = end;
    }
    out
}

/// Clip a polyline to the box, returning the visible pieces (Liang–Barsky per segment).
pub fn clip_polyline(pts: &[(f64, f64)], bx: (f64, f64), by: (f64, f64)) -> Vec<Vec<(f64, f64)>> {
    let inside = |p: (f64, f64)| p.0 >= bx.0 && p.0 <= bx.1 && p.1 >= by.0 && p.1 <= by.1;
    let mut pieces = Vec::new();
    let mut cur: Vec<(f64, f64)> = Vec::new();
    if pts.len() == 1 && inside(pts[0]) {
        return vec![pts.to_vec()];
    }
    for w in pts.windows(2) {
        let (p, q) = (w[0], w[1]);
        match clip_segment(p, q, bx, by) {
            Some((a, b)) => {
                if cur.is_empty() {
                    cur.push(a);
                } else if cur.last() != Some(&a) {
                    pieces.push(std::mem::take(&mut cur));
                    cur.push(a);
                }
                cur.push(b);
                if b != q {
                    pieces.push(std::mem::take(&mut cur));
                }
            }
            None => {
                if !cur.is_empty() {
                    pieces.push(std::mem::take(&mut cur));
                }
            }
        }
    }
    if !cur.is_empty() {
        pieces.push(cur);
    }
    pieces
}

fn clip_segment(
    p: (f64, f64),
    q: (f64, f64),
    bx: (f64, f64),
    by: (f64, f64),
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (pk, qk) in [
        (-dx, p.0 - bx.0),
        (dx, bx.1 - p.0),
        (-dy, p.1 - by.0),
        (dy, by.1 - p.1),
    ] {
        if pk == 0.0 {
            if qk < 0.0 {
                return None;
            }
        } else {
            let r = qk / pk;
            if pk < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
            if t0 > t1 {
                return None;
            }
        }
    }
    let a = if t0 == 0.0 {
        p
    } else {
        (p.0 + t0 * dx, p.1 + t0 * dy)
    };
    let b = if t1 == 1.0 {
        q
    } else {
        (p.0 + t1 * dx, p.1 + t1 * dy)
    };
    Some((a, b))
}

/// Keep at most one point per pixel (of a `w`×`h` grid over the box); points outside the
/// box are dropped.
pub fn dedup_pixels(
    pts: impl Iterator<Item = (f64, f64)>,
    bx: (f64, f64),
    by: (f64, f64),
    w: usize,
    h: usize,
) -> Vec<(f64, f64)> {
    let (w, h) = (w.max(1), h.max(1));
    let mut seen = vec![false; w * h];
    let sx = w as f64 / (bx.1 - bx.0);
    let sy = h as f64 / (by.1 - by.0);
    let mut out = Vec::new();
    for p in pts {
        if !(p.0 >= bx.0 && p.0 <= bx.1 && p.1 >= by.0 && p.1 <= by.1) {
            continue;
        }
        let ix = (((p.0 - bx.0) * sx) as usize).min(w - 1);
        let iy = (((p.1 - by.0) * sy) as usize).min(h - 1);
        let cell = &mut seen[iy * w + ix];
        if !*cell {
            *cell = true;
            out.push(p);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn m4_keeps_extremes_and_order() {
        let pts: Vec<(f64, f64)> = (0..100_000)
            .map(|i| {
                let x = i as f64 / 100_000.0;
                (x, (x * 300.0).sin())
            })
            .collect();
        let d = decimate_m4(&pts, 0.0, 1.0, 500);
        assert!(d.len() <= 4 * 500 + 4, "{}", d.len());
        assert!(d.windows(2).all(|w| w[0].0 <= w[1].0));
        let (lo, hi) = finite_range(d.iter().map(|p| p.1)).unwrap();
        assert!(lo < -0.999 && hi > 0.999);
        assert_eq!(d.first(), pts.first());
        assert_eq!(d.last(), pts.last());
    }

    #[test]
    fn a_trace_narrower_than_the_floor_is_drawn_at_the_floors_span_about_its_middle() {
        let resting = [2.300_975e-3, 2.300_838e-3, f64::NAN, 2.300_838e-3];
        let (lo, hi) = floor_span(resting, 0.05).unwrap();
        assert!((hi - lo - 0.05).abs() < 1e-12, "{lo} {hi}");
        assert!((0.5 * (lo + hi) - 0.5 * (2.300_975e-3 + 2.300_838e-3)).abs() < 1e-12);
        // Wide enough already, or nothing to draw: the data's own range.
        assert_eq!(floor_span([-1.0, 1.0], 0.05), None);
        assert_eq!(floor_span([f64::NAN], 0.05), None);
        assert_eq!(floor_span(std::iter::empty(), 0.05), None);
    }

    #[test]
    fn clipping_splits_lines() {
        let pts = [(0.0, 0.0), (1.0, 2.0), (2.0, 0.0), (3.0, 0.5)];
        let pieces = clip_polyline(&pts, (0.0, 3.0), (0.0, 1.0));
        assert_eq!(pieces.len(), 2);
        assert_eq!(pieces[0], vec![(0.0, 0.0), (0.5, 1.0)]);
        assert_eq!(pieces[1], vec![(1.5, 1.0), (2.0, 0.0), (3.0, 0.5)]);
    }

    #[test]
    fn tick_formats() {
        let f = TickFmt::for_ticks(&[0.0, 0.1, 0.2, 0.30000000000000004]);
        assert_eq!(f.format(0.30000000000000004), "0.3");
        assert_eq!(f.format(1.0), "1.0");
        assert_eq!(f.format(-0.2), "\u{2212}0.2");
        let f = TickFmt::for_ticks(&[0.0, 200.0, 400.0]);
        assert_eq!(f.format(200.0), "200");
        let f = TickFmt::for_ticks(&[0.0, 1e6, 2e6, 3e6]);
        assert!(f.format(1e6).contains("×10⁶"), "{}", f.format(1e6));
        assert_eq!(format_log(1e-6, true), "10⁻⁶");
        assert_eq!(format_log(0.01, false), "0.01");
        assert_eq!(format_log(100.0, false), "100");
        assert_eq!(pad_range((2.0, 2.0), 0.05), (1.8, 2.2));
        assert_eq!(pad_range((0.0, 0.0), 0.05), (-1.0, 1.0));
    }
}
