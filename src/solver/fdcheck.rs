//! Finite-difference check of the analytic (dual-number) element tangents: central differences
//! over each local dof, with rotation increments applied multiplicatively (`exp(+-h e) R`), and
//! over velocities and accelerations.
use super::assembly::{element_residual, MAXL};
use crate::structure::kin::{EvalCtx, NodeKin};
use crate::structure::model::{Element, Model};
use crate::structure::real::Dual;
use crate::structure::rotation::*;

/// Result of the check for one element.
#[derive(Clone, Debug)]
pub struct TangentCheck {
    pub element: String,
    /// max |K_ad - K_fd| / max(1, max |K_fd|), over configuration, velocity and acceleration.
    pub rel_error: f64,
}

#[derive(Clone, Copy)]
enum Var {
    Config,
    Vel,
    Acc,
}

fn perturb(k: &NodeKin<f64>, comp: usize, h: f64, var: Var) -> NodeKin<f64> {
    let mut k = *k;
    let mut e = [0.0; 3];
    e[comp % 3] = h;
    match (var, comp < 3) {
        (Var::Config, true) => k.x = add(k.x, e),
        (Var::Config, false) => k.r = mm(&exp_map(e), &k.r),
        (Var::Vel, true) => k.v = add(k.v, e),
        (Var::Vel, false) => k.w = add(k.w, e),
        (Var::Acc, true) => k.a = add(k.a, e),
        (Var::Acc, false) => k.al = add(k.al, e),
    }
    k
}

fn lift_seed(k: &NodeKin<f64>, comp: Option<(usize, Var)>) -> NodeKin<Dual<f64>> {
    let d = |v: &[f64; 3], e: &[f64; 3]| -> [Dual<f64>; 3] {
        std::array::from_fn(|i| Dual::new(v[i], e[i]))
    };
    let z = [0.0; 3];
    let mut e = [0.0; 3];
    let (mut dx, mut dth, mut dv, mut dw, mut da, mut dal) = (z, z, z, z, z, z);
    if let Some((c, var)) = comp {
        e[c % 3] = 1.0;
        match (var, c < 3) {
            (Var::Config, true) => dx = e,
            (Var::Config, false) => dth = e,
            (Var::Vel, true) => dv = e,
            (Var::Vel, false) => dw = e,
            (Var::Acc, true) => da = e,
            (Var::Acc, false) => dal = e,
        }
    }
    let dr = mm(&skew(dth), &k.r);
    NodeKin {
        x: d(&k.x, &dx),
        r: std::array::from_fn(|i| d(&k.r[i], &dr[i])),
        v: d(&k.v, &dv),
        w: d(&k.w, &dw),
        a: d(&k.a, &da),
        al: d(&k.al, &dal),
    }
}

/// Check one element at the given node kinematics and multipliers.
pub fn check_element(e: &Element, kin: &[NodeKin<f64>], lam: &[f64], ctx: &EvalCtx) -> f64 {
    let nnodes = kin.len();
    let n = 6 * nnodes + lam.len();
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    let mut scale: f64 = 0.0;
    let mut errs = vec![];
    for var in [Var::Config, Var::Vel, Var::Acc] {
        for b in 0..n {
            let mut rp = [0.0; MAXL];
            let mut rm = [0.0; MAXL];
            let mut ad = [Dual::new(0.0, 0.0); MAXL];
            let mut kd: Vec<NodeKin<Dual<f64>>> = kin.iter().map(|k| lift_seed(k, None)).collect();
            let mut ld: Vec<Dual<f64>> = lam.iter().map(|&l| Dual::new(l, 0.0)).collect();
            if b < 6 * nnodes {
                let (l, comp) = (b / 6, b % 6);
                let mut kp = kin.to_vec();
                let mut km = kin.to_vec();
                kp[l] = perturb(&kin[l], comp, h, var);
                km[l] = perturb(&kin[l], comp, -h, var);
                element_residual(e, &kp, lam, ctx, &mut rp[..n]);
                element_residual(e, &km, lam, ctx, &mut rm[..n]);
                kd[l] = lift_seed(&kin[l], Some((comp, var)));
            } else {
                if !matches!(var, Var::Config) {
                    continue;
                }
                let l = b - 6 * nnodes;
                let mut lp = lam.to_vec();
                let mut lm = lam.to_vec();
                lp[l] += h;
                lm[l] -= h;
                element_residual(e, kin, &lp, ctx, &mut rp[..n]);
                element_residual(e, kin, &lm, ctx, &mut rm[..n]);
                ld[l].d = 1.0;
            }
            element_residual(e, &kd, &ld, ctx, &mut ad[..n]);
            for a in 0..n {
                let fd = (rp[a] - rm[a]) / (2.0 * h);
                scale = scale.max(fd.abs()).max(ad[a].d.abs());
                errs.push((ad[a].d - fd).abs());
            }
        }
    }
    for e in errs {
        worst = worst.max(e);
    }
    worst / scale.max(1.0)
}

/// Check every built-in element of a model at state `kin` (all nodes) with multipliers `lam`.
pub fn check_model(
    model: &Model,
    kin: &[NodeKin<f64>],
    lam: &[f64],
    ctx: &EvalCtx,
) -> Vec<TangentCheck> {
    let offs = super::state::lambda_offsets(model);
    model
        .elements
        .iter()
        .enumerate()
        .map(|(i, e)| {
            let k: Vec<NodeKin<f64>> = e.node_list().iter().map(|&n| kin[n]).collect();
            let l = &lam[offs[i]..offs[i] + e.n_lambda()];
            TangentCheck {
                element: e.name().to_string(),
                rel_error: check_element(e, &k, l, ctx),
            }
        })
        .collect()
}
