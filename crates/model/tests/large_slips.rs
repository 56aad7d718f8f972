//! Issue 25, item 8: far from the origin of slip, doubles are too far apart to carry the
//! elastic slip (at 10¹¹ mm they are 1.5·10⁻⁵ mm apart; the elastic slip of Table 1's contact
//! at its capacity is 1.5·10⁻⁸ mm). Every run must give the answer of the same run shifted to
//! a small origin — the model depends on slip differences only — or be refused at a named row;
//! never a silently wrong number.

use subfric_model::{
    simulate, Contact3, Control, Model, Params, Protocol, SimError, State3, Trajectory,
    SLIP_RESOLUTION_SHARE,
};

/// Table 1 (medium): α_t = 2000 kN/mm³, μ_s = 0.37, at 78.4 kPa.
fn table1() -> Model {
    Model::base(Params {
        mu_s: 0.37,
        mu_k: 0.3,
        kappa: 33.0,
        xi: 0.027,
        u_tilde: 3000.0,
        alpha_t: 2000.0,
        alpha_n: 2000.0,
        mu_0: None,
    })
    .unwrap()
}

const P: f64 = 78.4;

/// Slip relative to the origin: loading to 0.05 mm by steps of 10⁻⁴ mm, then elastic
/// unloading by steps of 2·10⁻⁹ mm (4 kPa each), reloading by the same, and sliding back.
fn history() -> (Vec<f64>, Vec<f64>) {
    let mut u = vec![0.0];
    for _ in 0..500 {
        u.push(u.last().unwrap() + 1e-4);
    }
    for _ in 0..6 {
        u.push(u.last().unwrap() - 2e-9);
    }
    for _ in 0..6 {
        u.push(u.last().unwrap() + 2e-9);
    }
    for _ in 0..300 {
        u.push(u.last().unwrap() - 1e-4);
    }
    let t = (0..u.len()).map(|i| i as f64).collect();
    (t, u)
}

fn run(
    model: &Model,
    control: Control,
    t: &[f64],
    x: &[f64],
    initial_slip: f64,
) -> Result<Trajectory, SimError> {
    let normal = vec![P; t.len()];
    simulate(
        model,
        &Protocol {
            control,
            time: t,
            imposed: x,
            normal: &normal,
            initial_slip,
            initial: Default::default(),
        },
    )
}

const ORIGINS: [f64; 8] = [0.0, 1e3, 1e5, 1e6, 1e8, 1e9, 1e11, 9e11];

#[test]
fn slip_control_far_from_the_origin_gives_the_shifted_runs_shear_or_a_located_refusal() {
    let model = table1();
    let (t, u) = history();
    let near = run(&model, Control::Slip, &t, &u, 0.0).unwrap();
    // The elastic steps matter: each moves the shear by 4 kPa.
    assert!((near.shear[503] - near.shear[500]).abs() > 10.0);
    // The bound the refusal guarantees: α_t × spacing ≤ 0.1 % of μ_s p per slip value, twice
    // for a difference.
    let tolerance = 2.0 * SLIP_RESOLUTION_SHARE * model.params.mu_s * P;
    let mut refused = Vec::new();
    for origin in ORIGINS {
        let far: Vec<f64> = u.iter().map(|d| origin + d).collect();
        match run(&model, Control::Slip, &t, &far, 0.0) {
            Ok(out) => {
                let worst = out
                    .shear
                    .iter()
                    .zip(&near.shear)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
                assert!(
                    worst <= tolerance,
                    "origin {origin:e} mm: the shear differs from the shifted run's by {worst:.3e} kPa (at most {tolerance:.3e} expected): a silently wrong number"
                );
            }
            Err(SimError::Input {
                row,
                field,
                message,
            }) => {
                assert_eq!((row, field), (0, "imposed"), "{message}");
                assert!(
                    message.contains("subtract a constant") && message.contains("kPa"),
                    "{message}"
                );
                refused.push(origin);
            }
            Err(e) => panic!("origin {origin:e}: {e}"),
        }
    }
    // The small origins compute; the 10⁹ and 10¹¹ mm are refused.
    assert!(
        !refused.contains(&1e3) && !refused.contains(&0.0),
        "{refused:?}"
    );
    assert!(
        refused.contains(&1e9) && refused.contains(&1e11),
        "{refused:?}"
    );
}

#[test]
fn traction_control_far_from_the_origin_gives_the_shifted_runs_slip_or_a_located_refusal() {
    let model = table1();
    let (t, u) = history();
    let shear = run(&model, Control::Slip, &t, &u, 0.0).unwrap().shear;
    // Up to 80 % of the kinetic capacity and down again (no runaway as μ softens): the slip
    // follows elastically and plastically.
    let cap = model.params.mu_s * P;
    let top = 0.8 * model.params.mu_k * P;
    let tau: Vec<f64> = shear.iter().map(|s| s.clamp(-top, top)).collect();
    let near = run(&model, Control::Shear, &t, &tau, 0.0).unwrap();
    let alpha = model.params.alpha_t_kpa_per_mm();
    // Slip increments agree to the resolution the refusal guarantees (twice: a difference).
    let tolerance = 2.0 * SLIP_RESOLUTION_SHARE * cap / alpha;
    let mut refused = Vec::new();
    for origin in ORIGINS {
        match run(&model, Control::Shear, &t, &tau, origin) {
            Ok(out) => {
                for i in 1..t.len() {
                    let far = out.slip[i] - out.slip[i - 1];
                    let small = near.slip[i] - near.slip[i - 1];
                    assert!(
                        (far - small).abs() <= tolerance,
                        "origin {origin:e} mm, row {i}: slip increment {far:e} mm, {small:e} mm from the shifted run (tolerance {tolerance:.1e} mm): a silently wrong number"
                    );
                }
            }
            Err(SimError::Input { row, field, .. }) => {
                assert_eq!((row, field), (0, "initial_slip"));
                refused.push(origin);
            }
            Err(e) => panic!("origin {origin:e}: {e}"),
        }
    }
    assert!(!refused.contains(&1e3), "{refused:?}");
    assert!(
        refused.contains(&1e9) && refused.contains(&1e11),
        "{refused:?}"
    );
}

#[test]
fn the_3d_step_from_an_increment_is_exact_however_far_the_point_has_slid() {
    // The C interface's step: the state's slip is a record; the traction follows Δu.
    let model = table1();
    let c = Contact3::new(&model, [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);
    // The slip that moves the traction by 80 % of the capacity elastically (1.2·10⁻⁸ mm).
    let elastic = 0.8 * model.params.mu_s * P / model.params.alpha_t_kpa_per_mm();
    let steps: Vec<[f64; 3]> = [
        [elastic, 0.0, 0.0],
        [0.5 * elastic, 0.5 * elastic, 0.0],
        [1e-3, 0.0, 0.0],
        [-0.3 * elastic, 0.0, 0.0],
    ]
    .to_vec();
    let walk = |origin: f64| {
        let mut st = State3::virgin(&model, [origin, -origin, 0.0]);
        steps
            .iter()
            .map(|du| {
                st = c.step_increment(&st, du, P, 1.0).unwrap();
                st.shear
            })
            .collect::<Vec<_>>()
    };
    let near = walk(0.0);
    // Loaded from the virgin state, sliding, then unloaded elastically by 7 kPa.
    assert!(
        near[2][0] > 20.0 && near[2][0] - near[3][0] > 5.0,
        "{near:?}"
    );
    for origin in [1e6, 1e9, 1e11, 1e15] {
        assert_eq!(walk(origin), near, "origin {origin:e} mm");
    }
    // The slip form of the step still agrees with the increment form near the origin.
    let st = State3::virgin(&model, [0.0; 3]);
    let a = c.step_slip(&st, &steps[0], P, 1.0).unwrap();
    let b = c.step_increment(&st, &steps[0], P, 1.0).unwrap();
    assert_eq!(a, b);
}
