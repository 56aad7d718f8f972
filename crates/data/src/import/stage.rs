//! The stages of a record. A stage column (`stage`, `Stage Number`; a GDS file's stages)
//! splits the rows, and one stage becomes the test: the one asked for (`--stage`), else the
//! one with the longest shear travel — a consolidation stage travels nowhere, an aborted
//! shear stage a little — and the choice is said, with every stage's rows and travel.

use std::path::Path;

use super::columns::Col;
use super::ImportSpec;
use crate::error::{DataError, InputProblem};
use crate::plausible::Warning;

/// Names a stage column goes by (compared without case, units or punctuation).
const STAGE_NAMES: [&str; 4] = ["stage", "stage number", "stage no", "stage nr"];

/// A header name without its unit (`(…)`, `[…]`), in lower case, with punctuation read as
/// spaces: `Stage Number`, `stage_number` and `STAGE-NUMBER (-)` all read `stage number`.
pub(super) fn plain_name(name: &str) -> String {
    let mut depth = 0usize;
    let mut s = String::new();
    for c in name.chars() {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' => depth = depth.saturating_sub(1),
            c if depth == 0 => s.push(if c.is_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                ' '
            }),
            _ => {}
        }
    }
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The stage column of a header, if it has one.
pub(super) fn column(names: &[String]) -> Option<usize> {
    names
        .iter()
        .position(|n| STAGE_NAMES.contains(&plain_name(n).as_str()))
}

/// A stage's label as written (`2.0` reads `2`).
pub(super) fn label_of(cell: &str) -> String {
    let c = cell.trim();
    match c.parse::<f64>() {
        Ok(x) if x.is_finite() && x.fract() == 0.0 && x.abs() < 1e15 => format!("{}", x as i64),
        _ => c.to_string(),
    }
}

/// Whether the stage labelled `label` is the one `wanted` names: the same label (any case),
/// the same number, or a label ending in that number (`Stage 2` for `2`).
fn matches(label: &str, wanted: &str) -> bool {
    let wanted = label_of(wanted);
    if label.eq_ignore_ascii_case(&wanted) {
        return true;
    }
    let trailing: String = label
        .chars()
        .rev()
        .take_while(char::is_ascii_digit)
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect();
    !trailing.is_empty() && label_of(&trailing) == wanted
}

/// Data records of a table, each with the place (line or value) it came from.
type Records = Vec<(usize, Vec<String>)>;

/// How a table is laid out, as the stages are read from it: its header's names, the line of
/// the header, what a record's place counts (`line`, or `value` of a list), and whether its
/// numbers may carry a decimal comma.
#[derive(Clone, Copy)]
pub(super) struct Layout<'a> {
    pub(super) names: &'a [String],
    pub(super) first_line: usize,
    pub(super) place: &'a str,
    pub(super) decimal_comma: bool,
}

/// One stage of the record: its label, its records' indices and its shear travel [mm].
struct Stage {
    label: String,
    rows: Vec<usize>,
    travel_mm: f64,
}

/// The records of the stage to keep, and the note saying which was kept and why; a record
/// without stages is returned as it is. `slip` is the slip column (its travel ranks the
/// stages), `place` what a record's place counts, `decimal_comma` whether its numbers may be
/// written with a decimal comma (cells not separated by commas).
pub(super) fn choose(
    lf: &Path,
    spec: &ImportSpec,
    layout: &Layout<'_>,
    slip: &Col,
    records: Records,
) -> Result<(Records, Option<Warning>), DataError> {
    let Layout {
        names,
        first_line,
        place,
        decimal_comma,
    } = *layout;
    let refuse = |msg: String| {
        DataError::Problems(vec![InputProblem::new(
            lf,
            Some(first_line),
            Some("stage"),
            msg,
        )])
    };
    let Some(col) = column(names) else {
        return match &spec.stage {
            Some(s) => Err(refuse(format!(
                "--stage {s} asked for, but the file has no stage column (expected a column named `stage` or `Stage Number`, or a GDS file with stages)"
            ))),
            None => Ok((records, None)),
        };
    };
    let mut stages = stages_of(&records, col);
    measure_travels(
        &mut stages,
        &records,
        slip,
        (spec.slip_unit.to_mm(), decimal_comma),
    );
    let listing = || listing(&stages);
    let (kept, why) = match &spec.stage {
        Some(wanted) => {
            match asked_stages(&stages, wanted)[..] {
                [k] => (k, format!("as asked (--stage {wanted})")),
                [] => {
                    return Err(refuse(format!(
                        "--stage {wanted} is not among the file's stages ({}) (expected one of their labels)",
                        listing()
                    )))
                }
                _ => {
                    return Err(refuse(format!(
                        "--stage {wanted} names more than one of the file's stages ({}) (expected a label that names one)",
                        listing()
                    )))
                }
            }
        }
        None if stages.len() == 1 => return Ok((records, None)),
        None => {
            // The longest travel; on a tie the later stage (a repeat follows what it repeats).
            let k = (0..stages.len()).fold(0, |best, k| {
                if stages[k].travel_mm >= stages[best].travel_mm {
                    k
                } else {
                    best
                }
            });
            (
                k,
                "the one with the longest shear travel (--stage keeps another)".to_string(),
            )
        }
    };
    let keep_rows: std::collections::HashSet<usize> = stages[kept].rows.iter().copied().collect();
    let message = kept_stage_message(
        &stages,
        kept,
        &why,
        spec.stage.is_none(),
        (&records, &keep_rows, place),
    );
    let note = Warning {
        file: lf.to_path_buf(),
        field: names[col].clone(),
        message,
    };
    let records = records
        .into_iter()
        .enumerate()
        .filter(|(i, _)| keep_rows.contains(i))
        .map(|(_, r)| r)
        .collect();
    Ok((records, Some(note)))
}

/// The stages of `records` by the labels of their stage column `col`, in the order they first
/// appear; a row whose stage cell the logger missed belongs to the stage it is in (rows before
/// any label to a stage without one).
fn stages_of(records: &Records, col: usize) -> Vec<Stage> {
    let mut stages: Vec<Stage> = Vec::new();
    let mut current: Option<usize> = None;
    for (i, (_, cells)) in records.iter().enumerate() {
        let cell = cells.get(col).map(String::as_str).unwrap_or("");
        let k = if crate::gaps::is_missing(cell) {
            current.unwrap_or(0)
        } else {
            let label = label_of(cell);
            match stages.iter().position(|s| s.label == label) {
                Some(k) => k,
                None => {
                    stages.push(Stage {
                        label,
                        rows: Vec::new(),
                        travel_mm: 0.0,
                    });
                    stages.len() - 1
                }
            }
        };
        if stages.is_empty() {
            stages.push(Stage {
                label: String::new(),
                rows: Vec::new(),
                travel_mm: 0.0,
            });
        }
        stages[k].rows.push(i);
        current = Some(k);
    }
    stages
}

/// Each stage's shear travel [mm]: the span of its slip column `slip` (in the unit that
/// `to_mm` converts), read as the rows are read — a decimal comma where the cells are not
/// comma-separated (`decimal_comma`).
fn measure_travels(
    stages: &mut [Stage],
    records: &Records,
    slip: &Col,
    (to_mm, decimal_comma): (f64, bool),
) {
    for s in stages {
        let slips: Vec<f64> = s
            .rows
            .iter()
            .filter_map(|&i| records[i].1.get(slip.0))
            .filter_map(|c| {
                let c = if decimal_comma && c.contains(',') && !c.contains('.') {
                    c.replace(',', ".")
                } else {
                    c.clone()
                };
                crate::set::parse_number(&c).ok()
            })
            .filter(|x| x.is_finite())
            .collect();
        let (lo, hi) = slips
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                (lo.min(x), hi.max(x))
            });
        s.travel_mm = if hi >= lo { (hi - lo) * to_mm } else { 0.0 };
    }
}

/// What the import says of the stage kept (`kept`, kept because `why`): every stage, the rows
/// left out (`records` less `keep_rows`, counted as `place`s), and, where the stage was chosen by
/// its travel (`chosen_by_travel`), the other stages that travel at least half as far — a
/// multi-stage test whose stages are tests of their own.
fn kept_stage_message(
    stages: &[Stage],
    kept: usize,
    why: &str,
    chosen_by_travel: bool,
    (records, keep_rows, place): (&Records, &std::collections::HashSet<usize>, &str),
) -> String {
    let longest = stages[kept].travel_mm;
    let rivals: Vec<&str> = stages
        .iter()
        .enumerate()
        .filter(|&(k, s)| k != kept && longest > 0.0 && s.travel_mm >= 0.5 * longest)
        .map(|(_, s)| s.label.as_str())
        .collect();
    let mut message = format!(
        "the record holds {} stages ({}); stage {} is kept, {why}, and the other stages' rows are left out",
        stages.len(),
        listing(stages),
        stages[kept].label
    );
    if !rivals.is_empty() && chosen_by_travel {
        message.push_str(&format!(
            "; stage{} {} travel{} at least half as far: a multi-stage test? (import each stage as its own test with --stage)",
            if rivals.len() == 1 { "" } else { "s" },
            rivals.join(", "),
            if rivals.len() == 1 { "s" } else { "" }
        ));
    }
    let left_out: Vec<usize> = (0..records.len())
        .filter(|i| !keep_rows.contains(i))
        .map(|i| records[i].0)
        .collect();
    if !left_out.is_empty() {
        message.push_str(&format!(
            " ({place}s {})",
            crate::gaps::describe_lines(&left_out)
        ));
    }
    message
}

/// The stages as a sentence names them: label, rows and travel of each.
fn listing(stages: &[Stage]) -> String {
    stages
        .iter()
        .map(|s| {
            format!(
                "{}: {} row{}, {} mm of slip",
                s.label,
                s.rows.len(),
                if s.rows.len() == 1 { "" } else { "s" },
                crate::text::short_number(s.travel_mm)
            )
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// The stages `--stage wanted` names: the label itself first; a label ending in the number only
/// when none is it.
fn asked_stages(stages: &[Stage], wanted: &str) -> Vec<usize> {
    let exact: Vec<usize> = (0..stages.len())
        .filter(|&k| stages[k].label.eq_ignore_ascii_case(&label_of(wanted)))
        .collect();
    if exact.is_empty() {
        (0..stages.len())
            .filter(|&k| matches(&stages[k].label, wanted))
            .collect()
    } else {
        exact
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stage_columns_are_found_whatever_their_spelling() {
        for n in [
            "Stage Number",
            "stage_number",
            "STAGE",
            "Stage No.",
            "stage nr (-)",
        ] {
            assert_eq!(column(&[n.to_string()]), Some(0), "{n}");
        }
        for n in ["Time since start of stage (s)", "stages", "backstage"] {
            assert_eq!(column(&[n.to_string()]), None, "{n}");
        }
    }

    #[test]
    fn a_stage_is_named_by_its_label_or_its_number() {
        assert!(matches("2", "2"));
        assert!(matches("2", "2.0"));
        assert!(matches("Stage 2", "2"));
        assert!(matches("Shear", "shear"));
        assert!(!matches("Stage 12", "2"));
        assert!(!matches("3", "2"));
    }
}
