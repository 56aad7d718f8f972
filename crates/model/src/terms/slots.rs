//! The registered families switched on in a model ([`Terms`]): one slot per family, what the
//! integrator asks of them together, and their place in parameter files.

use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::{
    family_keyed, FamilyLaw, RateEffect, StateLaw, TermEffect, TermFamily, MAX_FAMILIES,
    MAX_STATE_SLOTS,
};
use crate::Target;

/// A kind of family a model may hold once.
type Kind = fn(&dyn TermFamily) -> bool;

/// The registered families switched on in a model, at most one form each (slot `i` holds
/// family `i` of [`FAMILIES`](super::FAMILIES)). In a parameter file each is an object under the family's key;
/// the reader also takes the `term` object of older files (`{"family": ..., ...}`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Terms([Option<TermEffect>; MAX_FAMILIES]);

impl Terms {
    /// No registered family.
    pub const NONE: Terms = Terms([None; MAX_FAMILIES]);

    /// Just `e`.
    pub fn one(e: TermEffect) -> Terms {
        let mut t = Terms::NONE;
        t.insert(e);
        t
    }

    /// These families and `e` (in place of the same family's, if on).
    pub fn with(mut self, e: TermEffect) -> Terms {
        self.insert(e);
        self
    }

    /// True when no registered family is on.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.0.iter().all(Option::is_none)
    }

    /// The families that are on, in registry order.
    #[inline]
    pub fn iter(&self) -> impl Iterator<Item = &TermEffect> {
        self.0.iter().flatten()
    }

    /// Family `family`, when on.
    #[inline]
    pub fn of(&self, family: u8) -> Option<TermEffect> {
        self.0.get(family as usize).copied().flatten()
    }

    /// Family `family`, to change it in place, when on.
    pub fn of_mut(&mut self, family: u8) -> Option<&mut TermEffect> {
        self.0.get_mut(family as usize).and_then(Option::as_mut)
    }

    /// Switches `e` on (in place of the same family's, if on); returns it to change in place.
    pub fn insert(&mut self, e: TermEffect) -> &mut TermEffect {
        self.0[e.family as usize].insert(e)
    }

    /// Every family of `self`, with those of `other` that `self` does not have.
    pub fn or(self, other: Terms) -> Terms {
        let mut out = self;
        for (slot, theirs) in out.0.iter_mut().zip(other.0) {
            if slot.is_none() {
                *slot = theirs;
            }
        }
        out
    }

    /// (key, value, expected) of every invalid parameter, a second family that gains friction
    /// at rest or reads the slip rate (the contact holds one gain at rest and one rate law), and
    /// a family whose state variables do not fit the contact's slots beside the others'.
    pub fn issues(&self) -> Vec<(&'static str, f64, &'static str)> {
        let mut out: Vec<_> = self.iter().flat_map(TermEffect::issues).collect();
        let single: [(Kind, &'static str); 2] = [
            (
                |f| f.gains_at_rest(),
                "one family that gains friction at rest, not two",
            ),
            (
                |f| f.reads_slip_rate(),
                "one family that reads the slip rate, not two",
            ),
        ];
        for (kind, expected) in single {
            if let Some(second) = self.iter().filter(|e| kind(e.family())).nth(1) {
                out.push((second.family().params()[0].key, second.p[0], expected));
            }
        }
        // The contact states hold MAX_STATE_SLOTS state variables: the family whose variables
        // would go beyond them is named.
        let mut used = 0;
        for e in self.iter() {
            used += FamilyLaw::of(e).map_or(0, |law| law.vars().len());
            if used > MAX_STATE_SLOTS {
                out.push((
                    e.family().params()[0].key,
                    e.p[0],
                    "families whose state variables fit the contact's slots together",
                ));
                break;
            }
        }
        out
    }

    /// The slip-rate law of the family on that reads the slip rate, if any.
    #[inline]
    pub fn rate_law(&self) -> Option<RateEffect> {
        self.iter()
            .find_map(|e| e.family().slip_rate_law(e.form as usize, &e.p))
    }

    /// True unless a family on replaces the recovery ξ(μ_s − μ) of Eq. (24).
    #[inline]
    pub fn recovery(&self) -> bool {
        self.iter()
            .all(|e| !e.family().replaces_recovery(e.form as usize))
    }

    /// Sum of every family's T and ∂T/∂s at accumulated plastic slip `s` and time `t`.
    #[inline]
    pub fn total(&self, s: f64, t: f64) -> (f64, f64) {
        self.iter().fold((0.0, 0.0), |(v, d), e| {
            let (a, b) = e.term(s, t);
            (v + a, d + b)
        })
    }

    /// True when a family on adds a term T.
    #[inline]
    pub fn adds_terms(&self) -> bool {
        self.iter().any(|e| e.family().adds_term())
    }

    /// The product of every family's factor on `target` at normal stress `normal_kpa` and
    /// sliding direction `cos_forward` ([`TermLaw::factor_on`]).
    #[inline]
    pub fn factor_on(&self, target: Target, normal_kpa: f64, cos_forward: f64) -> f64 {
        self.iter().fold(1.0, |f, e| {
            f * e
                .family()
                .factor_on(e.form as usize, &e.p, target, normal_kpa, cos_forward)
        })
    }

    /// The least and greatest product of the factors on `target` over every condition.
    pub fn range_on(&self, target: Target) -> (f64, f64) {
        self.iter().fold((1.0, 1.0), |(lo, hi), e| {
            let (a, b) = e.family().range_on(e.form as usize, &e.p, target);
            (lo * a, hi * b)
        })
    }

    /// True when a family on scales μ or its bounds.
    pub fn has_factors(&self) -> bool {
        self.iter()
            .any(|e| !e.family().targets(e.form as usize).is_empty())
    }

    /// True when a family on scales anything but μ as a whole (the integrator then builds the
    /// bounds per step).
    pub fn varies_bounds(&self) -> bool {
        self.iter().any(|e| {
            e.family()
                .targets(e.form as usize)
                .iter()
                .any(|&t| t != Target::Friction)
        })
    }

    /// True when a family on reads the sliding direction.
    pub fn reads_direction(&self) -> bool {
        self.iter().any(|e| e.family().reads_direction())
    }

    /// True when a family on reads the normal stress.
    pub fn reads_normal_stress(&self) -> bool {
        self.iter().any(|e| e.family().reads_normal_stress())
    }
}

// Inside `ext`, beside the other extensions (the `Extensions` field is flattened): each family
// under its key, without its name.
impl Serialize for Terms {
    fn serialize<S: Serializer>(&self, ser: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        struct Body<'a>(&'a TermEffect);
        impl Serialize for Body<'_> {
            fn serialize<S: Serializer>(&self, ser: S) -> Result<S::Ok, S::Error> {
                self.0.write(ser, false)
            }
        }
        let mut map = ser.serialize_map(Some(self.iter().count()))?;
        for e in self.iter() {
            map.serialize_entry(&e.family().key(), &Body(e))?;
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for Terms {
    fn deserialize<D: Deserializer<'de>>(de: D) -> Result<Self, D::Error> {
        // Keys that are no family are left alone: the reader of parameter files refuses every
        // key it cannot write back.
        let map = serde_json::Map::<String, serde_json::Value>::deserialize(de)?;
        let mut out = Terms::NONE;
        for (key, value) in &map {
            if value.is_null() {
                continue;
            }
            let e = if key == "term" {
                TermEffect::deserialize(value).map_err(D::Error::custom)?
            } else if let Some((index, _)) = family_keyed(key) {
                let Some(obj) = value.as_object() else {
                    return Err(D::Error::custom(format!(
                        "`{key}` is {value} (expected an object of the family's form and parameters)"
                    )));
                };
                TermEffect::read(index, obj).map_err(D::Error::custom)?
            } else {
                continue;
            };
            if out.of(e.family).is_some() {
                return Err(D::Error::custom(format!(
                    "family `{}` given twice (under `{}` and `term`)",
                    e.family().name(),
                    e.family().key()
                )));
            }
            out.insert(e);
        }
        Ok(out)
    }
}
