//! Blade loads of a run (docs/loads.md): the run-time equilibrium check, the fixed-frame hub
//! loads of the rotor's identical blades, and per-channel statistics for summary.json.
use super::ModelRun;
use crate::loads::hub;
use crate::rotor::loads::{CHECK_PREFIX, ROOT_CHANNELS};

/// Largest relative difference accepted between the root loads and the resultant of the
/// applied, inertial, damper and pitch-link loads (of each root channel's peak-to-peak).
pub const EQUILIBRIUM_TOL: f64 = 5e-3;

/// Fixed-frame hub load channels, in the order of [`ROOT_CHANNELS`].
pub const HUB_CHANNELS: [&str; 6] = [
    "hub_fx_fixed_N",
    "hub_fy_fixed_N",
    "hub_fz_fixed_N",
    "hub_mx_fixed_Nm",
    "hub_my_fixed_Nm",
    "hub_mz_fixed_Nm",
];

/// Root loads against the resultant of everything applied to the blade system, over the
/// reported revolution.
#[derive(Clone, Debug, serde::Serialize)]
pub struct EquilibriumCheck {
    /// Largest `|root - resultant| / scale` over samples and channels, the scale of a channel
    /// being its magnitude ([`load_scales`]).
    pub max_rel_error: f64,
    pub channel: String,
    pub tolerance: f64,
    pub passed: bool,
}

/// The magnitude each root channel's error is measured against: the larger of its
/// peak-to-peak and its largest absolute value (a steady load, as in hover, has no
/// peak-to-peak to speak of), and at least 1e-3 of the largest such magnitude among the
/// channels of its unit (forces, moments), so that a channel near zero is not judged by
/// round-off.
fn load_scales(channels: &[&[f64]; 6]) -> [f64; 6] {
    let own = channels.map(|v| {
        let st = super::summary::Stats::of(v);
        st.peak_to_peak.max(st.min.abs()).max(st.max.abs())
    });
    let unit = |k: usize| {
        own[3 * (k / 3)..3 * (k / 3) + 3]
            .iter()
            .cloned()
            .fold(0.0, f64::max)
    };
    std::array::from_fn(|k| own[k].max(1e-3 * unit(k)).max(f64::MIN_POSITIVE))
}

/// Consumes the check channels (computing the equilibrium check) and adds the fixed-frame
/// hub loads when the run has root loads and `blades` is known.
pub fn finish(run: &mut ModelRun, blades: Option<usize>) {
    let idx = |r: &ModelRun, n: &str| r.channel_names.iter().position(|c| c == n);
    let root: Option<Vec<usize>> = ROOT_CHANNELS.iter().map(|c| idx(run, c)).collect();
    let check: Option<Vec<usize>> = ROOT_CHANNELS
        .iter()
        .map(|c| idx(run, &format!("{CHECK_PREFIX}{c}")))
        .collect();
    if let (Some(root), Some(check)) = (&root, &check) {
        let mut worst = (0.0f64, String::new());
        let scales = load_scales(&std::array::from_fn(|k| run.last_rev[root[k]].as_slice()));
        for (k, (&i, &j)) in root.iter().zip(check).enumerate() {
            let scale = scales[k];
            let e = run.last_rev[i]
                .iter()
                .zip(&run.last_rev[j])
                .map(|(a, b)| (a - b).abs() / scale)
                .fold(0.0f64, |m, x| if x.is_nan() { f64::NAN } else { m.max(x) });
            if e.is_nan() || e > worst.0 || k == 0 {
                worst = (e, ROOT_CHANNELS[k].to_string());
            }
        }
        run.loads_check = Some(EquilibriumCheck {
            max_rel_error: worst.0,
            channel: worst.1,
            tolerance: EQUILIBRIUM_TOL,
            passed: worst.0 <= EQUILIBRIUM_TOL,
        });
    }
    // the check channels are not outputs
    let keep: Vec<bool> = run
        .channel_names
        .iter()
        .map(|c| !c.starts_with(CHECK_PREFIX))
        .collect();
    let mut k = keep.iter();
    run.channel_names.retain(|_| *k.next().unwrap_or(&true));
    let mut k = keep.iter();
    run.last_rev.retain(|_| *k.next().unwrap_or(&true));
    for rev in &mut run.all_revs {
        let mut k = keep.iter();
        rev.samples.retain(|_| *k.next().unwrap_or(&true));
    }
    let (Some(n), Some(_)) = (blades, root) else {
        return;
    };
    let root: Vec<usize> = ROOT_CHANNELS.iter().filter_map(|c| idx(run, c)).collect();
    if root.len() != 6 || n == 0 {
        return;
    }
    // blade 0's root loads in the non-rotating frame, then the sum over the blades; for every
    // kept revolution too, so that all_revs.csv has the channels of last_rev.csv
    let hub_loads = |samples: &[Vec<f64>]| -> Vec<Vec<f64>> {
        let m = run.azimuth_deg.len();
        let mut fixed = vec![vec![0.0; m]; 6];
        for (i, az) in run.azimuth_deg.iter().enumerate() {
            let psi = az.to_radians();
            for part in 0..2 {
                let v = std::array::from_fn(|c| samples[root[3 * part + c]][i]);
                let f = hub::to_fixed(psi, v);
                for (c, fc) in f.iter().enumerate() {
                    fixed[3 * part + c][i] = *fc;
                }
            }
        }
        fixed.iter().map(|y| hub::sum_of_blades(y, n)).collect()
    };
    let last = hub_loads(&run.last_rev);
    let kept: Vec<Vec<Vec<f64>>> = run.all_revs.iter().map(|k| hub_loads(&k.samples)).collect();
    for (c, y) in last.into_iter().enumerate() {
        run.channel_names.push(HUB_CHANNELS[c].to_string());
        run.last_rev.push(y);
    }
    for (k, y) in run.all_revs.iter_mut().zip(kept) {
        k.samples.extend(y);
    }
}

/// Whether `name` is a blade load channel (section in either frame, pitch link, root, bearing
/// moments or hub).
pub fn is_load_channel(name: &str) -> bool {
    use crate::rotor::deck::SECTION_KINDS;
    use crate::rotor::loads::{HINGE_MOMENT_CHANNELS, UNPITCHED};
    SECTION_KINDS.iter().any(|(k, _)| {
        name.starts_with(&format!("{k}_r")) || name.starts_with(&format!("{k}_{UNPITCHED}_r"))
    }) || name == crate::rotor::loads::PITCH_LINK_CHANNEL
        || HINGE_MOMENT_CHANNELS.contains(&name)
        || crate::rotor::loads::PITCH_LINK_CONTRIBUTOR_CHANNELS.contains(&name)
        || name == crate::rotor::loads::PITCH_LINK_ARM_CHANNEL
        || ROOT_CHANNELS.contains(&name)
        || HUB_CHANNELS.contains(&name)
        || super::rotor::HUB_ROTATING_CHANNELS.contains(&name)
}

/// Per channel of `r` that `keep` selects: mean, half peak-to-peak and harmonics 0-10/rev
/// (amplitude, phase) over the reported revolution.
pub fn channels_json(
    r: &ModelRun,
    keep: impl Fn(&str) -> bool,
) -> serde_json::Map<String, serde_json::Value> {
    use serde_json::json;
    let mut channels = serde_json::Map::new();
    for (name, v) in r.channel_names.iter().zip(&r.last_rev) {
        if !keep(name) {
            continue;
        }
        let st = super::summary::Stats::of(v);
        let h = crate::analysis::harmonics::harmonics(&r.azimuth_deg, v, super::N_HARMONICS)
            .map(|h| {
                h.iter()
                    .map(|x| json!({"n_per_rev": x.n, "amplitude": x.amplitude, "phase_deg": x.phase_deg}))
                    .collect::<Vec<_>>()
            })
            .unwrap_or_default();
        channels.insert(
            name.clone(),
            json!({"mean": st.mean, "half_peak_to_peak": 0.5 * st.peak_to_peak, "harmonics": h}),
        );
    }
    channels
}

/// Largest difference accepted between the pitch-link load and the sum of its contributors, of
/// the load's magnitude: the moment balance they come from holds to the structural solution's
/// equilibrium, as the root loads' check ([`EQUILIBRIUM_TOL`]).
pub const PITCH_LINK_BALANCE_TOL: f64 = EQUILIBRIUM_TOL;

/// Harmonics of the pitch link's contributors shown (1 to this, per rev).
pub const PITCH_LINK_HARMONICS: usize = 5;

/// One row of the pitch-link breakdown: mean and harmonic amplitudes 1..=[`PITCH_LINK_HARMONICS`]/rev
/// [N] over the reported revolution.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ContributorRow {
    pub name: String,
    /// The last_rev.csv column it comes from.
    pub channel: String,
    pub mean_n: f64,
    pub amplitude_n: Vec<f64>,
}

/// The pitch-link load and its contributors (docs/loads.md, "Pitch-link contributors"), the
/// bearing's split per harmonic by phase against the pitch-bearing angle (its moment's parts
/// over the mean arm), and the balance check.
#[derive(Clone, Debug, serde::Serialize)]
pub struct PitchLinkBreakdown {
    pub rows: Vec<ContributorRow>,
    pub balance_check: EquilibriumCheck,
}

/// The bearing moment's harmonic `b` split against the angle's harmonic `x` (both `a cos + b
/// sin`): the part in phase with the angle (its storage, the spring) and the part a quarter
/// period ahead (its loss, the damping), as amplitudes; None without pitch motion at that
/// harmonic, where the split is undefined.
fn phase_split(b: [f64; 2], x: [f64; 2]) -> Option<(f64, f64)> {
    let nx = x[0].hypot(x[1]);
    if nx.is_nan() || nx <= 1e-12 {
        return None;
    }
    let (u, v) = (x[0] / nx, x[1] / nx);
    Some(((b[0] * u + b[1] * v).abs(), (b[1] * u - b[0] * v).abs()))
}

/// The breakdown of a run with the pitch-link channels; None otherwise.
pub fn pitch_link_breakdown(r: &ModelRun) -> Option<PitchLinkBreakdown> {
    use crate::analysis::harmonics::harmonics;
    use crate::rotor::loads::{
        HINGE_CHANNELS, HINGE_MOMENT_CHANNELS, PITCH_LINK_ARM_CHANNEL, PITCH_LINK_CHANNEL as LINK,
        PITCH_LINK_CONTRIBUTOR_CHANNELS as PARTS,
    };
    let link = r.channel(LINK)?;
    let parts: Vec<&[f64]> = PARTS
        .iter()
        .map(|c| r.channel(c))
        .collect::<Option<Vec<_>>>()?;
    let angle = r.channel(HINGE_CHANNELS[2])?;
    let n = PITCH_LINK_HARMONICS;
    let fit = |v: &[f64]| harmonics(&r.azimuth_deg, v, n).ok();
    let row = |name: &str, channel: &str, v: &[f64]| -> Option<ContributorRow> {
        let h = fit(v)?;
        Some(ContributorRow {
            name: name.into(),
            channel: channel.into(),
            mean_n: h[0].cos,
            amplitude_n: h[1..].iter().map(|x| x.amplitude).collect(),
        })
    };
    let names = [
        "bearing (spring, damping and elastomer)",
        "airloads (applied loads)",
        "inertia (centrifugal and propeller moments included)",
        "gravity",
        "pitch link's own (shear at the horn, upper half's inertia)",
    ];
    // the bearing's split: its moment's harmonics against the angle's, over the mean arm
    let moment = r.channel(HINGE_MOMENT_CHANNELS[2])?;
    let arm = r.channel(PITCH_LINK_ARM_CHANNEL)?;
    let inv_arm = arm.iter().map(|a| 1.0 / a.abs()).sum::<f64>() / arm.len().max(1) as f64;
    let (hm, hx) = (fit(moment)?, fit(angle)?);
    let split: Vec<Option<(f64, f64)>> = (1..=n)
        .map(|j| phase_split([hm[j].cos, hm[j].sin], [hx[j].cos, hx[j].sin]))
        .collect();
    let pick = |f: fn((f64, f64)) -> f64| -> Vec<f64> {
        split
            .iter()
            .map(|s| s.map_or(f64::NAN, |s| f(s) * inv_arm))
            .collect()
    };
    let mut rows = vec![row("pitch-link load", LINK, link)?];
    for (k, (name, v)) in names.iter().zip(&parts).enumerate() {
        rows.push(row(name, PARTS[k], v)?);
        if k == 0 {
            let mean = rows.last().map_or(0.0, |r| r.mean_n);
            rows.push(ContributorRow {
                name: "bearing in phase with the pitch angle (spring)".into(),
                channel: HINGE_MOMENT_CHANNELS[2].into(),
                mean_n: mean,
                amplitude_n: pick(|s| s.0),
            });
            rows.push(ContributorRow {
                name: "bearing in quadrature with the pitch angle (damping)".into(),
                channel: HINGE_MOMENT_CHANNELS[2].into(),
                mean_n: 0.0,
                amplitude_n: pick(|s| s.1),
            });
        }
    }
    // the contributors' sum against the load, over the revolution
    let st = super::summary::Stats::of(link);
    let scale = st
        .peak_to_peak
        .max(st.min.abs())
        .max(st.max.abs())
        .max(f64::MIN_POSITIVE);
    let worst = (0..link.len())
        .map(|i| (link[i] - parts.iter().map(|p| p[i]).sum::<f64>()).abs() / scale)
        .fold(0.0f64, |m, x| if x.is_nan() { f64::NAN } else { m.max(x) });
    Some(PitchLinkBreakdown {
        rows,
        balance_check: EquilibriumCheck {
            max_rel_error: worst,
            channel: LINK.into(),
            tolerance: PITCH_LINK_BALANCE_TOL,
            passed: worst <= PITCH_LINK_BALANCE_TOL,
        },
    })
}

/// summary.json `loads`: per load channel mean, half peak-to-peak and harmonics 0-10/rev
/// (amplitude, phase), the equilibrium check and the pitch-link breakdown. Null for a run
/// without load channels.
pub fn loads_json(r: &ModelRun) -> serde_json::Value {
    use serde_json::json;
    let channels = channels_json(r, is_load_channel);
    if channels.is_empty() {
        return serde_json::Value::Null;
    }
    json!({
        "channels": channels,
        "equilibrium_check": r.loads_check,
        "pitch_link_contributors": pitch_link_breakdown(r),
    })
}

#[cfg(test)]
mod tests {
    use super::load_scales;

    #[test]
    fn a_steady_load_is_measured_by_its_magnitude_and_a_zero_one_by_its_units() {
        let steady = [3.0e5; 8]; // centrifugal force in hover: no peak-to-peak
        let cyclic: Vec<f64> = (0..8).map(|k| 2.0e3 * (k as f64).sin()).collect();
        let zero = [1e-9; 8];
        let moment = [1.0e4; 8];
        let s = load_scales(&[&steady, &cyclic, &zero, &moment, &zero, &cyclic]);
        assert_eq!(s[0], 3.0e5);
        let ptp = cyclic.iter().cloned().fold(f64::MIN, f64::max)
            - cyclic.iter().cloned().fold(f64::MAX, f64::min);
        assert_eq!(s[1], ptp);
        // a force channel near zero: 1e-3 of the largest force, not its round-off
        assert_eq!(s[2], 3.0e2);
        // moments are scaled among moments
        assert_eq!(s[4], 1.0e1);
        assert_eq!(s[5], ptp.max(1.0e1));
    }
}
