//! The fast part of `subfric selfcheck`: sets generated with withheld effects — none, a
//! measurement drift no candidate models, single effects in several forms, two effects at once,
//! with lab-like sampling and a mid-run start among them — are diagnosed without being told the
//! effects, and every verdict must be right.

use subfric_diagnose::selfcheck::{selfcheck, SelfcheckOptions};
use subfric_diagnose::synth::{Built, SynthOptions};
use subfric_diagnose::Effect;

fn b(effect: Effect, form: usize) -> Built {
    Built { effect, form }
}

#[test]
fn generated_sets_with_withheld_effects_are_named_right() {
    let classes = vec![
        vec![],
        vec![b(Effect::Unexplained, 0)],
        vec![b(Effect::Rate, 2)],
        vec![b(Effect::Pressure, 4)],
        vec![b(Effect::SlipHardening, 2)],
        vec![b(Effect::LogHealing, 1)],
        vec![b(Effect::Direction, 1)],
        vec![b(Effect::Rate, 0), b(Effect::Pressure, 0)],
    ];
    let opts = SelfcheckOptions {
        classes,
        // Two sets per class: plain, then with a lab-like clock and 0.1 µm quantised slip.
        per_class: 2,
        seed: 2026,
        // Coarser rows than a lab file (0.01 mm instead of 0.005 mm) keep the test fast.
        synth: SynthOptions {
            slip_per_row: 0.01,
            ..SynthOptions::default()
        },
        ..SelfcheckOptions::default()
    };
    let (cases, scores) = selfcheck(&opts, &|c| eprintln!("{c:?}"), &|_, _| {});
    eprintln!("{scores}");
    assert_eq!(cases.len(), 16);
    let wrong: Vec<String> = cases
        .iter()
        .filter(|c| !c.right())
        .map(|c| format!("{} ({}): named {:?}", c.name, c.truth_label, c.verdict))
        .collect();
    assert!(wrong.is_empty(), "wrong verdicts: {wrong:?}");
    assert_eq!(scores.false_alarms, 0);
    assert_eq!(scores.spurious_second.0, 0);
    assert_eq!(scores.two_effect_recall, (2, 2));
}
