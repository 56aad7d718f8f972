//! The self-check generator: sand–steel test sets with known effects and rig artifacts, made
//! by a forward model written here from the paper's equations ([`forward`]), with effects in
//! forms from the friction literature ([`effects`]), drawn over the literature's ranges
//! ([`draw`]), driven through lab protocols ([`path`]), recorded as a logger would
//! ([`record`]) and written with their truth ([`campaign`]). It shares no model code with
//! what it checks: `subfric_model` appears only in a test that compares the two base models.
//! Documentation: `docs/selfcheck-generator.md`.

pub mod campaign;
pub mod dense_sand;
pub mod draw;
pub mod effects;
pub mod forward;
pub mod path;
pub mod record;

pub use campaign::{
    all_classes, campaign_set, class_label, classes_of, generate, generate_seeded, long_record_set,
    write_campaign, Class, Generated, Layout, Options, Truth,
};
pub use dense_sand::dense_sand_programme;
pub use draw::{Form, Profile};
