//! Generalized-alpha time integration for index-3 constrained systems on the Lie group
//! R^3 x SO(3) per node (Arnold & Bruls 2007; Bruls, Cardona & Arnold 2012), with Chung-Hulbert
//! parameters from the spectral radius at infinity `rho_inf`.
//!
//! Per step: `x_{n+1} = x_n + h dq_x`, `R_{n+1} = exp(h dq_th) R_n` (spatial),
//! `dq = v_n + h (1/2 - beta) a_n + h beta a_{n+1}`, `v_{n+1} = v_n + h (1 - gamma) a_n + h gamma a_{n+1}`,
//! `(1 - alpha_m) a_{n+1} + alpha_m a_n = (1 - alpha_f) vd_{n+1} + alpha_f vd_n`, with the
//! equations of motion and constraints `Phi(q_{n+1}) = 0` enforced at t_{n+1}. Newton unknowns
//! are `dq` and scaled multipliers; the iteration matrix is the exact derivative including the
//! tangent operator of the exponential map. Full Newton refactors it at every iterate;
//! modified Newton keeps the factorization across iterations and steps, turned with the
//! driven shaft, until an iteration stops contracting (docs/structure.md, "Full and modified
//! Newton").
use super::assembly::Assembler;
use super::newton::{model_size, norm, NewtonError, NewtonMethod, NewtonOptions};
use super::state::{lambda_offsets, sensor_header, sensor_values, State};
use super::statics::{commit, diag_scale};
use crate::structure::joint::AngleLaw;
use crate::structure::kin::{EvalCtx, NodeKin, Seed};
use crate::structure::model::{Element, Model};
use crate::structure::rotation::*;

/// Generalized-alpha parameters (Chung & Hulbert 1993).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GenAlphaParams {
    pub rho_inf: f64,
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub gamma: f64,
    pub beta: f64,
}

impl GenAlphaParams {
    pub fn from_rho_inf(rho: f64) -> Self {
        let rho = rho.clamp(0.0, 1.0);
        let alpha_m = (2.0 * rho - 1.0) / (rho + 1.0);
        let alpha_f = rho / (rho + 1.0);
        let gamma = 0.5 + alpha_f - alpha_m;
        let beta = 0.25 * (gamma + 0.5).powi(2);
        GenAlphaParams {
            rho_inf: rho,
            alpha_m,
            alpha_f,
            gamma,
            beta,
        }
    }
}

/// Statistics of one step.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepInfo {
    pub t: f64,
    pub iterations: usize,
    pub residual: f64,
}

/// The frame that turns with a driven shaft: the axis (global) and angle law of the model's one
/// grounded joint with a prescribed rotation. A rotor's iteration matrix, seen from this frame,
/// changes slowly, so a stored factorization turned by the angle travelled since it was made
/// stays a good approximation (`J(t) ~ Q J_f Q^T`, `Q` the turn, on every node's force and
/// moment rows and displacement and rotation columns; multipliers live in joint frames).
/// The translational multipliers of grounded joints are reactions in the fixed joint frame,
/// so they turn too (in joint-frame components, by `Q_A^T Q Q_A`).
#[derive(Clone, Debug)]
struct CoRotation {
    axis: [f64; 3],
    law: AngleLaw,
    /// First multiplier dof and joint frame of every grounded joint.
    grounded: Vec<(usize, [[f64; 3]; 3])>,
}

impl CoRotation {
    /// The driven joint of `model`, if it has exactly one.
    fn of(model: &Model, asm: &Assembler) -> Option<Self> {
        let mut found = None;
        let mut on_node = vec![];
        let mut grounded = vec![];
        for (ei, e) in model.elements.iter().enumerate() {
            if let Element::Joint(j) = e {
                // only a full reaction vector turns (multipliers 0..3 along the joint axes);
                // a bushing's springs are node rows, which turn with the nodes, and a reaction
                // along fewer locked axes is not a vector (the contraction rule refreshes)
                if j.node_a.is_none() && j.locks().0 == 3 {
                    grounded.push((asm.lam_start[ei], j.qa));
                }
                // the driven shaft: on the ground, or else on a node that moves little (a
                // rotor's airframe, whose own rows then turn with the rest: an approximation
                // the contraction rule watches)
                if let Some(law) = &j.prescribed_angle {
                    match j.node_a {
                        None => {
                            if found.is_some() {
                                return None;
                            }
                            found = Some((j.qa, law.clone()));
                        }
                        Some(i) => on_node.push((mm(&model.node_r0(i), &j.qa), law.clone())),
                    }
                }
            }
        }
        if found.is_none() && on_node.len() == 1 {
            found = on_node.pop();
        }
        found.map(|(qa, law)| CoRotation {
            axis: [qa[0][2], qa[1][2], qa[2][2]],
            law,
            grounded,
        })
    }

    /// Turns the blocks of 3 that turn with the shaft (node forces and moments or displacements
    /// and rotations in `v[..nn]`, grounded joints' reactions) by `q`, or by `q^T` if `back`.
    fn turn(&self, v: &mut [f64], nn: usize, q: &[[f64; 3]; 3], back: bool) {
        let apply = |m: &[[f64; 3]; 3], b: &mut [f64]| {
            let x = [b[0], b[1], b[2]];
            let y = if back { mtv(m, x) } else { mv(m, x) };
            b.copy_from_slice(&y);
        };
        for b in v[..nn].chunks_exact_mut(3) {
            apply(q, b);
        }
        for (l0, qa) in &self.grounded {
            apply(&mtm(qa, &mm(q, qa)), &mut v[*l0..*l0 + 3]);
        }
    }
}

/// Dynamic solver owning the model and the state; step it with [`DynamicSolver::step`].
pub struct DynamicSolver {
    pub model: Model,
    pub state: State,
    pub h: f64,
    pub params: GenAlphaParams,
    pub newton: NewtonOptions,
    asm: Assembler,
    /// Algorithmic accelerations per node (translation, rotation).
    pub(super) acc: Vec<[f64; 6]>,
    pub(super) lam_hat: Vec<f64>,
    cscale: f64,
    size: f64,
    res: Vec<f64>,
    pub(super) kin: Vec<NodeKin<f64>>,
    dq: Vec<[f64; 6]>,
    tl: Vec<[[f64; 3]; 3]>,
    x_prev: Vec<[f64; 3]>,
    lam_offsets: Vec<usize>,
    ws_a: Vec<[f64; 6]>,
    ws_vd: Vec<[f64; 6]>,
    ws_v: Vec<[f64; 6]>,
    ws_x: Vec<[f64; 3]>,
    ws_q: Vec<nalgebra::UnitQuaternion<f64>>,
    ws_q2: Vec<nalgebra::UnitQuaternion<f64>>,
    ws_lam: Vec<f64>,
    /// True accelerations and multipliers of the step before the last (predictor).
    pub(super) prev_vd: Vec<[f64; 6]>,
    pub(super) prev_lam: Vec<f64>,
    /// Residual of the last zero-acceleration predictor evaluated (convergence scale), and
    /// whether the last step refactored.
    pub(super) r_ref: f64,
    /// Largest reference residual seen (with `f_model`, the force scale of the round-off floor).
    pub(super) r_scale: f64,
    /// The model's force scale at the initial state ([`Assembler::force_scale`]), taken at the
    /// first step (a turning frame is set after `new`); negative until then.
    f_model: f64,
    refreshed: bool,
    /// Residual norms of the Newton iterates of the last step (convergence diagnostics).
    pub last_residuals: Vec<f64>,
    /// Total Newton iterations so far.
    pub total_iterations: usize,
    /// Factorizations of the iteration matrix so far (one per iteration with full Newton).
    pub factorizations: usize,
    pub steps: usize,
    corot: Option<CoRotation>,
    /// Whether the assembler holds a factorization usable by modified Newton, and the shaft
    /// angle at which it was made.
    have_factor: bool,
    factor_angle: f64,
    /// Steady rotation of the frame the state is given in [rad/s] (None: inertial). With it the
    /// positions, velocities and accelerations of the state are relative to a frame turning at
    /// `omega` about the origin (as MBDyn's rigid-body kinematics), and every element sees the
    /// absolute kinematics `v + omega x x`, `w + omega`, `a + 2 omega x v + omega x (omega x x)`,
    /// `al + omega x w` in that frame's components (the elements are objective); the iteration
    /// matrix carries the same terms through the seeds ([`frame_seed`]).
    pub frame_omega: Option<[f64; 3]>,
}

/// Absolute kinematics of relative ones in a frame turning steadily at `om` (see
/// [`DynamicSolver::frame_omega`]).
pub fn to_frame(k: &mut NodeKin<f64>, om: [f64; 3]) {
    let wv = cross(om, k.v);
    k.a = add(add(k.a, fmul(2.0, wv)), cross(om, cross(om, k.x)));
    k.al = add(k.al, cross(om, k.w));
    k.v = add(k.v, cross(om, k.x));
    k.w = add(k.w, om);
}

/// The seed of a relative dof seen through [`to_frame`]: chain rule of the absolute
/// kinematics in the relative position and velocities.
pub fn frame_seed(s: Seed, om: [f64; 3]) -> Seed {
    Seed {
        dx: s.dx,
        dth: s.dth,
        dv: add(s.dv, cross(om, s.dx)),
        dw: s.dw,
        da: add(
            add(s.da, fmul(2.0, cross(om, s.dv))),
            cross(om, cross(om, s.dx)),
        ),
        dal: add(s.dal, cross(om, s.dw)),
    }
}

impl DynamicSolver {
    /// Set up with initial state `state` (velocities as given; accelerations of the state are
    /// taken as the initial true accelerations).
    pub fn new(model: Model, state: State, h: f64, rho_inf: f64) -> Result<Self, NewtonError> {
        let t = state.t;
        let asm = Assembler::new(&model).map_err(|source| NewtonError::Linear {
            t,
            iteration: 0,
            source,
        })?;
        let n = model.nodes.len();
        let ndof = asm.ndof;
        let acc = (0..n)
            .map(|i| {
                [
                    state.a[i][0],
                    state.a[i][1],
                    state.a[i][2],
                    state.al[i][0],
                    state.al[i][1],
                    state.al[i][2],
                ]
            })
            .collect();
        let size = model_size(&state.x);
        let lam_offsets = lambda_offsets(&model);
        let corot = CoRotation::of(&model, &asm);
        let mut s = DynamicSolver {
            model,
            h,
            params: GenAlphaParams::from_rho_inf(rho_inf),
            newton: NewtonOptions::default(),
            asm,
            acc,
            lam_hat: vec![0.0; ndof - 6 * n],
            cscale: 1.0,
            size,
            res: vec![0.0; ndof],
            kin: Vec::with_capacity(n),
            dq: vec![[0.0; 6]; n],
            tl: vec![[[0.0; 3]; 3]; n],
            x_prev: state.x.clone(),
            lam_offsets,
            total_iterations: 0,
            factorizations: 0,
            steps: 0,
            corot,
            have_factor: false,
            factor_angle: 0.0,
            frame_omega: None,
            ws_a: vec![],
            ws_vd: vec![],
            ws_v: vec![],
            ws_x: vec![],
            ws_q: vec![],
            ws_q2: vec![],
            ws_lam: vec![],
            prev_vd: vec![],
            prev_lam: vec![],
            r_ref: 0.0,
            r_scale: 0.0,
            f_model: -1.0,
            refreshed: false,
            last_residuals: Vec::with_capacity(64),
            state,
        };
        s.init_scaling()?;
        Ok(s)
    }

    fn coeffs(&self) -> (f64, f64) {
        let p = &self.params;
        let ca = (1.0 - p.alpha_m) / ((1.0 - p.alpha_f) * self.h * p.beta);
        (p.gamma / p.beta, ca)
    }

    fn init_scaling(&mut self) -> Result<(), NewtonError> {
        let t = self.state.t;
        self.state.kin(&mut self.kin);
        let (cv, ca) = self.coeffs();
        let h = self.h;
        let seed = move |_: usize, comp: usize| Seed::generalized_alpha(comp, h, cv, ca, &IDENT);
        let ctx = EvalCtx {
            t,
            load_factor: 1.0,
            gravity: self.model.gravity,
            cscale: 1.0,
            inertia: true,
            dt: 0.0,
        };
        self.asm
            .assemble(
                &mut self.model,
                &self.kin,
                &self.lam_hat,
                &ctx,
                &seed,
                None,
                true,
                &mut self.res,
            )
            .map_err(|source| NewtonError::Element {
                t,
                iteration: 0,
                residual: f64::NAN,
                source,
            })?;
        self.cscale = diag_scale(&self.asm) / h;
        for (l, lp) in self.lam_hat.iter_mut().zip(&self.state.lambda) {
            *l = lp / self.cscale;
        }
        Ok(())
    }

    /// Residual (and with `matrix` the iteration matrix) at the current iterate `self.kin`.
    fn assemble_at(
        &mut self,
        t: f64,
        t_n: f64,
        lam_hat: &[f64],
        ctx: &EvalCtx,
        matrix: bool,
        (iteration, residual): (usize, f64),
    ) -> Result<(), NewtonError> {
        let (cv, ca) = self.coeffs();
        let h = self.h;
        let tl = &self.tl;
        let fo = self.frame_omega;
        let seed = |node: usize, comp: usize| {
            let s = Seed::generalized_alpha(comp, h, cv, ca, &tl[node]);
            match fo {
                None => s,
                Some(om) => frame_seed(s, om),
            }
        };
        self.asm
            .assemble(
                &mut self.model,
                &self.kin,
                lam_hat,
                ctx,
                &seed,
                Some((t_n, h, &self.x_prev)),
                matrix,
                &mut self.res,
            )
            .map_err(|source| NewtonError::Element {
                t,
                iteration,
                residual,
                source,
            })
    }

    /// Solve `J dq = res` in place with the stored factorization, turned from the shaft angle
    /// at which it was made to `angle` (`dq = Q J_f^-1 Q^T res`); no turn without a driven
    /// shaft.
    fn solve_corotated(&mut self, angle: Option<f64>) {
        let turn = match (&self.corot, angle) {
            (Some(c), Some(a)) if a != self.factor_angle => {
                Some((c, exp_map(fmul(a - self.factor_angle, c.axis))))
            }
            _ => None,
        };
        let nn = 6 * self.model.nodes.len();
        if let Some((c, q)) = &turn {
            c.turn(&mut self.res, nn, q, true);
        }
        self.asm.solve(&mut self.res);
        if let Some((c, q)) = &turn {
            c.turn(&mut self.res, nn, q, false);
        }
    }

    /// Moves the zero-acceleration predictor to the one extrapolated from the last two steps:
    /// `vd = 2 vd_n - vd_n-1`, `lambda = 2 lambda_n - lambda_n-1`, through the same linear
    /// relations as a Newton correction (`dq += d`, `v += cv d`, `vd += ca d`).
    fn shift_predictor(
        &mut self,
        lam_hat: &mut [f64],
        v_new: &mut [[f64; 6]],
        vd_new: &mut [[f64; 6]],
        cv: f64,
        ca: f64,
    ) {
        for (k, l) in lam_hat.iter_mut().enumerate() {
            *l += self.lam_hat[k] - self.prev_lam[k];
        }
        for i in 0..v_new.len() {
            let vdn = cat(self.state.a[i], self.state.al[i]);
            for k in 0..6 {
                let d = (2.0 * vdn[k] - self.prev_vd[i][k] - vd_new[i][k]) / ca;
                self.dq[i][k] += d;
                v_new[i][k] += cv * d;
                vd_new[i][k] += ca * d;
            }
        }
    }

    /// Zero-acceleration predictor of the step from the converged state: `dq`, `v_new`,
    /// `vd_new` (`a_new`: the algorithmic accelerations it implies) and `x_prev`.
    fn predict(
        &mut self,
        a_new: &mut Vec<[f64; 6]>,
        v_new: &mut Vec<[f64; 6]>,
        vd_new: &mut Vec<[f64; 6]>,
    ) {
        let p = self.params;
        let h = self.h;
        let n = self.model.nodes.len();
        a_new.resize(n, [0.0; 6]);
        vd_new.resize(n, [0.0; 6]);
        v_new.resize(n, [0.0; 6]);
        for i in 0..n {
            let vn = cat(self.state.v[i], self.state.w[i]);
            let vdn = cat(self.state.a[i], self.state.al[i]);
            for k in 0..6 {
                a_new[i][k] = (p.alpha_f * vdn[k] - p.alpha_m * self.acc[i][k]) / (1.0 - p.alpha_m);
                v_new[i][k] =
                    vn[k] + h * (1.0 - p.gamma) * self.acc[i][k] + h * p.gamma * a_new[i][k];
                self.dq[i][k] =
                    vn[k] + h * (0.5 - p.beta) * self.acc[i][k] + h * p.beta * a_new[i][k];
                vd_new[i][k] = 0.0;
            }
        }
        self.x_prev.clone_from(&self.state.x);
    }

    /// Node kinematics `self.kin` of the iterate: configuration from `dq`
    /// (`x = x_n + h dq_x`, `R = exp(h dq_th) R_n`), velocities and accelerations `v_new`,
    /// `vd_new`, made absolute ([`to_frame`]) in a turning frame; `tl` the rotation tangents.
    fn set_iterate(
        &mut self,
        x_new: &mut [[f64; 3]],
        q_new: &mut [nalgebra::UnitQuaternion<f64>],
        q_prev: &[nalgebra::UnitQuaternion<f64>],
        v_new: &[[f64; 6]],
        vd_new: &[[f64; 6]],
    ) {
        let h = self.h;
        let n = self.model.nodes.len();
        for i in 0..n {
            let th = [h * self.dq[i][3], h * self.dq[i][4], h * self.dq[i][5]];
            for k in 0..3 {
                x_new[i][k] = self.x_prev[i][k] + h * self.dq[i][k];
            }
            q_new[i] = update_left(&q_prev[i], th);
            self.tl[i] = tangent_left(th);
        }
        self.kin.clear();
        for i in 0..n {
            self.kin.push(NodeKin {
                x: x_new[i],
                r: quat_to_arr(&q_new[i]),
                v: [v_new[i][0], v_new[i][1], v_new[i][2]],
                w: [v_new[i][3], v_new[i][4], v_new[i][5]],
                a: [vd_new[i][0], vd_new[i][1], vd_new[i][2]],
                al: [vd_new[i][3], vd_new[i][4], vd_new[i][5]],
            });
        }
        if let Some(om) = self.frame_omega {
            for k in self.kin.iter_mut() {
                to_frame(k, om);
            }
        }
    }

    /// Test hook for finite-difference checks of the iteration matrix: the residual and the
    /// dense iteration matrix of the next step's Newton system at the zero-acceleration
    /// predictor moved by the Newton correction `d` (node dofs, then scaled multipliers; the
    /// update of [`DynamicSolver::step`]). With `frame_terms = false` the matrix is assembled
    /// from seeds without the turning-frame terms of [`frame_seed`] (the residual is the
    /// same): the matrix of a solver that ignored them. The converged state is unchanged.
    #[doc(hidden)]
    pub fn iteration_system(
        &mut self,
        d: &[f64],
        frame_terms: bool,
    ) -> Result<(Vec<f64>, Vec<Vec<f64>>), NewtonError> {
        let n = self.model.nodes.len();
        let nn = 6 * n;
        assert_eq!(d.len(), self.asm.ndof, "correction length");
        let t_n = self.state.t;
        let t = t_n + self.h;
        let (cv, ca) = self.coeffs();
        let (mut a_new, mut v_new, mut vd_new) = (vec![], vec![], vec![]);
        self.predict(&mut a_new, &mut v_new, &mut vd_new);
        for i in 0..n {
            for k in 0..6 {
                let di = d[6 * i + k];
                self.dq[i][k] += di;
                v_new[i][k] += cv * di;
                vd_new[i][k] += ca * di;
            }
        }
        let lam_hat: Vec<f64> = self
            .lam_hat
            .iter()
            .zip(&d[nn..])
            .map(|(l, di)| l + di)
            .collect();
        let q_prev = self.state.q.clone();
        let mut x_new = self.state.x.clone();
        let mut q_new = q_prev.clone();
        self.set_iterate(&mut x_new, &mut q_new, &q_prev, &v_new, &vd_new);
        self.model.update_distributed_loads(t, &self.kin);
        let ctx = self.ctx(t, self.h);
        let fo = self.frame_omega;
        if !frame_terms {
            self.frame_omega = None;
        }
        let r = self.assemble_at(t, t_n, &lam_hat, &ctx, true, (0, f64::NAN));
        self.frame_omega = fo;
        r?;
        // the factorization (if any) no longer matches the assembled values
        self.have_factor = false;
        Ok((self.res.clone(), self.asm.to_dense()))
    }

    /// The evaluation context of a dynamic residual at time `t` (full loads and inertia), at
    /// the end of a step of `dt` (0: at a committed state).
    fn ctx(&self, t: f64, dt: f64) -> EvalCtx {
        EvalCtx {
            t,
            load_factor: 1.0,
            gravity: self.model.gravity,
            cscale: self.cscale,
            inertia: true,
            dt,
        }
    }

    /// The model's force scale at the current (initial) state, in absolute kinematics
    /// ([`Assembler::force_scale`]; distributed loads at `t`).
    fn model_force_scale(&mut self, t: f64) -> f64 {
        self.state.kin(&mut self.kin);
        if let Some(om) = self.frame_omega {
            for k in self.kin.iter_mut() {
                to_frame(k, om);
            }
        }
        self.model.update_distributed_loads(t, &self.kin);
        let ctx = self.ctx(t, 0.0);
        self.asm
            .force_scale(&self.model, &self.kin, &ctx, &mut self.res)
    }

    /// Evaluates the distributed loads at the current state (providers that record what they
    /// see, e.g. a lifting line, then hold the state's values).
    pub fn refresh_distributed_loads(&mut self) {
        let t = self.state.t;
        self.state.kin(&mut self.kin);
        if let Some(om) = self.frame_omega {
            for k in self.kin.iter_mut() {
                to_frame(k, om);
            }
        }
        self.model.update_distributed_loads(t, &self.kin);
    }

    /// Advance one step of size `h`. On error the state is left at the last converged step.
    pub fn step(&mut self) -> Result<StepInfo, NewtonError> {
        let h = self.h;
        let n = self.model.nodes.len();
        let t_n = self.state.t;
        let t = t_n + h;
        let (cv, ca) = self.coeffs();
        // predictor (vd_{n+1} = 0)
        let mut a_new = std::mem::take(&mut self.ws_a);
        let mut vd_new = std::mem::take(&mut self.ws_vd);
        let mut v_new = std::mem::take(&mut self.ws_v);
        self.predict(&mut a_new, &mut v_new, &mut vd_new);
        let mut q_prev = std::mem::take(&mut self.ws_q);
        q_prev.clone_from(&self.state.q);
        let mut lam_hat = std::mem::take(&mut self.ws_lam);
        lam_hat.clone_from(&self.lam_hat);
        let ctx = self.ctx(t, h);
        let mut r0 = 0.0;
        let mut r_prev = 0.0;
        let mut it = 0;
        self.last_residuals.clear();
        let mut x_new = std::mem::take(&mut self.ws_x);
        x_new.clone_from(&self.x_prev);
        let mut q_new = std::mem::take(&mut self.ws_q2);
        q_new.clone_from(&q_prev);
        let modified = self.newton.method == NewtonMethod::Modified;
        let angle_t = self.corot.as_ref().map(|c| c.law.angle(t));
        // Convergence: ||r|| <= rtol r_ref, r_ref the residual of the zero-acceleration
        // predictor. Full Newton starts every step there. Modified Newton evaluates it at the
        // first step and after each refactorization, and starts from a predictor extrapolated
        // from the last two steps (accelerations and multipliers), whose residual is ~1000x
        // smaller, so that the stored matrix has less to correct.
        if self.f_model < 0.0 {
            self.f_model = self.model_force_scale(t_n);
        }
        let extrapolate = modified && self.prev_vd.len() == n;
        let mut scale_pending = !extrapolate || self.refreshed || self.r_ref == 0.0;
        if !scale_pending {
            r0 = self.r_ref;
            self.shift_predictor(&mut lam_hat, &mut v_new, &mut vd_new, cv, ca);
        }
        self.refreshed = false;
        // A correction below xtol ends the iterations only where the residual at the corrected
        // iterate has reached the round-off floor: a tiny update alone is not convergence.
        let mut tiny = false;
        let mut r_last = f64::NAN;
        loop {
            self.set_iterate(&mut x_new, &mut q_new, &q_prev, &v_new, &vd_new);
            self.model.update_distributed_loads(t, &self.kin);
            // A matrix is assembled only where it is factored: modified Newton without a
            // stored factorization assembles it with the residual; otherwise the residual
            // comes first and the matrix only if the iterate is not converged.
            let mut assembled = modified && !self.have_factor && !(scale_pending && extrapolate);
            self.assemble_at(t, t_n, &lam_hat, &ctx, assembled, (it, r_last))?;
            let rn = norm(&self.res);
            if !rn.is_finite() {
                return Err(NewtonError::NonFinite {
                    t,
                    iteration: it,
                    residual: r_last,
                });
            }
            r_last = rn;
            if self.last_residuals.len() < self.last_residuals.capacity() {
                self.last_residuals.push(rn);
            }
            if scale_pending {
                scale_pending = false;
                r0 = rn;
                self.r_ref = rn;
                self.r_scale = self.r_scale.max(rn);
                if extrapolate && rn > self.newton.rtol * r0 && rn != 0.0 {
                    self.shift_predictor(&mut lam_hat, &mut v_new, &mut vd_new, cv, ca);
                    continue;
                }
            }
            if rn <= self.newton.rtol * r0
                || rn == 0.0
                || (tiny && rn <= self.newton.floor(self.f_model.max(self.r_scale).max(r0)))
            {
                break;
            }
            if it >= self.newton.max_iterations {
                return Err(NewtonError::Diverged {
                    t,
                    iterations: it,
                    residual: rn,
                    initial: r0,
                });
            }
            // Contraction-rate rule: the stored matrix is kept while each iteration divides
            // the residual by 1 / max_contraction at least.
            let refresh = !modified
                || !self.have_factor
                || (it > 0 && rn > self.newton.max_contraction * r_prev);
            if refresh {
                if !assembled {
                    self.assemble_at(t, t_n, &lam_hat, &ctx, true, (it, rn))?;
                    assembled = true;
                }
                // a failed factorization leaves none to reuse
                self.have_factor = false;
                self.asm.factor().map_err(|source| NewtonError::Linear {
                    t,
                    iteration: it,
                    source,
                })?;
                self.have_factor = true;
                self.refreshed = true;
                self.factor_angle = angle_t.unwrap_or(0.0);
                self.factorizations += 1;
            }
            debug_assert!(!refresh || assembled);
            r_prev = rn;
            for r in self.res.iter_mut() {
                *r = -*r;
            }
            self.solve_corotated(angle_t);
            let dmax = self.correct(&mut v_new, &mut vd_new, &mut lam_hat, cv, ca);
            it += 1;
            if !dmax.is_finite() {
                return Err(NewtonError::NonFinite {
                    t,
                    iteration: it,
                    residual: r_last,
                });
            }
            tiny = dmax <= self.newton.xtol * self.size;
        }
        self.accept(&x_new, &q_new, &v_new, &vd_new);
        self.ws_lam = std::mem::replace(&mut self.lam_hat, lam_hat);
        self.ws_a = a_new;
        self.ws_vd = vd_new;
        self.ws_v = v_new;
        self.ws_x = x_new;
        self.ws_q = q_prev;
        self.ws_q2 = q_new;
        for (lp, l) in self.state.lambda.iter_mut().zip(&self.lam_hat) {
            *lp = l * self.cscale;
        }
        self.state.t = t;
        self.state.kin(&mut self.kin);
        commit(&mut self.model, &self.kin, h);
        self.total_iterations += it;
        self.steps += 1;
        Ok(StepInfo {
            t,
            iterations: it,
            residual: r0,
        })
    }

    /// Apply the Newton correction in `res` to the increments, velocities and accelerations
    /// (Newmark-like coefficients `cv`, `ca`) and the scaled multipliers; the largest
    /// displacement correction `h |d|`.
    fn correct(
        &mut self,
        v_new: &mut [[f64; 6]],
        vd_new: &mut [[f64; 6]],
        lam_hat: &mut [f64],
        cv: f64,
        ca: f64,
    ) -> f64 {
        let h = self.h;
        let n = self.model.nodes.len();
        let nn = 6 * n;
        let mut dmax: f64 = 0.0;
        for i in 0..n {
            for k in 0..6 {
                let d = self.res[6 * i + k];
                self.dq[i][k] += d;
                v_new[i][k] += cv * d;
                vd_new[i][k] += ca * d;
                dmax = dmax.max((h * d).abs());
            }
        }
        for (k, l) in lam_hat.iter_mut().enumerate() {
            *l += self.res[nn + k];
        }
        dmax
    }

    /// Accept the converged iterate: the state takes it, the algorithmic accelerations and
    /// the extrapolation history move on.
    fn accept(
        &mut self,
        x_new: &[[f64; 3]],
        q_new: &[nalgebra::UnitQuaternion<f64>],
        v_new: &[[f64; 6]],
        vd_new: &[[f64; 6]],
    ) {
        let p = self.params;
        let n = self.model.nodes.len();
        self.prev_vd.resize(n, [0.0; 6]);
        for i in 0..n {
            self.prev_vd[i] = cat(self.state.a[i], self.state.al[i]);
        }
        self.prev_lam.clone_from(&self.lam_hat);
        for i in 0..n {
            let vdn = cat(self.state.a[i], self.state.al[i]);
            for k in 0..6 {
                self.acc[i][k] = ((1.0 - p.alpha_f) * vd_new[i][k] + p.alpha_f * vdn[k]
                    - p.alpha_m * self.acc[i][k])
                    / (1.0 - p.alpha_m);
            }
            self.state.x[i] = x_new[i];
            self.state.q[i] = q_new[i];
            self.state.v[i] = [v_new[i][0], v_new[i][1], v_new[i][2]];
            self.state.w[i] = [v_new[i][3], v_new[i][4], v_new[i][5]];
            self.state.a[i] = [vd_new[i][0], vd_new[i][1], vd_new[i][2]];
            self.state.al[i] = [vd_new[i][3], vd_new[i][4], vd_new[i][5]];
        }
    }

    /// What the last step's Newton iterations had to reach: `||r|| <= rtol r_ref` [N] (the
    /// residual's force rows are in N, its moment rows in N m).
    pub fn residual_tolerance(&self) -> f64 {
        self.newton.rtol * self.r_ref
    }

    /// Consistent initial accelerations: solves `M vd_0 + B^T lambda_0 = -r(q_0, v_0, vd = 0)`
    /// with `B vd_0 = -gamma`, `gamma = d^2 Phi / dt^2` along `(x + v t, exp(w t) R, t)`
    /// (velocity-dependent and explicit-time terms, by a Richardson-extrapolated second
    /// difference), and uses them as the initial algorithmic accelerations; also sets the
    /// initial multipliers.
    pub fn init_accelerations(&mut self) -> Result<(), NewtonError> {
        let t = self.state.t;
        let n = self.model.nodes.len();
        let nn = 6 * n;
        for i in 0..n {
            self.state.a[i] = [0.0; 3];
            self.state.al[i] = [0.0; 3];
        }
        self.state.kin(&mut self.kin);
        let seed_acc = |_: usize, comp: usize| {
            let mut e = [0.0; 3];
            e[comp % 3] = 1.0;
            if comp < 3 {
                Seed {
                    da: e,
                    ..Default::default()
                }
            } else {
                Seed {
                    dal: e,
                    ..Default::default()
                }
            }
        };
        let ctx = self.ctx(t, 0.0);
        self.model.update_distributed_loads(t, &self.kin);
        let xp = self.state.x.clone();
        let zero_lam = vec![0.0; self.lam_hat.len()];
        if !self.lam_hat.is_empty() {
            // constraint rows: B from the configuration seeds
            let mut tmp = vec![0.0; self.asm.ndof];
            self.asm
                .assemble(
                    &mut self.model,
                    &self.kin,
                    &zero_lam,
                    &ctx,
                    &super::statics::static_seed([0.0; 3]),
                    Some((t, 0.0, &xp)),
                    true,
                    &mut tmp,
                )
                .map_err(|source| NewtonError::Element {
                    t,
                    iteration: 0,
                    residual: f64::NAN,
                    source,
                })?;
        }
        let b_values = self.asm.values.clone();
        self.asm
            .assemble(
                &mut self.model,
                &self.kin,
                &zero_lam,
                &ctx,
                &seed_acc,
                Some((t, 0.0, &xp)),
                true,
                &mut self.res,
            )
            .map_err(|source| NewtonError::Element {
                t,
                iteration: 0,
                residual: f64::NAN,
                source,
            })?;
        self.asm.overwrite_rows_from(&b_values, nn);
        for r in self.res.iter_mut().take(nn) {
            *r = -*r;
        }
        // acceleration-level constraint right-hand side
        let size = self.size;
        let wmax = self
            .state
            .w
            .iter()
            .flat_map(|w| w.iter())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let vmax = self
            .state
            .v
            .iter()
            .flat_map(|v| v.iter())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        let tau = 1e-2 / (1.0 + wmax + vmax / size);
        let mut row = nn;
        for e in &self.model.elements {
            if let crate::structure::model::Element::Joint(j) = e {
                let nl = j.n_lambda();
                let phi_at = |s: f64, out: &mut [f64; 6]| {
                    let mv_node = |k: &NodeKin<f64>| NodeKin {
                        x: add(k.x, fmul(s, k.v)),
                        r: mm(&exp_map(fmul(s, k.w)), &k.r),
                        ..*k
                    };
                    let a = j
                        .node_a
                        .map(|i| mv_node(&self.kin[i]))
                        .unwrap_or_else(NodeKin::ground);
                    let b = mv_node(&self.kin[j.node_b]);
                    j.phi(&a, &b, t + s, out);
                };
                let mut g0 = [0.0; 6];
                phi_at(0.0, &mut g0);
                let second = |tau: f64| {
                    let mut gp = [0.0; 6];
                    let mut gm = [0.0; 6];
                    phi_at(tau, &mut gp);
                    phi_at(-tau, &mut gm);
                    std::array::from_fn::<f64, 6, _>(|k| {
                        (gp[k] - 2.0 * g0[k] + gm[k]) / (tau * tau)
                    })
                };
                let d1 = second(tau);
                let d2 = second(0.5 * tau);
                for k in 0..nl {
                    let gamma = (4.0 * d2[k] - d1[k]) / 3.0;
                    self.res[row + k] = -self.cscale * gamma;
                }
                row += nl;
            }
        }
        self.have_factor = false;
        self.asm.factor().map_err(|source| NewtonError::Linear {
            t,
            iteration: 0,
            source,
        })?;
        self.asm.solve(&mut self.res);
        for i in 0..n {
            let r = &self.res[6 * i..6 * i + 6];
            self.state.a[i] = [r[0], r[1], r[2]];
            self.state.al[i] = [r[3], r[4], r[5]];
            self.acc[i].copy_from_slice(r);
        }
        for (k, l) in self.lam_hat.iter_mut().enumerate() {
            *l = self.res[nn + k];
        }
        for (lp, l) in self.state.lambda.iter_mut().zip(&self.lam_hat) {
            *lp = l * self.cscale;
        }
        Ok(())
    }

    pub fn sensor_header(&self) -> Vec<String> {
        sensor_header(&self.model)
    }

    pub fn sensor_values(&self) -> Vec<f64> {
        sensor_values(&self.model, &self.state, &self.lam_offsets)
    }

    /// Kinetic and strain energy of beams and rigid bodies.
    pub fn energy(&self) -> (f64, f64) {
        energy(&self.model, &self.state)
    }
}

fn cat(a: [f64; 3], b: [f64; 3]) -> [f64; 6] {
    [a[0], a[1], a[2], b[0], b[1], b[2]]
}

const IDENT: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// (kinetic, strain) energy of the model at a state.
pub fn energy(model: &Model, st: &State) -> (f64, f64) {
    use crate::structure::model::Element;
    let mut ke = 0.0;
    let mut se = 0.0;
    for e in &model.elements {
        match e {
            Element::Beam(b) => {
                let k = b.nodes.map(|i| st.node_kin(i));
                ke += b.kinetic_energy(&k);
                se += b.strain_energy(&k);
            }
            Element::Rigid(r) => ke += r.kinetic_energy(&st.node_kin(r.node)),
            _ => {}
        }
    }
    (ke, se)
}

/// Linear and angular momentum (about the origin) of all beams.
pub fn momentum(model: &Model, st: &State) -> ([f64; 3], [f64; 3]) {
    use crate::structure::model::Element;
    let mut p = [0.0; 3];
    let mut l = [0.0; 3];
    for e in &model.elements {
        if let Element::Beam(b) = e {
            let k = b.nodes.map(|i| st.node_kin(i));
            let (pp, hh) = b.momentum(&k);
            p = add(p, pp);
            l = add(l, hh);
        }
    }
    (p, l)
}
