//! What is read is trusted only as far as it should be: a held-out run that is not held out
//! is refused with both names, and a manifest reads only the files of its own folder and
//! quotes nothing of a file that is not a recording.

mod common;
use std::path::Path;

use common::{hil_sim, scratch};

/// A simulated recording (2 s at 500 Hz, noise excitation) with random seed `seed`.
fn simulate(path: &Path, seed: u64) {
    common::simulate_noise_with(path, seed, 2.0, 500.0);
}

/// A manifest in `dir` with a train and a validate run.
fn manifest(dir: &Path, train: &str, validate: &str) -> String {
    let m = dir.join("runs.toml");
    let text = format!("[[run]]\nfile = \"{train}\"\n\n[[run]]\nfile = \"{validate}\"\nrole = \"validate\"\n");
    std::fs::write(&m, text).unwrap();
    m.display().to_string()
}

fn one_error(err: &str) -> bool {
    err.lines().filter(|l| l.starts_with("error")).count() == 1
}

/// Issue 61, behaviour 2: the same file, a copy of it, or a cut of it as the validate run
/// gave a held-out score equal to the training one, exit 0.
#[test]
fn a_validate_run_that_the_fit_saw_is_refused_with_both_names() {
    let dir = scratch("heldout");
    simulate(&dir.join("a.csv"), 1);
    simulate(&dir.join("other.csv"), 2);
    std::fs::copy(dir.join("a.csv"), dir.join("copy.csv")).unwrap();
    // A cut: rows 300-700 of a.csv (header kept), time as recorded.
    let text = std::fs::read_to_string(dir.join("a.csv")).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let cut = std::iter::once(lines[0]).chain(lines[300..700].iter().copied()).collect::<Vec<_>>().join("\n");
    std::fs::write(dir.join("cut.csv"), cut + "\n").unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(dir.join("a.csv"), dir.join("link.csv")).unwrap();
    let fit = |m: &str| hil_sim(&["fit", "--dataset", m, "--model", "algebraic", "--delay", "off"]);
    for (validate, how) in [
        ("a.csv", "is the same file as"),
        ("link.csv", "is the same file as"),
        ("copy.csv", "holds the same samples as"),
        ("cut.csv", "shares samples from"),
    ] {
        let (code, _, err) = fit(&manifest(&dir, "a.csv", validate));
        assert_ne!(code, 0, "{validate}: accepted");
        assert!(err.contains(validate) && err.contains("a.csv") && err.contains(how), "{validate}: {err}");
        assert!(one_error(&err), "{err}");
    }
    // Two different recordings: a held-out score.
    let (code, out, err) = fit(&manifest(&dir, "a.csv", "other.csv"));
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("scored on the validate runs"), "{out}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 61, behaviour 3: a manifest read any file of the machine and printed its content
/// in the error.
#[test]
fn a_manifest_reads_only_its_folder_and_quotes_no_other_file() {
    let dir = scratch("manifest-paths");
    simulate(&dir.join("a.csv"), 1);
    let secret = dir.join("outside-secret.txt");
    std::fs::write(&secret, "root:TOPSECRET:19000:0:99999:7:::\ndaemon:*:19000:0:99999:7:::\n").unwrap();
    let inner = dir.join("data");
    std::fs::create_dir_all(&inner).unwrap();
    std::fs::copy(dir.join("a.csv"), inner.join("a.csv")).unwrap();
    #[cfg(unix)]
    std::os::unix::fs::symlink(&secret, inner.join("link.csv")).unwrap();
    let mut cases = vec![secret.display().to_string(), "../outside-secret.txt".to_owned()];
    if cfg!(unix) {
        cases.push("link.csv".to_owned());
    }
    for file in &cases {
        let m = manifest(&inner, "a.csv", file);
        let (code, _, err) = hil_sim(&["fit", "--dataset", &m, "--model", "algebraic"]);
        assert_ne!(code, 0, "{file}: accepted");
        assert!(err.contains("outside the manifest's folder") && err.contains("--allow-outside"), "{file}: {err}");
        assert!(!err.contains("TOPSECRET") && !err.contains("daemon"), "{file}: content quoted: {err}");
        // Allowed, the file is read, and refused without a word of it.
        let (code, _, err) = hil_sim(&["fit", "--dataset", &m, "--allow-outside", "--model", "algebraic"]);
        assert_ne!(code, 0, "{file}: accepted");
        assert!(err.contains("not a recording") && err.contains("content is not shown"), "{file}: {err}");
        assert!(!err.contains("TOPSECRET") && !err.contains("root") && !err.contains("daemon"), "{file}: {err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 61, behaviour 4: a parameter file named every recording of the dataset in its
/// `source` (2 MB for 10,000 runs, over what `replay` and `export` read). Its size is now
/// that of the parameters, whatever the number of runs, and the per-run metrics are beside
/// it.
#[test]
fn what_fit_saves_replay_reads_whatever_the_number_of_runs() {
    let dir = scratch("many-runs");
    let mut manifest = String::new();
    for k in 0..300 {
        let name = format!("run-with-a-long-descriptive-name-{k:04}.csv");
        let mut text = String::from("t,b,torque\n");
        for i in 0..120 {
            let t = i as f64 * 0.002;
            let b = 0.4 + 0.35 * (t * (20.0 + k as f64 * 0.1)).sin() + 0.001 * ((i * 7919 + k) % 13) as f64;
            text += &format!("{t:.4},{b:.6},{:.5}\n", 10.0 * (4.0 * b).tanh() + 0.05 * ((i * 31 + k) % 7) as f64);
        }
        std::fs::write(dir.join(&name), text).unwrap();
        manifest += &format!("[[run]]\nfile = \"{name}\"\n");
    }
    let m = dir.join("runs.toml");
    std::fs::write(&m, manifest).unwrap();
    let save = dir.join("saved");
    let (code, _, err) = hil_sim(&[
        "fit",
        "--dataset",
        m.to_str().unwrap(),
        "--model",
        "algebraic",
        "--delay",
        "off",
        "--keep-flagged",
        "--save",
        save.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let params = save.join("algebraic.json");
    let bytes = std::fs::metadata(&params).unwrap().len();
    assert!(bytes < 4096, "a parameter file of {bytes} bytes for 300 runs");
    let text = std::fs::read_to_string(&params).unwrap();
    assert!(text.contains("300 recordings") && text.contains("0000.csv") && text.contains("0299.csv"), "{text}");
    let results: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(save.join("fit-results.json")).unwrap()).unwrap();
    assert_eq!(results["results"][0]["runs"].as_array().map(Vec::len), Some(300), "per-run metrics");
    let (code, _, err) = hil_sim(&["replay", "--dataset", m.to_str().unwrap(), "--params", params.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let (code, _, err) =
        hil_sim(&["export", params.to_str().unwrap(), "--out", dir.join("page.bin").to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 61, behaviour 1: 100 s added to the time column from row 1502 on made the fit step
/// at 29.7 Hz instead of 3 kHz (the rate taken over the gap), exit 0. The rate now comes from
/// the intervals that are not gaps, the gap splits the recording into runs, and it is
/// reported as a gap (not as a 100 s standstill).
#[test]
fn a_gap_in_the_time_column_splits_the_recording_and_leaves_the_rate_alone() {
    let dir = scratch("gap");
    let plain = dir.join("plain.csv");
    common::simulate_noise_with(&plain, 1, 2.0, 3000.0);
    let text = std::fs::read_to_string(&plain).unwrap();
    let mut gapped = String::new();
    for (k, line) in text.lines().enumerate() {
        match line.split_once(',') {
            // File line k + 1; from line 1502 on the stamps are 100 s later.
            Some((t, rest)) if k + 1 >= 1502 => {
                gapped += &format!("{},{rest}\n", t.parse::<f64>().unwrap() + 100.0);
            }
            _ => gapped += &format!("{line}\n"),
        }
    }
    let gap = dir.join("gap.csv");
    std::fs::write(&gap, gapped).unwrap();
    let fit = |f: &Path| {
        let (code, out, err) = hil_sim(&["fit", f.to_str().unwrap(), "--model", "algebraic", "--json"]);
        assert_eq!(code, 0, "{err}");
        serde_json::from_str::<serde_json::Value>(&out).unwrap()
    };
    let (a, b) = (fit(&plain), fit(&gap));
    let dt = a["dt_s"].as_f64().unwrap();
    assert!((b["dt_s"].as_f64().unwrap() - dt).abs() < 1e-3 * dt, "dt {} vs {dt}", b["dt_s"]);
    let kinds: Vec<&str> = b["warnings"].as_array().unwrap().iter().filter_map(|w| w["kind"].as_str()).collect();
    assert!(kinds.contains(&"dropout") && !kinds.contains(&"standstill"), "{}", b["warnings"]);
    let (da, db) = (a["results"][0]["delay_s"].as_f64().unwrap(), b["results"][0]["delay_s"].as_f64().unwrap());
    assert!((da - db).abs() <= 1.5 * dt, "delays {da} s vs {db} s");
    let (_, out, _) = hil_sim(&["fit", gap.to_str().unwrap(), "--model", "algebraic"]);
    assert!(out.contains("2 runs") && out.contains("gap in its time column") && out.contains("3000.0 Hz"), "{out}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 61, behaviour 5: two saves into one folder mixed two fits, and an interrupted save
/// left new and old model files side by side. A save is now one generation, swapped in
/// whole; a second writer is refused while the first holds the folder; a folder of the
/// user's own files is never replaced.
#[test]
fn a_saved_folder_is_one_generation() {
    let dir = scratch("generation");
    simulate(&dir.join("a.csv"), 1);
    let save = dir.join("saved");
    let fit = |models: &str| {
        hil_sim(&[
            "fit",
            dir.join("a.csv").to_str().unwrap(),
            "--model",
            models,
            "--delay",
            "off",
            "--save",
            save.to_str().unwrap(),
        ])
    };
    let (code, _, err) = fit("algebraic,dahl");
    assert_eq!(code, 0, "{err}");
    assert!(save.join("dahl.json").exists() && save.join("algebraic.json").exists());
    // A leftover of an interrupted save beside it: removed, never swapped in.
    let stale = dir.join(".saved.new-999999");
    std::fs::create_dir_all(&stale).unwrap();
    std::fs::write(stale.join("bouc_wen.json"), "{").unwrap();
    let (code, _, err) = fit("algebraic");
    assert_eq!(code, 0, "{err}");
    let mut names: Vec<String> =
        std::fs::read_dir(&save).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    assert_eq!(names, [".hil-sim-generation", "algebraic.json", "fit-results.json"], "a mixed folder");
    assert!(!stale.exists(), "the interrupted save's folder is still there");
    // While another writer holds the folder, a save is refused and changes nothing.
    #[cfg(unix)]
    {
        use std::os::unix::io::AsRawFd;
        let lock = std::fs::File::open(dir.join(".saved.lock")).unwrap();
        // SAFETY: flock on a descriptor this test owns.
        assert_eq!(unsafe { libc::flock(lock.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) }, 0);
        let before = std::fs::read(save.join("algebraic.json")).unwrap();
        let (code, _, err) = fit("dahl");
        assert_ne!(code, 0, "a second writer was let in");
        assert!(err.contains("another hil-sim is writing"), "{err}");
        assert_eq!(std::fs::read(save.join("algebraic.json")).unwrap(), before);
        assert!(!save.join("dahl.json").exists());
    }
    // A folder of the user's own files is not replaced.
    let mine = dir.join("mine");
    std::fs::create_dir_all(&mine).unwrap();
    std::fs::write(mine.join("notes.txt"), "keep me").unwrap();
    let (code, _, err) = hil_sim(&[
        "fit",
        dir.join("a.csv").to_str().unwrap(),
        "--model",
        "algebraic",
        "--save",
        mine.to_str().unwrap(),
    ]);
    assert_ne!(code, 0);
    assert!(err.contains("did not write") && err.contains("notes.txt"), "{err}");
    assert_eq!(std::fs::read_to_string(mine.join("notes.txt")).unwrap(), "keep me");
    let _ = std::fs::remove_dir_all(&dir);
}

/// Issue 61, behaviour 5 for reports: a report folder held the new page beside plots of an
/// older one. `fit --out` and `diagnose --out` now write one generation each.
#[test]
fn a_report_folder_is_one_generation() {
    let dir = scratch("report-generation");
    simulate(&dir.join("a.csv"), 1);
    let out = dir.join("report");
    for cmd in ["fit", "diagnose", "fit"] {
        let (code, _, err) = hil_sim(&[
            cmd,
            dir.join("a.csv").to_str().unwrap(),
            "--model",
            "algebraic",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{cmd}: {err}");
        assert!(out.join("index.html").exists() && out.join(".hil-sim-generation").exists(), "{cmd}");
        let what = std::fs::read_to_string(out.join(".hil-sim-generation")).unwrap();
        assert!(what.contains(&format!("hil-sim {cmd} --out")), "{what}");
        // A file of the previous generation never survives into the next.
        assert!(!out.join("planted.svg").exists(), "{cmd}: an old file beside the new page");
        std::fs::write(out.join("planted.svg"), "<svg/>").unwrap();
    }
    let _ = std::fs::remove_dir_all(&dir);
}
