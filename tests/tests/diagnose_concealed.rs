//! Issue 20 acceptance: `diagnose` run blind, as `hil-sim diagnose REC --json` runs it
//! (`--model auto`, no other flag), on the bench's recordings (`hil_sim::sim::bench`):
//! one concealed catalog effect or none, written by code that shares nothing with the
//! diagnosis, on five base families (two outside every family it fits), four excitations,
//! 500 Hz–10 kHz, unipolar and bipolar field, 3–8 % of the torque span, with noise, ADCs
//! and a zero-phase lab low-pass.
//!
//! - [`blind_subset_of_heldout_seeds`]: a fixed subset of held-out cases (the first 18
//!   effect and 4 null cases at 500 Hz–2 kHz of the held-out set), asserting a floor set
//!   from the development runs (at least 65 % named first, at most one false alarm): a
//!   regression guard; docs/diagnose.md has the held-out table.
//! - [`bench_table`] (ignored, about 25 minutes): the full table, per effect and per
//!   excitation: `BENCH_SET=heldout cargo test --release -p integration-tests --test
//!   diagnose_concealed -- --ignored --nocapture` (`BENCH_SET=dev` for the development
//!   seeds, `fresh` … `fresh65` for the second to sixty-sixth held-out ranges; `BENCH_N`,
//!   `BENCH_NULL` for the number of effect and null cases, default 256 and 48;
//!   `BENCH_MIN_FS`, `BENCH_MAX_FS` keep only the cases sampled within those rates, Hz;
//!   `BENCH_SEEDS=a,b,…` only the cases with those seeds, `BENCH_EFFECTS=e,…` only those
//!   concealing these effects; `BENCH_FAMILIES=f,…` the base families, e.g. seed 000's own
//!   `bouc_wen_n1,algebraic` beside `dahl` (`plant::MORE_FAMILIES`); `BENCH_WRITE=DIR` writes each case's
//!   recording to `DIR/<seed>.csv`, to diagnose it by hand; `BENCH_WRITE_ONLY=DIR` writes them and
//!   diagnoses none). It prints one line per case and writes
//!   `target/bench_<set>.md`; `BENCH_DUMP=FILE` appends a JSON line per case (the case,
//!   the findings with each one's share of the torque span, every candidate tested with its
//!   statistics) for studying a decision rule offline.

use std::collections::BTreeMap;
use std::path::Path;

use hil_sim::ident::dataset::prepare_recording;
use hil_sim::ident::diagnose::{diagnose, DiagnoseOptions};
use hil_sim::io::recording::Channels;
use hil_sim::progress::NoProgress;
use hil_sim::sim::bench::{cases, cases_of, generate, Case, Set, EFFECTS, EXCITATIONS};

struct Outcome {
    case: Case,
    form: String,
    found: Vec<String>,
    /// Round 1's candidates: effect, BIC gain, held-out R-RMSE after, t, why impossible.
    round1: Vec<String>,
    base: String,
    seconds: f64,
    /// The diagnosis' base, notes and every candidate tested (for `BENCH_DUMP`).
    json: serde_json::Value,
}

impl Outcome {
    fn right(&self) -> bool {
        match self.case.effect.as_str() {
            "none" => self.found.is_empty(),
            e => self.found.first().map(String::as_str) == Some(e),
        }
    }
}

/// Write `g`'s recording as `DIR/<seed>.csv` (`var`: the variable that named DIR, for the message).
fn write(var: &str, dir: &str, c: &Case, g: &hil_sim::sim::bench::Generated) {
    let path = Path::new(dir).join(format!("{}.csv", c.seed));
    let file = std::fs::File::create(&path).unwrap_or_else(|e| panic!("{var} {}: {e}", path.display()));
    g.recording.write_csv(std::io::BufWriter::new(file)).unwrap_or_else(|e| panic!("{var} {}: {e}", path.display()));
}

fn run(c: &Case) -> Outcome {
    let g = generate(c).unwrap_or_else(|e| panic!("{c:?}: {e}"));
    if let Ok(dir) = std::env::var("BENCH_WRITE") {
        write("BENCH_WRITE", &dir, c, &g);
    }
    let ch = Channels::default();
    let prepared = prepare_recording(g.recording, &ch, 0.7, false).expect("dataset");
    let (rec, data) = (&prepared.recording, &prepared.data);
    let aux = rec.auxiliary_channels(&ch);
    let opts = DiagnoseOptions::default();
    let (found, round1, base, seconds, json) = match diagnose(data, aux, None, ("b", "torque"), &opts, &NoProgress) {
        Ok(d) => {
            let round1 = d
                .candidates
                .iter()
                .filter(|t| t.round == 1)
                .map(|t| {
                    format!(
                        "{} bic {:.0} after {:.2} % t {:.1}{}",
                        t.effect,
                        t.bic_gain,
                        100.0 * t.heldout_r_rmse_after,
                        t.test.t,
                        t.impossible.as_deref().map(|w| format!(" ({w})")).unwrap_or_default()
                    )
                })
                .collect();
            let json = serde_json::json!({
                "base": d.base_model, "bases_tried": d.bases_tried, "noise_rms": d.locate.noise_rms,
                "notes": d.notes, "candidates": d.candidates, "contenders": d.contenders,
                "findings": d.findings.iter().map(|f| serde_json::json!({
                    "effect": f.effect, "term_rms": f.evidence.term_rms,
                    "term_share_of_span": f.evidence.term_share_of_span,
                })).collect::<Vec<_>>(),
            });
            (d.findings.iter().map(|f| f.effect.clone()).collect(), round1, d.base_model, d.seconds, json)
        }
        Err(e) => (vec![format!("error: {e}")], Vec::new(), String::new(), 0.0, serde_json::Value::Null),
    };
    Outcome { case: c.clone(), form: g.label.form, found, round1, base, seconds, json }
}

fn line(o: &Outcome) -> String {
    let c = &o.case;
    format!(
        "{} | {} ({}) | {} / {} | {} Hz{} | {:.1} % | auto→{} | {} | {:.1} s | {}",
        if o.right() { "ok  " } else { "MISS" },
        c.effect,
        o.form,
        c.family,
        c.excitation,
        c.fs_hz,
        if c.bipolar { " bipolar" } else { "" },
        100.0 * c.size,
        o.base,
        if o.found.is_empty() { "—".to_owned() } else { o.found.join(", ") },
        o.seconds,
        c.seed
    )
}

/// Right / total per key.
fn tally<'a>(outcomes: &'a [Outcome], key: impl Fn(&'a Outcome) -> String) -> BTreeMap<String, (usize, usize)> {
    let mut m: BTreeMap<String, (usize, usize)> = BTreeMap::new();
    for o in outcomes {
        let e = m.entry(key(o)).or_default();
        e.0 += usize::from(o.right());
        e.1 += 1;
    }
    m
}

/// The table: per effect (with the excitations as columns) and the totals.
fn table(outcomes: &[Outcome]) -> String {
    let effects: Vec<&str> = EFFECTS.iter().map(|(e, _)| *e).chain(["none"]).collect();
    let mut s = String::from("| effect | ");
    s += &EXCITATIONS.join(" | ");
    s += " | all |\n| --- |";
    s += &" --- |".repeat(EXCITATIONS.len() + 1);
    s += "\n";
    let cell = |(r, n): (usize, usize)| if n == 0 { "—".to_owned() } else { format!("{r}/{n}") };
    for e in effects {
        let of: Vec<&Outcome> = outcomes.iter().filter(|o| o.case.effect == e).collect();
        if of.is_empty() {
            continue;
        }
        s += &format!("| `{e}` |");
        for x in EXCITATIONS {
            let sel = of.iter().filter(|o| o.case.excitation == *x);
            let (r, n) = sel.fold((0, 0), |(r, n), o| (r + usize::from(o.right()), n + 1));
            s += &format!(" {} |", cell((r, n)));
        }
        let r = of.iter().filter(|o| o.right()).count();
        s += &format!(" {} ({:.0} %) |\n", cell((r, of.len())), 100.0 * r as f64 / of.len() as f64);
    }
    let eff: Vec<&Outcome> = outcomes.iter().filter(|o| o.case.effect != "none").collect();
    let r = eff.iter().filter(|o| o.right()).count();
    s += &format!(
        "\nEffect cases named first: **{r} of {}** ({:.1} %); null recordings with no finding: **{} of {}**.\n",
        eff.len(),
        100.0 * r as f64 / eff.len().max(1) as f64,
        outcomes.iter().filter(|o| o.case.effect == "none" && o.right()).count(),
        outcomes.iter().filter(|o| o.case.effect == "none").count()
    );
    s += "\nBy base family: ";
    s += &tally(outcomes, |o| o.case.family.clone())
        .iter()
        .map(|(k, (r, n))| format!("{k} {r}/{n}"))
        .collect::<Vec<_>>()
        .join(", ");
    s += "\n";
    s
}

/// Rates: all effect cases, the worst effect, and the number of false alarms.
fn rates(outcomes: &[Outcome]) -> (f64, f64, usize) {
    let eff: Vec<&Outcome> = outcomes.iter().filter(|o| o.case.effect != "none").collect();
    let all = eff.iter().filter(|o| o.right()).count() as f64 / eff.len().max(1) as f64;
    let worst = tally(outcomes, |o| o.case.effect.clone())
        .iter()
        .filter(|(k, _)| k.as_str() != "none")
        .map(|(_, (r, n))| *r as f64 / *n as f64)
        .fold(1.0, f64::min);
    let alarms = outcomes.iter().filter(|o| o.case.effect == "none" && !o.right()).count();
    (all, worst, alarms)
}

fn run_all(cases: &[Case]) -> Vec<Outcome> {
    cases
        .iter()
        .map(|c| {
            let o = run(c);
            println!("{}", line(&o));
            if let Ok(path) = std::env::var("BENCH_DUMP") {
                use std::io::Write;
                let rec = serde_json::json!({"case": o.case, "form": o.form, "found": o.found, "diagnosis": o.json});
                let mut f = std::fs::OpenOptions::new().create(true).append(true).open(path).expect("BENCH_DUMP");
                writeln!(f, "{rec}").expect("BENCH_DUMP");
            }
            if !o.right() && std::env::var("BENCH_VERBOSE").is_ok() {
                println!("      round 1: {}", o.round1.join("; "));
            }
            o
        })
        .collect()
}

/// The first `n` effect cases and `n_null` null cases of the held-out set at 2 kHz or
/// less, fixed by the set's seeds.
fn subset(n: usize, n_null: usize) -> Vec<Case> {
    let all = cases(Set::Heldout, 256, 48);
    let slow = |c: &&Case| c.fs_hz <= 2000.0;
    let mut out: Vec<Case> = all.iter().filter(|c| c.effect != "none").filter(slow).take(n).cloned().collect();
    out.extend(all.iter().filter(|c| c.effect == "none").filter(slow).take(n_null).cloned());
    out
}

#[test]
fn blind_subset_of_heldout_seeds() {
    let outcomes = run_all(&subset(18, 4));
    let t = table(&outcomes);
    println!("{t}");
    // A floor set from the development runs before this subset was run with the method of
    // 2026-11-26 (72 of 80 effect cases named first, 16 of 16 nulls clean there; 57 % and
    // 8 of 10 when the floor was 40 %): a regression guard, not the issue's 95 %.
    let (all, _, alarms) = rates(&outcomes);
    assert!(alarms <= 1, "{alarms} false alarms in 4 nulls\n{t}");
    assert!(all >= 0.65, "{:.1} % named first\n{t}", 100.0 * all);
}

/// The case of seed `seed` in range `set` as the reports ran it (200 effect cases, 40 nulls).
fn reported(set: Set, seed: u64) -> Case {
    cases(set, 200, 40).into_iter().find(|c| c.seed == seed).expect("the case")
}

/// Each of `cases` (set and seed, as reported) diagnosed right.
fn each_right(cases: impl IntoIterator<Item = (Set, u64)>) {
    for (set, seed) in cases {
        let o = run(&reported(set, seed));
        assert!(o.right(), "{}", line(&o));
    }
}

/// Saturations concealed under play truths (fresh48 `640015774`, fresh51 `718004626` and
/// `718039578`: development since their reports) were named `rate_dependence`: the algebraic
/// base's α, held ≥ 0 in the refits' box, started them at the fit's α < 0 (the curve bent
/// over, the saturation taken up) and stayed there, the box's end having no slope in the
/// bounded search. The refits now start inside the box, and the saturation is named.
#[test]
fn a_saturation_under_plays_is_not_taken_up_by_a_bent_base() {
    each_right([(Set::Fresh48, 640_015_774), (Set::Fresh51, 718_004_626), (Set::Fresh51, 718_039_578)]);
}

/// On play truths the play host's static curve, `k·b + α·|b|·b³` with α ≥ 0, curved one way
/// only on a bipolar field: a play null (fresh52 `770306049`, noise at 10 kHz) was named a
/// −25 mT `sensor_offset`, which moved where it bent, a saturation under blocks at 10 kHz
/// (fresh52 `744004734`) nothing, and a field lag under blocks (fresh53 `772038736`)
/// `transport_delay` (development since their report). With an odd cubic of the field, its
/// weight ≥ 0, beside the plays, each is named right.
#[test]
fn a_play_truths_curve_is_the_hosts_with_its_cubic() {
    each_right([(Set::Fresh52, 770_306_049), (Set::Fresh52, 744_004_734), (Set::Fresh53, 772_038_736)]);
}

/// A null named a field `saturation` found on one base alone: fresh60 `1031106531` (a
/// Bouc–Wen null, on LuGre with a level term, preferred to the play host, which predicts best
/// without a finding); no other base weighed found a saturation significant (development
/// since its report). Such a finding is withdrawn (`contenders::ASK_SUPPORT`), and says so;
/// true saturations kept on a contender (fresh62 `1080015850`, a Bouc–Wen truth, and
/// `1080048818`, a play truth, both on the play host and significant on two or more other
/// bases) are still named.
#[test]
fn a_saturation_no_other_base_finds_is_no_reason_to_change_base() {
    let o = run(&reported(Set::Fresh60, 1_031_106_531));
    assert!(o.right(), "{}", line(&o));
    let notes = o.json["notes"].as_array().map(|n| n.iter().filter_map(|s| s.as_str()).collect::<Vec<_>>());
    let withdrawn = notes.unwrap_or_default().iter().any(|n| n.starts_with("a saturation found on the base model"));
    assert!(withdrawn, "{}: {}", line(&o), o.json["notes"]);
    each_right([(Set::Fresh62, 1_080_015_850), (Set::Fresh62, 1_080_048_818)]);
}

/// Four nulls (fresh21 `145701067`, fresh22 `156100606` and `156102424`, fresh26 `213301017`:
/// development since their reports) on which a term gained 7–9 % of the held-out RMSE,
/// significant on the blocks, and was named: a finding needs 10 %
/// (`significance::MIN_FINDING_GAIN`).
#[test]
fn a_term_gaining_under_ten_percent_is_no_finding_on_a_null() {
    let nulls = [
        (Set::Fresh21, 145_701_067),
        (Set::Fresh22, 156_100_606),
        (Set::Fresh22, 156_102_424),
        (Set::Fresh26, 213_301_017),
    ];
    each_right(nulls);
}

/// Seed 000 fits the clutch with a Bouc–Wen loop of exponent `n = 1`; the base was fitted
/// with `n = 2` only, and on three of ten such nulls (held-out set, these families: a run of
/// 2026-11-28) LuGre with a field lag predicted the held-out part better than any base
/// alone: a false alarm. With `n = 1` as a variant of the base's search they give no finding.
#[test]
fn a_bouc_wen_loop_of_exponent_one_is_the_base_not_a_finding() {
    let all = cases_of(Set::Heldout, 60, 30, &["bouc_wen_n1", "algebraic", "dahl"]);
    for seed in [8_000_000, 8_000_021, 8_000_189] {
        let c = all.iter().find(|c| c.seed == seed).expect("the case");
        assert_eq!(c.family, "bouc_wen_n1");
        let o = run(c);
        assert!(o.right(), "{}", line(&o));
    }
}

/// Play nulls under band-limited noise (fresh25 `200902507`, fresh31 `290900447`, fresh32
/// `307100453`: development since their reports), each named `saturation` on the algebraic
/// base with play operators of radii 1, 3, 7 and 15 % of the field's span: the bench's plays
/// (0.01, 0.03 and 0.06 T) fell between those radii on a unipolar field, and a saturating
/// map of the field, which the plays follow, moved their radii towards the truth's. With
/// seven radii (1–15 %, `contenders::PLAY_RADII`) the loop is the base's.
#[test]
fn a_play_loop_between_the_base_radii_is_the_base_not_a_saturation() {
    let nulls = [(Set::Fresh25, 200_902_507), (Set::Fresh31, 290_900_447), (Set::Fresh32, 307_100_453)];
    for (set, seed) in nulls {
        let c = reported(set, seed);
        assert_eq!((c.family.as_str(), c.excitation.as_str()), ("play", "noise"));
        let o = run(&c);
        assert!(o.right(), "{}", line(&o));
    }
}

/// The Bingham truth (`τ₀·tanh(ḃ/ε)` on a power-law static curve) is tanh's loop, but tanh's
/// swarm could settle far from its rate gain: on fresh34's null `340305542` Dahl with a
/// `|ḃ|·ḃ` term then predicted best (a false alarm), on `324011736` a field lag was named a
/// rate dependence, on fresh35's `342025885` a rate term an asymmetry. With the grid over
/// tanh's rate gain and width (`hil_sim::ident::fit::separable`) each is right. The grid's
/// fit can bend its rate gain to take up a concealed rate term; the swarm's fit, in another
/// basin, contends beside it, and on fresh35's `342009853` (a Kwok clutch with `|ḃ|·ḃ`, named
/// with the grid's fit alone as nothing) names it.
#[test]
fn a_tanh_loop_far_from_the_swarm_start_is_found_by_the_grid() {
    let cases = [
        (Set::Fresh34, 340_305_542),
        (Set::Fresh34, 324_011_736),
        (Set::Fresh35, 342_025_885),
        (Set::Fresh35, 342_009_853),
    ];
    each_right(cases);
}

/// With tanh's grid its fit bends its rate gain to take up a concealed rate term; an additive
/// candidate's refit also starts at the grid point where base and term fit best together
/// (`hil_sim::ident::diagnose::joint_grid`). Each was named nothing with the grid alone
/// (fresh34's `324029177`, a `|ḃ|·ḃ` on a Bingham truth, fresh35's `342013861`, on a Kwok
/// truth), and fresh36's Bingham null `377305882` was named `rate_dependence` on LuGre.
#[test]
fn a_rate_term_on_a_tanh_base_is_refitted_from_the_joint_grid() {
    let cases = [(Set::Fresh34, 324_029_177), (Set::Fresh35, 342_013_861), (Set::Fresh36, 377_305_882)];
    each_right(cases);
}

#[test]
#[ignore = "the full bench (~25 min): BENCH_SET=heldout|fresh|fresh2…fresh65|dev, BENCH_N, BENCH_NULL"]
fn bench_table() {
    let sets = Set::NAMED;
    let key = std::env::var("BENCH_SET").ok();
    let (key, set, _, _) = sets.iter().copied().find(|(k, ..)| key.as_deref() == Some(*k)).unwrap_or(sets[1]);
    let n = std::env::var("BENCH_N").ok().and_then(|v| v.parse().ok()).unwrap_or(256);
    let n_null = std::env::var("BENCH_NULL").ok().and_then(|v| v.parse().ok()).unwrap_or(48);
    // BENCH_FROM / BENCH_TO: a slice of the list (to share a run between processes).
    let env = |k: &str, d: usize| std::env::var(k).ok().and_then(|v| v.parse().ok()).unwrap_or(d);
    // BENCH_MIN_FS / BENCH_MAX_FS: only the cases sampled within these rates, Hz.
    let fs = (env("BENCH_MIN_FS", 0) as f64, env("BENCH_MAX_FS", usize::MAX) as f64);
    // BENCH_SEEDS: only the cases with these seeds (comma-separated), to rerun a few.
    let only: Vec<u64> = std::env::var("BENCH_SEEDS")
        .map(|v| v.split(',').filter_map(|s| s.trim().parse().ok()).collect())
        .unwrap_or_default();
    // BENCH_EFFECTS: only the cases concealing these effects (comma-separated; `none` for the nulls).
    let effects: Vec<String> =
        std::env::var("BENCH_EFFECTS").map(|v| v.split(',').map(|s| s.trim().to_owned()).collect()).unwrap_or_default();
    // BENCH_FAMILIES: the base families (comma-separated; default the bench's five).
    let families: Vec<String> = std::env::var("BENCH_FAMILIES")
        .map(|v| v.split(',').map(|s| s.trim().to_owned()).collect())
        .unwrap_or_default();
    let families: Vec<&str> = families.iter().map(String::as_str).collect();
    let all: Vec<Case> = cases_of(set, n, n_null, &families)
        .into_iter()
        .filter(|c| c.fs_hz >= fs.0 && c.fs_hz <= fs.1)
        .filter(|c| only.is_empty() || only.contains(&c.seed))
        .filter(|c| effects.is_empty() || effects.contains(&c.effect))
        .collect();
    let (from, to) = (env("BENCH_FROM", 0).min(all.len()), env("BENCH_TO", all.len()).min(all.len()));
    // BENCH_WRITE_ONLY=DIR: write the recordings as `DIR/<seed>.csv` and diagnose none.
    if let Ok(dir) = std::env::var("BENCH_WRITE_ONLY") {
        for c in &all[from..to.max(from)] {
            write("BENCH_WRITE_ONLY", &dir, c, &generate(c).unwrap_or_else(|e| panic!("{c:?}: {e}")));
        }
        return;
    }
    let outcomes = run_all(&all[from..to.max(from)]);
    let t = table(&outcomes);
    println!("{t}");
    let (all, worst, alarms) = rates(&outcomes);
    println!("named first {:.1} %, worst effect {:.1} %, false alarms {alarms}", 100.0 * all, 100.0 * worst);
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target");
    let _ = std::fs::create_dir_all(&dir);
    let body: Vec<String> = outcomes.iter().map(line).collect();
    let _ = std::fs::write(dir.join(format!("bench_{key}.md")), format!("{t}\n```\n{}\n```\n", body.join("\n")));
}

/// Dahl nulls fitted with LuGre (fresh40 `455301351`, fresh44 `546306021`, fresh45
/// `568708399`: development since their reports) named a 1–3 ms `field_lag` gaining 15–21 %
/// on the tail: the lag smoothed the Hall reading's steps and noise, which wear a hysteresis
/// model's loop down. A field lag must now predict the tail better than the input smoothed
/// without its phase (`hil_sim::ident::diagnose::zero_phase`), and on each it did not; a
/// two-pole lag on a 10 kHz sweep (fresh44 `524016056`, whose phase shows only in the fast
/// blocks) still beats it.
#[test]
fn a_lag_no_better_than_smoothing_is_no_finding() {
    let cases = [
        (Set::Fresh40, 455_301_351),
        (Set::Fresh44, 546_306_021),
        (Set::Fresh45, 568_708_399),
        (Set::Fresh44, 524_016_056),
    ];
    each_right(cases);
}
