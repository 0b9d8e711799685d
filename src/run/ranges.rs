//! Values given as text: `START:STOP:STEP` or a list (rotor speeds of `modes`, `stability`
//! and a sweep's stability maps; the amplitude check's stroke amplitudes), and their checks.

/// The error for `name`'s value `s`: what is wrong (`m`) and the form expected.
pub fn range_error(name: &str, s: &str, m: &str, expected: &str) -> anyhow::Error {
    anyhow::anyhow!("{name} `{s}`: {m} ({expected})")
}

/// `name` (an option or a plan key): `START:STOP:STEP` (inclusive, rounded to the step) or a list `a,b,c`, at most
/// `max` values (`what`: who takes them, for the message); `expected` says the form in the
/// messages. Ranges must have a positive step and STOP >= START; the caller checks the values.
pub fn parse_range(
    name: &str,
    s: &str,
    expected: &str,
    max: usize,
    what: &str,
) -> anyhow::Result<Vec<f64>> {
    let bad = |m: &str| range_error(name, s, m, expected);
    let num = |t: &str| {
        t.trim()
            .parse::<f64>()
            .map_err(|_| bad(&format!("`{t}` is not a number")))
    };
    let v: Vec<f64> = if s.contains(':') {
        let p: Vec<&str> = s.split(':').collect();
        if p.len() != 3 {
            return Err(bad("three fields needed"));
        }
        let (a, b, h) = (num(p[0])?, num(p[1])?, num(p[2])?);
        if !(a.is_finite() && b.is_finite() && h.is_finite()) {
            return Err(bad("START, STOP and STEP must be finite"));
        }
        if h <= 0.0 || b < a {
            return Err(bad("STEP must be positive and STOP >= START"));
        }
        let n = ((b - a) / h + 1e-9).floor();
        if n >= max as f64 {
            return Err(bad(&format!(
                "{} values, beyond the {max} {what}; use a larger STEP",
                crate::solver::budget::count(n + 1.0)
            )));
        }
        (0..=n as usize)
            .map(|k| ((a + k as f64 * h) * 1e9).round() / 1e9)
            .collect()
    } else {
        s.split(',').map(num).collect::<Result<_, _>>()?
    };
    if v.is_empty() {
        return Err(bad("no value given"));
    }
    if v.len() > max {
        return Err(bad(&format!("{} values, beyond the {max} {what}", v.len())));
    }
    Ok(v)
}

/// `name`'s values (`unit`, each a `noun`): at least one, each finite and positive, strictly
/// increasing.
pub fn check_increasing(name: &str, v: &[f64], unit: &str, noun: &str) -> anyhow::Result<()> {
    if v.is_empty() {
        anyhow::bail!("{name}: no {noun} given");
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite() || **x <= 0.0) {
        anyhow::bail!("{name}: {x} {unit} is not a positive finite {noun}");
    }
    if let Some(w) = v.windows(2).find(|w| w[1] <= w[0]) {
        anyhow::bail!(
            "{name}: {} {unit} after {} {unit}: the values must increase",
            w[1],
            w[0]
        );
    }
    Ok(())
}

/// Refuses rotor speeds `name` [rad/s] that look like fractions of the nominal speed (every one
/// below a tenth of `nominal_rad_s`, `key` of `deck`): a map of them would answer for a rotor
/// barely turning, "stable", without saying why.
pub fn check_not_fractions(
    name: &str,
    speeds_rad_s: &[f64],
    nominal_rad_s: f64,
    deck: &std::path::Path,
    key: &str,
) -> anyhow::Result<()> {
    let top = speeds_rad_s
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    if top < 0.1 * nominal_rad_s {
        anyhow::bail!(
            "{name}: every speed is below a tenth of the nominal speed ({} {key} = {nominal_rad_s} \
             rad/s; the highest given is {top} rad/s): {name} is in rad/s, not a fraction of the \
             nominal (fraction 1 is {nominal_rad_s} rad/s)",
            deck.display()
        );
    }
    Ok(())
}
