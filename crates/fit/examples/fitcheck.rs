use subfric_fit::*;
use subfric_model::{Control, Model, Params};

fn load(dir: &std::path::Path) -> (Vec<FitTest>, Option<Params>) {
    let set = subfric_data::load_set(dir).unwrap();
    let tests = prepare_set(&set, false)
        .into_iter()
        .map(|p| p.fit)
        .collect();
    (tests, reference_model(&set).map(|m| m.params))
}

fn main() {
    let dir = std::path::PathBuf::from(std::env::args().nth(1).unwrap());
    let seed: u64 = std::env::args()
        .nth(2)
        .map(|s| s.parse().unwrap())
        .unwrap_or(1);
    let evals: usize = std::env::args()
        .nth(3)
        .map(|s| s.parse().unwrap())
        .unwrap_or(3000);
    let (tests, published) = load(&dir);
    let mut template = Model::base(Params::sample()).unwrap();
    if let Some(p) = published {
        template.params.alpha_t = p.alpha_t;
        template.params.alpha_n = p.alpha_n;
    }
    let space = Space::with_rate(template, &Param::BASE, &[], typical_rate(&tests));
    if let Some(pp) = published {
        let pr = Problem::new(&tests, space.clone());
        let x = space.point_of(&Model::base(pp).unwrap());
        println!("SSR at published: {:.1} (rows {})", pr.ssr(&x), pr.rows());
        let r = subfric_fit::lm::levenberg_marquardt(&pr, &x, None, &Default::default());
        println!(
            "LM from published: {:.1} {:?} {:?}",
            r.ssr,
            r.termination,
            space.natural(&r.x)
        );
        if std::env::var("DBG").is_ok() {
            for dq in [-2.0, -0.5, -0.1, 0.0, 0.1] {
                let mut y = x.clone();
                y[1] += dq;
                let m = space.model_at(&y);
                println!(
                    "dq {dq}: ssr {:.1} mu_k {} mu_s {}",
                    pr.ssr(&y),
                    m.params.mu_k,
                    m.params.mu_s
                );
            }
        }
    }
    let opts = FitOptions {
        seed,
        global_evaluations: evals,
        ..FitOptions::default()
    };
    let mut rep = calibrate(&tests, space, &opts, &|_| {}).unwrap();
    if let Some(p) = published {
        compare_with_published(&mut rep, &Model::base(p).unwrap());
    }
    println!(
        "{}: chi2 {:.3} starts {}/{} evals {} ({:.2}s) guesses {}",
        dir.display(),
        rep.reduced_chi2,
        rep.optimizer.starts_at_best,
        rep.optimizer.starts,
        rep.optimizer.evaluations,
        rep.optimizer.elapsed_s,
        rep.optimizer.informed_guesses
    );
    println!(
        "   start ssr {:?}",
        rep.optimizer
            .start_ssr
            .iter()
            .map(|v| format!("{v:.0}"))
            .collect::<Vec<_>>()
    );
    for p in &rep.parameters {
        println!(
            "   {:8} {:12.5} pub {:>10} diff {:>8} se {:>10} int {:?} {:?} {}",
            p.name,
            p.value,
            p.published.map(|v| format!("{v}")).unwrap_or_default(),
            p.difference_percent
                .map(|v| format!("{v:.2}%"))
                .unwrap_or_default(),
            p.std_error.map(|v| format!("{v:.3e}")).unwrap_or_default(),
            p.interval
                .map(|(a, b)| (format!("{a:.4e}"), format!("{b:.4e}"))),
            p.interval_open,
            p.status.describe()
        );
    }
    for c in &rep.combinations {
        println!(
            "   comb {:60} {:.5e} {:?} {:?} det {}",
            c.name, c.value, c.interval, c.interval_open, c.determined
        );
    }
    for f in &rep.flat_directions {
        println!("   flat: {:?}", f);
    }
    if std::env::var("PROF").is_ok() {
        for (n, pts) in &rep.profiles {
            println!(
                "   profile {n}: {:?}",
                pts.iter()
                    .map(|(a, b)| format!("{a:.4e}:{b:.1}"))
                    .collect::<Vec<_>>()
            );
        }
    }
}
#[allow(dead_code)]
fn _unused() {}
