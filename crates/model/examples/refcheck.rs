//! Simulates each reference set with its published parameters and prints the RMS error.
use subfric_model::{simulate, Control, Model, Params, Protocol};

fn main() {
    let root = std::env::args()
        .nth(1)
        .unwrap_or("../../experiments".into());
    let mut dirs: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    dirs.sort();
    for d in dirs {
        let meta: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("experiment.json")).unwrap())
                .unwrap();
        let p: Params = serde_json::from_value(meta["reference_parameters"].clone()).unwrap();
        for t in meta["tests"].as_array().unwrap() {
            let file = d.join(t["file"].as_str().unwrap());
            let control = if t["control"] == "slip" {
                Control::Slip
            } else {
                Control::Shear
            };
            let fnorm = t["normal_stress_kpa"].as_f64().unwrap();
            let mut rdr = csv::ReaderBuilder::new()
                .comment(Some(b'#'))
                .from_path(&file)
                .unwrap();
            let (mut tm, mut u, mut s) = (vec![], vec![], vec![]);
            for rec in rdr.records() {
                let r = rec.unwrap();
                tm.push(r[0].parse::<f64>().unwrap());
                u.push(r[1].parse::<f64>().unwrap());
                s.push(r[2].parse::<f64>().unwrap());
            }
            let normal = vec![fnorm; tm.len()];
            let (imp, meas) = match control {
                Control::Slip => (&u, &s),
                Control::Shear => (&s, &u),
            };
            let proto = Protocol {
                control,
                time: &tm,
                imposed: imp,
                normal: &normal,
                initial_slip: u[0],
            };
            let m = Model::base(p).unwrap();
            let t0 = std::time::Instant::now();
            let out = simulate(&m, &proto).unwrap();
            let el = t0.elapsed();
            let pred = out.predicted(control);
            let rms = (pred
                .iter()
                .zip(meas.iter())
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                / pred.len() as f64)
                .sqrt();
            let scale = match control {
                Control::Slip => meas.iter().cloned().fold(0.0, f64::max),
                Control::Shear => *meas.last().unwrap(),
            };
            println!(
                "{:?} {:?}: rms {:.4} scale {:.4} -> {:.3}%  ({:?})",
                d.file_name().unwrap(),
                t["name"],
                rms,
                scale,
                100.0 * rms / scale,
                el
            );
            if std::env::var("DUMP").is_ok() {
                for i in (0..tm.len()).step_by(tm.len() / 25) {
                    println!(
                        "  t {:8.2} imp {:10.5} meas {:10.5} pred {:10.5} mu {:.4} r {:.4}",
                        tm[i], imp[i], meas[i], pred[i], out.mu[i], out.r[i]
                    );
                }
            }
        }
    }
}
