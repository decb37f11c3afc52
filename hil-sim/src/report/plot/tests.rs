#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]
use std::path::{Path, PathBuf};

use super::canvas::tick;
use super::decimate::envelope;
use super::range::{pad, range_of};
use super::*;

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join("hil-sim-plot-tests");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn read_svg(p: &Path) -> String {
    let s = std::fs::read_to_string(p).unwrap();
    assert!(s.starts_with("<svg"), "{}", &s[..s.len().min(80)]);
    assert!(s.trim_end().ends_with("</svg>"));
    s
}

/// The contents of the `<text>` elements.
fn texts(svg: &str) -> Vec<String> {
    svg.split("<text")
        .skip(1)
        .filter_map(|t| Some(t.split_once('>')?.1.split_once("</text>")?.0.trim().to_owned()))
        .collect()
}

fn sine(n: usize, f: f64, dt: f64) -> (Vec<f64>, Vec<f64>) {
    let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
    let y = t.iter().map(|t| (2.0 * std::f64::consts::PI * f * t).sin()).collect();
    (t, y)
}

#[test]
fn time_series_writes_svg_with_title_and_legend() {
    let (t, y) = sine(3000, 2.0, 1e-3);
    let m: Vec<f64> = y.iter().map(|v| 0.9 * v).collect();
    let p = tmp("ts.svg");
    time_series(
        &p,
        "Force: measured vs model",
        "time (s)",
        "force (N)",
        &t,
        &[Series::new("measured", &y), Series::new("model", &m).style(Style::rgb(200, 0, 0).width(1))],
    )
    .unwrap();
    let s = read_svg(&p);
    for want in ["Force: measured vs model", "measured", "model", "time (s)", "force (N)"] {
        assert!(s.contains(want), "missing {want}");
    }
}

#[test]
fn long_series_are_decimated_and_keep_peaks() {
    let n = 1_000_000;
    let (t, mut y) = sine(n, 3.0, 1e-5);
    y[654_321] = 25.0; // one-sample spike must survive
    let p = tmp("long.svg");
    time_series(&p, "long", "time (s)", "y", &t, &[Series::new("a", &y), Series::new("b", &y)]).unwrap();
    let s = read_svg(&p);
    assert!(s.len() < 500_000, "{} bytes", s.len());
    let segs = envelope(&t, &y, 0.0..t[n - 1], PLOT_W);
    assert!(segs[0].len() <= 4 * PLOT_W + 4);
    assert!(segs[0].iter().any(|p| p.1 == 25.0));
    // The y axis reaches the spike.
    assert!(texts(&s).iter().any(|t| t == "25"), "axis does not reach the spike: {:?}", texts(&s));
}

#[test]
fn nan_constant_and_empty_inputs() {
    let t: Vec<f64> = (0..500).map(|i| i as f64 * 0.01).collect();
    let mut y = vec![3.0; 500];
    y[10] = f64::NAN;
    y[20] = f64::INFINITY;
    let mut tt = t.clone();
    tt[30] = f64::NAN;
    let p = tmp("nan.svg");
    time_series(&p, "constant with holes", "t (s)", "y", &tt, &[Series::new("c", &y)]).unwrap();
    read_svg(&p);
    let nan = vec![f64::NAN; 500];
    assert!(matches!(
        time_series(&p, "x", "t", "y", &t, &[Series::new("n", &nan)]),
        Err(PlotError::NoFiniteData { .. })
    ));
    assert!(matches!(time_series(&p, "x", "t", "y", &[], &[]), Err(PlotError::Empty { .. })));
    assert!(matches!(time_series(&p, "x", "t", "y", &t, &[]), Err(PlotError::Empty { .. })));
    assert!(matches!(
        time_series(&p, "x", "t", "y", &t, &[Series::new("short", &y[..10])]),
        Err(PlotError::LengthMismatch { .. })
    ));
    assert!(matches!(hysteresis_loop(&p, "x", "a", "b", &[], &[], &[]), Err(PlotError::Empty { .. })));
    assert!(matches!(residual(&p, "x", "r", &[], &[], &[], None), Err(PlotError::Empty { .. })));
    let no: [(&str, Vec<f64>); 0] = [];
    assert!(matches!(bars(&p, "x", "y", &[], &no), Err(PlotError::Empty { .. })));
    assert!(matches!(bars(&p, "x", "y", &["a".to_owned()], &no), Err(PlotError::Empty { .. })));
    // A single point and all-equal time stamps do not panic.
    time_series(&p, "one point", "t", "y", &[1.0], &[Series::new("p", &[2.0])]).unwrap();
    time_series(&p, "same t", "t", "y", &[1.0; 5], &[Series::new("p", &[2.0, 3.0, f64::NAN, 1.0, 0.0])]).unwrap();
}

#[test]
fn hysteresis_loop_writes_both_curves_and_bounds_size() {
    let n = 200_000;
    let (t, xs) = sine(n, 5.0, 1e-4);
    let meas: Vec<f64> = t
        .iter()
        .enumerate()
        .map(|(i, t)| (2.0 * std::f64::consts::PI * 5.0 * t).cos() + 0.05 * ((i * 7919 % 101) as f64 / 101.0))
        .collect();
    let mut model: Vec<f64> = t.iter().map(|t| (2.0 * std::f64::consts::PI * 5.0 * t).cos()).collect();
    model[5] = f64::NAN;
    let p = tmp("loop.svg");
    hysteresis_loop(&p, "Loop: force vs displacement", "displacement (cm)", "force (N)", &xs, &meas, &model).unwrap();
    let s = read_svg(&p);
    for want in ["Loop: force vs displacement", "measured", "model", "displacement (cm)"] {
        assert!(s.contains(want), "missing {want}");
    }
    assert!(s.len() < 2_000_000, "{} bytes", s.len());
    assert!(matches!(
        hysteresis_loop(&p, "x", "a", "b", &xs, &meas[..5], &model),
        Err(PlotError::LengthMismatch { .. })
    ));
}

#[test]
fn residual_with_windows_and_train_marker() {
    let (t, y) = sine(150_000, 1.0, 1e-4);
    let p = tmp("res.svg");
    residual(
        &p,
        "Residual, held-out part shaded",
        "force residual (N)",
        &t,
        &y,
        &[(2.0, 3.0), (10.0, 12.0), (f64::NAN, 1.0)],
        Some(12.75),
    )
    .unwrap();
    let s = read_svg(&p);
    for want in
        ["Residual, held-out part shaded", "residual", "flagged by the quality checks", "end of training", "held-out"]
    {
        assert!(s.contains(want), "missing {want}");
    }
    assert!(s.len() < 1_000_000);
    // No windows, marker outside the axis: plain residual plot.
    residual(&p, "plain", "r (N)", &t, &y, &[], Some(1e9)).unwrap();
    let s = read_svg(&p);
    assert!(!s.contains("end of training") && !s.contains("flagged"));
}

#[test]
fn time_series_marks_the_boundary_and_puts_the_legend_under_the_chart() {
    let (t, y) = sine(3000, 2.0, 1e-3);
    let p = tmp("ts_marked.svg");
    time_series_marked(&p, "around the boundary", "time (s)", "F (N)", &t, &[Series::new("measured", &y)], Some(1.5))
        .unwrap();
    let s = read_svg(&p);
    assert!(s.contains("end of training") && s.contains("held-out"));
    // The legend's text sits below the plot area: under the x axis label.
    let y_of = |text: &str| -> f64 {
        let el = s
            .split("<text")
            .skip(1)
            .find(|e| e.split_once('>').unwrap().1.split("</text>").next().unwrap().trim() == text);
        let attrs = el.unwrap().split_once('>').unwrap().0;
        attrs.split(" y=\"").nth(1).unwrap().split('"').next().unwrap().parse().unwrap()
    };
    assert!(y_of("measured") > y_of("time (s)"), "legend over the chart");
    time_series_marked(&p, "outside", "time (s)", "F (N)", &t, &[Series::new("m", &y)], Some(99.0)).unwrap();
    assert!(!read_svg(&p).contains("end of training"));
}

#[test]
fn grouped_bars() {
    let cats: Vec<String> = ["bouc_wen", "spencer", "algebraic"].iter().map(|s| s.to_string()).collect();
    let groups = vec![("1 Hz", vec![0.12, 0.08, 0.2]), ("5 Hz", vec![0.15, f64::NAN, 0.25])];
    let p = tmp("bars.svg");
    bars(&p, "Held-out R-RMSE per model", "R-RMSE (%)", &cats, &groups).unwrap();
    let s = read_svg(&p);
    for want in ["Held-out R-RMSE per model", "1 Hz", "5 Hz", "bouc_wen", "spencer", "algebraic", "R-RMSE (%)"] {
        assert!(s.contains(want), "missing {want}");
    }
    // Negative and constant values.
    bars(&p, "neg", "v", &cats, &[("g", [-1.0, 2.0, 0.5])]).unwrap();
    bars(&p, "const", "v", &cats, &[("g", [0.0, 0.0, 0.0])]).unwrap();
    assert!(matches!(bars(&p, "nan", "v", &cats, &[("g", [f64::NAN; 3])]), Ok(())));
    assert!(matches!(bars(&p, "len", "v", &cats, &[("g", [1.0])]), Err(PlotError::LengthMismatch { .. })));
}

#[test]
fn helpers() {
    assert_eq!(pad(2.0..2.0, 0.05), 1.8..2.2);
    assert_eq!(pad(0.0..0.0, 0.05), -1.0..1.0);
    assert_eq!(range_of([f64::NAN, 1.0, -2.0, f64::INFINITY].into_iter()), Some(-2.0..1.0));
    assert_eq!(range_of([f64::NAN].into_iter()), None);
    assert_eq!(tick(3000.0, 5000.0), "3000");
    assert_eq!(tick(-0.0, 2.0), "0");
    assert_eq!(tick(0.25, 1.0), "0.25");
    assert_eq!(tick(0.2, 1.0), "0.2");
    assert_eq!(tick(12.5, 100.0), "12.5");
    assert_eq!(tick(2e-6, 1e-5), "2.00e-6");
    assert_eq!(tick(1e-17, 1.0), "0");
    let segs = envelope(&[0.0, 1.0, 2.0, 3.0], &[1.0, f64::NAN, 2.0, 3.0], 0.0..3.0, 10);
    assert_eq!(segs, vec![vec![(0.0, 1.0)], vec![(2.0, 2.0), (3.0, 3.0)]]);
}
