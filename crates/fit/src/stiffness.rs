//! A trial of the elastic stiffness α_t where no event of the record resolves it but a first
//! loading rises over several rows: two calibrations, α_t held and α_t free
//! ([`stiffness_by_trial`]). The readings of α_t and the one decision among them and this
//! trial are `subfric_reading::stiffness`'s.

use crate::calibrate::{calibrate, FitOptions};
use crate::space::{Param, Space};
use subfric_model::Model;
use subfric_reading::stats::upper_median;
use subfric_reading::stiffness::rise_secants;
use subfric_reading::{typical_rate, FitTest, PreparedTest, Stiffness};

/// Model runs of the global stage of each trial calibration, at most.
const TRIAL_EVALUATIONS: usize = 1000;

/// Local runs of each trial calibration, at most.
const TRIAL_STARTS: usize = 4;

/// The misfit a free α_t must reach, as a share of the misfit with α_t held, to be kept where
/// no event resolved it: the rise decides it only when it halves the misfit.
pub const TRIAL_SHARE: f64 = 0.5;

/// Where no unload, reload or straight rise resolves the stiffness but a first loading rises
/// over several rows: the base model calibrated (global stage and polish, no profiles) with α_t
/// held as in `template` and with α_t free from the rises' secant (their median), the
/// parameters `free` free in both (the calibration `options` without profiles). The stiffness when freeing α_t halves the misfit — a shear
/// box's rise, curved from its start like the model's own but elastic, the specimen's
/// deformation (α_t held at 1000 kN/mm³ there, μ_s went to 1.5–2.4 and the misfit was several
/// times what it is with α_t free) — else `None` (a stiff interface: the free α_t ends stiff
/// and gains nothing). Two extra calibrations, only on records without a resolved stiffness.
pub fn stiffness_by_trial(
    tests: &[PreparedTest],
    template: &Model,
    free: &[Param],
    options: &FitOptions,
) -> Option<Stiffness> {
    if free.contains(&Param::AlphaT) {
        return None;
    }
    let mut secants: Vec<f64> = rise_secants(tests);
    let secant = upper_median(&mut secants)?;
    // A rise as steep as the held stiffness says nothing the held value does not.
    if secant >= 0.1 * template.params.alpha_t {
        return None;
    }
    let fits: Vec<FitTest> = tests.iter().map(|t| t.fit.clone()).collect();
    // A coarse calibration decides it: where the rise is elastic, freeing α_t lowers the misfit
    // several times over (7–12× on generated shear boxes), not by a few per cent.
    let opts = FitOptions {
        profiles: false,
        statistics: false,
        global_evaluations: options.global_evaluations.min(TRIAL_EVALUATIONS),
        starts: options.starts.min(TRIAL_STARTS),
        ..options.clone()
    };
    let rate = typical_rate(&fits);
    let held = Space::try_with_rate(*template, free, &[], rate).ok()?;
    let mut soft = *template;
    soft.params.alpha_t = secant;
    soft.params.alpha_n = secant;
    let mut with_alpha = free.to_vec();
    with_alpha.push(Param::AlphaT);
    let freed = Space::try_with_rate(soft, &with_alpha, &[], rate).ok()?;
    let a = calibrate(&fits, held, &opts, &|_| {}).ok()?;
    let b = calibrate(&fits, freed, &opts, &|_| {}).ok()?;
    let rows: f64 = fits
        .iter()
        .map(FitTest::rows_represented)
        .sum::<f64>()
        .max(1.0);
    (b.ssr.is_finite() && b.ssr <= TRIAL_SHARE * a.ssr).then(|| Stiffness {
        alpha_t: b.model.params.alpha_t,
        events: secants.len(),
        evidence: format!(
            "no unload or straight rise resolves it, but freeing α_t from the secant of {} first loading{} (about {secant:.3e} kN/mm³) lowers the base model's misfit from {:.3}× to {:.3}× the noise variance, where α_t held at {} kN/mm³ leaves it: the rise is elastic (a shear box's specimen, or the machine's compliance); α_t about {:.3e} kN/mm³",
            secants.len(),
            if secants.len() == 1 { "" } else { "s" },
            a.ssr / rows,
            b.ssr / rows,
            template.params.alpha_t,
            b.model.params.alpha_t
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    use subfric_data::{ControlColumn, TestData, TestSpec};
    use subfric_model::{simulate, Params, Protocol};
    use subfric_reading::{prepare_test, resolved_stiffness, SegmentOptions};

    /// A monotonic test at 200 kPa logged every 5 µm (a 1 µm encoder reading 0.5 µm of noise, a
    /// shear box's displacement gauge; 0.2 kPa of shear noise) whose shear follows `shear(u)`.
    fn monotonic(shear: impl Fn(f64) -> f64) -> TestData {
        let mut rng = rand::rngs::StdRng::seed_from_u64(11);
        let (du, dtau) = (
            Normal::new(0.0, 5e-4).unwrap(),
            Normal::new(0.0, 0.2).unwrap(),
        );
        let u: Vec<f64> = (0..=1200).map(|i| 0.005 * i as f64).collect();
        let n = u.len();
        TestData {
            spec: TestSpec::new("box", "box.csv", ControlColumn::Slip, 200.0),
            path: "box.csv".into(),
            time_s: u.iter().map(|x| 60.0 * x).collect(),
            slip_mm: u
                .iter()
                .map(|x| ((x + du.sample(&mut rng)) / 1e-3).round() * 1e-3)
                .collect(),
            shear_kpa: u
                .iter()
                .map(|x| shear(*x) + dtau.sample(&mut rng))
                .collect(),
            normal_kpa: vec![200.0; n],
            friction_given: false,
            line_of_row: (2..n + 2).collect(),
            comments: vec![],
            reading_notes: Vec::new(),
            channels: Vec::new(),
        }
    }

    /// A monotonic slide to 6 mm at 200 kPa of the model with `params`, logged every 5 µm as
    /// [`monotonic`] logs it.
    fn model_slide(params: Params) -> TestData {
        let model = Model::base(params).unwrap();
        let u: Vec<f64> = (0..=1200).map(|i| 0.005 * i as f64).collect();
        let curve = simulate(
            &model,
            &Protocol {
                control: subfric_model::Control::Slip,
                time: &u.iter().map(|x| 60.0 * x).collect::<Vec<_>>(),
                imposed: &u,
                normal: &vec![200.0; u.len()],
                initial_slip: 0.0,
                initial: Default::default(),
            },
        )
        .unwrap()
        .shear;
        monotonic(|x| curve[(x / 0.005).round() as usize])
    }

    #[test]
    fn a_rise_the_model_follows_only_with_a_soft_alpha_is_freed_by_the_trial() {
        // The model's own curve through a soft spring (2·10⁻³ kN/mm³) with a slow ũ: the rise is
        // curved from its start, so no straight rise reads it, yet holding α_t at 1000 kN/mm³
        // cannot follow it. The trial frees α_t and keeps it.
        let mut params = Params::sample();
        params.alpha_t = 0.002;
        params.alpha_n = 0.002;
        params.u_tilde = 2.0;
        let prepared = prepare_test(
            &model_slide(params),
            "box".into(),
            &SegmentOptions::default(),
        );
        let tests = [prepared];
        assert!(resolved_stiffness(&tests).is_none(), "read off the rise");
        let template = Model::base(Params::sample()).unwrap();
        assert_eq!(template.params.alpha_t, 1000.0);
        let found = stiffness_by_trial(&tests, &template, &Param::BASE, &FitOptions::default())
            .expect("freeing α_t decides the rise");
        assert!(
            (found.alpha_t / 0.002 - 1.0).abs() < 0.1,
            "{} ({})",
            found.alpha_t,
            found.evidence
        );
        // A stiff interface: α_t free gains nothing, and nothing is claimed.
        let mut stiff = Params::sample();
        stiff.u_tilde = 2.0;
        let prepared = prepare_test(
            &model_slide(stiff),
            "box".into(),
            &SegmentOptions::default(),
        );
        assert!(
            stiffness_by_trial(&[prepared], &template, &Param::BASE, &FitOptions::default())
                .is_none()
        );
    }
}
