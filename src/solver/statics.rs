//! Nonlinear static analysis by load stepping, optionally about a steadily rotating state
//! (inertial forces of a rigid rotation `omega` included: centrifugal loads and stiffening).
use super::assembly::Assembler;
use super::newton::{model_size, norm, NewtonError, NewtonOptions};
use super::state::State;
use crate::structure::kin::{EvalCtx, NodeKin, Seed};
use crate::structure::model::Model;
use crate::structure::rotation::*;

#[derive(Clone, Debug)]
pub struct StaticOptions {
    pub load_steps: usize,
    pub newton: NewtonOptions,
    /// Time at which prescribed motions and time tables are evaluated.
    pub time: f64,
    /// Steady rotation (rad/s, global vector through the origin): the solution is the
    /// equilibrium in the frame rotating with it.
    pub omega: Option<[f64; 3]>,
    /// Load factor ramps linearly from `start_factor` (exclusive) to `end_factor`.
    pub start_factor: f64,
    pub end_factor: f64,
}

impl Default for StaticOptions {
    fn default() -> Self {
        StaticOptions {
            load_steps: 1,
            newton: NewtonOptions::default(),
            time: 0.0,
            omega: None,
            start_factor: 0.0,
            end_factor: 1.0,
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct StaticReport {
    /// Newton iterations per load step.
    pub iterations: Vec<usize>,
    pub residual: f64,
}

/// Seeds for the static / steady-rotating tangent: configuration derivative, with the
/// velocities and accelerations of the rigid rotation following the configuration.
pub fn static_seed(omega: [f64; 3]) -> impl Fn(usize, usize) -> Seed {
    move |_n, comp| {
        let mut e = [0.0; 3];
        e[comp % 3] = 1.0;
        if comp < 3 {
            Seed {
                dx: e,
                dv: cross(omega, e),
                da: cross(omega, cross(omega, e)),
                ..Default::default()
            }
        } else {
            Seed {
                dth: e,
                ..Default::default()
            }
        }
    }
}

/// Fill nodal kinematics of the steady rotation for the current configuration.
pub fn rotating_kin(st: &State, omega: [f64; 3], kin: &mut Vec<NodeKin<f64>>) {
    st.kin(kin);
    for k in kin.iter_mut() {
        k.v = cross(omega, k.x);
        k.w = omega;
        k.a = cross(omega, cross(omega, k.x));
        k.al = [0.0; 3];
    }
}

/// Mean absolute diagonal of the node block (constraint scaling).
pub fn diag_scale(asm: &Assembler) -> f64 {
    let n = 6 * asm.n_nodes;
    let s: f64 = (0..n).map(|i| asm.diag(i).abs()).sum::<f64>() / n.max(1) as f64;
    if s > 0.0 && s.is_finite() {
        s
    } else {
        1.0
    }
}

/// Largest rotation increment of a Newton correction in the damped retry [rad].
const DAMPED_MAX_ROTATION: f64 = 0.1;

/// Solve the static equilibrium, updating `st` in place (load factor ramps to 1). Full Newton
/// first; when it diverges or meets a singular matrix on the way (a large first correction can
/// overshoot, e.g. a rotating blade whose pitch, flap and lag are all soft), once more from
/// the same start with each correction scaled down to at most 0.1 rad of rotation (damped
/// Newton, 8 times the iterations). If that fails too, the first error is returned.
pub fn static_solve(
    model: &mut Model,
    st: &mut State,
    opts: &StaticOptions,
    mut progress: impl FnMut(usize, usize, usize, f64),
) -> Result<StaticReport, NewtonError> {
    let start = st.clone();
    match solve(model, st, opts, None, &mut progress) {
        Err(
            first @ (NewtonError::StaticDiverged { .. }
            | NewtonError::NonFinite { .. }
            | NewtonError::Linear { .. }),
        ) => {
            *st = start;
            let mut damped = opts.clone();
            damped.newton.max_iterations *= 8;
            solve(model, st, &damped, Some(DAMPED_MAX_ROTATION), &mut progress).map_err(|_| first)
        }
        r => r,
    }
}

fn solve(
    model: &mut Model,
    st: &mut State,
    opts: &StaticOptions,
    max_rotation: Option<f64>,
    progress: &mut impl FnMut(usize, usize, usize, f64),
) -> Result<StaticReport, NewtonError> {
    let t = opts.time;
    let lerr = |source, iteration| NewtonError::Linear {
        t,
        iteration,
        source,
    };
    let mut asm = Assembler::new(model).map_err(|e| lerr(e, 0))?;
    let omega = opts.omega.unwrap_or([0.0; 3]);
    let seed = static_seed(omega);
    let nn = 6 * model.nodes.len();
    let ndof = asm.ndof;
    let mut res = vec![0.0; ndof];
    let mut kin = Vec::with_capacity(model.nodes.len());
    let size = model_size(&st.x);
    let mut ctx = EvalCtx {
        t,
        load_factor: 1.0,
        gravity: model.gravity,
        cscale: 1.0,
        inertia: opts.omega.is_some(),
        dt: 0.0,
    };
    // constraint scaling from the tangent diagonal at the start
    let mut lam_hat = vec![0.0; ndof - nn];
    let mk_kin = |st: &State, kin: &mut Vec<NodeKin<f64>>| {
        if opts.omega.is_some() {
            rotating_kin(st, omega, kin)
        } else {
            st.kin(kin)
        }
    };
    mk_kin(st, &mut kin);
    model.update_distributed_loads(t, &kin);
    let at = (t, 0, f64::NAN);
    tangent(
        &mut asm, model, &kin, &lam_hat, &ctx, &seed, &st.x, at, &mut res,
    )?;
    ctx.cscale = diag_scale(&asm);
    for (l, lp) in lam_hat.iter_mut().zip(&st.lambda) {
        *l = lp / ctx.cscale;
    }
    let mut report = StaticReport::default();
    // force scale of the round-off floor: the model's at the end load factor (loads, inertia of
    // the steady rotation, device forces; Assembler::force_scale), or the largest initial
    // residual of the load steps if larger
    let mut r_scale: f64 = {
        let g = model.gravity;
        let lf = opts.end_factor;
        let c = EvalCtx {
            load_factor: lf,
            gravity: fmul(lf, g),
            ..ctx
        };
        asm.force_scale(model, &kin, &c, &mut res)
    };
    let mut xi: Vec<[f64; 3]> = st.x.clone();
    let nsteps = opts.load_steps.max(1);
    let g = model.gravity;
    for step in 1..=nsteps {
        let lf =
            opts.start_factor + (opts.end_factor - opts.start_factor) * step as f64 / nsteps as f64;
        ctx.load_factor = lf;
        ctx.gravity = fmul(lf, g);
        let mut r0 = 0.0;
        let mut it = 0;
        let mut tiny = false;
        let mut r_last = f64::NAN;
        loop {
            mk_kin(st, &mut kin);
            model.update_distributed_loads(t, &kin);
            xi.copy_from_slice(&st.x);
            let at = (t, it, r_last);
            tangent(
                &mut asm, model, &kin, &lam_hat, &ctx, &seed, &xi, at, &mut res,
            )?;
            let rn = norm(&res);
            if !rn.is_finite() {
                return Err(NewtonError::NonFinite {
                    t,
                    iteration: it,
                    residual: r_last,
                });
            }
            r_last = rn;
            if it == 0 {
                r0 = rn;
                r_scale = r_scale.max(rn);
            }
            progress(step, nsteps, it, rn);
            if rn <= opts.newton.rtol * r0.max(1e-300)
                || rn == 0.0
                || (tiny && rn <= opts.newton.floor(r_scale))
            {
                report.residual = rn;
                break;
            }
            if it >= opts.newton.max_iterations {
                return Err(NewtonError::StaticDiverged {
                    load_factor: lf,
                    iterations: it,
                    residual: rn,
                    initial: r0,
                });
            }
            asm.factor().map_err(|e| lerr(e, it))?;
            for r in res.iter_mut() {
                *r = -*r;
            }
            asm.solve(&mut res);
            let dmax = apply_correction(st, &mut res, &mut lam_hat, max_rotation);
            it += 1;
            if !dmax.is_finite() {
                return Err(NewtonError::NonFinite {
                    t,
                    iteration: it,
                    residual: r_last,
                });
            }
            // a tiny correction ends the iterations only with the residual at its floor
            tiny = dmax <= opts.newton.xtol * size;
        }
        report.iterations.push(it);
        for (lp, l) in st.lambda.iter_mut().zip(&lam_hat) {
            *lp = l * ctx.cscale;
        }
    }
    st.t = t;
    if let Some(om) = opts.omega {
        st.set_rigid_rotation([0.0; 3], om);
    }
    // commit: joint angle tracking and step elements
    let kin_c: Vec<NodeKin<f64>> = (0..st.x.len()).map(|i| st.node_kin(i)).collect();
    commit(model, &kin_c, 0.0);
    Ok(report)
}

/// Residual and tangent at positions `x`; an element's failure names time, iteration and the
/// last residual `at`.
#[allow(clippy::too_many_arguments)]
fn tangent(
    asm: &mut Assembler,
    model: &mut Model,
    kin: &[NodeKin<f64>],
    lam_hat: &[f64],
    ctx: &EvalCtx,
    seed: &dyn Fn(usize, usize) -> Seed,
    x: &[[f64; 3]],
    (t, iteration, residual): (f64, usize, f64),
    res: &mut [f64],
) -> Result<(), NewtonError> {
    asm.assemble(model, kin, lam_hat, ctx, seed, Some((t, 0.0, x)), true, res)
        .map_err(|source| NewtonError::Element {
            t,
            iteration,
            residual,
            source,
        })
}

/// Apply the Newton correction `res` (scaled to at most `max_rotation` of node rotation) to the
/// nodes and the scaled multipliers; the largest component applied.
fn apply_correction(
    st: &mut State,
    res: &mut [f64],
    lam_hat: &mut [f64],
    max_rotation: Option<f64>,
) -> f64 {
    let n = st.x.len();
    let nn = 6 * n;
    if let Some(cap) = max_rotation {
        let rot = (0..n)
            .flat_map(|i| res[6 * i + 3..6 * i + 6].iter())
            .fold(0.0f64, |m, v| m.max(v.abs()));
        if rot > cap {
            let f = cap / rot;
            res.iter_mut().for_each(|r| *r *= f);
        }
    }
    let mut dmax: f64 = 0.0;
    for i in 0..n {
        let dx = [res[6 * i], res[6 * i + 1], res[6 * i + 2]];
        let dth = [res[6 * i + 3], res[6 * i + 4], res[6 * i + 5]];
        st.x[i] = add(st.x[i], dx);
        st.q[i] = update_left(&st.q[i], dth);
        dmax = dmax.max(
            dx.iter()
                .chain(dth.iter())
                .fold(0.0f64, |m, v| m.max(v.abs())),
        );
    }
    for (k, l) in lam_hat.iter_mut().enumerate() {
        *l += res[nn + k];
    }
    dmax
}

/// Commit the converged state at the end of a step of `dt` [s] (0: statics): joints update
/// their unwrapped angle and their elastomer's history, step elements `commit()`.
pub fn commit(model: &mut Model, kin: &[NodeKin<f64>], dt: f64) {
    for e in model.elements.iter_mut() {
        if let crate::structure::model::Element::Joint(j) = e {
            let a = j.node_a.map(|i| kin[i]).unwrap_or_else(NodeKin::ground);
            let b = kin[j.node_b];
            j.commit(&a, &b, dt);
        }
    }
    for s in model.step_elements.iter_mut() {
        s.commit();
    }
}

/// Check that the constraint gradient has full row rank at `st`; names the first redundant
/// joint (singular constraint set) otherwise.
pub fn check_constraints(model: &mut Model, st: &State) -> Result<(), String> {
    let mut asm = Assembler::new(model).map_err(|e| e.to_string())?;
    let nn = 6 * model.nodes.len();
    let ndof = asm.ndof;
    if ndof == nn {
        return Ok(());
    }
    let mut kin = vec![];
    st.kin(&mut kin);
    let ctx = EvalCtx {
        t: st.t,
        ..Default::default()
    };
    let lam = vec![0.0; ndof - nn];
    let mut res = vec![0.0; ndof];
    asm.assemble(
        model,
        &kin,
        &lam,
        &ctx,
        &static_seed([0.0; 3]),
        None,
        true,
        &mut res,
    )
    .map_err(|e| e.to_string())?;
    // constraint rows only: the whole matrix dense would be ndof^2
    let d = asm.dense_rows(nn..ndof, nn);
    let mut basis: Vec<Vec<f64>> = vec![];
    for (ei, e) in model.elements.iter().enumerate() {
        for k in 0..e.n_lambda() {
            let row = asm.lam_start[ei] + k;
            let mut v: Vec<f64> = d[row - nn].clone();
            let n0 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            for b in &basis {
                let p: f64 = v.iter().zip(b).map(|(x, y)| x * y).sum();
                v.iter_mut().zip(b).for_each(|(x, y)| *x -= p * y);
            }
            let n1 = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if n0 == 0.0 || n1 <= 1e-8 * n0 {
                return Err(format!(
                    "singular constraint set: constraint {} of joint `{}` is redundant with the constraints before it (e.g. a node clamped twice, or a revolute axis already locked)",
                    k + 1,
                    e.name()
                ));
            }
            basis.push(v.iter().map(|x| x / n1).collect());
        }
    }
    Ok(())
}
