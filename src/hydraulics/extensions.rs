//! Model extensions beyond the paper (the paper's conclusions list what its model
//! misses: friction, force dwell near zero, asymmetric peaks). Each is a physical element:
//! - [`SealFriction`]: Coulomb/Stribeck friction of the piston and rod seals (force element in
//!   parallel with the hydraulic force);
//! - [`FreePlay`]: a gap in the attachments (kinematic backlash in series with the damper: no
//!   force is transmitted while the gap is open);
//! - [`EntrainedAir`]: free air in the oil, isothermal, giving a pressure-dependent effective
//!   bulk modulus (replaces Eq. 3 in the chambers);
//! - [`AnnularLeakage`]: leakage through the piston's annular clearance, `Q = k (p0 - p1)` in
//!   parallel with the orifice plus the Couette flow the moving piston drags along;
//! - [`Leakage`]: a laminar bypass `Q = k dp` (the accumulator bleed);
//! - [`SeriesMount`]: elastic mounts in series;
//! - [`CompliantFreePlay`]: a gap behind a contact stiffness (free play as in hardware).
//!
//! Area asymmetry (`A1_m2`) and relief-valve asymmetry (`F_p_N` per valve) are parameters of the
//! existing elements. [`ExtendedDamper`] composes a [`CircuitDevice`] with friction and free play.
use super::circuit::CircuitDevice;
use super::fluid::Fluid;
use super::link::Link;
use super::{Device, HydraulicError, StepForce, StepResult, StrokePath};

/// Seal friction: `F = -[F_c + (F_s - F_c) exp(-(v/v_s)^2)] tanh(v/v_eps)` with v the piston
/// velocity. `tanh(v/v_eps)` regularises the Coulomb sign so that the law stays continuous;
/// at |v| >> v_eps it is the Coulomb/Stribeck law exactly (tanh = 1 in f64 beyond ~19 v_eps).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SealFriction {
    /// Coulomb (sliding) friction force F_c [N].
    pub f_c: f64,
    /// Static (breakaway) friction force F_s [N] (>= F_c; F_s = F_c is pure Coulomb).
    pub f_s: f64,
    /// Stribeck velocity v_s [m/s].
    pub v_s: f64,
    /// Regularisation velocity v_eps [m/s].
    pub v_eps: f64,
    /// Presliding displacement x_p [m] (0: none). After a reversal the force approaches the
    /// sliding law over a stroke of about x_p, `dF/dd = (F_slide(v) - F) sign(d_dot) / x_p` (a
    /// Dahl-type first-order law; F_c/x_p is the seal's presliding stiffness).
    pub presliding_m: f64,
}

impl SealFriction {
    /// Pure Coulomb friction with the default regularisation (1e-4 m/s).
    pub fn coulomb(f_c: f64) -> Self {
        Self {
            f_c,
            f_s: f_c,
            v_s: 0.01,
            v_eps: 1e-4,
            presliding_m: 0.0,
        }
    }

    /// Dahl's friction (Dahl 1968, exponent 1): `dF/dt = sigma0 (v - |v| F/F_c)` for the
    /// friction F resisting the stroke rate v, i.e. along the stroke s travelled the force
    /// relaxes to `-F_c sign(v)` (on the damper) over `x_p = F_c/sigma0`: the presliding law
    /// below with the exact Coulomb sign (`v_eps = 0`) and no Stribeck bump.
    pub fn dahl(f_c: f64, sigma0: f64) -> Self {
        Self {
            f_c,
            f_s: f_c,
            v_s: 0.01,
            v_eps: 0.0,
            presliding_m: f_c / sigma0,
        }
    }

    /// Whether this is [`SealFriction::dahl`]'s friction (exact sign, presliding).
    pub fn is_dahl(&self) -> bool {
        self.v_eps == 0.0 && self.f_s == self.f_c && self.has_presliding()
    }

    /// `tanh(v/v_eps)`, the exact sign (0 at rest) when `v_eps = 0`.
    #[inline]
    fn sign_of(&self, v: f64) -> f64 {
        if self.v_eps == 0.0 {
            if v == 0.0 {
                0.0
            } else {
                v.signum()
            }
        } else {
            (v / self.v_eps).tanh()
        }
    }

    /// Friction force on the damper (opposes the piston velocity `v`) [N].
    #[inline]
    pub fn force(&self, v: f64) -> f64 {
        let s = (-(v / self.v_s).powi(2)).exp();
        -(self.f_c + (self.f_s - self.f_c) * s) * self.sign_of(v)
    }

    /// With presliding: the force at the end of a step and its mean over the step, from `f0` at
    /// its start, the stroke moving by `dd` at the constant rate `v`. The law is linear in the
    /// force along the stroke, so the step is exact: `F = F* + (f0 - F*) exp(-|s|/x_p)` with
    /// `F* = force(v)`, s the stroke travelled.
    #[inline]
    pub fn presliding_step(&self, f0: f64, v: f64, dd: f64) -> (f64, f64) {
        let target = self.force(v);
        let lambda = dd.abs() / self.presliding_m;
        let decay = (-lambda).exp();
        // (1 - e^-lambda)/lambda, 1 at lambda = 0.
        let mean_decay = if lambda > 1e-12 {
            -(-lambda).exp_m1() / lambda
        } else {
            1.0
        };
        (
            target + (f0 - target) * decay,
            target + (f0 - target) * mean_decay,
        )
    }

    /// Slope `dF*/dv` of the sliding law [N s/m].
    #[inline]
    pub fn force_slope(&self, v: f64) -> f64 {
        let s = (-(v / self.v_s).powi(2)).exp();
        let g = self.f_c + (self.f_s - self.f_c) * s;
        let dg = (self.f_s - self.f_c) * s * (-2.0 * v / (self.v_s * self.v_s));
        if self.v_eps == 0.0 {
            // the exact sign: flat but at 0, where the presliding law takes over
            return -dg * self.sign_of(v);
        }
        let th = (v / self.v_eps).tanh();
        -dg * th - g * (1.0 - th * th) / self.v_eps
    }

    /// With presliding: the derivative of [`SealFriction::presliding_step`]'s mean force with
    /// respect to the stroke at the step's end (its start and `f0` held, the rate `dd/dt`):
    /// `F*'(v) (1 - M)/dt + (f0 - F*) M'(lambda) sign(dd)/x_p`, `M = (1 - e^-lambda)/lambda`.
    #[inline]
    pub fn presliding_tangent(&self, f0: f64, dd: f64, dt: f64) -> f64 {
        let v = dd / dt;
        let target = self.force(v);
        let lambda = dd.abs() / self.presliding_m;
        // M and M' = (e^-l (1 + l) - 1)/l^2, by their series near 0 (-1/2 + l/3 at l = 0).
        let (m, dm) = if lambda > 1e-4 {
            let e = (-lambda).exp();
            (
                -(-lambda).exp_m1() / lambda,
                (e * (1.0 + lambda) - 1.0) / (lambda * lambda),
            )
        } else {
            (1.0 - 0.5 * lambda, -0.5 + lambda / 3.0)
        };
        self.force_slope(v) * (1.0 - m) / dt + (f0 - target) * dm * dd.signum() / self.presliding_m
    }

    /// Whether the friction has presliding (a state).
    #[inline]
    pub fn has_presliding(&self) -> bool {
        self.presliding_m > 0.0
    }
}

/// Free play (backlash) of total width `gap` in the attachments: the piston stroke `d_h` follows
/// the attachment stroke `d` only when the gap is closed, `d_h = clamp(d_h, d - g/2, d + g/2)`
/// (play operator); while it is open no force is transmitted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FreePlay {
    /// Total gap g [m].
    pub gap: f64,
}

impl FreePlay {
    /// New piston stroke and whether the gap is closed (the attachment pushes the piston).
    #[inline]
    pub fn follow(&self, d_h: f64, d: f64) -> (f64, bool) {
        let h = 0.5 * self.gap;
        if d_h < d - h {
            (d - h, true)
        } else if d_h > d + h {
            (d + h, true)
        } else {
            (d_h, false)
        }
    }
}

/// Free air in the oil: volume fraction `a0` at the reference pressure `p_ref` (the background
/// pressure p_s), compressed isothermally (`V_g p = const`) while the liquid follows Eq. (3).
/// Mixture: `1/B_eff = (1 - x)/B_l + x/p`, `x = V_g/(V_l + V_g)`, with
/// `V_l = (1 - a0) c_l(p_ref)/c_l(p)`, `c_l(p) = 1 + alpha p + beta p^2` (the integral of Eq. 3)
/// and `V_g = a0 p_ref / p`. Below `p_min` the gas law is frozen at `p_min` (no vacuum).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EntrainedAir {
    /// Air volume fraction at p_ref [-].
    pub fraction: f64,
    /// Reference pressure [Pa] (> 0).
    pub p_ref: f64,
}

/// Lowest pressure used in the gas law [Pa].
pub const AIR_P_MIN_PA: f64 = 1.0e4;

impl EntrainedAir {
    /// Effective bulk modulus and its derivative in p.
    #[inline]
    pub fn bulk(&self, fluid: &Fluid, p: f64) -> (f64, f64) {
        let (bl, dbl) = fluid.bulk(p);
        let (pg, dpg) = if p > AIR_P_MIN_PA {
            (p, 1.0)
        } else {
            (AIR_P_MIN_PA, 0.0)
        };
        let cl = |p: f64| 1.0 + fluid.alpha * p + fluid.beta * p * p;
        let vl = (1.0 - self.fraction) * cl(self.p_ref) / cl(p);
        let dvl = -vl * (fluid.alpha + 2.0 * fluid.beta * p) / cl(p);
        let vg = self.fraction * self.p_ref / pg;
        let dvg = -vg / pg * dpg;
        let vt = vl + vg;
        let x = vg / vt;
        let dx = (dvg * vt - vg * (dvl + dvg)) / (vt * vt);
        // c = 1/B_eff
        let c = (1.0 - x) / bl + x / pg;
        let dc = -dx / bl - (1.0 - x) * dbl / (bl * bl) + dx / pg - x * dpg / (pg * pg);
        (1.0 / c, -dc / (c * c))
    }

    /// Mixture volume per unit initial volume at pressure p (the sealed-chamber integral of
    /// `dV/V = -dp/B_eff`), for tests and design.
    pub fn sealed_volume_ratio(&self, fluid: &Fluid, p: f64) -> f64 {
        let cl = |p: f64| 1.0 + fluid.alpha * p + fluid.beta * p * p;
        (1.0 - self.fraction) * cl(self.p_ref) / cl(p)
            + self.fraction * self.p_ref / p.max(AIR_P_MIN_PA)
    }
}

/// A laminar bypass, `Q = k dp` (the bleed of a chamber to the accumulator).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leakage {
    /// Leakage conductance k [m^3/(s Pa)].
    pub conductance: f64,
}

/// Leakage through the annular clearance h between piston and bore, from chamber 0 to chamber 1:
/// plane Poiseuille flow under the pressure difference plus the Couette flow of the piston
/// wall dragging the oil toward the chamber it shrinks (Merritt, Hydraulic Control Systems,
/// 1967, Sec. 2.4; the annulus as parallel plates of width pi D):
/// `Q = k (p0 - p1) + (pi D h / 2) w`, `k = pi D h^3 / (12 mu L)`, w the piston velocity
/// (positive growing chamber 0). The clearance follows from k and the product of the oil's
/// viscosity mu and the seal land's length L, `h = (12 mu L k / (pi D))^(1/3)`; mu L = 0 is a
/// pure Poiseuille bypass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AnnularLeakage {
    /// Poiseuille conductance k [m^3/(s Pa)].
    pub conductance: f64,
    /// Viscosity times seal land length, mu L [Pa s m] (0: no drag flow).
    pub viscosity_length: f64,
}

impl AnnularLeakage {
    /// Laminar leakage without drag (`Q = k (p0 - p1)`).
    pub fn laminar(conductance: f64) -> Self {
        Self {
            conductance,
            viscosity_length: 0.0,
        }
    }

    /// Radial clearance h [m] of a bore of area `bore_area` (D = 2 sqrt(A / pi)).
    pub fn clearance(&self, bore_area: f64) -> f64 {
        self.bore_and_clearance(bore_area).1
    }

    /// Couette flow per unit piston velocity, `pi D h / 2` [m^2].
    pub fn drag_area(&self, bore_area: f64) -> f64 {
        let (d, h) = self.bore_and_clearance(bore_area);
        0.5 * std::f64::consts::PI * d * h
    }

    fn bore_and_clearance(&self, bore_area: f64) -> (f64, f64) {
        let d = 2.0 * (bore_area / std::f64::consts::PI).sqrt();
        let h =
            (12.0 * self.viscosity_length * self.conductance / (std::f64::consts::PI * d)).cbrt();
        (d, h)
    }
}

/// Hydraulic extensions held in the circuit parameters (defaults: none).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HydraulicExtensions {
    pub air: Option<EntrainedAir>,
    /// Air in one chamber only (e.g. trapped on the rod side): chamber k uses
    /// `air_by_chamber[k]` where given, else `air`.
    pub air_by_chamber: [Option<EntrainedAir>; 2],
    pub leakage: Option<AnnularLeakage>,
    /// Bleed of each chamber to the accumulator at p_s, `Q_k = k (p_k - p_s)` out of chamber k
    /// (the accumulator's link that the paper's conclusions say is not modelled).
    pub bleed: Option<Leakage>,
    /// Viscosity and bore length of the inter-chamber orifice: with them the orifice follows the
    /// laminar-to-turbulent law ([`super::elements::ViscousOrificeLaw`]); without, Eq. (4) with
    /// the `dp_laminar` regularisation.
    pub orifice_viscosity: Option<super::elements::OrificeViscosity>,
}

impl HydraulicExtensions {
    /// The air of chamber k, if any.
    #[inline]
    pub fn air_of(&self, k: usize) -> Option<&EntrainedAir> {
        self.air_by_chamber[k].as_ref().or(self.air.as_ref())
    }
}

/// A circuit device with seal friction and/or free play in the attachments.
#[derive(Debug, Clone)]
pub struct ExtendedDamper {
    inner: CircuitDevice,
    friction: Option<SealFriction>,
    play: Option<FreePlay>,
    /// Committed piston stroke and contact flag.
    d_h: f64,
    contact: bool,
    v_h: f64,
    /// Friction force at the committed state (presliding friction only) [N].
    f_fric: f64,
    /// No step taken since the reset: the piston starts centred in the gap at the first stroke.
    fresh: bool,
    trial: Option<(f64, bool, f64, f64)>,
}

impl ExtendedDamper {
    pub fn new(
        inner: CircuitDevice,
        friction: Option<SealFriction>,
        play: Option<FreePlay>,
    ) -> Self {
        Self {
            inner,
            friction,
            play,
            d_h: 0.0,
            contact: play.is_none(),
            v_h: 0.0,
            f_fric: 0.0,
            fresh: true,
            trial: None,
        }
    }

    pub fn inner(&self) -> &CircuitDevice {
        &self.inner
    }

    /// Piston stroke (behind the free play) at the committed state [m].
    pub fn piston_stroke(&self) -> f64 {
        self.d_h
    }

    fn out_force(&self, hydraulic: f64, contact: bool, v_h: f64) -> f64 {
        if !contact {
            return 0.0;
        }
        hydraulic
            + self.friction.map_or(0.0, |f| {
                if f.has_presliding() {
                    self.f_fric
                } else {
                    f.force(v_h)
                }
            })
    }
}

impl Device for ExtendedDamper {
    fn step_along(&mut self, t_i: f64, path: &StrokePath) -> StepResult {
        let (dt, d_i, d_f) = (path.dt, path.d_i, path.d_f);
        if self.fresh {
            self.d_h = d_i;
        }
        let (dh_i, dh_f, contact) = match &self.play {
            Some(p) => {
                let (dh, c) = p.follow(self.d_h, d_f);
                (self.d_h, dh, c)
            }
            None => (d_i, d_f, true),
        };
        // The piston moves along the end's path only while the gap stays closed on one side
        // over the whole step (its offset from the end unchanged); else along its chord.
        let follows = contact && ((dh_f - d_f) - (dh_i - d_i)).abs() <= 1e-12;
        let inner_path = if follows {
            path.with_ends(dh_i, dh_f)
        } else {
            StrokePath::linear(dt, dh_i, dh_f)
        };
        let v_h = inner_path.chord_rate();
        // the piston's rate at the step's end (the chord's on a straight step)
        let v_end = inner_path.end_rate();
        let sf = self.inner.trial_step_path(t_i, &inner_path)?;
        // The sliding law's tangent is left out (its slope F_c/v_eps at reversal would swamp
        // the damper's); presliding adds its bounded one, the seal's presliding stiffness.
        let (fr_end, fr_mean, fr_slope) = match self.friction {
            Some(f) if f.has_presliding() => {
                let dd = dh_f - dh_i;
                let (end, mean) = f.presliding_step(self.f_fric, v_h, dd);
                (end, mean, f.presliding_tangent(self.f_fric, dd, dt))
            }
            Some(f) => (f.force(v_end), inner_path.mean_of_rate(|v| f.force(v)), 0.0),
            None => (0.0, 0.0, 0.0),
        };
        let out = StepForce {
            force_mean: if contact {
                sf.force_mean + fr_mean
            } else {
                0.0
            },
            dforce_dstroke: if contact {
                sf.dforce_dstroke + fr_slope
            } else {
                0.0
            },
            force_end: if contact { sf.force_end + fr_end } else { 0.0 },
        };
        self.trial = Some((dh_f, contact, v_end, fr_end));
        Ok(out)
    }

    fn commit(&mut self) {
        if let Some((d_h, c, v, f)) = self.trial.take() {
            self.inner.commit();
            self.fresh = false;
            self.d_h = d_h;
            self.contact = c;
            self.v_h = v;
            self.f_fric = f;
        }
    }

    fn channel_names(&self) -> &'static [&'static str] {
        self.inner.channel_names()
    }

    fn channels(&self, out: &mut [f64]) {
        self.inner.channels(out)
    }

    fn committed_force(&self) -> f64 {
        self.out_force(self.inner.committed_force(), self.contact, self.v_h)
    }

    fn force_scale(&self) -> f64 {
        self.inner.force_scale().max(self.committed_force().abs())
    }

    fn set_substep_envelope(&mut self, on: bool) {
        self.inner.set_substep_envelope(on);
    }

    fn clone_device(&self) -> Box<dyn Device> {
        Box::new(self.clone())
    }

    fn reset(&mut self) {
        self.inner.reset();
        self.d_h = 0.0;
        self.contact = self.play.is_none();
        self.v_h = 0.0;
        self.f_fric = 0.0;
        self.fresh = true;
        self.trial = None;
    }

    /// `[d_h, contact, v_h, fresh, circuit...]`, then the friction force with presliding.
    fn state_values(&self) -> Vec<f64> {
        let mut v = vec![
            self.d_h,
            f64::from(u8::from(self.contact)),
            self.v_h,
            f64::from(u8::from(self.fresh)),
        ];
        v.extend(self.inner.state_values());
        if self.friction.is_some_and(|f| f.has_presliding()) {
            v.push(self.f_fric);
        }
        v
    }

    fn set_state_values(&mut self, v: &[f64]) -> Result<(), HydraulicError> {
        let tail = usize::from(self.friction.is_some_and(|f| f.has_presliding()));
        if v.len() < 4 + tail {
            return super::check_state_len("extended damper", v, 4 + tail);
        }
        let (v, rest) = v.split_at(v.len() - tail);
        self.inner.set_state_values(&v[4..])?;
        super::check_state_len("extended damper", &v[..4], 4)?;
        if let Some(&f) = rest.first() {
            super::check_state_len("extended damper", rest, 1)?;
            self.f_fric = f;
        }
        self.d_h = v[0];
        self.contact = v[1] != 0.0;
        self.v_h = v[2];
        self.fresh = v[3] != 0.0;
        self.trial = None;
        Ok(())
    }
}

/// The [`Device`] methods of a device in series with an inner one through a hidden stroke
/// `d_h` (fields `inner`, `d_h`, `fresh`, `trial`): commit, channels, reset and state are the
/// same for every such link; only the trial step differs.
macro_rules! series_link_methods {
    ($what:literal) => {
        fn commit(&mut self) {
            if let Some(x) = self.trial.take() {
                self.inner.commit();
                self.d_h = x;
                self.fresh = false;
            }
        }

        series_link_state_methods!($what);

        fn force_scale(&self) -> f64 {
            self.inner.force_scale()
        }

        fn set_substep_envelope(&mut self, on: bool) {
            self.inner.set_substep_envelope(on);
        }
    };
}

/// Elastic mounts (rod-end bearings, bushings, airframe attachment) in series with a damper:
/// a spring of stiffness `k` between the attachment stroke `d` and the device stroke `d_h`.
/// The link force is the device force `F(d_h)` and also the spring's, `F = k (d_h - d)`
/// (a damper pushing its ends apart compresses the spring), so every step solves
/// `g(d_h) = d_h - d_f - F(d_h)/k = 0` for the end-of-step device stroke by secant iterations
/// started with the device's own tangent (Eq. 16 estimate), to a force mismatch of 0.1 N (or,
/// where valve switching stalls the secant, its best iterate within 1 N). A Maxwell element when the device is
/// a linear dashpot: force lag `atan(c omega / k)`.
#[derive(Debug, Clone)]
pub struct SeriesMount {
    inner: Box<dyn Device>,
    k: f64,
    d_h: f64,
    fresh: bool,
    trial: Option<f64>,
}

/// Iterations of the series-mount solve.
const MOUNT_MAX_ITER: usize = 40;

impl SeriesMount {
    pub fn new(inner: Box<dyn Device>, k_n_per_m: f64) -> Self {
        Self {
            inner,
            k: k_n_per_m,
            d_h: 0.0,
            fresh: true,
            trial: None,
        }
    }

    /// Device stroke behind the mount at the committed state [m].
    pub fn device_stroke(&self) -> f64 {
        self.d_h
    }
}

impl Device for SeriesMount {
    fn step_along(&mut self, t_i: f64, path: &StrokePath) -> StepResult {
        let (dt, d_i, d_f) = (path.dt, path.d_i, path.d_f);
        if self.fresh {
            self.d_h = d_i + self.inner.committed_force() / self.k;
        }
        let dh_i = self.d_h;
        // Converged when the spring and device forces agree to 0.1 N (the device force is only
        // piecewise smooth in the stroke: valve and seat switching limit the secant to ~0.05 N).
        let tol = 0.1 / self.k;
        // Start: the spring keeps its deflection.
        let mut x0 = d_f + (dh_i - d_i);
        let mut s0 = self.inner.trial_step_path(t_i, &path.with_ends(dh_i, x0))?;
        let mut g0 = x0 - d_f - s0.force_end / self.k;
        if g0.abs() <= tol {
            self.trial = Some(x0);
            return Ok(s0);
        }
        let slope = 1.0 - s0.dforce_dstroke / self.k;
        let mut x1 = x0 - g0 / slope.max(1.0);
        let mut best = (x0, g0.abs());
        let accept = |me: &mut Self, x: f64, sf: StepForce| {
            me.trial = Some(x);
            // Link force: dF/dd_f through the spring, F = k (d_h - d).
            let kd = -sf.dforce_dstroke;
            StepForce {
                dforce_dstroke: -(kd * me.k) / (kd + me.k),
                ..sf
            }
        };
        for _ in 0..MOUNT_MAX_ITER {
            if !x1.is_finite() {
                break;
            }
            let s1 = self.inner.trial_step_path(t_i, &path.with_ends(dh_i, x1))?;
            let g1 = x1 - d_f - s1.force_end / self.k;
            if g1.abs() <= tol {
                return Ok(accept(self, x1, s1));
            }
            if g1.abs() < best.1 {
                best = (x1, g1.abs());
            }
            if g1 == g0 {
                break;
            }
            let x2 = x1 - g1 * (x1 - x0) / (g1 - g0);
            (x0, g0, x1) = (x1, g1, x2);
            s0 = s1;
        }
        let _ = s0;
        // The device force is only piecewise smooth (valve and seat switching), where a secant
        // can stall. Fall back to a bracketed Illinois (regula falsi) solve: the residual
        // g(x) = x - d_f - F(x)/k is continuous and, for a passive device (dF/dx <= 0),
        // increasing with slope >= 1, so a bracket is found by stepping against g.
        let g = |me: &mut Self, x: f64| -> Result<(f64, StepForce), HydraulicError> {
            let sf = me.inner.trial_step_path(t_i, &path.with_ends(dh_i, x))?;
            Ok((x - d_f - sf.force_end / me.k, sf))
        };
        let (xb, _) = best;
        let (gb, sb) = g(self, xb)?;
        if gb.abs() <= tol {
            return Ok(accept(self, xb, sb));
        }
        let (mut a, mut ga, mut b, mut gbr) = (xb, gb, xb, gb);
        let mut step = 2.0 * gb.abs().max(tol);
        for _ in 0..60 {
            let x = if gb > 0.0 { b - step } else { a + step };
            let (gx, _) = g(self, x)?;
            if gb > 0.0 {
                (a, ga) = (x, gx);
                if gx <= 0.0 {
                    break;
                }
            } else {
                (b, gbr) = (x, gx);
                if gx >= 0.0 {
                    break;
                }
            }
            step *= 2.0;
        }
        if ga <= 0.0 && gbr >= 0.0 {
            let mut side = 0i8;
            for _ in 0..MOUNT_MAX_ITER {
                let x = if gbr - ga > 0.0 {
                    (a * gbr - b * ga) / (gbr - ga)
                } else {
                    0.5 * (a + b)
                };
                let (gx, sx) = g(self, x)?;
                if gx.abs() <= tol || (b - a).abs() <= 4.0 * f64::EPSILON * x.abs().max(1e-3) {
                    return Ok(accept(self, x, sx));
                }
                if gx < 0.0 {
                    (a, ga) = (x, gx);
                    if side == -1 {
                        gbr *= 0.5;
                    }
                    side = -1;
                } else {
                    (b, gbr) = (x, gx);
                    if side == 1 {
                        ga *= 0.5;
                    }
                    side = 1;
                }
                if gx.abs() < best.1 {
                    best = (x, gx.abs());
                }
            }
        }
        // Last resort: a stall within 1 N of force balance is accepted at its best iterate.
        if best.1 * self.k <= 1.0 {
            let sf = self
                .inner
                .trial_step_path(t_i, &path.with_ends(dh_i, best.0))?;
            return Ok(accept(self, best.0, sf));
        }
        Err(HydraulicError::BadStep {
            t: t_i + dt,
            reason: format!(
                "series mount solve did not converge in {MOUNT_MAX_ITER} iterations (force mismatch {:.3e} N)",
                best.1 * self.k
            ),
        })
    }

    series_link_methods!("series mount");
}

/// Free play as in hardware: a gap of total width `gap` in series with a contact stiffness `k`
/// (rod-end and bearing stiffness behind the gap). The link force is a dead-band spring of the
/// link deflection `e = d_h - d`: `F = k (e - g/2)` for `e > g/2`, `k (e + g/2)` for `e < -g/2`,
/// zero inside the gap. Quasi-static: the moving mass between gap and contact is neglected, so
/// the device force equals the link force at every instant (inside the gap the piston drifts so
/// that the damper's own force is zero). This is the limit the damper itself enforces: with a
/// rod-end mass m of a few kg and the damper's ~1e5 N s/m, the mass relaxes in m/c ~ 1e-5 s, far
/// below a stroke period, and the contact mode is at least critically damped (c >= 2 sqrt(k m))
/// up to k ~ 1e9 N/m; so contact damping adds nothing this model would resolve.
/// Each step solves `H(x) = k dz(x - d_f) - F(x) = 0` for the device stroke x; H increases in x
/// for a passive device (dF/dx < 0), so Newton steps safeguarded by a bracket converge to a force
/// mismatch of 0.1 N. Limits: `gap = 0` is [`SeriesMount`]; `k -> infinity` is the play operator
/// of [`FreePlay`] on a memoryless device (a dashpot); on the hydraulic damper the rigid
/// [`FreePlay`] instead holds the piston still while the gap is open.
#[derive(Debug, Clone)]
pub struct CompliantFreePlay {
    inner: Box<dyn Device>,
    link: Link,
    d_h: f64,
    fresh: bool,
    trial: Option<f64>,
}

/// Iterations of the compliant free-play solve.
const PLAY_MAX_ITER: usize = 80;

impl CompliantFreePlay {
    pub fn new(inner: Box<dyn Device>, gap_m: f64, k_n_per_m: f64) -> Self {
        Self {
            inner,
            link: Link {
                half_gap: 0.5 * gap_m,
                k: k_n_per_m,
            },
            d_h: 0.0,
            fresh: true,
            trial: None,
        }
    }

    /// Device stroke behind the gap and contact at the committed state [m].
    pub fn device_stroke(&self) -> f64 {
        self.d_h
    }

    /// Link force of a link deflection `e = d_h - d` [N] and whether the gap is closed.
    #[inline]
    pub fn link_force(&self, e: f64) -> (f64, bool) {
        self.link.force(e)
    }
}

impl Device for CompliantFreePlay {
    fn step_along(&mut self, t_i: f64, path: &StrokePath) -> StepResult {
        let (dt, d_i, d_f) = (path.dt, path.d_i, path.d_f);
        if self.fresh {
            self.d_h = d_i + self.link.deflection_of(self.inner.committed_force());
        }
        let dh_i = self.d_h;
        let tol = 0.1;
        // The piston takes the end's path (less the link's deflection, linear over the step)
        // where the gap is closed at the step's start; inside the gap its chord.
        let shape = if path.is_linear() || self.link.force(dh_i - d_i).1 {
            *path
        } else {
            StrokePath::linear(dt, d_i, d_f)
        };
        let eval = |me: &mut Self, x: f64| -> Result<(f64, bool, StepForce), HydraulicError> {
            let sf = me.inner.trial_step_path(t_i, &shape.with_ends(dh_i, x))?;
            let (fl, contact) = me.link_force(x - d_f);
            Ok((fl - sf.force_end, contact, sf))
        };
        // Bracket: H(lo) < 0 < H(hi); best iterate kept for a stall at a valve switch.
        let mut lo: Option<(f64, f64)> = None;
        let mut hi: Option<(f64, f64)> = None;
        let mut best = (f64::NAN, f64::INFINITY);
        // Start: the link keeps its deflection.
        let mut x = d_f + (dh_i - d_i);
        let mut prev = f64::INFINITY;
        let mut step = 1e-6_f64.max(tol / self.link.k);
        let mut collapsed = false;
        for _ in 0..PLAY_MAX_ITER {
            let (h, contact, sf) = eval(self, x)?;
            if h.abs() <= tol {
                self.trial = Some(x);
                let kd = -sf.dforce_dstroke;
                let dl = if contact {
                    -(kd * self.link.k) / (kd + self.link.k)
                } else {
                    0.0
                };
                return Ok(StepForce {
                    dforce_dstroke: dl,
                    ..sf
                });
            }
            if h.abs() < best.1 {
                best = (x, h.abs());
            }
            if h < 0.0 {
                lo = Some((x, h));
            } else {
                hi = Some((x, h));
            }
            let slope = if contact { self.link.k } else { 0.0 } - sf.dforce_dstroke;
            let newton = x - h / slope;
            x = match (lo, hi) {
                (Some((a, ga)), Some((b, gb))) => {
                    let inside = newton.is_finite() && newton > a.min(b) && newton < a.max(b);
                    if inside && h.abs() < 0.5 * prev {
                        newton
                    } else {
                        // Regula falsi with a bisection guard.
                        let rf = (a * gb - b * ga) / (gb - ga);
                        let mid = 0.5 * (a + b);
                        if rf.is_finite() && (rf - mid).abs() < 0.25 * (b - a).abs() {
                            rf
                        } else {
                            mid
                        }
                    }
                }
                _ => {
                    if newton.is_finite() && slope > 0.0 && h.abs() < 0.5 * prev {
                        newton
                    } else {
                        step *= 2.0;
                        if h > 0.0 {
                            x - step
                        } else {
                            x + step
                        }
                    }
                }
            };
            if let (Some((a, _)), Some((b, _))) = (lo, hi) {
                if (b - a).abs() <= 4.0 * f64::EPSILON * a.abs().max(1e-3) {
                    collapsed = true;
                    break;
                }
            }
            prev = h.abs();
        }
        // A bracket closed to round-off holds no root: the device force jumps there (a valve
        // switching inside the step) and the jump is the force balance's best (as the series
        // mount's bracket accepts). Otherwise a stall within 1 N of force balance is accepted.
        if collapsed || best.1 <= 1.0 {
            let (_, contact, sf) = eval(self, best.0)?;
            self.trial = Some(best.0);
            let kd = -sf.dforce_dstroke;
            let dl = if contact {
                -(kd * self.link.k) / (kd + self.link.k)
            } else {
                0.0
            };
            return Ok(StepForce {
                dforce_dstroke: dl,
                ..sf
            });
        }
        Err(HydraulicError::BadStep {
            t: t_i + dt,
            reason: format!(
                "compliant free-play solve did not converge in {PLAY_MAX_ITER} iterations (force mismatch {:.3e} N)",
                best.1
            ),
        })
    }

    series_link_methods!("compliant free play");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn air_bulk_derivative_matches_finite_difference() {
        let fluid = Fluid {
            rho: 850.0,
            alpha: 6.667e-10,
            beta: 2.0e-18,
            p_cav: 0.0,
        };
        let air = EntrainedAir {
            fraction: 0.02,
            p_ref: 5.0e5,
        };
        for p in [2.0e4, 3.0e5, 5.0e5, 2.0e6, 1.0e7] {
            let (_, db) = air.bulk(&fluid, p);
            let h = 1e-5 * p;
            let fd = (air.bulk(&fluid, p + h).0 - air.bulk(&fluid, p - h).0) / (2.0 * h);
            assert!(
                (db - fd).abs() < 1e-6 * fd.abs().max(1.0),
                "p {p}: {db} vs {fd}"
            );
        }
        // No air: the liquid's Eq. (3).
        let none = EntrainedAir {
            fraction: 0.0,
            p_ref: 5.0e5,
        };
        let (b, _) = none.bulk(&fluid, 1.0e6);
        assert!((b - fluid.bulk(1.0e6).0).abs() < 1e-9 * b);
    }

    #[test]
    fn friction_is_coulomb_at_steady_velocity() {
        let f = SealFriction::coulomb(400.0);
        assert_eq!(f.force(0.05), -400.0);
        assert_eq!(f.force(-0.05), 400.0);
        assert_eq!(f.force(0.0), 0.0);
        let s = SealFriction { f_s: 600.0, ..f };
        // At v = v_s the Stribeck term has decayed by 1/e.
        let expect = -(400.0 + 200.0 * (-1.0f64).exp());
        assert!((s.force(0.01) - expect).abs() < 1e-9);
    }

    #[test]
    fn play_operator() {
        let p = FreePlay { gap: 2e-3 };
        assert_eq!(p.follow(0.0, 0.5e-3), (0.0, false));
        assert_eq!(p.follow(0.0, 3e-3), (2e-3, true));
        assert_eq!(p.follow(2e-3, 2.5e-3), (2e-3, false));
        assert_eq!(p.follow(2e-3, 0.5e-3), (1.5e-3, true));
    }
}
