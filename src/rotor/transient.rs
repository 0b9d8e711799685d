//! Perturbation aerodynamic damping of the forced response (docs/rotor_model.md, "Transient
//! and periodicity").
//!
//! The measured airloads are replayed as prescribed loads and carry no aerodynamic damping.
//! This adds, along the section normal (+z section axis, follower), the quasi-steady
//! lift-curve-slope damping of the deviation of the normal velocity from the same load point
//! one revolution earlier:
//!
//! `f_n(t, r) = -g c_n(r) (v_n(t, r) - v_n(t - T, r))`, `c_n(r) = 1/2 rho a c Omega r`,
//!
//! which vanishes on every T-periodic solution (the periodic solution under the measured
//! airloads is unchanged) and is zero during the first revolution. `v_n` is the section
//! normal velocity relative to the rigid rotation of the hub, `n . (v - Omega x (x - x_hub))`:
//! on a periodic solution it repeats with period T like the global velocity, but it excludes
//! the `Omega r` component that a pitch deviation rotates into the normal (an aerodynamic
//! pitch-flap coupling, not a damping), so the term is a pure plunge damping with a symmetric,
//! positive semi-definite coefficient.
//!
//! For a mode `e^{st}` the feedback is `g c_n s (1 - e^{-sT})`: at `s = i w` its damping part
//! scales with `1 - cos wT` and its stiffness part with `-sin wT` (docs/rotor_model.md).
use super::deck::RotorSpec;
use crate::flight::FlightRecord;
use crate::structure::beam::{SectionLoad, NPTS_M};
use crate::structure::model::{DistributedLoad, Element, LoadPoint, Model};
use crate::structure::rotation::{cross, sub};

/// Lift-curve slope of the quasi-steady damping [1/rad] (thin aerofoil, compressibility
/// ignored: 5.73 is the classical blade-element value).
pub const LIFT_SLOPE_PER_RAD: f64 = 5.73;

/// Parameters of [`PerturbationDamping`].
#[derive(Clone, Copy, Debug)]
pub struct DampingParams {
    /// Gain g (0 disables the term).
    pub gain: f64,
    /// `1/2 rho a c Omega` [N s/m^3]: `c_n(r)` per unit radius.
    pub cn_per_r_n_s_per_m3: f64,
    /// Radius of the beam's first station (`r = root_r_m + s_m`) [m].
    pub root_r_m: f64,
    /// Rigid rotation of the hub: centre [m] and angular velocity [rad/s] (global).
    pub center_m: [f64; 3],
    pub omega_rad_s: [f64; 3],
    /// Structural time step [s], exactly `T / steps_per_rev`.
    pub h_s: f64,
    pub steps_per_rev: usize,
    /// Delay in revolutions k (the term uses `v_n(t - kT)`; 1 is the brief's choice, a
    /// longer delay reaches modes close to an integer /rev, see docs/rotor_model.md).
    pub delay_revs: usize,
}

/// Ring buffer of the converged normal velocity of every load point over one revolution, and
/// the damping force it implies.
pub struct PerturbationDamping {
    p: DampingParams,
    /// Per element id: index of its first load point (usize::MAX: not a loaded element).
    first_point: Vec<usize>,
    /// Reference arc length of every load point (NPTS_M per element).
    s_m: Vec<f64>,
    /// `(delay + 1)` slots x points (delay = delay_revs steps_per_rev steps): the slot of step
    /// k is overwritten at every evaluation of step k (the last one is at the converged state)
    /// while the slot of step `k - delay` is still intact.
    ring: Vec<f64>,
    /// Step index held by each slot (i64::MIN: empty).
    stamp: Vec<i64>,
}

impl PerturbationDamping {
    /// Load points of beam elements `(element id, s_m of its NPTS_M points)`.
    pub fn from_layout(elements: &[(usize, [f64; NPTS_M])], p: DampingParams) -> Self {
        let n_el = elements.iter().map(|e| e.0 + 1).max().unwrap_or(0);
        let mut first_point = vec![usize::MAX; n_el];
        let mut s_m = Vec::with_capacity(elements.len() * NPTS_M);
        for (id, s) in elements {
            first_point[*id] = s_m.len();
            s_m.extend_from_slice(s);
        }
        let slots = p.delay_revs.max(1) * p.steps_per_rev + 1;
        PerturbationDamping {
            ring: vec![0.0; slots * s_m.len()],
            stamp: vec![i64::MIN; slots],
            first_point,
            s_m,
            p,
        }
    }

    /// The load points of beam `beam` of `model`.
    pub fn new(model: &Model, beam: &str, p: DampingParams) -> anyhow::Result<Self> {
        let ids = model
            .beams
            .get(beam)
            .ok_or_else(|| anyhow::anyhow!("perturbation damping: model has no beam `{beam}`"))?;
        let mut layout = Vec::with_capacity(ids.len());
        for &id in ids {
            if let Element::Beam(b) = &model.elements[id] {
                layout.push((id, std::array::from_fn(|q| b.gm[q].s_m)));
            }
        }
        Ok(Self::from_layout(&layout, p))
    }

    pub fn params(&self) -> &DampingParams {
        &self.p
    }

    /// Structural step index of time `t` (the step ending at t).
    pub fn step_index(&self, t: f64) -> i64 {
        (t / self.p.h_s).round() as i64
    }

    /// Index of the load point at (element, s_m), if it is one of ours.
    pub fn point_index(&self, element: usize, s_m: f64) -> Option<usize> {
        let i0 = *self.first_point.get(element)?;
        if i0 == usize::MAX {
            return None;
        }
        // exact match in practice (the beam passes its own quadrature abscissae); else nearest
        let s = &self.s_m[i0..i0 + NPTS_M];
        let q = (0..NPTS_M)
            .min_by(|&a, &b| (s[a] - s_m).abs().total_cmp(&(s[b] - s_m).abs()))
            .unwrap_or(0);
        Some(i0 + q)
    }

    /// Normal velocity relative to the rigid rotation of the hub, `n . (v - Omega x (x - x_c))`
    /// [m/s], n = section axis 3 (column 3 of the section rotation).
    pub fn normal_velocity(&self, p: &LoadPoint) -> f64 {
        let rigid = cross(self.p.omega_rad_s, sub(p.x, self.p.center_m));
        let v = sub(p.v, rigid);
        (0..3).map(|i| p.r[i][2] * v[i]).sum()
    }

    /// Delay in steps (delay_revs x steps_per_rev).
    pub fn delay_steps(&self) -> usize {
        self.p.delay_revs.max(1) * self.p.steps_per_rev
    }

    /// Store `vn` as the value of point `i` at step `k`; return the value stored for step
    /// `k - delay_steps` (None when that step was never evaluated, e.g. in the first
    /// revolutions).
    pub fn record(&mut self, k: i64, i: usize, vn: f64) -> Option<f64> {
        let slots = self.delay_steps() as i64 + 1;
        let np = self.s_m.len();
        let w = k.rem_euclid(slots) as usize;
        if self.stamp[w] != k {
            self.stamp[w] = k;
        }
        self.ring[w * np + i] = vn;
        let k_old = k - self.delay_steps() as i64;
        let r = k_old.rem_euclid(slots) as usize;
        (self.stamp[r] == k_old).then(|| self.ring[r * np + i])
    }

    /// Damping force along the section normal at `p` [N/m]; records the point's velocity.
    pub fn normal_force(&mut self, p: &LoadPoint) -> f64 {
        let Some(i) = self.point_index(p.element, p.s_m) else {
            return 0.0;
        };
        let vn = self.normal_velocity(p);
        let k = self.step_index(p.t);
        match self.record(k, i, vn) {
            Some(old) => {
                let r = self.p.root_r_m + p.s_m;
                -self.p.gain * self.p.cn_per_r_n_s_per_m3 * r * (vn - old)
            }
            None => 0.0,
        }
    }
}

/// A distributed load plus the perturbation damping along the section normal.
pub struct Damped<L: DistributedLoad> {
    pub inner: L,
    pub damping: PerturbationDamping,
}

impl<L: DistributedLoad> DistributedLoad for Damped<L> {
    fn eval(&mut self, p: &LoadPoint) -> SectionLoad {
        let mut l = self.inner.eval(p);
        let f = self.damping.normal_force(p);
        if l.follower {
            l.force[2] += f;
        } else {
            for i in 0..3 {
                l.force[i] += f * p.r[i][2];
            }
        }
        l
    }
}

/// The blade load of the forced response: `airloads` alone when the deck's
/// `blade.perturbation_damping_gain` is 0 or `enabled` is false, else wrapped in [`Damped`] with
/// `c_n(r) = 1/2 rho a c Omega r` (rho, c from the record meta `density_kg_m3`, `chord_m`).
pub fn blade_load<L: DistributedLoad + 'static>(
    airloads: L,
    model: &Model,
    beam: &str,
    spec: &RotorSpec,
    record: &FlightRecord,
    steps_per_rev: usize,
    enabled: bool,
) -> anyhow::Result<Box<dyn DistributedLoad>> {
    let gain = spec.blade.perturbation_damping_gain;
    if gain == 0.0 || !enabled {
        return Ok(Box::new(airloads));
    }
    let need = |v: Option<f64>, key: &str| {
        v.filter(|x| x.is_finite() && *x > 0.0).ok_or_else(|| {
            anyhow::anyhow!(
                "blade.perturbation_damping_gain = {gain} needs a positive `{key}` in the flight record meta"
            )
        })
    };
    let rho = need(record.meta.density_kg_m3, "density_kg_m3")?;
    let chord = need(record.meta.chord_m, "chord_m")?;
    let om = spec.rotor.omega_rad_s;
    let p = DampingParams {
        gain,
        cn_per_r_n_s_per_m3: 0.5 * rho * LIFT_SLOPE_PER_RAD * chord * om,
        root_r_m: spec.blade.root_r_m,
        center_m: [0.0; 3],
        omega_rad_s: [0.0, 0.0, om],
        h_s: 2.0 * std::f64::consts::PI / om / steps_per_rev as f64,
        steps_per_rev,
        delay_revs: spec.blade.perturbation_damping_delay_revs,
    };
    Ok(Box::new(Damped {
        inner: airloads,
        damping: PerturbationDamping::new(model, beam, p)?,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(n: usize, gain: f64) -> DampingParams {
        DampingParams {
            gain,
            cn_per_r_n_s_per_m3: 2.0,
            root_r_m: 1.0,
            center_m: [0.0; 3],
            omega_rad_s: [0.0, 0.0, 3.0],
            h_s: 0.01,
            steps_per_rev: n,
            delay_revs: 1,
        }
    }

    fn point(t: f64, element: usize, s_m: f64, x: [f64; 3], v: [f64; 3]) -> LoadPoint {
        LoadPoint {
            t,
            element,
            s_m,
            x,
            r: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            v,
            w: [0.0; 3],
        }
    }

    #[test]
    fn ring_buffer_returns_the_value_of_one_revolution_earlier() {
        let n = 5;
        let mut d = PerturbationDamping::from_layout(
            &[(2, [0.1, 0.2, 0.3, 0.4]), (7, [0.5, 0.6, 0.7, 0.8])],
            params(n, 1.0),
        );
        assert_eq!(d.point_index(2, 0.3), Some(2));
        assert_eq!(d.point_index(7, 0.5), Some(4));
        assert_eq!(d.point_index(3, 0.5), None);
        assert_eq!(d.point_index(70, 0.5), None);
        for k in 0..4 * n as i64 {
            for i in 0..8 {
                // several Newton iterates per step: the last one is kept
                d.record(k, i, -1.0);
                let old = d.record(k, i, (100 * k + i as i64) as f64);
                if k < n as i64 {
                    assert_eq!(old, None, "step {k}");
                } else {
                    assert_eq!(old, Some((100 * (k - n as i64) + i as i64) as f64));
                }
            }
        }
        // a delay of 3 revolutions
        let mut d = PerturbationDamping::from_layout(
            &[(0, [0.0; 4])],
            DampingParams {
                delay_revs: 3,
                ..params(n, 1.0)
            },
        );
        for k in 0..8 * n as i64 {
            let old = d.record(k, 1, k as f64);
            assert_eq!(old, (k >= 3 * n as i64).then(|| (k - 3 * n as i64) as f64));
        }
        // a skipped step leaves no stale value one revolution later
        let mut d = PerturbationDamping::from_layout(&[(0, [0.0; 4])], params(n, 1.0));
        d.record(0, 0, 1.0);
        assert_eq!(d.record(n as i64 + 1, 0, 1.0), None);
    }

    #[test]
    fn zero_on_a_periodic_history_and_known_value_otherwise() {
        let n = 16;
        let p = params(n, 0.7);
        let om = p.omega_rad_s[2];
        let mut d = PerturbationDamping::from_layout(&[(0, [0.0, 0.5, 1.0, 1.5])], p);
        let vn =
            |k: i64| (2.0 * std::f64::consts::PI * k.rem_euclid(n as i64) as f64 / n as f64).sin();
        for k in 0..3 * n as i64 {
            let t = k as f64 * p.h_s;
            // point rotating rigidly at (2, 0, 0) plus an elastic normal velocity
            let x = [2.0, 0.0, 0.0];
            let f = d.normal_force(&point(t, 0, 1.0, x, [0.0, 2.0 * om, vn(k)]));
            assert!(f == 0.0, "periodic history, step {k}: {f}");
        }
        // a deviation of 0.3 m/s from the previous revolution: -g c_n(r) 0.3, r = 1 + 1
        let k = 3 * n as i64;
        let f = d.normal_force(&point(
            k as f64 * p.h_s,
            0,
            1.0,
            [2.0, 0.0, 0.0],
            [0.0, 2.0 * om, vn(k) + 0.3],
        ));
        let expect = -0.7 * 2.0 * 2.0 * 0.3;
        assert!((f - expect).abs() < 1e-12, "{f} vs {expect}");
    }
}
