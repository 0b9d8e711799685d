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
    // the revolutions kept along the way are each blade's, in its folder
    run.all_revs = Vec::new();
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
    // the blades share threads: the rotor's wall time runs from its first blade's start to
    // its last blade's end
    let spans: Vec<_> = blades.iter().filter_map(|b| b.span).collect();
    run.span = spans
        .iter()
        .map(|s| s.0)
        .min()
        .zip(spans.iter().map(|s| s.1).max());
    run.wall_s = match run.span {
        Some((a, b)) if spans.len() == blades.len() => (b - a).as_secs_f64(),
        _ => blades.iter().map(|b| b.wall_s).fold(0.0, f64::max),
    };
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

/// The airframe's equation of motion against the rotor's loads on it, over the reported
/// revolution: per moving direction, the largest `|m a + c v + k u - F_hub|` against the
/// largest `|F_hub|`.
#[derive(Clone, Debug, serde::Serialize)]
pub struct AirframeCheck {
    pub directions: Vec<AirframeBalance>,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct AirframeBalance {
    /// `x`, `y`, `z`, `roll` or `pitch`.
    pub direction: String,
    /// Largest imbalance [N or N m].
    pub max_imbalance: f64,
    /// Largest rotor load on the airframe in this direction [N or N m].
    pub max_hub_load: f64,
    /// Largest ratio of the imbalance to the residual tolerance of its step (at most 1: the
    /// balance holds to what Newton was asked for).
    pub max_over_step_tolerance: f64,
}

/// The channels of `run` at `idx`, renamed `names`, as a run of their own (last revolution and
/// kept revolutions alike).
fn select(run: &ModelRun, idx: &[usize], names: Vec<String>) -> ModelRun {
    let mut r = run.clone();
    r.channel_names = names;
    r.last_rev = idx.iter().map(|&i| run.last_rev[i].clone()).collect();
    for (kr, src) in r.all_revs.iter_mut().zip(&run.all_revs) {
        kr.samples = idx.iter().map(|&i| src.samples[i].clone()).collect();
    }
    r.blade_runs = Vec::new();
    r
}

/// A whole rotor simulated as one model (blades coupled through a moving hub) split into its
/// blades' runs and combined as [`combine`] does, with the whole model's periodicity, state and
/// Floquet multipliers, the airframe's channels and its momentum check. `whole` holds blade 1's
/// channels without prefix (its equilibrium check already taken), blade K's as `b<K>.`, then
/// the airframe's; `limits`: each blade's relief-valve limits.
pub fn combine_coupled(
    whole: ModelRun,
    n: usize,
    limits: &[Option<(f64, f64)>],
) -> anyhow::Result<ModelRun> {
    use crate::rotor::sim::AIRFRAME_EOM_PREFIX;
    let is_airframe = |c: &str| c.starts_with("airframe_") || c.starts_with(AIRFRAME_EOM_PREFIX);
    let blade_of = |c: &str| -> Option<(usize, String)> {
        let rest = c.strip_prefix('b')?;
        let (k, name) = rest.split_once('.')?;
        Some((k.parse().ok()?, name.to_string()))
    };
    let mut blades = Vec::with_capacity(n);
    for k in 1..=n {
        let (idx, names): (Vec<usize>, Vec<String>) = whole
            .channel_names
            .iter()
            .enumerate()
            .filter_map(|(i, c)| match blade_of(c) {
                Some((j, name)) if j == k => Some((i, name)),
                None if k == 1 && !is_airframe(c) => Some((i, c.clone())),
                _ => None,
            })
            .unzip();
        let mut r = select(&whole, &idx, names);
        r.blade = Some(k);
        r.blades = None;
        r.periodic_state = None;
        r.force_limits_n = limits.get(k - 1).copied().flatten();
        if k > 1 {
            super::loads::finish(&mut r, None);
        }
        blades.push(r);
    }
    let mut run = combine(blades)?;
    run.periodic = whole.periodic.clone();
    run.periodic_state = whole.periodic_state.clone();
    run.revolutions = whole.revolutions;
    run.timing = whole.timing;
    run.wall_s = whole.wall_s;
    run.build_s = whole.build_s;
    for b in &mut run.blade_runs {
        b.periodic = whole.periodic.clone();
        b.periodic.floquet_multipliers = Vec::new();
    }
    let mut directions = Vec::new();
    let tol = whole
        .channel_names
        .iter()
        .position(|c| c == crate::rotor::sim::AIRFRAME_STEP_TOLERANCE)
        .map(|i| &whole.last_rev[i]);
    for (i, c) in whole.channel_names.iter().enumerate() {
        if c == crate::rotor::sim::AIRFRAME_STEP_TOLERANCE {
            continue;
        }
        if let Some(eom) = c.strip_prefix(AIRFRAME_EOM_PREFIX) {
            // eom_airframe_<dir>_<unit> pairs with airframe_<dir>_hub_{force_N,moment_Nm}
            let dir = eom
                .strip_prefix("airframe_")
                .and_then(|r| r.rsplit_once('_'))
                .map(|(d, _)| d.to_string())
                .unwrap_or_default();
            let hub = whole.channel_names.iter().position(|h| {
                h == &format!("airframe_{dir}_hub_force_N")
                    || h == &format!("airframe_{dir}_hub_moment_Nm")
            });
            let Some(j) = hub else { continue };
            let (a, f) = (&whole.last_rev[i], &whole.last_rev[j]);
            let max_imbalance = a
                .iter()
                .zip(f)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            let max_hub_load = f.iter().map(|x| x.abs()).fold(0.0, f64::max);
            let max_over_step_tolerance = match tol {
                Some(t) => a
                    .iter()
                    .zip(f)
                    .zip(t)
                    .map(|((x, y), t)| (x - y).abs() / t)
                    .fold(0.0, f64::max),
                None => f64::NAN,
            };
            directions.push(AirframeBalance {
                direction: dir,
                max_imbalance,
                max_hub_load,
                max_over_step_tolerance,
            });
        } else if c.starts_with("airframe_") {
            run.channel_names.push(c.clone());
            run.last_rev.push(whole.last_rev[i].clone());
        }
    }
    run.airframe_check = Some(AirframeCheck { directions });
    Ok(run)
}
