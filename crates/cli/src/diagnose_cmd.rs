//! `subfric diagnose` and `subfric selfcheck`.

use crate::io::{write_json, write_text};
use anyhow::Result;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use subfric_data::load_set;
use subfric_diagnose::selfcheck::{score, selfcheck, Case, SelfcheckOptions};
use subfric_diagnose::verdict::Decision;
use subfric_diagnose::{diagnose, prepare_for_diagnosis, DiagnoseOptions, Diagnosis, Effect};
use subfric_plot::{render_bars_png, BarFigure};

/// Diagnoses the set in `dir`; writes diagnosis.json and the plots under `out`.
pub fn run_diagnose(
    dir: &Path,
    out: &Path,
    opts: &DiagnoseOptions,
) -> Result<(Diagnosis, Vec<PathBuf>)> {
    let set = load_set(dir)?;
    let prepared = prepare_for_diagnosis(&set);
    let d = diagnose(&prepared, opts)?;
    let v = serde_json::json!({
        "set": set.meta.name,
        "verdict": {
            "effect": d.verdict.effect.name(),
            "held_out_shrink": d.verdict.held_out_shrink,
            "explanation": d.verdict.explanation,
            "extra_parameters": d.verdict.extra_parameters,
        },
        "diagnosis": d,
    });
    write_json(&out.join("diagnosis.json"), &v)?;
    write_text(
        &out.join("diagnosis.txt"),
        &(report_text(&set.meta.name, &d) + "\n"),
    )?;
    let mut plots = Vec::new();
    let label = d
        .verdict
        .effects
        .iter()
        .map(|e| e.effect.to_string())
        .collect::<Vec<_>>()
        .join(" + ");
    plots.extend(crate::figures::diagnosis_figures(
        &set.meta.name,
        &prepared,
        &d.base.model,
        (!d.verdict.effects.is_empty()).then_some((&d.final_model, label.as_str())),
        &out.join("figures"),
    )?);
    // Residual by segment: base model, and with the named effect on held-out rows.
    let cats: Vec<String> = d
        .localisation
        .by_segment
        .iter()
        .map(|g| g.group.clone())
        .collect();
    let base: Vec<f64> = d
        .localisation
        .by_segment
        .iter()
        .map(|g| g.rms_over_noise)
        .collect();
    let mut fig = BarFigure::new(
        format!(
            "{}: residual by segment (verdict: {})",
            set.meta.name, d.verdict.effect
        ),
        "RMS residual / noise SD [-]",
        cats.clone(),
    )
    .with_group("base model (all rows)", base);
    let after: Vec<f64> = cats
        .iter()
        .map(|c| {
            d.remaining_by_segment
                .iter()
                .find(|g| &g.group == c)
                .map(|g| g.rms_over_noise)
                .unwrap_or(f64::NAN)
        })
        .collect();
    if !d.verdict.effects.is_empty() {
        let names: Vec<String> = d
            .verdict
            .effects
            .iter()
            .map(|e| e.effect.to_string())
            .collect();
        fig = fig.with_group(format!("with {} (all rows)", names.join(" + ")), after);
    }
    fig = fig.with_reference_line("noise level", 1.0);
    let f = out.join("residual-by-segment.png");
    render_bars_png(&fig, &f)?;
    plots.push(f);
    let tests: Vec<String> = d
        .localisation
        .by_test
        .iter()
        .map(|g| g.group.clone())
        .collect();
    let mut fig = BarFigure::new(
        format!("{}: residual by test", set.meta.name),
        "RMS residual / noise SD [-]",
        tests.clone(),
    )
    .with_group(
        "base model",
        d.localisation
            .by_test
            .iter()
            .map(|g| g.rms_over_noise)
            .collect(),
    );
    if !d.verdict.effects.is_empty() {
        let c = &d.final_model;
        let m = subfric_fit::misfits(
            &prepared.iter().map(|p| p.fit.clone()).collect::<Vec<_>>(),
            c,
        );
        fig = fig.with_group(
            "with the named effects",
            tests
                .iter()
                .map(|t| {
                    m.iter()
                        .find(|x| &x.name == t)
                        .map(|x| x.rms_over_noise)
                        .unwrap_or(f64::NAN)
                })
                .collect(),
        );
    }
    fig = fig.with_reference_line("noise level", 1.0);
    let f = out.join("residual-by-test.png");
    render_bars_png(&fig, &f)?;
    plots.push(f);
    Ok((d, plots))
}

fn row(s: &mut String, x: &subfric_diagnose::localise::GroupMisfit) {
    let _ = writeln!(
        s,
        "   {:<48} {:>6} rows  {:8.2}× noise  {:5.1}% of the gap",
        x.group,
        x.rows,
        x.rms_over_noise,
        100.0 * x.share_of_gap
    );
}

/// The terminal report.
pub fn report_text(name: &str, d: &Diagnosis) -> String {
    let mut s = String::new();
    let p = &d.base.model.params;
    let _ = writeln!(
        s,
        "diagnosis of {name}: {} rows{}",
        d.base.rows,
        if d.base.fitted_rows < d.base.rows {
            format!(
                ", fitted on {} bins (dense where the data change, thin in steady sliding)",
                d.base.fitted_rows
            )
        } else {
            String::new()
        }
    );
    for st in &d.starts {
        if !st.from_spec && st.start != subfric_data::StartKind::Rest {
            let _ = writeln!(s, "   {}: {}", st.test, st.reason);
        }
        if st.noise_floor {
            let _ = writeln!(
                s,
                "   {}: the noise estimate {:.3e} is the quantisation floor, not a measurement",
                st.test, st.noise_sd
            );
        }
    }
    if let Some(k) = &d.stiffness {
        let _ = writeln!(s, "   α_t fitted: {}", k.evidence);
    }
    let _ = writeln!(
        s,
        "base model: misfit {:.2}× the noise variance on all rows (μ_s {:.3}, μ_k {:.3}, κ {:.4}, ξ {:.3e}, ũ {:.3}, α_t {:.4})",
        d.base.reduced_chi2, p.mu_s, p.mu_k, p.kappa, p.xi, p.u_tilde, p.alpha_t
    );
    let _ = writeln!(
        s,
        "\n1. where the base model misses (all rows; share of the excess over the noise):"
    );
    // The excess of a sum of n squared unit normals has an SD of √(2n).
    if d.localisation.total_excess < 3.0 * (2.0 * d.base.rows as f64).sqrt() {
        let _ = writeln!(
            s,
            "   (the total excess over the noise is within its scatter: the shares below are of nothing significant)"
        );
    }
    let mut g = d.localisation.by_test_segment.clone();
    g.sort_by(|a, b| b.share_of_gap.total_cmp(&a.share_of_gap));
    for x in g.iter().take(8) {
        row(&mut s, x);
    }
    for x in d
        .localisation
        .by_cycle
        .iter()
        .chain(&d.localisation.by_normal_stress)
    {
        row(&mut s, x);
    }
    let _ = writeln!(
        s,
        "\n2. every form of every candidate family, fitted to all data (in-sample):"
    );
    let _ = writeln!(
        s,
        "   {:<15} {:<44} {:>10}  {:<10} parameters",
        "family", "form", "score", "fit"
    );
    for f in &d.forms {
        let extra: Vec<String> = f
            .parameters
            .iter()
            .map(|(k, v)| format!("{k}={v:.4e}"))
            .collect();
        let _ = writeln!(
            s,
            "   {:<15} {:<44} {:>10.1}  {:<10} {}{}",
            f.effect.name(),
            f.form,
            f.in_sample_score,
            if f.converged {
                "converged"
            } else {
                "NOT conv."
            },
            extra.join(" "),
            if f.chosen {
                "  ← best of its family"
            } else {
                ""
            }
        );
    }
    let counts: Vec<String> = d.pieces.iter().map(|(k, n)| format!("{n} {k}")).collect();
    let _ = writeln!(
        s,
        "\n3. held out: pieces ({}) left out in {} folds, each predicted after refitting without it",
        counts.join(", "),
        d.folds.len()
    );
    for (k, st) in d.selection.iter().enumerate() {
        let _ = writeln!(
            s,
            "   stage {}: added to {} (held-out misfit {:.2}× noise)",
            k + 1,
            st.reference,
            st.reference_chi2
        );
        let _ = writeln!(
            s,
            "     {:<58} {:>10} {:>9} {:>9} {:>9}",
            "candidate", "evidence D", "excess", "relative", "typical"
        );
        for c in st.candidates.iter().chain(&st.drift) {
            let _ = writeln!(
                s,
                "     {:<58} {:>10.1} {:>8.0}% {:>8.0}% {:>8.0}%",
                truncate(&c.spec, 58),
                c.held_out.score,
                100.0 * c.held_out.excess_shrink.max(-9.99),
                100.0 * c.held_out.relative_shrink.max(-9.99),
                100.0 * c.held_out.typical_shrink.max(-9.99),
            );
        }
        let _ = writeln!(
            s,
            "     → {}",
            match st.decision {
                Decision::Named(i) => format!("named: {}", st.candidates[i].spec),
                Decision::NoGap if k == 0 =>
                    "nothing to explain: the base fits at the noise".into(),
                Decision::NoGap => "nothing left to explain".into(),
                Decision::Drift =>
                    "a drift of the measurement explains more than any candidate".into(),
                Decision::Unexplained if k == 0 => "no candidate explains enough".into(),
                Decision::Unexplained => "no further effect".into(),
            }
        );
        if let Decision::Named(i) = st.decision {
            for x in &st.candidates[i].by_kind {
                let _ = writeln!(
                    s,
                    "       {:<18} {:>6} rows  {:8.2} → {:8.2}× noise ({:+.0}% of its misfit)",
                    x.kind,
                    x.rows,
                    x.reference_rms_over_noise,
                    x.candidate_rms_over_noise,
                    -100.0 * x.shrink
                );
            }
        }
    }
    let _ = writeln!(
        s,
        "\n4. what the held-out residual of the base model follows:"
    );
    let _ = writeln!(s, "   {}", d.evidence.summary);
    let _ = writeln!(s, "\n5. verdict: {}", d.verdict.effect);
    for e in &d.verdict.effects {
        let extra: Vec<String> = e
            .parameters
            .iter()
            .map(|(k, v)| format!("{k}={v:.4e}"))
            .collect();
        let _ = writeln!(s, "   {} — {}: {}", e.effect, e.form, extra.join(" "));
        let checks: Vec<String> = [
            ("tail of each test", e.tail_shrink),
            ("each test left out", e.leave_one_test_out_shrink),
        ]
        .iter()
        .filter_map(|(n, v)| v.map(|v| format!("{n}: {:.0}%", 100.0 * v)))
        .collect();
        if !checks.is_empty() {
            let _ = writeln!(
                s,
                "     extra held-out checks (share of the excess removed) — {}",
                checks.join(", ")
            );
        }
    }
    let _ = writeln!(s, "   {}", d.verdict.explanation);
    if let Some(sup) = d.verdict.evidence_supports {
        let _ = writeln!(
            s,
            "   the residual evidence {} this",
            if sup {
                "supports"
            } else {
                "does not single out"
            }
        );
    }
    let _ = write!(s, "({:.1} s)", d.elapsed_s);
    s
}

fn truncate(s: &str, n: usize) -> String {
    if s.chars().count() <= n {
        s.to_string()
    } else {
        format!("{}…", s.chars().take(n - 1).collect::<String>())
    }
}

/// Diagnoses every set under `root` and scores against its truth.json.
pub fn score_folder(
    root: &Path,
    opts: &DiagnoseOptions,
) -> Result<(Vec<Case>, subfric_diagnose::selfcheck::Scores)> {
    let truth_path = root.join("truth.json");
    let text = std::fs::read_to_string(&truth_path).map_err(|e| {
        anyhow::anyhow!(
            "{}: cannot read ({e}); expected {{\"set\": {{\"effect\": name}}}}",
            truth_path.display()
        )
    })?;
    let truth: serde_json::Value = serde_json::from_str(&text).map_err(|e| {
        anyhow::anyhow!("{}:{}:{}: {e}", truth_path.display(), e.line(), e.column())
    })?;
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(root)?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.join("experiment.json").is_file())
        .collect();
    dirs.sort();
    let mut cases = Vec::new();
    for d in dirs {
        let name = d
            .file_name()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        // Either {"effect": name} or {"effects": [names]}; "none" is no effect, and a name
        // outside the library (a drift) counts as "unexplained".
        let entry = &truth[&name];
        let names: Vec<&str> = match (entry["effect"].as_str(), entry["effects"].as_array()) {
            (_, Some(list)) => list.iter().filter_map(|v| v.as_str()).collect(),
            (Some(e), None) => vec![e],
            (None, None) => {
                eprintln!("{name}: no truth in {}, skipped", truth_path.display());
                continue;
            }
        };
        let families: Vec<Effect> = names
            .iter()
            .map(|e| Effect::from_name(e).unwrap_or(Effect::Unexplained))
            .filter(|e| *e != Effect::None)
            .collect();
        let set = load_set(&d)?;
        let diag = diagnose(&prepare_for_diagnosis(&set), opts)?;
        let c = Case::new(&name, families, names.join(" + "), &diag);
        print_case(&c);
        cases.push(c);
    }
    let s = score(&cases);
    Ok((cases, s))
}

/// One line per diagnosed set.
fn print_case(c: &Case) {
    let names = |v: &[Effect]| {
        if v.is_empty() {
            "none".to_string()
        } else {
            v.iter().map(|e| e.name()).collect::<Vec<_>>().join(" + ")
        }
    };
    println!(
        "{:<22} truth {:<44} verdict {:<30} {} shrink {:>4.0}%  ({:.1} s){}",
        c.name,
        truncate(&c.truth_label, 44),
        names(&c.verdict),
        if c.right() { "right" } else { "WRONG" },
        100.0 * c.shrink,
        c.elapsed_s,
        match (c.lab_like, c.mid_run) {
            (true, true) => "  [lab-like, mid-run]",
            (true, false) => "  [lab-like]",
            (false, true) => "  [mid-run]",
            _ => "",
        }
    );
}

/// Runs the generated self-check; with `write_to`, every generated set is written there as a
/// folder, and their truths to `truth.json` (which `selfcheck --sets` reads).
pub fn run_selfcheck(
    opts: &SelfcheckOptions,
    write_to: Option<&Path>,
) -> Result<(Vec<Case>, subfric_diagnose::selfcheck::Scores)> {
    let truths = std::sync::Mutex::new(serde_json::Map::new());
    let failed = std::sync::Mutex::new(None::<anyhow::Error>);
    let keep = |set: &subfric_data::ExperimentSet, truth: &subfric_diagnose::synth::Truth| {
        let Some(root) = write_to else { return };
        let dir = root.join(&set.meta.name);
        if let Err(e) = subfric_data::write_set(set, &dir) {
            failed.lock().expect("not poisoned").get_or_insert(e.into());
        }
        let names: Vec<&str> = if truth.effects.is_empty() {
            vec!["none"]
        } else {
            truth
                .effects
                .iter()
                .map(|b| match b.effect {
                    Effect::Unexplained => "drift",
                    e => e.name(),
                })
                .collect()
        };
        truths.lock().expect("not poisoned").insert(
            set.meta.name.clone(),
            serde_json::json!({"effects": names, "label": truth.label(), "model": truth.model}),
        );
    };
    let result = selfcheck(opts, &print_case, &keep);
    if let Some(e) = failed.into_inner().expect("not poisoned") {
        return Err(e);
    }
    if let Some(root) = write_to {
        let truths = truths.into_inner().expect("not poisoned");
        write_json(&root.join("truth.json"), &serde_json::Value::Object(truths))?;
    }
    Ok(result)
}
