//! The campaign table: one row per set, sorted by its results folder's name, from the files in
//! the set's results folder (whoever wrote them: a local run, a Slurm array task, a Dask
//! worker) and the set's `experiment.json`. Nothing in it depends on when, where or how fast
//! the sets ran, so the same results give the same bytes.

use super::record::{part_key, read_inputs, PartRecord, PartStatus, SetRecord};
use super::run::set_dir;
use super::SetJob;
use crate::error_text;
use serde::Serialize;
use serde_json::Value;
use std::fmt::Write as _;
use subfric_data::meta::INTERFACE_NUMBERS;
use subfric_data::ExperimentMeta;
use subfric_fit::interval::short_number;

/// Where a set stands.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RowStatus {
    /// Fitted (and diagnosed when asked) for its inputs and options of today.
    Ok,
    /// Its fit or diagnosis failed (the error is in the row).
    Failed,
    /// No results yet.
    NotRun,
    /// Results for other inputs or options: the set changed since.
    OutOfDate,
}

impl RowStatus {
    /// As the table writes it.
    pub fn text(self) -> &'static str {
        match self {
            RowStatus::Ok => "ok",
            RowStatus::Failed => "failed",
            RowStatus::NotRun => "not run",
            RowStatus::OutOfDate => "out of date",
        }
    }
}

/// A parameter of a set's fit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParamCell {
    /// Key (`mu_s`, ...).
    pub name: String,
    /// Unit.
    pub unit: String,
    /// Fitted (or fixed) value.
    pub value: f64,
    /// Lower end of the 95 % profile interval (None: no interval).
    pub lo: Option<f64>,
    /// Upper end.
    pub hi: Option<f64>,
    /// The data set no lower bound (`lo` is the search's wall).
    pub lo_open: bool,
    /// The data set no upper bound.
    pub hi_open: bool,
    /// Identifiability in the words of `fit` (fit.json's `status`: determined, weakly determined, ...).
    pub status: String,
}

/// One row of the campaign table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Row {
    /// The set's results folder name (`sets/<set>`).
    pub set: String,
    /// The set's name in its experiment.json.
    pub name: Option<String>,
    /// The set's folder as the campaign gave it.
    pub folder: String,
    /// Where it stands.
    pub status: RowStatus,
    /// Why it failed, or what is missing.
    pub error: Option<String>,
    /// `interface.soil`.
    pub soil: Option<String>,
    /// `interface.d50_mm`.
    pub d50_mm: Option<f64>,
    /// `interface.surface`.
    pub surface: Option<String>,
    /// `interface.roughness_rmax_um`.
    pub roughness_rmax_um: Option<f64>,
    /// `interface.roughness_ra_um`.
    pub roughness_ra_um: Option<f64>,
    /// Normalised roughness R_max/D50 (R_max in µm over D50 in µm).
    pub rmax_over_d50: Option<f64>,
    /// The normal stresses of the tests fitted, distinct, ascending, kPa.
    pub normal_stresses_kpa: Vec<f64>,
    /// Rows fitted.
    pub rows: Option<usize>,
    /// Reduced χ² of the fit.
    pub reduced_chi2: Option<f64>,
    /// The fitted parameters with their intervals.
    pub parameters: Vec<ParamCell>,
    /// The diagnosis's verdict (effects named, `none` or `unexplained`), when diagnosed.
    pub verdict: Option<String>,
    /// The held-out shrink of the misfit the verdict's first effect gives (a fraction).
    pub held_out_shrink: Option<f64>,
    /// The probability that the verdict's effects are exactly the ones at work (the
    /// diagnosis's calibrated confidence), when diagnosed and judged.
    pub confidence: Option<f64>,
}

impl Row {
    /// A parameter by key.
    pub fn parameter(&self, name: &str) -> Option<&ParamCell> {
        self.parameters.iter().find(|p| p.name == name)
    }

    fn empty(job: &SetJob) -> Row {
        Row::not_run(job.id.clone(), job.folder.clone())
    }

    /// The row of set `set` (its folder `folder`) before anything is known of it.
    pub(super) fn not_run(set: String, folder: String) -> Row {
        Row {
            set,
            name: None,
            folder,
            status: RowStatus::NotRun,
            error: None,
            soil: None,
            d50_mm: None,
            surface: None,
            roughness_rmax_um: None,
            roughness_ra_um: None,
            rmax_over_d50: None,
            normal_stresses_kpa: Vec::new(),
            rows: None,
            reduced_chi2: None,
            parameters: Vec::new(),
            verdict: None,
            held_out_shrink: None,
            confidence: None,
        }
    }

    fn interface(&mut self, meta: &ExperimentMeta, job: &SetJob) {
        let i = &meta.interface;
        self.name = Some(meta.name.clone());
        self.soil = i.soil.clone();
        self.surface = i.surface.clone();
        self.roughness_rmax_um = i.roughness_rmax_um;
        self.d50_mm = i.number(INTERFACE_NUMBERS[0].0);
        self.roughness_ra_um = i.number(INTERFACE_NUMBERS[1].0);
        self.rmax_over_d50 = match (self.roughness_rmax_um, self.d50_mm) {
            (Some(r), Some(d)) if d > 0.0 => Some(r / (1000.0 * d)),
            _ => None,
        };
        let mut stresses: Vec<f64> = meta
            .tests
            .iter()
            .filter(|t| job.options.tests.is_empty() || job.options.tests.contains(&t.name))
            .map(|t| t.normal_stress_kpa)
            .collect();
        stresses.sort_by(f64::total_cmp);
        stresses.dedup();
        self.normal_stresses_kpa = stresses;
    }
}

/// How a recorded part compares with today's inputs and options.
fn part_status(record: Option<&PartRecord>, key: &str) -> (RowStatus, Option<String>) {
    match record {
        None => (RowStatus::NotRun, None),
        Some(r) if r.key != key => (RowStatus::OutOfDate, None),
        Some(r) if r.status == PartStatus::Failed => (RowStatus::Failed, r.error.clone()),
        Some(_) => (RowStatus::Ok, None),
    }
}

fn read_json(path: &std::path::Path) -> Result<Value, String> {
    let text = crate::folders::io::read_settings_text(path, "the results file")
        .map_err(|e| e.to_string())?;
    serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))
}

/// The row of set `job` of the campaign written to `out`.
pub fn row(out: &std::path::Path, job: &SetJob) -> Row {
    let mut row = Row::empty(job);
    let (meta, inputs) = match read_inputs(&job.dir) {
        Ok(x) => x,
        Err(e) => {
            row.status = RowStatus::Failed;
            row.error = Some(error_text(&e));
            return row;
        }
    };
    row.interface(&meta, job);
    let dir = set_dir(out, &job.id);
    let record = SetRecord::read(&dir);
    let fit_key = part_key("fit", &inputs, &job.options.fit_part());
    let (status, error) = part_status(record.as_ref().and_then(|r| r.fit.as_ref()), &fit_key);
    row.status = status;
    row.error = error;
    if status == RowStatus::Ok {
        if let Err(e) = read_json(&dir.join("fit.json")).map(|v| fit_cells(&mut row, &v)) {
            row.status = RowStatus::NotRun;
            row.error = Some(e);
        }
    }
    if row.status == RowStatus::Ok && job.options.diagnose {
        let key = part_key("diagnosis", &inputs, &job.options.diagnosis_part());
        let (status, error) = part_status(record.as_ref().and_then(|r| r.diagnosis.as_ref()), &key);
        row.status = status;
        row.error = error;
        if status == RowStatus::Ok {
            let file = dir.join("diagnosis").join("diagnosis.json");
            match read_json(&file) {
                Ok(v) => verdict_cells(&mut row, &v),
                Err(e) => {
                    row.status = RowStatus::NotRun;
                    row.error = Some(e);
                }
            }
        }
    }
    row
}

fn fit_cells(row: &mut Row, fit: &Value) {
    let report = &fit["report"];
    row.rows = report["rows"].as_u64().map(|r| r as usize);
    row.reduced_chi2 = report["reduced_chi2"].as_f64();
    for p in report["parameters"].as_array().into_iter().flatten() {
        let interval = &p["interval"];
        row.parameters.push(ParamCell {
            name: p["name"].as_str().unwrap_or_default().to_string(),
            unit: p["unit"].as_str().unwrap_or_default().to_string(),
            value: p["value"].as_f64().unwrap_or(f64::NAN),
            lo: interval["lo"].as_f64(),
            hi: interval["hi"].as_f64(),
            lo_open: interval["lo_open"].as_bool().unwrap_or(false),
            hi_open: interval["hi_open"].as_bool().unwrap_or(false),
            status: p["status"].as_str().unwrap_or_default().to_string(),
        });
    }
}

fn verdict_cells(row: &mut Row, d: &Value) {
    let verdict = &d["verdict"];
    let named: Vec<&str> = d["diagnosis"]["verdict"]["effects"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|e| e["effect"].as_str())
        .collect();
    row.verdict = if named.is_empty() {
        verdict["effect"].as_str().map(str::to_string)
    } else {
        Some(named.join(" + "))
    };
    row.held_out_shrink = verdict["held_out_shrink"].as_f64();
    row.confidence = verdict["confidence"].as_f64();
}

/// The parameters of the rows, in the order of the first row that has each.
pub fn parameter_names(rows: &[Row]) -> Vec<(String, String)> {
    let mut names: Vec<(String, String)> = Vec::new();
    for p in rows.iter().flat_map(|r| &r.parameters) {
        if !names.iter().any(|(n, _)| n == &p.name) {
            names.push((p.name.clone(), p.unit.clone()));
        }
    }
    names
}

/// A number as the CSV writes it: shortest text that reads back to the same double.
fn num(v: Option<f64>) -> String {
    v.filter(|x| x.is_finite())
        .map(|x| format!("{x}"))
        .unwrap_or_default()
}

fn stresses(v: &[f64]) -> String {
    v.iter()
        .map(|x| format!("{x}"))
        .collect::<Vec<_>>()
        .join(";")
}

/// `campaign.csv`: one row per set; a parameter `p` has the columns `p`, `p_lo`, `p_hi` (empty
/// where the data set no bound, or without an interval) and `p_status`. Written by the CSV
/// writer ([`subfric_data::csvio::text_of`]): a cell is quoted when it holds a comma, a quote or
/// a line break.
pub fn csv(rows: &[Row], diagnosed: bool) -> String {
    let params = parameter_names(rows);
    let mut head: Vec<String> = [
        "set",
        "name",
        "folder",
        "status",
        "soil",
        "d50_mm",
        "surface",
        "roughness_rmax_um",
        "roughness_ra_um",
        "rmax_over_d50",
        "normal_stresses_kpa",
        "rows",
        "reduced_chi2",
    ]
    .map(String::from)
    .to_vec();
    for (p, _) in &params {
        head.extend([
            p.clone(),
            format!("{p}_lo"),
            format!("{p}_hi"),
            format!("{p}_status"),
        ]);
    }
    if diagnosed {
        head.extend([
            "verdict".into(),
            "held_out_shrink".into(),
            "confidence".into(),
        ]);
    }
    head.push("error".into());
    let mut records = vec![head];
    for r in rows {
        let mut cells = vec![
            r.set.clone(),
            r.name.clone().unwrap_or_default(),
            r.folder.clone(),
            r.status.text().to_string(),
            r.soil.clone().unwrap_or_default(),
            num(r.d50_mm),
            r.surface.clone().unwrap_or_default(),
            num(r.roughness_rmax_um),
            num(r.roughness_ra_um),
            num(r.rmax_over_d50),
            stresses(&r.normal_stresses_kpa),
            r.rows.map(|n| n.to_string()).unwrap_or_default(),
            num(r.reduced_chi2),
        ];
        for (p, _) in &params {
            match r.parameter(p) {
                Some(c) => cells.extend([
                    num(Some(c.value)),
                    num(c.lo.filter(|_| !c.lo_open)),
                    num(c.hi.filter(|_| !c.hi_open)),
                    c.status.clone(),
                ]),
                None => cells.extend([String::new(), String::new(), String::new(), String::new()]),
            }
        }
        if diagnosed {
            cells.push(r.verdict.clone().unwrap_or_default());
            cells.push(num(r.held_out_shrink));
            cells.push(num(r.confidence));
        }
        cells.push(r.error.clone().unwrap_or_default());
        records.push(cells);
    }
    subfric_data::csvio::text_of(records)
}

/// A Markdown cell: one line, `|` escaped.
fn md(s: &str) -> String {
    s.replace('\r', "")
        .split('\n')
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect::<Vec<_>>()
        .join(" ")
        .replace('|', "\\|")
}

fn md_num(v: Option<f64>) -> String {
    v.filter(|x| x.is_finite())
        .map(short_number)
        .unwrap_or_default()
}

/// A parameter as the Markdown table shows it: value and interval, with open ends marked as
/// `fit.txt` marks them and the status when only weakly determined. A parameter the data do
/// not determine is never shown as a number (the optimiser's point is one point of a flat
/// valley): "not determined (≤ b)", "(≥ a)" or "(any value)", as `fit` says it.
fn md_param(c: &ParamCell) -> String {
    if c.status.starts_with("not determined") {
        // fit.json's status names (subfric_fit::Status).
        return match (c.status.as_str(), c.lo, c.hi) {
            ("not determined (upper bound only)", _, Some(hi)) => {
                format!("not determined (≤ {})", short_number(hi))
            }
            ("not determined (lower bound only)", Some(lo), _) => {
                format!("not determined (≥ {})", short_number(lo))
            }
            ("not determined", _, _) => "not determined (any value)".into(),
            (other, _, _) => other.to_string(),
        };
    }
    let mut s = short_number(c.value);
    if let (Some(lo), Some(hi)) = (c.lo, c.hi) {
        let _ = write!(
            s,
            " {}{}, {}{}",
            if c.lo_open { "(≤" } else { "[" },
            short_number(lo),
            short_number(hi),
            if c.hi_open { "≥)" } else { "]" }
        );
    }
    if c.status != "determined" {
        let _ = write!(s, " {}", c.status.replace('-', " "));
    }
    s
}

/// Symbols of the parameters in the Markdown header.
fn symbol(name: &str) -> &str {
    match name {
        "mu_s" => "μ_s",
        "mu_k" => "μ_k",
        "kappa" => "κ",
        "xi" => "ξ",
        "u_tilde" => "ũ",
        "alpha_t" => "α_t",
        other => other,
    }
}

/// The sentence under a campaign table's title: how many sets stand where.
pub(super) fn counts(rows: &[Row]) -> String {
    let count = |st: RowStatus| rows.iter().filter(|r| r.status == st).count();
    format!(
        "{} sets: {} ok, {} failed, {} not run, {} out of date.",
        rows.len(),
        count(RowStatus::Ok),
        count(RowStatus::Failed),
        count(RowStatus::NotRun),
        count(RowStatus::OutOfDate)
    )
}

/// How to read a campaign table (`code` between backticks).
pub(super) const TABLE_LEGEND: &str = "Each parameter: the fitted value and its 95 % profile interval; `(≤a` or `b≥)` marks an end \
     the data do not bound (the search's wall), and the identifiability follows when the \
     parameter is only weakly determined. A parameter the data do not determine shows the \
     bound they set (`not determined (≤ b)`) and no value: any smaller value fits as well. R_max/D50: R_max over D50, both in µm. σ_n: the normal \
     stresses of the tests fitted. Misfit: the mean square of the residual over the noise variance \
     estimated from the data (1 = the model follows the data to within their noise), as every \
     report of subfric says it. Every number here is in `campaign.csv` at full precision.";

/// The header of a campaign table.
pub(super) fn header(rows: &[Row], diagnosed: bool) -> Vec<String> {
    let mut head = vec![
        "set".to_string(),
        "soil".into(),
        "D50 (mm)".into(),
        "surface".into(),
        "R_max (µm)".into(),
        "R_max/D50".into(),
        "σ_n (kPa)".into(),
    ];
    for (p, unit) in &parameter_names(rows) {
        head.push(if unit.is_empty() {
            symbol(p).to_string()
        } else {
            format!("{} ({unit})", symbol(p))
        });
    }
    head.push("misfit (× noise variance)".into());
    if diagnosed {
        head.push("verdict".into());
    }
    head.push("status".into());
    head
}

/// The cells of one row of a campaign table, texts passed through `text` (Markdown's escape,
/// or none for a page that escapes them itself).
pub(super) fn cells(
    r: &Row,
    rows: &[Row],
    diagnosed: bool,
    text: &dyn Fn(&str) -> String,
) -> Vec<String> {
    let mut cells = vec![
        text(&r.set),
        text(r.soil.as_deref().unwrap_or_default()),
        md_num(r.d50_mm),
        text(r.surface.as_deref().unwrap_or_default()),
        md_num(r.roughness_rmax_um),
        md_num(r.rmax_over_d50),
        r.normal_stresses_kpa
            .iter()
            .map(|x| format!("{x}"))
            .collect::<Vec<_>>()
            .join(", "),
    ];
    for (p, _) in &parameter_names(rows) {
        cells.push(r.parameter(p).map(md_param).unwrap_or_default());
    }
    cells.push(md_num(r.reduced_chi2));
    if diagnosed {
        cells.push(match &r.verdict {
            Some(v) => verdict_cell(&text(v), r.held_out_shrink, r.confidence),
            None => String::new(),
        });
    }
    cells.push(r.status.text().to_string());
    cells
}

/// A verdict in a campaign's Markdown or HTML table: led by the word its confidence earns
/// (as `diagnose` leads its verdict: "probably", "uncertain:"), then the held-out misfit its
/// first effect removes and how sure.
fn verdict_cell(verdict: &str, held_out_shrink: Option<f64>, confidence: Option<f64>) -> String {
    use subfric_diagnose::confidence::Standing;
    let lead = match confidence.map(Standing::of) {
        Some(Standing::Probable) => format!("probably {verdict}"),
        Some(Standing::Uncertain) => format!("uncertain: {verdict}"),
        None | Some(Standing::Confident) => verdict.to_string(),
    };
    let mut notes = Vec::new();
    if let Some(h) = held_out_shrink.filter(|h| *h > 0.0) {
        notes.push(format!("held-out misfit −{:.0} %", 100.0 * h));
    }
    if let Some(c) = confidence {
        notes.push(format!("how sure {:.0} %", 100.0 * c));
    }
    if notes.is_empty() {
        lead
    } else {
        format!("{lead} ({})", notes.join("; "))
    }
}

/// Why a set has no results, in words.
pub(super) fn why_incomplete(r: &Row) -> String {
    match (r.status, &r.error) {
        (_, Some(e)) => e.clone(),
        (RowStatus::NotRun, None) => "no results yet (run the campaign, or its array task)".into(),
        (RowStatus::OutOfDate, None) => {
            "its inputs or options changed since its results were written (run it again)".into()
        }
        _ => String::new(),
    }
}

/// `campaign.md`: the table to read, then the sets that failed or are missing, with why.
pub fn markdown(title: &str, rows: &[Row], diagnosed: bool) -> String {
    let mut s = format!("# Campaign {}\n\n", md(title));
    let _ = writeln!(s, "{}\n", counts(rows));
    s.push_str(TABLE_LEGEND);
    s.push_str("\n\n");
    let head = header(rows, diagnosed);
    let _ = writeln!(s, "| {} |", head.join(" | "));
    let _ = writeln!(s, "|{}", "---|".repeat(head.len()));
    for r in rows {
        let _ = writeln!(s, "| {} |", cells(r, rows, diagnosed, &md).join(" | "));
    }
    let problems: Vec<&Row> = rows.iter().filter(|r| r.status != RowStatus::Ok).collect();
    if !problems.is_empty() {
        s.push_str("\n## Sets without results\n\n");
        for r in problems {
            let _ = writeln!(
                s,
                "- `{}` ({}): {}",
                md(&r.set),
                r.status.text(),
                md(&why_incomplete(r))
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_verdict_cell_leads_with_how_sure_it_is() {
        assert_eq!(
            verdict_cell("rate", Some(0.88), Some(0.93)),
            "rate (held-out misfit −88 %; how sure 93 %)"
        );
        assert_eq!(
            verdict_cell("rate", Some(0.5), Some(0.7)),
            "probably rate (held-out misfit −50 %; how sure 70 %)"
        );
        assert_eq!(
            verdict_cell("unexplained", Some(0.0), Some(0.02)),
            "uncertain: unexplained (how sure 2 %)"
        );
        assert_eq!(verdict_cell("none", None, None), "none");
        // Read from diagnosis.json as `diagnose` writes it, and written to the CSV beside the
        // verdict.
        let mut row = Row {
            status: RowStatus::Ok,
            normal_stresses_kpa: vec![100.0],
            rows: Some(10),
            reduced_chi2: Some(1.0),
            ..Row::not_run("s".into(), String::new())
        };
        verdict_cells(
            &mut row,
            &serde_json::json!({
                "verdict": {"effect": "rate", "held_out_shrink": 0.5, "confidence": 0.25},
                "diagnosis": {"verdict": {"effects": [{"effect": "rate"}]}}
            }),
        );
        assert_eq!(row.confidence, Some(0.25));
        let text = csv(&[row], true);
        let mut lines = text.lines();
        let head: Vec<&str> = lines.next().unwrap().split(',').collect();
        let cells: Vec<&str> = lines.next().unwrap().split(',').collect();
        let at = head.iter().position(|h| *h == "confidence").unwrap();
        assert_eq!((head[at - 2], cells[at - 2]), ("verdict", "rate"));
        assert_eq!(cells[at], "0.25");
    }

    #[test]
    fn csv_cells_with_commas_quotes_and_lines_are_quoted() {
        // The cells as the table's CSV writer writes them.
        let cell = |s: &str| {
            let line = subfric_data::csvio::text_of([[s, "next"]]);
            line.strip_suffix(",next\n").unwrap_or(&line).to_string()
        };
        assert_eq!(cell("plain"), "plain");
        assert_eq!(cell("a,b"), "\"a,b\"");
        assert_eq!(cell("say \"x\"\nnext"), "\"say \"\"x\"\"\nnext\"");
        assert_eq!(md("a|b\n  c\n"), "a\\|b c");
    }

    #[test]
    fn numbers_read_back_exactly_and_open_ends_are_marked() {
        assert_eq!(num(Some(0.1 + 0.2)), "0.30000000000000004");
        assert_eq!(num(Some(f64::NAN)), "");
        let c = ParamCell {
            name: "mu_k".into(),
            unit: String::new(),
            value: 0.3032,
            lo: Some(1.683e-4),
            hi: Some(0.3033),
            lo_open: true,
            hi_open: false,
            status: "weakly determined".into(),
        };
        assert_eq!(md_param(&c), "0.3032 (≤1.683e-4, 0.3033] weakly determined");
        // Not determined: the bound the data set, never the optimiser's point.
        let reads = |status: &str, interval: bool| {
            md_param(&ParamCell {
                status: status.into(),
                lo: c.lo.filter(|_| interval),
                hi: c.hi.filter(|_| interval),
                ..c.clone()
            })
        };
        let cases = [
            (
                "not determined (upper bound only)",
                true,
                "not determined (≤ 0.3033)",
            ),
            (
                "not determined (lower bound only)",
                true,
                "not determined (≥ 1.683e-4)",
            ),
            ("not determined", false, "not determined (any value)"),
            (
                "not determined (the noise is not measured)",
                false,
                "not determined (the noise is not measured)",
            ),
        ];
        for (status, interval, expected) in cases {
            assert_eq!(reads(status, interval), expected, "{status}");
        }
    }
}
