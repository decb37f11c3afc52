//! The report as a reader sees it: `fit --out` and `diagnose --out` pages opened in
//! headless Chromium at 1400 px with `report_check.js` injected, which measures the laid-out
//! page: nothing wider than the window, no table that must scroll, no overlapping or
//! clipped SVG text, every numeric column with its unit, no e-notation. The fit page of a
//! recording with flagged held-out samples shows the unflagged score beside the full one,
//! with the sentence on why they differ.
//!
//! Chromium comes from `scripts/setup` (Debian's `chromium`); without it the test fails
//! under CI and is skipped with a message elsewhere.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{hil_sim_within, scratch};

const CHECK_JS: &str = include_str!("report_check.js");

fn chromium() -> Option<PathBuf> {
    ["chromium", "chromium-browser", "google-chrome"].iter().find_map(|c| {
        let out = Command::new("sh").args(["-c", &format!("command -v {c}")]).output().ok()?;
        let p = String::from_utf8_lossy(&out.stdout).trim().to_owned();
        (out.status.success() && !p.is_empty()).then(|| PathBuf::from(p))
    })
}

/// Load `page` with the check injected; the check's JSON.
fn layout(browser: &Path, page: &Path) -> serde_json::Value {
    let html = std::fs::read_to_string(page).expect("report page");
    let checked = page.with_file_name("layout-check.html");
    let html = html.replace("</body>", &format!("<script>{CHECK_JS}</script></body>"));
    std::fs::write(&checked, html).unwrap();
    // A profile of this page's own: two browsers on one profile (the tests run side by side)
    // hand over to each other through its lock, and one of them dumps nothing.
    let profile = page.with_file_name("chromium-profile");
    let out = Command::new(browser)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--hide-scrollbars",
            "--window-size=1400,1000",
            "--virtual-time-budget=5000",
            "--dump-dom",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg(format!("file://{}", checked.display()))
        .output()
        .expect("running chromium");
    let dom = String::from_utf8_lossy(&out.stdout);
    let start = dom.rfind("<pre id=\"layout-check\">").unwrap_or_else(|| {
        panic!(
            "no check result in the DOM of {} (chromium {}; stderr: {})",
            page.display(),
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        )
    });
    let rest = &dom[start + "<pre id=\"layout-check\">".len()..];
    let json = rest.split("</pre>").next().unwrap();
    let json = json.replace("&quot;", "\"").replace("&lt;", "<").replace("&gt;", ">").replace("&amp;", "&");
    serde_json::from_str(&json).unwrap_or_else(|e| panic!("check result {json}: {e}"))
}

fn assert_readable(browser: &Path, page: &Path) {
    let v = layout(browser, page);
    eprintln!("{}: {v}", page.display());
    assert_eq!(v["width"], 1400, "window width");
    for key in ["overflow", "overlaps", "clipped", "unitless", "enotation"] {
        let found = v[key].as_array().unwrap();
        assert!(found.is_empty(), "{}: {key}: {found:?}", page.display());
    }
}

fn data(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data").join(rel).display().to_string()
}

#[test]
fn fit_and_diagnose_pages_read_at_1400_px() {
    let Some(browser) = chromium() else {
        assert!(std::env::var("CI").is_err(), "chromium missing: scripts/setup installs it");
        eprintln!("skipped: no chromium (scripts/setup installs Debian's chromium)");
        return;
    };
    // A recording whose held-out part has flagged samples (the clipped end stop).
    let fit_dir = scratch("report-fit");
    let rec = data("dyke/ransim_u.csv");
    let (code, _, err) = hil_sim_within(
        &[
            "fit",
            &rec,
            "--input",
            "D",
            "--output",
            "F",
            "--command",
            "Y",
            "--model",
            "spencer,bouc_wen,algebraic,lugre,narx",
            "--train",
            "0.85",
            "--out",
            fit_dir.to_str().unwrap(),
        ],
        300,
    );
    assert_eq!(code, 0, "{err}");
    let page = fit_dir.join("index.html");
    assert_readable(&browser, &page);
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(html.contains("held-out RMSE, unflagged (N)"), "no unflagged column");
    assert!(html.contains("did not flag: RMSE") && html.contains("The two differ because"), "no sentence");
    assert!(!html.contains("/shared/data"), "the user's folders are in the report");

    let diag_dir = scratch("report-diagnose");
    let rec = data("dyke/ranran_50.csv");
    let (code, _, err) = hil_sim_within(
        &[
            "diagnose",
            &rec,
            "--input",
            "D",
            "--output",
            "F",
            "--model",
            "bouc_wen",
            "--out",
            diag_dir.to_str().unwrap(),
        ],
        300,
    );
    assert_eq!(code, 0, "{err}");
    assert_readable(&browser, &diag_dir.join("index.html"));
}

/// The check finds what it looks for: a page built to break every rule.
#[test]
fn the_check_sees_a_broken_page() {
    let Some(browser) = chromium() else {
        assert!(std::env::var("CI").is_err(), "chromium missing: scripts/setup installs it");
        eprintln!("skipped: no chromium");
        return;
    };
    let dir = scratch("report-broken");
    let cells: String = (0..40).map(|i| format!("<td>{i}000000</td>")).collect();
    let page = dir.join("index.html");
    std::fs::write(
        &page,
        format!(
            "<!DOCTYPE html><html><head><style>table {{ display: block; overflow-x: auto; }}</style></head><body>\
             <div style=\"width: 2000px\">wide</div>\
             <table><thead><tr>{}</tr></thead><tbody><tr>{cells}</tr></tbody></table>\
             <p>alpha = 6.891e-1</p>\
             <svg width=\"300\" height=\"100\"><text x=\"10\" y=\"50\">bouc_wen</text><text x=\"30\" y=\"52\">spencer</text>\
             <text x=\"290\" y=\"50\">cut off</text></svg></body></html>",
            (0..40).map(|i| format!("<th>rmse {i}</th>")).collect::<String>()
        ),
    )
    .unwrap();
    let v = layout(&browser, &page);
    for key in ["overflow", "overlaps", "clipped", "unitless", "enotation"] {
        assert!(!v[key].as_array().unwrap().is_empty(), "{key} not seen: {v}");
    }
    assert!(v["overflow"].to_string().contains("page") && v["overflow"].to_string().contains("table"), "{v}");
}
