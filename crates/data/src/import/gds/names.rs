//! What a GDS channel's name says: the role of the channel, and the unit it is in.

use crate::import::stage::plain_name;

/// What a channel holds, read off its name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Role {
    Stage,
    /// Time; the rank orders several (time since the test's start before the stage's).
    Time(u8),
    Slip,
    NormalDisp,
    ShearStress,
    ShearForce,
    NormalStress,
    NormalForce,
    Area,
    Rate,
    Temperature,
}

/// The role a channel's name says it has (`None`: a channel the test does not carry).
pub(super) fn role_of(name: &str) -> Option<Role> {
    let n = plain_name(name);
    let has = |w: &str| n.contains(w);
    let any = |ws: &[&str]| ws.iter().any(|w| n.contains(w));
    if crate::import::stage::column(&[name.to_string()]).is_some() {
        return Some(Role::Stage);
    }
    if any(&["rate", "velocity", "speed"]) {
        return any(&["displacement", "shear", "horizontal"])
            .then_some(Role::Rate)
            .or((n == "rate").then_some(Role::Rate));
    }
    if has("time") {
        return Some(Role::Time(if has("stage") {
            2
        } else if has("test") || n == "time" || has("elapsed") {
            0
        } else {
            1
        }));
    }
    if any(&[
        "horizontal displacement",
        "shear displacement",
        "horizontal disp",
    ]) {
        return Some(Role::Slip);
    }
    if any(&[
        "vertical displacement",
        "normal displacement",
        "vertical disp",
    ]) {
        return Some(Role::NormalDisp);
    }
    if any(&["shear stress", "horizontal stress"]) {
        return Some(Role::ShearStress);
    }
    if any(&[
        "shear force",
        "shear load",
        "horizontal load",
        "horizontal force",
    ]) {
        return Some(Role::ShearForce);
    }
    if any(&["normal stress", "vertical stress"]) {
        return Some(Role::NormalStress);
    }
    if any(&[
        "normal force",
        "normal load",
        "vertical load",
        "vertical force",
    ]) {
        return Some(Role::NormalForce);
    }
    if has("area") {
        return Some(Role::Area);
    }
    if has("temperature") || n == "temp" {
        return Some(Role::Temperature);
    }
    None
}

/// The unit a channel's name states: the text of its last `(…)` or `[…]`.
pub(super) fn stated_unit(name: &str) -> Option<String> {
    let open = name.rfind(['(', '['])?;
    let close = name[open..].find([')', ']'])? + open;
    let u = name[open + 1..close].trim();
    (!u.is_empty()).then(|| u.to_string())
}

/// Square millimetres per unit of an area.
pub(super) fn area_unit(u: &str) -> Result<f64, String> {
    match u
        .trim()
        .to_lowercase()
        .replace(['²', '^'], "2")
        .replace("22", "2")
        .as_str()
    {
        "mm2" | "sq mm" => Ok(1.0),
        "cm2" | "sq cm" => Ok(100.0),
        "m2" | "sq m" => Ok(1e6),
        other => Err(format!(
            "unknown area unit `{other}` (expected mm², cm² or m²)"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn channels_are_known_by_their_names() {
        let cases = [
            ("Horizontal Displacement (mm)", Some(Role::Slip)),
            ("Vertical Displacement", Some(Role::NormalDisp)),
            ("Shear Force (kN)", Some(Role::ShearForce)),
            ("Horizontal Load (kN)", Some(Role::ShearForce)),
            ("Normal Stress (kPa)", Some(Role::NormalStress)),
            ("Vertical Load (kN)", Some(Role::NormalForce)),
            ("Box Area (mm2)", Some(Role::Area)),
            ("Rate of Shear Displacement", Some(Role::Rate)),
            ("Time since start of test (s)", Some(Role::Time(0))),
            ("Time since start of stage (s)", Some(Role::Time(2))),
            ("Stage Number", Some(Role::Stage)),
            ("Back Pressure (kPa)", None),
        ];
        for (name, role) in cases {
            assert_eq!(role_of(name), role, "{name}");
        }
    }

    #[test]
    fn units_are_read_from_the_names() {
        assert_eq!(stated_unit("Shear Force (kN)").as_deref(), Some("kN"));
        assert_eq!(stated_unit("Area [cm²]").as_deref(), Some("cm²"));
        assert_eq!(stated_unit("Rate"), None);
        assert_eq!(area_unit("cm²"), Ok(100.0));
        assert_eq!(area_unit("mm^2"), Ok(1.0));
        assert!(area_unit("acre").is_err());
    }
}
