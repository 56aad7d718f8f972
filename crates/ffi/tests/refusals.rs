//! Issue 25, items 6 and 8, through the C functions: what a finite-element code may hand the
//! interface by mistake is refused with a status and a message naming it, and nothing it is
//! handed gives a success with a number that is not one.
//!
//! - a state that is no state (an all-zero array, μ outside the model's bounds, garbage);
//! - a forward axis without a direction in the contact plane;
//! - a model "file" that is a FIFO (would block forever) or `/dev/zero` (would be read until
//!   memory runs out), or a regular file too large to be a model;
//! - a point that has slid far (a slip record of 10¹¹ mm): its traction is still exact.

use std::ffi::{c_char, CStr, CString};
use std::time::{Duration, Instant};
use subfric_ffi::*;

const MSG: usize = 512;

/// Runs a call that takes a message buffer; returns its status and message.
fn call(f: impl FnOnce(*mut c_char, usize) -> SubfricStatus) -> (SubfricStatus, String) {
    let mut buf = vec![0 as c_char; MSG];
    let status = f(buf.as_mut_ptr(), MSG);
    // SAFETY: the interface NUL-terminates the buffer it was given.
    let msg = unsafe { CStr::from_ptr(buf.as_ptr()) }
        .to_string_lossy()
        .into_owned();
    (status, msg)
}

/// μ_s = 0.45, α_t = 1000 kN/mm³ (the sample parameters): 45 kPa at 100 kPa.
fn sample_params() -> SubfricParams {
    SubfricParams {
        mu_s: 0.45,
        mu_k: 0.3,
        kappa: 1.2,
        xi: 0.003,
        u_tilde: 15.0,
        alpha_t: 1000.0,
        alpha_n: 1000.0,
        mu_0: f64::NAN,
    }
}

/// A model from `params` on the plane of `normal` with `forward` (None: NULL pointers).
fn model(
    params: &SubfricParams,
    normal: Option<[f64; 3]>,
    forward: Option<[f64; 3]>,
) -> (SubfricStatus, String, *mut SubfricModel) {
    let mut m = std::ptr::null_mut();
    let ptr = |v: &Option<[f64; 3]>| v.as_ref().map_or(std::ptr::null(), |a| a.as_ptr());
    let (status, msg) = call(|buf, len| {
        // SAFETY: valid pointers or NULL, a buffer of `len` bytes.
        unsafe { subfric_model_new(params, ptr(&normal), ptr(&forward), &mut m, buf, len) }
    });
    (status, msg, m)
}

fn init(m: *const SubfricModel) -> SubfricState {
    let mut st = std::mem::MaybeUninit::<SubfricState>::uninit();
    // SAFETY: a live model, a buffer-less call.
    let status = unsafe { subfric_state_init(m, st.as_mut_ptr(), std::ptr::null_mut(), 0) };
    assert_eq!(status, SubfricStatus::Ok);
    // SAFETY: written on success.
    unsafe { st.assume_init() }
}

/// One step; returns status, message, next state and response (those two unchanged on
/// failure: they start as NaN, so a failure that wrote them shows).
fn step(
    m: *const SubfricModel,
    st: &SubfricState,
    du: [f64; 3],
    p: f64,
    dt: f64,
) -> (SubfricStatus, String, SubfricState, SubfricResponse) {
    let mut next = SubfricState {
        slip: [f64::NAN; 3],
        shear: [f64::NAN; 3],
        mu: f64::NAN,
        r: f64::NAN,
        cos_r: f64::NAN,
        sin_r: f64::NAN,
        slip_path: f64::NAN,
        time: f64::NAN,
        slots: [f64::NAN; SUBFRIC_STATE_SLOTS],
    };
    let mut r = SubfricResponse {
        shear: [f64::NAN; 3],
        traction: [f64::NAN; 3],
        dshear_dslip: [[f64::NAN; 3]; 3],
        dshear_dpressure: [f64::NAN; 3],
        plastic_slip: [f64::NAN; 3],
        plastic: -1,
    };
    let (status, msg) = call(|buf, len| {
        // SAFETY: a live model, valid state, increment, outputs and buffer.
        unsafe { subfric_step(m, st, du.as_ptr(), p, dt, &mut next, &mut r, buf, len) }
    });
    (status, msg, next, r)
}

fn free(m: *mut SubfricModel) {
    // SAFETY: a model from a constructor, released once.
    unsafe { subfric_model_free(m) }
}

#[test]
fn an_all_zero_state_is_no_state_and_is_refused() {
    let (_, _, m) = model(&sample_params(), None, None);
    let zero = SubfricState {
        slip: [0.0; 3],
        shear: [0.0; 3],
        mu: 0.0,
        r: 0.0,
        cos_r: 0.0,
        sin_r: 0.0,
        slip_path: 0.0,
        time: 0.0,
        slots: [0.0; SUBFRIC_STATE_SLOTS],
    };
    let (status, msg, next, _) = step(m, &zero, [0.01, 0.0, 0.0], 100.0, 1.0);
    assert_eq!(status, SubfricStatus::InvalidInput, "{msg}");
    assert!(
        msg.contains("cos_r") && msg.contains("subfric_state_init"),
        "{msg}"
    );
    assert!(next.mu.is_nan(), "state_out written on failure");
    // The virgin state steps.
    let (status, msg, ..) = step(m, &init(m), [0.01, 0.0, 0.0], 100.0, 1.0);
    assert_eq!(status, SubfricStatus::Ok, "{msg}");
    free(m);
}

#[test]
fn a_state_with_mu_outside_the_model_is_refused_not_stepped_to_4137_kpa() {
    let (_, _, m) = model(&sample_params(), None, None);
    let mut st = init(m);
    st.mu = 100.0;
    let (status, msg, ..) = step(m, &st, [0.01, 0.0, 0.0], 100.0, 1.0);
    assert_eq!(status, SubfricStatus::InvalidInput, "{msg}");
    assert!(
        msg.contains("state.mu = 100") && msg.contains("[0.3, 0.45]"),
        "{msg}"
    );
    free(m);
}

#[test]
fn a_forward_axis_without_a_direction_in_the_plane_is_refused() {
    let p = sample_params();
    for forward in [[0.0, 0.0, 0.0], [0.0, 0.0, 2.0], [0.0, 0.0, -1e-3]] {
        let (status, msg, m) = model(&p, None, Some(forward));
        assert_eq!(status, SubfricStatus::InvalidInput, "{forward:?}: {msg}");
        assert!(msg.contains("forward") && msg.contains("plane"), "{msg}");
        assert!(m.is_null());
    }
    // Through JSON too, and for a model with a direction effect the default (1, 0, 0) along
    // the normal is no axis either.
    let json = CString::new(
        r#"{"params": {"mu_s":0.45,"mu_k":0.3,"kappa":1.2,"xi":0.003,"u_tilde":15,"alpha_t":1000},
            "ext": {"direction": {"d": 0.2}}}"#,
    )
    .unwrap();
    let normal = [1.0, 0.0, 0.0];
    let mut m = std::ptr::null_mut();
    let (status, msg) = call(|buf, len| {
        // SAFETY: a NUL-terminated text, valid pointers, a buffer of `len` bytes.
        unsafe {
            subfric_model_from_json(
                json.as_ptr(),
                normal.as_ptr(),
                std::ptr::null(),
                &mut m,
                buf,
                len,
            )
        }
    });
    assert_eq!(status, SubfricStatus::InvalidInput, "{msg}");
    assert!(msg.contains("forward NULL"), "{msg}");
    // Without a direction effect the default is not used: accepted. A tilted axis projects.
    let (status, msg, m) = model(&p, Some(normal), None);
    assert_eq!(status, SubfricStatus::Ok, "{msg}");
    free(m);
    let (status, msg, m) = model(&p, None, Some([1.0, 0.0, 5.0]));
    assert_eq!(status, SubfricStatus::Ok, "{msg}");
    free(m);
}

#[test]
fn a_point_that_has_slid_far_keeps_its_exact_traction() {
    // The elastic slip at 45 kPa is 4.5·10⁻⁸ mm; at a slip of 10¹¹ mm doubles are 1.5·10⁻⁵ mm
    // apart. The traction of the step must not depend on the slip record.
    let (_, _, m) = model(&sample_params(), None, None);
    let mut near = init(m);
    let mut far = near;
    far.slip = [1e11, -3e11, 0.0];
    let increments = [
        [2e-3, 0.0, 0.0],
        [1e-8, 1e-8, 0.0],
        [-2e-8, 0.0, 0.0],
        [0.0, -3e-8, 0.0],
        [1e-3, 1e-3, 0.0],
    ];
    for du in increments {
        let (s1, msg1, n1, r1) = step(m, &near, du, 100.0, 1.0);
        let (s2, msg2, n2, r2) = step(m, &far, du, 100.0, 1.0);
        assert_eq!(
            (s1, s2),
            (SubfricStatus::Ok, SubfricStatus::Ok),
            "{msg1} {msg2}"
        );
        assert_eq!(
            r1.shear, r2.shear,
            "dslip {du:?}: the far point's traction differs"
        );
        assert_eq!(r1.dshear_dslip, r2.dshear_dslip);
        assert_eq!((n1.mu, n1.r), (n2.mu, n2.r));
        (near, far) = (n1, n2);
    }
    assert!(near.shear[0].abs() > 1.0, "{:?}", near.shear);
    free(m);
}

/// A small deterministic generator (no dependency).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        self.0 >> 11
    }
    fn unit(&mut self) -> f64 {
        self.next() as f64 / (1u64 << 53) as f64
    }
    /// A double of any sign and magnitude: one of a few special values, a random bit pattern
    /// or a number of random exponent in [1e-300, 1e300].
    fn garbage(&mut self) -> f64 {
        match self.next() % 8 {
            0 => {
                [0.0, -0.0, 1.0, -1.0, f64::MAX, f64::MIN_POSITIVE, 1e308][self.next() as usize % 7]
            }
            1 => f64::from_bits(self.next() << 11 | self.next() & 0x7ff),
            _ => {
                let sign = if self.next().is_multiple_of(2) {
                    1.0
                } else {
                    -1.0
                };
                sign * 10f64.powf(600.0 * self.unit() - 300.0)
            }
        }
    }
}

#[test]
fn no_garbage_state_steps_to_a_success_with_a_number_that_is_not_one() {
    let (_, _, base) = model(&sample_params(), None, None);
    let json = CString::new(
        r#"{"params": {"mu_s":0.45,"mu_k":0.3,"kappa":1.2,"xi":0.003,"u_tilde":15,"alpha_t":1},
            "ext": {"rate": {"form": "state-ageing", "a": 0.01, "b": 0.008, "d_c": 0.02, "v_c": 1e-6, "v_ref": 0.001},
                    "slip_hardening": {"h": 0.02, "s_h": 0.5}}}"#,
    )
    .unwrap();
    let mut rate_state = std::ptr::null_mut();
    let (status, msg) = call(|buf, len| {
        // SAFETY: a NUL-terminated text, a valid output, a buffer of `len` bytes.
        unsafe {
            subfric_model_from_json(
                json.as_ptr(),
                std::ptr::null(),
                std::ptr::null(),
                &mut rate_state,
                buf,
                len,
            )
        }
    });
    assert_eq!(status, SubfricStatus::Ok, "{msg}");
    let mut rng = Rng(2025);
    let (mut ok, mut refused) = (0, 0);
    for k in 0..100_000 {
        let m = if k % 2 == 0 { base } else { rate_state };
        let mut st = init(m);
        // Garbage in a few fields of a real state, or everywhere.
        let fields = if k % 10 == 0 {
            13
        } else {
            1 + rng.next() as usize % 3
        };
        for _ in 0..fields {
            let v = rng.garbage();
            match rng.next() % 13 {
                i @ 0..=2 => st.slip[i as usize] = v,
                i @ 3..=5 => st.shear[i as usize - 3] = v,
                6 => st.mu = v,
                7 => st.r = v,
                8 => st.cos_r = v,
                9 => st.sin_r = v,
                10 => st.slip_path = v,
                11 => st.time = v,
                // θ of the rate-and-state form (its first slot), or a slot of none.
                _ => st.slots[rng.next() as usize % 2] = v,
            }
        }
        let du = [rng.garbage() * 1e-3, rng.garbage() * 1e-3, rng.garbage()];
        let du = if k % 3 == 0 { [1e-3, -2e-3, 0.0] } else { du };
        let p = if k % 4 == 0 {
            rng.garbage().abs()
        } else {
            100.0
        };
        let dt = if k % 5 == 0 { rng.garbage().abs() } else { 1.0 };
        let (status, msg, next, r) = step(m, &st, du, p, dt);
        if status == SubfricStatus::Ok {
            ok += 1;
            let mut all: Vec<f64> = next.slip.to_vec();
            all.extend(next.shear);
            all.extend([
                next.mu,
                next.r,
                next.cos_r,
                next.sin_r,
                next.slip_path,
                next.time,
            ]);
            all.extend(next.slots);
            all.extend(r.shear.iter().chain(&r.traction).chain(&r.dshear_dpressure));
            all.extend(r.dshear_dslip.iter().flatten().chain(&r.plastic_slip));
            assert!(
                all.iter().all(|x| x.is_finite()),
                "case {k}: OK with a number that is not one from {st:?}, dslip {du:?}, p {p}, dt {dt}: {next:?} {r:?}"
            );
        } else {
            refused += 1;
            assert!(!msg.is_empty(), "case {k}: {status:?} without a message");
            assert_ne!(status, SubfricStatus::Internal, "case {k}: {msg}");
        }
    }
    eprintln!("garbage states: {ok} stepped, {refused} refused");
    assert!(
        ok > 1000 && refused > 1000,
        "{ok} stepped, {refused} refused"
    );
    free(base);
    free(rate_state);
}

/// Runs `subfric_model_from_file` on `path` in a thread; if it has not returned after 20 s it
/// blocks or reads without end, and the test process stops (a thread blocked in open() or
/// filling memory from /dev/zero cannot be cancelled).
fn from_file_within_time(path: &str) -> (SubfricStatus, String) {
    let shown = path.to_string();
    let path = CString::new(path).unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut m = std::ptr::null_mut();
        let out = call(|buf, len| {
            // SAFETY: a NUL-terminated path, a valid output, a buffer of `len` bytes.
            unsafe {
                subfric_model_from_file(
                    path.as_ptr(),
                    std::ptr::null(),
                    std::ptr::null(),
                    &mut m,
                    buf,
                    len,
                )
            }
        });
        free(m);
        let _ = tx.send(out);
    });
    let started = Instant::now();
    match rx.recv_timeout(Duration::from_secs(20)) {
        Ok(out) => out,
        Err(_) => {
            eprintln!(
                "subfric_model_from_file({shown}) has not returned after {:.0} s: it blocks or reads without end",
                started.elapsed().as_secs_f64()
            );
            std::process::exit(101);
        }
    }
}

#[cfg(unix)]
#[test]
fn a_fifo_a_device_a_folder_and_a_huge_file_are_refused_as_model_files() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("fit.json");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo runs");
    assert!(made.success());
    let huge = dir.path().join("huge.json");
    // Sparse: no disk is used.
    std::fs::File::create(&huge)
        .unwrap()
        .set_len(SUBFRIC_MAX_MODEL_FILE_BYTES + 1)
        .unwrap();
    for (path, expected) in [
        (fifo.display().to_string(), "not a regular file"),
        ("/dev/zero".to_string(), "not a regular file"),
        (dir.path().display().to_string(), "a folder"),
        (huge.display().to_string(), "bytes or more"),
    ] {
        let (status, msg) = from_file_within_time(&path);
        assert_eq!(status, SubfricStatus::Io, "{path}: {msg}");
        assert!(
            msg.starts_with(&path) && msg.contains(expected),
            "{path}: {msg}"
        );
    }
}

// Issue 42, case 10 -----------------------------------------------------------------------------

/// A model from a JSON string; its status, message and handle.
fn from_json(text: &str) -> (SubfricStatus, String, *mut SubfricModel) {
    let json = CString::new(text).unwrap();
    let mut m = std::ptr::null_mut();
    let (status, msg) = call(|buf, len| {
        // SAFETY: a NUL-terminated text, a valid output, a buffer of `len` bytes.
        unsafe {
            subfric_model_from_json(
                json.as_ptr(),
                std::ptr::null(),
                std::ptr::null(),
                &mut m,
                buf,
                len,
            )
        }
    });
    (status, msg, m)
}

#[test]
fn every_state_field_time_included_is_guarded_in_and_out() {
    // Rate and state beside time healing: their state variables fill the first slots, in the
    // order the families are registered, and are named as the families name them.
    let (status, msg, m) = from_json(
        r#"{"params": {"mu_s":0.45,"mu_k":0.3,"kappa":1.2,"xi":0.003,"u_tilde":15,"alpha_t":1000},
            "ext": {"rate": {"form": "state-ageing", "a": 0.01, "b": 0.008, "d_c": 0.02, "v_c": 1e-6, "v_ref": 0.001},
                    "healing": {"form": "log", "b": 0.02, "t_c": 1, "d_h": 0.01}}}"#,
    );
    assert_eq!(status, SubfricStatus::Ok, "{msg}");
    // In: each field of a real state made infinite (or NaN) in turn is refused, by name.
    let slots = ["theta", "rate_add", "rate_factor", "age", "healed"];
    assert_eq!(slots.len(), SUBFRIC_STATE_SLOTS);
    for (k, name) in ["time", "slip_path"].iter().chain(&slots).enumerate() {
        let mut st = init(m);
        let bad = if k % 2 == 0 { f64::INFINITY } else { f64::NAN };
        match *name {
            "time" => st.time = bad,
            "slip_path" => st.slip_path = bad,
            _ => st.slots[k - 2] = bad,
        }
        let (status, msg, _, _) = step(m, &st, [1e-3, 0.0, 0.0], 100.0, 1.0);
        assert_eq!(status, SubfricStatus::InvalidInput, "{name}: {msg}");
        assert!(msg.contains(&format!("state_in.{name} = ")), "{msg}");
    }
    // A slot no family of the model uses is named by its place.
    let (_, _, base) = model(&sample_params(), None, None);
    let mut st = init(base);
    assert_eq!(st.slots, [0.0; SUBFRIC_STATE_SLOTS]);
    st.slots[4] = f64::NAN;
    let (status, msg, _, _) = step(base, &st, [1e-3, 0.0, 0.0], 100.0, 1.0);
    assert_eq!(status, SubfricStatus::InvalidInput, "{msg}");
    assert!(msg.contains("state_in.slots[4] = NaN"), "{msg}");
    free(base);
    // What the families allow of their variables is theirs to say.
    for (slot, bad, expected) in [(0, 0.0, "> 0 [s]"), (3, -1.0, "a time >= 0")] {
        let mut st = init(m);
        st.slots[slot] = bad;
        let (status, msg, _, _) = step(m, &st, [1e-3, 0.0, 0.0], 100.0, 1.0);
        assert_eq!(status, SubfricStatus::InvalidInput, "{msg}");
        assert!(
            msg.contains(&format!("state.{} = ", slots[slot])) && msg.contains(expected),
            "{msg}"
        );
    }
    // Out: a time at the edge of the doubles plus a step of them is no success with time = inf.
    let mut st = init(m);
    st.time = f64::MAX;
    let (status, msg, next, _) = step(m, &st, [1e-3, 0.0, 0.0], 100.0, f64::MAX);
    assert_ne!(status, SubfricStatus::Ok, "time = {} {msg}", next.time);
    free(m);
}

#[test]
fn extension_parameters_the_integrator_cannot_carry_are_refused_at_construction() {
    let base =
        r#""params": {"mu_s":0.45,"mu_k":0.3,"kappa":1.2,"xi":0.003,"u_tilde":15,"alpha_t":1000}"#;
    for (ext, named) in [
        (
            r#"{"rate": {"form": "log-direct", "a": 1e300, "v_ref": 0.001}}"#,
            "rate",
        ),
        (
            r#"{"slip_hardening": {"h": 1e300, "s_h": 0.5}}"#,
            "slip_hardening",
        ),
    ] {
        let (status, msg, m) = from_json(&format!("{{{base}, \"ext\": {ext}}}"));
        assert_eq!(status, SubfricStatus::InvalidParameters, "{ext}: {msg}");
        assert!(
            msg.contains("cannot take an ordinary step") && msg.contains(named),
            "{msg}"
        );
        assert!(m.is_null());
    }
    // The fitted magnitudes still build, and step.
    for ext in [
        r#"{"rate": {"form": "log-direct", "a": 0.01, "v_ref": 0.001}}"#,
        r#"{"slip_hardening": {"h": 0.05, "s_h": 0.5}}"#,
    ] {
        let (status, msg, m) = from_json(&format!("{{{base}, \"ext\": {ext}}}"));
        assert_eq!(status, SubfricStatus::Ok, "{ext}: {msg}");
        let (status, msg, _, _) = step(m, &init(m), [1e-3, 0.0, 0.0], 100.0, 1.0);
        assert_eq!(status, SubfricStatus::Ok, "{msg}");
        free(m);
    }
}
