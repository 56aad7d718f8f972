//! # subfric-reading
//!
//! What a subfric record says before any global model is fitted to it, read once for the
//! calibration (`subfric-fit`), the diagnosis (`subfric-diagnose`) and the application layer:
//!
//! - [`segment()`]: loading phases (initial loading, steady sliding, velocity steps, holds,
//!   unloading, reversals) and cycles, on the imposed column conditioned at the resolution of
//!   the data ([`condition`], [`imposed`]: the events of the imposed column; [`normal`]: the
//!   normal-stress column the model is given);
//! - [`artifacts`]: rig and logger artifacts (a seating toe, a gap closed in the record);
//! - [`noise`]: the noise of a column, white and slow;
//! - [`summary()`]: a readable table of a set for `subfric check`;
//! - [`stats`]: the small statistics every reading shares (medians, quantiles, the
//!   least-squares line, the autocorrelation).
//!
//! File formats, located errors and the I/O of records are `subfric-data`'s; this crate reads
//! the records that crate loads.

#![warn(missing_docs)]

pub mod artifacts;
pub mod condition;
pub mod imposed;
pub mod noise;
pub mod normal;
pub mod segment;
pub mod stats;
pub mod summary;

pub use artifacts::{
    close_gap, gap_remainder, seating_toe, without_gap_rows, GapRemainder, SeatingToe,
};
pub use condition::{condition_imposed, condition_imposed_with, Conditioned};
pub use noise::{estimate_noise, NoiseEstimate};
pub use segment::{
    segment, RateLevel, Segment, SegmentKind, SegmentOptions, Segmentation, Start, StartKind,
};
pub use summary::{
    reading_lines, summary, summary_with, HoldSummary, SetSummary, StepSummary, TestSummary,
};
