//! Dashpot idealizations of a damper: linear `F = -c d_dot` and nonlinear
//! `F = -sign(v) f(|v|)` with `f` a monotone (Fritsch-Carlson) interpolation of a table.
//! On a straight step the stroke rate is constant, so `F_m` is exact; on a replay's Hermite
//! path the force at the step's end is the law at the end's rate.
use super::{Device, HydraulicError, StepForce, StepResult, StrokePath};
use std::sync::Arc;

const CHANNELS: &[&str] = &["velocity_m_s"];

/// Linear dashpot `F = -c d_dot`.
#[derive(Debug, Clone)]
pub struct LinearDashpot {
    pub c: f64,
    committed_v: f64,
    trial_v: Option<f64>,
}

impl LinearDashpot {
    pub fn new(c_n_s_per_m: f64) -> Self {
        Self {
            c: c_n_s_per_m,
            committed_v: 0.0,
            trial_v: None,
        }
    }
}

/// The state of a dashpot, the committed stroke rate (and the trial's), its channel and its
/// protocol: the same `Device` methods for both dashpots.
macro_rules! rate_state {
    () => {
        fn commit(&mut self) {
            if let Some(v) = self.trial_v.take() {
                self.committed_v = v;
            }
        }
        fn channel_names(&self) -> &'static [&'static str] {
            CHANNELS
        }
        fn channels(&self, out: &mut [f64]) {
            out[0] = self.committed_v;
        }
        fn clone_device(&self) -> Box<dyn Device> {
            Box::new(self.clone())
        }
        fn state_values(&self) -> Vec<f64> {
            vec![self.committed_v]
        }
        fn set_state_values(&mut self, v: &[f64]) -> Result<(), HydraulicError> {
            super::check_state_len("dashpot", v, 1)?;
            self.committed_v = v[0];
            self.trial_v = None;
            Ok(())
        }
        fn reset(&mut self) {
            self.committed_v = 0.0;
            self.trial_v = None;
        }
    };
}

impl Device for LinearDashpot {
    fn step_along(&mut self, _t_i: f64, path: &StrokePath) -> StepResult {
        // the mean rate is the chord's on any path
        let v = path.chord_rate();
        let v_end = path.end_rate();
        self.trial_v = Some(v_end);
        Ok(StepForce {
            force_mean: -self.c * v,
            dforce_dstroke: -self.c / path.dt,
            force_end: -self.c * v_end,
        })
    }
    fn committed_force(&self) -> f64 {
        -self.c * self.committed_v
    }
    rate_state!();
}

/// Monotone piecewise-cubic interpolant (Fritsch-Carlson) of a non-decreasing table, extended
/// linearly with the end slope beyond the last point.
#[derive(Debug, Clone, PartialEq)]
pub struct MonotoneTable {
    x: Vec<f64>,
    y: Vec<f64>,
    m: Vec<f64>,
}

impl MonotoneTable {
    /// `x` strictly increasing from 0, `y` non-decreasing from 0, at least 2 points.
    pub fn new(x: Vec<f64>, y: Vec<f64>) -> Result<Self, String> {
        let n = x.len();
        if n < 2 || y.len() != n {
            return Err(format!(
                "need at least 2 points and equal lengths (got {} velocities, {} forces)",
                n,
                y.len()
            ));
        }
        if x.iter().chain(&y).any(|v| !v.is_finite()) {
            return Err("table has a non-finite entry".into());
        }
        if x[0] != 0.0 || y[0] != 0.0 {
            return Err("table must start at velocity 0 with force 0".into());
        }
        if let Some(i) = x.windows(2).position(|w| w[1] <= w[0]) {
            return Err(format!(
                "velocities not strictly increasing at entry {}",
                i + 1
            ));
        }
        if let Some(i) = y.windows(2).position(|w| w[1] < w[0]) {
            return Err(format!(
                "forces decrease at entry {} (the table must be monotone)",
                i + 1
            ));
        }
        let delta: Vec<f64> = (0..n - 1)
            .map(|i| (y[i + 1] - y[i]) / (x[i + 1] - x[i]))
            .collect();
        let mut m = vec![0.0; n];
        m[0] = delta[0];
        m[n - 1] = delta[n - 2];
        for i in 1..n - 1 {
            m[i] = if delta[i - 1] * delta[i] <= 0.0 {
                0.0
            } else {
                // Fritsch-Carlson: harmonic mean keeps each segment monotone.
                2.0 * delta[i - 1] * delta[i] / (delta[i - 1] + delta[i])
            };
        }
        for i in 0..n - 1 {
            if delta[i] == 0.0 {
                m[i] = 0.0;
                m[i + 1] = 0.0;
            } else {
                let (a, b) = (m[i] / delta[i], m[i + 1] / delta[i]);
                let s = a * a + b * b;
                if s > 9.0 {
                    let tau = 3.0 / s.sqrt();
                    m[i] = tau * a * delta[i];
                    m[i + 1] = tau * b * delta[i];
                }
            }
        }
        Ok(Self { x, y, m })
    }

    /// f(v) and f'(v) for v >= 0.
    pub fn eval(&self, v: f64) -> (f64, f64) {
        let n = self.x.len();
        if v >= self.x[n - 1] {
            let s = self.m[n - 1];
            return (self.y[n - 1] + s * (v - self.x[n - 1]), s);
        }
        let i = self.x.partition_point(|&k| k <= v).saturating_sub(1);
        let h = self.x[i + 1] - self.x[i];
        let t = (v - self.x[i]) / h;
        let (t2, t3) = (t * t, t * t * t);
        let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
        let h10 = t3 - 2.0 * t2 + t;
        let h01 = -2.0 * t3 + 3.0 * t2;
        let h11 = t3 - t2;
        let f =
            h00 * self.y[i] + h10 * h * self.m[i] + h01 * self.y[i + 1] + h11 * h * self.m[i + 1];
        let d00 = 6.0 * t2 - 6.0 * t;
        let d10 = 3.0 * t2 - 4.0 * t + 1.0;
        let d01 = -6.0 * t2 + 6.0 * t;
        let d11 = 3.0 * t2 - 2.0 * t;
        let df =
            (d00 * self.y[i] + d01 * self.y[i + 1]) / h + d10 * self.m[i] + d11 * self.m[i + 1];
        (f, df)
    }
}

/// Nonlinear dashpot `F = -sign(v) f(|v|)`.
#[derive(Debug, Clone)]
pub struct NonlinearDashpot {
    table: Arc<MonotoneTable>,
    committed_v: f64,
    trial_v: Option<f64>,
}

impl NonlinearDashpot {
    pub fn new(table: MonotoneTable) -> Self {
        Self {
            table: Arc::new(table),
            committed_v: 0.0,
            trial_v: None,
        }
    }

    /// F(v) and dF/dv.
    pub fn force(&self, v: f64) -> (f64, f64) {
        let (f, df) = self.table.eval(v.abs());
        (-f.copysign(v), -df)
    }
}

impl Device for NonlinearDashpot {
    fn step_along(&mut self, _t_i: f64, path: &StrokePath) -> StepResult {
        let v = path.chord_rate();
        let (f, df) = self.force(v);
        let v_end = path.end_rate();
        self.trial_v = Some(v_end);
        Ok(StepForce {
            force_mean: path.mean_of_rate(|r| self.force(r).0),
            dforce_dstroke: df / path.dt,
            force_end: if path.is_linear() {
                f
            } else {
                self.force(v_end).0
            },
        })
    }
    fn committed_force(&self) -> f64 {
        self.force(self.committed_v).0
    }
    rate_state!();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn monotone_table_interpolates_and_is_monotone() {
        let t = MonotoneTable::new(
            vec![0.0, 0.05, 0.10, 0.20, 0.40],
            vec![0.0, 3500.0, 9000.0, 14000.0, 15500.0],
        )
        .unwrap();
        assert_eq!(t.eval(0.10).0, 9000.0);
        let mut last = -1.0;
        for i in 0..=1000 {
            let v = i as f64 * 0.5e-3;
            let (f, df) = t.eval(v);
            assert!(f >= last && df >= -1e-9, "not monotone at {v}");
            last = f;
            // derivative against a central difference
            if v > 1e-3 && (0..5).all(|k| (v - [0.0, 0.05, 0.1, 0.2, 0.4][k]).abs() > 1e-5) {
                let e = 1e-7;
                let fd = (t.eval(v + e).0 - t.eval(v - e).0) / (2.0 * e);
                assert!(
                    (fd - df).abs() < 1e-4 * df.abs().max(1.0),
                    "v {v}: {fd} vs {df}"
                );
            }
        }
    }

    #[test]
    fn nonmonotone_table_is_rejected() {
        assert!(MonotoneTable::new(vec![0.0, 1.0, 2.0], vec![0.0, 2.0, 1.0]).is_err());
    }
}
