//! Checks of the data beyond its syntax: a test's numbers, and tests of a set repeating others.

use std::collections::HashMap;
use std::path::Path;

use super::{TestData, MAX_MAGNITUDE};
use crate::error::{InputProblem, Problems};

/// Tests of one set that hold the same rows (a CSV copied under another name, or one file
/// named by two tests): each is refused at its `file` in `experiment.json`, naming the test it
/// repeats. Its rows would count twice and every interval would be too narrow by √2.
pub(super) fn repeated_tests(
    tests: &[TestData],
    json: &Path,
    positions: &HashMap<String, (usize, usize)>,
) -> Vec<InputProblem> {
    let hashes: Vec<u64> = tests.iter().map(TestData::content_hash).collect();
    let mut problems = Vec::new();
    for (j, t) in tests.iter().enumerate() {
        if let Some(i) = (0..j).find(|&i| hashes[i] == hashes[j]) {
            let field = format!("tests[{j}].file");
            problems.push(InputProblem::new(
                json,
                positions.get(&field).map(|p| p.0),
                Some(&field),
                format!(
                    "test `{}` ({}) holds the same {} rows as test `{}` ({}), value for value: its rows would count twice and every interval would be too narrow by √2 (expected each measured test once: remove the copy)",
                    t.spec.name,
                    t.spec.file,
                    t.len(),
                    tests[i].spec.name,
                    tests[i].spec.file
                ),
            ));
        }
    }
    problems
}

/// Semantic checks of a test's numbers: all columns the same length, finite values, time
/// strictly increasing, positive normal stress. Used for loaded and imported tests alike.
pub(crate) fn validate_data(td: &TestData, normal_from_column: bool) -> Vec<InputProblem> {
    let mut pr = Problems::default();
    let path = td.path.as_path();
    let n = td.time_s.len();
    if n == 0 {
        pr.add(
            path,
            None,
            None,
            "the test has no data rows (expected at least one row of numbers)",
        );
        return pr.into_vec();
    }
    let lens = [
        td.slip_mm.len(),
        td.shear_kpa.len(),
        td.normal_kpa.len(),
        td.line_of_row.len(),
    ];
    if lens.iter().any(|&l| l != n) || td.channels.iter().any(|c| c.values.len() != n) {
        pr.add(
            path,
            None,
            None,
            format!("columns have different lengths {n}, {lens:?} (expected one value per row in every column)"),
        );
        return pr.into_vec();
    }
    let shear_name = if td.friction_given {
        "friction"
    } else {
        "shear_kpa"
    };
    for i in 0..n {
        let line = Some(td.line(i));
        // A constant normal stress is the description's, checked there once (not on each row).
        let columns = [
            ("time_s", td.time_s[i]),
            ("slip_mm", td.slip_mm[i]),
            (shear_name, td.shear_kpa[i]),
            ("normal_kpa", td.normal_kpa[i]),
        ];
        for (name, x) in columns
            .into_iter()
            .take(if normal_from_column { 4 } else { 3 })
        {
            if !x.is_finite() {
                pr.add(
                    path,
                    line,
                    Some(name),
                    format!(
                        "value {} is not finite (expected a finite number)",
                        crate::text::short_number(x)
                    ),
                );
            } else if x.abs() > MAX_MAGNITUDE {
                pr.add(
                    path,
                    line,
                    Some(name),
                    format!(
                        "value {x:e} is beyond ±{MAX_MAGNITUDE:e} (expected a measurement in s, mm or kPa: a corrupt cell?)"
                    ),
                );
            }
        }
        if i > 0 {
            let (a, b) = (td.time_s[i - 1], td.time_s[i]);
            if a.is_finite() && b.is_finite() && b <= a {
                pr.add(
                    path,
                    line,
                    Some("time_s"),
                    format!(
                        "time {b} is not after time {a} on line {} (expected time_s strictly increasing)",
                        td.line(i - 1)
                    ),
                );
            }
        }
        if normal_from_column {
            let x = td.normal_kpa[i];
            if x.is_finite() && x <= 0.0 {
                pr.add(
                    path,
                    line,
                    Some("normal_kpa"),
                    format!("normal stress {x} kPa is not positive (expected normal_kpa > 0)"),
                );
            }
        }
    }
    pr.into_vec()
}
