//! The next test to run for a set: the set is fitted, one more test of each kind under the
//! rig's control is proposed and ranked by how far it would take the parameters the data do
//! not determine towards "determined", per hour of lab time, and the top one is checked by
//! fitting a simulated joint campaign (the planning itself is the `subfric-design` crate).
//!
//! [`plan_to_folder`] writes `plan.json`, `plan.txt`, one scenario JSON per proposal
//! (`scenarios/<name>.json`, runnable with `subfric simulate --scenario`) and
//! `top-proposal.png`: the top proposal's predicted curve with the band the undetermined
//! parameters still allow.

pub use crate::outcome::plan_basis::misfit_warning;

use crate::fit::{run_setup, setup, FitOutcome, FitRequest};
use crate::folders::io::{write_json, write_text};
use crate::folders::output::{default_results_dir, Destination, ResultsDir};
use crate::located;
use crate::outcome::adequacy::misfit_number;
use crate::outcome::plan_basis::{basis, Basis};
use crate::progress::Progress;
use crate::render::fit_report::INTERVAL_LEGEND;
use crate::repeat::{repeated_test, Protocol};
use anyhow::{bail, Result};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use subfric_design::{
    plan_excluding, Band, Check, Plan, PlanOptions, PredictedParam, Proposal, NARROWS_MIN_SHRINK,
};
use subfric_fit::interval::short_number as num;
use subfric_fit::{FitOptions, Param, RunCounter, Status};
use subfric_model::Control;
use subfric_plot::{write_figure, Figure, Panel, Series, Style};
use subfric_reading::FitTest;

/// The folder of a set's results that holds its plan.
pub const PLAN_DIR: &str = "plan";

/// What a plan folder holds (scenarios/ is a folder of one JSON per proposal).
fn plan_files() -> Vec<String> {
    [
        "plan.json",
        "plan.txt",
        "top-proposal.png",
        "top-proposal.svg",
        "scenarios",
        crate::render::report::REPORT_FILE,
    ]
    .map(String::from)
    .to_vec()
}

/// What to plan for.
#[derive(Clone, Debug)]
pub struct PlanRequest {
    /// The set's folder.
    pub set: PathBuf,
    /// Seed of the fits and of the simulated check's noise.
    pub seed: u64,
    /// How many of the top proposals to check by fitting a simulated joint campaign.
    pub check: usize,
    /// Lab time of a new test beyond its duration (specimen, set-up) [h].
    pub setup_hours: f64,
    /// The diagnosis whose model to plan on; `None`: `fits/<set>/diagnosis/diagnosis.json`
    /// when it exists and was written for this set folder, else the base model.
    pub diagnosis: Option<PathBuf>,
}

/// A plan written to its folder.
pub struct PlanWritten {
    /// The set's name.
    pub name: String,
    /// The plan.
    pub plan: Plan,
    /// The readable plan (also in `plan.txt`).
    pub text: String,
    /// The files written.
    pub files: Vec<PathBuf>,
    /// The model planned on.
    pub basis: Basis,
    /// The fit the plan rests on.
    pub outcome: FitOutcome,
}

/// `subfric plan`: the request and the set checked and the output folder
/// (`fits/<set name>/plan` unless given) claimed before the fit; the plan written, then the
/// folder's record of its set.
pub fn plan_to_folder(
    req: &PlanRequest,
    to: &Destination,
    progress: &dyn Progress,
) -> Result<PlanWritten> {
    if !(req.setup_hours >= 0.0 && req.setup_hours.is_finite()) {
        bail!(
            "--setup-hours {}: expected a finite number of hours >= 0",
            req.setup_hours
        );
    }
    // The fit and the planning are one job: their model runs count together.
    let options = FitOptions {
        seed: req.seed,
        run_counter: Some(RunCounter::new()),
        ..FitOptions::default()
    };
    let set_name = subfric_data::load_set(&req.set)?.meta.name;
    let basis = basis(&req.set, &set_name, req.diagnosis.as_deref())?;
    if let Some(n) = &basis.note {
        progress.note(n);
    }
    let mut fit = FitRequest::of_set(req.set.clone(), options.clone());
    fit.free.extend(basis.extra_free.iter().copied());
    fit.start = basis.start;
    let setup = setup(&fit, progress)?;
    let dir = to
        .dir
        .clone()
        .unwrap_or_else(|| default_results_dir(&setup.name()).join(PLAN_DIR));
    let claim = ResultsDir::claim(
        &dir,
        std::slice::from_ref(&req.set),
        &plan_files(),
        to.force,
    )?;
    let outcome = run_setup(&fit, setup, progress)?;
    if let Some(w) = misfit_warning(&outcome.adequacy, &basis, &req.set) {
        progress.warning(&w);
    }
    progress.stage("planning: the valley, the proposals, the check", None);
    let opts = PlanOptions {
        setup_hours: req.setup_hours,
        check: req.check,
        fit: options,
        ..PlanOptions::default()
    };
    let p = plan_outcome(&outcome, &opts).map_err(|e| located(e, &req.set))?;
    let text = plan_text(&outcome, &basis, &req.set, &p);
    let mut files = write_plan(claim.path(), &outcome, &basis, &p, &text)?;
    let plots: Vec<PathBuf> = files
        .iter()
        .filter(|f| f.extension().is_some_and(|x| x == "png"))
        .cloned()
        .collect();
    let page = crate::render::report::plan_page(
        &outcome,
        &basis,
        &req.set,
        &p,
        &text,
        claim.path(),
        &plots,
    )?;
    let report = claim.path().join(crate::render::report::REPORT_FILE);
    write_text(&report, &page)?;
    files.push(report);
    claim.commit()?;
    Ok(PlanWritten {
        name: outcome.name.clone(),
        plan: p,
        text,
        files,
        basis,
        outcome,
    })
}

/// Plans the next test for a finished fit, never proposing a test the set already holds.
pub fn plan_outcome(outcome: &FitOutcome, opts: &PlanOptions) -> Result<Plan> {
    let tests: Vec<FitTest> = outcome.tests.iter().map(|t| t.fit.clone()).collect();
    let held: Vec<Protocol> = outcome.tests.iter().map(Protocol::of_prepared).collect();
    let excluded = |t: &FitTest| repeated_test(t, &held);
    Ok(plan_excluding(&tests, &outcome.report, opts, &excluded)?)
}

/// Writes plan.json, plan.txt, the scenarios and the band figure under `dir`.
pub fn write_plan(
    dir: &Path,
    outcome: &FitOutcome,
    basis: &Basis,
    p: &Plan,
    text: &str,
) -> Result<Vec<PathBuf>> {
    let name = &outcome.name;
    let mut files = Vec::new();
    let json = dir.join("plan.json");
    write_json(
        &json,
        &serde_json::json!({
            "set": name,
            "model": {
                "planned_on": basis.model_words(),
                "effects": basis.effects,
                "diagnosis": basis.diagnosis,
                "verdict": outcome.adequacy.json(&basis.model_words()),
            },
            "ranking": "share of the valley (the parameter vectors the current data allow) over which every undetermined parameter is predicted determined within ±5 %, per hour of lab time; ties by ln(shrink) per hour",
            "plan": p,
        }),
    )?;
    files.push(json);
    let txt = dir.join("plan.txt");
    write_text(&txt, &format!("{text}\n"))?;
    files.push(txt);
    // A scenario or figure of an earlier plan in this folder would be read as one of this
    // plan's proposals: the plan's own files are cleared first (the folder is claimed).
    clear_earlier_plan(dir)?;
    for prop in &p.proposals {
        let f = dir.join("scenarios").join(format!("{}.json", prop.name));
        write_json(&f, &prop.scenario)?;
        files.push(f);
    }
    if let (Some(band), Some(top)) = (&p.band, p.top()) {
        let f = dir.join("top-proposal.png");
        write_figure(&band_figure(name, &top.name, band), &f)?;
        files.push(f);
    }
    Ok(files)
}

/// Removes the scenarios (`scenarios/*.json`) and the band figure (PNG and SVG) of an earlier
/// plan in `dir`.
fn clear_earlier_plan(dir: &Path) -> Result<()> {
    crate::folders::io::remove_earlier_files(&dir.join("scenarios"), "json")?;
    for f in ["top-proposal.png", "top-proposal.svg"] {
        match std::fs::remove_file(dir.join(f)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(e.into()),
            _ => {}
        }
    }
    Ok(())
}

/// The top proposal's predicted curve against time, with the envelope of the curves of every
/// parameter vector the current data allow, and the width of that envelope below.
fn band_figure(set: &str, proposal: &str, b: &Band) -> Figure {
    let slip = b.control == Control::Slip;
    let y = |v: &[f64]| -> Vec<f64> {
        if slip {
            v.iter().zip(&b.normal).map(|(a, n)| a / n).collect()
        } else {
            v.to_vec()
        }
    };
    let (lo, hi) = (y(&b.lo), y(&b.hi));
    let spread: Vec<f64> = hi.iter().zip(&lo).map(|(a, c)| a - c).collect();
    let t = b.time.clone();
    let main = Panel::new(
        if slip {
            "friction τ/σ_n [-]"
        } else {
            "slip u [mm]"
        },
        vec![
            Series::new(
                format!("range over the {} parameter sets the data allow", b.curves),
                t.clone(),
                lo,
                Style::Published,
            ),
            Series::new(
                format!("range over the {} parameter sets the data allow", b.curves),
                t.clone(),
                hi,
                Style::Published,
            ),
            Series::new("current fit", t.clone(), y(&b.fit), Style::Other(2)),
            Series::new(
                "middle of the values the data allow",
                t.clone(),
                y(&b.centre),
                Style::Fitted,
            ),
        ],
    );
    let residual = Panel::new(
        if slip { "range [-]" } else { "range [mm]" },
        vec![Series::new(
            "width of the range",
            t,
            spread,
            Style::Other(1),
        )],
    )
    .with_zero_line();
    Figure::new(
        format!("{set}: next test {proposal}, predicted"),
        "time t [s]",
        main,
    )
    .with_residual(residual)
}

fn interval_or_dash(i: Option<subfric_fit::Interval>) -> String {
    i.map(|i| i.to_string())
        .unwrap_or_else(|| "unbounded".into())
}

/// The readable plan printed by `subfric plan` and written to plan.txt: the verdict on the
/// model planned on first (with a warning when it does not describe the data), then the rig,
/// the valley, the proposals and the check.
pub fn plan_text(outcome: &FitOutcome, basis: &Basis, set: &Path, p: &Plan) -> String {
    let name = &outcome.name;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "verdict: {}",
        outcome.adequacy.sentence(&basis.model_words())
    );
    if let Some(w) = misfit_warning(&outcome.adequacy, basis, set) {
        let _ = writeln!(s, "warning: {w}");
    }
    let _ = writeln!(s, "{}", basis.line());
    if !outcome.adequacy.describes() && basis.diagnosis.is_none() {
        let _ = writeln!(
            s,
            "next: `subfric diagnose {}`, then `subfric plan {}` again",
            set.display(),
            set.display()
        );
    } else if !outcome.adequacy.describes() {
        // Parameters of a model that misses the data mean nothing: the next test is the one
        // that tells the diagnosis's leading explanations apart.
        for l in basis.must_change_lines() {
            let _ = writeln!(s, "{l}");
        }
        let _ = writeln!(
            s,
            "next: {}, then `subfric diagnose {}` again; the proposals below only narrow the parameters of {}",
            if basis.alternatives.is_empty() {
                "a test that shows the effect the model lacks (see the diagnosis's report)"
            } else {
                "the test that tells these explanations apart"
            },
            set.display(),
            basis.model_words()
        );
    } else if let Some(top) = p.top() {
        let _ = writeln!(s, "next: run {}: {}", top.name, top.description);
    } else {
        let _ = writeln!(
            s,
            "next: no proposal narrows the undetermined parameters (see the table): a test of another kind, or a longer one, is needed"
        );
    }
    let _ = writeln!(s);
    let noise_unit = match p.rig.control {
        Control::Slip => "kPa",
        Control::Shear => "mm",
    };
    write_rig_and_valley(&mut s, name, p);
    write_proposal_table(&mut s, p);
    for (n, why) in &p.rejected {
        let _ = writeln!(s, "not proposed: {n}: {why}");
    }
    if let Some(top) = p.top() {
        let _ = writeln!(s, "top proposal: {}: {}", top.name, top.description);
        if let Some(c) = &top.check {
            write_check(&mut s, top, c, p.rig.noise_sd, noise_unit);
        }
    }
    let _ = writeln!(s, "how to read the intervals:");
    for l in INTERVAL_LEGEND {
        let _ = writeln!(s, "  {l}");
    }
    s.trim_end().to_string()
}

/// The head of the plan: what the rig did, what is not determined, the valley and the
/// planning point.
fn write_rig_and_valley(s: &mut String, name: &str, p: &Plan) {
    let r = &p.rig;
    let (noise_unit, control) = match r.control {
        Control::Slip => ("kPa", "slip"),
        Control::Shear => ("mm", "traction"),
    };
    let _ = writeln!(
        s,
        "plan for {}: {control} control at {} mm/s, {:.0} kPa, sampled every {} s, noise {} {noise_unit}",
        crate::visible(name),
        num(r.rate_mm_s),
        r.normal_stress_kpa,
        num(r.dt_s),
        num(r.noise_sd)
    );
    if p.undetermined.is_empty() {
        let _ = writeln!(
            s,
            "the data determine every free parameter; proposals are ranked by how far they would narrow them further"
        );
    } else {
        let _ = writeln!(s, "not determined now: {}", p.undetermined.join(", "));
    }
    if let Some((lo, hi)) = valley_range(p, "xi") {
        let _ = writeln!(
            s,
            "{} parameter vectors the data allow (the valley): ξ from {} to {} 1/s",
            p.valley.len(),
            num(lo),
            num(hi)
        );
    }
    let pp = &p.planning_point.params;
    let _ = writeln!(
        s,
        "planning point (the middle of the values the data allow, where each proposal is simulated and its intervals predicted): mu_s {} mu_k {} kappa {} xi {} u_tilde {}",
        num(pp.mu_s),
        num(pp.mu_k),
        num(pp.kappa),
        num(pp.xi),
        num(pp.u_tilde)
    );
}

/// Smallest and largest value of parameter `key` over the valley.
fn valley_range(p: &Plan, key: &str) -> Option<(f64, f64)> {
    let q = Param::from_key(key)?;
    let v: Vec<f64> = p.valley.iter().filter_map(|v| q.get(&v.model)).collect();
    let lo = v.iter().cloned().fold(f64::INFINITY, f64::min);
    let hi = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    (lo <= hi).then_some((lo, hi))
}

/// The ranked proposals, one line each, and the legend of the columns.
fn write_proposal_table(s: &mut String, p: &Plan) {
    let _ = writeln!(
        s,
        "{:<4} {:<28} {:>7} {:>6} {:>11} {:>8} {:>8}  {:<28} still undetermined there",
        "rank",
        "proposal",
        "lab h",
        "rows",
        "determines",
        "shrink",
        "score",
        "ξ predicted (planning point)",
    );
    let ranked = p.ranked().count();
    for (i, prop) in p.proposals.iter().enumerate() {
        let rank = if prop.narrows {
            (i + 1).to_string()
        } else {
            "—".to_string()
        };
        let xi = prop.predicted.iter().find(|x| x.name == "xi");
        let left: Vec<&str> = prop
            .predicted
            .iter()
            .filter(|x| !x.determined)
            .map(|x| x.name.as_str())
            .collect();
        let _ = writeln!(
            s,
            "{:<4} {:<28} {:>7.2} {:>6} {:>10.0}% {:>7.1}× {:>8.3}  {:<28} {}",
            rank,
            prop.name,
            prop.hours,
            prop.rows,
            100.0 * prop.determines_share,
            prop.shrink,
            prop.score,
            xi.map(predicted_words).unwrap_or_default(),
            if left.is_empty() {
                "none".to_string()
            } else {
                left.join(", ")
            }
        );
    }
    let _ = writeln!(
        s,
        "determines: share of the valley where every undetermined parameter is predicted within ±5 %; shrink: geometric-mean narrowing of their intervals; score: determines per lab hour (test + set-up)"
    );
    let unranked = p.proposals.len() - ranked;
    if unranked > 0 {
        let _ = writeln!(
            s,
            "—: not ranked: {unranked} proposal{} narrow{} nothing (determine{} nothing and narrow{} the intervals by less than {NARROWS_MIN_SHRINK}×)",
            if unranked == 1 { "" } else { "s" },
            if unranked == 1 { "s" } else { "" },
            if unranked == 1 { "s" } else { "" },
            if unranked == 1 { "s" } else { "" },
        );
    }
    if ranked > 0 && p.ranked().all(|q| q.determines_share == 0.0) {
        let _ = writeln!(
            s,
            "no proposal determines the undetermined parameters within ±5 % anywhere the data allow: they are ranked by how far they narrow them per lab hour"
        );
    }
}

/// A predicted interval in words: the interval and its half-width, or that it stays wider
/// than the value itself (an interval of many orders of magnitude says nothing a number can).
fn predicted_words(x: &PredictedParam) -> String {
    match x.predicted {
        Some(i)
            if x.predicted_half_width_percent.is_finite()
                && x.predicted_half_width_percent <= 100.0 =>
        {
            format!("{i} ±{:.1}%", x.predicted_half_width_percent)
        }
        Some(_) => "not determined (> ±100 %)".into(),
        None => "not bounded".into(),
    }
}

/// The check of the top proposal: achieved intervals beside the predicted ones.
fn write_check(s: &mut String, top: &Proposal, c: &Check, noise_sd: f64, noise_unit: &str) {
    let _ = writeln!(
        s,
        "check: {} simulated at the planning point with noise {} {noise_unit} (seed {}), fitted with the current tests: misfit {}× the noise variance, {}",
        top.name,
        num(noise_sd),
        c.seed,
        misfit_number(c.reduced_chi2),
        if c.determines_all {
            "every parameter determined"
        } else {
            "not every parameter determined"
        }
    );
    let _ = writeln!(
        s,
        "  {:<10} {:>11} {:>26} {:>26} {:>7}  status",
        "parameter", "simulated", "predicted", "achieved", "ratio"
    );
    for q in &c.parameters {
        let _ = writeln!(
            s,
            "  {:<10} {:>11} {:>26} {:>26} {:>7}  {}",
            q.name,
            num(q.truth),
            interval_or_dash(q.predicted),
            interval_or_dash(q.achieved),
            q.width_ratio.map(|v| format!("{v:.2}")).unwrap_or_default(),
            q.status.describe()
        );
    }
}

/// What `subfric reproduce` reports of a set's plan: the top proposal and its ξ interval.
pub struct NextTest {
    /// Proposal name.
    pub name: String,
    /// What it is.
    pub description: String,
    /// Lab hours.
    pub hours: f64,
    /// Predicted ξ interval at the planning point, with its ±%.
    pub xi: String,
    /// Share of the valley where it determines every parameter.
    pub determines_share: f64,
}

impl NextTest {
    /// One Markdown paragraph for the set `set` (links relative to the folder holding the sets).
    pub fn markdown(&self, set: &str) -> String {
        format!(
            "Next test (`subfric plan`, [plan]({set}/plan/plan.txt)): **{}**, {}",
            self.name,
            self.details()
        )
    }

    /// The paragraph in words, without Markdown (for the HTML page).
    pub fn text(&self) -> String {
        format!(
            "Next test (`subfric plan`): {}, {}",
            self.name,
            self.details()
        )
    }

    fn details(&self) -> String {
        format!(
            "{:.2} h of lab time — {}. Predicted ξ: {}. Every undetermined parameter is predicted within ±5 % over {:.0} % of the parameter values the data allow.",
            self.hours,
            self.description,
            self.xi,
            100.0 * self.determines_share
        )
    }
}

/// Plans the next test of a fitted set for `reproduce` (no check fit, to keep it quick), and
/// writes the plan under `dir`; `None` when the fit determines every parameter. Its model runs
/// count into `run_counter` when given (the job's).
pub fn next_test(
    outcome: &FitOutcome,
    dir: &Path,
    run_counter: Option<&RunCounter>,
) -> Result<Option<NextTest>> {
    let r = &outcome.report;
    if r.parameters
        .iter()
        .all(|p| matches!(p.status, Status::Fixed | Status::Determined))
    {
        return Ok(None);
    }
    let p = plan_outcome(
        outcome,
        &PlanOptions {
            check: 0,
            fit: FitOptions {
                run_counter: run_counter.cloned(),
                ..FitOptions::default()
            },
            ..PlanOptions::default()
        },
    )?;
    let basis = Basis::default();
    let set = outcome.dirs.first().cloned().unwrap_or_default();
    let text = plan_text(outcome, &basis, &set, &p);
    write_plan(dir, outcome, &basis, &p, &text)?;
    Ok(p.top().map(|top| {
        let xi = top.predicted.iter().find(|x| x.name == "xi");
        NextTest {
            name: top.name.clone(),
            description: top.description.clone(),
            hours: top.hours,
            xi: xi
                .map(|x| {
                    format!(
                        "{} if ξ = {} 1/s, the middle of the values the data allow",
                        predicted_words(x),
                        num(x.value)
                    )
                })
                .unwrap_or_default(),
            determines_share: top.determines_share,
        }
    }))
}
