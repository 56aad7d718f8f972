//! Dev probe: fit base and base + one candidate family to a set; write predictions per test.
use subfric_diagnose::candidates::library;
use subfric_diagnose::features::data_features;
use subfric_diagnose::fits::{fit, space_of, with_values, Spec};
use subfric_fit::{calibrate, resolved_stiffness, FitOptions, Param};
use subfric_model::{Model, Params};

fn main() {
    let dir = std::env::args().nth(1).unwrap();
    let which = std::env::args()
        .nth(2)
        .unwrap_or("rate and state, slip law".into());
    let iters: usize = std::env::args()
        .nth(3)
        .map(|s| s.parse().unwrap())
        .unwrap_or(80);
    let set = subfric_data::load_set(std::path::Path::new(&dir)).unwrap();
    let prepared = subfric_diagnose::prepare_for_diagnosis(&set);
    let tests: Vec<_> = prepared.iter().map(|p| p.fit.clone()).collect();
    let f = data_features(&prepared);
    eprintln!("{f:?}");
    let mut template = Model::base(Params::sample()).unwrap();
    let mut free = Param::BASE.to_vec();
    if let Some(s) = resolved_stiffness(&prepared) {
        template.params.alpha_t = s.alpha_t;
        template.params.alpha_n = s.alpha_t;
        free.push(Param::AlphaT);
    }
    let t0 = std::time::Instant::now();
    let space = space_of(&template, &free, &Spec::base(), f.v_ref);
    let base = calibrate(
        &tests,
        space,
        &FitOptions {
            global_evaluations: 1500,
            starts: 4,
            profiles: false,
            ..Default::default()
        },
        &|_| {},
    )
    .unwrap();
    eprintln!(
        "base ssr {:.4e} in {:.1}s {:?}",
        base.ssr,
        t0.elapsed().as_secs_f64(),
        base.model.params
    );
    let lib = library(&f);
    let form = lib.iter().find(|x| x.name == which).expect("form");
    let spec = Spec::with(form);
    let sp = space_of(&base.model, &free, &spec, f.v_ref);
    let starts: Vec<Model> = form
        .starts
        .iter()
        .map(|s| with_values(&base.model, &spec, std::slice::from_ref(s)))
        .collect();
    let t1 = std::time::Instant::now();
    let r = fit(&tests, &sp, &starts, iters);
    eprintln!(
        "{} ssr {:.4e} conv {} {} in {:.1}s\n{:?}\n{:?}",
        which,
        r.ssr,
        r.converged,
        r.termination,
        t1.elapsed().as_secs_f64(),
        r.model.params,
        r.model.ext
    );
    for p in &prepared {
        let t = &p.full;
        let b = t.predict(&base.model).unwrap();
        let e = t.predict(&r.model).unwrap();
        let mut s = String::from("t,u,mu,base,eff\n");
        for i in 0..t.len() {
            s += &format!(
                "{},{},{},{},{}\n",
                t.time[i],
                t.imposed[i],
                t.measured[i] / t.normal[i],
                b[i] / t.normal[i],
                e[i] / t.normal[i]
            );
        }
        std::fs::write(format!("/tmp/probe-{}.csv", t.name), s).unwrap();
    }
}
