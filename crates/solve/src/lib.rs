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
//! solver on the MINPACK problems with known answers (`test_problems`, public to the other
//! crates' tests through the `test-problems` feature).

pub mod lm;
pub mod residuals;

#[cfg(any(test, feature = "test-problems"))]
pub mod test_problems;

pub use lm::{jacobian, levenberg_marquardt, LmOptions, LmResult, Termination};
pub use residuals::Residuals;
