//! The command line: one `Args` struct per subcommand (clap derive), value enums for methods,
//! units and delimiters, and the shared value parsers of `--fix`, `--bounds` and `--weight`
//! (`subfric_app::flags`, which the Python package uses too), so that a malformed option is a
//! usage error naming the flag before anything runs.

use clap::{Args, Parser, Subcommand, ValueEnum};
use std::path::PathBuf;
use subfric_app::flags::{
    conflicts, parse_bound, parse_count, parse_fix, parse_hours, parse_param, parse_weight,
};
use subfric_data::{ColumnRef, ControlColumn, Delimiter, LengthUnit, StressUnit, TimeUnit};
use subfric_fit::{Method, Param};
use subfric_model::MAX_SCENARIO_ROWS;

use crate::progress::ProgressMode;

/// The command line.
#[derive(Parser, Debug)]
#[command(
    name = "subfric",
    bin_name = "subfric",
    version,
    about = "Calibrate the subloading-friction model of sand–metal interfaces and diagnose the sim-to-real gap"
)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Fit every set of experiments/ and write Tables 1–4, plots and a summary under fits/.
    Reproduce(ReproduceArgs),
    /// Simulate every test of a set (or a scenario) with given parameters.
    Simulate(SimulateArgs),
    /// Validate a set, print a summary of its tests and warn about implausible data.
    Check(CheckArgs),
    /// Turn a laboratory export into a test of a set in the data format.
    Import(ImportArgs),
    /// Calibrate μ_s, μ_k, κ, ξ, ũ (or chosen parameters) against one or several sets.
    Fit(FitArgs),
    /// Overlay plots of a set: measured, published, and a fit.
    Plot(PlotArgs),
    /// Where the calibrated model misses, which unmodelled effect explains it, how far it shrinks.
    Diagnose(DiagnoseArgs),
    /// Check the diagnosis on generated sets with withheld effects (or on a folder with truth.json).
    Selfcheck(SelfcheckArgs),
    /// Which test to run next: proposals ranked by how far they determine what the data do not.
    Plan(PlanArgs),
    /// Speed of the model step, of each paper fit, of multi-start scaling, of diagnoses and of the posterior sampler.
    Bench(BenchArgs),
    /// Fit (and diagnose) many sets at once, locally or as a Slurm job array, into one table.
    Campaign(crate::campaign::CampaignArgs),
}

/// `subfric reproduce`.
#[derive(Args, Debug)]
pub struct ReproduceArgs {
    /// Folder of experiment sets.
    #[arg(long, default_value = "experiments")]
    pub experiments: PathBuf,
    /// Output folder (subfric's own: results in it are replaced when they come from the same sets).
    #[arg(long, default_value = "fits")]
    pub out: PathBuf,
    /// Seed of the optimiser.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Replace results in the output folder that came from other sets (or not from subfric).
    #[arg(long)]
    pub force: bool,
    /// Progress display on stderr.
    #[arg(long, value_enum, default_value_t = ProgressMode::Auto)]
    pub progress: ProgressMode,
}

/// `subfric simulate`.
#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// Set folder [default: none: give --scenario instead].
    #[arg(conflicts_with = "scenario", required_unless_present = "scenario")]
    pub set: Option<PathBuf>,
    /// Parameters: params.json, a fit.json, or an experiment.json with reference_parameters.
    #[arg(long)]
    pub params: PathBuf,
    /// Declarative scenario JSON instead of a set [default: none: simulate the set].
    #[arg(long)]
    pub scenario: Option<PathBuf>,
    /// Output folder: a new set in the same format (never the set simulated).
    #[arg(long)]
    pub out: PathBuf,
    /// Replace a set already in the output folder (its old CSVs are removed).
    #[arg(long)]
    pub force: bool,
    /// Most rows a scenario may generate (it is refused beyond, before any is generated).
    #[arg(long, default_value_t = MAX_SCENARIO_ROWS)]
    pub max_rows: usize,
    /// Progress display on stderr (accepted for a uniform command line; a simulation is quick).
    #[arg(long, value_enum, default_value_t = ProgressMode::Auto)]
    pub progress: ProgressMode,
}

/// `subfric check`.
#[derive(Args, Debug)]
pub struct CheckArgs {
    /// Set folder.
    pub set: PathBuf,
    /// Progress display on stderr (accepted for a uniform command line; a check is quick).
    #[arg(long, value_enum, default_value_t = ProgressMode::Auto)]
    pub progress: ProgressMode,
}

/// Which column the apparatus imposed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ControlArg {
    /// Slip imposed, shear measured.
    Slip,
    /// Shear imposed, slip measured.
    Shear,
}

impl From<ControlArg> for ControlColumn {
    fn from(c: ControlArg) -> ControlColumn {
        match c {
            ControlArg::Slip => ControlColumn::Slip,
            ControlArg::Shear => ControlColumn::Shear,
        }
    }
}

/// Unit of a time column.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TimeUnitArg {
    /// seconds
    #[value(alias = "sec", alias = "second", alias = "seconds")]
    S,
    /// minutes
    #[value(alias = "minute", alias = "minutes")]
    Min,
    /// hours
    #[value(alias = "hr", alias = "hour", alias = "hours")]
    H,
    /// milliseconds
    #[value(alias = "millisecond", alias = "milliseconds")]
    Ms,
}

impl From<TimeUnitArg> for TimeUnit {
    fn from(u: TimeUnitArg) -> TimeUnit {
        match u {
            TimeUnitArg::S => TimeUnit::S,
            TimeUnitArg::Min => TimeUnit::Min,
            TimeUnitArg::H => TimeUnit::H,
            TimeUnitArg::Ms => TimeUnit::Ms,
        }
    }
}

/// Unit of a slip column.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LengthUnitArg {
    /// millimetres
    Mm,
    /// micrometres
    #[value(alias = "µm", alias = "μm", alias = "micron", alias = "microns")]
    Um,
    /// metres
    M,
    /// inches
    #[value(alias = "inch", alias = "inches")]
    In,
}

impl From<LengthUnitArg> for LengthUnit {
    fn from(u: LengthUnitArg) -> LengthUnit {
        match u {
            LengthUnitArg::Mm => LengthUnit::Mm,
            LengthUnitArg::Um => LengthUnit::Um,
            LengthUnitArg::M => LengthUnit::M,
            LengthUnitArg::In => LengthUnit::In,
        }
    }
}

/// Unit of a stress column, or of a force column divided by `--area`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum StressUnitArg {
    /// kilopascals
    #[value(name = "kPa")]
    KPa,
    /// megapascals
    #[value(name = "MPa")]
    MPa,
    /// pascals
    #[value(name = "Pa")]
    Pa,
    /// pounds per square inch
    Psi,
    /// newtons: a force, divided by --area
    #[value(name = "N")]
    N,
    /// kilonewtons: a force, divided by --area
    #[value(name = "kN")]
    KN,
    /// pounds-force: a force, divided by --area
    Lbf,
}

impl From<StressUnitArg> for StressUnit {
    fn from(u: StressUnitArg) -> StressUnit {
        match u {
            StressUnitArg::KPa => StressUnit::KPa,
            StressUnitArg::MPa => StressUnit::MPa,
            StressUnitArg::Pa => StressUnit::Pa,
            StressUnitArg::Psi => StressUnit::Psi,
            StressUnitArg::N => StressUnit::N,
            StressUnitArg::KN => StressUnit::KN,
            StressUnitArg::Lbf => StressUnit::Lbf,
        }
    }
}

/// Cell delimiter of a lab file.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DelimiterArg {
    /// `,`
    #[value(alias = "csv", alias = ",")]
    Comma,
    /// tab
    #[value(alias = "tsv", alias = "\\t", alias = "\t")]
    Tab,
    /// runs of spaces or tabs
    #[value(alias = "space", alias = "ws", alias = " ")]
    Whitespace,
    /// `;` (a decimal comma is then accepted)
    #[value(alias = ";")]
    Semicolon,
    /// detected from the header line: tab, then `;`, then `,`, else whitespace
    Auto,
}

impl From<DelimiterArg> for Delimiter {
    fn from(d: DelimiterArg) -> Delimiter {
        match d {
            DelimiterArg::Comma => Delimiter::Comma,
            DelimiterArg::Tab => Delimiter::Tab,
            DelimiterArg::Whitespace => Delimiter::Whitespace,
            DelimiterArg::Semicolon => Delimiter::Semicolon,
            DelimiterArg::Auto => Delimiter::Auto,
        }
    }
}

/// `NAME=COLUMN` of `--channel`.
fn parse_channel(s: &str) -> Result<(String, ColumnRef), String> {
    let (name, col) = s
        .split_once('=')
        .ok_or_else(|| format!("`{s}` is not NAME=COLUMN (expected e.g. normal_disp_mm=\"Vertical (mm)\" or normal_disp_mm=5)"))?;
    let col: ColumnRef = col.parse()?;
    Ok((name.trim().to_string(), col))
}

/// `subfric import`.
#[derive(Args, Debug)]
pub struct ImportArgs {
    /// Lab file.
    pub file: PathBuf,
    /// Output set folder (created, or the test is added to it; nothing in it is overwritten).
    #[arg(long)]
    pub out: PathBuf,
    /// Time column (header name or 1-based index).
    #[arg(long, default_value = "time_s")]
    pub time: ColumnRef,
    /// Unit of time.
    #[arg(long, value_enum, ignore_case = true, default_value = "s")]
    pub time_unit: TimeUnitArg,
    /// Slip column.
    #[arg(long, default_value = "slip_mm")]
    pub slip: ColumnRef,
    /// Unit of slip.
    #[arg(long, value_enum, ignore_case = true, default_value = "mm")]
    pub slip_unit: LengthUnitArg,
    /// Shear column [default: shear_kpa, unless --friction is given].
    #[arg(long)]
    pub shear: Option<ColumnRef>,
    /// Unit of shear (a force unit needs --area).
    #[arg(long, value_enum, ignore_case = true, default_value = "kPa")]
    pub shear_unit: StressUnitArg,
    /// Friction (shear/normal) column [default: none].
    #[arg(long)]
    pub friction: Option<ColumnRef>,
    /// Normal stress column [default: none: give --normal-stress].
    #[arg(long, conflicts_with = "normal_stress")]
    pub normal: Option<ColumnRef>,
    /// Unit of the normal column (a force unit needs --area).
    #[arg(long, value_enum, ignore_case = true, default_value = "kPa")]
    pub normal_unit: StressUnitArg,
    /// Constant normal stress [kPa] when there is no normal column [default: none].
    #[arg(long)]
    pub normal_stress: Option<f64>,
    /// Contact area [mm²] that a force column (--shear-unit or --normal-unit N, kN, lbf) is
    /// divided by, e.g. 3600 for a 60 mm square shear box [default: none: stresses only].
    #[arg(long, value_name = "MM2")]
    pub area: Option<f64>,
    /// Which column the apparatus imposed.
    #[arg(long, value_enum, default_value_t = ControlArg::Slip)]
    pub control: ControlArg,
    /// Cell delimiter.
    #[arg(long, value_enum, ignore_case = true, default_value = "auto")]
    pub delimiter: DelimiterArg,
    /// Lines to skip before the header (a header block of specimen, date, operator…).
    #[arg(long, default_value_t = 0)]
    pub skip: usize,
    /// The file has no header line (columns by index).
    #[arg(long)]
    pub no_header: bool,
    /// Keep one stretch of the record, read on time [s] or slip [mm] after the units are
    /// converted: `time=120:` trims off an aborted stage before 120 s, `slip=:9.5` the
    /// end-of-travel drop of a shear box (cut where the slip first passes 9.5 mm). The test's
    /// comments say which lines went [default: every row].
    #[arg(long, value_name = "COLUMN=FROM:TO")]
    pub keep: Option<subfric_data::Keep>,
    /// How the file is laid out: `gds` maps a GDS export's channels by their names (the
    /// `.ini` channel file, or the tabular GDSLAB export) and the column options above are
    /// not used; `delimited` reads the columns named; `auto` tells them apart.
    #[arg(long, default_value = "auto", value_name = "auto|delimited|gds")]
    pub format: subfric_data::ImportFormat,
    /// The stage to keep, by number or name, when the file holds several (a `stage` or
    /// `Stage Number` column, a GDS file's stages) [default: the stage with the longest shear
    /// travel, said].
    #[arg(long)]
    pub stage: Option<String>,
    /// A further channel to carry with the test, `NAME=COLUMN` (header name or 1-based
    /// index), in the unit its name states: normal_disp_mm, temperature_c, shear_force_kn,
    /// normal_force_kn, area_mm2. Repeatable [default: none].
    #[arg(long = "channel", value_name = "NAME=COLUMN", value_parser = parse_channel)]
    pub channels: Vec<(String, ColumnRef)>,
    /// Unit of a GDS file's rate of shear displacement when the file states none (the time
    /// is then the displacement over the rate), e.g. mm/min [default: none: the file's own, or
    /// the file is refused when it states none].
    #[arg(long, value_name = "LENGTH/TIME")]
    pub rate_unit: Option<subfric_data::RateUnit>,
    /// Test name.
    #[arg(long, default_value = "test")]
    pub test_name: String,
    /// Set name, for a new set [default: the --out folder's name].
    #[arg(long)]
    pub set_name: Option<String>,
    /// Soil, for a new set [default: none].
    #[arg(long)]
    pub soil: Option<String>,
    /// Surface, for a new set [default: none].
    #[arg(long)]
    pub surface: Option<String>,
    /// Title, for a new set [default: the set name].
    #[arg(long)]
    pub title: Option<String>,
}

/// Local optimiser.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MethodArg {
    /// Levenberg–Marquardt least squares
    #[value(alias = "lm")]
    Lsq,
    /// Nelder–Mead simplex
    #[value(alias = "nelder-mead")]
    Nm,
}

impl From<MethodArg> for Method {
    fn from(m: MethodArg) -> Method {
        match m {
            MethodArg::Lsq => Method::Lsq,
            MethodArg::Nm => Method::NelderMead,
        }
    }
}

/// How the posterior's likelihood takes the residuals.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ResidualsArg {
    /// Correlated in time (real load cells): the noise variance inflated by the residuals'
    /// autocorrelation time, as the profile intervals do
    #[value(alias = "autocorrelated")]
    Correlated,
    /// Independent rows
    Independent,
}

impl From<ResidualsArg> for subfric_app::posterior::ResidualModel {
    fn from(r: ResidualsArg) -> Self {
        match r {
            ResidualsArg::Correlated => subfric_app::posterior::ResidualModel::Autocorrelated,
            ResidualsArg::Independent => subfric_app::posterior::ResidualModel::Independent,
        }
    }
}

/// `subfric fit`.
#[derive(Args, Debug)]
pub struct FitArgs {
    /// Set folders (several: a joint fit sharing parameters).
    #[arg(required = true)]
    pub sets: Vec<PathBuf>,
    /// Only these tests, comma separated [default: all tests].
    #[arg(long, value_delimiter = ',')]
    pub tests: Vec<String>,
    /// Free parameters, comma separated (alpha_t and extension parameters may be added)
    /// [default: mu_s,mu_k,kappa,xi,u_tilde, less those given to --fix].
    #[arg(long, value_delimiter = ',', value_parser = parse_param)]
    pub free: Option<Vec<Param>>,
    /// Fixed values, key=value, comma separated [default: none].
    #[arg(long, value_delimiter = ',', value_parser = parse_fix, value_name = "KEY=VALUE")]
    pub fix: Vec<(Param, f64)>,
    /// Bounds of free parameters in their own units, key=lo:hi, comma separated [default: none].
    #[arg(long, value_delimiter = ',', value_parser = parse_bound, value_name = "KEY=LO:HI")]
    pub bounds: Vec<(Param, f64, f64)>,
    /// Relative test weights, name=w with w from 1e-6 to 1e6, comma separated (scaled to a mean
    /// of 1 over the rows) [default: 1 for every test].
    #[arg(long, value_delimiter = ',', value_parser = parse_weight, value_name = "TEST=W")]
    pub weight: Vec<(String, f64)>,
    /// Local method.
    #[arg(long, value_enum, default_value_t = MethodArg::Lsq)]
    pub method: MethodArg,
    /// Local starts.
    #[arg(long, default_value_t = 8, value_parser = parse_count)]
    pub starts: usize,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Model runs of the global stage.
    #[arg(long, default_value_t = 3000)]
    pub global_evals: usize,
    /// Skip profile intervals.
    #[arg(long)]
    pub no_profiles: bool,
    /// After the fit, sample the posterior of the free parameters (docs/posterior.md): median
    /// and 95 % credible interval beside the profile intervals, the corner plot, 95 % bands on
    /// every test and the thinned chain (posterior-chain.csv); convergence judged on the
    /// parameters the fit determines, and said when not reached.
    #[arg(long)]
    pub posterior: bool,
    /// Prior file of the posterior, JSON or TOML (uniform, log-uniform, normal, log-normal per
    /// parameter) [default: uniform within the bounds, on the fit's scale].
    #[arg(long, requires = "posterior", value_name = "FILE")]
    pub priors: Option<PathBuf>,
    /// Budget of the posterior sampler, in model runs (it stops earlier once converged).
    #[arg(long, requires = "posterior", default_value_t = subfric_app::posterior::DEFAULT_MAX_EVALS, value_name = "N")]
    pub max_evals: usize,
    /// Residuals of the posterior's likelihood: correlated in time, as the profile intervals
    /// take them, or independent.
    #[arg(long, requires = "posterior", value_enum, default_value_t = ResidualsArg::Correlated)]
    pub residuals: ResidualsArg,
    /// Output folder [default: fits/<set name>].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Replace results in the output folder that came from another set (or not from subfric).
    #[arg(long)]
    pub force: bool,
    /// Progress display on stderr.
    #[arg(long, value_enum, default_value_t = ProgressMode::Auto)]
    pub progress: ProgressMode,
}

/// `subfric plot`.
#[derive(Args, Debug)]
pub struct PlotArgs {
    /// Set folder.
    pub set: PathBuf,
    /// Fitted parameters, fit.json or params.json [default: fits/<set name>/fit.json when it
    /// exists, else none: measured and published only].
    #[arg(long)]
    pub params: Option<PathBuf>,
    /// Output folder [default: fits/<set name>/plots].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Replace figures in the output folder that came from another set (or not from subfric).
    #[arg(long)]
    pub force: bool,
    /// Progress display on stderr.
    #[arg(long, value_enum, default_value_t = ProgressMode::Auto)]
    pub progress: ProgressMode,
}

/// `subfric diagnose`.
#[derive(Args, Debug)]
pub struct DiagnoseArgs {
    /// Set folder.
    pub set: PathBuf,
    /// Output folder for diagnosis.json and plots [default: fits/<set name>/diagnosis].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Replace results in the output folder that came from another set (or not from subfric).
    #[arg(long)]
    pub force: bool,
    /// Progress display on stderr.
    #[arg(long, value_enum, default_value_t = ProgressMode::Auto)]
    pub progress: ProgressMode,
    /// Leave this candidate form out (its name as in the report's list of forms; repeat the
    /// flag for several): is the effect still named through the family's other forms?
    /// [default: every form]
    #[arg(long, value_parser = known_form)]
    pub without_form: Vec<String>,
    /// Also try this registered effect family (`crates/model/src/terms`), one the diagnosis
    /// does not try by default because an artifact can mimic it (repeat for several; the
    /// names are listed in docs/diagnosis.md and by an unknown name's error)
    /// [default: none beyond the default library]
    #[arg(long, value_parser = known_family)]
    pub with_family: Vec<String>,
    /// Diagnose N times in all, at the seed and the N - 1 after it, and say whether the verdict
    /// moves with the fits' random start (each replicate is a whole diagnosis, without figures)
    #[arg(long, default_value_t = 1, value_parser = subfric_app::replicates::parse_count)]
    pub replicates: usize,
}

/// A registered family's name, as `--with-family` takes it.
fn known_family(s: &str) -> Result<String, String> {
    let names = subfric_diagnose::candidates::registered_family_names();
    if names.contains(&s) {
        Ok(s.to_string())
    } else {
        Err(format!(
            "unknown family `{s}` (expected one of: {})",
            names.join(", ")
        ))
    }
}

/// A candidate form's name, as `--without-form` takes it.
fn known_form(s: &str) -> Result<String, String> {
    let names = subfric_diagnose::candidates::all_form_names();
    if names.contains(&s) {
        Ok(s.to_string())
    } else {
        Err(format!(
            "no candidate form is called {s:?}; the forms are: {}",
            names
                .iter()
                .map(|n| format!("{n:?}"))
                .collect::<Vec<_>>()
                .join(", ")
        ))
    }
}

/// `subfric plan`.
#[derive(Args, Debug)]
pub struct PlanArgs {
    /// Set folder.
    pub set: PathBuf,
    /// Output folder for plan.json, plan.txt, scenarios/ and the figure [default: fits/<set name>/plan].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Seed of the fits and of the simulated check's noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// How many of the top proposals to check by fitting a simulated joint campaign.
    #[arg(long, default_value_t = 1)]
    pub check: usize,
    /// Lab time of a new test beyond its duration (specimen, set-up) [h].
    #[arg(long, default_value_t = 0.5, value_parser = parse_hours)]
    pub setup_hours: f64,
    /// Plan on the model of this diagnosis.json [default: fits/<set name>/diagnosis/diagnosis.json
    /// when it exists and is of this set folder, else the base model].
    #[arg(long)]
    pub diagnosis: Option<PathBuf>,
    /// Replace results in the output folder that came from another set (or not from subfric).
    #[arg(long)]
    pub force: bool,
    /// Progress display on stderr.
    #[arg(long, value_enum, default_value_t = ProgressMode::Auto)]
    pub progress: ProgressMode,
}

/// What tests a generated set holds (`selfcheck --layout`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LayoutArg {
    /// Velocity steps, slide-hold-slide, two-way cycles and monotonic tests at several normal
    /// stresses.
    Mixed,
    /// A direct-shear programme: monotonic tests at three or four normal stresses through the
    /// peak to the residual on a soft rig (only pressure, slip-hardening and load-cell classes).
    DirectShear,
    /// A direct-shear programme of dense sand whose curves follow the geotechnical
    /// literature's empirical laws, not the model (Bolton's peak, a saturating rise,
    /// exponential softening): class 1 the shape alone, class 2 pressure.
    DenseSand,
}

impl From<LayoutArg> for subfric_app::selfcheck::Layout {
    fn from(a: LayoutArg) -> Self {
        match a {
            LayoutArg::Mixed => subfric_app::selfcheck::Layout::Mixed,
            LayoutArg::DirectShear => subfric_app::selfcheck::Layout::DirectShear,
            LayoutArg::DenseSand => subfric_app::selfcheck::Layout::DenseSand,
        }
    }
}

/// `subfric selfcheck`.
#[derive(Args, Debug)]
pub struct SelfcheckArgs {
    /// Sets per class (set k of class c is recorded with profile c + k in turn: lab, clean,
    /// logger, rig).
    #[arg(long, default_value_t = 2, value_parser = parse_count)]
    pub per_class: usize,
    /// Seed: of the generated sets [default: 7]; with --sets, of the diagnoses, as
    /// `diagnose --seed` takes it [default: 1]
    #[arg(long)]
    pub seed: Option<u64>,
    /// Score the sets of this folder against its truth.json [default: generate sets].
    #[arg(long)]
    pub sets: Option<PathBuf>,
    /// Write the scores as JSON to this file [default: none].
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Write the generated sets (a folder per set and a truth.json, which `selfcheck --sets`
    /// scores) to this new folder, and stop: nothing is diagnosed [default: none].
    #[arg(long, alias = "write-sets", conflicts_with_all = ["sets", "json", "unlisted"])]
    pub write: Option<PathBuf>,
    /// Only these classes (1-based numbers, comma separated; `--list-classes` prints them)
    /// [default: all].
    #[arg(long, value_delimiter = ',')]
    pub classes: Vec<usize>,
    /// What tests each generated set holds.
    #[arg(long, value_enum, default_value_t = LayoutArg::Mixed, conflicts_with = "sets")]
    pub layout: LayoutArg,
    /// Print the numbered classes and stop.
    #[arg(long, conflicts_with_all = ["sets", "json", "write"])]
    pub list_classes: bool,
    /// Diagnose each generated set without the library forms its effects reduce to: is the
    /// family still named through its other forms? (generated sets only) [default: off]
    #[arg(long, conflicts_with = "sets")]
    pub unlisted: bool,
    /// Replace an existing --json file.
    #[arg(long)]
    pub force: bool,
}

/// `subfric bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    /// Folder of experiment sets (read by fits, multistart and sampler).
    #[arg(long, default_value = "experiments")]
    pub experiments: PathBuf,
    /// Run only these parts, comma-separated (the whole benchmark takes minutes; the step alone,
    /// seconds).
    #[arg(long, value_enum, value_delimiter = ',', default_values_t = BenchPartArg::all())]
    pub only: Vec<BenchPartArg>,
    /// Also time the model step against this peer script, run with python3 and alternated
    /// with ours round by round (the numba peer `../shared/peers/peer_numba.py`; pin the whole
    /// benchmark to one core with `taskset -c 0`) [default: none].
    #[arg(long, value_name = "SCRIPT")]
    pub peer: Option<PathBuf>,
    /// Also time a whole diagnosis of this set folder, from loading it to the verdict (a real
    /// record, e.g. `../shared/real-dev/psu_p446_till_gouge`); repeat for several [default:
    /// none].
    #[arg(long = "record", value_name = "SET")]
    pub records: Vec<PathBuf>,
}

/// A part of `subfric bench`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum BenchPartArg {
    /// The model step on one core.
    Step,
    /// One full fit of each set of --experiments.
    Fits,
    /// A multi-start fit on 1 thread and on all.
    Multistart,
    /// A fit of 10 000 short tests.
    ManyTests,
    /// Whole diagnoses of two generated sets.
    Diagnoses,
    /// The posterior sampler.
    Sampler,
}

impl BenchPartArg {
    /// Every part.
    pub fn all() -> Vec<BenchPartArg> {
        use BenchPartArg::*;
        vec![Step, Fits, Multistart, ManyTests, Diagnoses, Sampler]
    }

    /// The application's part.
    pub fn part(self) -> subfric_app::bench::BenchPart {
        use subfric_app::bench::BenchPart;
        match self {
            BenchPartArg::Step => BenchPart::Step,
            BenchPartArg::Fits => BenchPart::Fits,
            BenchPartArg::Multistart => BenchPart::Multistart,
            BenchPartArg::ManyTests => BenchPart::ManyTests,
            BenchPartArg::Diagnoses => BenchPart::Diagnoses,
            BenchPartArg::Sampler => BenchPart::Sampler,
        }
    }
}

/// Options that contradict each other, which clap cannot see value by value: a usage error
/// (exit code 2) naming both (see [`subfric_app::flags::conflicts`]).
pub fn check_conflicts(command: &Command) -> Result<(), clap::Error> {
    use clap::CommandFactory;
    if let Command::Fit(f) = command {
        conflicts(f.free.as_deref(), &f.fix, &f.bounds, &f.weight)
            .map_err(|msg| Cli::command().error(clap::error::ErrorKind::ArgumentConflict, msg))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn the_command_line_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn option_values_go_through_the_shared_parsers() {
        let cli = Cli::try_parse_from([
            "subfric",
            "fit",
            "s",
            "--fix",
            "kappa=2",
            "--bounds",
            "xi=1e-3:1",
            "--weight",
            "a=2",
            "--free",
            "mu_s,xi",
        ])
        .unwrap();
        let Command::Fit(f) = cli.command else {
            panic!("not a fit")
        };
        assert_eq!(f.fix, vec![(Param::Kappa, 2.0)]);
        assert_eq!(f.bounds, vec![(Param::Xi, 1e-3, 1.0)]);
        assert_eq!(f.weight, vec![("a".to_string(), 2.0)]);
        assert_eq!(f.free, Some(vec![Param::MuS, Param::Xi]));
        let e = Cli::try_parse_from(["subfric", "fit", "s", "--bounds", "kappa=-5:-1"])
            .unwrap_err()
            .to_string();
        assert!(e.contains("--bounds") && e.contains("> 0"), "{e}");
    }

    #[test]
    fn contradicting_options_are_usage_errors_naming_both() {
        let usage = |args: &[&str]| {
            let cli = Cli::try_parse_from(args).unwrap();
            let e = check_conflicts(&cli.command).unwrap_err();
            assert_eq!(e.exit_code(), 2);
            e.to_string()
        };
        let e = usage(&["subfric", "fit", "s", "--fix", "xi=0.1,xi=0.2"]);
        assert!(e.contains("xi=0.1") && e.contains("xi=0.2"), "{e}");
        let e = usage(&[
            "subfric", "fit", "s", "--free", "mu_s,xi", "--fix", "mu_s=0.4",
        ]);
        assert!(
            e.contains("--free mu_s") && e.contains("--fix mu_s=0.4"),
            "{e}"
        );
        let cli = Cli::try_parse_from(["subfric", "fit", "s", "--fix", "mu_s=0.4"]).unwrap();
        assert!(check_conflicts(&cli.command).is_ok());
        let e = Cli::try_parse_from([
            "subfric",
            "import",
            "f.csv",
            "--out",
            "o",
            "--normal",
            "N",
            "--normal-stress",
            "78.4",
        ])
        .unwrap_err();
        assert_eq!(e.exit_code(), 2);
        let e = e.to_string();
        assert!(
            e.contains("--normal") && e.contains("--normal-stress"),
            "{e}"
        );
        let e = Cli::try_parse_from(["subfric", "plan", "s", "--setup-hours", "NaN"]).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert!(e.to_string().contains("--setup-hours"), "{e}");
    }
}
