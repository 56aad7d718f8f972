//! # subfric-harness
//!
//! Research harnesses: measurements *of* subfric on data it generates, not parts of it. They
//! live here rather than in the libraries' public API so that a library's API is what a user
//! of the library needs.
//!
//! - [`coverage`]: do the reported 95 % intervals hold the truth 95 % of the time? Generated
//!   multi-test campaigns fitted by the default calibration
//!   (`cargo run --release -p subfric-harness --example coverage -- --campaigns 40 --seed 1`).

pub mod coverage;
