//! # subfric-solve
//!
//! The bounded nonlinear least-squares solver the calibration (`subfric-fit`) and the events
//! read one by one (`subfric-reading`: every velocity step's spring-slider fit) share:
//!
//! - [`residuals`]: what a solver needs from a problem ([`Residuals`]: its box and its
//!   residual vector), and nothing more;
//! - [`lm`]: Levenberg–Marquardt in a box, with a forward-difference Jacobian
//!   ([`lm::levenberg_marquardt`], [`lm::jacobian`]), written as an argmin `Solver`.
//!
//! It sits below both so that reading a record needs no calibration. Its unit tests run the
//! solver on the MINPACK problems with known answers (`test_problems`, public for the other
//! crates' tests: `subfric-fit`'s global stage and intervals run on the same trait).

pub mod lm;
pub mod residuals;

// Public, not behind a feature: a feature that only the test programs switch on would build
// this crate, and every crate above it, a second time for the Python extension
// (`tests/e2e/python.rs`).
#[doc(hidden)]
pub mod test_problems;

pub use lm::{jacobian, levenberg_marquardt, LmOptions, LmResult, Termination};
pub use residuals::{Bounded, Residuals};
