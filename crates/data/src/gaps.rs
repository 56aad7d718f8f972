//! What the reader makes of a record as loggers write it: a sample the logger missed (an empty
//! cell, `NaN`, `NA`) leaves a gap — the row is left out, as rows may be unevenly spaced — and
//! a clock coarser than the sampling (one-second stamps at 10 Hz) repeats its stamps, whose
//! rows are spread evenly over their tick. Each is said in a note on the test (shown with the
//! plausibility warnings by `check`, `fit` and `diagnose`), never done silently.

use std::path::Path;

use crate::plausible::Warning;

/// Whether a cell stands for a sample the logger did not record: empty, or a missing-value
/// marker of spreadsheets and loggers (`NaN`, `NA`, `N/A`, any case). `inf` is not one: an
/// overflow is a corrupt cell, refused.
pub(crate) fn is_missing(cell: &str) -> bool {
    let c = cell.trim();
    c.is_empty()
        || c.eq_ignore_ascii_case("nan")
        || c.eq_ignore_ascii_case("na")
        || c.eq_ignore_ascii_case("n/a")
}

/// Lines as a short list of ranges ("5, 9–12 and 40"; the first few ranges and a count of the
/// rest when there are many).
pub(crate) fn describe_lines(lines: &[usize]) -> String {
    const SHOWN: usize = 6;
    let mut ranges: Vec<(usize, usize)> = Vec::new();
    for &l in lines {
        match ranges.last_mut() {
            Some((_, hi)) if *hi + 1 == l => *hi = l,
            _ => ranges.push((l, l)),
        }
    }
    let text = |&(lo, hi): &(usize, usize)| {
        if lo == hi {
            lo.to_string()
        } else {
            format!("{lo}–{hi}")
        }
    };
    let shown: Vec<String> = ranges.iter().take(SHOWN).map(text).collect();
    let rest = ranges.len().saturating_sub(SHOWN);
    match (shown.len(), rest) {
        (0, _) => String::new(),
        (1, 0) => shown[0].clone(),
        (n, 0) => format!("{} and {}", shown[..n - 1].join(", "), shown[n - 1]),
        (_, r) => format!(
            "{} and {r} more stretch{}",
            shown.join(", "),
            if r == 1 { "" } else { "es" }
        ),
    }
}

/// The note for rows left out as gaps: `gaps` holds each such row's line and the columns it
/// missed.
/// `place` is what a row's place counts (`line`, or `value` of a file of channel lists).
pub(crate) fn gap_note(path: &Path, gaps: &[(usize, Vec<String>)], place: &str) -> Option<Warning> {
    if gaps.is_empty() {
        return None;
    }
    let mut columns: Vec<&str> = gaps
        .iter()
        .flat_map(|(_, c)| c.iter().map(String::as_str))
        .collect();
    columns.sort_unstable();
    columns.dedup();
    let lines: Vec<usize> = gaps.iter().map(|g| g.0).collect();
    let n = gaps.len();
    Some(Warning {
        file: path.to_path_buf(),
        field: columns.join(", "),
        message: format!(
            "{n} row{s} without a value (an empty cell, NaN or NA) read as gap{s}, left out of the record: {place}{s} {} (a logger's missing sample; a row needs every column to be used)",
            describe_lines(&lines),
            s = if n == 1 { "" } else { "s" },
        ),
    })
}

/// What the reader made of a record, one note each: the rows left out as `gaps`, and the
/// repeated stamps of `time` spread over their tick (`time` changed in place; `lines` the
/// rows' places in the file, each a `place`: a line, or a value of a file of channel lists).
pub(crate) fn reading_notes(
    path: &Path,
    gaps: &[(usize, Vec<String>)],
    time: &mut [f64],
    lines: &[usize],
    place: &str,
) -> Vec<Warning> {
    gap_note(path, gaps, place)
        .into_iter()
        .chain(spread_repeated_stamps(time, lines, path, place))
        .collect()
}

/// Spreads rows whose time stamps repeat evenly over their clock tick — a run of k rows stamped
/// t, followed by the next stamp t', takes t + j (t' − t) / k; a last run takes the tick before
/// it — and says so. Only where the stamps never go back and every repeated run has a tick to
/// spread over: a clock that goes back, or a single stamp, is left for validation to refuse.
/// `lines` are the rows' places in the file, each a `place` (a line, or a value of a list).
pub(crate) fn spread_repeated_stamps(
    time: &mut [f64],
    lines: &[usize],
    path: &Path,
    place: &str,
) -> Option<Warning> {
    let n = time.len();
    let finite = time.iter().all(|t| t.is_finite());
    let never_back = time.windows(2).all(|w| w[1] >= w[0]);
    let repeats = time.windows(2).any(|w| w[1] == w[0]);
    if !(finite && never_back && repeats) {
        return None;
    }
    // Runs of equal stamps: (first row, rows).
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut i = 0;
    while i < n {
        let mut j = i + 1;
        while j < n && time[j] == time[i] {
            j += 1;
        }
        runs.push((i, j - i));
        i = j;
    }
    let tick_after = |r: usize| -> Option<f64> {
        match runs.get(r + 1) {
            Some(&(next, _)) => Some(time[next] - time[runs[r].0]),
            None if r > 0 => Some(time[runs[r].0] - time[runs[r - 1].0]),
            None => None,
        }
    };
    let ticks: Vec<Option<f64>> = (0..runs.len()).map(tick_after).collect();
    if runs
        .iter()
        .zip(&ticks)
        .any(|(&(_, k), tick)| k > 1 && tick.is_none())
    {
        return None;
    }
    let mut repeated_lines = Vec::new();
    let mut smallest_tick = f64::INFINITY;
    for (&(first, k), tick) in runs.iter().zip(&ticks) {
        if k < 2 {
            continue;
        }
        let tick = tick.expect("checked above");
        smallest_tick = smallest_tick.min(tick);
        let t0 = time[first];
        for j in 1..k {
            time[first + j] = t0 + tick * j as f64 / k as f64;
            repeated_lines.push(lines.get(first + j).copied().unwrap_or(0));
        }
    }
    let m = repeated_lines.len();
    Some(Warning {
        file: path.to_path_buf(),
        field: "time_s".into(),
        message: format!(
            "time_s repeats its stamp on {m} row{s} ({place}{s} {}): a clock coarser than the sampling (a tick of {} s); the rows within a tick are spread evenly over it (expected time_s strictly increasing; a clock that goes back is refused)",
            describe_lines(&repeated_lines),
            crate::text::short_number(smallest_tick),
            s = if m == 1 { "" } else { "s" },
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn missing_markers_are_gaps_and_overflows_are_not() {
        for c in ["", "  ", "NaN", "nan", "NA", "n/a"] {
            assert!(is_missing(c), "{c:?}");
        }
        for c in ["inf", "0", "-", "x", "1e999"] {
            assert!(!is_missing(c), "{c:?}");
        }
    }

    #[test]
    fn lines_read_as_ranges() {
        assert_eq!(describe_lines(&[5]), "5");
        assert_eq!(describe_lines(&[5, 9, 10, 11, 12, 40]), "5, 9–12 and 40");
        let many: Vec<usize> = (0..10).map(|k| 10 * k).collect();
        assert_eq!(
            describe_lines(&many),
            "0, 10, 20, 30, 40, 50 and 4 more stretches"
        );
    }

    #[test]
    fn a_one_second_clock_at_four_hertz_is_spread_over_its_ticks() {
        // Stamps 0,0,0,0,1,1,1,1,2,2: the last run spreads over the tick before it.
        let mut t = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 2.0, 2.0];
        let lines: Vec<usize> = (2..12).collect();
        let w = spread_repeated_stamps(&mut t, &lines, Path::new("a.csv"), "line").expect("spread");
        assert_eq!(
            t,
            vec![0.0, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0, 2.5]
        );
        assert!(t.windows(2).all(|w| w[1] > w[0]));
        assert!(w.message.contains("on 7 rows"), "{}", w.message);
        assert!(w.message.contains("lines 3–5, 7–9 and 11"), "{}", w.message);
        assert_eq!(w.field, "time_s");
    }

    #[test]
    fn stamps_that_go_back_or_never_tick_are_left_for_validation() {
        let mut back = vec![0.0, 1.0, 1.0, 0.5];
        assert!(spread_repeated_stamps(&mut back, &[1, 2, 3, 4], Path::new("a"), "line").is_none());
        assert_eq!(back, vec![0.0, 1.0, 1.0, 0.5]);
        let mut one_stamp = vec![1.0, 1.0];
        assert!(spread_repeated_stamps(&mut one_stamp, &[1, 2], Path::new("a"), "line").is_none());
        let mut increasing = vec![0.0, 1.0, 2.0];
        assert!(
            spread_repeated_stamps(&mut increasing, &[1, 2, 3], Path::new("a"), "line").is_none()
        );
    }

    #[test]
    fn a_gap_note_names_the_columns_and_lines() {
        let gaps = vec![
            (4, vec!["shear_kpa".to_string()]),
            (5, vec!["shear_kpa".to_string(), "slip_mm".to_string()]),
        ];
        let w = gap_note(Path::new("a.csv"), &gaps, "line").expect("a note");
        assert_eq!(w.field, "shear_kpa, slip_mm");
        assert!(
            w.message.starts_with("2 rows without a value"),
            "{}",
            w.message
        );
        assert!(w.message.contains("lines 4–5"), "{}", w.message);
        assert!(gap_note(Path::new("a.csv"), &[], "line").is_none());
    }
}
