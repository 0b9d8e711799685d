//! Modal analysis linearised about a static or steadily rotating equilibrium (rotating frame).
//!
//! Linearisation by the same dual-number seeding as the solvers: `K` (configuration, with the
//! rigid-rotation velocities following it: centrifugal and geometric stiffening), `G`
//! (relative velocities: Coriolis/gyroscopic + damping), `M` (relative accelerations) and the
//! constraint gradient `B`. Constraints are eliminated with a null-space basis `N` of `B`
//! (`B N = 0`), and the first-order problem `[0 I; -M^-1 K, -M^-1 G]` is solved with faer's dense
//! eigen solver.
use super::assembly::Assembler;
use super::state::State;
use super::statics::rotating_kin;
use crate::structure::kin::{EvalCtx, NodeKin, Seed};
use crate::structure::model::Model;
use crate::structure::rotation::*;
use nalgebra::DMatrix;
use thiserror::Error;

#[derive(Debug, Error)]
pub enum ModalError {
    #[error("modal analysis: {0}")]
    Failed(String),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModeKind {
    Flap,
    Lag,
    Torsion,
    Axial,
}

impl ModeKind {
    pub fn as_str(&self) -> &'static str {
        match self {
            ModeKind::Flap => "flap",
            ModeKind::Lag => "lag",
            ModeKind::Torsion => "torsion",
            ModeKind::Axial => "axial",
        }
    }
}

#[derive(Clone, Debug)]
pub struct Mode {
    /// Damped natural frequency |s| / 2 pi [Hz] and |s| [rad/s].
    pub freq_hz: f64,
    pub omega_rad_s: f64,
    pub damping_ratio: f64,
    pub kind: ModeKind,
    /// Mass-weighted fractions (flap, lag, torsion, axial), section frames.
    pub fractions: [f64; 4],
    /// Real mode shape per node (translation, rotation), global, max component 1.
    pub shape: Vec<[f64; 6]>,
}

#[derive(Clone, Debug, Default)]
pub struct ModalOptions {
    pub n_modes: usize,
    /// Steady rotation (rad/s) about the origin; `None` = non-rotating.
    pub omega: Option<[f64; 3]>,
    /// Real spectral shift sigma [1/s] of the shift-invert form (0: none, the form about s = 0).
    /// A model with a free rigid-body rotation (a hinge without spring at rest) has a singular
    /// `K`; about `s = sigma > 0` the form is regular: `K + sigma G + sigma^2 M` replaces `K`,
    /// `G + 2 sigma M` replaces `G`, and `s = sigma + mu`.
    pub shift_rad_s: f64,
}

fn dense_block(asm: &Assembler, n: usize, rows: std::ops::Range<usize>) -> DMatrix<f64> {
    let d = asm.to_dense();
    let r0 = rows.start;
    DMatrix::from_fn(rows.len(), n, |i, j| d[r0 + i][j])
}

/// The linearised matrices about a state: `K`, `G`, `M` (displacement rows) and the
/// constraint gradient `B`, with the node kinematics they were taken at.
struct Linearised {
    k: DMatrix<f64>,
    g: DMatrix<f64>,
    m: DMatrix<f64>,
    b: DMatrix<f64>,
    kin: Vec<NodeKin<f64>>,
}

/// Compute modes at the (equilibrium) state `st`.
pub fn modes(model: &mut Model, st: &State, opts: &ModalOptions) -> Result<Vec<Mode>, ModalError> {
    let lin = linearise(model, st, opts)?;
    let nn = 6 * model.nodes.len();
    let nsp = null_space(&lin.b, nn)?;
    let kr = nsp.transpose() * &lin.k * &nsp;
    let gr = nsp.transpose() * &lin.g * &nsp;
    let mr = nsp.transpose() * &lin.m * &nsp;
    let (s, u) = eigen_first_order(&kr, &gr, &mr, opts.shift_rad_s)?;
    let mut idx: Vec<usize> = (0..s.len())
        .filter(|&i| s[i].im > 1e-9 * (1.0 + s[i].re.abs()))
        .collect();
    idx.sort_by(|&x, &y| s[x].norm().partial_cmp(&s[y].norm()).unwrap());
    let rots: Vec<[[f64; 3]; 3]> = lin.kin.iter().map(|k| k.r).collect();
    Ok(idx
        .iter()
        .take(opts.n_modes)
        .map(|&i| mode_at(s[i], u.col(i), &nsp, &lin.m, &rots))
        .collect())
}

fn linearise(model: &mut Model, st: &State, opts: &ModalOptions) -> Result<Linearised, ModalError> {
    let fail = |e: String| ModalError::Failed(e);
    let mut asm = Assembler::new(model).map_err(|e| fail(e.to_string()))?;
    let om = opts.omega.unwrap_or([0.0; 3]);
    let nn = 6 * model.nodes.len();
    let ndof = asm.ndof;
    let mut kin: Vec<NodeKin<f64>> = vec![];
    if opts.omega.is_some() {
        rotating_kin(st, om, &mut kin);
    } else {
        st.kin(&mut kin);
    }
    let ctx = EvalCtx {
        t: st.t,
        load_factor: 1.0,
        gravity: model.gravity,
        cscale: 1.0,
        inertia: true,
        dt: 0.0,
    };
    let lam = st.lambda.clone();
    let mut res = vec![0.0; ndof];
    model.update_distributed_loads(st.t, &kin);
    let mut run =
        |seed: &dyn Fn(usize, usize) -> Seed| -> Result<(DMatrix<f64>, DMatrix<f64>), ModalError> {
            asm.assemble(
                model,
                &kin,
                &lam,
                &ctx,
                seed,
                Some((st.t, 0.0, &st.x)),
                true,
                &mut res,
            )
            .map_err(|e| fail(e.to_string()))?;
            let full = dense_block(&asm, ndof, 0..ndof);
            let a = full.view((0, 0), (nn, nn)).into_owned();
            let b = full.view((nn, 0), (ndof - nn, nn)).into_owned();
            Ok((a, b))
        };
    let e = |c: usize| {
        let mut e = [0.0; 3];
        e[c % 3] = 1.0;
        e
    };
    let (k, b) = run(&|_, c| {
        if c < 3 {
            Seed {
                dx: e(c),
                dv: cross(om, e(c)),
                da: cross(om, cross(om, e(c))),
                ..Default::default()
            }
        } else {
            Seed {
                dth: e(c),
                ..Default::default()
            }
        }
    })?;
    let (g, _) = run(&|_, c| {
        if c < 3 {
            Seed {
                dv: e(c),
                da: fmul(2.0, cross(om, e(c))),
                ..Default::default()
            }
        } else {
            Seed {
                dw: e(c),
                dal: cross(om, e(c)),
                ..Default::default()
            }
        }
    })?;
    let (m, _) = run(&|_, c| {
        if c < 3 {
            Seed {
                da: e(c),
                ..Default::default()
            }
        } else {
            Seed {
                dal: e(c),
                ..Default::default()
            }
        }
    })?;
    Ok(Linearised { k, g, m, b, kin })
}

/// A basis of the null space of `B` (`nn` columns of displacement).
fn null_space(b: &DMatrix<f64>, nn: usize) -> Result<DMatrix<f64>, ModalError> {
    let fail = |e: String| ModalError::Failed(e);
    if b.nrows() == 0 {
        return Ok(DMatrix::identity(nn, nn));
    }
    // Right singular vectors of B padded to a square matrix: the columns with zero singular
    // value span the null space (eigen solvers of B^T B failed to converge on the rotor
    // model's 480-dof B^T B, which has many exactly-zero rows).
    let mut bp = DMatrix::<f64>::zeros(nn.max(b.nrows()), nn);
    bp.view_mut((0, 0), (b.nrows(), nn)).copy_from(b);
    let svd = bp.svd(false, true);
    let vt = svd
        .v_t
        .ok_or_else(|| fail("SVD of the constraint gradient failed".into()))?;
    let sv = &svd.singular_values;
    let mx = sv.iter().cloned().fold(0.0, f64::max);
    let evals: Vec<f64> = sv.iter().map(|v| v * v).collect();
    let mx = mx * mx;
    let cols: Vec<usize> = (0..nn).filter(|&i| evals[i] <= 1e-10 * mx).collect();
    if nn - cols.len() != b.nrows() {
        return Err(fail(format!(
            "constraint gradient has rank {} for {} constraints (redundant or singular constraint set)",
            nn - cols.len(),
            b.nrows()
        )));
    }
    Ok(DMatrix::from_fn(nn, cols.len(), |i, j| vt[(cols[j], i)]))
}

/// Eigenvalues `s` and eigenvectors of the reduced first-order problem.
fn eigen_first_order(
    kr: &DMatrix<f64>,
    gr: &DMatrix<f64>,
    mr: &DMatrix<f64>,
    sig: f64,
) -> Result<(Vec<faer::c64>, faer::Mat<faer::c64>), ModalError> {
    let fail = |e: String| ModalError::Failed(e);
    let nr = kr.nrows();
    // Shift-invert form when K is regular: eigenvalues 1/s of
    // A^-1 = [-K^-1 G, -K^-1 M; I, 0] resolve the lowest modes to full relative precision even
    // with very stiff axial/shear modes; otherwise the direct form [0 I; -M^-1 K, -M^-1 G].
    let (kr_s, gr_s) = if sig != 0.0 {
        (kr + gr * sig + mr * (sig * sig), gr + mr * (2.0 * sig))
    } else {
        (kr.clone(), gr.clone())
    };
    let klu = kr_s.clone().lu();
    let kinv = klu
        .solve(&DMatrix::<f64>::identity(nr, nr))
        .filter(|ki| ki.iter().all(|v| v.is_finite()));
    let mut a = faer::Mat::<f64>::zeros(2 * nr, 2 * nr);
    let inverted = kinv.is_some();
    if let Some(ki) = kinv {
        let kig = &ki * &gr_s;
        let kim = &ki * mr;
        for i in 0..nr {
            a[(nr + i, i)] = 1.0;
            for j in 0..nr {
                a[(i, j)] = -kig[(i, j)];
                a[(i, nr + j)] = -kim[(i, j)];
            }
        }
    } else {
        let mlu = mr.clone().lu();
        let mik = mlu
            .solve(kr)
            .ok_or_else(|| fail("singular reduced mass matrix".into()))?;
        let mig = mlu
            .solve(gr)
            .ok_or_else(|| fail("singular reduced mass matrix".into()))?;
        for i in 0..nr {
            a[(i, nr + i)] = 1.0;
            for j in 0..nr {
                a[(nr + i, j)] = -mik[(i, j)];
                a[(nr + i, nr + j)] = -mig[(i, j)];
            }
        }
    }
    let eig = a
        .eigen()
        .map_err(|e| fail(format!("eigen solver: {e:?}")))?;
    let s_raw = eig.S();
    let s: Vec<faer::c64> = (0..2 * nr)
        .map(|i| {
            let z = s_raw[i];
            if inverted {
                if z.norm() == 0.0 {
                    faer::c64::new(f64::INFINITY, 0.0)
                } else {
                    z.conj() / (z.norm() * z.norm()) + faer::c64::new(sig, 0.0)
                }
            } else {
                z
            }
        })
        .collect();
    Ok((s, eig.U().to_owned()))
}

/// The mode of eigenvalue `sv` and reduced eigenvector `u`: its real shape (phase-normalised
/// displacement) and its mass-weighted flap/lag/torsion/axial fractions.
fn mode_at(
    sv: faer::c64,
    u: faer::ColRef<'_, faer::c64>,
    nsp: &DMatrix<f64>,
    m: &DMatrix<f64>,
    rots: &[[[f64; 3]; 3]],
) -> Mode {
    let (nn, nr) = (nsp.nrows(), nsp.ncols());
    let wabs = sv.norm();
    // displacement part, phase-normalised
    let mut full = vec![faer::c64::new(0.0, 0.0); nn];
    for r in 0..nn {
        let mut acc = faer::c64::new(0.0, 0.0);
        for j in 0..nr {
            acc += u[j] * nsp[(r, j)];
        }
        full[r] = acc;
    }
    let (imax, _) =
        full.iter().enumerate().fold(
            (0, 0.0),
            |b, (k, z)| if z.norm() > b.1 { (k, z.norm()) } else { b },
        );
    let ph = full[imax].conj() / full[imax].norm();
    let re: Vec<f64> = full
        .iter()
        .map(|z| (*z * ph).re / full[imax].norm())
        .collect();
    let mut fr = [0.0; 4];
    let mut shape = vec![[0.0; 6]; rots.len()];
    for (nd, r) in rots.iter().enumerate() {
        let t = [re[6 * nd], re[6 * nd + 1], re[6 * nd + 2]];
        let th = [re[6 * nd + 3], re[6 * nd + 4], re[6 * nd + 5]];
        shape[nd] = [t[0], t[1], t[2], th[0], th[1], th[2]];
        let tl = mtv(r, t);
        let rl = mtv(r, th);
        let mt = m[(6 * nd, 6 * nd)];
        let mr3: [f64; 3] = std::array::from_fn(|k| rots_inertia(m, r, nd, k));
        fr[0] += mt * tl[2] * tl[2] + mr3[1] * rl[1] * rl[1];
        fr[1] += mt * tl[1] * tl[1] + mr3[2] * rl[2] * rl[2];
        fr[2] += mr3[0] * rl[0] * rl[0];
        fr[3] += mt * tl[0] * tl[0];
    }
    let tot: f64 = fr.iter().sum::<f64>().max(1e-300);
    let fr = fr.map(|v| v / tot);
    let kinds = [
        ModeKind::Flap,
        ModeKind::Lag,
        ModeKind::Torsion,
        ModeKind::Axial,
    ];
    let (kmax, _) = fr
        .iter()
        .enumerate()
        .fold((0, -1.0), |b, (k, &v)| if v > b.1 { (k, v) } else { b });
    Mode {
        freq_hz: wabs / (2.0 * std::f64::consts::PI),
        omega_rad_s: wabs,
        damping_ratio: -sv.re / wabs,
        kind: kinds[kmax],
        fractions: fr,
        shape,
    }
}

/// Mass-matrix diagonal of rotation about section axis k of node nd (e_k^T R^T M_rr R e_k).
fn rots_inertia(m: &DMatrix<f64>, r: &[[f64; 3]; 3], nd: usize, k: usize) -> f64 {
    let ax = [r[0][k], r[1][k], r[2][k]];
    let mut s = 0.0;
    for i in 0..3 {
        for j in 0..3 {
            s += ax[i] * m[(6 * nd + 3 + i, 6 * nd + 3 + j)] * ax[j];
        }
    }
    s
}
