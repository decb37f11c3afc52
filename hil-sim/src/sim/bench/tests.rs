use super::*;

#[test]
fn every_effect_and_form_reaches_its_size_on_every_family() {
    for (e, forms) in EFFECTS {
        for form in 0..*forms {
            for f in FAMILIES {
                let c = Case { form, duration_s: 6.0, fs_hz: 1000.0, size: 0.05, ..Case::draw(e, f, "multisine", 3) };
                let g = generate(&c).unwrap_or_else(|err| panic!("{e}/{form}/{f}: {err}"));
                let share = g.label.effect_rms_nm / g.label.span_nm;
                assert!((share - 0.05).abs() < 0.005, "{e}/{form} ({}) on {f}: {share}", g.label.form);
            }
        }
    }
}

#[test]
fn the_sets_do_not_share_seeds_and_cover_everything() {
    let seeds: Vec<Vec<u64>> =
        Set::NAMED.iter().map(|(_, s, _, _)| cases(*s, 300, 60).iter().map(|c| c.seed).collect()).collect();
    for (i, a) in seeds.iter().enumerate() {
        for b in &seeds[i + 1..] {
            assert!(a.iter().all(|s| !b.contains(s)), "two sets share a seed");
        }
    }
    let held = cases(Set::Heldout, 300, 60);
    for (e, _) in EFFECTS {
        for x in EXCITATIONS {
            assert!(held.iter().any(|c| c.effect == *e && c.excitation == *x), "{e} {x}");
        }
    }
    for f in FAMILIES {
        assert!(held.iter().any(|c| c.family == *f && c.effect == "none"));
    }
}

#[test]
fn the_label_stays_out_of_the_recording() {
    let c = Case::draw("field_lag", "kwok", "noise", 5);
    let g = generate(&c).unwrap();
    let names: Vec<&str> = g.recording.columns.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(&names[..5], &["t", "b", "torque", "i", "speed"]);
    assert!(generate(&c).unwrap().recording.columns[2].values == g.recording.columns[2].values);
}

#[test]
fn blocks_join_without_a_jump_in_the_field() {
    let dt = 1e-3;
    let t: Vec<f64> = (0..20_000).map(|k| k as f64 * dt).collect();
    let mut rng = rand::rngs::StdRng::seed_from_u64(11);
    let s = signals::excitation("blocks", &t, 20.0, dt, &mut rng);
    // Normalised to [−1, 1] from amplitudes of at least 0.5: a slope of at most 2·2π·9 per s.
    let steepest = 2.0 * 2.0 * PI * 9.0 * dt;
    let worst = s.windows(2).map(|w| (w[1] - w[0]).abs()).fold(0.0, f64::max);
    assert!(worst <= 1.01 * steepest, "a step of {worst} between samples (slope bound {steepest})");
}

#[test]
fn rate_dependence_is_sized_beyond_a_linear_damping() {
    for form in 0..3 {
        let c = Case {
            form,
            duration_s: 6.0,
            fs_hz: 1000.0,
            size: 0.05,
            ..Case::draw("rate_dependence", "bouc_wen", "multisine", 7)
        };
        let mut rng = rand::rngs::StdRng::seed_from_u64(c.seed);
        let w = World::new(&c, &mut rng).unwrap();
        let a = effects::apply(&w, "rate_dependence", form, c.size);
        let change: Vec<f64> = a.torque.iter().zip(&w.base).map(|(t, b)| t - b).collect();
        // What a refitted c·ḃ and offset leave of the change, by ordinary least squares.
        let x = nalgebra::DMatrix::from_fn(change.len(), 2, |i, j| if j == 0 { 1.0 } else { w.db[i] });
        let y = nalgebra::DVector::from_column_slice(&change);
        let fit = x.clone().svd(true, true).solve(&y, 1e-12).unwrap();
        let left = (&y - &x * fit).norm() / (change.len() as f64).sqrt();
        assert!((left / w.span - 0.05).abs() < 0.002, "form {form}: {} of the span beyond c·ḃ", left / w.span);
        assert!(
            signals::rms_about_mean(&change) > left,
            "form {form}: the whole term is larger than its part beyond c·ḃ"
        );
    }
}
