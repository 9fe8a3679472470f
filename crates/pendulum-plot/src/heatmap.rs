//! [`Heatmap`]: grid of coloured cells with a colour bar; several side by side.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontTransform;

use crate::axis::LinAxis;
use crate::common::{self, Area};
use crate::{Heatmap, PlotError};

/// Viridis (matplotlib), sampled at 17 evenly spaced stops.
const VIRIDIS: [(u8, u8, u8); 17] = [
    (68, 1, 84),
    (72, 21, 104),
    (72, 38, 119),
    (69, 55, 129),
    (63, 71, 136),
    (57, 85, 140),
    (50, 100, 142),
    (45, 113, 142),
    (39, 127, 142),
    (34, 139, 141),
    (31, 152, 139),
    (34, 165, 133),
    (53, 183, 121),
    (83, 197, 104),
    (122, 209, 81),
    (165, 219, 54),
    (253, 231, 37),
];

/// Viridis colour of `t` in 0..=1 (clamped).
fn viridis(t: f64) -> RGBColor {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let f = t * (VIRIDIS.len() - 1) as f64;
    let i = (f.floor() as usize).min(VIRIDIS.len() - 2);
    let u = f - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |p: u8, q: u8| (f64::from(p) + u * (f64::from(q) - f64::from(p))).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// Blue–white–red of `t` in 0..=1 (clamped), white at 0.5: ColorBrewer's RdBu ends
/// (colour-blind safe), for signed differences.
fn diverging(t: f64) -> RGBColor {
    const STOPS: [(u8, u8, u8); 5] = [
        (33, 102, 172),
        (146, 197, 222),
        (247, 247, 247),
        (244, 165, 130),
        (178, 24, 43),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.5
    };
    let f = t * (STOPS.len() - 1) as f64;
    let i = (f.floor() as usize).min(STOPS.len() - 2);
    let u = f - i as f64;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    let mix = |p: u8, q: u8| (f64::from(p) + u * (f64::from(q) - f64::from(p))).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The heat map's colour of `t` in 0..=1.
fn scale(hm: &Heatmap, t: f64) -> RGBColor {
    if hm.diverging {
        diverging(t)
    } else {
        viridis(t)
    }
}

pub fn save(hm: &Heatmap, path: &Path) -> Result<(), PlotError> {
    common::check_size(path, hm.width, hm.height)?;
    validate(hm, path)?;
    common::save_atomic(path, (hm.width, hm.height), |root| {
        let s = common::scale_for(hm.width, hm.height);
        let body = common::titled(root, &hm.title, s)?;
        draw_map(&body, hm, s, None)
    })
}

/// Several heat maps in one PNG, left to right, under a common `title`. The image is as
/// wide as the maps' widths added up and as tall as the tallest map; each map keeps its
/// own title (as a sub-title), axes and colour bar.
pub fn save_heatmaps_side_by_side(
    maps: &[Heatmap],
    title: &str,
    path: &Path,
) -> Result<(), PlotError> {
    if maps.is_empty() {
        return Err(common::invalid(path, "no heat maps to draw"));
    }
    let width: u32 = maps.iter().map(|m| m.width).fold(0u32, u32::saturating_add);
    let height = maps.iter().map(|m| m.height).max().unwrap_or(0);
    common::check_size(path, width, height)?;
    for (i, m) in maps.iter().enumerate() {
        validate(m, path).map_err(|e| match e {
            PlotError::InvalidData { path, what } => PlotError::InvalidData {
                path,
                what: format!("heat map {i}: {what}"),
            },
            other => other,
        })?;
    }
    common::save_atomic(path, (width, height), |root| {
        let s = common::scale_for(width / maps.len() as u32, height);
        let body = common::titled(root, title, s)?;
        let mut breaks = Vec::new();
        let mut acc = 0i32;
        for m in &maps[..maps.len() - 1] {
            acc += m.width as i32;
            breaks.push(acc);
        }
        let areas = body.split_by_breakpoints(breaks, Vec::<i32>::new());
        for (area, m) in areas.iter().zip(maps) {
            draw_map(area, m, s, Some(&m.title))?;
        }
        Ok(())
    })
}

fn validate(hm: &Heatmap, path: &Path) -> Result<(), PlotError> {
    let nx = hm.x_edges.len().saturating_sub(1);
    let ny = hm.y_edges.len().saturating_sub(1);
    if hm.values.is_empty() && (nx == 0 || ny == 0) {
        return Ok(()); // nothing to draw: an empty frame saying "no data"
    }
    if hm.values.len() != ny {
        return Err(common::invalid(
            path,
            format!(
                "{} y edges need {ny} rows of values, got {}",
                hm.y_edges.len(),
                hm.values.len()
            ),
        ));
    }
    if let Some((iy, row)) = hm.values.iter().enumerate().find(|(_, r)| r.len() != nx) {
        return Err(common::invalid(
            path,
            format!(
                "{} x edges need {nx} values per row, row {iy} has {}",
                hm.x_edges.len(),
                row.len()
            ),
        ));
    }
    if hm.x_edges.iter().chain(&hm.y_edges).any(|e| !e.is_finite()) {
        return Err(common::invalid(path, "cell edges must be finite"));
    }
    Ok(())
}

fn draw_map(area: &Area<'_>, hm: &Heatmap, s: f64, subtitle: Option<&str>) -> Result<(), String> {
    let area = match subtitle {
        Some(t) if !t.trim().is_empty() => {
            let (w, _) = area.dim_in_pixel();
            common::centered_text(
                area,
                t,
                &common::font(s, 20.0),
                w as i32 / 2,
                (16.0 * s) as i32,
            )?;
            area.split_vertically((32.0 * s) as i32).1
        }
        _ => area.clone(),
    };
    let nx = hm.x_edges.len().saturating_sub(1);
    let ny = hm.y_edges.len().saturating_sub(1);
    let has_cells = nx > 0 && ny > 0 && hm.values.len() == ny;

    let xr = common::finite_range(hm.x_edges.iter().copied())
        .map(|r| common::pad_range(r, 0.0))
        .unwrap_or((0.0, 1.0));
    let yr = common::finite_range(hm.y_edges.iter().copied())
        .map(|r| common::pad_range(r, 0.0))
        .unwrap_or((0.0, 1.0));
    let data_range = common::finite_range(hm.values.iter().flatten().copied());
    let pick = |v: Option<f64>, d: Option<f64>, fallback: f64| {
        v.filter(|v| v.is_finite()).or(d).unwrap_or(fallback)
    };
    let (mut vlo, mut vhi) = (
        pick(hm.vmin, data_range.map(|r| r.0), 0.0),
        pick(hm.vmax, data_range.map(|r| r.1), 1.0),
    );
    if vlo > vhi {
        std::mem::swap(&mut vlo, &mut vhi);
    }
    if vhi - vlo <= f64::EPSILON * vlo.abs().max(vhi.abs()) * 16.0 {
        (vlo, vhi) = common::pad_range((vlo, vhi), 0.0);
    }
    let any_nan = has_cells && hm.values.iter().flatten().any(|v| !v.is_finite());

    let label_font = common::font(s, 16.0);
    let desc_font = common::font(s, 19.0);
    let (aw, ah) = area.dim_in_pixel();
    let x_area = 58.0 * s;
    let margin_top = 12.0 * s;
    let plot_h = f64::from(ah) - x_area - margin_top;
    let ny_ticks = ((plot_h / (48.0 * s)) as usize).clamp(2, 10);

    // Colour bar width: bar + tick labels + rotated label.
    let v_axis = LinAxis::new(vlo, vhi, ny_ticks);
    let v_tick_w = common::max_text_width(&area, v_axis.labels(), &label_font);
    let no_data_w = if any_nan {
        common::max_text_width(&area, ["no data".to_string()], &label_font) + (30.0 * s) as u32
    } else {
        0
    };
    let bar_w = 26.0 * s;
    // Tick marks and labels right of the bar, then the rotated value label.
    let cb_label_w = f64::from(v_tick_w) + 16.0 * s;
    let desc_w = if hm.value_label.trim().is_empty() {
        0.0
    } else {
        30.0 * s
    };
    let cb_w = ((16.0 * s + bar_w + cb_label_w + desc_w + 10.0 * s) as u32)
        .max(no_data_w + (20.0 * s) as u32);
    let cb_w = cb_w.min(aw / 3);
    let (main, cb_area) = area.split_horizontally(aw - cb_w);

    // Main map.
    let (mw, _) = main.dim_in_pixel();
    let nx_ticks = ((f64::from(mw) / (110.0 * s)) as usize).clamp(3, 10);
    let x_axis = LinAxis::new(xr.0, xr.1, nx_ticks);
    let y_axis = LinAxis::new(yr.0, yr.1, ny_ticks);
    let y_tick_w = common::max_text_width(&main, y_axis.labels(), &label_font);
    let mut chart = ChartBuilder::on(&main)
        .margin_top(margin_top as i32)
        .margin_right((12.0 * s) as i32)
        .margin_left((10.0 * s) as i32)
        .margin_bottom((6.0 * s) as i32)
        .x_label_area_size(x_area as i32)
        .y_label_area_size((f64::from(y_tick_w) + 48.0 * s) as i32)
        .build_cartesian_2d(x_axis.clone(), y_axis.clone())
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_labels(nx_ticks)
        .y_labels(ny_ticks)
        .x_label_formatter(&|v| x_axis.label(*v))
        .y_label_formatter(&|v| y_axis.label(*v))
        .x_desc(hm.x_label.as_str())
        .y_desc(hm.y_label.as_str())
        .axis_desc_style(desc_font.clone())
        .label_style(label_font.clone())
        .axis_style(common::TEXT)
        .draw()
        .map_err(|e| e.to_string())?;

    if has_cells {
        let cells = hm
            .values
            .iter()
            .enumerate()
            .flat_map(|(iy, row)| row.iter().enumerate().map(move |(ix, &v)| (ix, iy, v)));
        chart
            .draw_series(cells.map(|(ix, iy, v)| {
                let color = if v.is_finite() {
                    scale(hm, (v - vlo) / (vhi - vlo))
                } else {
                    common::NO_DATA
                };
                Rectangle::new(
                    [
                        (hm.x_edges[ix], hm.y_edges[iy]),
                        (hm.x_edges[ix + 1], hm.y_edges[iy + 1]),
                    ],
                    color.filled(),
                )
            }))
            .map_err(|e| e.to_string())?;

        // Marker dots: black with a white ring, visible on every viridis colour and on grey.
        let (pw, ph) = chart.plotting_area().dim_in_pixel();
        let cell_px = (f64::from(pw) / nx as f64).min(f64::from(ph) / ny as f64);
        let r = (cell_px * 0.22).clamp(1.5, 6.0 * s);
        let marks: Vec<(f64, f64)> = hm
            .marks
            .iter()
            .filter(|&&(ix, iy)| ix < nx && iy < ny)
            .map(|&(ix, iy)| {
                (
                    0.5 * (hm.x_edges[ix] + hm.x_edges[ix + 1]),
                    0.5 * (hm.y_edges[iy] + hm.y_edges[iy + 1]),
                )
            })
            .collect();
        chart
            .draw_series(
                marks
                    .iter()
                    .map(|&c| Circle::new(c, r + 1.5 * s.max(1.0), WHITE.filled())),
            )
            .map_err(|e| e.to_string())?;
        chart
            .draw_series(marks.iter().map(|&c| Circle::new(c, r, BLACK.filled())))
            .map_err(|e| e.to_string())?;
    } else {
        let (pw, ph) = chart.plotting_area().dim_in_pixel();
        let style = common::font(s, 20.0).color(&RGBColor(120, 120, 120));
        common::centered_text(
            &chart.plotting_area().strip_coord_spec(),
            "no data",
            &style,
            pw as i32 / 2,
            ph as i32 / 2,
        )?;
    }

    // Colour bar, its plotting area level with the map's.
    let (cw, _) = cb_area.dim_in_pixel();
    let bar_left = ((f64::from(cw) - bar_w - cb_label_w - desc_w) / 2.0).max(4.0 * s);
    let mut bar = ChartBuilder::on(&cb_area)
        .margin_top(margin_top as i32)
        .margin_left(bar_left as i32)
        .margin_right((f64::from(cw) - bar_left - bar_w - cb_label_w).max(0.0) as i32)
        .margin_bottom((6.0 * s) as i32)
        .x_label_area_size(x_area as i32)
        .right_y_label_area_size(cb_label_w as i32)
        .build_cartesian_2d(LinAxis::new(0.0, 1.0, 2), v_axis.clone())
        .map_err(|e| e.to_string())?;
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .x_labels(0)
        .y_labels(ny_ticks)
        .y_label_formatter(&|v| v_axis.label(*v))
        .label_style(label_font.clone())
        .axis_style(common::TEXT)
        .draw()
        .map_err(|e| e.to_string())?;
    let (_, bar_h) = bar.plotting_area().dim_in_pixel();
    if desc_w > 0.0 {
        // Reads bottom to top, like the map's y label.
        let x = (bar_left + bar_w + cb_label_w + desc_w / 2.0) as i32;
        let y = (margin_top + f64::from(bar_h) / 2.0) as i32;
        let style = desc_font
            .transform(FontTransform::Rotate270)
            .pos(Pos::new(HPos::Center, VPos::Center));
        cb_area
            .draw_text(&hm.value_label, &style, (x, y))
            .map_err(|e| e.to_string())?;
    }
    let steps = bar_h.clamp(2, 512) as usize;
    bar.draw_series((0..steps).map(|k| {
        let a = vlo + (vhi - vlo) * k as f64 / steps as f64;
        let b = vlo + (vhi - vlo) * (k + 1) as f64 / steps as f64;
        Rectangle::new(
            [(0.0, a), (1.0, b)],
            scale(hm, (k as f64 + 0.5) / steps as f64).filled(),
        )
    }))
    .map_err(|e| e.to_string())?;
    bar.draw_series(std::iter::once(Rectangle::new(
        [(0.0, vlo), (1.0, vhi)],
        common::TEXT.stroke_width(1),
    )))
    .map_err(|e| e.to_string())?;

    if any_nan {
        // "no data" swatch under the bar.
        let (_, ch) = cb_area.dim_in_pixel();
        let y = ch as i32 - (6.0 * s + x_area * 0.55) as i32;
        let x = bar_left as i32;
        let sq = (14.0 * s) as i32;
        cb_area
            .draw(&Rectangle::new(
                [(x, y - sq / 2), (x + sq, y + sq / 2)],
                common::NO_DATA.filled(),
            ))
            .map_err(|e| e.to_string())?;
        cb_area
            .draw(&Rectangle::new(
                [(x, y - sq / 2), (x + sq, y + sq / 2)],
                RGBColor(120, 120, 120).stroke_width(1),
            ))
            .map_err(|e| e.to_string())?;
        cb_area
            .draw_text(
                "no data",
                &label_font.pos(Pos::new(HPos::Left, VPos::Center)),
                (x + sq + (6.0 * s) as i32, y),
            )
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The diverging scale is white at its middle (0 difference), RdBu's blue and red at its
    /// ends, and lighter towards the middle on both sides, so equal and opposite differences
    /// read as equally strong.
    #[test]
    fn diverging_scale_is_white_in_the_middle_and_symmetric_in_lightness() {
        assert_eq!(diverging(0.5), RGBColor(247, 247, 247));
        assert_eq!(diverging(0.0), RGBColor(33, 102, 172));
        assert_eq!(diverging(1.0), RGBColor(178, 24, 43));
        let light = |c: RGBColor| u32::from(c.0) + u32::from(c.1) + u32::from(c.2);
        for k in 0..10 {
            let t = 0.05 * f64::from(k);
            assert!(light(diverging(t)) <= light(diverging(t + 0.05)), "{t}");
            assert!(
                light(diverging(1.0 - t)) <= light(diverging(0.95 - t)),
                "{t}"
            );
        }
        // NaN is the middle, not an end.
        assert_eq!(diverging(f64::NAN), diverging(0.5));
    }
}
