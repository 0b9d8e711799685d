//! The numbers a sensitivity moves: the deck's labelled values (read with the deck by
//! [`crate::rotor::assumed`]) and the `--vary` keys (docs/sensitivity.md, "Parameters").
pub use crate::rotor::assumed::{lookup, scan, targets, Labelled, Scan, Skipped, Target, MARK};
use toml::{Table, Value};

/// The target a `--vary` key names in the deck: `a.b.c` or `a.b.c[i]`.
pub fn target_of(root: &Table, name: &str) -> Result<Target, String> {
    let (key, index) = match name.strip_suffix(']').and_then(|s| s.split_once('[')) {
        Some((k, i)) => (
            k,
            Some(
                i.trim()
                    .parse::<usize>()
                    .map_err(|_| format!("`[{i}]` is not a component index"))?,
            ),
        ),
        None => (name, None),
    };
    crate::overrides::check_key(key).map_err(|e| e.to_string())?;
    let v = lookup(root, key).ok_or_else(|| {
        format!("the deck has no value at `{key}` (a sensitivity moves a value the deck states; keys are dotted with the unit in the name, e.g. bearing.lag_stiffness_Nm_per_rad)")
    })?;
    let num = |v: &Value| match v {
        Value::Float(x) => Some(*x),
        Value::Integer(i) => Some(*i as f64),
        _ => None,
    };
    match (v, index) {
        (Value::Array(a), Some(i)) => {
            let nums: Option<Vec<f64>> = a.iter().map(num).collect();
            let nums = nums.ok_or_else(|| format!("`{key}` is not an array of numbers"))?;
            if i >= nums.len() {
                return Err(format!(
                    "`{key}` has {} components, [{i}] is beyond them",
                    nums.len()
                ));
            }
            Ok(Target {
                key: key.into(),
                index: Some(i),
                nominal: nums[i],
                array: Some(nums),
                integer: false,
                line: None,
            })
        }
        (Value::Array(_), None) => Err(format!(
            "`{key}` is an array: name one component, e.g. {key}[0]"
        )),
        (v, None) if num(v).is_some() => Ok(Target {
            key: key.into(),
            index: None,
            nominal: num(v).unwrap_or_default(),
            array: None,
            integer: matches!(v, Value::Integer(_)),
            line: None,
        }),
        (v, _) => Err(format!("`{key}` is {v} in the deck, not a number")),
    }
}

/// The unit of a deck key, from its name (`lag_damping_Nms_per_rad` -> `Nms_per_rad`; `-`
/// when the name carries none, e.g. `tip_loss_factor`).
pub fn unit_of(key: &str) -> String {
    let leaf = key.rsplit('.').next().unwrap_or(key);
    let leaf = leaf.split('[').next().unwrap_or(leaf);
    const UNITS: &[&str] = &[
        "Nms_per_rad",
        "Nm_per_rad",
        "N_s_per_m",
        "N_per_m",
        "kg_per_m",
        "kg_m3",
        "per_Pa2",
        "per_Pa",
        "rad_s",
        "m_s",
        "Nm2",
        "kgm",
        "Nm",
        "kg",
        "m2",
        "m3",
        "Pa",
        "deg",
        "rad",
        "m",
        "s",
        "N",
    ];
    for u in UNITS {
        if leaf.ends_with(&format!("_{u}")) {
            return u.to_string();
        }
    }
    "-".into()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units() {
        assert_eq!(unit_of("bearing.lag_damping_Nms_per_rad"), "Nms_per_rad");
        assert_eq!(unit_of("pitch_control.horn_tip_m[1]"), "m");
        assert_eq!(unit_of("aero.tip_loss_factor"), "-");
        assert_eq!(unit_of("blade.damping_mu_s"), "s");
    }
}
