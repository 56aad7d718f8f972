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
    let r = fit(&tests, &sp, &starts, 2, iters);
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
    {
        use subfric_diagnose::fits::{cross_validate, residuals};
        use subfric_diagnose::folds::{piece_folds, pieces};
        use subfric_diagnose::score::compare;
        let all = pieces(&prepared);
        let folds = piece_folds(&tests, &all, 4);
        let w: Vec<Vec<f64>> = tests
            .iter()
            .map(|t| (0..t.len()).map(|i| t.weight_of(i)).collect())
            .collect();
        let rb = residuals(&tests, &base.model, None);
        let rr = residuals(&tests, &r.model, None);
        let c = compare(&all, &w, &rb, &rr);
        eprintln!(
            "in-sample on pieces: D {:.1} shape {:.1} level {:.1} rel {:.3} typical {:.3}",
            c.score, c.shape_score, c.level_score, c.relative_shrink, c.typical_shrink
        );
        let bsp = space_of(&base.model, &free, &Spec::base(), f.v_ref);
        for it in [0usize, 8, 30] {
            let t2 = std::time::Instant::now();
            let hb = cross_validate(&tests, &folds, &bsp, &[base.model], it, false);
            let hr = cross_validate(&tests, &folds, &sp, &[r.model, base.model], it, false);
            let c = compare(&all, &w, &hb, &hr);
            eprintln!(
                "CV iters {it}: D {:.1} shape {:.1} level {:.1} rel {:.3} typical {:.3} ({:.1}s)",
                c.score,
                c.shape_score,
                c.level_score,
                c.relative_shrink,
                c.typical_shrink,
                t2.elapsed().as_secs_f64()
            );
        }
    }
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
