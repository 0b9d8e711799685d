//! One rigid blade on a lag hinge in the rotating frame, with a real damper [`Device`]. Two
//! parameter sets: [`SdofParams::from_record`], a test double of the run pipeline driven by the
//! chord force alone (`--model sdof`, not a rotor model), and [`SdofParams::from_rotor`], the
//! rigid-blade reduction of a rotor deck with the airloads projected by the control pitch
//! (`--model rigid`, docs/rotor_model.md).
//!
//! Equation of motion (lag angle `zeta`, positive aft, i.e. against the rotation, docs/formats.md):
//!
//! `I zeta'' + c zeta' + (e S Omega^2 + k) zeta = M(psi) + a F`
//!
//! with `I`, `S` the second and first mass moments of the blade about the hinge, `e` the hinge
//! offset (centrifugal lag stiffness `e S Omega^2`), `k` and `c` the lag spring and damping
//! (c = 0 in the test double), `a` the damper arm
//! (stroke `d = a zeta`, so aft lag lengthens the damper) and `F` the damper force (docs/formats.md:
//! positive pushes the ends apart, so its generalized force on `zeta` is `a F`). `M(psi)` is the
//! aerodynamic lag moment about the hinge, a sum of harmonics (0..2/rev in the test double,
//! 0..16/rev in the reduction).
//!
//! Time integration: trapezoidal rule (average acceleration) with the forces averaged over the
//! step, which is what the device returns (`F_m` of Eq. 13):
//! `I (w1 - w0)/h = M(t + h/2) - c (w0 + w1)/2 - k_t (z0 + z1)/2 + a F_m`,
//! `z1 = z0 + h (w0 + w1)/2`,
//! solved by Newton on `z1` with the device's `dF_m/dd_f` (Eq. 16 estimate for the physical
//! damper) in the tangent.
use crate::analysis::harmonics::{harmonics, Harmonic};
use crate::flight::FlightRecord;
use crate::hydraulics::circuit::CircuitParams;
use crate::hydraulics::{CircuitDevice, DamperDeck, DamperModel, Device, IntegratorOptions};
use crate::rotor::{ForcedResponse, Timing, BASE_CHANNELS};
use anyhow::bail;
use std::time::Instant;

/// Parameters of the lag-hinge blade.
#[derive(Debug, Clone, PartialEq)]
pub struct SdofParams {
    /// Rotor speed Omega [rad/s].
    pub omega_rad_s: f64,
    /// Lag hinge offset e [m].
    pub hinge_offset_m: f64,
    /// Blade radius R [m] (tip lag motion = (R - e) zeta).
    pub radius_m: f64,
    /// Second mass moment about the hinge I [kg m^2].
    pub inertia_kg_m2: f64,
    /// First mass moment about the hinge S [kg m].
    pub first_moment_kg_m: f64,
    /// Lag spring k [N m/rad].
    pub lag_spring_n_m_per_rad: f64,
    /// Damper arm a [m]: stroke = a zeta.
    pub damper_arm_m: f64,
    /// Lag moment harmonics about the hinge [N m] (n = 0, 1, 2, ...; psi in the record's sense).
    pub moment: Vec<Harmonic>,
    /// Viscous lag damping of the hinge (elastomer) [N m s/rad].
    pub lag_damping_n_m_s_per_rad: f64,
}

impl SdofParams {
    /// UH-60A-like values: e = 0.381 m, a = 0.175 m, k = 20400 N m/rad (the shipped record's
    /// metadata), mass moments integrated from rotors/data/blade_sections_yeo.csv (stations
    /// r = 0.8178 m + s to the tip; the root hardware inboard of the first station is left out):
    /// S = 386.8 kg m, I = 2087 kg m^2 about the hinge. Lag frequency
    /// sqrt((e S Omega^2 + k)/I) = 0.29/rev at Omega = 27 rad/s.
    pub fn uh60a_like(omega_rad_s: f64, moment: Vec<Harmonic>) -> Self {
        SdofParams {
            omega_rad_s,
            hinge_offset_m: 0.381,
            radius_m: 8.1786,
            inertia_kg_m2: 2087.0,
            first_moment_kg_m: 386.8,
            lag_spring_n_m_per_rad: 20400.0,
            damper_arm_m: 0.175,
            moment,
            lag_damping_n_m_s_per_rad: 0.0,
        }
    }

    /// The rigid-blade reduction of a rotor deck (`rotorsim run --model rigid`): the blade of
    /// the deck taken rigid on its lag hinge, no flap (so no Coriolis coupling), driven by the
    /// record's airloads projected into the hub plane with the rigid pitch of the controls and
    /// the built-in twist (the control-pitch frame of docs/rotor_model.md):
    ///
    /// `M(psi) = integral over the blade of (N sin(theta) + C cos(theta)) (r - e) dr`,
    /// `theta = th0 + th1c cos(psi) + th1s sin(psi) + twist(r)`,
    ///
    /// N, C from the replay (revolution average, radial taper to the root cut-out and the tip),
    /// harmonics 0..=16. The blade's `I`, `S`, lag spring and damping and damper arm are its
    /// [`crate::resonance::rigid_blade::RigidLagBlade`].
    pub fn from_rotor(
        spec: &crate::rotor::deck::RotorSpec,
        deck_path: &std::path::Path,
        record: &FlightRecord,
    ) -> anyhow::Result<Self> {
        use crate::flight::replay::{AirloadReplay, ReplayMode, ReplayOptions};
        // the record must be of this rotor, as the elastic model requires
        spec.check_record(record, deck_path)?;
        let blade = crate::resonance::rigid_blade::RigidLagBlade::of(spec, deck_path)?;
        let e = blade.hinge_offset_m;
        let radius = spec.rotor.radius_m;
        let replay = AirloadReplay::new(record, ReplayMode::Average, ReplayOptions::default())?;
        let controls = crate::rotor::expand::Controls::from_record(&record.meta.controls_deg);
        let twist = crate::structure::kin::TimeTable {
            points: spec.blade.twist_deg.iter().map(|p| (p[0], p[1])).collect(),
        };
        let psi: Vec<f64> = (0..256).map(|k| k as f64 * 360.0 / 256.0).collect();
        let nr = 800;
        let dr = (radius - e) / nr as f64;
        let mut moment = Vec::with_capacity(psi.len());
        for &p in &psi {
            let pr = p.to_radians();
            let th_c =
                (controls.th0_deg + controls.th1c_deg * pr.cos() + controls.th1s_deg * pr.sin())
                    .to_radians();
            let mut m = 0.0;
            for k in 0..=nr {
                let r = e + k as f64 * dr;
                let w = if k == 0 || k == nr { 0.5 * dr } else { dr };
                let l = replay.at_azimuth(p, r / record.meta.radius_m);
                let tw = if spec.blade.twist_deg.is_empty() {
                    0.0
                } else {
                    twist.eval(r).to_radians()
                };
                let (st, ct) = (th_c + tw).sin_cos();
                m += w * (l.normal_N_per_m * st + l.chord_N_per_m * ct) * (r - e);
            }
            moment.push(m);
        }
        Ok(SdofParams {
            omega_rad_s: spec.rotor.omega_rad_s,
            hinge_offset_m: e,
            radius_m: radius,
            inertia_kg_m2: blade.inertia_kg_m2,
            first_moment_kg_m: blade.first_moment_kg_m,
            lag_spring_n_m_per_rad: blade.lag_stiffness_nm_per_rad,
            damper_arm_m: blade.damper_arm_m,
            moment: harmonics(&psi, &moment, 16)?,
            lag_damping_n_m_s_per_rad: blade.lag_damping_nms_per_rad,
        })
    }

    /// As [`SdofParams::uh60a_like`], driven by harmonics 0..=2/rev of the record's lag moment
    /// about the hinge, `M(psi) = integral of D(r) (r - e) dr` (chord force D positive = drag,
    /// which pushes the blade aft), averaged over the record's revolutions.
    pub fn from_record(record: &FlightRecord) -> anyhow::Result<Self> {
        let p0 = Self::uh60a_like(record.meta.rotor_speed_rad_s, Vec::new());
        let e = p0.hinge_offset_m;
        let radius = record.meta.radius_m;
        let st: Vec<f64> = record
            .stations_r_over_r()
            .iter()
            .map(|x| x * radius)
            .collect();
        let (nr, na, ns) = (
            record.revolutions().len(),
            record.azimuths_deg().len(),
            st.len(),
        );
        if nr == 0 || na < 5 || ns < 2 {
            bail!("flight record has too few airload samples for the lag moment ({nr} revolutions, {na} azimuths, {ns} stations)");
        }
        let chord = record.chord_n_per_m();
        let mut m = vec![0.0; na];
        for ir in 0..nr {
            for (ia, mi) in m.iter_mut().enumerate() {
                let f = |is: usize| chord[record.index(ir, ia, is)] * (st[is] - e);
                for is in 0..ns - 1 {
                    *mi += 0.5 * (f(is) + f(is + 1)) * (st[is + 1] - st[is]) / nr as f64;
                }
            }
        }
        let h = harmonics(record.azimuths_deg(), &m, 2)?;
        Ok(SdofParams {
            radius_m: radius,
            moment: h,
            ..p0
        })
    }

    /// Lag moment at azimuth `psi` [rad].
    fn moment_at(&self, psi: f64) -> f64 {
        self.moment
            .iter()
            .map(|h| {
                let a = h.n as f64 * psi;
                h.cos * a.cos() + h.sin * a.sin()
            })
            .sum()
    }

    /// Total lag stiffness about the hinge [N m/rad].
    fn stiffness(&self) -> f64 {
        self.hinge_offset_m * self.first_moment_kg_m * self.omega_rad_s.powi(2)
            + self.lag_spring_n_m_per_rad
    }
}

/// `summary.json` `rotor_model` of the rigid-blade reduction.
pub const RIGID_LABEL: &str =
    "rigid-blade reduction of the rotor deck (lag hinge, control-pitch airloads)";

/// The rigid-blade reduction of `rotor` (`rotorsim run --model rigid`) with damper model `model`
/// of `damper`, labelled "<model> (rigid)".
pub fn rigid_reduction(
    rotor: &crate::rotor::RotorDeck,
    damper: &DamperDeck,
    model: DamperModel,
    record: &FlightRecord,
    opts: &crate::rotor::RunOptions,
) -> anyhow::Result<LagHingeSdof> {
    let p = SdofParams::from_rotor(&rotor.spec, &rotor.path, record)
        .map_err(|e| anyhow::anyhow!("rigid-blade reduction of {}: {e:#}", rotor.path.display()))?;
    let mut sim = LagHingeSdof::new(p, damper, model, opts.hydraulics, opts.steps_per_rev)?;
    sim.label = format!("{} (rigid)", model.name());
    Ok(sim)
}

/// The device, kept concrete for the physical damper without extensions so that the poppet
/// velocities (states of the circuit) can be reported.
#[derive(Debug)]
enum Holder {
    Circuit(CircuitDevice),
    Other(Box<dyn Device>),
}

impl Holder {
    fn dev(&mut self) -> &mut dyn Device {
        match self {
            Holder::Circuit(c) => c,
            Holder::Other(d) => d.as_mut(),
        }
    }
    fn dev_ref(&self) -> &dyn Device {
        match self {
            Holder::Circuit(c) => c,
            Holder::Other(d) => d.as_ref(),
        }
    }
}

/// The lag-hinge forced response (test double; label "<model> (sdof)").
#[derive(Debug)]
pub struct LagHingeSdof {
    p: SdofParams,
    label: String,
    dev: Holder,
    limits: Option<(f64, f64)>,
    dt: f64,
    period: f64,
    step: usize,
    zeta: f64,
    zeta_dot: f64,
    timing: Timing,
}

/// Relief-valve force limits of a circuit [N] (min, max): the damper force `p0 A0 - p1 A1` at
/// which valve k cracks (`p_k A_front - p_other A_back = F_p`, Eq. 5), with the other chamber
/// at the background pressure p_s (the force does not depend on it when
/// `A_back/A_front = A_other/A_k`, as for the symmetric UH-60A-like damper).
pub fn relief_limits(c: &CircuitParams) -> Option<(f64, f64)> {
    let (a0, a1) = (c.chambers[0].area, c.chambers[1].area);
    let (v0, v1) = (c.relief[0]?, c.relief[1]?);
    // Valve 0: p0 = (F_p + p1 A_back)/A_front, p1 = p_s.
    let hi = (v0.f_p + c.p_s * v0.a_back) / v0.a_front * a0 - c.p_s * a1;
    let lo = c.p_s * a0 - (v1.f_p + c.p_s * v1.a_back) / v1.a_front * a1;
    Some((lo, hi))
}

impl LagHingeSdof {
    pub fn new(
        p: SdofParams,
        deck: &DamperDeck,
        model: DamperModel,
        opts: IntegratorOptions,
        steps_per_rev: usize,
    ) -> anyhow::Result<Self> {
        if steps_per_rev < 8 {
            bail!("steps per revolution must be >= 8 (got {steps_per_rev})");
        }
        if !(p.omega_rad_s > 0.0 && p.inertia_kg_m2 > 0.0) {
            bail!(
                "lag-hinge model needs a positive rotor speed and inertia (Omega = {} rad/s)",
                p.omega_rad_s
            );
        }
        let plain = deck.extensions == Default::default();
        let dev = match model {
            DamperModel::Physical if plain => Holder::Circuit(deck.physical_device(opts)?),
            _ => Holder::Other(deck.build(model, opts)?),
        };
        let limits = match model {
            DamperModel::Physical => deck.physical.as_ref().and_then(relief_limits),
            _ => None,
        };
        let period = 2.0 * std::f64::consts::PI / p.omega_rad_s;
        // Start at the static deflection under the mean moment (shorter transient).
        let zeta = p.moment.first().map_or(0.0, |h| h.cos) / p.stiffness();
        Ok(LagHingeSdof {
            label: format!("{} (sdof)", model.name()),
            dev,
            limits,
            dt: period / steps_per_rev as f64,
            period,
            step: 0,
            zeta,
            zeta_dot: 0.0,
            timing: Timing::default(),
            p,
        })
    }

    /// Lag angle [rad] and rate [rad/s].
    pub fn state(&self) -> (f64, f64) {
        (self.zeta, self.zeta_dot)
    }
}

impl ForcedResponse for LagHingeSdof {
    fn label(&self) -> &str {
        &self.label
    }
    fn period_s(&self) -> f64 {
        self.period
    }
    fn time_step_s(&self) -> f64 {
        self.dt
    }
    fn time_s(&self) -> f64 {
        self.step as f64 * self.dt
    }

    fn step(&mut self) -> anyhow::Result<()> {
        let t0 = Instant::now();
        let (h, t) = (self.dt, self.time_s());
        let (i, kt, a, c) = (
            self.p.inertia_kg_m2,
            self.p.stiffness(),
            self.p.damper_arm_m,
            self.p.lag_damping_n_m_s_per_rad,
        );
        let m_mid = self.p.moment_at(self.p.omega_rad_s * (t + 0.5 * h));
        let (z0, w0) = (self.zeta, self.zeta_dot);
        // Predictor: constant rate.
        let mut z1 = z0 + h * w0;
        let mut hyd = 0.0;
        let mut converged = None;
        let scale = m_mid.abs().max(kt * z0.abs()).max(1.0);
        // A relief valve opening inside the step makes the residual kinked in z1, where plain
        // Newton can cycle: after PLAIN iterations each update is kept inside the bracket of
        // the residual's sign change seen so far (bisection when it would leave it).
        const PLAIN: usize = 10;
        const MAX_IT: usize = 80;
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for it in 0..MAX_IT {
            let th = Instant::now();
            let sf = self.dev.dev().trial_step(t, h, a * z0, a * z1)?;
            hyd += th.elapsed().as_secs_f64();
            self.timing.iterations += 1;
            let w1 = 2.0 * (z1 - z0) / h - w0;
            let r = i * (w1 - w0) / h + c * 0.5 * (w0 + w1) + kt * 0.5 * (z0 + z1)
                - m_mid
                - a * sf.force_mean;
            let drdz = 2.0 * i / (h * h) + c / h + 0.5 * kt - a * a * sf.dforce_dstroke;
            if r < 0.0 {
                lo = lo.max(z1);
            } else {
                hi = hi.min(z1);
            }
            let mut dz = -r / drdz;
            if !dz.is_finite() {
                bail!("lag-hinge model: non-finite Newton update at t = {t} s, iteration {it}, residual {r:e} N m");
            }
            let bracketed = lo.is_finite() && hi.is_finite() && lo < hi;
            if it >= PLAIN && bracketed && !(lo < z1 + dz && z1 + dz < hi) {
                dz = 0.5 * (lo + hi) - z1;
            }
            z1 += dz;
            // Residual small; or the update below 1e-12 rad with the residual below 1e-6 of
            // the moment scale (devices with an inner solve, e.g. a series mount, have force
            // noise far below what moves the blade). A tiny update alone is not convergence: a
            // device stiff beyond sense makes every update tiny whatever the residual.
            if it > 0
                && (r.abs() <= 1e-10 * scale || (dz.abs() <= 1e-12 && r.abs() <= 1e-6 * scale))
            {
                converged = Some(());
                break;
            }
            if it == MAX_IT - 1 {
                bail!("lag-hinge model: Newton did not converge at t = {t} s after {} iterations, residual {r:e} N m", it + 1);
            }
        }
        if converged.is_none() {
            bail!("lag-hinge model: Newton did not converge at t = {t} s");
        }
        // Re-run the device at the converged stroke so the committed state matches z1.
        let th = Instant::now();
        self.dev.dev().trial_step(t, h, a * z0, a * z1)?;
        self.dev.dev().commit();
        hyd += th.elapsed().as_secs_f64();
        self.zeta_dot = 2.0 * (z1 - z0) / h - w0;
        self.zeta = z1;
        self.step += 1;
        self.timing.steps += 1;
        self.timing.hydraulics_s += hyd;
        self.timing.total_s += t0.elapsed().as_secs_f64();
        Ok(())
    }

    fn channel_names(&self) -> Vec<String> {
        let mut v: Vec<String> = BASE_CHANNELS.iter().map(|s| s.to_string()).collect();
        v.extend(
            self.dev
                .dev_ref()
                .channel_names()
                .iter()
                .map(|s| s.to_string()),
        );
        v
    }

    fn channels(&self, out: &mut [f64]) {
        let a = self.p.damper_arm_m;
        let base = [
            self.dev.dev_ref().committed_force(),
            a * self.zeta,
            a * self.zeta_dot,
            0.0,
            (self.p.radius_m - self.p.hinge_offset_m) * self.zeta,
            0.0,
        ];
        out[..6].copy_from_slice(&base);
        let nd = self.dev.dev_ref().channel_names().len();
        self.dev.dev_ref().channels(&mut out[6..6 + nd]);
    }

    fn force_limits_n(&self) -> Option<(f64, f64)> {
        self.limits
    }

    fn relief_regulation(&self) -> Option<[crate::rotor::ReliefRegulation; 2]> {
        match &self.dev {
            Holder::Circuit(c) => crate::rotor::ReliefRegulation::of(c.params()),
            Holder::Other(_) => None,
        }
    }

    fn timing(&self) -> Timing {
        self.timing
    }

    /// Coordinates `[zeta, zeta_dot / Omega]` [rad]; aux: the device state.
    fn save_state(&self) -> Option<crate::rotor::SimState> {
        Some(crate::rotor::SimState {
            t_s: self.time_s(),
            coords: vec![self.zeta, self.zeta_dot / self.p.omega_rad_s],
            solver: None,
            aux: self.dev.dev_ref().state_values(),
        })
    }

    fn restore_state(&mut self, s: &crate::rotor::SimState) -> anyhow::Result<()> {
        if s.coords.len() != 2 || s.coords.iter().any(|c| !c.is_finite()) {
            bail!(
                "{}: a saved state of the lag-hinge model has 2 finite coordinates, got {:?}",
                self.label,
                s.coords
            );
        }
        let step = (s.t_s / self.dt).round();
        if !(step >= 0.0 && (step * self.dt - s.t_s).abs() <= 1e-6 * self.dt.max(s.t_s.abs())) {
            bail!(
                "{}: saved time {} s is not a whole number of steps of {} s",
                self.label,
                s.t_s,
                self.dt
            );
        }
        self.dev
            .dev()
            .set_state_values(&s.aux)
            .map_err(|e| anyhow::anyhow!("{}: {e}", self.label))?;
        self.step = step as usize;
        self.zeta = s.coords[0];
        self.zeta_dot = s.coords[1] * self.p.omega_rad_s;
        Ok(())
    }

    fn mode_label(&self, _re: &[f64], _im: &[f64]) -> String {
        "lag".into()
    }
}
