//! The C test: `tests/c/check_interface.c`, compiled with the system C compiler against
//! `include/subfric.h` and the static library cargo built for this test, run on reference
//! values from the Rust path.
//!
//! This test writes the cases (the model, the slip increments and, for every step, the state,
//! traction, tangent and plastic slip that `Contact3::step_increment` and
//! `Contact3::step_increment_with_tangent` give) to a text file; the C program steps the same
//! increments through the C interface, compares, and checks the tangent against its own
//! finite differences. The compiler is `$CC`, or `cc`. The static library is
//! `libsubfric_ffi.a` beside this test's executable (`target/<profile>/deps/`) or one folder
//! up (`target/<profile>/`): cargo builds every crate type of the library before the
//! integration tests, so it is the library of this very build.
#![cfg(unix)]

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;
use subfric_model::{
    Contact3, Extensions, Model, Params, RateEffect, RateForm, State3, TermEffect, Terms, Vec3,
};

/// How a case gives its model to the C program.
enum Source {
    /// `SubfricParams` filled field by field.
    Params,
    /// `subfric_model_from_file` on a JSON file.
    File(String),
    /// `subfric_model_from_json` on the text of a JSON file.
    Json(String),
}

enum Step {
    /// A slip increment and a time increment.
    Slip(Vec3, f64),
    /// A step back and sideways from the current traction, whose elastic path passes beside
    /// the origin (the step restarts from the closest point): Δu = −(1.6 f̂ + 0.6 f̂⊥)‖f‖/α.
    SharpTurn(f64),
}

struct Case {
    name: &'static str,
    model: Model,
    source: Source,
    normal: Vec3,
    forward: Vec3,
    pressure: f64,
    steps: Vec<Step>,
}

fn circle_steps(normal: &Vec3, radius: f64, per_turn: usize, turns: usize, dt: f64) -> Vec<Step> {
    let l = (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt();
    let n = normal.map(|x| x / l);
    let a = {
        let t = [1.0 - n[0] * n[0], -n[0] * n[1], -n[0] * n[2]];
        let tl = (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
        t.map(|x| x / tl)
    };
    let b = [
        n[1] * a[2] - n[2] * a[1],
        n[2] * a[0] - n[0] * a[2],
        n[0] * a[1] - n[1] * a[0],
    ];
    let at = |k: usize| -> Vec3 {
        let phi = 2.0 * std::f64::consts::PI * k as f64 / per_turn as f64;
        let (s, c) = phi.sin_cos();
        std::array::from_fn(|i| radius * (s * a[i] + (1.0 - c) * b[i]))
    };
    (1..=per_turn * turns)
        .map(|k| {
            let (u0, u1) = (at(k - 1), at(k));
            Step::Slip(std::array::from_fn(|i| u1[i] - u0[i]), dt)
        })
        .collect()
}

/// ±`amp` along `dir`, `n` steps a quarter; at each reversal `small` steps of `unload` (elastic
/// unloading) and, if `hold` > 0, a hold of that duration.
fn two_way_steps(
    dir: &Vec3,
    amp: f64,
    n: usize,
    small: usize,
    unload: f64,
    hold: f64,
    dt: f64,
) -> Vec<Step> {
    let du = amp / n as f64;
    let mut steps = Vec::new();
    for (sign, count, reversal) in [(1.0, n, false), (-1.0, 2 * n, true), (1.0, 2 * n, true)] {
        let mut left = count as f64 * du;
        if reversal {
            if hold > 0.0 {
                steps.push(Step::Slip([0.0; 3], hold));
            }
            for _ in 0..small {
                steps.push(Step::Slip(dir.map(|x| sign * unload * x), dt));
                left -= unload;
            }
        }
        let m = (left / du).round() as usize;
        for _ in 0..m {
            steps.push(Step::Slip(dir.map(|x| sign * left / m as f64 * x), dt));
        }
    }
    steps
}

fn penalty() -> Params {
    // A finite-element penalty stiffness: 1 kN/mm³ = 10⁶ kPa/mm.
    Params {
        alpha_t: 1.0,
        alpha_n: 1.0,
        ..Params::sample()
    }
}

fn cases(dir: &Path) -> Vec<Case> {
    let sample = Model::base(Params::sample()).unwrap();
    let with_mu_0 = Model::base(Params {
        mu_0: Some(0.4),
        ..Params::sample()
    })
    .unwrap();

    // A fit.json as `subfric fit` writes it (the model to use is its `model`).
    let rate_state = Model::new(
        penalty(),
        Extensions::default().with_rate(RateEffect {
            form: RateForm::StateAgeing,
            a: 0.01,
            v_c: 1e-6,
            b: 0.008,
            d_c: 0.02,
            n: 0.0,
            v_ref: 0.001,
            at_rest: subfric_model::AtRest::Creep,
        }),
    )
    .unwrap();
    let fit = serde_json::json!({
        "model": rate_state,
        "params": rate_state.params,
        "report": {"optimizer": {"method": "lsq"}, "misfit": 1.0},
    });
    let fit_path = dir.join("fit.json");
    std::fs::write(&fit_path, serde_json::to_string_pretty(&fit).unwrap()).unwrap();

    // A model object with extensions acting on the bounds, by direction and pressure.
    let extended = Model::new(
        penalty(),
        Extensions {
            terms: Terms::one(TermEffect::named("direction", "mu-k", &[0.15]).unwrap())
                .with(TermEffect::named("slip-hardening", "hyperbolic", &[0.02, 0.5]).unwrap())
                .with(TermEffect::named("pressure", "exponential-mu-s", &[0.2, 100.0]).unwrap()),
        },
    )
    .unwrap();
    let model_path = dir.join("model.json");
    std::fs::write(&model_path, serde_json::to_string(&extended).unwrap()).unwrap();

    let tilted = [0.3, -0.2, 0.9];
    let mut circle_paper = circle_steps(&tilted, 1.0, 100, 2, 2.0);
    circle_paper.push(Step::SharpTurn(1.0));
    let mut circle_ext = circle_steps(&[0.0, 0.0, 1.0], 0.5, 80, 2, 1.0);
    circle_ext.push(Step::SharpTurn(1.0));
    vec![
        Case {
            name: "circle-paper",
            model: sample,
            source: Source::Params,
            normal: tilted,
            forward: [1.0, 0.0, 0.0],
            pressure: 100.0,
            steps: circle_paper,
        },
        Case {
            name: "two-way-paper",
            model: with_mu_0,
            source: Source::Params,
            normal: [0.0, 0.0, 1.0],
            forward: [1.0, 0.0, 0.0],
            pressure: 100.0,
            // α = 10⁹ kPa/mm: 45 kPa unload within 4.5e-8 mm.
            steps: two_way_steps(&[0.6, 0.8, 0.0], 0.5, 50, 3, 1e-8, 0.0, 1.0),
        },
        Case {
            name: "two-way-rate-state",
            model: rate_state,
            source: Source::File(fit_path.display().to_string()),
            normal: [0.0, 0.0, 1.0],
            forward: [1.0, 0.0, 0.0],
            pressure: 150.0,
            steps: two_way_steps(&[1.0, 0.0, 0.0], 0.5, 50, 4, 1e-5, 50.0, 0.5),
        },
        Case {
            name: "circle-extensions",
            model: extended,
            source: Source::Json(model_path.display().to_string()),
            normal: [0.0, 0.0, 1.0],
            forward: [0.8, 0.6, 0.0],
            pressure: 120.0,
            steps: circle_ext,
        },
    ]
}

fn num(out: &mut String, x: f64) {
    write!(out, " {x:e}").unwrap();
}

/// The cases file: the model, then every step with what the Rust path gives.
fn write_cases(cases: &[Case]) -> (String, usize) {
    let mut out = String::new();
    let mut total = 0;
    for case in cases {
        let m = &case.model;
        writeln!(out, "case {}", case.name).unwrap();
        match &case.source {
            Source::Params => {
                let p = &m.params;
                out.push_str("model params");
                for x in [
                    p.mu_s, p.mu_k, p.kappa, p.xi, p.u_tilde, p.alpha_t, p.alpha_n,
                ] {
                    num(&mut out, x);
                }
                num(&mut out, p.mu_0.unwrap_or(f64::NAN));
                out.push('\n');
            }
            Source::File(path) => writeln!(out, "model file {path}").unwrap(),
            Source::Json(path) => writeln!(out, "model json {path}").unwrap(),
        }
        out.push_str("normal");
        case.normal.iter().for_each(|&x| num(&mut out, x));
        out.push_str("\nforward");
        case.forward.iter().for_each(|&x| num(&mut out, x));
        writeln!(
            out,
            "\npressure {:e}\nsteps {}",
            case.pressure,
            case.steps.len()
        )
        .unwrap();

        let c = Contact3::new(m, case.normal, case.forward);
        let p = case.pressure;
        let alpha = m.params.alpha_t_kpa_per_mm();
        let mut st = State3::virgin(m, [0.0; 3]);
        let mut plastic = 0;
        for step in &case.steps {
            let (du, dt) = match *step {
                Step::Slip(du, dt) => (du, dt),
                Step::SharpTurn(dt) => {
                    // In the plane: f̂ and n̂ × f̂.
                    let f = st.shear;
                    let fl = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
                    let g = f.map(|x| x / fl);
                    let l = c.tangential(&[0.0; 3]);
                    let nn = {
                        let v = case.normal;
                        let vl = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                        v.map(|x| x / vl)
                    };
                    let perp = [
                        nn[1] * g[2] - nn[2] * g[1],
                        nn[2] * g[0] - nn[0] * g[2],
                        nn[0] * g[1] - nn[1] * g[0],
                    ];
                    let du: Vec3 =
                        std::array::from_fn(|i| l[i] - (1.6 * g[i] + 0.6 * perp[i]) * fl / alpha);
                    (du, dt)
                }
            };
            // What the C interface does with an increment.
            let next = c.step_increment(&st, &du, p, dt).unwrap();
            let (with_tangent, tan) = c.step_increment_with_tangent(&st, &du, p, dt).unwrap();
            assert_eq!(next, with_tangent);
            out.push_str("step");
            du.iter().for_each(|&x| num(&mut out, x));
            num(&mut out, dt);
            let n = &next;
            for x in n.slip.iter().chain(&n.shear) {
                num(&mut out, *x);
            }
            for x in [n.mu, n.r, n.cos_r, n.sin_r, n.slip_path, n.time]
                .into_iter()
                .chain(n.slots.0)
            {
                num(&mut out, x);
            }
            tan.d_slip.iter().flatten().for_each(|&x| num(&mut out, x));
            tan.d_pressure.iter().for_each(|&x| num(&mut out, x));
            tan.plastic_slip.iter().for_each(|&x| num(&mut out, x));
            let slid = tan.plastic_slip != [0.0; 3];
            plastic += usize::from(slid);
            writeln!(out, " {}", u8::from(slid)).unwrap();
            st = next;
        }
        out.push_str("end\n");
        total += case.steps.len();
        assert!(plastic > 0 && plastic < case.steps.len() || case.name.starts_with("circle"));
    }
    (out, total)
}

/// The static library of this build (see the module documentation).
fn static_library() -> PathBuf {
    let exe = std::env::current_exe().expect("the test's executable");
    let deps = exe.parent().expect("deps folder");
    let candidates = [
        deps.join("libsubfric_ffi.a"),
        deps.join("../libsubfric_ffi.a"),
    ];
    candidates
        .iter()
        .find(|p| p.is_file())
        .unwrap_or_else(|| panic!("libsubfric_ffi.a not found at {candidates:?}"))
        .clone()
}

/// The system libraries a Rust static library needs (`rustc --print native-static-libs`).
fn native_libs() -> &'static [&'static str] {
    if cfg!(target_os = "macos") {
        &["-lSystem", "-lc", "-lm"]
    } else {
        &[
            "-lgcc_s",
            "-lutil",
            "-lrt",
            "-lpthread",
            "-lm",
            "-ldl",
            "-lc",
        ]
    }
}

#[test]
fn c_program_agrees_with_the_rust_path_and_with_finite_differences() {
    let started = Instant::now();
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = tempfile::tempdir().unwrap();
    let cases = cases(tmp.path());
    let (text, steps) = write_cases(&cases);
    let cases_file = tmp.path().join("cases.txt");
    std::fs::write(&cases_file, text).unwrap();

    let exe = tmp.path().join("check_interface");
    let compiler = std::env::var("CC").unwrap_or_else(|_| "cc".to_string());
    let lib = static_library();
    let out = Command::new(&compiler)
        .args([
            "-std=c99",
            "-O2",
            "-Wall",
            "-Wextra",
            "-pedantic",
            "-Werror",
            "-I",
        ])
        .arg(crate_dir.join("include"))
        .arg(crate_dir.join("tests/c/check_interface.c"))
        .arg(&lib)
        .args(native_libs())
        .arg("-o")
        .arg(&exe)
        .output()
        .unwrap_or_else(|e| panic!("cannot run the C compiler `{compiler}` (set CC): {e}"));
    assert!(
        out.status.success(),
        "compiling tests/c/check_interface.c with {compiler} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let compiled = started.elapsed();

    let run = Command::new(&exe).arg(&cases_file).output().unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout);
    let stderr = String::from_utf8_lossy(&run.stderr);
    println!("{stdout}{stderr}");
    println!(
        "{steps} steps in {} cases; compile {:.2} s, total {:.2} s (library {})",
        cases.len(),
        compiled.as_secs_f64(),
        started.elapsed().as_secs_f64(),
        lib.display()
    );
    assert!(
        run.status.success(),
        "the C program failed:\n{stdout}{stderr}"
    );
    // Every case reported, and every check passed.
    for case in &cases {
        assert!(stdout.contains(case.name), "no line for {}", case.name);
    }
    assert!(stdout.contains("C checks: ") && !stderr.contains("FAILED"));
}
