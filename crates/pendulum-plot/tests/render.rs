//! Every figure kind renders to a PNG of the requested size, on good and on degenerate data.

use std::path::Path;
use std::time::Instant;

use pendulum_plot::{
    save_heatmaps_side_by_side, CategoryScatter, Figure, Heatmap, Panel, PlotError, Series,
    SeriesStyle,
};

/// Width and height from the PNG signature + IHDR chunk.
fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert!(
        bytes.len() > 33,
        "{} is too short for a PNG",
        path.display()
    );
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "not a PNG signature");
    assert_eq!(&bytes[12..16], b"IHDR", "first chunk is not IHDR");
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    (w, h)
}

fn no_temp_files_left(dir: &Path) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.contains(".tmp"), "temporary file left behind: {name}");
    }
}

fn line(label: &str, x: Vec<f64>, y: Vec<f64>, style: SeriesStyle) -> Series {
    Series {
        label: label.into(),
        x,
        y,
        style,
        color: None,
    }
}

fn panel(title: &str, series: Vec<Series>) -> Panel {
    Panel {
        title: title.into(),
        x_label: "time (s)".into(),
        y_label: "angle (rad)".into(),
        series,
        log_y: false,
        y_range: None,
    }
}

#[test]
fn figure_with_stacked_panels() {
    let dir = tempfile::tempdir().unwrap();
    let t: Vec<f64> = (0..2000).map(|i| f64::from(i) * 0.01).collect();
    let y: Vec<f64> = t
        .iter()
        .map(|t| (-t / 5.0).exp() * (6.0 * t).sin())
        .collect();
    let env: Vec<f64> = t.iter().map(|t| (-t / 5.0).exp()).collect();
    let mut log_panel = panel(
        "envelope",
        vec![line("fit", t.clone(), env, SeriesStyle::LinePoints)],
    );
    log_panel.log_y = true;
    let fig = Figure {
        title: "Decay".into(),
        panels: vec![
            panel(
                "angle",
                vec![line("measured", t.clone(), y.clone(), SeriesStyle::Line)],
            ),
            panel("points", vec![line("samples", t, y, SeriesStyle::Points)]),
            log_panel,
        ],
        width: 1200,
        height: 900,
    };
    let path = dir.path().join("fig.png");
    fig.save_png(&path).unwrap();
    assert_eq!(png_size(&path), (1200, 900));
    no_temp_files_left(dir.path());
    // Overwriting an existing file works too.
    fig.save_png(&path).unwrap();
    assert_eq!(png_size(&path), (1200, 900));
}

#[test]
fn figure_degenerate_data_does_not_panic() {
    let dir = tempfile::tempdir().unwrap();
    let nan = f64::NAN;
    let cases: Vec<(&str, Figure)> = vec![
        (
            "no_panels",
            Figure {
                title: "nothing".into(),
                panels: vec![],
                width: 640,
                height: 480,
            },
        ),
        (
            "empty_series",
            Figure {
                panels: vec![
                    panel("", vec![Series::default()]),
                    panel("no series", vec![]),
                ],
                ..Figure::default()
            },
        ),
        (
            "all_nan",
            Figure {
                panels: vec![panel(
                    "nan",
                    vec![line("a", vec![nan; 10], vec![nan; 10], SeriesStyle::Line)],
                )],
                ..Figure::default()
            },
        ),
        (
            "constant",
            Figure {
                panels: vec![panel(
                    "flat",
                    vec![line(
                        "c",
                        vec![3.0; 5],
                        vec![7.0; 5],
                        SeriesStyle::LinePoints,
                    )],
                )],
                ..Figure::default()
            },
        ),
        (
            "mixed_nan_inf_mismatched_len",
            Figure {
                panels: vec![panel(
                    "gaps",
                    vec![line(
                        "g",
                        vec![0.0, 1.0, 2.0, f64::INFINITY, 4.0, 5.0, 6.0],
                        vec![1.0, nan, 3.0, 4.0, 5.0],
                        SeriesStyle::Line,
                    )],
                )],
                ..Figure::default()
            },
        ),
        (
            "log_with_nonpositive",
            Figure {
                panels: vec![Panel {
                    log_y: true,
                    ..panel(
                        "log",
                        vec![line(
                            "l",
                            vec![0.0, 1.0, 2.0, 3.0],
                            vec![-1.0, 0.0, 1e-3, 10.0],
                            SeriesStyle::Line,
                        )],
                    )
                }],
                ..Figure::default()
            },
        ),
        (
            "log_all_nonpositive",
            Figure {
                panels: vec![Panel {
                    log_y: true,
                    ..panel(
                        "log",
                        vec![line(
                            "l",
                            vec![0.0, 1.0],
                            vec![-1.0, 0.0],
                            SeriesStyle::Points,
                        )],
                    )
                }],
                ..Figure::default()
            },
        ),
        (
            "bad_y_range_ignored",
            Figure {
                panels: vec![
                    Panel {
                        y_range: Some((nan, 1.0)),
                        ..panel(
                            "r",
                            vec![line("l", vec![0.0, 1.0], vec![0.0, 1.0], SeriesStyle::Line)],
                        )
                    },
                    Panel {
                        y_range: Some((2.0, 2.0)),
                        ..panel(
                            "r",
                            vec![line("l", vec![0.0, 1.0], vec![0.0, 1.0], SeriesStyle::Line)],
                        )
                    },
                    Panel {
                        y_range: Some((-1.0, 1.0)),
                        log_y: true,
                        ..panel(
                            "r",
                            vec![line("l", vec![0.0, 1.0], vec![0.5, 1.0], SeriesStyle::Line)],
                        )
                    },
                    Panel {
                        y_range: Some((0.2, 0.4)),
                        ..panel(
                            "clipped",
                            vec![line("l", vec![0.0, 1.0], vec![0.0, 1.0], SeriesStyle::Line)],
                        )
                    },
                ],
                ..Figure::default()
            },
        ),
        (
            "huge_and_tiny_values",
            Figure {
                panels: vec![
                    panel(
                        "big",
                        vec![line(
                            "b",
                            vec![0.0, 1e9],
                            vec![1e12, 3e12],
                            SeriesStyle::Line,
                        )],
                    ),
                    panel(
                        "tiny",
                        vec![line(
                            "t",
                            vec![0.0, 1e-9],
                            vec![-1e-12, 3e-12],
                            SeriesStyle::Line,
                        )],
                    ),
                ],
                ..Figure::default()
            },
        ),
    ];
    for (name, fig) in cases {
        let path = dir.path().join(format!("{name}.png"));
        fig.save_png(&path)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(png_size(&path), (fig.width, fig.height), "{name}");
    }
    no_temp_files_left(dir.path());
}

#[test]
fn million_point_series_renders_quickly() {
    let dir = tempfile::tempdir().unwrap();
    let n = 1_000_000;
    let x: Vec<f64> = (0..n).map(|i| f64::from(i) * 1e-4).collect();
    let y: Vec<f64> = x
        .iter()
        .map(|t| (t * 13.0).sin() + 0.01 * (t * 977.0).sin())
        .collect();
    let fig = Figure {
        title: "long".into(),
        panels: vec![
            panel(
                "line",
                vec![line("y", x.clone(), y.clone(), SeriesStyle::Line)],
            ),
            panel("points", vec![line("y", x, y, SeriesStyle::Points)]),
        ],
        ..Figure::default()
    };
    let path = dir.path().join("long.png");
    let start = Instant::now();
    fig.save_png(&path).unwrap();
    let took = start.elapsed();
    assert_eq!(png_size(&path), (1200, 700));
    assert!(took.as_secs_f64() < 10.0, "took {took:?}");
}

#[test]
fn category_scatter_renders() {
    let dir = tempfile::tempdir().unwrap();
    let n = 50_000;
    let x: Vec<f64> = (0..n)
        .map(|i| 0.5 + 2.0 * f64::from(i) / f64::from(n))
        .collect();
    let y: Vec<f64> = x
        .iter()
        .enumerate()
        .map(|(i, w)| w * ((i % 17) as f64 * 0.1))
        .collect();
    let category: Vec<usize> = (0..n as usize).map(|i| i % 3).collect();
    let sc = CategoryScatter {
        title: "bifurcation".into(),
        x_label: "ω (rad/s)".into(),
        y_label: "θ̇ (rad/s)".into(),
        x,
        y,
        category,
        category_names: vec![
            "period 1".into(),
            "period 2".into(),
            "chaos".into(),
            "rest".into(),
        ],
        category_colors: None,
        width: 1200,
        height: 700,
    };
    let path = dir.path().join("scatter.png");
    sc.save_png(&path).unwrap();
    assert_eq!(png_size(&path), (1200, 700));

    // Custom colours, too-short colour list, unnamed category, NaNs.
    let sc2 = CategoryScatter {
        x: vec![1.0, 2.0, f64::NAN, 4.0],
        y: vec![1.0, f64::INFINITY, 3.0, 4.0],
        category: vec![0, 7, 1, 1],
        category_names: vec!["a".into()],
        category_colors: Some(vec![(10, 20, 30)]),
        width: 800,
        height: 600,
        ..CategoryScatter::default()
    };
    let path = dir.path().join("scatter2.png");
    sc2.save_png(&path).unwrap();
    assert_eq!(png_size(&path), (800, 600));

    for (name, sc) in [
        ("empty", CategoryScatter::default()),
        (
            "constant",
            CategoryScatter {
                x: vec![2.0; 4],
                y: vec![-1.0; 4],
                category: vec![0; 4],
                ..CategoryScatter::default()
            },
        ),
        (
            "all_nan",
            CategoryScatter {
                x: vec![f64::NAN; 3],
                y: vec![1.0; 3],
                category: vec![2; 3],
                ..CategoryScatter::default()
            },
        ),
    ] {
        let path = dir.path().join(format!("{name}.png"));
        sc.save_png(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(png_size(&path), (1200, 700), "{name}");
    }
    no_temp_files_left(dir.path());
}

fn grid(nx: usize, ny: usize) -> Heatmap {
    let x_edges: Vec<f64> = (0..=nx).map(|i| 1.0 + i as f64 * 0.1).collect();
    let y_edges: Vec<f64> = (0..=ny).map(|j| j as f64 * 0.01).collect();
    let values = (0..ny)
        .map(|j| {
            (0..nx)
                .map(|i| {
                    if (i + j) % 11 == 0 {
                        f64::NAN
                    } else {
                        (i * j) as f64
                    }
                })
                .collect()
        })
        .collect();
    Heatmap {
        title: "zones".into(),
        x_label: "ω (rad/s)".into(),
        y_label: "amplitude (m)".into(),
        x_edges,
        y_edges,
        values,
        value_label: "fraction rotating".into(),
        marks: vec![(0, 0), (nx - 1, ny - 1), (nx + 5, 0)],
        ..Heatmap::default()
    }
}

#[test]
fn heatmaps_render() {
    let dir = tempfile::tempdir().unwrap();
    let hm = grid(80, 50);
    let path = dir.path().join("heat.png");
    hm.save_png(&path).unwrap();
    assert_eq!(png_size(&path), (hm.width, hm.height));

    let cases = [
        ("empty", Heatmap::default()),
        (
            "all_nan",
            Heatmap {
                values: vec![vec![f64::NAN; 80]; 50],
                ..grid(80, 50)
            },
        ),
        (
            "constant",
            Heatmap {
                values: vec![vec![0.5; 80]; 50],
                ..grid(80, 50)
            },
        ),
        (
            "fixed_scale_reversed",
            Heatmap {
                vmin: Some(10.0),
                vmax: Some(-10.0),
                ..grid(3, 2)
            },
        ),
        (
            "single_cell",
            Heatmap {
                vmin: Some(f64::NAN),
                ..grid(1, 1)
            },
        ),
    ];
    for (name, hm) in &cases {
        let path = dir.path().join(format!("{name}.png"));
        hm.save_png(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(png_size(&path), (hm.width, hm.height), "{name}");
    }

    let a = grid(40, 30);
    let b = Heatmap {
        title: "other".into(),
        width: 800,
        height: 600,
        ..grid(20, 10)
    };
    let path = dir.path().join("side.png");
    save_heatmaps_side_by_side(&[a.clone(), b.clone()], "compare", &path).unwrap();
    assert_eq!(png_size(&path), (a.width + b.width, a.height.max(b.height)));
    no_temp_files_left(dir.path());
}

#[test]
fn bad_input_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bad.png");

    let mut hm = grid(4, 3);
    hm.values.pop();
    let err = hm.save_png(&path).unwrap_err();
    assert!(matches!(err, PlotError::InvalidData { .. }), "{err}");
    assert!(err.to_string().contains("bad.png"), "{err}");

    let mut hm = grid(4, 3);
    hm.values[1].push(1.0);
    assert!(matches!(
        hm.save_png(&path),
        Err(PlotError::InvalidData { .. })
    ));

    let mut hm = grid(4, 3);
    hm.x_edges[2] = f64::NAN;
    assert!(matches!(
        hm.save_png(&path),
        Err(PlotError::InvalidData { .. })
    ));

    let sc = CategoryScatter {
        x: vec![1.0, 2.0],
        y: vec![1.0],
        category: vec![0, 0],
        ..CategoryScatter::default()
    };
    assert!(matches!(
        sc.save_png(&path),
        Err(PlotError::InvalidData { .. })
    ));

    let fig = Figure {
        width: 0,
        ..Figure::default()
    };
    assert!(matches!(
        fig.save_png(&path),
        Err(PlotError::InvalidData { .. })
    ));

    assert!(matches!(
        save_heatmaps_side_by_side(&[], "none", &path),
        Err(PlotError::InvalidData { .. })
    ));

    // A path whose parent is a file cannot be written: an I/O error, no panic.
    let file = dir.path().join("plain-file");
    std::fs::write(&file, b"x").unwrap();
    let err = Figure::default()
        .save_png(&file.join("sub.png"))
        .unwrap_err();
    assert!(matches!(err, PlotError::Io { .. }), "{err}");

    assert!(!path.exists(), "nothing should have been written");
    no_temp_files_left(dir.path());
}

#[test]
fn concurrent_saves_do_not_clash() {
    let dir = tempfile::tempdir().unwrap();
    std::thread::scope(|s| {
        for i in 0..4 {
            let dir = dir.path();
            s.spawn(move || {
                let fig = Figure {
                    title: format!("thread {i}"),
                    panels: vec![panel(
                        "p",
                        vec![line(
                            "l",
                            vec![0.0, 1.0],
                            vec![0.0, f64::from(i)],
                            SeriesStyle::Line,
                        )],
                    )],
                    width: 400,
                    height: 300,
                };
                fig.save_png(&dir.join("same.png")).unwrap();
            });
        }
    });
    assert_eq!(png_size(&dir.path().join("same.png")), (400, 300));
    no_temp_files_left(dir.path());
}

/// Issue 13, item 6: every PNG carries the text set for the process (the program's invocation
/// id), in a `tEXt` chunk right after IHDR that a PNG reader accepts (valid CRC); the image is
/// unchanged otherwise; a key PNG does not allow is refused.
#[test]
fn issue_13_pngs_carry_the_process_text() {
    let dir = tempfile::tempdir().unwrap();
    let fig = Figure {
        title: "t".into(),
        panels: vec![panel(
            "p",
            vec![line("a", vec![0.0, 1.0], vec![0.0, 1.0], SeriesStyle::Line)],
        )],
        width: 320,
        height: 240,
    };
    pendulum_plot::set_png_text("invocation_id", "1700000000.000000001-42").unwrap();
    pendulum_plot::set_png_text("invocation_id", "1700000000.000000002-42").unwrap();
    let path = dir.path().join("stamped.png");
    fig.save_png(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    assert_eq!(&bytes[33 + 4..33 + 8], b"tEXt", "the chunk follows IHDR");
    let text = pendulum_plot::png_text_of(&bytes);
    assert_eq!(
        text,
        [(
            "invocation_id".to_string(),
            "1700000000.000000002-42".to_string()
        )]
    );
    assert_eq!(png_size(&path), (320, 240));
    no_temp_files_left(dir.path());
    // A corrupted chunk is not read back as text.
    let mut bad = bytes.clone();
    bad[33 + 9] ^= 1;
    assert!(pendulum_plot::png_text_of(&bad).is_empty());
    assert!(pendulum_plot::set_png_text("", "x").is_err());
    assert!(pendulum_plot::set_png_text(" lead", "x").is_err());
    assert!(pendulum_plot::set_png_text("k", "a\0b").is_err());
}
