//! Rotating natural frequencies of a rotor deck (fan plot), `rotorsim modes --rotor`.
//!
//! The expanded model (docs/rotor_deck.md) without airloads, at zero controls, is brought to its
//! rotating equilibrium at each speed and linearised (solver/modal.rs: rotating frame,
//! centrifugal stiffening, Coriolis). The damper, a step element with internal states, has no
//! place in that linearisation; it is represented by its linearised stiffness and damping moved
//! to the lag hinge: `k_h = arm^2 k_eq`, `c_h = arm^2 c_eq` (stroke = arm x lag angle), with
//! `c` the deck's linear dashpot (the paper's linear model, 4659.6 lb/(ft/s)) and, for the
//! hydraulic stiffness `k_d = B (A0^2/V0 + A1^2/V1)` (Eq. 16) of the physical damper in series
//! with it (a Maxwell element), at the lag frequency w:
//! `k_eq = k_d (c w)^2 / (k_d^2 + (c w)^2)`, `c_eq = c k_d^2 / (k_d^2 + (c w)^2)`.
use super::deck::{BearingAxis, RotorSpec};
use super::expand::ExpandOptions;
use super::sim::expanded_model;
use super::RotorDeck;
use crate::hydraulics::DamperDeck;
use crate::solver::modal::{modes, ModalOptions, Mode, ModeKind};
use crate::solver::statics::{static_solve, StaticOptions};
use crate::solver::State;
use std::path::Path;

/// The modes followed in the fan plot, in this order.
pub const TRACKED: [&str; 5] = ["lag1", "flap1", "flap2", "flap3", "torsion1"];

/// Linearised damper (translational, along the damper line).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DamperLinear {
    /// Dashpot constant c [N s/m] (deck `[damper.linear]`).
    pub c_n_s_per_m: f64,
    /// Hydraulic stiffness of Eq. (16) at the background pressure [N/m] (physical table), if any.
    pub k_hydraulic_n_per_m: Option<f64>,
}

impl DamperLinear {
    pub fn from_deck(d: &DamperDeck) -> anyhow::Result<Self> {
        let c = d.linear_c_n_s_per_m.ok_or_else(|| {
            anyhow::anyhow!(
                "{}: the fan plot represents the damper by its linear dashpot: table [damper.linear] is missing",
                d.source
            )
        })?;
        let k = d.physical.as_ref().map(|p| {
            let y = p.initial_state();
            p.static_stiffness(&y, 0.0)
        });
        Ok(DamperLinear {
            c_n_s_per_m: c,
            k_hydraulic_n_per_m: k,
        })
    }
    /// (k_eq [N/m], c_eq [N s/m]) at circular frequency w [rad/s] (Maxwell element).
    pub fn at(&self, w: f64) -> (f64, f64) {
        let c = self.c_n_s_per_m;
        match self.k_hydraulic_n_per_m {
            None => (0.0, c),
            Some(k) => {
                let cw = c * w;
                let den = k * k + cw * cw;
                (k * cw * cw / den, c * k * k / den)
            }
        }
    }
}

/// Modes at one rotor speed.
#[derive(Clone, Debug)]
pub struct FanPoint {
    pub fraction: f64,
    pub omega_rad_s: f64,
    pub modes: Vec<Mode>,
    /// Frequencies [Hz] of [`TRACKED`] (NaN when not found among the computed modes).
    pub tracked_hz: [f64; 5],
    /// Damper representation used at this speed: lag-hinge spring [N m/rad] and damper [N m s/rad].
    pub lag_k_nm_per_rad: f64,
    pub lag_c_nms_per_rad: f64,
}

/// Pick lag1, flap1..3, torsion1 by the dominant mass-weighted fraction (modes sorted by
/// frequency): the first lag mode, the first three flap modes, the first torsion mode.
pub fn track(ms: &[Mode]) -> [f64; 5] {
    let mut out = [f64::NAN; 5];
    let mut nflap = 0;
    for m in ms {
        match m.kind {
            ModeKind::Lag if out[0].is_nan() => out[0] = m.freq_hz,
            ModeKind::Flap if nflap < 3 => {
                out[1 + nflap] = m.freq_hz;
                nflap += 1;
            }
            ModeKind::Torsion if out[4].is_nan() => out[4] = m.freq_hz,
            _ => {}
        }
    }
    out
}

/// Modes at the speed fractions `fractions` of the deck's nominal Omega (`count` modes each).
pub fn fan(deck: &RotorDeck, fractions: &[f64], count: usize) -> anyhow::Result<Vec<FanPoint>> {
    let damper = deck.damper()?;
    let lin = DamperLinear::from_deck(&damper)?;
    fan_with(&deck.spec, &deck.path, &lin, fractions, count)
}

pub fn fan_with(
    spec: &RotorSpec,
    file: &Path,
    lin: &DamperLinear,
    fractions: &[f64],
    count: usize,
) -> anyhow::Result<Vec<FanPoint>> {
    let arm = spec.damper_attachment.arm_m;
    let om_n = spec.rotor.omega_rad_s;
    let bearing_lag = spec.bearing.equivalent(BearingAxis::Lag, om_n);
    let mut out = vec![];
    // linearisation frequency: the lag frequency of the previous speed (first point: of a pass
    // with the dashpot alone)
    let mut w_lag: Option<f64> = None;
    for &x in fractions {
        if !(x.is_finite() && x >= 0.0) {
            anyhow::bail!("speed fraction {x} must be finite and non-negative");
        }
        let om = x * om_n;
        let solve = |k_eq: f64, c_eq: f64| -> anyhow::Result<Vec<Mode>> {
            let xo = ExpandOptions {
                lag_extra_k: arm * arm * k_eq,
                lag_extra_c: arm * arm * c_eq,
                bearing_equivalent: true,
                ..Default::default()
            };
            let mut model = expanded_model(spec, &xo, file)?;
            let mut st = State::from_model(&model);
            let rot = if om > 0.0 { Some([0.0, 0.0, om]) } else { None };
            static_solve(
                &mut model,
                &mut st,
                &StaticOptions {
                    load_steps: 1,
                    omega: rot,
                    ..Default::default()
                },
                |_, _, _, _| {},
            )
            .map_err(|e| anyhow::anyhow!("equilibrium at {x} x Omega: {e}"))?;
            Ok(modes(
                &mut model,
                &st,
                &ModalOptions {
                    n_modes: count,
                    omega: rot,
                    shift_rad_s: 0.0,
                },
            )?)
        };
        let w = match w_lag {
            Some(w) => w,
            None => {
                let (_, c0) = lin.at(0.0);
                let ms = solve(0.0, c0)?;
                track(&ms)[0] * 2.0 * std::f64::consts::PI
            }
        };
        let (k_eq, c_eq) = lin.at(if w.is_finite() { w } else { 0.0 });
        let ms = solve(k_eq, c_eq)?;
        let tracked = track(&ms);
        if tracked[0].is_finite() {
            w_lag = Some(tracked[0] * 2.0 * std::f64::consts::PI);
        }
        out.push(FanPoint {
            fraction: x,
            omega_rad_s: om,
            modes: ms,
            tracked_hz: tracked,
            lag_k_nm_per_rad: bearing_lag.0 + arm * arm * k_eq,
            lag_c_nms_per_rad: bearing_lag.1 + arm * arm * c_eq,
        });
    }
    Ok(out)
}

/// Digitized reference fan plot (CSV `x,l1,f1,f2,f3,f4,t1,f5`, frequencies in Hz, x = Omega /
/// Omega_nominal): rows of (x, [l1, f1, f2, f3, t1]) in the order of [`TRACKED`].
pub fn read_reference(path: &Path) -> anyhow::Result<Vec<(f64, [f64; 5])>> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| anyhow::anyhow!("reference fan plot {file}: cannot read: {e}"))?;
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let head: Vec<&str> = lines
        .next()
        .ok_or_else(|| anyhow::anyhow!("reference fan plot {file}: empty"))?
        .split(',')
        .map(str::trim)
        .collect();
    let col = |n: &str| {
        head.iter().position(|h| *h == n).ok_or_else(|| {
            anyhow::anyhow!("reference fan plot {file}: no column `{n}` (header {head:?})")
        })
    };
    let cols = [
        col("x")?,
        col("l1")?,
        col("f1")?,
        col("f2")?,
        col("f3")?,
        col("t1")?,
    ];
    let mut rows = vec![];
    for (i, l) in lines.enumerate() {
        let v: Vec<&str> = l.split(',').map(str::trim).collect();
        let get = |c: usize| -> anyhow::Result<f64> {
            v.get(c).and_then(|s| s.parse::<f64>().ok()).ok_or_else(|| {
                anyhow::anyhow!(
                    "reference fan plot {file}, line {}: expected a number in column {}",
                    i + 2,
                    head[c]
                )
            })
        };
        rows.push((
            get(cols[0])?,
            [
                get(cols[1])?,
                get(cols[2])?,
                get(cols[3])?,
                get(cols[4])?,
                get(cols[5])?,
            ],
        ));
    }
    Ok(rows)
}
