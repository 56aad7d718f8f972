//! Do the reported 95 % intervals hold the truth 95 % of the time? Generated multi-test
//! campaigns with random sand–steel parameters and a realistic noise model (white sensor noise
//! plus a slowly correlated component, as real load cells and amplifiers give), fitted with the
//! default [`calibrate()`], counting per parameter how often the interval holds the true value.
//!
//! A campaign is four tests as a sand–steel interface is usually characterised: velocity steps
//! (×10 either side of the base rate) and slide–hold–slide (holds of 10, 100, 1000 s) at
//! 100 kPa, two-way cycles at 200 kPa and a monotonic test at 400 kPa. The base rate, the noise
//! levels and the noise's correlation time are drawn per campaign. The data go through the same
//! preparation as a set read from disk ([`prepare_set_with`]: conditioning of the noisy imposed
//! column, segmentation, thinning of long records).
//!
//! `cargo run --release -p subfric-harness --example coverage -- --campaigns 40 --seed 1`

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::Serialize;
use subfric_data::{ControlColumn, ExperimentMeta, ExperimentSet, Interface, TestData, TestSpec};
use subfric_fit::{calibrate, FitOptions, Param, Space, Status};
use subfric_model::{simulate, Control, Model, Params, Protocol};
use subfric_reading::{prepare_set_with, typical_rate, FitTest, PrepareOptions};

/// The noise added to the measured shear of a campaign: white plus a stationary AR(1) process
/// in time (an Ornstein–Uhlenbeck process sampled at the rows), and white noise on the imposed
/// slip.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct NoiseModel {
    /// SD of the white part of the shear noise [kPa].
    pub white_kpa: f64,
    /// Stationary SD of the correlated part [kPa] (0: white noise only).
    pub correlated_kpa: f64,
    /// Correlation time of the correlated part [s].
    pub correlation_time_s: f64,
    /// SD of the white noise on the imposed slip [mm].
    pub slip_mm: f64,
}

impl NoiseModel {
    /// White shear noise only (no correlated part, no slip noise).
    pub fn white(sd_kpa: f64) -> NoiseModel {
        NoiseModel {
            white_kpa: sd_kpa,
            correlated_kpa: 0.0,
            correlation_time_s: 1.0,
            slip_mm: 0.0,
        }
    }

    /// A draw of the shear noise at the times `t`.
    pub fn shear_noise(&self, t: &[f64], rng: &mut ChaCha8Rng) -> Vec<f64> {
        let mut out = Vec::with_capacity(t.len());
        let mut c = self.correlated_kpa * gauss(rng);
        for (i, ti) in t.iter().enumerate() {
            if i > 0 {
                let a = (-(ti - t[i - 1]).max(0.0) / self.correlation_time_s).exp();
                c = a * c + (1.0 - a * a).max(0.0).sqrt() * self.correlated_kpa * gauss(rng);
            }
            out.push(self.white_kpa * gauss(rng) + c);
        }
        out
    }
}

/// A standard normal draw.
fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

fn log_uniform(rng: &mut ChaCha8Rng, a: f64, b: f64) -> f64 {
    (a.ln() + rng.gen::<f64>() * (b.ln() - a.ln())).exp()
}

fn uniform(rng: &mut ChaCha8Rng, a: f64, b: f64) -> f64 {
    a + rng.gen::<f64>() * (b - a)
}

/// Ranges the campaigns are drawn from.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CampaignRanges {
    /// White shear noise SD [kPa].
    pub white_kpa: (f64, f64),
    /// Correlated SD as a multiple of the white SD.
    pub correlated_ratio: (f64, f64),
    /// Correlation time [s] (log-uniform).
    pub correlation_time_s: (f64, f64),
    /// Base slip rate [mm/s] (log-uniform).
    pub rate_mm_s: (f64, f64),
    /// Slip per row while sliding [mm] (the logger samples by travel, as many rigs do).
    pub slip_per_row: f64,
    /// White noise SD of the imposed slip [mm].
    pub slip_noise_mm: f64,
}

impl Default for CampaignRanges {
    fn default() -> Self {
        CampaignRanges {
            white_kpa: (0.15, 0.5),
            correlated_ratio: (0.5, 2.0),
            correlation_time_s: (5.0, 100.0),
            rate_mm_s: (0.005, 0.02),
            slip_per_row: 0.005,
            slip_noise_mm: 0.0002,
        }
    }
}

/// A generated campaign: the truth, the noise, and the set as if read from disk.
#[derive(Clone, Debug)]
pub struct Campaign {
    /// The parameters that generated the data.
    pub truth: Model,
    /// The noise added.
    pub noise: NoiseModel,
    /// Base slip rate [mm/s].
    pub rate_mm_s: f64,
    /// The tests, in the data format's types.
    pub set: ExperimentSet,
}

/// A random sand–steel parameter set (the ranges of the diagnosis's self-check generator).
pub fn random_truth(rng: &mut ChaCha8Rng) -> Model {
    let mu_s = uniform(rng, 0.5, 0.8);
    Model::base(Params {
        mu_s,
        mu_k: mu_s * uniform(rng, 0.65, 0.85),
        kappa: log_uniform(rng, 1.0, 4.0),
        xi: log_uniform(rng, 1e-3, 6e-3),
        u_tilde: log_uniform(rng, 8.0, 40.0),
        alpha_t: 1000.0,
        alpha_n: 1000.0,
        mu_0: None,
    })
    .expect("the ranges give valid parameters")
}

/// Rows of a slip-controlled protocol, sampled every `du` of slip while sliding and 30 times
/// per hold.
struct Rows {
    t: Vec<f64>,
    u: Vec<f64>,
    du: f64,
}

impl Rows {
    fn new(du: f64) -> Self {
        Rows {
            t: vec![0.0],
            u: vec![0.0],
            du,
        }
    }
    fn last(&self) -> (f64, f64) {
        (self.t[self.t.len() - 1], self.u[self.u.len() - 1])
    }
    fn slide(&mut self, rate: f64, distance: f64) {
        let (t0, u0) = self.last();
        let n = (distance.abs() / self.du).round().max(1.0) as usize;
        for j in 1..=n {
            let f = j as f64 / n as f64;
            self.t.push(t0 + f * distance.abs() / rate);
            self.u.push(u0 + f * distance);
        }
    }
    fn hold(&mut self, duration: f64) {
        let (t0, u0) = self.last();
        for j in 1..=30 {
            self.t.push(t0 + duration * j as f64 / 30.0);
            self.u.push(u0);
        }
    }
}

/// The four protocols at base rate `v`: (name, normal stress, rows).
fn protocols(v: f64, du: f64) -> Vec<(&'static str, f64, Rows)> {
    let mut vs = Rows::new(du);
    vs.slide(v, 2.0);
    vs.slide(10.0 * v, 1.0);
    vs.slide(v, 0.9);
    vs.slide(0.1 * v, 0.5);
    vs.slide(v, 0.6);
    let mut shs = Rows::new(du);
    shs.slide(v, 2.0);
    for h in [10.0, 100.0, 1000.0] {
        shs.hold(h);
        shs.slide(v, 0.8);
    }
    let mut cyc = Rows::new(du);
    for _ in 0..3 {
        cyc.slide(v, 1.0);
        cyc.slide(v, -2.0);
        cyc.slide(v, 1.0);
    }
    let mut mono = Rows::new(du);
    mono.slide(v, 4.0);
    vec![
        ("velocity-steps", 100.0, vs),
        ("slide-hold-slide", 100.0, shs),
        ("two-way-cyclic", 200.0, cyc),
        ("monotonic-400kPa", 400.0, mono),
    ]
}

/// Generates campaign number `index` of a measurement seeded with `seed`.
pub fn generate_campaign(seed: u64, index: usize, ranges: &CampaignRanges) -> Campaign {
    let mut rng =
        ChaCha8Rng::seed_from_u64(seed.wrapping_mul(1_000_003).wrapping_add(index as u64));
    let truth = random_truth(&mut rng);
    let white = uniform(&mut rng, ranges.white_kpa.0, ranges.white_kpa.1);
    let noise = NoiseModel {
        white_kpa: white,
        correlated_kpa: white
            * uniform(
                &mut rng,
                ranges.correlated_ratio.0,
                ranges.correlated_ratio.1,
            ),
        correlation_time_s: log_uniform(
            &mut rng,
            ranges.correlation_time_s.0,
            ranges.correlation_time_s.1,
        ),
        slip_mm: ranges.slip_noise_mm,
    };
    let rate = log_uniform(&mut rng, ranges.rate_mm_s.0, ranges.rate_mm_s.1);
    let name = format!("campaign-{seed}-{index:03}");
    let mut tests = Vec::new();
    let mut specs = Vec::new();
    for (test_name, normal, rows) in protocols(rate, ranges.slip_per_row) {
        let n = rows.t.len();
        let normal_col = vec![normal; n];
        let proto = Protocol {
            control: Control::Slip,
            time: &rows.t,
            imposed: &rows.u,
            normal: &normal_col,
            initial_slip: 0.0,
            initial: Default::default(),
        };
        let shear = simulate(&truth, &proto)
            .expect("the base model runs under slip control")
            .shear;
        let e = noise.shear_noise(&rows.t, &mut rng);
        let shear_meas: Vec<f64> = shear.iter().zip(&e).map(|(s, e)| s + e).collect();
        let slip_meas: Vec<f64> = rows
            .u
            .iter()
            .map(|u| u + noise.slip_mm * gauss(&mut rng))
            .collect();
        let spec = TestSpec::new(
            test_name,
            &format!("{test_name}.csv"),
            ControlColumn::Slip,
            normal,
        );
        specs.push(spec.clone());
        tests.push(TestData {
            spec,
            path: format!("{test_name}.csv").into(),
            time_s: rows.t,
            slip_mm: slip_meas,
            shear_kpa: shear_meas,
            normal_kpa: normal_col,
            friction_given: false,
            line_of_row: (2..n + 2).collect(),
            comments: vec!["generated for the coverage measurement".into()],
            reading_notes: Vec::new(),
            channels: Vec::new(),
        });
    }
    let set = ExperimentSet {
        dir: name.clone().into(),
        meta: ExperimentMeta {
            name: name.clone(),
            title: format!("generated campaign {name}"),
            source: "subfric-fit coverage generator".into(),
            provenance: Some("synthetic: random parameters, white + correlated noise".into()),
            interface: Interface::default(),
            tests: specs,
            reference_parameters: None,
            units: None,
            extra: Default::default(),
        },
        tests,
    };
    Campaign {
        truth,
        noise,
        rate_mm_s: rate,
        set,
    }
}

/// One parameter of one campaign.
#[derive(Clone, Debug, Serialize)]
pub struct ParamOutcome {
    /// Key.
    pub name: String,
    /// True value.
    pub truth: f64,
    /// Fitted value.
    pub value: f64,
    /// Reported 95 % interval (lo, hi).
    pub interval: Option<(f64, f64)>,
    /// The interval holds the truth.
    pub covered: bool,
    /// Identifiability verdict.
    pub status: Status,
}

/// One fitted campaign.
#[derive(Clone, Debug, Serialize)]
pub struct CampaignOutcome {
    /// Campaign index.
    pub index: usize,
    /// Noise model used.
    pub noise: NoiseModel,
    /// Base rate [mm/s].
    pub rate_mm_s: f64,
    /// Misfit (reduced χ² in the units of the estimated white noise).
    pub reduced_chi2: f64,
    /// Variance inflation for correlated residuals the fit applied.
    pub noise_correlation: f64,
    /// Per parameter.
    pub parameters: Vec<ParamOutcome>,
    /// Wall time of the fit [s].
    pub elapsed_s: f64,
}

/// Per-parameter coverage over the campaigns.
#[derive(Clone, Debug, Serialize)]
pub struct CoverageRow {
    /// Key.
    pub name: String,
    /// Campaigns whose interval held the truth.
    pub covered: usize,
    /// Campaigns.
    pub total: usize,
    /// Campaigns where the parameter was reported determined.
    pub determined: usize,
    /// Median of (interval half-width / truth) [%].
    pub median_half_width_percent: f64,
}

impl CoverageRow {
    /// covered/total.
    pub fn fraction(&self) -> f64 {
        self.covered as f64 / self.total.max(1) as f64
    }
}

/// What a coverage measurement found.
#[derive(Clone, Debug, Serialize)]
pub struct CoverageReport {
    /// Seed.
    pub seed: u64,
    /// Ranges the campaigns were drawn from.
    pub ranges: CampaignRanges,
    /// Per parameter.
    pub rows: Vec<CoverageRow>,
    /// Per campaign.
    pub campaigns: Vec<CampaignOutcome>,
    /// Wall time [s].
    pub elapsed_s: f64,
}

/// Fits one campaign with the default calibration, as `subfric fit` would (generic start, the
/// five parameters of the paper free).
pub fn fit_campaign(c: &Campaign, index: usize, opts: &FitOptions) -> CampaignOutcome {
    let t0 = std::time::Instant::now();
    let tests: Vec<FitTest> = prepare_set_with(&c.set, false, &PrepareOptions::default())
        .into_iter()
        .map(|p| p.fit)
        .collect();
    let mut template = Model::base(Params::sample()).expect("sample parameters are valid");
    template.params.alpha_t = c.truth.params.alpha_t;
    template.params.alpha_n = c.truth.params.alpha_n;
    let space = Space::with_rate(template, &Param::BASE, &[], typical_rate(&tests));
    let report = calibrate(&tests, space, opts, &|_| {}).expect("a generated campaign fits");
    let parameters = Param::BASE
        .iter()
        .map(|&q| {
            let truth = q.get(&c.truth).unwrap_or(f64::NAN);
            let p = report.param(q.key()).expect("free parameters are reported");
            let interval = p.interval.map(|i| (i.lo, i.hi));
            ParamOutcome {
                name: q.key().into(),
                truth,
                value: p.value,
                interval,
                covered: p.interval.is_some_and(|i| i.contains(truth)),
                status: p.status,
            }
        })
        .collect();
    CampaignOutcome {
        index,
        noise: c.noise,
        rate_mm_s: c.rate_mm_s,
        reduced_chi2: report.reduced_chi2,
        noise_correlation: report.noise_correlation,
        parameters,
        elapsed_s: t0.elapsed().as_secs_f64(),
    }
}

/// Generates and fits `campaigns` campaigns (indices `0..campaigns`), calling `progress` after
/// each, and counts per parameter how often the reported interval holds the truth.
pub fn measure_coverage(
    campaigns: usize,
    seed: u64,
    ranges: &CampaignRanges,
    opts: &FitOptions,
    progress: &dyn Fn(&CampaignOutcome),
) -> CoverageReport {
    let t0 = std::time::Instant::now();
    let mut outcomes = Vec::new();
    for index in 0..campaigns {
        let c = generate_campaign(seed, index, ranges);
        let o = fit_campaign(
            &c,
            index,
            &FitOptions {
                seed: seed.wrapping_add(index as u64),
                ..opts.clone()
            },
        );
        progress(&o);
        outcomes.push(o);
    }
    CoverageReport {
        seed,
        ranges: *ranges,
        rows: tally(&outcomes),
        campaigns: outcomes,
        elapsed_s: t0.elapsed().as_secs_f64(),
    }
}

/// Per-parameter counts over fitted campaigns.
pub fn tally(outcomes: &[CampaignOutcome]) -> Vec<CoverageRow> {
    Param::BASE
        .iter()
        .map(|q| {
            let of: Vec<&ParamOutcome> = outcomes
                .iter()
                .filter_map(|o| o.parameters.iter().find(|p| p.name == q.key()))
                .collect();
            let mut widths: Vec<f64> = of
                .iter()
                .filter_map(|p| p.interval.map(|(a, b)| 50.0 * (b - a) / p.truth.abs()))
                .collect();
            CoverageRow {
                name: q.key().into(),
                covered: of.iter().filter(|p| p.covered).count(),
                total: of.len(),
                determined: of.iter().filter(|p| p.status == Status::Determined).count(),
                median_half_width_percent: subfric_reading::stats::upper_median(&mut widths)
                    .unwrap_or(f64::NAN),
            }
        })
        .collect()
}
