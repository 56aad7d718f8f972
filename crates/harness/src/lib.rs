//! # subfric-harness
//!
//! Research harnesses: measurements *of* subfric on data it generates, not parts of it. They
//! live here rather than in the libraries' public API so that a library's API is what a user
//! of the library needs.
//!
//! - [`coverage`]: do the reported 95 % intervals hold the truth 95 % of the time? Generated
//!   multi-test campaigns fitted by the default calibration
//!   (`cargo run --release -p subfric-harness --example coverage -- --campaigns 40 --seed 1`).
//! - [`generator`]: the self-check generator (`subfric selfcheck`): sand–steel sets with withheld
//!   effects and rig artifacts, made by its own forward model of the paper, sharing no model
//!   code with what it checks (`docs/selfcheck-generator.md`).

pub mod coverage;
pub mod generator;
