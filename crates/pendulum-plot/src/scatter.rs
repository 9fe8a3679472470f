//! [`CategoryScatter`]: points coloured by category, legend beside the plot.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::axis::LinAxis;
use crate::common::{self, Area};
use crate::{CategoryScatter, PlotError};

/// More categories than this cannot be told apart by colour anyway.
const MAX_CATEGORIES: usize = 1000;

pub fn save(sc: &CategoryScatter, path: &Path) -> Result<(), PlotError> {
    common::check_size(path, sc.width, sc.height)?;
    if sc.x.len() != sc.y.len() || sc.x.len() != sc.category.len() {
        return Err(common::invalid(
            path,
            format!(
                "x, y and category must have the same length (got {}, {}, {})",
                sc.x.len(),
                sc.y.len(),
                sc.category.len()
            ),
        ));
    }
    if let Some(&c) = sc.category.iter().find(|&&c| c >= MAX_CATEGORIES) {
        return Err(common::invalid(
            path,
            format!(
                "category index {c} is too large (at most {} categories)",
                MAX_CATEGORIES
            ),
        ));
    }
    common::save_atomic(path, (sc.width, sc.height), |root| draw(root, sc))
}

fn category_color(sc: &CategoryScatter, c: usize) -> RGBColor {
    match sc.category_colors.as_ref().and_then(|cols| cols.get(c)) {
        Some(&(r, g, b)) => RGBColor(r, g, b),
        None => common::palette(c),
    }
}

fn category_name(sc: &CategoryScatter, c: usize) -> String {
    match sc.category_names.get(c) {
        Some(n) if !n.trim().is_empty() => n.clone(),
        _ => format!("category {c}"),
    }
}

fn draw(root: &Area<'_>, sc: &CategoryScatter) -> Result<(), String> {
    let s = common::scale_for(sc.width, sc.height);
    let body = common::titled(root, &sc.title, s)?;

    let valid: Vec<(f64, f64, usize)> =
        sc.x.iter()
            .zip(&sc.y)
            .zip(&sc.category)
            .filter(|((x, y), _)| x.is_finite() && y.is_finite())
            .map(|((&x, &y), &c)| (x, y, c))
            .collect();

    // Legend entries: every named category, plus unnamed ones that occur.
    let n_cat = valid
        .iter()
        .map(|p| p.2 + 1)
        .max()
        .unwrap_or(0)
        .max(sc.category_names.len());
    let mut counts = vec![0usize; n_cat];
    for p in &valid {
        counts[p.2] += 1;
    }
    let entries: Vec<usize> = (0..n_cat)
        .filter(|&c| c < sc.category_names.len() || counts[c] > 0)
        .collect();

    let names: Vec<String> = entries
        .iter()
        .map(|&c| {
            if counts[c] == 0 {
                format!("{} (none)", category_name(sc, c))
            } else {
                category_name(sc, c)
            }
        })
        .collect();
    let label_font = common::font(s, 16.0);
    let legend_w = if entries.is_empty() {
        0
    } else {
        common::max_text_width(&body, names.iter().cloned(), &label_font) + (56.0 * s) as u32
    };
    let (bw, _) = body.dim_in_pixel();
    let legend_w = legend_w.min(bw / 3);
    let (plot_area, legend_area) = body.split_horizontally(bw - legend_w);

    let xr = common::finite_range(valid.iter().map(|p| p.0))
        .map(|r| common::pad_range(r, 0.02))
        .unwrap_or((0.0, 1.0));
    let yr = common::finite_range(valid.iter().map(|p| p.1))
        .map(|r| common::pad_range(r, 0.04))
        .unwrap_or((0.0, 1.0));

    let (aw, ah) = plot_area.dim_in_pixel();
    let x_area = 58.0 * s;
    let nx = ((f64::from(aw) / (120.0 * s)) as usize).clamp(3, 12);
    let ny = (((f64::from(ah) - x_area) / (45.0 * s)) as usize).clamp(2, 10);
    let x_axis = LinAxis::new(xr.0, xr.1, nx);
    let y_axis = LinAxis::new(yr.0, yr.1, ny);
    let y_tick_w = common::max_text_width(&plot_area, y_axis.labels(), &label_font);
    let margin_top = (14.0 * s) as i32;
    let mut chart = ChartBuilder::on(&plot_area)
        .margin_top(margin_top)
        .margin_right((16.0 * s) as i32)
        .margin_left((10.0 * s) as i32)
        .margin_bottom((4.0 * s) as i32)
        .x_label_area_size(x_area as i32)
        .y_label_area_size((f64::from(y_tick_w) + 48.0 * s) as i32)
        .build_cartesian_2d(x_axis.clone(), y_axis.clone())
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_labels(nx)
        .y_labels(ny)
        .x_label_formatter(&|v| x_axis.label(*v))
        .y_label_formatter(&|v| y_axis.label(*v))
        .x_desc(sc.x_label.as_str())
        .y_desc(sc.y_label.as_str())
        .axis_desc_style(common::font(s, 19.0))
        .label_style(label_font.clone())
        .bold_line_style(common::GRID)
        .light_line_style(TRANSPARENT)
        .axis_style(common::TEXT)
        .draw()
        .map_err(|e| e.to_string())?;

    let (pw, ph) = chart.plotting_area().dim_in_pixel();
    let radius = if valid.len() > 20_000 {
        1.4
    } else if valid.len() > 2_000 {
        2.0
    } else {
        3.0
    } * s;
    for (c, _) in counts.iter().enumerate().filter(|(_, &n)| n > 0) {
        let color = category_color(sc, c);
        let pts = common::dedup_pixels(
            valid.iter().filter(|p| p.2 == c).map(|p| (p.0, p.1)),
            xr,
            yr,
            pw as usize,
            ph as usize,
        );
        chart
            .draw_series(
                pts.into_iter()
                    .map(|p| Circle::new(p, radius.max(1.0), color.filled())),
            )
            .map_err(|e| e.to_string())?;
    }
    if valid.is_empty() {
        let style = common::font(s, 20.0).color(&RGBColor(120, 120, 120));
        common::centered_text(
            &chart.plotting_area().strip_coord_spec(),
            "no data",
            &style,
            pw as i32 / 2,
            ph as i32 / 2,
        )?;
    }

    // Legend beside the plot, aligned with the top of the plotting area.
    let row = (24.0 * s) as i32;
    let mut y = margin_top + (12.0 * s) as i32;
    let x0 = (8.0 * s) as i32;
    let text_style = label_font.pos(Pos::new(HPos::Left, VPos::Center));
    for (&c, name) in entries.iter().zip(&names) {
        let color = category_color(sc, c);
        legend_area
            .draw(&Circle::new(
                (x0 + (8.0 * s) as i32, y),
                (5.0 * s).max(2.0),
                color.filled(),
            ))
            .map_err(|e| e.to_string())?;
        legend_area
            .draw_text(name, &text_style, (x0 + (22.0 * s) as i32, y))
            .map_err(|e| e.to_string())?;
        y += row;
    }
    Ok(())
}
