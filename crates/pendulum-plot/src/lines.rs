//! [`Figure`]: stacked panels of line / point series.

use std::path::Path;

use plotters::chart::ChartContext;
use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::prelude::*;

use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::axis::{LinAxis, LogAxis};
use crate::common::{self, Area};
use crate::{Figure, Panel, PlotError, SeriesStyle};

pub fn save(fig: &Figure, path: &Path) -> Result<(), PlotError> {
    common::check_size(path, fig.width, fig.height)?;
    common::save_atomic(path, (fig.width, fig.height), |root| draw_figure(root, fig))
}

fn draw_figure(root: &Area<'_>, fig: &Figure) -> Result<(), String> {
    let s = common::scale_for(fig.width, fig.height);
    let body = common::titled(root, &fig.title, s)?;
    if fig.panels.is_empty() {
        let (w, h) = body.dim_in_pixel();
        return common::centered_text(
            &body,
            "no data",
            &common::font(s, 20.0),
            w as i32 / 2,
            h as i32 / 2,
        );
    }
    let areas = body.split_evenly((fig.panels.len(), 1));
    for (area, panel) in areas.iter().zip(&fig.panels) {
        draw_panel(area, panel, s)?;
    }
    Ok(())
}

/// y in display space: identity, or log10 for a log axis; `None` = not drawable.
fn to_display(y: f64, log: bool) -> Option<f64> {
    if !y.is_finite() {
        None
    } else if log {
        (y > 0.0).then(|| y.log10())
    } else {
        Some(y)
    }
}

fn from_display(t: f64, log: bool) -> f64 {
    if log {
        10f64.powf(t)
    } else {
        t
    }
}

/// Drawable points of one series in display space, split at NaN / infinite / non-positive
/// (log) values.
fn segments(x: &[f64], y: &[f64], log: bool) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut cur = Vec::new();
    for (&xv, &yv) in x.iter().zip(y) {
        match (xv.is_finite(), to_display(yv, log)) {
            (true, Some(t)) => cur.push((xv, t)),
            _ => {
                if !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
            }
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

fn draw_panel(area: &Area<'_>, panel: &Panel, s: f64) -> Result<(), String> {
    let log = panel.log_y;
    let segs: Vec<Vec<Vec<(f64, f64)>>> = panel
        .series
        .iter()
        .map(|se| segments(&se.x, &se.y, log))
        .collect();
    let all = || segs.iter().flatten().flatten();
    let has_data = all().next().is_some();
    let has_points = panel.series.iter().any(|se| se.style != SeriesStyle::Line);

    let xr = common::finite_range(all().map(|p| p.0))
        .map(|r| common::pad_range(r, if has_points { 0.03 } else { 0.0 }))
        .unwrap_or((0.0, 1.0));
    // y range in display space
    let tr = match common::valid_range(panel.y_range, log) {
        Some((lo, hi)) => (
            to_display(lo, log).unwrap_or(0.0),
            to_display(hi, log).unwrap_or(1.0),
        ),
        None => common::finite_range(all().map(|p| p.1))
            .map(|r| common::pad_range(r, 0.05))
            .unwrap_or((0.0, 1.0)),
    };
    let yr = (from_display(tr.0, log), from_display(tr.1, log));

    let (aw, ah) = area.dim_in_pixel();
    let has_title = !panel.title.trim().is_empty();
    let label_font = common::font(s, 16.0);
    let margin_top = if has_title { 6.0 * s } else { 14.0 * s };
    let title_h = if has_title { 30.0 * s } else { 0.0 };
    let x_area = 58.0 * s;
    let plot_h_est = (f64::from(ah) - margin_top - title_h - x_area).max(20.0);
    let ny = ((plot_h_est / (42.0 * s)) as usize).clamp(2, 10);
    let nx = ((f64::from(aw) / (120.0 * s)) as usize).clamp(3, 12);

    let x_axis = LinAxis::new(xr.0, xr.1, nx);
    let y_lin = LinAxis::new(yr.0, yr.1, ny);
    let log_axis = log.then(|| LogAxis::new(yr.0, yr.1, plot_h_est, 30.0 * s));
    let y_labels: Vec<String> = match &log_axis {
        Some(axis) => axis.labels(),
        None => y_lin.labels(),
    };
    let y_tick_w = common::max_text_width(area, y_labels, &label_font);
    let y_area = f64::from(y_tick_w) + 48.0 * s;

    let mut builder = ChartBuilder::on(area);
    builder
        .margin_top(margin_top as i32)
        .margin_right((28.0 * s) as i32)
        .margin_left((10.0 * s) as i32)
        .margin_bottom((4.0 * s) as i32)
        .x_label_area_size(x_area as i32)
        .y_label_area_size(y_area as i32);
    if has_title {
        builder.caption(&panel.title, common::font(s, 20.0));
    }
    let ctx = PanelCtx {
        panel,
        segs: &segs,
        s,
        log,
        xr,
        tr,
        nx,
        ny,
        has_data,
    };
    match log_axis {
        Some(axis) => {
            let chart = builder
                .build_cartesian_2d(x_axis.clone(), axis.clone())
                .map_err(|e| e.to_string())?;
            ctx.finish(chart, &|v: &f64| x_axis.label(*v), &|v: &f64| {
                axis.label(*v)
            })
        }
        None => {
            let chart = builder
                .build_cartesian_2d(x_axis.clone(), y_lin.clone())
                .map_err(|e| e.to_string())?;
            ctx.finish(chart, &|v: &f64| x_axis.label(*v), &|v: &f64| {
                y_lin.label(*v)
            })
        }
    }
}

struct PanelCtx<'p> {
    panel: &'p Panel,
    segs: &'p [Vec<Vec<(f64, f64)>>],
    s: f64,
    log: bool,
    xr: (f64, f64),
    /// y range in display space
    tr: (f64, f64),
    nx: usize,
    ny: usize,
    has_data: bool,
}

impl PanelCtx<'_> {
    fn finish<'a, 'b, Y>(
        &self,
        mut chart: ChartContext<'a, BitMapBackend<'b>, Cartesian2d<LinAxis, Y>>,
        xfmt: &dyn Fn(&f64) -> String,
        yfmt: &dyn Fn(&f64) -> String,
    ) -> Result<(), String>
    where
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let s = self.s;
        let log = self.log;
        chart
            .configure_mesh()
            .x_labels(self.nx)
            .y_labels(self.ny)
            .x_label_formatter(xfmt)
            .y_label_formatter(yfmt)
            .x_desc(self.panel.x_label.as_str())
            .y_desc(self.panel.y_label.as_str())
            .axis_desc_style(common::font(s, 19.0))
            .label_style(common::font(s, 16.0))
            .bold_line_style(common::GRID)
            .light_line_style(if log {
                common::GRID.mix(0.45)
            } else {
                TRANSPARENT
            })
            .axis_style(common::TEXT)
            .draw()
            .map_err(|e| e.to_string())?;

        let (pw, ph) = chart.plotting_area().dim_in_pixel();
        let (xr, tr) = (self.xr, self.tr);
        let line_w = (2.0 * s).round().max(1.0) as u32;
        // Every drawn vertex, normalised to 0..1, to keep the legend off the data.
        let mut occupied: Vec<(f64, f64)> = Vec::new();
        let norm = |p: (f64, f64)| ((p.0 - xr.0) / (xr.1 - xr.0), (p.1 - tr.0) / (tr.1 - tr.0));
        let mut legend: Vec<(String, RGBColor, SeriesStyle)> = Vec::new();

        for (i, (se, segs)) in self.panel.series.iter().zip(self.segs).enumerate() {
            let color = common::palette(se.color.unwrap_or(i));
            let draws_line = se.style != SeriesStyle::Points;
            let draws_points = se.style != SeriesStyle::Line;
            let n_points: usize = segs.iter().map(Vec::len).sum();
            let radius = if se.style == SeriesStyle::LinePoints {
                3.0 * s
            } else if n_points > 20_000 {
                1.5 * s
            } else if n_points > 2_000 {
                2.2 * s
            } else {
                3.2 * s
            }
            .max(1.0);

            if draws_line {
                let style = color.stroke_width(line_w);
                for seg in segs {
                    let dec = common::decimate_m4(seg, xr.0, xr.1, pw as usize);
                    for piece in common::clip_polyline(&dec, xr, tr) {
                        densify_into(&mut occupied, &piece, &norm);
                        if piece.len() == 1 && !draws_points {
                            // An isolated point between gaps would be invisible as a line.
                            let (x, t) = piece[0];
                            chart
                                .draw_series(std::iter::once(Circle::new(
                                    (x, from_display(t, log)),
                                    f64::from(line_w),
                                    color.filled(),
                                )))
                                .map_err(|e| e.to_string())?;
                            continue;
                        }
                        // Segment by segment: plotters joins a thick polyline into one
                        // polygon, which breaks up on dense zig-zags.
                        chart
                            .draw_series(piece.windows(2).map(|w| {
                                PathElement::new(
                                    vec![
                                        (w[0].0, from_display(w[0].1, log)),
                                        (w[1].0, from_display(w[1].1, log)),
                                    ],
                                    style,
                                )
                            }))
                            .map_err(|e| e.to_string())?;
                    }
                }
            }
            if draws_points {
                let pts = common::dedup_pixels(
                    segs.iter().flatten().copied(),
                    xr,
                    tr,
                    pw as usize,
                    ph as usize,
                );
                occupied.extend(pts.iter().map(|&p| norm(p)));
                chart
                    .draw_series(pts.into_iter().map(|(x, t)| {
                        Circle::new((x, from_display(t, log)), radius, color.filled())
                    }))
                    .map_err(|e| e.to_string())?;
            }

            if !se.label.trim().is_empty() {
                legend.push((se.label.clone(), color, se.style));
            }
        }

        if !self.has_data {
            let style = common::font(s, 20.0).color(&RGBColor(120, 120, 120));
            common::centered_text(
                &chart.plotting_area().strip_coord_spec(),
                "no data",
                &style,
                pw as i32 / 2,
                ph as i32 / 2,
            )?;
        }

        if !legend.is_empty() {
            let area = chart.plotting_area().strip_coord_spec();
            draw_legend(&area, &legend, &occupied, s, line_w)?;
        }
        Ok(())
    }
}

/// Add the normalised vertices of a polyline, with extra samples along long segments so a
/// line crossing a corner counts even without a vertex there.
fn densify_into(
    out: &mut Vec<(f64, f64)>,
    piece: &[(f64, f64)],
    norm: &impl Fn((f64, f64)) -> (f64, f64),
) {
    let mut prev: Option<(f64, f64)> = None;
    for &p in piece {
        let q = norm(p);
        if let Some(a) = prev {
            let len = ((q.0 - a.0).powi(2) + (q.1 - a.1).powi(2)).sqrt();
            let n = ((len / 0.02).ceil() as usize).clamp(1, 100);
            for k in 1..n {
                let t = k as f64 / n as f64;
                out.push((a.0 + t * (q.0 - a.0), a.1 + t * (q.1 - a.1)));
            }
        }
        out.push(q);
        prev = Some(q);
    }
}

/// Draw the legend box in the plot corner that covers the fewest drawn points.
fn draw_legend(
    area: &Area<'_>,
    entries: &[(String, RGBColor, SeriesStyle)],
    occupied: &[(f64, f64)],
    s: f64,
    line_w: u32,
) -> Result<(), String> {
    let font = common::font(s, 16.0);
    let (pw, ph) = area.dim_in_pixel();
    let text_w = common::max_text_width(area, entries.iter().map(|e| e.0.clone()), &font) as i32;
    let pad = (10.0 * s) as i32;
    let sample = (30.0 * s) as i32;
    let row = (24.0 * s) as i32;
    let margin = (10.0 * s) as i32;
    let bw = pad + sample + pad + text_w + pad;
    let bh = pad / 2 + row * entries.len() as i32 + pad / 2;
    // Normalised box (plus its margin) for the overlap count; y counts upwards there.
    let wn = f64::from(bw + 2 * margin) / f64::from(pw.max(1));
    let hn = f64::from(bh + 2 * margin) / f64::from(ph.max(1));
    let (fx, fy) = best_spot(occupied, wn, hn);
    let x0 = margin + (f64::from(pw as i32 - 2 * margin - bw).max(0.0) * fx) as i32;
    let y0 = margin + (f64::from(ph as i32 - 2 * margin - bh).max(0.0) * fy) as i32;
    area.draw(&Rectangle::new(
        [(x0, y0), (x0 + bw, y0 + bh)],
        WHITE.mix(0.8).filled(),
    ))
    .map_err(|e| e.to_string())?;
    area.draw(&Rectangle::new(
        [(x0, y0), (x0 + bw, y0 + bh)],
        RGBColor(170, 170, 170).stroke_width(1),
    ))
    .map_err(|e| e.to_string())?;
    let text_style = font.pos(Pos::new(HPos::Left, VPos::Center));
    for (k, (label, color, style)) in entries.iter().enumerate() {
        let y = y0 + pad / 2 + row * k as i32 + row / 2;
        let xs = x0 + pad;
        if *style != SeriesStyle::Points {
            area.draw(&PathElement::new(
                vec![(xs, y), (xs + sample, y)],
                color.stroke_width(line_w),
            ))
            .map_err(|e| e.to_string())?;
        }
        if *style != SeriesStyle::Line {
            area.draw(&Circle::new(
                (xs + sample / 2, y),
                (3.5 * s).max(1.5),
                color.filled(),
            ))
            .map_err(|e| e.to_string())?;
        }
        area.draw_text(label, &text_style, (xs + sample + pad, y))
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

/// Where the legend covers the fewest drawn points, as fractions (0 = left / top, 1 =
/// right / bottom) of the room left around a `w`×`h` box (normalised units). Corners
/// first, then edge middles; ties keep the earlier candidate.
fn best_spot(occupied: &[(f64, f64)], w: f64, h: f64) -> (f64, f64) {
    const SPOTS: [(f64, f64); 8] = [
        (1.0, 0.0),
        (0.0, 0.0),
        (1.0, 1.0),
        (0.0, 1.0),
        (0.5, 0.0),
        (0.5, 1.0),
        (1.0, 0.5),
        (0.0, 0.5),
    ];
    let (w, h) = (w.min(1.0), h.min(1.0));
    let mut best = SPOTS[0];
    let mut best_count = usize::MAX;
    for (fx, fy) in SPOTS {
        // occupied points have y counting upwards; spots count downwards
        let x0 = (1.0 - w) * fx;
        let y1 = 1.0 - (1.0 - h) * fy;
        let count = occupied
            .iter()
            .filter(|p| p.0 >= x0 && p.0 <= x0 + w && p.1 >= y1 - h && p.1 <= y1)
            .count();
        // Edge middles must be clearly better than a corner to win.
        let count = if fx == 0.5 || fy == 0.5 {
            count.saturating_add(count / 2 + 1)
        } else {
            count
        };
        if count < best_count {
            best = (fx, fy);
            best_count = count;
        }
    }
    best
}
