//! Golden data from an independent implementation: the bundled curves of Tables 1–4 were
//! computed from the published parameters (plus 0.3 % noise). Simulating them with those
//! parameters must reproduce them within the noise.

use subfric_model::{simulate, Control, Model, Params, Protocol};

struct Curve {
    control: Control,
    normal: f64,
    time: Vec<f64>,
    slip: Vec<f64>,
    shear: Vec<f64>,
    params: Params,
}

fn load(set: &str) -> Curve {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../experiments")
        .join(set);
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("experiment.json")).unwrap())
            .unwrap();
    let params: Params = serde_json::from_value(meta["reference_parameters"].clone()).unwrap();
    let test = &meta["tests"][0];
    let control = serde_json::from_value(test["control"].clone()).unwrap();
    let normal = test["normal_stress_kpa"].as_f64().unwrap();
    let mut rdr = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_path(dir.join(test["file"].as_str().unwrap()))
        .unwrap();
    let mut c = Curve {
        control,
        normal,
        time: vec![],
        slip: vec![],
        shear: vec![],
        params,
    };
    for rec in rdr.records() {
        let r = rec.unwrap();
        c.time.push(r[0].parse().unwrap());
        c.slip.push(r[1].parse().unwrap());
        c.shear.push(r[2].parse().unwrap());
    }
    c
}

/// RMS error of the simulated curve relative to the peak shear (slip control) or the final
/// slip (traction control), in percent.
fn relative_rms_percent(set: &str) -> f64 {
    let c = load(set);
    let normal = vec![c.normal; c.time.len()];
    let (imposed, measured) = match c.control {
        Control::Slip => (&c.slip, &c.shear),
        Control::Shear => (&c.shear, &c.slip),
    };
    let proto = Protocol {
        control: c.control,
        time: &c.time,
        imposed,
        normal: &normal,
        initial_slip: c.slip[0],
        initial: Default::default(),
    };
    let out = simulate(&Model::base(c.params).unwrap(), &proto).unwrap();
    let pred = out.predicted(c.control);
    let ms = pred
        .iter()
        .zip(measured)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        / pred.len() as f64;
    let scale = match c.control {
        Control::Slip => measured.iter().fold(0.0f64, |m, v| m.max(v.abs())),
        Control::Shear => measured.last().unwrap().abs(),
    };
    100.0 * ms.sqrt() / scale
}

#[test]
fn table1_smooth_reproduces_within_noise() {
    let e = relative_rms_percent("table1-smooth");
    assert!(e <= 0.5, "RMS error {e:.3} % of peak");
}

#[test]
fn table1_medium_reproduces_within_noise() {
    let e = relative_rms_percent("table1-medium");
    assert!(e <= 0.5, "RMS error {e:.3} % of peak");
}

#[test]
fn table1_rough_reproduces_within_noise() {
    let e = relative_rms_percent("table1-rough");
    assert!(e <= 0.5, "RMS error {e:.3} % of peak");
}

#[test]
fn table2_ring_torsion_reproduces_within_noise() {
    let e = relative_rms_percent("table2-ring-torsion");
    assert!(e <= 0.5, "RMS error {e:.3} % of peak");
}

#[test]
fn table3_pulsating_under_traction_control_reproduces_within_noise() {
    let e = relative_rms_percent("table3-pulsating");
    assert!(e <= 0.5, "RMS error {e:.3} % of final slip");
}

#[test]
fn table4_two_way_cyclic_reproduces_within_noise() {
    let e = relative_rms_percent("table4-two-way");
    assert!(e <= 0.5, "RMS error {e:.3} % of peak");
}

#[test]
fn wrong_parameters_do_not_reproduce_table1() {
    // The check above must be able to fail: a 10 % change of μ_k is far outside the noise.
    let mut c = load("table1-medium");
    c.params.mu_k *= 0.9;
    let normal = vec![c.normal; c.time.len()];
    let proto = Protocol {
        control: c.control,
        time: &c.time,
        imposed: &c.slip,
        normal: &normal,
        initial_slip: 0.0,
        initial: Default::default(),
    };
    let out = simulate(&Model::base(c.params).unwrap(), &proto).unwrap();
    let peak = c.shear.iter().fold(0.0f64, |m, v| m.max(*v));
    let rms = (out
        .shear
        .iter()
        .zip(&c.shear)
        .map(|(a, b)| (a - b).powi(2))
        .sum::<f64>()
        / c.time.len() as f64)
        .sqrt();
    assert!(100.0 * rms / peak > 2.0);
}
