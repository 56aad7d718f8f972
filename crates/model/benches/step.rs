//! Criterion benchmarks of the model (`cargo bench -p subfric-model --bench step`).
//!
//! - `step`: the speed target of the project, the case `subfric bench` times
//!   (crates/cli/src/bench.rs `step_case`): the 1-D slip-controlled step on
//!   u(t) = 1 mm · sin(2π t / 200 s), 10 cycles in 200 000 equal steps, `Params::sample()`,
//!   normal stress 100 kPa. Throughput is in steps.
//! - `simulate`: one run of the general `simulate` path over the bundled Table 4 two-way cyclic
//!   curve (experiments/table4-two-way, 3150 rows) as recorded, with the published parameters.
//!   Throughput is in rows.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use std::path::Path;
use subfric_model::{simulate, Contact1, Control, Model, Params, Protocol, State1};

/// The benchmark history, built exactly as `subfric bench` builds it.
fn sine_case() -> (Model, Vec<f64>, Vec<f64>) {
    let model = Model::base(Params::sample()).expect("sample parameters are valid");
    let n = 200_000;
    let dt = 2000.0 / n as f64;
    let time: Vec<f64> = (0..=n).map(|i| i as f64 * dt).collect();
    let slip = time
        .iter()
        .map(|t| (2.0 * std::f64::consts::PI * t / 200.0).sin())
        .collect();
    (model, time, slip)
}

/// The hot loop: slip-controlled steps at 100 kPa; returns the shear of every row.
fn run_steps(model: &Model, dts: &[f64], slip: &[f64], shear: &mut [f64]) {
    let mut contact = Contact1::new(model);
    let mut s = State1::virgin(model, 0.0);
    for ((dt, u), out) in dts.iter().zip(&slip[1..]).zip(&mut shear[1..]) {
        s = match contact.step_slip(&s, *u, 100.0, *dt) {
            Ok(next) => next,
            Err(e) => panic!("step failed: {e}"),
        };
        *out = s.shear;
    }
}

fn step(c: &mut Criterion) {
    let (model, time, slip) = sine_case();
    // The time steps exactly as `simulate` sees them (equal up to rounding).
    let dts: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    let mut shear = vec![0.0; slip.len()];

    // What is timed is the real thing: the loop gives `simulate`'s results bit for bit.
    run_steps(&model, &dts, &slip, &mut shear);
    let normal = vec![100.0; time.len()];
    let reference = simulate(
        &model,
        &Protocol {
            control: Control::Slip,
            time: &time,
            imposed: &slip,
            normal: &normal,
            initial_slip: 0.0,
            initial: Default::default(),
        },
    )
    .expect("the sine case simulates");
    assert!(
        reference
            .shear
            .iter()
            .zip(&shear)
            .skip(1)
            .all(|(a, b)| a.to_bits() == b.to_bits()),
        "the benchmarked loop differs from simulate"
    );

    let mut g = c.benchmark_group("step");
    g.throughput(Throughput::Elements(dts.len() as u64));
    g.sample_size(20);
    g.bench_function("slip-control sine 200k steps", |b| {
        b.iter(|| {
            run_steps(&model, &dts, &slip, &mut shear);
            black_box(shear[shear.len() - 1])
        })
    });
    g.finish();
}

/// The bundled Table 4 test: time, slip, shear, normal stress and the published model.
fn table4() -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>, Model) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../experiments/table4-two-way");
    let meta: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("experiment.json")).expect("table4 experiment.json"),
    )
    .expect("table4 experiment.json parses");
    let test = &meta["tests"][0];
    assert_eq!(test["control"], "slip");
    let sigma = test["normal_stress_kpa"].as_f64().expect("normal stress");
    let params: Params = serde_json::from_value(meta["reference_parameters"].clone())
        .expect("published parameters parse");
    let model = Model::base(params).expect("published parameters are valid");
    let mut rd = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_path(dir.join(test["file"].as_str().expect("file")))
        .expect("table4 CSV opens");
    let header = rd.headers().expect("header").clone();
    let col = |name: &str| header.iter().position(|h| h == name).expect(name);
    let (it, iu, iq) = (col("time_s"), col("slip_mm"), col("shear_kpa"));
    let (mut time, mut slip, mut shear) = (Vec::new(), Vec::new(), Vec::new());
    for r in rd.records() {
        let r = r.expect("row");
        let num = |k: usize| r[k].parse::<f64>().expect("number");
        time.push(num(it));
        slip.push(num(iu));
        shear.push(num(iq));
    }
    let normal = vec![sigma; time.len()];
    (time, slip, shear, normal, model)
}

fn simulate_table4(c: &mut Criterion) {
    let (time, slip, measured, normal, model) = table4();
    let proto = Protocol {
        control: Control::Slip,
        time: &time,
        imposed: &slip,
        normal: &normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    // The published parameters reproduce the curve (0.3 % noise): the bench runs a sane case.
    let out = simulate(&model, &proto).expect("table4 simulates");
    let peak = measured.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let rms = (out
        .shear
        .iter()
        .zip(&measured)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        / out.shear.len() as f64)
        .sqrt();
    assert!(rms < 0.01 * peak, "table4: RMS {rms} kPa of {peak} kPa");

    let mut g = c.benchmark_group("simulate");
    g.throughput(Throughput::Elements(time.len() as u64));
    g.bench_function("table4 two-way cyclic", |b| {
        b.iter(|| black_box(simulate(&model, &proto).unwrap().shear.len()))
    });
    g.finish();
}

criterion_group!(benches, step, simulate_table4);
criterion_main!(benches);
