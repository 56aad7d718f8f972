//! `subfric diagnose` and `subfric selfcheck`.

use crate::io::{write_json, write_text};
use anyhow::Result;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use subfric_data::load_set;
use subfric_diagnose::selfcheck::{score, selfcheck, Case, SelfcheckOptions};
use subfric_diagnose::{diagnose, DiagnoseOptions, Diagnosis, Effect};
use subfric_fit::prepare_set;
use subfric_plot::{render_bars_png, BarFigure};

/// Diagnoses the set in `dir`; writes diagnosis.json and the plots under `out`.
pub fn run_diagnose(
    dir: &Path,
    out: &Path,
    opts: &DiagnoseOptions,
) -> Result<(Diagnosis, Vec<PathBuf>)> {
    let set = load_set(dir)?;
    let prepared = prepare_set(&set, false);
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
    if d.verdict.effect != Effect::None && d.verdict.effect != Effect::Unexplained {
        fig = fig.with_group(format!("with {} (all rows)", d.verdict.effect), after);
        let held: Vec<f64> = cats
            .iter()
            .map(|c| {
                d.shrink_by_segment
                    .iter()
                    .find(|g| &g.group == c)
                    .map(|g| g.effect_rms_over_noise)
                    .unwrap_or(f64::NAN)
            })
            .collect();
        fig = fig.with_group(format!("with {} (held-out rows)", d.verdict.effect), held);
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
    if let Some(c) = d.candidates.iter().find(|c| c.effect == d.verdict.effect) {
        let m = subfric_fit::misfits(
            &prepared.iter().map(|p| p.fit.clone()).collect::<Vec<_>>(),
            &c.model,
        );
        fig = fig.with_group(
            format!("with {}", c.effect),
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

/// The terminal report.
pub fn report_text(name: &str, d: &Diagnosis) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "diagnosis of {name}");
    let _ = writeln!(
        s,
        "base model: misfit {:.2}× the noise variance over {} rows (μ_s {:.3}, μ_k {:.3}, κ {:.3}, ξ {:.2e}, ũ {:.2})",
        d.base.reduced_chi2, d.base.rows, d.base.model.params.mu_s, d.base.model.params.mu_k, d.base.model.params.kappa, d.base.model.params.xi, d.base.model.params.u_tilde
    );
    let _ = writeln!(
        s,
        "\n1. where the base model misses (share of the excess over noise):"
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
        let _ = writeln!(
            s,
            "   {:<48} {:>5} rows  {:6.2}× noise  {:5.1}% of the gap",
            x.group,
            x.rows,
            x.rms_over_noise,
            100.0 * x.share_of_gap
        );
    }
    for x in d
        .localisation
        .by_cycle
        .iter()
        .chain(&d.localisation.by_normal_stress)
    {
        let _ = writeln!(
            s,
            "   {:<48} {:>5} rows  {:6.2}× noise  {:5.1}% of the gap",
            x.group,
            x.rows,
            x.rms_over_noise,
            100.0 * x.share_of_gap
        );
    }
    let _ = writeln!(s, "\n2. candidate effects (refitted; held-out = last 40% of each test predicted after fitting the rest):");
    let _ = writeln!(
        s,
        "   {:<15} {:>10} {:>12} {:>14} {:>16}  extra parameters",
        "effect", "fit χ²", "ΔBIC", "held-out shrink", "leave-test-out"
    );
    for c in &d.candidates {
        let extra: Vec<String> = c
            .extra_parameters
            .iter()
            .map(|(k, v)| format!("{k}={v:.4}"))
            .collect();
        let _ = writeln!(
            s,
            "   {:<15} {:>10.3} {:>12.1} {:>13.0}% {:>15.0}%  {}",
            c.effect.name(),
            c.fit_reduced_chi2,
            c.delta_bic,
            100.0 * c.held_out_shrink,
            100.0 * c.leave_one_test_out_shrink,
            extra.join(" ")
        );
    }
    let _ = writeln!(s, "\n3. verdict: {}", d.verdict.effect);
    let _ = writeln!(s, "   {}", d.verdict.explanation);
    if !d.shrink_by_segment.is_empty() {
        let _ = writeln!(
            s,
            "   held-out misfit per segment, base → with {}:",
            d.verdict.effect
        );
        for x in &d.shrink_by_segment {
            let _ = writeln!(
                s,
                "   {:<24} {:>5} rows  {:6.2} → {:6.2}× noise  ({:+.0}% of the excess removed)",
                x.group,
                x.rows,
                x.base_rms_over_noise,
                x.effect_rms_over_noise,
                100.0 * x.shrink
            );
        }
    }
    let _ = write!(s, "({:.1} s)", d.elapsed_s);
    s
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
        let Some(effect) = truth[&name]["effect"].as_str() else {
            eprintln!("{name}: no truth in {}, skipped", truth_path.display());
            continue;
        };
        // An effect outside the library counts as "unexplained".
        let t = Effect::from_name(effect).unwrap_or(Effect::Unexplained);
        let set = load_set(&d)?;
        let diag = diagnose(&prepare_set(&set, false), opts)?;
        let c = Case::new(&name, t, &diag);
        println!(
            "{name:<24} truth {:<15} verdict {:<15} shrink {:>4.0}%  ({:.1} s)",
            c.truth.name(),
            c.verdict.name(),
            100.0 * c.shrink,
            c.elapsed_s
        );
        cases.push(c);
    }
    let s = score(&cases);
    Ok((cases, s))
}

/// Runs the generated self-check.
pub fn run_selfcheck(opts: &SelfcheckOptions) -> (Vec<Case>, subfric_diagnose::selfcheck::Scores) {
    selfcheck(opts, &|c| {
        println!(
            "{:<32} truth {:<15} verdict {:<15} shrink {:>4.0}%  ({:.1} s)",
            c.name,
            c.truth.name(),
            c.verdict.name(),
            100.0 * c.shrink,
            c.elapsed_s
        )
    })
}
