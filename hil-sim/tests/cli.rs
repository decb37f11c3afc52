//! The command-line contract (shared/spec/cli-contract.md), exercised on the binary.

mod common;
use common::hil_sim;

#[test]
fn models_json_lists_all_17_with_contract_fields() {
    let (code, out, _) = hil_sim(&["models", "--json"]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&out).expect("stdout is one JSON object");
    let models = v["models"].as_array().unwrap();
    let ids: Vec<&str> = models.iter().map(|m| m["id"].as_str().unwrap()).collect();
    // The registry's list, in its order, and every id of the contract's "Model identifiers".
    let registry: Vec<&str> = model_core::MODELS.iter().map(|m| m.id).collect();
    assert_eq!(ids, registry);
    assert_eq!(ids.len(), 17);
    for m in models {
        let params = m["params"].as_array().unwrap();
        assert!(!params.is_empty(), "{} has no parameter names", m["id"]);
        assert!(params.iter().all(|p| p.as_str().is_some_and(|s| !s.is_empty())));
        assert_eq!(m["no_std"], true);
        assert!(m["state_bytes"].as_u64().is_some());
        assert!(m["n_params"].as_u64().unwrap() >= params.len() as u64);
    }
}

#[test]
fn errors_are_one_line_and_nonzero() {
    let dir = std::env::temp_dir().join(format!("hil-sim-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let params = dir.join("p.json");
    std::fs::write(&params, r#"{"model":"algebraic","params":{"k":1,"c":0,"alpha":0,"t0":0}}"#).unwrap();
    let bad_params = dir.join("bad.json");
    std::fs::write(&bad_params, r#"{"model":"algebraic","params":{"k":1}}"#).unwrap();
    let rec = dir.join("r.csv");
    std::fs::write(&rec, "t,b,torque\n0,0,0\n0.001,0.1,0.1\n0.002,x,0.2\n").unwrap();
    let (p, b, r) = (params.to_str().unwrap(), bad_params.to_str().unwrap(), rec.to_str().unwrap());
    for (args, needle) in [
        (vec!["replay", r, "--params", p], "r.csv:4"),
        (vec!["replay", "/nonexistent.csv", "--params", p], "no such file"),
        (vec!["replay", r, "--params", b], "missing parameter `c`"),
        (vec!["replay", r, "--params", p, "--rate", "fast"], "--rate fast"),
        (vec!["accuracy", "--model", "nope"], "unknown model `nope`"),
    ] {
        let (code, out, err) = hil_sim(&args);
        assert_ne!(code, 0, "{args:?}");
        assert!(out.is_empty(), "{args:?} printed on stdout: {out}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
    // A good replay with --json prints exactly one object with metrics.
    std::fs::write(&rec, "t,b,torque\n0,0,0\n0.001,0.1,0.1\n0.002,0.2,0.2\n0.003,0.3,0.3\n").unwrap();
    let (code, out, _) = hil_sim(&["replay", r, "--params", p, "--json"]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(v["metrics"]["rmse"].as_f64().unwrap() < 1e-6);
    assert!(v["metrics"]["r2"].as_f64().unwrap() > 0.999_999);
}

#[test]
fn diagnose_json_follows_the_contract_on_a_concealed_recording() {
    let dir = std::env::temp_dir().join(format!("hil-sim-diagnose-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rec = dir.join("lag.csv");
    let label = dir.join("lag.label.json");
    let (code, _, err) = hil_sim(&[
        "simulate",
        "--effect",
        "field_lag",
        "--base",
        "algebraic",
        "--excitation",
        "noise",
        "--duration",
        "10",
        "--fs",
        "1000",
        "--out",
        rec.to_str().unwrap(),
        "--label",
        label.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let csv = std::fs::read_to_string(&rec).unwrap();
    assert!(csv.starts_with("t,b,torque,i,speed,temperature\n") && !csv.contains("lag"));
    let (code, out, err) = hil_sim(&["diagnose", rec.to_str().unwrap(), "--model", "algebraic", "--json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("one JSON object");
    assert_eq!(v["base_model"], "algebraic");
    assert_eq!(v["heldout_fraction"], 0.3);
    let f = &v["findings"][0];
    assert_eq!(f["effect"], "field_lag", "{out}");
    assert!(f["summary"].as_str().unwrap().contains("ms"));
    assert!(f["params"]["tau_s"].as_f64().unwrap() > 0.0);
    assert!(f["windows"].is_array());
    assert!(f["heldout_after"]["r_rmse"].as_f64().unwrap() < f["heldout_before"]["r_rmse"].as_f64().unwrap());
    // Bad input: one clear error each.
    let (code, _, err) = hil_sim(&["diagnose", rec.to_str().unwrap(), "--model", "nope"]);
    assert_ne!(code, 0);
    assert!(err.contains("unknown model"), "{err}");
    let (code, _, err) = hil_sim(&["simulate", "--effect", "warp", "--out", dir.join("x.csv").to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(err.contains("field_lag"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
