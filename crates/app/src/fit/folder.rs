//! The folder form of the fit (`subfric fit`): the results folder claimed, then `fit.json`,
//! `fit.txt`, the figures, `report.html` and the posterior's files written. Above the fit's
//! values and the reports it renders from them.

use super::{fit_json, prepare_posterior, run_setup, setup, with_posterior, FitRequest, Fitted};
use crate::folders::io::{write_json, write_text};
use crate::folders::output::{default_results_dir, Destination, ResultsDir};
use crate::progress::Progress;
use anyhow::Result;
use std::path::PathBuf;

/// A fit written to its results folder.
pub struct FitWritten {
    /// The fit.
    pub fitted: Fitted,
    /// The `fit.json` written.
    pub file: PathBuf,
    /// Everything else written: `fit.txt`, one figure per test, `report.html` (with
    /// `--posterior` also the chain, the corner plot and the band figures).
    pub files: Vec<PathBuf>,
}

/// `subfric fit`: the request checked and the output folder (`fits/<set names>` unless
/// given) claimed before the fit runs; `fit.json`, `fit.txt`, one figure per test (measured,
/// published, fitted) and `report.html` written (with `--posterior` also the posterior's files,
/// all in the same claim), then the folder's record of its sets.
pub fn fit_to_folder(
    req: &FitRequest,
    to: &Destination,
    progress: &dyn Progress,
) -> Result<FitWritten> {
    let setup = setup(req, progress)?;
    let dir = to
        .dir
        .clone()
        .unwrap_or_else(|| default_results_dir(&setup.name()));
    let sampler = prepare_posterior(req, &setup)?;
    let mut files: Vec<String> = ["fit.json", "fit.txt", crate::render::report::REPORT_FILE]
        .map(String::from)
        .to_vec();
    files.extend(crate::render::figures::figure_files(&setup.tests));
    if sampler.is_some() {
        // fit.txt is already listed: the posterior's table goes into it.
        files.extend(
            crate::posterior::files(&setup.tests)
                .into_iter()
                .filter(|f| f != "fit.txt"),
        );
    }
    let claim = ResultsDir::claim(&dir, &req.dirs, &files, to.force)?;
    let warnings = setup.warnings.clone();
    let outcome = run_setup(req, setup, progress)?;
    let posterior = sampler.map(|s| s.sample(&outcome, progress)).transpose()?;
    let json = with_posterior(fit_json(&outcome)?, &outcome, posterior.as_ref())?;
    let file = dir.join("fit.json");
    write_json(&file, &json)?;
    progress.stage("drawing the figures and the report", None);
    let txt = dir.join("fit.txt");
    let table = crate::render::fit_report::report_table(&outcome);
    match &posterior {
        Some(p) => write_text(&txt, &format!("{table}\n\n{}", p.text(&outcome.report)))?,
        None => write_text(&txt, &(table + "\n"))?,
    }
    let (plots, notes) = crate::render::figures::plot_set(
        &outcome.name,
        &outcome.tests,
        outcome.published.as_ref(),
        Some(&outcome.report.model),
        &dir,
    )?;
    for n in &notes {
        progress.warning(n);
    }
    let html = dir.join(crate::render::report::REPORT_FILE);
    write_text(
        &html,
        &crate::render::report::fit_page(&outcome, &dir, &plots)?,
    )?;
    let mut posterior_files = Vec::new();
    if let Some(p) = &posterior {
        progress.stage("drawing the posterior's figures", None);
        posterior_files = p.write(&outcome, &dir)?;
    }
    claim.commit()?;
    let mut written = vec![txt];
    written.extend(plots);
    written.push(html);
    written.extend(posterior_files);
    Ok(FitWritten {
        fitted: Fitted {
            outcome,
            json,
            warnings,
            posterior,
        },
        file,
        files: written,
    })
}
