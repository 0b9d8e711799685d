//! The time-domain check: the nonlinear rigid-blade rotor on its airframe, marched.
use crate::hydraulics::{DamperDeck, DamperModel};
use crate::rotor::deck::RotorSpec;
use crate::rotor::RotorDeck;
use anyhow::{anyhow, bail};
use std::f64::consts::PI;

/// The whole multibody rotor on its airframe at one speed, kicked along the hub's x axis:
/// its airframe x motion and the growth rate and frequency fitted to it.
#[derive(Clone, Debug)]
pub struct TimeCheck {
    pub omega_rad_s: f64,
    /// Velocity of the kick [m/s].
    pub kick_m_s: f64,
    pub time_s: Vec<f64>,
    pub airframe_x_m: Vec<f64>,
    /// Slope of ln|x| at its peaks over the fitted window [1/s].
    pub growth_rate_per_s: f64,
    /// From the spacing of the peaks of |x| in the window [Hz].
    pub frequency_hz: f64,
    /// Start of the fitted window [s] (the kick's faster modes have died out before it).
    pub fit_from_s: f64,
}

/// A flight record of no airloads and no controls at `omega` for the rotor of `spec`: a
/// rotor on the ground.
fn ground_record(spec: &RotorSpec, omega: f64) -> anyhow::Result<crate::flight::FlightRecord> {
    use crate::flight::record::FlightMeta;
    let meta = serde_json::json!({
        "synthetic": true,
        "description": "no airloads: a rotor on the ground (rotorsim stability)",
        "rotor_speed_rad_s": omega,
        "radius_m": spec.rotor.radius_m,
        "controls_deg": {"collective": 0.0, "lateral_cyclic": 0.0, "longitudinal_cyclic": 0.0},
    });
    let serde_json::Value::Object(raw) = meta else {
        bail!("ground record metadata");
    };
    let meta = FlightMeta::from_json(raw, std::path::Path::new("<ground record>"))?;
    let az = vec![0.0, 90.0, 180.0, 270.0];
    let n = 2 * az.len();
    // a record holds a damper channel: none was measured, zeros stand in (never compared)
    let damper = az
        .iter()
        .map(|&a| crate::flight::record::DamperSample {
            revolution: 0,
            azimuth_deg: a,
            force_N: 0.0,
            stroke_m: None,
        })
        .collect();
    Ok(crate::flight::FlightRecord::new(
        meta,
        vec![0.5, 1.0],
        vec![0],
        az,
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        damper,
    )?)
}

/// Airframe motion up to which a kicked response is fitted [m]: small against the rotor, so
/// that the lag angles stay small and the linear analysis applies (a growing response is
/// stopped there).
pub const TIME_FIT_MAX_M: f64 = 0.01;

/// Growth rate and frequency of `x(t)` after `from_s` and before `|x|` first exceeds
/// [`TIME_FIT_MAX_M`]. The frequency from the mean spacing of the peaks of `|x|`; the growth
/// rate as the least-squares slope of `ln E / 2` against time over every sample, `E = x^2 +
/// (x'/omega)^2` (x' by central differences): for a growing oscillation `E` grows smoothly,
/// without the peaks' sampling of the cycle.
pub fn fit_growth(t: &[f64], x: &[f64], from_s: f64) -> Option<(f64, f64)> {
    let end = x
        .iter()
        .position(|v| v.abs() > TIME_FIT_MAX_M)
        .unwrap_or(x.len());
    // a decaying response ends where it meets the solver's noise: 1e-4 of its largest value
    let top = x
        .iter()
        .zip(t)
        .filter(|(_, ti)| **ti >= from_s)
        .fold(0.0f64, |m, (v, _)| m.max(v.abs()));
    let end = match x
        .iter()
        .zip(t)
        .rposition(|(v, ti)| *ti >= from_s && v.abs() > 1e-4 * top)
    {
        Some(i) => end.min(i + 1),
        None => end,
    };
    let (t, x) = (&t[..end], &x[..end]);
    let peaks: Vec<f64> = (1..x.len().saturating_sub(1))
        .filter(|&i| t[i] >= from_s && x[i].abs() > x[i - 1].abs() && x[i].abs() >= x[i + 1].abs())
        .map(|i| t[i])
        .collect();
    if peaks.len() < 6 {
        return None;
    }
    let f = 0.5 * (peaks.len() - 1) as f64 / (peaks[peaks.len() - 1] - peaks[0]);
    let w = 2.0 * std::f64::consts::PI * f;
    // whole cycles of the window, so that what is left of the cycle in E averages out
    let (a, b) = (peaks[0], peaks[peaks.len() - 1]);
    let pts: Vec<(f64, f64)> = (1..x.len() - 1)
        .filter(|&i| t[i] >= a && t[i] <= b)
        .map(|i| {
            let v = (x[i + 1] - x[i - 1]) / (t[i + 1] - t[i - 1]);
            (t[i], 0.5 * (x[i] * x[i] + (v / w) * (v / w)).ln())
        })
        .collect();
    Some((crate::analysis::compare::slope(&pts), f))
}

/// Most steps per revolution of a time-domain check.
pub const MAX_TIME_STEPS_PER_REV: usize = 16384;
/// Most structural steps of one time-domain check (about an hour of the whole rotor).
pub const MAX_TIME_STEPS: f64 = 5e6;

/// How the time-domain check runs.
#[derive(Clone, Copy, Debug)]
pub struct TimeOptions {
    /// Velocity of the kick along x [m/s].
    pub kick_m_s: f64,
    /// Simulated time [s] (a growing response stops at [`TIME_FIT_MAX_M`]).
    pub duration_s: f64,
    /// Start of the fitted window [s].
    pub fit_from_s: f64,
    /// Structural steps per revolution.
    pub steps_per_rev: usize,
}

impl TimeOptions {
    /// The options at rotor speed `omega` [rad/s], sizes checked before anything is built or
    /// allocated.
    pub fn check(&self, omega: f64) -> anyhow::Result<()> {
        let TimeOptions {
            kick_m_s,
            duration_s,
            steps_per_rev,
            ..
        } = *self;
        if !(kick_m_s.is_finite() && kick_m_s > 0.0) {
            bail!("--kick-m-s {kick_m_s}: expected a positive velocity in m/s");
        }
        if !(duration_s.is_finite() && duration_s > 0.0) {
            bail!("--time-duration-s {duration_s}: expected a positive time in s");
        }
        if !(8..=MAX_TIME_STEPS_PER_REV).contains(&steps_per_rev) {
            bail!("--steps-per-rev {steps_per_rev}: expected 8 to {MAX_TIME_STEPS_PER_REV}");
        }
        let steps = duration_s * omega / (2.0 * PI) * steps_per_rev as f64;
        if steps > MAX_TIME_STEPS {
            bail!(
                "--time-duration-s {duration_s} at {omega} rad/s and {steps_per_rev} steps per revolution is {steps:.3e} steps, beyond the {MAX_TIME_STEPS:.0e} a time-domain check may take; shorten it"
            );
        }
        Ok(())
    }
}

impl Default for TimeOptions {
    fn default() -> Self {
        TimeOptions {
            kick_m_s: 1e-4,
            duration_s: 20.0,
            fit_from_s: 7.0,
            // 256 puts the Hammond rotor's growth rates up to 4.5% off near the coalescence,
            // 512 within 1%, 1024 within 0.04% (docs/stability.md)
            steps_per_rev: 512,
        }
    }
}

/// The time-domain check at `omega`: the deck at that speed (`sets` applied, e.g. a blade's
/// damper), the whole multibody rotor on its airframe with damper model `model`, in rotating
/// equilibrium without airloads, kicked along x and marched ([`TimeOptions`]).
pub fn time_check(
    path: &std::path::Path,
    sets: &[crate::overrides::Override],
    model: DamperModel,
    omega: f64,
    o: &TimeOptions,
) -> anyhow::Result<TimeCheck> {
    let TimeOptions {
        kick_m_s,
        duration_s,
        fit_from_s,
        steps_per_rev,
    } = *o;
    o.check(omega)?;
    let mut all = sets.to_vec();
    all.push(crate::overrides::Override::parse(&format!(
        "rotor.omega_rad_s={omega}"
    ))?);
    let deck = RotorDeck::from_file_with(path, &all)?;
    if deck.spec.airframe.is_none() {
        bail!(
            "rotor deck {} has no [airframe]: nothing to kick",
            path.display()
        );
    }
    let n = deck.spec.rotor.blades;
    let mut blades = Vec::with_capacity(n);
    for k in 1..=n {
        let b = deck.blade(k)?;
        let d = b.damper()?;
        blades.push((b, d));
    }
    let parts: Vec<(&RotorSpec, &DamperDeck)> = blades.iter().map(|(b, d)| (&b.spec, d)).collect();
    let record = ground_record(&deck.spec, omega)?;
    let opts = crate::rotor::RunOptions {
        perturbation_damping: false,
        steps_per_rev,
        ..Default::default()
    };
    let mut sim = crate::rotor::sim::build_rotor_sim(&parts, path, model, &record, &opts)?;
    use crate::rotor::ForcedResponse;
    sim.set_output_channels(false);
    let names = sim.channel_names();
    let ix = names
        .iter()
        .position(|c| c == "airframe_x_m")
        .ok_or_else(|| anyhow!("the rotor has no airframe x channel"))?;
    sim.kick_airframe(0, kick_m_s)?;
    let steps = (duration_s / sim.time_step_s()).ceil() as usize;
    let mut buf = vec![0.0; names.len()];
    let (mut t, mut x) = (Vec::with_capacity(steps), Vec::with_capacity(steps));
    let t0 = sim.time_s();
    for _ in 0..steps {
        sim.step()?;
        sim.channels(&mut buf);
        t.push(sim.time_s() - t0);
        x.push(buf[ix]);
        if buf[ix].abs() > TIME_FIT_MAX_M {
            break; // beyond what the fit uses
        }
    }
    let (g, f) = fit_growth(&t, &x, fit_from_s).ok_or_else(|| {
        anyhow!("the airframe x motion has too few peaks after {fit_from_s} s to fit a growth rate")
    })?;
    Ok(TimeCheck {
        omega_rad_s: omega,
        kick_m_s,
        time_s: t,
        airframe_x_m: x,
        growth_rate_per_s: g,
        frequency_hz: f,
        fit_from_s,
    })
}
