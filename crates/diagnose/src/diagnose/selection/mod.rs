//! Screening every form, polishing the best of each family, and the forward selection on
//! held-out pieces, one file per step:
//!
//! - [`screening`]: every form fitted on the base and ranked, the best of each family polished;
//!   at a later stage, the families refitted on top of the current model;
//! - [`scoring`]: each candidate added to the current model and scored on the held-out pieces
//!   (all of them, its own kinds, where the events show it), and the drift of the measurement;
//! - [`stage`]: one stage and its decision (the first effect, a further one, what the events
//!   read one by one credit);
//! - [`forward`]: the stages in turn, how many of the effects taken are named, the backward step.

use super::context::{parameters_of, switched_off, Context, Current, SpecFit};
use super::report::{
    CandidateScore, DroppedEffect, FormReport, KindShrink, OwnKindScore, SelectionStage,
};
use crate::candidates::{Effect, Form, OwnKind};
use crate::fits::{residuals, with_values, Effort, Spec};
use crate::folds::{Piece, PieceKind};
use crate::score::{by_kind, Comparison, HeldOut};
use crate::verdict::{
    decide_among, decide_further, drift_outweighs, material, named_count, named_over_drift,
    Decision,
};
use rayon::prelude::*;
use std::collections::BTreeMap;
use subfric_model::Model;

mod forward;
mod scoring;
mod screening;
mod stage;

use scoring::*;
use screening::*;
use stage::*;

pub(super) use forward::{forward_selection, Selection};
pub(super) use screening::screen_and_polish;

#[cfg(test)]
mod shown_tests;
#[cfg(test)]
mod tests;
