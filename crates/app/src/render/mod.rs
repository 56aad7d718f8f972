//! Everything a person reads, in one place: the fit's table ([`fit_report`]), the diagnosis's
//! text ([`diagnose_report`], its event readings [`events_report`] and their figures), the
//! HTML reports ([`report`] and [`diagnosis_page`], pages of [`html`]) and the overlay figures
//! ([`figures`]). A report reads an outcome ([`crate::outcome`]) and never the reverse.

pub mod diagnose_report;
pub mod diagnosis_page;
pub(crate) mod events_figures;
pub(crate) mod events_report;
pub mod figures;
pub mod fit_report;
pub mod html;
pub mod report;
