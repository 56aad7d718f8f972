//! The registry macro: one line per family (see [`super::FAMILIES`]).

/// The registry: declares each family's folder (`terms/<module>/`) and lists its unit struct in
/// [`FAMILIES`](super::FAMILIES), one line per family, so that a new family is its folder and one
/// line (a line may carry attributes, e.g. `#[cfg(test)]` for a family only the tests know).
///
/// A family with a state ([`StateFamily`](super::StateFamily)) ends its line with `with state`:
/// its built law is then one arm of [`FamilyLaw`](super::FamilyLaw), the enum the integrator
/// keeps the laws of a model in and calls them through, by a `match` the compiler sees through
/// rather than a call through a trait object.
macro_rules! registry {
    // Sorts the lines into every family and the families with a state, then declares them.
    (@sort [$($all:tt)*] [$($stateful:tt)*]
        $(#[$attr:meta])* $module:ident::$family:ident with state, $($rest:tt)*) => {
        registry!(@sort
            [$($all)* $(#[$attr])* $module::$family,]
            [$($stateful)* $(#[$attr])* $module::$family,]
            $($rest)*);
    };
    (@sort [$($all:tt)*] [$($stateful:tt)*]
        $(#[$attr:meta])* $module:ident::$family:ident, $($rest:tt)*) => {
        registry!(@sort [$($all)* $(#[$attr])* $module::$family,] [$($stateful)*] $($rest)*);
    };
    (@sort
        [$($(#[$attr:meta])* $module:ident::$family:ident,)*]
        [$($(#[$sattr:meta])* $smodule:ident::$sfamily:ident,)*]) => {
        $($(#[$attr])* mod $module;)*

        /// The registered families, in the order the diagnosis tries them.
        pub static FAMILIES: &[&dyn TermFamily] = &[$($(#[$attr])* &$module::$family,)*];

        /// The state law of a family switched on in a model, built for its form and parameters
        /// ([`StateFamily::law`]): one variant per registered family with a state.
        #[derive(Clone, Copy, Debug)]
        pub enum FamilyLaw {
            $($(#[$sattr])* $sfamily(<$smodule::$sfamily as StateFamily>::Law),)*
        }

        impl FamilyLaw {
            /// The state law of `e`, built, when its family integrates a state.
            pub fn of(e: &TermEffect) -> Option<FamilyLaw> {
                let name = e.family().name();
                $($(#[$sattr])* {
                    let family = &$smodule::$sfamily;
                    if name == TermLaw::name(family) {
                        let law = StateFamily::law(family, e.form as usize, &e.p);
                        return Some(FamilyLaw::$sfamily(law));
                    }
                })*
                None
            }
        }

        impl FamilyLaw {
            /// Does `op` with the law by its own type.
            #[inline(always)]
            pub(crate) fn apply<O: LawOp>(&self, op: O) -> O::Output {
                match self {
                    $($(#[$sattr])* FamilyLaw::$sfamily(law) => op.apply(law),)*
                }
            }
        }

        impl StateLaw for FamilyLaw {
            #[inline]
            fn vars(&self) -> &'static [StateVar] {
                match self {
                    $($(#[$sattr])* FamilyLaw::$sfamily(law) => law.vars(),)*
                }
            }

            #[inline]
            fn initial(&self, x: &mut [f64]) {
                match self {
                    $($(#[$sattr])* FamilyLaw::$sfamily(law) => law.initial(x),)*
                }
            }

            #[inline]
            fn steady(&self, v: f64, x: &mut [f64]) {
                match self {
                    $($(#[$sattr])* FamilyLaw::$sfamily(law) => law.steady(v, x),)*
                }
            }

            #[inline]
            fn invalid(&self, x: &[f64]) -> Option<(usize, &'static str)> {
                match self {
                    $($(#[$sattr])* FamilyLaw::$sfamily(law) => law.invalid(x),)*
                }
            }

            #[inline(always)]
            fn rest(&self, x: &mut [f64], dt: f64) -> Option<f64> {
                match self {
                    $($(#[$sattr])* FamilyLaw::$sfamily(law) => law.rest(x, dt),)*
                }
            }

            #[inline(always)]
            fn at_rest(&self, x: &[f64]) -> StateTerms {
                match self {
                    $($(#[$sattr])* FamilyLaw::$sfamily(law) => law.at_rest(x),)*
                }
            }

            #[inline(always)]
            fn slide(&self, start: &[f64], dt: f64, lam: f64, end: &mut [f64]) -> StateTerms {
                match self {
                    $($(#[$sattr])* FamilyLaw::$sfamily(law) => law.slide(start, dt, lam, end),)*
                }
            }

            #[inline(always)]
            fn settle(&self, start: &[f64], lam: f64, end: &mut [f64]) {
                match self {
                    $($(#[$sattr])* FamilyLaw::$sfamily(law) => law.settle(start, lam, end),)*
                }
            }
        }
    };
    ($($line:tt)*) => {
        registry!(@sort [] [] $($line)*);
    };
}
