//! The C interface's guards against input no model point should see: a forward axis without
//! a direction in the plane, a model "file" that is a FIFO or a device, and a step whose
//! numbers would not be finite.

use crate::{Failure, SubfricResponse, SubfricState, SubfricStatus, SUBFRIC_MAX_MODEL_FILE_BYTES};
use subfric_model::Model;

/// Smallest share of the forward axis that must lie in the contact plane: below it the axis
/// is parallel to the normal to round-off and its projection, the direction of "forward", is
/// noise.
const MIN_FORWARD_IN_PLANE: f64 = 1e-6;

/// Whether `forward` has a direction in the plane of normal `normal` (both finite, the normal
/// nonzero).
pub(crate) fn in_plane(normal: &[f64; 3], forward: &[f64; 3]) -> bool {
    let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let n = normal.map(|x| x / dot(normal, normal).sqrt());
    let along = dot(forward, &n);
    let plane: [f64; 3] = std::array::from_fn(|i| forward[i] - along * n[i]);
    let length = dot(forward, forward).sqrt();
    length > 0.0 && dot(&plane, &plane).sqrt() > MIN_FORWARD_IN_PLANE * length
}

/// The text of the model file at `path`: a regular file (a FIFO would block the caller until
/// a writer comes, a device like /dev/zero would be read until memory runs out) of at most
/// [`SUBFRIC_MAX_MODEL_FILE_BYTES`].
pub(crate) fn read_model_file(path: &str) -> Result<String, Failure> {
    use std::io::Read;
    let io = |what: String| Failure(SubfricStatus::Io, format!("{path}: {what}"));
    // Checked before opening: opening a FIFO for reading blocks.
    let meta =
        std::fs::metadata(path).map_err(|e| io(format!("cannot read the parameter file: {e}")))?;
    let kind = |m: &std::fs::Metadata| {
        if m.is_dir() {
            Some("a folder")
        } else if !m.is_file() {
            Some("not a regular file (a FIFO, socket or device)")
        } else {
            None
        }
    };
    let too_big = |len: u64| {
        io(format!(
            "the parameter file holds {len} bytes or more (expected a JSON model of at most \
             {SUBFRIC_MAX_MODEL_FILE_BYTES} bytes)"
        ))
    };
    if let Some(k) = kind(&meta) {
        return Err(io(format!("is {k} (expected a JSON file)")));
    }
    if meta.len() > SUBFRIC_MAX_MODEL_FILE_BYTES {
        return Err(too_big(meta.len()));
    }
    let file = std::fs::File::open(path)
        .map_err(|e| io(format!("cannot read the parameter file: {e}")))?;
    // The file may have been replaced since: check what was opened, and read no more than
    // the limit whatever it is.
    if let Some(k) = file.metadata().ok().as_ref().and_then(kind) {
        return Err(io(format!("is {k} (expected a JSON file)")));
    }
    let mut bytes = Vec::new();
    file.take(SUBFRIC_MAX_MODEL_FILE_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| io(format!("cannot read the parameter file: {e}")))?;
    if bytes.len() as u64 > SUBFRIC_MAX_MODEL_FILE_BYTES {
        return Err(too_big(bytes.len() as u64));
    }
    String::from_utf8(bytes).map_err(|e| {
        Failure(
            SubfricStatus::InvalidJson,
            format!("{path}: the JSON text is not UTF-8: {e}"),
        )
    })
}

/// Every number of a state, by name, in the order of the struct: destructured, so that a field
/// added to [`SubfricState`] cannot be left out of a guard (it would not compile). The slots are
/// named as the families of `model` name their state variables (`slots[i]` for unused ones).
pub(crate) fn state_numbers(
    s: &SubfricState,
    model: &Model,
) -> [(&'static str, f64); crate::SUBFRIC_STATE_LEN] {
    let SubfricState {
        slip,
        shear,
        mu,
        r,
        cos_r,
        sin_r,
        slip_path,
        time,
        slots,
    } = *s;
    let contact = [
        ("slip[0]", slip[0]),
        ("slip[1]", slip[1]),
        ("slip[2]", slip[2]),
        ("shear[0]", shear[0]),
        ("shear[1]", shear[1]),
        ("shear[2]", shear[2]),
        ("mu", mu),
        ("r", r),
        ("cos_r", cos_r),
        ("sin_r", sin_r),
        ("slip_path", slip_path),
        ("time", time),
    ];
    const _: () = assert!(12 + crate::SUBFRIC_STATE_SLOTS == crate::SUBFRIC_STATE_LEN);
    let names = model.ext.terms.slot_names();
    std::array::from_fn(|i| match i.checked_sub(contact.len()) {
        None => contact[i],
        Some(k) => (names[k], slots[k]),
    })
}

/// The first field of a state that is not a finite number, by name (as `model` names its
/// slots), with its value.
pub(crate) fn first_not_finite(s: &SubfricState, model: &Model) -> Option<(&'static str, f64)> {
    state_numbers(s, model)
        .into_iter()
        .find(|(_, x)| !x.is_finite())
}

/// Whether every number of a step's result (state and response) is finite.
pub(crate) fn all_finite(out: &SubfricState, model: &Model, r: &SubfricResponse) -> bool {
    first_not_finite(out, model).is_none()
        && r.shear
            .iter()
            .chain(&r.traction)
            .chain(r.dshear_dslip.iter().flatten())
            .chain(&r.dshear_dpressure)
            .chain(&r.plastic_slip)
            .all(|x| x.is_finite())
}
