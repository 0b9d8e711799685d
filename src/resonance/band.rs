//! Verdicts with the uncertainty that could flip them (docs/stability.md, "Verdicts and their
//! band"). At the speeds a verdict is made (the deck's operating speed, and the fastest growth
//! of each unstable range), the map is recomputed with each of the deck's `# ASSUMED` values
//! moved to half and to twice its value (the sensitivity study's default range), and, for the
//! physical damper, with the flow laws' numerical floor `dp_laminar_Pa` moved by 10x each way.
//! The band of the mode's growth rate combines the one-at-a-time changes in quadrature, each
//! side separately: `g0 + sqrt(sum max(dg_i, 0)^2)` above, `g0 - sqrt(sum max(-dg_i, 0)^2)`
//! below (independent values; a linear estimate, not a bound). A mode is "unstable" only where
//! the whole band grows, "marginal" where the band crosses zero.
use super::{air, stability_map, StabilityMap};
use crate::hydraulics::DamperModel;
use crate::overrides::Override;
use crate::rotor::assumed::{targets, Target};
use crate::rotor::RotorDeck;
use crate::stability::ModeLabel;
use rayon::prelude::*;

/// The numerical floor of the flow laws and the factor it is moved by each way.
pub const FLOOR_KEY: &str = "damper.physical.dp_laminar_Pa";
pub const FLOOR_FACTOR: f64 = 10.0;
/// The factor each `# ASSUMED` value is moved by each way (as `rotorsim sensitivity`).
pub const ASSUMED_FACTOR: f64 = 2.0;
/// Contributions named with a verdict.
pub const NAMED: usize = 3;

/// What a verdict says of a mode at a speed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Call {
    Stable,
    Marginal,
    Unstable,
}

impl Call {
    pub fn word(self) -> &'static str {
        match self {
            Call::Stable => "stable",
            Call::Marginal => "marginal",
            Call::Unstable => "UNSTABLE",
        }
    }
}

/// One value moved: its key, the values tried and the mode's growth rate at each.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Contribution {
    pub key: String,
    pub nominal: f64,
    pub low: f64,
    pub high: f64,
    pub growth_rate_at_low_per_s: f64,
    pub growth_rate_at_high_per_s: f64,
}

impl Contribution {
    /// The larger change of the growth rate over the two ends.
    pub fn effect(&self, g0: f64) -> f64 {
        (self.growth_rate_at_low_per_s - g0)
            .abs()
            .max((self.growth_rate_at_high_per_s - g0).abs())
    }
}

/// A verdict on one mode at one speed, with its band.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Verdict {
    /// Why this speed: "operating speed" or "fastest growth of the range".
    pub at: String,
    pub omega_rad_s: f64,
    pub mode: String,
    pub frequency_hz: f64,
    pub growth_rate_per_s: f64,
    pub damping_ratio: f64,
    /// The growth rate's band [1/s], low and high.
    pub band_per_s: [f64; 2],
    pub call: Call,
    /// The values that move the growth rate most, largest first ([`NAMED`] of them).
    pub deciding: Vec<Contribution>,
    /// Values moved in all, and those that could not be (key and why).
    pub moved: usize,
    pub not_moved: Vec<(String, String)>,
    /// What the mode is when it is not a resonance (a free airframe's flight-dynamics mode).
    pub note: Option<String>,
    /// The amplitude check's outcome, when it ran at this speed on this mode (its headline).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub amplitude_check: Option<String>,
}

impl Verdict {
    /// One line: the call, the band and the deciding values.
    pub fn line(&self) -> String {
        let names: Vec<String> = self
            .deciding
            .iter()
            .map(|c| {
                format!(
                    "{} {}..{} gives {:+.4}..{:+.4}",
                    c.key,
                    crate::overrides::display(&toml::Value::Float(c.low)),
                    crate::overrides::display(&toml::Value::Float(c.high)),
                    c.growth_rate_at_low_per_s,
                    c.growth_rate_at_high_per_s
                )
            })
            .collect();
        let what = self
            .note
            .as_ref()
            .map_or(String::new(), |n| format!(" [{n}]"));
        format!(
            "{}: {}{what} at {:.3} rad/s ({}): growth rate {:+.4} 1/s (damping ratio {:+.4}), band {:+.4} to {:+.4} 1/s over {} assumed values{}",
            self.call.word(),
            self.mode,
            self.omega_rad_s,
            self.at,
            self.growth_rate_per_s,
            self.damping_ratio,
            self.band_per_s[0],
            self.band_per_s[1],
            self.moved,
            if names.is_empty() {
                String::new()
            } else {
                format!("; decided by {}", names.join("; "))
            }
        ) + &self
            .amplitude_check
            .as_ref()
            .map_or(String::new(), |a| format!("; amplitude check {a}"))
    }
}

/// How the map is computed: on the ground or in hover.
#[derive(Clone, Copy, Debug)]
pub enum Condition<'a> {
    Ground,
    Hover(&'a air::HoverOptions),
}

fn map_of(
    deck: &RotorDeck,
    model: DamperModel,
    speeds: &[f64],
    cond: Condition,
) -> anyhow::Result<StabilityMap> {
    match cond {
        Condition::Ground => stability_map(deck, model, speeds),
        Condition::Hover(h) => air::air_resonance_map(deck, model, speeds, h),
    }
}

/// The values a band moves: the deck's labelled values that the user did not set, and the
/// numerical floor of the physical damper's flow laws.
fn moved_values(deck: &RotorDeck, model: DamperModel, set: &[Override]) -> Vec<(Target, f64)> {
    let user_set = |k: &str| set.iter().any(|o| o.key == k);
    let mut out: Vec<(Target, f64)> = deck
        .assumed()
        .labelled
        .iter()
        .flat_map(|l| targets(l).0)
        .filter(|t| !user_set(&t.key))
        .map(|t| (t, ASSUMED_FACTOR))
        .collect();
    let floor = crate::rotor::assumed::lookup(deck.table(), FLOOR_KEY).and_then(|v| v.as_float());
    if let (DamperModel::Physical, Some(x)) = (model, floor) {
        if x > 0.0 && !user_set(FLOOR_KEY) && !out.iter().any(|(t, _)| t.key == FLOOR_KEY) {
            out.push((
                Target {
                    key: FLOOR_KEY.into(),
                    index: None,
                    nominal: x,
                    array: None,
                    integer: false,
                    line: None,
                },
                FLOOR_FACTOR,
            ));
        }
    }
    out
}

/// The growth rate of the mode of `label`'s block ([`ModeLabel::block`]) whose eigenvalue is
/// nearest `lambda` in `map` at its speed `k` (of any label when none has it). Not by label
/// alone: each label names one mode, and where two modes coalesce a moved value may trade
/// their labels.
fn follow(map: &StabilityMap, k: usize, label: ModeLabel, lambda: faer::c64) -> Option<f64> {
    let modes = &map.speeds.get(k)?.modes;
    let near = |m: &&crate::stability::Mode| (m.eigenvalue - lambda).norm();
    modes
        .iter()
        .filter(|m| m.label.block() == label.block())
        .min_by(|a, b| near(a).total_cmp(&near(b)))
        .or_else(|| modes.iter().min_by(|a, b| near(a).total_cmp(&near(b))))
        .map(|m| m.growth_rate_per_s)
}

/// Where verdicts are made on `map`, as (why, speed, mode label): the deck's operating speed
/// when the map reaches it (its least damped mode: no label), and the fastest growth of each
/// unstable range.
fn verdict_asks(deck: &RotorDeck, map: &StabilityMap) -> Vec<(String, f64, Option<String>)> {
    // (why, speed, label) of each verdict
    let mut asks: Vec<(String, f64, Option<String>)> = vec![];
    let (first, last) = match (map.speeds.first(), map.speeds.last()) {
        (Some(a), Some(b)) => (a.omega_rad_s, b.omega_rad_s),
        _ => return vec![],
    };
    let op = deck.spec.rotor.omega_rad_s;
    if (first..=last).contains(&op) {
        asks.push(("operating speed".into(), op, None));
    }
    for u in &map.unstable {
        let peak = map
            .speeds
            .iter()
            .filter(|s| s.omega_rad_s >= u.from_rad_s && s.omega_rad_s <= u.to_rad_s)
            .filter_map(|s| {
                s.modes
                    .iter()
                    .filter(|m| m.label.as_str() == u.mode)
                    .map(|m| m.growth_rate_per_s)
                    .max_by(f64::total_cmp)
                    .map(|g| (s.omega_rad_s, g))
            })
            .max_by(|a, b| a.1.total_cmp(&b.1));
        if let Some((w, _)) = peak {
            if !asks
                .iter()
                .any(|a| a.1 == w && a.2.as_deref() == Some(&u.mode))
            {
                asks.push((
                    "fastest growth of the range".into(),
                    w,
                    Some(u.mode.clone()),
                ));
            }
        }
    }
    asks
}

/// The verdicts of `map`: at the deck's operating speed when it lies within the map's speeds
/// (its least damped mode), and at the fastest growth of each unstable range. `path` and `set`
/// are the deck file and the user's overrides the map was computed with.
pub fn verdicts(
    deck: &RotorDeck,
    set: &[Override],
    model: DamperModel,
    map: &StabilityMap,
    cond: Condition,
) -> anyhow::Result<Vec<Verdict>> {
    let mut asks = verdict_asks(deck, map);
    if asks.is_empty() {
        return Ok(vec![]);
    }
    // the maps take increasing speeds
    asks.sort_by(|a, b| a.1.total_cmp(&b.1));
    asks.dedup_by(|a, b| a.1 == b.1 && a.2 == b.2);
    let mut speeds: Vec<f64> = asks.iter().map(|a| a.1).collect();
    speeds.dedup();
    // the index in `speeds` of each verdict's speed
    let at: Vec<usize> = asks
        .iter()
        .map(|a| speeds.iter().position(|&w| w == a.1).unwrap_or(0))
        .collect();
    let nominal = map_of(deck, model, &speeds, cond)?;
    // the mode of each verdict, at the nominal values
    let modes: Vec<crate::stability::Mode> = asks
        .iter()
        .enumerate()
        .map(|(k, (_, _, label))| {
            let ms = &nominal.speeds[at[k]].modes;
            let pick = match label {
                Some(l) => ms
                    .iter()
                    .filter(|m| m.label.as_str() == l)
                    .max_by(|a, b| a.growth_rate_per_s.total_cmp(&b.growth_rate_per_s)),
                // the least damped resonance: flight dynamics has its own verdicts
                None => ms
                    .iter()
                    .filter(|m| {
                        flight_mode(deck, &cond, m.label.as_str(), m.frequency_hz).is_none()
                    })
                    .min_by(|a, b| a.damping_ratio.total_cmp(&b.damping_ratio)),
            };
            pick.cloned()
                .ok_or_else(|| anyhow::anyhow!("no mode at {} rad/s", asks[k].1))
        })
        .collect::<anyhow::Result<_>>()?;
    let moved = moved_values(deck, model, set);
    // each value at its two ends: the map at the verdicts' speeds, or why it could not be moved
    type Ends = Result<(f64, f64, Vec<f64>, Vec<f64>), String>;
    let ends: Vec<Ends> = moved
        .par_iter()
        .map(|(t, f)| {
            let (lo, hi) = (t.nominal / f, t.nominal * f);
            let at = |x: f64| -> Result<Vec<f64>, String> {
                let mut s = set.to_vec();
                s.push(Override {
                    key: t.key.clone(),
                    value: t.value_at(x),
                });
                let d = RotorDeck::from_file_with(&deck.path, &s).map_err(|e| format!("{e:#}"))?;
                let m = map_of(&d, model, &speeds, cond).map_err(|e| format!("{e:#}"))?;
                Ok(modes
                    .iter()
                    .enumerate()
                    .map(|(k, m0)| follow(&m, at[k], m0.label, m0.eigenvalue).unwrap_or(f64::NAN))
                    .collect())
            };
            Ok((lo, hi, at(lo)?, at(hi)?))
        })
        .collect();
    let mut out = vec![];
    for (k, ((why, w, _), m0)) in asks.iter().zip(&modes).enumerate() {
        let g0 = m0.growth_rate_per_s;
        let (mut up, mut down) = (0.0f64, 0.0f64);
        let mut contributions = vec![];
        let mut not_moved = vec![];
        for ((t, _), e) in moved.iter().zip(&ends) {
            match e {
                Ok((lo, hi, glo, ghi)) if glo[k].is_finite() && ghi[k].is_finite() => {
                    let d = [glo[k] - g0, ghi[k] - g0];
                    up += d.iter().map(|x| x.max(0.0)).fold(0.0, f64::max).powi(2);
                    down += d.iter().map(|x| (-x).max(0.0)).fold(0.0, f64::max).powi(2);
                    contributions.push(Contribution {
                        key: t.name(),
                        nominal: t.nominal,
                        low: *lo,
                        high: *hi,
                        growth_rate_at_low_per_s: glo[k],
                        growth_rate_at_high_per_s: ghi[k],
                    });
                }
                Ok(_) => not_moved.push((t.name(), "the mode was not found".into())),
                Err(why) => not_moved.push((t.name(), why.clone())),
            }
        }
        contributions.sort_by(|a, b| b.effect(g0).total_cmp(&a.effect(g0)));
        let moved_n = contributions.len();
        // a value that does not move the mode decides nothing
        contributions.retain(|c| c.effect(g0) > 1e-9 * g0.abs().max(1e-9));
        contributions.truncate(NAMED);
        let band = [g0 - down.sqrt(), g0 + up.sqrt()];
        let call = if band[0] > 0.0 {
            Call::Unstable
        } else if band[1] < 0.0 {
            Call::Stable
        } else {
            Call::Marginal
        };
        out.push(Verdict {
            at: why.clone(),
            omega_rad_s: *w,
            mode: m0.label.as_str().to_string(),
            frequency_hz: m0.frequency_hz,
            growth_rate_per_s: g0,
            damping_ratio: m0.damping_ratio,
            band_per_s: band,
            call,
            deciding: contributions,
            moved: moved_n,
            not_moved,
            note: flight_mode(deck, &cond, m0.label.as_str(), m0.frequency_hz),
            amplitude_check: None,
        });
    }
    Ok(out)
}

/// In hover, a mode of the airframe slower than three times the fastest of the springs that
/// stand in for free flight is the aircraft's flight dynamics (the hovering oscillation or a
/// drift), not air resonance: what it is, in words.
pub fn flight_mode(
    deck: &RotorDeck,
    cond: &Condition,
    label: &str,
    freq_hz: f64,
) -> Option<String> {
    if !matches!(cond, Condition::Hover(_)) || !label.starts_with("airframe") {
        return None;
    }
    let springs = deck.spec.airframe.as_ref()?.dofs();
    let fastest = springs
        .iter()
        .filter(|d| d.mass > 0.0)
        .map(|d| (d.stiffness / d.mass).sqrt() / (2.0 * std::f64::consts::PI))
        .fold(0.0, f64::max);
    (freq_hz < 3.0 * fastest).then(|| {
        let kind = if freq_hz == 0.0 {
            "a drift (real root)"
        } else {
            "the hovering oscillation"
        };
        format!(
            "flight dynamics of the free airframe, {kind}: the aircraft on springs of {fastest:.3} Hz that stand in for free flight, not air resonance"
        )
    })
}
