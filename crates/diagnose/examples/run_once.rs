//! Dev probe: N model runs of one form on a set's diagnosis rows (for instruction counts).
use subfric_diagnose::candidates::library;
use subfric_diagnose::features::data_features;
use subfric_diagnose::fits::{with_values, Spec};
use subfric_model::{Model, Params};

fn main() {
    let dir = std::env::args().nth(1).unwrap();
    let which = std::env::args().nth(2).unwrap();
    let n: usize = std::env::args().nth(3).unwrap().parse().unwrap();
    let set = subfric_data::load_set(std::path::Path::new(&dir)).unwrap();
    let prepared = subfric_diagnose::prepare_for_diagnosis(&set);
    let tests: Vec<_> = prepared.iter().map(|p| p.fit.clone()).collect();
    let f = data_features(&prepared);
    let mut m = Model::base(Params::sample()).unwrap();
    m.params.alpha_t = 0.02;
    m.params.alpha_n = 0.02;
    if which != "base" {
        let form = library(&f).into_iter().find(|x| x.name == which).unwrap();
        m = with_values(&m, &Spec::with(&form), &[form.starts[0].clone()]);
    }
    let mut s = 0.0;
    for _ in 0..n {
        for t in &tests {
            s += t.predict(&m).map(|v| v[v.len() - 1]).unwrap_or(0.0);
        }
    }
    println!("{s}");
}
