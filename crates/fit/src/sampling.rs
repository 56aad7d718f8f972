//! Keeping the global stage's cost bounded on large problems (issue 25, item 9).
//!
//! The global stage ranks the informed guesses and runs differential evolution: thousands of
//! model runs, each over every row. Its job is to find the basins the least-squares polish
//! starts from, which a share of the tests shows as well as all of them; the polish, the
//! uncertainty and the profiles then use every row. So on a problem of more than
//! [`GLOBAL_STAGE_ROWS`] rows the global stage works on an evenly spread share of the tests,
//! and the informed guesses are capped by the global budget: before, ten thousand tests of 39
//! rows gave 60 000 guesses of 390 000 rows each, and the fit's cost grew with the square of
//! the number of tests.

use subfric_model::Model;
use subfric_reading::FitTest;

/// Rows the global stage simulates per model run at most: above every set of the paper and of
/// a lab campaign after thinning (a few thousand rows), so their fits are unchanged; a problem
/// of more rows explores on a share of its tests.
pub const GLOBAL_STAGE_ROWS: usize = 20_000;

/// Fewest informed guesses evaluated whatever the global budget: the guesses of one
/// traction-controlled test (135), so `--global-evals 0` still starts from the curves.
pub const MIN_INFORMED_GUESSES: usize = 150;

/// Rows a model run of `t` simulates (up to its last counted row).
fn simulated_rows(t: &FitTest) -> usize {
    t.counted_rows().end
}

/// The tests the global stage explores on when `tests` simulate more than `max_rows` rows:
/// every k-th test (k the smallest stride that brings the rows within the limit), and the
/// first test of each control the stride missed, so every kind of test is seen. `None` when
/// the problem is within the limit: the global stage then uses every test, as before.
pub fn global_sample(tests: &[FitTest], max_rows: usize) -> Option<Vec<FitTest>> {
    let total: usize = tests.iter().map(simulated_rows).sum();
    if total <= max_rows || tests.len() < 2 {
        return None;
    }
    let stride = total.div_ceil(max_rows.max(1));
    let mut keep: Vec<usize> = (0..tests.len()).step_by(stride).collect();
    for (i, t) in tests.iter().enumerate() {
        if !keep.iter().any(|&k| tests[k].control == t.control) {
            keep.push(i);
        }
    }
    keep.sort_unstable();
    Some(keep.into_iter().map(|i| tests[i].clone()).collect())
}

/// How many informed guesses a calibration with a global budget of `global_evaluations`
/// model runs evaluates: at most the budget, and at least [`MIN_INFORMED_GUESSES`].
pub fn informed_guess_budget(global_evaluations: usize) -> usize {
    global_evaluations.max(MIN_INFORMED_GUESSES)
}

/// At most `max` of `guesses`, evenly spread over them (so over the tests they were read
/// from, in order); all of them when they are fewer.
pub fn spread(guesses: Vec<Model>, max: usize) -> Vec<Model> {
    let n = guesses.len();
    if n <= max {
        return guesses;
    }
    (0..max).map(|i| guesses[i * n / max]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use subfric_model::{Control, Params};

    fn test(name: &str, control: Control, rows: usize) -> FitTest {
        let time: Vec<f64> = (0..rows).map(|i| i as f64).collect();
        let x: Vec<f64> = time.iter().map(|t| 0.01 * t).collect();
        FitTest::new(name, control, time, x.clone(), x, vec![100.0; rows])
    }

    #[test]
    fn a_problem_within_the_limit_is_explored_whole() {
        let tests: Vec<FitTest> = (0..10)
            .map(|i| test(&i.to_string(), Control::Slip, 50))
            .collect();
        assert!(global_sample(&tests, 500).is_none());
        assert!(global_sample(&tests, 499).is_some());
    }

    #[test]
    fn a_large_problem_is_explored_on_a_spread_share_with_every_control() {
        let mut tests: Vec<FitTest> = (0..1000)
            .map(|i| test(&format!("s{i}"), Control::Slip, 39))
            .collect();
        tests.insert(501, test("shear", Control::Shear, 39));
        let s = global_sample(&tests, 2000).unwrap();
        let rows: usize = s.iter().map(|t| t.len()).sum();
        assert!(rows <= 2000 + 39, "{rows} rows");
        assert!(s.len() >= 40, "{} tests", s.len());
        assert!(s.iter().any(|t| t.control == Control::Shear));
        // Spread: from the start to the end of the set.
        assert_eq!(s[0].name, "s0");
        assert!(
            s.last()
                .unwrap()
                .name
                .trim_start_matches('s')
                .parse::<usize>()
                .unwrap()
                > 950
        );
    }

    #[test]
    fn guesses_beyond_the_budget_are_spread_over_all_of_them() {
        let m = Model::base(Params::sample()).unwrap();
        let guesses: Vec<Model> = (0..60_000)
            .map(|i| {
                let mut g = m;
                g.params.kappa = i as f64;
                g
            })
            .collect();
        let kept = spread(guesses, informed_guess_budget(3000));
        assert_eq!(kept.len(), 3000);
        assert_eq!(kept[0].params.kappa, 0.0);
        assert!(kept[2999].params.kappa >= 59_900.0);
        assert_eq!(informed_guess_budget(0), MIN_INFORMED_GUESSES);
        assert_eq!(spread(vec![m; 7], 150).len(), 7);
    }
}
