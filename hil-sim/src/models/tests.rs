//! The host registry against model-core's: every model has a search box whose names
//! follow the registry.

use super::search::*;
use super::spencer::{dyke_1997, DYKE_SCALES};
use super::*;

fn spec(id: &str, s: &Scales, rate: Option<RateSpec>) -> Option<ModelSpec> {
    host(id)?.spec(s, rate)
}

fn scales(u: Option<f64>) -> Scales {
    Scales { x_mean: 0.1, x: 0.35, dx: 16.0, ddx: 2000.0, y_mean: -20.0, y: 430.0, u, fs: 3000.0 }
}

#[test]
fn names_follow_the_registry() {
    assert_eq!(HOSTS.len(), model_core::MODELS.len());
    for id in model_core::MODELS.iter().map(|m| m.id) {
        let s = spec(id, &scales(Some(2.0)), None).unwrap();
        let info = model_core::registry::find(id).unwrap();
        let mut names: Vec<&str> = s.params.iter().map(|p| p.name).collect();
        names.dedup();
        assert_eq!(names, info.params, "{id}");
        assert_eq!(s.params.len(), info.n_params, "{id}");
        for p in &s.params {
            assert!(p.lo <= p.start && p.start <= p.hi || p.fixed, "{id}.{}: {p:?}", p.name);
            assert!(p.spacing == Spacing::Linear || p.lo > 0.0, "{id}.{}", p.name);
        }
    }
    assert!(spec("nope", &scales(None), None).is_none());
}

#[test]
fn command_terms_are_fixed_without_a_command() {
    let with = spec("spencer", &scales(Some(2.25)), None).unwrap();
    let without = spec("spencer", &scales(None), None).unwrap();
    assert!(without.free().len() < with.free().len());
    assert!(without.params.iter().filter(|p| p.name.ends_with("b")).all(|p| p.fixed && p.start == 0.0));
}

#[test]
fn published_spencer_set_is_the_start_on_dyke_scales() {
    let (x, v, y) = DYKE_SCALES;
    let s = Scales { x_mean: 0.0, x, dx: v, ddx: 1.0, y_mean: 0.0, y, u: Some(2.25), fs: 3000.0 };
    let sp = spec("spencer", &s, None).unwrap();
    for (got, want) in sp.start().iter().zip(dyke_1997()) {
        assert!((got - want).abs() <= 1e-9 * want.abs().max(1.0), "{got} vs {want}");
    }
}

#[test]
fn unit_mapping_round_trips() {
    let a = ParamSpec::new("a", -2.0, 6.0, 0.0);
    let b = ParamSpec::new("b", 1e-3, 1e3, 1.0).log();
    for s in [0.0, 0.25, 0.5, 1.0] {
        assert!((a.to_unit(a.from_unit(s)) - s).abs() < 1e-12);
        assert!((b.to_unit(b.from_unit(s)) - s).abs() < 1e-12);
    }
    assert!((b.from_unit(0.5) - 1.0).abs() < 1e-12);
}

#[test]
fn published_values_are_the_printed_decimals() {
    assert_eq!(published(46.9), 46.9);
    assert_eq!(published(2.95), 2.95);
    assert_eq!(dyke_1997().map(|v| v as f32), model_core::models::spencer::DYKE_1997_FLAT);
}
