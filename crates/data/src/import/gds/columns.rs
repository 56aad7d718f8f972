//! The test's columns from a GDS file's channels: slip, stresses, area, further channels.

use super::names::{area_unit, stated_unit, Role};
use super::{missing_role, Mapper};
use crate::import::{LengthUnit, StressUnit};

impl Mapper<'_> {
    /// A stress column [kPa]: the channel of `stress_role` in its unit, else the channel of
    /// `force_role` over each row's `area`; `None` where the file has neither, or gives a force
    /// without an area (said, naming the `what`).
    pub(super) fn stress_column(
        &mut self,
        names: &[String],
        area: Option<&Vec<Option<f64>>>,
        (stress_role, force_role): (Role, Role),
        what: &str,
    ) -> Option<Vec<Option<f64>>> {
        if let Some(k) = self.channel_of(|r| r == stress_role) {
            let name = names[k].clone();
            let u = self.unit(&name, self.raw.channels[k].line, StressUnit::KPa, "kPa", |u| u.parse::<StressUnit>().and_then(|s| if s.is_force() { Err(format!("`{u}` is a force but the channel is named a stress (expected kPa, MPa, Pa or psi)")) } else { Ok(s) }));
            return u.map(|u| self.values(k, |_| u.to_kpa()));
        }
        let k = self.channel_of(|r| r == force_role)?;
        self.force_read = true;
        let name = names[k].clone();
        let u = self.unit(&name, self.raw.channels[k].line, StressUnit::KN, "kN", |u| u.parse::<StressUnit>().and_then(|s| if s.is_force() { Ok(s) } else { Err(format!("`{u}` is a stress but the channel is named a force (expected N, kN or lbf)")) }))?;
        match area {
            Some(a) => {
                let a = a.clone();
                Some(self.values(k, |i| a[i].map_or(f64::NAN, |a| u.to_kpa() / a)))
            }
            None => {
                self.pr.add(self.lf, None, Some(&name), format!("the {what} is a force in {} but the file states no area (expected an area line or channel, or --area in mm²)", u.name()));
                None
            }
        }
    }

    /// The slip column [mm], from the horizontal (shear) displacement channel in its unit; `None`,
    /// with the problem said, where there is none or its unit is not a length.
    pub(super) fn slip_column(&mut self, names: &[String]) -> Option<Vec<Option<f64>>> {
        match self.channel_of(|r| r == Role::Slip) {
            Some(k) => {
                let name = names[k].clone();
                let u = self.unit(
                    &name,
                    self.raw.channels[k].line,
                    LengthUnit::Mm,
                    "mm",
                    |u| u.parse(),
                );
                u.map(|u| self.values(k, |_| u.to_mm()))
            }
            None => {
                self.pr.add(
                    self.lf,
                    None,
                    Some("slip"),
                    missing_role(names, "horizontal (shear) displacement"),
                );
                None
            }
        }
    }

    /// The contact area of each row [mm²]: `--area`, else an area channel (area correction),
    /// else the file's single value; `None` where none is given (a file that logs stresses needs
    /// none). An area that is not positive is a problem, said where it was read.
    pub(super) fn area_column(&mut self, names: &[String]) -> Option<Vec<Option<f64>>> {
        let n = self.raw.places.len();
        if let Some(a) = self.spec.area_mm2 {
            if !(a > 0.0 && a.is_finite()) {
                self.pr.add(
                    self.lf,
                    None,
                    Some("area"),
                    format!(
                        "--area {a} mm² (expected the contact area in mm², a finite number > 0)"
                    ),
                );
            }
            Some(vec![Some(a); n])
        } else if let Some(k) = self.channel_of(|r| r == Role::Area) {
            let name = names[k].clone();
            let values = self
                .unit(&name, self.raw.channels[k].line, 1.0, "mm²", area_unit)
                .map(|f| self.values(k, |_| f));
            // A row's area that is not positive would turn its force into a wrong stress.
            if let Some(i) = values.as_ref().and_then(|v| {
                v.iter()
                    .position(|a| a.is_some_and(|a| !(a > 0.0 && a.is_finite())))
            }) {
                let at = self.raw.channels[k].origin.get(i).copied();
                let (line, place) = match at {
                    Some((line, j)) => (line, format!("value {j} of the list: ")),
                    None => (self.raw.places[i], String::new()),
                };
                self.pr.add(
                    self.lf,
                    Some(line).filter(|&l| l > 0),
                    Some(&name),
                    format!("{place}an area that is not positive (expected the contact area, > 0)"),
                );
            }
            values
        } else if let Some((x, key, line)) = self.single_number(Role::Area) {
            self.unit(&key, line, 1.0, "mm²", area_unit)
                .map(|f| vec![Some(x * f); n])
        } else {
            None
        }
    }

    /// The further channels the test carries, in its own columns: the normal displacement, the
    /// forces read (kN per mm² of area: a force's kPa on one mm²), the area where a channel gave
    /// it (`area`: each row's) and the temperature in °C.
    pub(super) fn further_channels(
        &mut self,
        names: &[String],
        area: Option<&Vec<Option<f64>>>,
    ) -> Vec<(&'static str, Vec<Option<f64>>)> {
        let mut extra: Vec<(&'static str, Vec<Option<f64>>)> = Vec::new();
        if let Some(k) = self.channel_of(|r| r == Role::NormalDisp) {
            let name = names[k].clone();
            if let Some(u) = self.unit(
                &name,
                self.raw.channels[k].line,
                LengthUnit::Mm,
                "mm",
                |u| u.parse(),
            ) {
                extra.push(("normal_disp_mm", self.values(k, |_| u.to_mm())));
            }
        }
        for (role, col) in [
            (Role::ShearForce, "shear_force_kn"),
            (Role::NormalForce, "normal_force_kn"),
        ] {
            if let Some(k) = self.channel_of(|r| r == role) {
                let name = names[k].clone();
                if let Some(u) = self.unit(
                    &name,
                    self.raw.channels[k].line,
                    StressUnit::KN,
                    "kN",
                    |u| u.parse(),
                ) {
                    // kN per unit: a force's kPa on one mm² is 1e6 per kN.
                    extra.push((col, self.values(k, |_| u.to_kpa() / 1e6)));
                }
            }
        }
        if let Some(a) = area {
            if self.spec.area_mm2.is_none() && self.find_channel(|r| r == Role::Area).is_some() {
                extra.push(("area_mm2", a.clone()));
            }
        }
        if let Some(k) = self.channel_of(|r| r == Role::Temperature) {
            let name = names[k].clone();
            if stated_unit(&name).is_none() {
                self.defaulted.push(format!("`{name}` in °C"));
            }
            let ok = stated_unit(&name).is_none_or(|u| {
                matches!(
                    u.trim().to_lowercase().replace(['°', ' '], "").as_str(),
                    "c" | "degc"
                )
            });
            if ok {
                extra.push(("temperature_c", self.values(k, |_| 1.0)));
            } else {
                self.pr.add(
                    self.lf,
                    Some(self.raw.channels[k].line).filter(|&l| l > 0),
                    Some(&name),
                    "a temperature not in °C (expected °C)",
                );
            }
        }
        extra
    }
}
