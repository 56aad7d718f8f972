//! Criterion benchmarks of the model step (`cargo bench -p subfric-model`).
//!
//! The main case is the speed target of the project: the 1-D slip-controlled step on
//! u(t) = 1 mm · sin(2π t / 200 s), 10 cycles in 200 000 equal steps, `Params::sample()`,
//! normal stress 100 kPa.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use subfric_model::{
    simulate, Contact1, Control, Model, Params, Protocol, Scenario, Stage, State1,
};

fn sine_case() -> (Model, Vec<f64>, Vec<f64>) {
    let model = Model::base(Params::sample()).unwrap();
    let n = 200_000;
    let dt = 2000.0 / n as f64;
    let time: Vec<f64> = (0..=n).map(|i| i as f64 * dt).collect();
    let slip = time
        .iter()
        .map(|t| (2.0 * std::f64::consts::PI * t / 200.0).sin())
        .collect();
    (model, time, slip)
}

fn step(c: &mut Criterion) {
    let (model, time, slip) = sine_case();
    let dts: Vec<f64> = time.windows(2).map(|w| w[1] - w[0]).collect();
    let mut g = c.benchmark_group("step");
    g.throughput(Throughput::Elements((slip.len() - 1) as u64));
    g.sample_size(20);
    g.bench_function("slip-control sine 200k steps", |b| {
        b.iter(|| {
            let mut contact = Contact1::new(&model);
            let mut s = State1::virgin(&model, 0.0);
            let mut sum = 0.0;
            for (dt, u) in dts.iter().zip(&slip[1..]) {
                s = match contact.step_slip(&s, *u, 100.0, *dt) {
                    Ok(next) => next,
                    Err(e) => panic!("{e}"),
                };
                sum += s.shear;
            }
            black_box(sum)
        })
    });
    g.finish();
}

fn simulate_two_way(c: &mut Criterion) {
    // A two-way cyclic test like Table 4's: ±1.5 mm at 0.02 mm/s, 0.5 s rows.
    let sc = Scenario {
        name: "two-way".into(),
        control: Control::Slip,
        normal_stress_kpa: 98.0,
        dt_s: 0.5,
        stages: vec![Stage::Cycles {
            amplitude_mm: 1.5,
            rate_mm_s: 0.02,
            count: 5,
        }],
    };
    let rows = sc.rows().unwrap();
    let model = Model::base(Params::sample()).unwrap();
    let proto = Protocol {
        control: Control::Slip,
        time: &rows.time,
        imposed: &rows.imposed,
        normal: &rows.normal,
        initial_slip: 0.0,
    };
    let mut g = c.benchmark_group("simulate");
    g.throughput(Throughput::Elements(rows.time.len() as u64));
    g.bench_function("two-way cyclic", |b| {
        b.iter(|| black_box(simulate(&model, &proto).unwrap().shear.len()))
    });
    g.finish();
}

criterion_group!(benches, step, simulate_two_way);
criterion_main!(benches);
