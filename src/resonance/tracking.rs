//! Helpers of the amplitude check ([`super::amplitude`]): the Floquet basis of a reduced rotor
//! (right and left eigenvectors of its monodromy matrix over one revolution), the mode that
//! continues a previous one by its modal assurance criterion (MAC), the projection of a
//! response onto that mode, and the dampers brought to their pressurised, periodic state on a
//! prescribed stroke before a free response starts.
use crate::stability::{BladeDamper, Mode};
use anyhow::{anyhow, bail};
use faer::{c64, Mat};
use std::f64::consts::PI;

/// Below this MAC with the previous amplitude's mode the tracking is called ambiguous.
pub const AMBIGUOUS_MAC: f64 = 0.8;

/// A mode of a reduced rotor followed in a response: at the start of a revolution (blade 1
/// at zero azimuth) its right eigenvector `right` (individual blade coordinates, the state
/// `[q, q']`), scaled so that `Re(right)` has a cyclic lag amplitude of 1 rad, and the left
/// one `left` with `left . right = 1`: the modal coordinate of a state `z` is `c = left . z`
/// and the mode's part of the state `2 Re(c right)`, of cyclic lag amplitude `2 |c|`.
#[derive(Clone, Debug)]
pub struct TrackedMode {
    /// The mode's eigenvalue (frequency resolved) and label.
    pub mode: Mode,
    pub right: Vec<c64>,
    pub left: Vec<c64>,
    /// MAC with the mode it continues (1 for the first).
    pub mac: f64,
    /// The next best MAC among the rotor's other modes (0 for the first).
    pub runner_up_mac: f64,
}

impl TrackedMode {
    /// The mode's real state of cyclic lag amplitude 1 rad (its phase at zero).
    pub fn unit_state(&self) -> Vec<f64> {
        self.right.iter().map(|v| v.re).collect()
    }
    /// The modal coordinate of `z`.
    pub fn coordinate(&self, z: &[f64]) -> c64 {
        self.left
            .iter()
            .zip(z)
            .fold(c64::new(0.0, 0.0), |s, (l, &x)| s + *l * x)
    }
    /// Whether the continuation was ambiguous.
    pub fn ambiguous(&self) -> bool {
        self.mac < AMBIGUOUS_MAC
    }
}

/// Modal assurance criterion of two complex vectors, `|a^H b|^2 / (|a|^2 |b|^2)`.
pub fn mac(a: &[c64], b: &[c64]) -> f64 {
    let (mut ab, mut aa, mut bb) = (c64::new(0.0, 0.0), 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        ab += x.conj() * *y;
        aa += x.norm_sqr();
        bb += y.norm_sqr();
    }
    if aa > 0.0 && bb > 0.0 {
        ab.norm_sqr() / (aa * bb)
    } else {
        0.0
    }
}

/// Cyclic lag amplitude of a real state (see [`crate::stability::cyclic_amplitude`]) at zero
/// time.
fn unit_scale(v: &[c64], blades: usize, omega: f64, w: f64) -> f64 {
    let re: Vec<f64> = v.iter().map(|x| x.re).collect();
    crate::stability::cyclic_amplitude(&re, blades, omega, 0.0, w)
}

/// Which mode to take.
pub enum Follow<'a> {
    /// The mode of eigenvalue nearest this one (the first, the labelled regressing lag).
    Eigenvalue(c64),
    /// The mode of largest MAC with this right eigenvector.
    Vector(&'a [c64]),
}

/// The mode of the rotor of monodromy `phi` (column-major, `m x m`, over one revolution at
/// `omega`) and resolved modes `modes` (one per conjugate pair) that `follow` picks.
pub fn track(
    phi: &[f64],
    m: usize,
    modes: &[Mode],
    omega: f64,
    blades: usize,
    follow: Follow,
) -> anyhow::Result<TrackedMode> {
    use faer::linalg::solvers::Solve;
    if phi.len() != m * m || m == 0 {
        bail!("monodromy of {} values for {m} states", phi.len());
    }
    let a = Mat::<f64>::from_fn(m, m, |i, j| phi[j * m + i]);
    let eig = a
        .eigen()
        .map_err(|e| anyhow!("eigenvectors of the monodromy matrix: {e:?}"))?;
    let mus: Vec<c64> = (0..m).map(|j| eig.S().column_vector()[j]).collect();
    let u = eig.U().to_owned();
    let inv = u.partial_piv_lu().solve(Mat::<c64>::from_fn(m, m, |i, j| {
        c64::new(f64::from(u8::from(i == j)), 0.0)
    }));
    if (0..m).any(|i| (0..m).any(|j| !(inv[(i, j)].re.is_finite() && inv[(i, j)].im.is_finite()))) {
        bail!("the monodromy matrix's eigenvectors are not independent (a defective mode)");
    }
    let period = 2.0 * PI / omega;
    // each resolved mode with its column of the decomposition
    let cands: Vec<(Mode, usize)> = modes
        .iter()
        .filter_map(|md| {
            let mu = (md.eigenvalue * period).exp();
            (0..m)
                .min_by(|&p, &q| (mus[p] - mu).norm().total_cmp(&(mus[q] - mu).norm()))
                .map(|j| (md.clone(), j))
        })
        .collect();
    let col = |j: usize| -> Vec<c64> { (0..m).map(|i| u[(i, j)]).collect() };
    let (pick, mac_best, runner) = match follow {
        Follow::Eigenvalue(l) => {
            let k = (0..cands.len())
                .min_by(|&p, &q| {
                    (cands[p].0.eigenvalue - l)
                        .norm()
                        .total_cmp(&(cands[q].0.eigenvalue - l).norm())
                })
                .ok_or_else(|| anyhow!("the reduced rotor has no modes"))?;
            (k, 1.0, 0.0)
        }
        Follow::Vector(prev) => {
            let macs: Vec<f64> = cands.iter().map(|(_, j)| mac(prev, &col(*j))).collect();
            let k = (0..cands.len())
                .max_by(|&p, &q| macs[p].total_cmp(&macs[q]))
                .ok_or_else(|| anyhow!("the reduced rotor has no modes"))?;
            let runner = (0..cands.len())
                .filter(|&p| p != k && cands[p].1 != cands[k].1)
                .map(|p| macs[p])
                .fold(0.0f64, f64::max);
            (k, macs[k], runner)
        }
    };
    let (mode, j) = cands[pick].clone();
    let mut right = col(j);
    // the phase: the largest lag entry real and positive
    let big = (0..blades)
        .max_by(|&p, &q| right[p].norm().total_cmp(&right[q].norm()))
        .unwrap_or(0);
    let ph = if right[big].norm() > 0.0 {
        right[big].conj() / right[big].norm()
    } else {
        c64::new(1.0, 0.0)
    };
    right.iter_mut().for_each(|v| *v *= ph);
    let s = unit_scale(&right, blades, omega, mode.eigenvalue.im.abs().max(1e-9));
    if !(s > 0.0 && s.is_finite()) {
        bail!(
            "the {} mode ({:.4} Hz) has no cyclic lag motion to follow",
            mode.label,
            mode.frequency_hz
        );
    }
    right.iter_mut().for_each(|v| *v /= s);
    // left: row j of U^-1 scaled to the new right (row . column = 1)
    let f = ph / s;
    let left: Vec<c64> = (0..m).map(|i| inv[(j, i)] / f).collect();
    Ok(TrackedMode {
        mode,
        right,
        left,
        mac: mac_best,
        runner_up_mac: runner,
    })
}

/// Lag angle of blade `k` (of `blades`) at time `t` on the mode at constant cyclic amplitude
/// `scale` rad: the multi-blade coordinates of its right eigenvector's lag entries turned at
/// the mode's fixed-frame frequency, `zeta_k = Re((C cos psi_k + S sin psi_k) e^{i w t})`,
/// `psi_k = Omega t + 2 pi k / N` (exact for an isotropic rotor; for one whose blades differ,
/// the cyclic whirl of its mode at zero time).
pub struct Whirl {
    c: c64,
    s: c64,
    w: f64,
    omega: f64,
    blades: usize,
    scale: f64,
}

impl Whirl {
    pub fn of(t: &TrackedMode, blades: usize, omega: f64, scale: f64) -> Self {
        let (mut c, mut s) = (c64::new(0.0, 0.0), c64::new(0.0, 0.0));
        for k in 0..blades {
            let (sn, cs) = (2.0 * PI * k as f64 / blades as f64).sin_cos();
            c += t.right[k] * cs;
            s += t.right[k] * sn;
        }
        let f = 2.0 / blades as f64;
        Whirl {
            c: c * f,
            s: s * f,
            w: t.mode.eigenvalue.im,
            omega,
            blades,
            scale,
        }
    }
    pub fn lag(&self, k: usize, t: f64) -> f64 {
        let (sn, cs) = (self.omega * t + 2.0 * PI * k as f64 / self.blades as f64).sin_cos();
        let e = c64::new(0.0, self.w * t).exp();
        self.scale * ((self.c * cs + self.s * sn) * e).re
    }
}

/// Most damper cycles of the pressurising run before a start.
pub const SETTLE_MAX_CYCLES: usize = 32;
/// Damper cycles of the first pressurising run (doubled until settled).
pub const SETTLE_MIN_CYCLES: usize = 2;
/// Change of a damper's mean force and of its RMS force about the mean over the last damper
/// cycle before the start, from a pressurising run of `n / 2` cycles to one of `n`, relative
/// to the RMS force, at which the devices count as settled. The two runs end on the same
/// stroke, so that only the devices' history differs (the check valves' ratcheting of the
/// mean pressures), not the stroke (which for an elliptic whirl is not periodic in the
/// damper's cycle).
pub const SETTLE_TOL: f64 = 1e-3;

/// How the devices were brought to their periodic state.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Settled {
    /// Damper cycles run on the prescribed stroke before the free response.
    pub cycles: usize,
    /// The last cycle's change of mean and RMS force over the RMS force (largest blade)
    /// from the run of half as many cycles.
    pub change: f64,
}

/// The dampers run alone on the stroke of `whirl` (each blade's `arm * zeta_k(t)`) from
/// `-n P` to 0 (`P` the damper's cycle, steps of `dt`), `n` doubled from
/// [`SETTLE_MIN_CYCLES`] until the last cycle's mean and RMS forces agree with the previous
/// run's within [`SETTLE_TOL`] or [`SETTLE_MAX_CYCLES`] is reached; each device reset before
/// each run. They end at zero time on the stroke the free response starts from.
pub fn settle(
    dampers: &mut [BladeDamper],
    whirl: &Whirl,
    period_s: f64,
    dt: f64,
) -> anyhow::Result<Settled> {
    let per = (period_s / dt).ceil().max(8.0) as usize;
    let nb = dampers.len();
    let mut n = SETTLE_MIN_CYCLES;
    let mut before: Option<Vec<(f64, f64)>> = None;
    loop {
        for d in dampers.iter_mut() {
            d.device.reset();
        }
        let steps = n * per;
        let t0 = -(steps as f64) * dt;
        // per blade: sums of force and force^2 over the last cycle
        let mut sums = vec![[0.0f64; 2]; nb];
        for i in 0..steps {
            let t = t0 + i as f64 * dt;
            let last = i >= steps - per;
            for (k, d) in dampers.iter_mut().enumerate() {
                let (a, b) = (d.arm_m * whirl.lag(k, t), d.arm_m * whirl.lag(k, t + dt));
                let f = d
                    .device
                    .trial_step(t, dt, a, b)
                    .map_err(|e| {
                        anyhow!(
                            "the damper of blade {} on its prescribed stroke at t = {t:.6} s (before the start): {e}",
                            k + 1
                        )
                    })?
                    .force_mean;
                d.device.commit();
                if last {
                    sums[k][0] += f;
                    sums[k][1] += f * f;
                }
            }
        }
        let stats: Vec<(f64, f64)> = sums
            .iter()
            .map(|s| {
                let m = s[0] / per as f64;
                (m, (s[1] / per as f64 - m * m).max(0.0).sqrt())
            })
            .collect();
        if let Some(b) = &before {
            let change = stats
                .iter()
                .zip(b)
                .map(|(x, y)| ((x.0 - y.0).abs() + (x.1 - y.1).abs()) / x.1.max(1e-30))
                .fold(0.0f64, f64::max);
            if change <= SETTLE_TOL || n >= SETTLE_MAX_CYCLES {
                return Ok(Settled { cycles: n, change });
            }
        }
        before = Some(stats);
        n = (2 * n).min(SETTLE_MAX_CYCLES);
    }
}

/// Growth rate [1/s] (least-squares slope of `ln |c|`) and the geometric mean of `|c|` over
/// the samples `(t, |c|)`.
pub fn fit_log(samples: &[(f64, f64)]) -> (f64, f64) {
    let pts: Vec<(f64, f64)> = samples.iter().map(|&(t, a)| (t, a.ln())).collect();
    let g = crate::analysis::compare::slope(&pts);
    let mean = pts.iter().map(|p| p.1).sum::<f64>() / pts.len().max(1) as f64;
    (g, mean.exp())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mac_is_one_for_a_multiple_and_zero_for_orthogonal() {
        let a = [c64::new(1.0, 2.0), c64::new(-0.5, 0.1)];
        let b: Vec<c64> = a.iter().map(|x| *x * c64::new(0.3, -4.0)).collect();
        assert!((mac(&a, &b) - 1.0).abs() < 1e-12);
        let o = [c64::new(0.0, 0.0), c64::new(1.0, 0.0)];
        let p = [c64::new(1.0, 0.0), c64::new(0.0, 0.0)];
        assert_eq!(mac(&o, &p), 0.0);
    }
}
