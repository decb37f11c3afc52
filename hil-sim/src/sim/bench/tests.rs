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
        Set::NAMED.iter().map(|(_, s)| cases(*s, 300, 60).iter().map(|c| c.seed).collect()).collect();
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
