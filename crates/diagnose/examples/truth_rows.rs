//! Dev probe: the generating model against one test of a generated set, row by row.
fn main() {
    let dir = std::path::PathBuf::from(std::env::args().nth(1).unwrap());
    let test = std::env::args().nth(2).unwrap();
    let truth: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.parent().unwrap().join("truth.json")).unwrap(),
    )
    .unwrap();
    let name = dir.file_name().unwrap().to_string_lossy().to_string();
    let model: subfric_model::Model =
        serde_json::from_value(truth[&name]["model"].clone()).unwrap();
    let set = subfric_data::load_set(&dir).unwrap();
    let prepared = subfric_fit::prepare_set_with(
        &set,
        false,
        &subfric_fit::PrepareOptions {
            budget_rows: 0,
            ..Default::default()
        },
    );
    let p = prepared.iter().find(|p| p.full.name == test).unwrap();
    let t = &p.full;
    let pred = t.predict(&model).unwrap();
    let raw = &set.test(&test).unwrap().slip_mm;
    let every: usize = std::env::args()
        .nth(3)
        .map_or((t.len() / 40).max(1), |s| s.parse().unwrap());
    let upto: usize = std::env::args()
        .nth(4)
        .map_or(t.len(), |s| s.parse().unwrap());
    for i in (0..upto.min(t.len())).step_by(every) {
        println!(
            "t {:8.2} u {:.5} raw {:.5} kind {:?} meas {:8.3} pred {:8.3} res {:6.2}",
            t.time[i],
            t.imposed[i],
            raw[i],
            p.segmentation.row_kind[i],
            t.measured[i],
            pred[i],
            (pred[i] - t.measured[i]) / t.noise_sd
        );
    }
}
