//! `subfric campaign`: many interface pairs at once. Every set of a folder of sets (or of a
//! manifest, [`manifest`]) is fitted, and diagnosed when asked, into its own results folder
//! `sets/<set>/` (the files `subfric fit` and `subfric diagnose` write, and a record of the
//! inputs' hashes and options, [`record`]); a set whose inputs and options have not changed
//! since its results were written is skipped; a failing set is reported and the others go on.
//! The campaign table (`campaign.csv`, `campaign.md`) and the summary figures are then made
//! from the per-set folders alone ([`collect`]), so the same results give the same bytes
//! whoever wrote them: a local run ([`run`]), Slurm array tasks ([`run_index`] after
//! [`emit_slurm`], submitted and followed by [`submit`]), or Dask workers (the Python package: [`prepare`], [`run_index`],
//! [`collect`]).
//!
//! ```text
//! <out>/  .subfric-source  campaign.json (the plan)  campaign.csv  campaign.md  campaign.html
//!         figures/mu-vs-roughness.png  mu-vs-normal-stress.png  verdicts.png
//!         sets/<set>/  fit.json  fit.txt  campaign-set.json  diagnosis/…
//!         campaign.sbatch  collect.sbatch  slurm/   (--emit-slurm)
//! ```

mod figures;
pub mod manifest;
mod page;
pub mod record;
mod run;
pub mod slurm;
pub mod submit;
mod table;

pub use figures::{verdict_page, ROUGHNESS_FIGURE, STRESS_FIGURE, VERDICT_FIGURE, VERDICT_PAGE};
pub use page::PAGE;
pub use run::{Interrupted, SetOutcome, SetRun};
pub use table::{ParamCell, Row, RowStatus};

use crate::flags::{conflicts, parse_bound, parse_fix, parse_param};
use crate::folders::io::{write_json, write_text};
use crate::folders::output::{safe_name, ResultsDir};
use crate::progress::Progress;
use crate::FitRequest;
use anyhow::{anyhow, bail, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use subfric_data::{PathKind, EXPERIMENT_JSON};
use subfric_diagnose::DiagnoseOptions;
use subfric_fit::{FitOptions, Param};

/// The campaign's plan: its sets in order, with their options.
pub const PLAN_FILE: &str = "campaign.json";
/// The campaign table, every number at full precision.
pub const TABLE_CSV: &str = "campaign.csv";
/// The campaign table to read.
pub const TABLE_MD: &str = "campaign.md";
/// The folder of the summary figures.
pub const FIGURES_DIR: &str = "figures";
/// The folder of the per-set results folders.
pub const SETS_DIR: &str = "sets";

/// What is done to each set: the fit's options (as `subfric fit` takes them) and whether to
/// diagnose it too (with the same seed).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SetOptions {
    /// Only these tests (all when empty).
    pub tests: Vec<String>,
    /// Free parameters (`None`: μ_s, μ_k, κ, ξ, ũ, less those fixed).
    pub free: Option<Vec<String>>,
    /// Fixed values.
    pub fix: BTreeMap<String, f64>,
    /// Bounds, `[lo, hi]` in the parameter's units.
    pub bounds: BTreeMap<String, [f64; 2]>,
    /// Seed of the fit and of the diagnosis.
    pub seed: u64,
    /// Local starts of the fit.
    pub starts: usize,
    /// Model runs of the fit's global stage.
    pub global_evals: usize,
    /// Profile intervals.
    pub profiles: bool,
    /// Diagnose the set too.
    pub diagnose: bool,
}

impl Default for SetOptions {
    /// `subfric fit`'s defaults, no diagnosis.
    fn default() -> Self {
        let fit = FitOptions::default();
        SetOptions {
            tests: Vec::new(),
            free: None,
            fix: BTreeMap::new(),
            bounds: BTreeMap::new(),
            seed: fit.seed,
            starts: fit.starts,
            global_evals: fit.global_evaluations,
            profiles: fit.profiles,
            diagnose: false,
        }
    }
}

impl SetOptions {
    fn free(&self) -> Result<Option<Vec<Param>>, String> {
        self.free
            .as_ref()
            .map(|keys| keys.iter().map(|k| parse_param(k)).collect())
            .transpose()
    }

    fn fix(&self) -> Result<Vec<(Param, f64)>, String> {
        self.fix
            .iter()
            .map(|(k, v)| parse_fix(&format!("{k}={v}")))
            .collect()
    }

    fn bounds(&self) -> Result<Vec<(Param, f64, f64)>, String> {
        self.bounds
            .iter()
            .map(|(k, [lo, hi])| parse_bound(&format!("{k}={lo}:{hi}")))
            .collect()
    }

    /// Whether the options make sense together (as `subfric fit` checks its flags).
    pub fn check(&self) -> Result<(), String> {
        let free = self.free()?;
        let (fix, bounds) = (self.fix()?, self.bounds()?);
        conflicts(free.as_deref(), &fix, &bounds, &[])?;
        if self.starts == 0 {
            return Err("starts = 0 (expected at least one local start)".into());
        }
        Ok(())
    }

    /// The fit of the set in `dir` as `subfric fit` would run it with these options.
    pub fn fit_request(&self, dir: &Path) -> Result<FitRequest> {
        let e = |e: String| anyhow!("{}: {e}", dir.display());
        Ok(FitRequest {
            dirs: vec![dir.to_path_buf()],
            tests: self.tests.clone(),
            free: self
                .free()
                .map_err(e)?
                .unwrap_or_else(|| Param::BASE.to_vec()),
            fix: self.fix().map_err(e)?,
            bounds: self.bounds().map_err(e)?,
            weights: Vec::new(),
            posterior: None,
            start: None,
            options: FitOptions {
                seed: self.seed,
                starts: self.starts,
                global_evaluations: self.global_evals,
                profiles: self.profiles,
                ..FitOptions::default()
            },
        })
    }

    /// The diagnosis as `subfric diagnose --seed` runs it.
    pub fn diagnose_options(&self) -> DiagnoseOptions {
        DiagnoseOptions {
            seed: self.seed,
            ..DiagnoseOptions::default()
        }
    }

    /// The options the fit's results depend on (recorded and hashed).
    pub fn fit_part(&self) -> serde_json::Value {
        serde_json::json!({
            "tests": self.tests,
            "free": self.free,
            "fix": self.fix,
            "bounds": self.bounds,
            "seed": self.seed,
            "starts": self.starts,
            "global_evals": self.global_evals,
            "profiles": self.profiles,
        })
    }

    /// The options the diagnosis's results depend on (recorded and hashed).
    pub fn diagnosis_part(&self) -> serde_json::Value {
        serde_json::json!({ "seed": self.seed })
    }
}

/// One set of a campaign.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SetJob {
    /// Its results folder's name: `sets/<id>`.
    pub id: String,
    /// Its folder as the campaign gave it (the table shows it).
    pub folder: String,
    /// Its folder, absolute.
    pub dir: PathBuf,
    /// What is done to it.
    pub options: SetOptions,
}

/// The sets of a campaign in order (by `id`), as `campaign.json` holds them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Plan {
    /// The campaign's name (the table's title): its folder's or manifest's name.
    pub name: String,
    /// What the campaign was made from.
    pub source: String,
    /// The sets.
    pub sets: Vec<SetJob>,
}

impl Plan {
    /// The plan in the campaign folder `out`.
    pub fn read(out: &Path) -> Result<Plan> {
        let file = out.join(PLAN_FILE);
        let text =
            crate::folders::io::read_settings_text(&file, "the campaign plan").map_err(|e| {
                anyhow!("{e} (expected a folder written by `subfric campaign` or `--emit-slurm`)")
            })?;
        serde_json::from_str(&text).map_err(|e| {
            anyhow!(
                "{}:{}: not a campaign plan: {e} (expected the file `subfric campaign` writes; run it again)",
                file.display(),
                e.line()
            )
        })
    }
}

/// Where a campaign's sets come from.
#[derive(Clone, Debug, PartialEq)]
pub enum CampaignSource {
    /// A folder whose sub-folders holding `experiment.json` are the sets.
    Folder(PathBuf),
    /// A manifest file (JSON or TOML) listing set folders ([`manifest`]).
    Manifest(PathBuf),
    /// Set folders (the Python package's list).
    Sets(Vec<PathBuf>),
}

impl CampaignSource {
    /// A folder of sets, or a manifest file; refuses a single set (with the command for it).
    pub fn of(path: &Path) -> Result<CampaignSource> {
        match PathKind::of(path) {
            PathKind::Folder if path.join(EXPERIMENT_JSON).is_file() => bail!(
                "{}: is one set (it holds {EXPERIMENT_JSON}) (expected a folder of sets or a manifest; one set is fitted with `subfric fit {}`)",
                path.display(),
                path.display()
            ),
            PathKind::Folder => Ok(CampaignSource::Folder(path.to_path_buf())),
            PathKind::File => Ok(CampaignSource::Manifest(path.to_path_buf())),
            kind => bail!(
                "{}: {} (expected a folder of sets, or a manifest file .json or .toml)",
                path.display(),
                kind.describe()
            ),
        }
    }

    /// The paths the campaign folder records as its source.
    fn paths(&self) -> Vec<PathBuf> {
        match self {
            CampaignSource::Folder(p) | CampaignSource::Manifest(p) => vec![p.clone()],
            CampaignSource::Sets(v) => v.clone(),
        }
    }

    /// The campaign's name: the folder's name, the manifest's stem, or `sets`.
    pub fn name(&self) -> String {
        let name = match self {
            CampaignSource::Folder(p) => std::fs::canonicalize(p)
                .ok()
                .and_then(|c| c.file_name().map(|n| n.to_string_lossy().to_string())),
            CampaignSource::Manifest(p) => p.file_stem().map(|n| n.to_string_lossy().to_string()),
            CampaignSource::Sets(_) => None,
        };
        safe_name(&name.unwrap_or_else(|| "sets".into()))
    }
}

/// A campaign: its sets, where it writes, what is done to each set unless a manifest says
/// otherwise.
#[derive(Clone, Debug)]
pub struct CampaignRequest {
    /// The sets.
    pub source: CampaignSource,
    /// The campaign folder (`None`: `campaigns/<name>`).
    pub out: Option<PathBuf>,
    /// Options of every set (a manifest's own win over these).
    pub defaults: SetOptions,
    /// Replace results of another campaign or of other sets.
    pub force: bool,
}

impl CampaignRequest {
    /// The campaign folder.
    pub fn out_dir(&self) -> PathBuf {
        self.out
            .clone()
            .unwrap_or_else(|| Path::new("campaigns").join(self.source.name()))
    }
}

/// A plan and what was noticed making it.
pub struct Planned {
    /// The plan.
    pub plan: Plan,
    /// Notes (sub-folders that are not sets).
    pub notes: Vec<String>,
}

fn canonical(p: &Path) -> Result<PathBuf> {
    std::fs::canonicalize(p).map_err(|e| anyhow!("{}: {e}", p.display()))
}

/// The sets of the campaign, sorted by their results folders' names; every problem of a
/// manifest is found here, before anything is written.
pub fn plan(req: &CampaignRequest) -> Result<Planned> {
    req.defaults
        .check()
        .map_err(|e| anyhow!("campaign options: {e}"))?;
    let mut notes = Vec::new();
    let mut sets = Vec::new();
    match &req.source {
        CampaignSource::Folder(root) => {
            let entries = std::fs::read_dir(root)
                .map_err(|e| anyhow!("{}: cannot read the folder: {e}", root.display()))?;
            let mut names: Vec<String> = entries
                .flatten()
                .map(|e| e.file_name().to_string_lossy().to_string())
                .filter(|n| !n.starts_with('.'))
                .collect();
            names.sort();
            for name in names {
                let dir = root.join(&name);
                if PathKind::of(&dir) != PathKind::Folder {
                    continue;
                }
                if !dir.join(EXPERIMENT_JSON).is_file() {
                    notes.push(format!(
                        "{}: holds no {EXPERIMENT_JSON}: not a set, left out",
                        dir.display()
                    ));
                    continue;
                }
                sets.push(job(&dir, name, req.defaults.clone())?);
            }
        }
        CampaignSource::Manifest(file) => {
            let m = manifest::load(file, &req.defaults)?;
            let base = m.options.over(&req.defaults);
            for s in &m.sets {
                let mut j = job(&s.path, s.written.clone(), s.options.over(&base))?;
                j.id = manifest::set_id(s);
                sets.push(j);
            }
        }
        CampaignSource::Sets(dirs) => {
            for d in dirs {
                let json = d.join(EXPERIMENT_JSON);
                if !json.is_file() {
                    bail!(
                        "{}: holds no {EXPERIMENT_JSON} (expected a set folder)",
                        d.display()
                    );
                }
                sets.push(job(d, d.display().to_string(), req.defaults.clone())?);
            }
        }
    }
    if sets.is_empty() {
        bail!(
            "{}: no sets (expected sub-folders holding {EXPERIMENT_JSON}, or a manifest listing set folders)",
            req.source
                .paths()
                .first()
                .map_or_else(String::new, |p| p.display().to_string())
        );
    }
    sets.sort_by(|a, b| a.id.cmp(&b.id));
    if let Some(w) = sets.windows(2).find(|w| w[0].id == w[1].id) {
        bail!(
            "{} and {}: both would write their results to {SETS_DIR}/{} (expected folders with distinct names; a manifest gives one an `id`)",
            w[0].folder,
            w[1].folder,
            w[0].id
        );
    }
    Ok(Planned {
        plan: Plan {
            name: req.source.name(),
            source: req
                .source
                .paths()
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
            sets,
        },
        notes,
    })
}

fn job(dir: &Path, folder: String, options: SetOptions) -> Result<SetJob> {
    Ok(SetJob {
        id: manifest::folder_id(dir),
        folder,
        dir: canonical(dir)?,
        options,
    })
}

/// The campaign folder claimed for the campaign's source (see [`ResultsDir`]): locked, and
/// refused when it holds another campaign's results (unless `force`) or a set.
fn claim(req: &CampaignRequest, out: &Path) -> Result<ResultsDir> {
    let files = [
        PLAN_FILE,
        TABLE_CSV,
        TABLE_MD,
        FIGURES_DIR,
        SETS_DIR,
        slurm::ARRAY_SCRIPT,
        slurm::COLLECT_SCRIPT,
        slurm::LOG_DIR,
    ]
    .map(String::from);
    ResultsDir::claim(out, &req.source.paths(), &files, req.force)
}

/// A campaign folder ready for its sets to be run by others (Slurm tasks, Dask workers).
pub struct Prepared {
    /// The campaign folder.
    pub out: PathBuf,
    /// The plan written there.
    pub plan: Plan,
    /// Notes of the planning.
    pub notes: Vec<String>,
}

/// Plans the campaign and writes its plan into its folder (claimed, then committed): what
/// [`run_index`] and [`collect`] read.
pub fn prepare(req: &CampaignRequest) -> Result<Prepared> {
    let Planned { plan, notes } = plan(req)?;
    let out = req.out_dir();
    let root = claim(req, &out)?;
    write_json(&out.join(PLAN_FILE), &plan)?;
    root.commit()?;
    Ok(Prepared { out, plan, notes })
}

/// The same plan, or what differs (`stored`: the one in the campaign folder).
fn check_same(stored: &Plan, now: &Plan, out: &Path) -> Result<()> {
    if stored.sets == now.sets {
        return Ok(());
    }
    let ids = |p: &Plan| p.sets.iter().map(|s| s.id.clone()).collect::<Vec<_>>();
    let what = match stored.sets.iter().zip(&now.sets).find(|(a, b)| a != b) {
        _ if ids(stored) != ids(now) => format!(
            "its sets are now {} ({} before)",
            ids(now).join(", "),
            ids(stored).join(", ")
        ),
        Some((a, _)) => format!("set {} is not the same (folder or options)", a.id),
        None => "its sets differ".into(),
    };
    bail!(
        "{}: the campaign's plan differs from what these arguments give: {what} (expected the same source and options as when the plan was written; write it again with --emit-slurm, or run the campaign)",
        out.join(PLAN_FILE).display()
    )
}

/// Runs set `index` of the plan in the campaign folder `out` (a Slurm array task, a Dask
/// worker); with `req`, first checks that the plan is the one `req` gives.
pub fn run_index(
    req: Option<&CampaignRequest>,
    out: &Path,
    index: usize,
    force: bool,
    progress: &dyn Progress,
) -> Result<SetRun> {
    let stored = Plan::read(out)?;
    if let Some(req) = req {
        check_same(&stored, &plan(req)?.plan, out)?;
    }
    let job = stored.sets.get(index).ok_or_else(|| {
        anyhow!(
            "--index {index}: the campaign has {} sets (expected 0 to {})",
            stored.sets.len(),
            stored.sets.len().saturating_sub(1)
        )
    })?;
    Ok(run::run_set(out, index, job, force, progress))
}

/// The campaign table and figures, written.
pub struct Collected {
    /// The campaign folder.
    pub out: PathBuf,
    /// One row per set, sorted by set.
    pub rows: Vec<Row>,
    /// The files written.
    pub files: Vec<PathBuf>,
}

impl Collected {
    /// The rows of sets without results for today's inputs (failed, not run, out of date).
    pub fn incomplete(&self) -> Vec<&Row> {
        self.rows
            .iter()
            .filter(|r| r.status != RowStatus::Ok)
            .collect()
    }
}

fn write_table(out: &Path, plan: &Plan) -> Result<Collected> {
    let rows: Vec<Row> = plan.sets.iter().map(|j| table::row(out, j)).collect();
    let diagnosed = plan.sets.iter().any(|j| j.options.diagnose);
    let csv = out.join(TABLE_CSV);
    write_text(&csv, &table::csv(&rows, diagnosed))?;
    let md = out.join(TABLE_MD);
    write_text(&md, &table::markdown(&plan.name, &rows, diagnosed))?;
    let mut files = vec![csv, md];
    let figures = figures::write(&out.join(FIGURES_DIR), &rows)?;
    let html = out.join(PAGE);
    write_text(
        &html,
        &page::page(&plan.name, out, &rows, diagnosed, &figures)?,
    )?;
    files.push(html);
    files.extend(figures);
    Ok(Collected {
        out: out.to_path_buf(),
        rows,
        files,
    })
}

/// The table's rows as the per-set results folders of the campaign folder `out` give them now,
/// by the plan there; nothing is written (what `--collect` would write, e.g. while Slurm
/// tasks still run or once they have ended).
pub fn rows(out: &Path) -> Result<Vec<Row>> {
    let plan = Plan::read(out)?;
    Ok(plan.sets.iter().map(|j| table::row(out, j)).collect())
}

/// Assembles the table and the figures from the per-set results folders of the campaign
/// `req` writes (after checking that its plan is the one `req` gives): `--collect`.
pub fn collect(req: &CampaignRequest) -> Result<Collected> {
    let out = req.out_dir();
    let stored = Plan::read(&out)?;
    check_same(&stored, &plan(req)?.plan, &out)?;
    let root = claim(req, &out)?;
    let c = write_table(&out, &stored)?;
    root.commit()?;
    Ok(c)
}

/// A local run of a campaign.
pub struct Finished {
    /// The plan.
    pub plan: Plan,
    /// Notes of the planning.
    pub notes: Vec<String>,
    /// Each set's run, in the plan's order.
    pub runs: Vec<SetRun>,
    /// The table and figures.
    pub collected: Collected,
}

/// `subfric campaign`: plans, claims the campaign folder, runs every set (at most `parallel`
/// at a time, default one per core: see [`run::run_sets`]), reporting each through `on_set`
/// as it ends, then writes the table and the figures. A failing set is in the runs and the
/// table; the error is for a campaign that cannot run at all.
pub fn run(
    req: &CampaignRequest,
    parallel: Option<usize>,
    on_set: &(dyn Fn(&SetRun) + Sync),
    progress: &dyn Progress,
) -> Result<Finished> {
    let Planned { plan, notes } = plan(req)?;
    for n in &notes {
        progress.note(n);
    }
    let out = req.out_dir();
    let root = claim(req, &out)?;
    write_json(&out.join(PLAN_FILE), &plan)?;
    let parallel = parallel.unwrap_or_else(rayon::current_num_threads).max(1);
    let jobs: Vec<(usize, &SetJob)> = plan.sets.iter().enumerate().collect();
    let runs = run::run_sets(&out, &jobs, parallel, req.force, on_set, progress)?;
    progress.stage("campaign: table and figures", None);
    let collected = write_table(&out, &plan)?;
    root.commit()?;
    Ok(Finished {
        plan,
        notes,
        runs,
        collected,
    })
}

/// The scripts written by [`emit_slurm`].
pub struct Emitted {
    /// The campaign folder.
    pub out: PathBuf,
    /// The plan written there.
    pub plan: Plan,
    /// The job-array script and the collect step's.
    pub scripts: [PathBuf; 2],
    /// Notes of the planning.
    pub notes: Vec<String>,
}

/// `subfric campaign --emit-slurm`: the plan and the two scripts written into the campaign
/// folder (and its folder of logs made, which Slurm does not make); nothing is run.
pub fn emit_slurm(req: &CampaignRequest, o: &slurm::SlurmOptions) -> Result<Emitted> {
    let Planned { plan, notes } = plan(req)?;
    let out = req.out_dir();
    let root = claim(req, &out)?;
    write_json(&out.join(PLAN_FILE), &plan)?;
    let abs = std::path::absolute(&out).map_err(|e| anyhow!("{}: {e}", out.display()))?;
    let name = format!("subfric-{}", plan.name);
    let (array, collect) = slurm::scripts(o, &name, &abs, plan.sets.len());
    let scripts = [
        out.join(slurm::ARRAY_SCRIPT),
        out.join(slurm::COLLECT_SCRIPT),
    ];
    write_text(&scripts[0], &array)?;
    write_text(&scripts[1], &collect)?;
    let logs = out.join(slurm::LOG_DIR);
    std::fs::create_dir_all(&logs)
        .map_err(|e| anyhow!("{}: cannot create the folder: {e}", logs.display()))?;
    root.commit()?;
    Ok(Emitted {
        out,
        plan,
        scripts,
        notes,
    })
}
