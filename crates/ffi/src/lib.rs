//! # subfric-ffi
//!
//! The C interface of the subloading-friction model: one material point of the 3-D contact, the
//! call an implicit finite-element contact routine makes at each integration point. Given the
//! state at the start of an increment, the slip increment, the contact pressure and the time
//! increment, [`subfric_step`] returns the state at the end, the tangential traction, its
//! consistent tangent ∂f_t/∂u and its derivative in the pressure ∂f_t/∂p (Abaqus FRIC's TAU,
//! DDTDDG, DDTDDP), and the plastic slip increment (DSLIP).
//!
//! The normal stress is an input, as in a friction subroutine (the host code owns the normal
//! contact). A routine that must return the normal traction too (penalty contact with
//! p = α_n ⟨−g_n⟩) assembles the full stiffness from the outputs:
//! ∂f/∂u = ∂f_t/∂u + α_n (n − ∂f_t/∂p) ⊗ n with f = f_t − p n (see the README).
//!
//! Units: slip mm, stress kPa, time s, α_t and α_n in kN/mm³ (10⁶ kPa/mm).
//!
//! Every function returns a [`SubfricStatus`] and writes a NUL-terminated message (truncated to
//! the buffer) on failure; no panic crosses the boundary. A model is immutable once built:
//! several threads may step points of the same model at once.
//!
//! The header `include/subfric.h` is generated from this file by cbindgen (`tests/header.rs`
//! checks that the committed header is up to date).

#![deny(unsafe_op_in_unsafe_fn)]

mod guards;

use guards::{all_finite, in_plane, read_model_file};
use std::ffi::{c_char, c_int, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};
use subfric_model::{Contact3, Model, ModelJsonError, Params, State3, StateSlots, StepError};

/// Number of doubles in a [`SubfricState`] (the number of solution-dependent state variables
/// of a friction subroutine that stores it): 12 of the contact and [`SUBFRIC_STATE_SLOTS`].
pub const SUBFRIC_STATE_LEN: usize = 17;

/// Number of slots in a [`SubfricState`] for the state variables of the model's effect
/// families (θ of rate and state, the contact's age under time healing, ...).
pub const SUBFRIC_STATE_SLOTS: usize = 5;

// The slots are the model's own, one for one.
const _: () = assert!(SUBFRIC_STATE_SLOTS == subfric_model::MAX_STATE_SLOTS);

/// What a call did.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SubfricStatus {
    /// Success.
    Ok = 0,
    /// A required pointer was NULL (the message names the argument).
    NullPointer = 1,
    /// Invalid model parameters (the message names each invalid one).
    InvalidParameters = 2,
    /// A JSON text that is not valid JSON or not a model.
    InvalidJson = 3,
    /// A file that cannot be read.
    Io = 4,
    /// An invalid argument of a step: slip, pressure, time increment or state (named).
    InvalidInput = 5,
    /// The return mapping did not converge: cut the increment (Abaqus: PNEWDT < 1).
    NoConvergence = 6,
    /// An internal error (a bug): the message says where.
    Internal = 7,
}

/// The base parameters of the model (the keys of `params.json`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubfricParams {
    /// Static friction coefficient μ_s.
    pub mu_s: f64,
    /// Kinetic friction coefficient μ_k (0 ≤ μ_k ≤ μ_s).
    pub mu_k: f64,
    /// Decay rate κ of μ with plastic slip [1/mm].
    pub kappa: f64,
    /// Recovery rate ξ of μ with time [1/s].
    pub xi: f64,
    /// Growth rate ũ of the normal-yield ratio [1/mm].
    pub u_tilde: f64,
    /// Tangential elastic modulus α_t [kN/mm³ = 10⁶ kPa/mm].
    pub alpha_t: f64,
    /// Normal elastic modulus α_n [kN/mm³] (not used by the step; for a penalty normal law).
    pub alpha_n: f64,
    /// Initial friction coefficient μ₀ in [μ_k, μ_s]; NaN means μ₀ = μ_s.
    pub mu_0: f64,
}

/// The state of one material point (17 doubles, no padding: it can live in the state-variable
/// array of a friction subroutine). Vectors are in the same frame as the slip increments.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubfricState {
    /// Tangential slip [mm], accumulated from the increments: a record. The step computes the
    /// traction from the increment itself, so however far a point slides (where doubles are
    /// further apart than its elastic slip) its traction stays exact.
    pub slip: [f64; 3],
    /// Tangential traction f_t [kPa].
    pub shear: [f64; 3],
    /// Friction coefficient μ.
    pub mu: f64,
    /// Normal-yield ratio r.
    pub r: f64,
    /// cos(π r / 2).
    pub cos_r: f64,
    /// sin(π r / 2).
    pub sin_r: f64,
    /// Accumulated plastic slip [mm].
    pub slip_path: f64,
    /// Time since the point started [s] (a registered term of time reads it).
    pub time: f64,
    /// The state variables of the model's effect families that integrate one, in the order
    /// the families are registered, as many as each declares: rate and state its θ [s] and the
    /// rate terms R and V of the last plastic step (kept at rest by a form locked at rest),
    /// time healing the time since plastic sliding [s] and its gain of its own on top of μ.
    /// Unused slots are 0. What they hold is the model's business, as the rest of the state:
    /// store them and hand them back; a message about one names it as its family does
    /// (`state_in.theta = ...`).
    pub slots: [f64; SUBFRIC_STATE_SLOTS],
}

/// What one step returns besides the new state.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SubfricResponse {
    /// Tangential traction f_t at the end of the step [kPa] (also in the new state).
    pub shear: [f64; 3],
    /// Full traction f = f_t − p n [kPa] (compression along −n).
    pub traction: [f64; 3],
    /// Consistent tangent ∂f_t/∂u [kPa/mm], row-major: `dshear_dslip[i][j]` = ∂f_t,i/∂Δu_j.
    pub dshear_dslip: [[f64; 3]; 3],
    /// ∂f_t/∂p at fixed slip [kPa/kPa].
    pub dshear_dpressure: [f64; 3],
    /// Plastic (frictional) slip increment of the step [mm].
    pub plastic_slip: [f64; 3],
    /// 1 if the step slid plastically, 0 if it was elastic.
    pub plastic: c_int,
}

/// A validated model and its contact plane (opaque to C).
#[derive(Debug)]
pub struct SubfricModel {
    model: Model,
    contact: Contact3,
    normal: [f64; 3],
}

const _: () = assert!(std::mem::size_of::<SubfricState>() == SUBFRIC_STATE_LEN * 8);

/// A failure: its status and message.
#[derive(Debug)]
struct Failure(SubfricStatus, String);

fn fail<T>(status: SubfricStatus, message: impl Into<String>) -> Result<T, Failure> {
    Err(Failure(status, message.into()))
}

/// Writes `message` into `buf` as a NUL-terminated string, truncated at a character boundary.
///
/// # Safety
/// `buf` is NULL or valid for writes of `len` bytes.
unsafe fn write_message(buf: *mut c_char, len: usize, message: &str) {
    if buf.is_null() || len == 0 {
        return;
    }
    let mut n = message.len().min(len - 1);
    while !message.is_char_boundary(n) {
        n -= 1;
    }
    // SAFETY: not NULL, valid for writes of `len` bytes by the contract; n + 1 <= len bytes
    // are written.
    unsafe {
        std::ptr::copy_nonoverlapping(message.as_ptr(), buf.cast::<u8>(), n);
        *buf.add(n) = 0;
    }
}

/// Runs `body` with panics caught, turning a failure or a panic into a status and a message.
///
/// # Safety
/// `msg` is NULL or valid for writes of `msg_len` bytes.
unsafe fn guard(
    msg: *mut c_char,
    msg_len: usize,
    body: impl FnOnce() -> Result<(), Failure>,
) -> SubfricStatus {
    let outcome = catch_unwind(AssertUnwindSafe(body)).unwrap_or_else(|panic| {
        let what = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".to_string());
        fail(SubfricStatus::Internal, format!("internal error: {what}"))
    });
    let (status, message) = match outcome {
        Ok(()) => (SubfricStatus::Ok, String::new()),
        Err(Failure(status, message)) => (status, message),
    };
    // SAFETY: `msg` is NULL or valid for `msg_len` bytes by the contract.
    unsafe { write_message(msg, msg_len, &message) };
    status
}

/// Reads a `T` through a pointer that must not be NULL.
///
/// # Safety
/// `p` is NULL or valid for reads of a `T` (any alignment).
unsafe fn read<T: Copy>(p: *const T, name: &str) -> Result<T, Failure> {
    if p.is_null() {
        return fail(SubfricStatus::NullPointer, format!("`{name}` is NULL"));
    }
    // SAFETY: not NULL, and valid for reads by the caller's contract.
    Ok(unsafe { p.read_unaligned() })
}

/// Reads three doubles, or `default` for a NULL pointer.
///
/// # Safety
/// `p` is NULL or valid for reads of three doubles.
unsafe fn read_vec3_or(p: *const f64, default: [f64; 3]) -> [f64; 3] {
    if p.is_null() {
        return default;
    }
    // SAFETY: not NULL, and valid for reads of three doubles by the caller's contract.
    unsafe { p.cast::<[f64; 3]>().read_unaligned() }
}

/// Writes a `T` through a pointer that must not be NULL.
///
/// # Safety
/// `p` is NULL or valid for writes of a `T` (any alignment).
unsafe fn write<T>(p: *mut T, value: T) {
    if !p.is_null() {
        // SAFETY: not NULL, and valid for writes by the caller's contract.
        unsafe { p.write_unaligned(value) }
    }
}

fn vec_name(v: &[f64; 3]) -> String {
    format!("[{}, {}, {}]", v[0], v[1], v[2])
}

/// Builds the handle on the plane `normal` (default e₃) with the forward axis `forward`
/// (default e₁) and writes it to `out`: the end of every constructor.
///
/// # Safety
/// `normal` and `forward` are NULL or valid for reads of three doubles; `out` is not NULL and
/// valid for writes.
unsafe fn hand_out(
    model: Model,
    normal: *const f64,
    forward: *const f64,
    out: *mut *mut SubfricModel,
) -> Result<(), Failure> {
    // SAFETY: NULL or three doubles by the caller's contract.
    let (n, f) = unsafe {
        (
            read_vec3_or(normal, [0.0, 0.0, 1.0]),
            read_vec3_or(forward, [1.0, 0.0, 0.0]),
        )
    };
    let handle = build(model, n, f, !forward.is_null())?;
    // SAFETY: not NULL and valid for writes by the caller's contract.
    unsafe { write(out, Box::into_raw(handle)) };
    Ok(())
}

/// Builds the handle, checking the plane's normal and forward axis (`given_forward`: the
/// caller passed one; the default matters only to a model with a direction effect).
fn build(
    model: Model,
    normal: [f64; 3],
    forward: [f64; 3],
    given_forward: bool,
) -> Result<Box<SubfricModel>, Failure> {
    let len = (normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2]).sqrt();
    if !(len.is_finite() && len > 0.0) {
        return fail(
            SubfricStatus::InvalidInput,
            format!(
                "normal = {} (expected a finite nonzero vector)",
                vec_name(&normal)
            ),
        );
    }
    if !forward.iter().all(|x| x.is_finite()) {
        return fail(
            SubfricStatus::InvalidInput,
            format!(
                "forward = {} (expected a finite vector)",
                vec_name(&forward)
            ),
        );
    }
    if !in_plane(&normal, &forward) && (given_forward || model.ext.terms.reads_direction()) {
        let what = if given_forward {
            format!("forward = {}", vec_name(&forward))
        } else {
            "forward NULL, i.e. (1, 0, 0),".to_string()
        };
        return fail(
            SubfricStatus::InvalidInput,
            format!(
                "{what} has no direction in the contact plane of normal = {} (expected an axis \
                 not parallel to the normal: the direction effect measures sliding from it)",
                vec_name(&normal)
            ),
        );
    }
    let contact = Contact3::new(&model, normal, forward);
    probe_steps(&model, &contact)?;
    let normal = normal.map(|x| x / len);
    Ok(Box::new(SubfricModel {
        model,
        contact,
        normal,
    }))
}

/// The slip increments (mm) of [`probe_steps`], one after the other from rest, each over 1 s
/// at 100 kPa: a micrometre to a millimetre per second, the rates of a laboratory test and of
/// a pile.
const PROBE_SLIPS: [f64; 3] = [1e-6, 1e-3, 1.0];

/// Refuses a model its own integrator cannot step: from the virgin state, the slip increments
/// of [`PROBE_SLIPS`] in turn along the plane at 100 kPa over 1 s each, then a hold of 1000 s,
/// must each converge to finite numbers. An extension parameter far beyond what the
/// doubles can carry through the return mapping (`rate.a = 1e300`: a friction change of 10³⁰⁰
/// per decade; `slip_hardening.h = 1e300` per mm) fails here, at construction, instead of
/// asking the finite-element code to cut every increment forever. No tuned bound: the model
/// is refused exactly when it cannot integrate an ordinary step.
fn probe_steps(model: &Model, contact: &Contact3) -> Result<(), Failure> {
    let along = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
        .into_iter()
        .map(|a| contact.tangential(&a))
        .find(|t| t.iter().map(|x| x * x).sum::<f64>() > 0.25)
        .unwrap_or([1.0, 0.0, 0.0]);
    let refuse = |what: String| {
        Failure(
            SubfricStatus::InvalidParameters,
            format!(
                "the model cannot take an ordinary step: {what} (expected extension parameters the integrator can carry: ext = {})",
                serde_json::to_string(&model.ext).unwrap_or_default()
            ),
        )
    };
    let mut st = State3::virgin(model, [0.0; 3]);
    let mut slid = 0.0;
    for du in PROBE_SLIPS {
        let inc = along.map(|x| x * du);
        let (next, _) = contact
            .step_increment_with_tangent(&st, &inc, 100.0, 1.0)
            .map_err(|e| {
                refuse(format!(
                    "a slip of {du} mm in 1 s at 100 kPa after {slid} mm from rest: {e}"
                ))
            })?;
        slid += du;
        let out = to_c(&next);
        if let Some((field, x)) = guards::first_not_finite(&out, model) {
            return Err(refuse(format!(
                "a slip of {du} mm in 1 s at 100 kPa gives {field} = {x}"
            )));
        }
        st = next;
    }
    let (held, _) = contact
        .step_increment_with_tangent(&st, &[0.0; 3], 100.0, 1000.0)
        .map_err(|e| refuse(format!("a hold of 1000 s after {slid} mm: {e}")))?;
    if let Some((field, x)) = guards::first_not_finite(&to_c(&held), model) {
        return Err(refuse(format!(
            "a hold of 1000 s after {slid} mm gives {field} = {x}"
        )));
    }
    Ok(())
}

fn params_of(p: &SubfricParams) -> Params {
    Params {
        mu_s: p.mu_s,
        mu_k: p.mu_k,
        kappa: p.kappa,
        xi: p.xi,
        u_tilde: p.u_tilde,
        alpha_t: p.alpha_t,
        alpha_n: p.alpha_n,
        mu_0: if p.mu_0.is_nan() { None } else { Some(p.mu_0) },
    }
}

fn invalid_parameters(e: impl std::fmt::Display) -> Failure {
    Failure(SubfricStatus::InvalidParameters, e.to_string())
}

/// Reads a model from JSON text with the workspace's one reader
/// ([`subfric_model::model_from_json`]: a `fit.json`, a model object `{"params", "ext"}`, an
/// `experiment.json` or a `params.json`): invalid values are `InvalidParameters`, anything
/// else `InvalidJson`.
fn model_from_json(text: &str) -> Result<Model, Failure> {
    subfric_model::model_from_json(text).map_err(|e| match e {
        ModelJsonError::Invalid(e) => invalid_parameters(e),
        e => Failure(SubfricStatus::InvalidJson, e.to_string()),
    })
}

/// Builds a model of the base parameters `params` on the contact plane of unit normal `normal`.
/// `normal` NULL means (0, 0, 1); `forward` (the axis of the direction extension, projected on
/// the plane) NULL means (1, 0, 0). A `forward` given as (0, 0, 0) or parallel to the normal
/// is refused (`SUBFRIC_STATUS_INVALID_INPUT`): it has no direction in the plane. So is the
/// default along the normal for a model with a direction effect. On success `*out` owns a
/// model to release with [`subfric_model_free`]; on failure `*out` is set to NULL.
///
/// # Safety
/// `params` and `out` are NULL or valid; `normal` and `forward` are NULL or point to three
/// doubles; `msg` is NULL or valid for writes of `msg_len` bytes.
#[no_mangle]
pub unsafe extern "C" fn subfric_model_new(
    params: *const SubfricParams,
    normal: *const f64,
    forward: *const f64,
    out: *mut *mut SubfricModel,
    msg: *mut c_char,
    msg_len: usize,
) -> SubfricStatus {
    let body = || {
        // SAFETY: `out` is NULL or valid by the contract.
        unsafe { write(out, std::ptr::null_mut()) };
        if out.is_null() {
            return fail(SubfricStatus::NullPointer, "`out` is NULL");
        }
        // SAFETY: `params` is NULL or valid by the contract.
        let p = unsafe { read(params, "params") }?;
        let model = Model::base(params_of(&p)).map_err(invalid_parameters)?;
        // SAFETY: the pointers as in this function's contract; `out` checked not NULL.
        unsafe { hand_out(model, normal, forward, out) }
    };
    // SAFETY: `msg` is NULL or valid for `msg_len` bytes by this function's contract.
    unsafe { guard(msg, msg_len, body) }
}

/// Builds a model (base parameters and extensions) from a NUL-terminated UTF-8 JSON text: a
/// `fit.json` written by `subfric fit` (its `model`), `{"params": {...}, "ext": {...}}`, an
/// `experiment.json` (its `reference_parameters`) or a `params.json`. `normal`, `forward` and
/// `out` as in [`subfric_model_new`].
///
/// # Safety
/// `json` is NULL or a NUL-terminated string; the other pointers as in [`subfric_model_new`].
#[no_mangle]
pub unsafe extern "C" fn subfric_model_from_json(
    json: *const c_char,
    normal: *const f64,
    forward: *const f64,
    out: *mut *mut SubfricModel,
    msg: *mut c_char,
    msg_len: usize,
) -> SubfricStatus {
    let body = || {
        // SAFETY: `out` is NULL or valid by the contract.
        unsafe { write(out, std::ptr::null_mut()) };
        if out.is_null() {
            return fail(SubfricStatus::NullPointer, "`out` is NULL");
        }
        if json.is_null() {
            return fail(SubfricStatus::NullPointer, "`json` is NULL");
        }
        // SAFETY: not NULL, and NUL-terminated by the contract.
        let text = unsafe { CStr::from_ptr(json) }.to_str().map_err(|e| {
            Failure(
                SubfricStatus::InvalidJson,
                format!("the JSON text is not UTF-8: {e}"),
            )
        })?;
        let model = model_from_json(text)?;
        // SAFETY: the pointers as in this function's contract; `out` checked not NULL.
        unsafe { hand_out(model, normal, forward, out) }
    };
    // SAFETY: `msg` is NULL or valid for `msg_len` bytes by this function's contract.
    unsafe { guard(msg, msg_len, body) }
}

/// As [`subfric_model_from_json`], reading the JSON from the file at `path` (e.g.
/// `fits/<set>/fit.json`); messages start with the path. Only a regular file of at most
/// [`SUBFRIC_MAX_MODEL_FILE_BYTES`] is read: a folder, a FIFO (which would block), a device
/// (`/dev/zero` would be read until memory runs out) or a larger file is refused with
/// `SUBFRIC_STATUS_IO`.
///
/// # Safety
/// `path` is NULL or a NUL-terminated string; the other pointers as in [`subfric_model_new`].
#[no_mangle]
pub unsafe extern "C" fn subfric_model_from_file(
    path: *const c_char,
    normal: *const f64,
    forward: *const f64,
    out: *mut *mut SubfricModel,
    msg: *mut c_char,
    msg_len: usize,
) -> SubfricStatus {
    let body = || {
        // SAFETY: `out` is NULL or valid by the contract.
        unsafe { write(out, std::ptr::null_mut()) };
        if out.is_null() {
            return fail(SubfricStatus::NullPointer, "`out` is NULL");
        }
        if path.is_null() {
            return fail(SubfricStatus::NullPointer, "`path` is NULL");
        }
        // SAFETY: not NULL, and NUL-terminated by the contract.
        let path = unsafe { CStr::from_ptr(path) }
            .to_string_lossy()
            .into_owned();
        let text = read_model_file(&path)?;
        let model =
            model_from_json(&text).map_err(|Failure(s, m)| Failure(s, format!("{path}: {m}")))?;
        // SAFETY: the pointers as in this function's contract; `out` checked not NULL.
        unsafe { hand_out(model, normal, forward, out) }
    };
    // SAFETY: `msg` is NULL or valid for `msg_len` bytes by this function's contract.
    unsafe { guard(msg, msg_len, body) }
}

/// Largest model file read [bytes]: a fit.json of a joint fit of ten thousand tests is a few
/// MB; a larger file is not a model, and reading it would only exhaust memory.
pub const SUBFRIC_MAX_MODEL_FILE_BYTES: u64 = 64 << 20;

/// Releases a model (NULL is ignored).
///
/// # Safety
/// `model` is NULL or a model from one of the constructors, not yet released.
#[no_mangle]
pub unsafe extern "C" fn subfric_model_free(model: *mut SubfricModel) {
    if model.is_null() {
        return;
    }
    // Dropping plain data cannot panic; the guard only keeps the boundary uniform.
    let body = || {
        // SAFETY: a pointer from Box::into_raw in a constructor, released once by the contract.
        drop(unsafe { Box::from_raw(model) });
        Ok(())
    };
    // SAFETY: a NULL message buffer is allowed.
    unsafe { guard(std::ptr::null_mut(), 0, body) };
}

/// Copies the base parameters of a model (e.g. α_n of a model read from JSON) into `*out`
/// (μ₀ NaN when it defaults to μ_s).
///
/// # Safety
/// `model` is NULL or a live model; `out` NULL or valid for writes; `msg` as in
/// [`subfric_model_new`].
#[no_mangle]
pub unsafe extern "C" fn subfric_model_params(
    model: *const SubfricModel,
    out: *mut SubfricParams,
    msg: *mut c_char,
    msg_len: usize,
) -> SubfricStatus {
    let body = || {
        if model.is_null() || out.is_null() {
            let name = if model.is_null() { "model" } else { "out" };
            return fail(SubfricStatus::NullPointer, format!("`{name}` is NULL"));
        }
        // SAFETY: not NULL, a live model by the contract.
        let p = unsafe { &*model }.model.params;
        let c = SubfricParams {
            mu_s: p.mu_s,
            mu_k: p.mu_k,
            kappa: p.kappa,
            xi: p.xi,
            u_tilde: p.u_tilde,
            alpha_t: p.alpha_t,
            alpha_n: p.alpha_n,
            mu_0: p.mu_0.unwrap_or(f64::NAN),
        };
        // SAFETY: not NULL (checked), valid for writes by the contract.
        unsafe { write(out, c) };
        Ok(())
    };
    // SAFETY: `msg` is NULL or valid for `msg_len` bytes by this function's contract.
    unsafe { guard(msg, msg_len, body) }
}

/// Sets `*out` to the virgin state of a model (no slip, no traction, μ = μ₀, r = 0): the
/// state of a contact point when it first closes.
///
/// # Safety
/// `model` is NULL or a live model; `out` NULL or valid for writes; `msg` as in
/// [`subfric_model_new`].
#[no_mangle]
pub unsafe extern "C" fn subfric_state_init(
    model: *const SubfricModel,
    out: *mut SubfricState,
    msg: *mut c_char,
    msg_len: usize,
) -> SubfricStatus {
    let body = || {
        if model.is_null() || out.is_null() {
            let name = if model.is_null() { "model" } else { "out" };
            return fail(SubfricStatus::NullPointer, format!("`{name}` is NULL"));
        }
        // SAFETY: not NULL, a live model by the contract.
        let m = unsafe { &*model };
        let st = State3::virgin(&m.model, [0.0; 3]);
        // SAFETY: not NULL (checked), valid for writes by the contract.
        unsafe { write(out, to_c(&st)) };
        Ok(())
    };
    // SAFETY: `msg` is NULL or valid for `msg_len` bytes by this function's contract.
    unsafe { guard(msg, msg_len, body) }
}

fn to_c(s: &State3) -> SubfricState {
    SubfricState {
        slip: s.slip,
        shear: s.shear,
        mu: s.mu,
        r: s.r,
        cos_r: s.cos_r,
        sin_r: s.sin_r,
        slip_path: s.slip_path,
        time: s.time,
        slots: s.slots.0,
    }
}

/// The state of `s`, if it is one the model can have (see [`Contact3::check_state`]).
fn from_c(m: &SubfricModel, s: &SubfricState) -> Result<State3, Failure> {
    if let Some((field, x)) = guards::first_not_finite(s, &m.model) {
        return Err(Failure(
            SubfricStatus::InvalidInput,
            format!(
                "state_in.{field} = {x} (expected a finite number: not a state the model writes); a new contact point starts from subfric_state_init"
            ),
        ));
    }
    let st = State3 {
        slip: s.slip,
        shear: s.shear,
        mu: s.mu,
        r: s.r,
        cos_r: s.cos_r,
        sin_r: s.sin_r,
        slip_path: s.slip_path,
        time: s.time,
        slots: StateSlots(s.slots),
    };
    m.contact.check_state(&st).map_err(|e| {
        Failure(
            SubfricStatus::InvalidInput,
            format!("state_in: {e}; a new contact point starts from subfric_state_init"),
        )
    })?;
    Ok(st)
}

/// One implicit step of a material point under slip control.
///
/// - `state_in`: the state at the start of the increment: one the model wrote (from
///   [`subfric_state_init`] or a step). A state it cannot have — an all-zero array, μ outside
///   the model's bounds, cos_r and sin_r not those of r, a non-finite number — is refused with
///   `SUBFRIC_STATUS_INVALID_INPUT` naming the field;
/// - `dslip`: the increment of relative tangential displacement Δu [mm] (three components in
///   the frame of the normal; its normal part is ignored);
/// - `pressure`: the contact pressure p > 0 at the end of the increment [kPa];
/// - `dt`: the time increment [s] (≥ 0; > 0 for a model with a rate extension);
/// - `state_out`: receives the state at the end (may be the same as `state_in`);
/// - `response`: receives the traction and its derivatives (may be NULL).
///
/// The traction follows from `dslip` itself, not from a difference of accumulated slips, so
/// it is exact however far the point has slid. A step whose result would not be finite is
/// refused. On failure neither `state_out` nor `response` is written.
///
/// # Safety
/// `model` is NULL or a live model; `state_in`, `state_out` and `response` are NULL or valid
/// (`state_in` and `state_out` may alias); `dslip` is NULL or points to three doubles; `msg` as
/// in [`subfric_model_new`].
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn subfric_step(
    model: *const SubfricModel,
    state_in: *const SubfricState,
    dslip: *const f64,
    pressure: f64,
    dt: f64,
    state_out: *mut SubfricState,
    response: *mut SubfricResponse,
    msg: *mut c_char,
    msg_len: usize,
) -> SubfricStatus {
    let body = || {
        if model.is_null() {
            return fail(SubfricStatus::NullPointer, "`model` is NULL");
        }
        if state_out.is_null() {
            return fail(SubfricStatus::NullPointer, "`state_out` is NULL");
        }
        // SAFETY: not NULL, a live model by the contract.
        let m = unsafe { &*model };
        // SAFETY: NULL or valid for reads by the contract; copied before anything is written.
        let st = from_c(m, &unsafe { read(state_in, "state_in") }?)?;
        // SAFETY: NULL or valid for reads of three doubles by the contract.
        let du = unsafe { read(dslip.cast::<[f64; 3]>(), "dslip") }?;
        if !du.iter().all(|x| x.is_finite()) {
            return fail(
                SubfricStatus::InvalidInput,
                format!("dslip = {} (expected finite numbers [mm])", vec_name(&du)),
            );
        }
        if !(pressure.is_finite() && pressure > 0.0) {
            return fail(
                SubfricStatus::InvalidInput,
                format!(
                    "pressure = {pressure} (expected a finite contact pressure > 0 [kPa]; \
                     call only for a closed contact)"
                ),
            );
        }
        if !(dt.is_finite() && dt >= 0.0) {
            return fail(
                SubfricStatus::InvalidInput,
                format!("dt = {dt} (expected a finite time increment >= 0 [s])"),
            );
        }
        if dt == 0.0 && m.model.ext.rate().is_some() {
            return fail(
                SubfricStatus::InvalidInput,
                "dt = 0 (expected a time increment > 0 [s]: the model has a rate effect)",
            );
        }
        // From the increment itself: exact however far the point has slid.
        let (next, tan) = m
            .contact
            .step_increment_with_tangent(&st, &du, pressure, dt)
            .map_err(|e| match e {
                StepError::NoConvergence { .. } => Failure(
                    SubfricStatus::NoConvergence,
                    format!("{e}: cut the increment"),
                ),
                StepError::Runaway { .. } => {
                    Failure(SubfricStatus::Internal, format!("internal error: {e}"))
                }
            })?;
        let n = &m.normal;
        let r = SubfricResponse {
            shear: next.shear,
            traction: std::array::from_fn(|i| next.shear[i] - pressure * n[i]),
            dshear_dslip: tan.d_slip,
            dshear_dpressure: tan.d_pressure,
            plastic_slip: tan.plastic_slip,
            plastic: c_int::from(tan.plastic_slip != [0.0; 3]),
        };
        // Never a success with a number that is not one: a state at the edge of the doubles
        // (a slip record near 1e308, say) is refused rather than stepped into infinity.
        let out = to_c(&next);
        if !all_finite(&out, &m.model, &r) {
            return fail(
                SubfricStatus::InvalidInput,
                format!(
                    "state_in with dslip = {} gives numbers beyond the doubles (slip {}, shear \
                     {}): not a state to step from",
                    vec_name(&du),
                    vec_name(&next.slip),
                    vec_name(&next.shear)
                ),
            );
        }
        // SAFETY: not NULL (checked) and valid for writes by the contract; `state_in` was
        // copied above, so aliasing `state_out` is fine.
        unsafe { write(state_out, out) };
        // SAFETY: NULL (skipped) or valid for writes by the contract.
        unsafe { write(response, r) };
        Ok(())
    };
    // SAFETY: `msg` is NULL or valid for `msg_len` bytes by this function's contract.
    unsafe { guard(msg, msg_len, body) }
}

/// The version of the library, a static NUL-terminated string.
#[no_mangle]
pub extern "C" fn subfric_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

#[cfg(test)]
mod tests;
