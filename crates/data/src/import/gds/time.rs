//! The time of a GDS file that logs none: the slip travelled over the rate of displacement.

use super::names::{stated_unit, Role};
use super::Mapper;
use crate::import::RateUnit;
use crate::plausible::Warning;

impl Mapper<'_> {
    /// Time from the displacement and the rate of shear displacement (a single value or a
    /// channel): each row's time is the slip travelled so far over the rate. The rate's unit
    /// is the one its name states, else `--rate-unit`, else the file is refused.
    pub(super) fn time_from_rate(
        &mut self,
        slip: Option<&[Option<f64>]>,
        notes: &mut Vec<Warning>,
    ) -> Option<Vec<Option<f64>>> {
        let n = self.raw.places.len();
        let rate_channel = self.channel_of(|r| r == Role::Rate);
        let (name, line) = match (rate_channel, self.single_of(Role::Rate)) {
            (Some(k), _) => (self.raw.channels[k].name.clone(), self.raw.channels[k].line),
            (None, Some((k, _, l))) => (k.clone(), *l),
            (None, None) => {
                self.pr.add(self.lf, None, Some("time"), "no time channel and no rate of shear displacement to reckon the time from (expected a `Time` channel, or a `Rate` line with --rate-unit)");
                return None;
            }
        };
        let unit = self.rate_unit(&name, line)?;
        let per_s = unit.to_mm_per_s();
        let rates: Vec<Option<f64>> = match rate_channel {
            // Read as written and converted unrounded: the time divides by it, and rounding
            // 0.1 mm/min to the digits of mm/s would put 2 % into every time.
            Some(k) => self
                .values(k, |_| 1.0)
                .into_iter()
                .map(|r| r.map(|r| r * per_s))
                .collect(),
            None => {
                let (x, _, _) = self.single_number(Role::Rate)?;
                vec![Some(x * per_s); n]
            }
        };
        let slip = slip?;
        // The clock restarts with each stage: the travel between stages (a box set back) is
        // not shearing at the rate.
        let stage = self
            .channel_of(|r| r == Role::Stage)
            .map(|k| self.raw.channels[k].cells.clone());
        let mut t = 0.0;
        let mut prev: Option<f64> = None;
        let mut out = Vec::with_capacity(n);
        // The stage of the rows so far: a row whose stage cell is missing stays in it.
        let mut current: Option<String> = None;
        for (i, (s, r)) in slip.iter().zip(&rates).enumerate() {
            if let Some(cell) = stage.as_ref().map(|st| st[i].as_str()) {
                if !crate::gaps::is_missing(cell) {
                    let label = crate::import::stage::label_of(cell);
                    if current.as_ref().is_some_and(|c| *c != label) {
                        t = 0.0;
                        prev = None;
                    }
                    current = Some(label);
                }
            }
            match (s, r) {
                (Some(s), Some(r)) if *r > 0.0 => {
                    if let Some(p) = prev {
                        t += (s - p).abs() / r;
                    }
                    prev = Some(*s);
                    // Rounded to a thousandth of a second: the slip's digits carry no more.
                    out.push(Some((t * 1e3).round() / 1e3));
                }
                _ => out.push(None),
            }
        }
        let rate_text = match rate_channel {
            Some(_) => format!("the rates of channel `{name}`"),
            None => format!(
                "the stated rate {} {unit}",
                crate::text::short_number(rates.first().copied().flatten().unwrap_or(0.0) / per_s)
            ),
        };
        notes.push(self.note(
            "time_s",
            format!(
                "no time in the file: each row's time is the slip travelled so far in its stage over {rate_text}{} — a record that holds or changes rate unlogged is not what this time says",
                if self.spec.rate_unit.is_some() { " (unit from --rate-unit)" } else { "" }
            ),
        ));
        Some(out)
    }

    /// The unit of the rate channel or value `name` (on line `line`): the one its name states,
    /// else `--rate-unit`; `None`, with the problem added, when they contradict, when the stated
    /// one is not a unit of rate, or when neither says.
    fn rate_unit(&mut self, name: &str, line: usize) -> Option<RateUnit> {
        let unit = match (stated_unit(name), self.spec.rate_unit) {
            // The file's own unit stands; --rate-unit is for a file that states none, and one
            // that contradicts the file is refused rather than chosen between.
            (Some(stated), Some(given)) => match stated.parse::<RateUnit>() {
                Ok(u) if u == given => u,
                Ok(u) => {
                    self.pr.add(
                        self.lf,
                        Some(line).filter(|&l| l > 0),
                        Some(name),
                        format!("the file states the rate in {u}, --rate-unit says {given} (expected --rate-unit only for a rate that states no unit, or the same unit)"),
                    );
                    return None;
                }
                Err(e) => {
                    self.pr
                        .add(self.lf, Some(line).filter(|&l| l > 0), Some(name), e);
                    return None;
                }
            },
            (None, Some(u)) => u,
            (Some(u), None) => match u.parse::<RateUnit>() {
                Ok(u) => u,
                Err(e) => {
                    self.pr
                        .add(self.lf, Some(line).filter(|&l| l > 0), Some(name), e);
                    return None;
                }
            },
            (None, None) => {
                self.pr.add(
                    self.lf,
                    Some(line).filter(|&l| l > 0),
                    Some(name),
                    "the rate of shear displacement states no unit, and the file has no time (expected --rate-unit, e.g. mm/min, to reckon the time from the displacement)",
                );
                return None;
            }
        };
        Some(unit)
    }
}
