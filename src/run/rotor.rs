//! A whole-rotor run on a driven hub: every blade is run as its own model (blade k at azimuth
//! (k-1) 360/N ahead of blade 1, with its own deck) and the runs are combined into the rotor's:
//! blade 1's channels, the hub loads as the sum of every blade's actual root loads (no
//! symmetry assumed), the periodicity and Floquet multipliers of the whole.
//!
//! On a driven hub the blades are coupled only through prescribed motion (the hub turns at
//! Omega, the swashplate follows the controls), so the whole rotor's equations are
//! block-diagonal by blade: each blade's periodic solution, on its own core, is the whole
//! rotor's, and its monodromy matrix is block-diagonal with the blades' as blocks.
use super::loads::HUB_CHANNELS;
use super::ModelRun;
use crate::loads::hub;
use crate::rotor::loads::ROOT_CHANNELS;

/// Rotating-frame hub load channels (the frame turning with blade 1, x along it), in the order
/// of [`ROOT_CHANNELS`].
pub const HUB_ROTATING_CHANNELS: [&str; 6] = [
    "hub_fx_rotating_N",
    "hub_fy_rotating_N",
    "hub_fz_rotating_N",
    "hub_mx_rotating_Nm",
    "hub_my_rotating_Nm",
    "hub_mz_rotating_Nm",
];

/// Azimuth of blade `k` (1 to `n`) ahead of blade 1 [deg].
pub fn blade_azimuth_deg(k: usize, n: usize) -> f64 {
    (k - 1) as f64 * 360.0 / n as f64
}

/// Floquet multipliers kept for the whole rotor: the least damped of all blades.
const FLOQUET_KEPT: usize = 2 * super::periodic::FLOQUET_REPORTED;

/// The rotor's run from its blades' runs (blade 1 first, all sampled alike): blade 1's
/// channels, then the hub loads in the rotating frame and in the fixed frame.
pub fn combine(blades: Vec<ModelRun>) -> anyhow::Result<ModelRun> {
    let n = blades.len();
    let first = blades
        .first()
        .ok_or_else(|| anyhow::anyhow!("a whole-rotor run without blades"))?;
    let m = first.azimuth_deg.len();
    for b in &blades[1..] {
        if b.azimuth_deg != first.azimuth_deg {
            anyhow::bail!(
                "blade {} is sampled at other azimuths than blade 1 ({} against {} samples)",
                b.blade.unwrap_or(0),
                b.azimuth_deg.len(),
                m
            );
        }
    }
    let mut rotating = vec![vec![0.0; m]; 6];
    let mut fixed = vec![vec![0.0; m]; 6];
    let mut have_root = true;
    for (i, b) in blades.iter().enumerate() {
        let root: Option<Vec<&[f64]>> = ROOT_CHANNELS.iter().map(|c| b.channel(c)).collect();
        let Some(root) = root else {
            have_root = false;
            break;
        };
        let ahead = blade_azimuth_deg(b.blade.unwrap_or(i + 1), n).to_radians();
        for j in 0..m {
            let psi = first.azimuth_deg[j].to_radians();
            for part in 0..2 {
                let v = std::array::from_fn(|c| root[3 * part + c][j]);
                let r = hub::to_fixed(ahead, v);
                let f = hub::to_fixed(psi + ahead, v);
                for c in 0..3 {
                    rotating[3 * part + c][j] += r[c];
                    fixed[3 * part + c][j] += f[c];
                }
            }
        }
    }
    let mut run = first.clone();
    run.blade = None;
    run.blades = None;
    run.periodic_state = None;
    if have_root {
        for (c, y) in rotating.into_iter().enumerate() {
            run.channel_names.push(HUB_ROTATING_CHANNELS[c].to_string());
            run.last_rev.push(y);
        }
        for (c, y) in fixed.into_iter().enumerate() {
            run.channel_names.push(HUB_CHANNELS[c].to_string());
            run.last_rev.push(y);
        }
    }
    // the whole rotor is periodic when every blade is; its worst blade speaks for it
    let worst = blades
        .iter()
        .max_by(|a, b| a.periodic.residual.total_cmp(&b.periodic.residual))
        .unwrap_or(first);
    let mut p = worst.periodic.clone();
    p.converged = blades.iter().all(|b| b.periodic.converged);
    // the blades run side by side: the rotor took as many revolutions as its slowest blade
    p.revolutions_integrated = blades
        .iter()
        .map(|b| b.periodic.revolutions_integrated)
        .max()
        .unwrap_or(0);
    let mut mult: Vec<_> = blades
        .iter()
        .flat_map(|b| {
            let k = b.blade.unwrap_or(0);
            b.periodic.floquet_multipliers.iter().map(move |mu| {
                let mut mu = mu.clone();
                mu.mode = if mu.mode.is_empty() {
                    format!("blade {k}")
                } else {
                    format!("blade {k} {}", mu.mode)
                };
                mu
            })
        })
        .collect();
    mult.sort_by(|a, b| b.magnitude.total_cmp(&a.magnitude));
    mult.truncate(FLOQUET_KEPT);
    p.floquet_multipliers = mult;
    p.error_estimate = blades
        .iter()
        .filter_map(|b| b.periodic.error_estimate)
        .reduce(f64::max);
    if worst.blade != first.blade {
        let note = format!(
            "the least periodic blade is blade {}",
            worst.blade.unwrap_or(0)
        );
        p.message = if p.message.is_empty() {
            note
        } else {
            format!("{note}: {}", p.message)
        };
    }
    run.periodic = p;
    run.revolutions = blades.iter().map(|b| b.revolutions).max().unwrap_or(0);
    run.timing = blades.iter().fold(Default::default(), |t, b| {
        let s = &b.timing;
        crate::rotor::Timing {
            total_s: t.total_s + s.total_s,
            hydraulics_s: t.hydraulics_s + s.hydraulics_s,
            steps: t.steps + s.steps,
            iterations: t.iterations + s.iterations,
            factorizations: t.factorizations + s.factorizations,
            relaxed_steps: t.relaxed_steps + s.relaxed_steps,
        }
    });
    run.wall_s = blades.iter().map(|b| b.wall_s).fold(0.0, f64::max);
    run.build_s = blades.iter().map(|b| b.build_s).fold(0.0, f64::max);
    run.loads_check = blades
        .iter()
        .filter_map(|b| {
            let mut c = b.loads_check.clone()?;
            c.channel = format!("blade {} {}", b.blade.unwrap_or(0), c.channel);
            Some(c)
        })
        .max_by(|a, b| a.max_rel_error.total_cmp(&b.max_rel_error));
    run.blade_runs = blades;
    Ok(run)
}
