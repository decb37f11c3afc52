use std::path::Path;

use super::*;
use crate::io::recording::Column;

const FS: f64 = 1000.0;

/// Deterministic noise in [-1, 1).
fn noise(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    (0..n)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
        })
        .collect()
}

/// 10 s at 1 kHz: a multi-sine input `b` (span ≈ 5) and an output `torque` = 2·b + noise.
fn signals() -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = 10_000;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / FS).collect();
    let e = noise(n, 1);
    let b: Vec<f64> = t
        .iter()
        .zip(&e)
        .map(|(t, e)| {
            use std::f64::consts::TAU;
            (TAU * 1.3 * t).sin() + 0.8 * (TAU * 2.9 * t + 1.0).sin() + 0.6 * (TAU * 4.7 * t + 2.0).sin() + 1e-3 * e
        })
        .collect();
    let e = noise(n, 2);
    let y = b.iter().zip(&e).map(|(b, e)| 2.0 * b + 2e-3 * e).collect();
    (t, b, y)
}

fn rec(t: Vec<f64>, b: Vec<f64>, y: Vec<f64>) -> Recording {
    let col = |name: &str, values| Column { name: name.into(), values };
    Recording::from_columns(Path::new("syn.mat"), vec![col("t", t), col("b", b), col("torque", y)], vec![])
}

fn warnings(r: &Recording) -> Vec<(WarningKind, String, f64, f64)> {
    check(r, &Channels::default())
        .unwrap()
        .warnings
        .into_iter()
        .map(|w| (w.kind, w.channel, w.start_s, w.end_s))
        .collect()
}

fn near(a: f64, b: f64) -> bool {
    (a - b).abs() <= 0.05
}

#[test]
fn clean_signals_raise_nothing() {
    let (t, b, y) = signals();
    assert_eq!(warnings(&rec(t, b, y)), vec![]);
}

#[test]
fn flat_top_is_clipped() {
    let (t, b, mut y) = signals();
    let top = y.iter().copied().fold(f64::NEG_INFINITY, f64::max) * 1.02;
    // The output pinned at a sensor limit above its free peaks during 6.0–6.5 s.
    for v in &mut y[6000..=6500] {
        *v = top;
    }
    let w = warnings(&rec(t, b, y));
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!((w[0].0, w[0].1.as_str()), (WarningKind::Clipped, "torque"));
    assert!(near(w[0].2, 6.0) && near(w[0].3, 6.5), "{w:?}");
}

/// 12 s at 1 kHz: `b` a swept sine, 0.3 to 9 Hz (exponential), then 2 s of 1 Hz and 2 s of
/// 9 Hz at the same amplitude; `torque` = 2·b + noise of 1 % of the amplitude, clipped at
/// `clip` (± N·m) when given.
fn sweep_and_blocks(clip: Option<f64>) -> Recording {
    use std::f64::consts::TAU;
    let n = 16_000;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / FS).collect();
    let (f0, f1, sweep_s) = (0.3_f64, 9.0_f64, 12.0);
    let k = (f1 / f0).ln() / sweep_s;
    let phase = |t: f64| {
        if t < sweep_s {
            TAU * f0 * ((k * t).exp() - 1.0) / k
        } else if t < sweep_s + 2.0 {
            TAU * (t - sweep_s)
        } else {
            TAU * 9.0 * (t - sweep_s - 2.0)
        }
    };
    let (e1, e2) = (noise(n, 5), noise(n, 6));
    let b: Vec<f64> = t.iter().zip(&e1).map(|(&t, e)| phase(t).sin() + 1e-3 * e).collect();
    let y = b
        .iter()
        .zip(&e2)
        .map(|(b, e)| {
            let v = 2.0 * b + 0.02 * 3f64.sqrt() * e;
            clip.map_or(v, |c| v.clamp(-c, c))
        })
        .collect();
    rec(t, b, y)
}

#[test]
fn slow_peaks_and_blocks_of_full_peaks_are_not_clipped() {
    // The median T½ is the fast part's: a slow cycle's peak stays in the 2 % band for
    // several of them, and the 9 Hz block's peaks merge into one long episode; neither is flat.
    assert_eq!(warnings(&sweep_and_blocks(None)), vec![]);
}

#[test]
fn a_sweep_clipped_at_nine_tenths_of_its_peaks_is_clipped() {
    let w = warnings(&sweep_and_blocks(Some(1.8)));
    // The clamped samples are also bit-identical runs (held values); the input is untouched.
    assert!(w.iter().any(|w| (w.0, w.1.as_str()) == (WarningKind::Clipped, "torque")), "{w:?}");
    assert!(w.iter().all(|w| w.1 == "torque"), "{w:?}");
}

#[test]
fn bouncing_at_an_end_stop_is_clipped() {
    let (t, mut b, y) = signals();
    let top = b.iter().copied().fold(f64::NEG_INFINITY, f64::max) + 0.1;
    let e = noise(b.len(), 3);
    // The input held at a stop, bouncing by 1 % of its span, during 3.0–3.4 s.
    for i in 3000..=3400 {
        b[i] = top - 0.05 * e[i].abs() * ((i as f64) * 0.3).sin().abs();
    }
    let w = warnings(&rec(t, b, y));
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!((w[0].0, w[0].1.as_str()), (WarningKind::Clipped, "b"));
    assert!(near(w[0].2, 3.0) && near(w[0].3, 3.4), "{w:?}");
}

#[test]
fn input_at_rest_is_a_standstill() {
    let (t, mut b, y) = signals();
    let e = noise(b.len(), 4);
    let rest = b[7000];
    for i in 7000..b.len() {
        b[i] = rest + 1e-3 * e[i];
    }
    let w = warnings(&rec(t, b, y));
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!((w[0].0, w[0].1.as_str()), (WarningKind::Standstill, "b"));
    assert!(near(w[0].2, 7.0) && near(w[0].3, 9.999), "{w:?}");
    // Shorter than 0.5 s: no warning.
    let (t, mut b, y) = signals();
    let rest = b[7000];
    for v in &mut b[7000..7300] {
        *v = rest;
    }
    let w = warnings(&rec(t, b, y));
    assert!(w.iter().all(|w| w.0 != WarningKind::Standstill), "{w:?}");
}

#[test]
fn held_value_and_time_gap_are_dropouts() {
    let (t, b, mut y) = signals();
    let held = y[4000];
    for v in &mut y[4000..4040] {
        *v = held;
    }
    let w = warnings(&rec(t.clone(), b.clone(), y));
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!((w[0].0, w[0].1.as_str()), (WarningKind::Dropout, "torque"));
    assert!(near(w[0].2, 4.0) && near(w[0].3, 4.039), "{w:?}");
    // A 9-sample hold is within chance for nothing here but below the 10-sample floor.
    let (t2, b2, mut y2) = signals();
    let held = y2[4000];
    for v in &mut y2[4000..4009] {
        *v = held;
    }
    assert_eq!(warnings(&rec(t2, b2, y2)), vec![]);
    // 20 samples missing at 5 s.
    let (t, b, y) = signals();
    let keep = |v: &Vec<f64>| [&v[..5000], &v[5020..]].concat();
    let w = warnings(&rec(keep(&t), keep(&b), keep(&y)));
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!((w[0].0, w[0].1.as_str()), (WarningKind::Dropout, "t"));
    assert!(near(w[0].2, 4.999) && near(w[0].3, 5.02), "{w:?}");
}

#[test]
fn isolated_outlier_is_a_spike() {
    let (t, mut b, y) = signals();
    b[2500] += 1.0; // 20 % of the span
    let w = warnings(&rec(t, b, y));
    assert_eq!(w.len(), 1, "{w:?}");
    assert_eq!((w[0].0, w[0].1.as_str()), (WarningKind::Spike, "b"));
    assert!(near(w[0].2, 2.5) && near(w[0].3, 2.5), "{w:?}");
    // A step is not a spike.
    let (t, mut b, y) = signals();
    for v in &mut b[2500..] {
        *v += 1.0;
    }
    let w = warnings(&rec(t, b, y));
    assert!(w.iter().all(|w| w.0 != WarningKind::Spike), "{w:?}");
}

#[test]
fn short_intervals_are_non_uniform_sampling() {
    let (mut t, b, y) = signals();
    for (k, v) in t.iter_mut().enumerate().skip(8000) {
        *v -= if k == 8000 { 0.0007 } else { 0.0 };
    }
    // Interval 7999→8000 is 0.3 ms, 8000→8001 1.7 ms: the second is a gap-sized one.
    let w = warnings(&rec(t, b, y));
    let kinds: Vec<WarningKind> = w.iter().map(|w| w.0).collect();
    assert_eq!(kinds, vec![WarningKind::NonUniformSampling, WarningKind::Dropout], "{w:?}");
    assert!(w.iter().all(|w| near(w.2, 8.0) && w.1 == "t"), "{w:?}");
    // 30 % jitter (timestamp rounding) passes.
    let (mut t, b, y) = signals();
    for v in t.iter_mut().skip(1).step_by(3) {
        *v += 0.0003;
    }
    assert_eq!(warnings(&rec(t, b, y)), vec![]);
}

#[test]
fn excluded_marks_the_warned_samples_and_messages_name_places() {
    let (t, mut b, y) = signals();
    b[2500] += 1.0;
    let q = check(&rec(t, b, y), &Channels::default()).unwrap();
    let ex = q.excluded();
    assert_eq!(ex.len(), 10_000);
    assert_eq!(ex.iter().filter(|&&e| e).count(), 1);
    assert!(ex[2500]);
    assert_eq!(q.excluded_samples, 1);
    assert!(q.warnings[0].message.starts_with("syn.mat: sample 2501: b spike to"), "{}", q.warnings[0].message);
    let json = serde_json::to_value(&q).unwrap();
    assert_eq!(json["warnings"][0]["kind"], "spike");
}

#[test]
fn rest_at_start_between_tests_and_end_is_a_standstill() {
    let (t, mut b, mut y) = signals();
    let e = noise(b.len(), 5);
    let lowest = b.iter().copied().fold(f64::INFINITY, f64::min);
    // At rest at the input's minimum before the test (0–0.3 s), held bit for bit between two
    // tests (5.0–5.2 s) and after the end (9.8–10 s); the output stays quiet with it.
    let n = b.len();
    for (range, at) in [(0..300, lowest), (5000..5200, b[5000]), (9800..n, b[9800])] {
        for i in range {
            b[i] = at;
            y[i] = 2.0 * at + 2e-3 * e[i];
        }
    }
    let w = warnings(&rec(t, b, y));
    assert!(!w.is_empty(), "nothing found");
    assert!(w.iter().all(|w| w.0 == WarningKind::Standstill && w.1 == "b"), "{w:?}");
    for (a, z) in [(0.0, 0.299), (5.0, 5.199), (9.8, 9.999)] {
        assert!(w.iter().any(|w| near(w.2, a) && near(w.3, z)), "no standstill at {a}–{z} s: {w:?}");
    }
}
