//! Renders one figure of each kind from synthetic data, for looking at:
//! `cargo run --release -p pendulum-plot --example gallery -- /tmp/plot-examples`

use std::path::PathBuf;
use std::time::Instant;

use pendulum_plot::{
    save_heatmaps_side_by_side, CategoryScatter, Figure, Heatmap, Panel, Series, SeriesStyle,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "plot-examples".into()),
    );
    std::fs::create_dir_all(&dir)?;

    // 1. Stacked time series: a million-sample decaying oscillation, then a log-y envelope.
    let n = 1_000_000;
    let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
    let theta: Vec<f64> = t
        .iter()
        .enumerate()
        .map(|(i, &t)| {
            let noise = (((i as u64).wrapping_mul(2654435761) % 1000) as f64 / 1000.0 - 0.5) * 0.02;
            0.8 * (-t / 40.0).exp() * (2.0 * std::f64::consts::PI * 0.9 * t).sin() + noise
        })
        .collect();
    let mut model: Vec<f64> = t
        .iter()
        .map(|&t| 0.8 * (-t / 40.0).exp() * (2.0 * std::f64::consts::PI * 0.9 * t).sin())
        .collect();
    for v in &mut model[300_000..320_000] {
        *v = f64::NAN; // a gap
    }
    let peaks_t: Vec<f64> = (0..90).map(|k| k as f64 / 0.9 + 0.28).collect();
    let peaks: Vec<f64> = peaks_t
        .iter()
        .map(|&t| 0.8 * (-t / 40.0).exp() * (1.0 + 0.03 * (t * 7.0).sin()))
        .collect();
    let fit: Vec<f64> = peaks_t.iter().map(|&t| 0.8 * (-t / 40.0).exp()).collect();
    let fig = Figure {
        title: "Free decay, run 2024-05-03-a".into(),
        panels: vec![
            Panel {
                title: "Angle".into(),
                x_label: "time (s)".into(),
                y_label: "θ (rad)".into(),
                series: vec![
                    Series {
                        label: "encoder".into(),
                        x: t.clone(),
                        y: theta,
                        style: SeriesStyle::Line,
                        color: None,
                    },
                    Series {
                        label: "model".into(),
                        x: t.clone(),
                        y: model,
                        style: SeriesStyle::Line,
                        color: None,
                    },
                ],
                log_y: false,
                y_range: None,
            },
            Panel {
                title: "Peak amplitude".into(),
                x_label: "time (s)".into(),
                y_label: "amplitude (rad)".into(),
                series: vec![
                    Series {
                        label: "measured peaks".into(),
                        x: peaks_t.clone(),
                        y: peaks,
                        style: SeriesStyle::Points,
                        color: None,
                    },
                    Series {
                        label: "exponential fit, τ = 40 s".into(),
                        x: peaks_t,
                        y: fit,
                        style: SeriesStyle::Line,
                        color: Some(1),
                    },
                ],
                log_y: true,
                y_range: None,
            },
        ],
        width: 1200,
        height: 900,
    };
    let start = Instant::now();
    fig.save_png(&dir.join("decay.png"))?;
    println!("decay.png: {:?}", start.elapsed());

    // 2. Bifurcation-style category scatter.
    let mut x = Vec::new();
    let mut y = Vec::new();
    let mut cat = Vec::new();
    let mut seed = 12345u64;
    let mut rnd = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed % 1_000_000) as f64 / 1_000_000.0
    };
    for i in 0..800 {
        let w = 0.5 + 2.5 * i as f64 / 800.0;
        let (class, count) = if w < 1.6 {
            (0, 1)
        } else if w < 1.9 {
            (1, 2)
        } else if w < 2.3 {
            (2, 60)
        } else {
            (3, 1)
        };
        for k in 0..count {
            x.push(w);
            let v = match class {
                0 => 0.3 * w,
                1 => 0.5 + 0.3 * (k as f64 - 0.5) * (w - 1.6).sqrt() * 2.0,
                2 => -1.0 + 3.0 * rnd(),
                _ => 4.0 + 0.2 * (w - 2.3),
            };
            y.push(v);
            cat.push(class);
        }
    }
    let sc = CategoryScatter {
        title: "Steady state vs drive frequency".into(),
        x_label: "drive frequency ω (rad/s)".into(),
        y_label: "θ̇ at drive phase 0 (rad/s)".into(),
        x,
        y,
        category: cat,
        category_names: vec![
            "period 1".into(),
            "period 2".into(),
            "chaotic".into(),
            "rotating".into(),
            "at rest".into(),
        ],
        category_colors: None,
        width: 1200,
        height: 700,
    };
    let start = Instant::now();
    sc.save_png(&dir.join("bifurcation.png"))?;
    println!("bifurcation.png: {:?}", start.elapsed());

    // 3. Heat map with missing cells and marks.
    let (nx, ny) = (60, 40);
    let x_edges: Vec<f64> = (0..=nx).map(|i| 0.5 + 2.5 * i as f64 / nx as f64).collect();
    let y_edges: Vec<f64> = (0..=ny).map(|j| 0.3 * j as f64 / ny as f64).collect();
    let zone = |shift: f64| -> Vec<Vec<f64>> {
        (0..ny)
            .map(|j| {
                (0..nx)
                    .map(|i| {
                        let w = 0.5 * (x_edges[i] + x_edges[i + 1]);
                        let a = 0.5 * (y_edges[j] + y_edges[j + 1]);
                        if i > 50 && j > 30 {
                            return f64::NAN;
                        }
                        let d = (w - 2.0 - shift).abs() - a * 6.0;
                        (1.0 / (1.0 + (d * 8.0).exp())).clamp(0.0, 1.0)
                    })
                    .collect()
            })
            .collect()
    };
    let a = zone(0.0);
    let b = zone(0.05);
    let mut marks = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            if a[j][i].is_finite() && ((a[j][i] > 0.5) != (b[j][i] > 0.5)) {
                marks.push((i, j));
            }
        }
    }
    let hm_a = Heatmap {
        title: "Rotation zone, rigid model".into(),
        x_label: "drive frequency ω (rad/s)".into(),
        y_label: "drive amplitude (m)".into(),
        x_edges: x_edges.clone(),
        y_edges: y_edges.clone(),
        values: a,
        value_label: "fraction of runs rotating".into(),
        vmin: Some(0.0),
        vmax: Some(1.0),
        marks: marks.clone(),
        width: 1000,
        height: 700,
        diverging: false,
    };
    let hm_b = Heatmap {
        title: "Rotation zone, flexible model".into(),
        values: b,
        ..hm_a.clone()
    };
    let start = Instant::now();
    hm_a.save_png(&dir.join("heatmap.png"))?;
    println!("heatmap.png: {:?}", start.elapsed());
    save_heatmaps_side_by_side(
        &[hm_a, hm_b],
        "Rotation zones (dots: models disagree)",
        &dir.join("heatmaps_side.png"),
    )?;

    // 4. Degenerate inputs.
    let degenerate = Figure {
        title: "Degenerate data".into(),
        panels: vec![
            Panel {
                title: "empty series".into(),
                x_label: "x (m)".into(),
                y_label: "y (m)".into(),
                series: vec![Series::default()],
                ..Panel::default()
            },
            Panel {
                title: "constant".into(),
                x_label: "time (s)".into(),
                y_label: "y (V)".into(),
                series: vec![Series {
                    label: "flat".into(),
                    x: vec![1.0, 2.0, 3.0],
                    y: vec![2.5; 3],
                    ..Series::default()
                }],
                ..Panel::default()
            },
            Panel {
                title: "NaNs, clipped range, single point".into(),
                x_label: "time (s)".into(),
                y_label: "y (1)".into(),
                series: vec![
                    Series {
                        label: "with gaps".into(),
                        x: (0..50).map(f64::from).collect(),
                        y: (0..50)
                            .map(|i| {
                                if i % 10 == 5 {
                                    f64::NAN
                                } else {
                                    f64::from(i % 7)
                                }
                            })
                            .collect(),
                        ..Series::default()
                    },
                    Series {
                        label: "one point".into(),
                        x: vec![25.0],
                        y: vec![3.0],
                        style: SeriesStyle::LinePoints,
                        color: None,
                    },
                ],
                y_range: Some((0.5, 4.5)),
                ..Panel::default()
            },
        ],
        width: 1200,
        height: 1000,
    };
    let awkward = Figure {
        title: "Awkward ranges".into(),
        panels: vec![
            Panel {
                title: "narrow log range".into(),
                x_label: "frequency (Hz)".into(),
                y_label: "PSD (rad²/Hz)".into(),
                series: vec![Series {
                    label: "psd".into(),
                    x: (0..100).map(f64::from).collect(),
                    y: (0..100).map(|i| 0.31 + 0.0008 * f64::from(i)).collect(),
                    ..Series::default()
                }],
                log_y: true,
                ..Panel::default()
            },
            Panel {
                title: "many decades".into(),
                x_label: "frequency (Hz)".into(),
                y_label: "PSD (rad²/Hz)".into(),
                series: vec![Series {
                    label: "psd".into(),
                    x: (1..500).map(f64::from).collect(),
                    y: (1..500)
                        .map(|i| 1e-9 * f64::from(i).powi(-3) + 1e-16)
                        .collect(),
                    ..Series::default()
                }],
                log_y: true,
                ..Panel::default()
            },
            Panel {
                title: "huge and tiny".into(),
                x_label: "time (ns)".into(),
                y_label: "count".into(),
                series: vec![Series {
                    label: String::new(),
                    x: vec![0.0, 2e-7, 4e-7],
                    y: vec![1e6, 3.5e6, 2e6],
                    style: SeriesStyle::LinePoints,
                    color: Some(2),
                }],
                ..Panel::default()
            },
        ],
        width: 1200,
        height: 1000,
    };
    awkward.save_png(&dir.join("awkward.png"))?;
    degenerate.save_png(&dir.join("degenerate.png"))?;
    Heatmap::default().save_png(&dir.join("heatmap_empty.png"))?;
    Ok(())
}
