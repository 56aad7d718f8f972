//! The fast part of `subfric selfcheck`: sets generated with one withheld effect each (or none,
//! or a measurement drift no candidate models) are diagnosed without being told the effect.

use subfric_diagnose::selfcheck::{selfcheck, SelfcheckOptions};
use subfric_diagnose::synth::SynthOptions;
use subfric_diagnose::Effect;

#[test]
fn generated_sets_with_withheld_effects_are_named_right() {
    let opts = SelfcheckOptions {
        classes: Effect::ALL.to_vec(),
        per_class: 1,
        seed: 2024,
        // Coarser rows than a lab file (0.02 mm instead of 0.005 mm) keep the test fast.
        synth: SynthOptions {
            slip_per_row: 0.02,
            ..SynthOptions::default()
        },
        ..SelfcheckOptions::default()
    };
    let (cases, scores) = selfcheck(&opts, &|c| eprintln!("{c:?}"));
    eprintln!("{scores}");
    assert_eq!(cases.len(), Effect::ALL.len());
    assert_eq!(
        scores.false_alarms, 0,
        "an effect was named on a set without one"
    );
    assert!(
        scores.share_right >= 6.0 / 7.0,
        "named right: {:.2}",
        scores.share_right
    );
    let drift = cases
        .iter()
        .find(|c| c.truth == Effect::Unexplained)
        .unwrap();
    assert_eq!(
        drift.verdict,
        Effect::Unexplained,
        "a drift no candidate models must not be named an effect"
    );
    let median = scores.median_shrink.expect("effects named right");
    assert!(median >= 0.7, "median held-out shrink {median}");
}
