//! Global assembly: dof numbering, sparse pattern (built once), residual and tangent by seeded
//! dual numbers, sparse LU (faer) with the symbolic factorisation done once.
use super::bordered::{BorderedError, BorderedLu, Partition};
use crate::structure::joint::Joint;
use crate::structure::kin::{EvalCtx, NodeKin, Seed};
use crate::structure::model::{Element, ElementError, ElementOutput, Model};
use crate::structure::real::{c, Dual, DualN, Real};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuSymbolicParams, NumericLu, SymbolicLu};
use faer::sparse::linalg::{LuError, SupernodalThreshold};
use faer::sparse::{FaerError, SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};
use thiserror::Error;

/// Largest number of local dofs of a built-in element (beam: 4 nodes x 6).
pub const MAXL: usize = 24;

#[derive(Debug, Error)]
pub enum LinearError {
    #[error("sparse LU factorisation failed (singular iteration matrix: check for redundant or conflicting constraints, unconstrained rigid-body motion, or zero mass with free dofs): {0}")]
    Singular(String),
    #[error("sparse LU of {ndof} unknowns: out of memory (the model is too large for this machine: use fewer or longer elements)")]
    OutOfMemory { ndof: usize },
}

impl LinearError {
    pub(crate) fn of_faer(e: FaerError, ndof: usize) -> Self {
        match e {
            FaerError::OutOfMemory | FaerError::IndexOverflow => LinearError::OutOfMemory { ndof },
            other => LinearError::Singular(format!("{other:?}")),
        }
    }

    pub(crate) fn of_lu(e: LuError, ndof: usize) -> Self {
        match e {
            LuError::Generic(g) => Self::of_faer(g, ndof),
            other => LinearError::Singular(format!("{other:?}")),
        }
    }
}

/// Dof layout: node n has dofs 6n..6n+6 (translation, rotation); multipliers follow.
pub struct Assembler {
    pub n_nodes: usize,
    pub ndof: usize,
    /// Global dofs of each element (local order).
    pub elem_dofs: Vec<Vec<usize>>,
    /// First multiplier dof of each element.
    pub lam_start: Vec<usize>,
    elem_pos: Vec<Vec<usize>>,
    step_pos: Vec<Vec<usize>>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    pub values: Vec<f64>,
    lu: Lu,
    factored: bool,
    step_out: ElementOutput,
    /// Beam tangents from one 24-lane dual evaluation (true) or 24 single-lane ones (false);
    /// both give the same exact derivatives.
    pub multilane: bool,
    /// Joint residuals and tangents by nested duals (true) instead of the closed form (false).
    pub joint_tangent_dual: bool,
    /// With `multilane`: beam tangents from the 24-lane dual evaluation (true) or from the
    /// closed form [`Beam::tangent`](crate::structure::Beam::tangent) (false, default).
    pub beam_tangent_dual: bool,
}

/// The factorization of the assembled matrix: one sparse LU, or the bordered LU of blocks that
/// the model's border nodes separate (factored independently, in parallel).
// One per assembler, never moved in a loop: the variants' sizes do not matter.
#[allow(clippy::large_enum_variant)]
enum Lu {
    Single {
        symbolic: SymbolicLu<usize>,
        numeric: NumericLu<usize, f64>,
        buf: MemBuffer,
    },
    Bordered(Box<BorderedLu>),
}

/// The blocks of the pattern that the unknowns of `border_nodes` separate: the connected
/// components of the pattern without them. A component without node unknowns (the multipliers
/// of a joint between border nodes) joins the border. `None` unless there are two blocks.
fn border_partition(
    n_nodes: usize,
    border_nodes: &[usize],
    col_ptr: &[usize],
    row_idx: &[usize],
) -> Option<Partition> {
    let ndof = col_ptr.len() - 1;
    let mut border = vec![false; ndof];
    for &n in border_nodes.iter().filter(|&&n| n < n_nodes) {
        border[6 * n..6 * n + 6].fill(true);
    }
    // union-find over the unknowns off the border
    let mut parent: Vec<usize> = (0..ndof).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for j in (0..ndof).filter(|&j| !border[j]) {
        for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
            if !border[i] {
                let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                parent[a.max(b)] = a.min(b);
            }
        }
    }
    let mut block_of = vec![usize::MAX; ndof];
    let mut blocks: Vec<Vec<usize>> = vec![];
    for d in (0..ndof).filter(|&d| !border[d]) {
        let r = root(&mut parent, d);
        if block_of[r] == usize::MAX {
            block_of[r] = blocks.len();
            blocks.push(vec![]);
        }
        blocks[block_of[r]].push(d);
    }
    let nl6 = 6 * n_nodes;
    let (blocks, lone): (Vec<_>, Vec<_>) = blocks.into_iter().partition(|b| b[0] < nl6);
    let mut border: Vec<usize> = (0..ndof).filter(|&d| border[d]).collect();
    border.extend(lone.into_iter().flatten());
    border.sort_unstable();
    (blocks.len() >= 2).then_some(Partition { blocks, border })
}

/// Residual of one built-in element in scalar `T`; `k` holds the element's nodes in order.
pub fn element_residual<T: Real>(
    e: &Element,
    k: &[NodeKin<T>],
    lam: &[T],
    ctx: &EvalCtx,
    out: &mut [T],
) {
    match e {
        Element::Beam(b) => {
            let kk = [k[0], k[1], k[2], k[3]];
            b.residual(&kk, ctx, out)
        }
        Element::Rigid(b) => b.residual(&k[0], ctx, out),
        Element::Load(l) => l.residual(&k[0], ctx, out),
        Element::Joint(j) => {
            if j.node_a.is_some() {
                j.residual(&k[0], &k[1], lam, ctx, out)
            } else {
                j.residual(&NodeKin::ground(), &k[0], lam, ctx, out)
            }
        }
    }
}

/// Closed-form joint residual and (if `mat`) tangent block, scattered into `res` and `values`
/// at `pos`.
#[allow(clippy::too_many_arguments)]
fn assemble_joint(
    j: &Joint,
    k: &[NodeKin<f64>],
    lam: &[f64],
    ctx: &EvalCtx,
    seed: &dyn Fn(usize, usize) -> Seed,
    dofs: &[usize],
    res: &mut [f64],
    mat: Option<(&mut [f64], &[usize])>,
) {
    let (a, b) = match j.node_a {
        Some(_) => (k[0], k[1]),
        None => (NodeKin::ground(), k[0]),
    };
    let n = dofs.len();
    let mut r = [0.0; 18];
    j.residual_f64(&a, &b, lam, ctx, &mut r[..n]);
    for (&d, &v) in dofs.iter().zip(&r[..n]) {
        res[d] += v;
    }
    if let Some((values, pos)) = mat {
        let mut seeds = [[Seed::default(); 6]; 2];
        for (l, sl) in seeds.iter_mut().enumerate().take(k.len()) {
            for (c, s) in sl.iter_mut().enumerate() {
                *s = seed(dofs[6 * l] / 6, c);
            }
        }
        let mut t = [0.0; 18 * 18];
        j.tangent(&a, &b, lam, ctx, &seeds[..k.len()], &mut t[..n * n]);
        for (&p, &v) in pos.iter().zip(&t[..n * n]) {
            values[p] += v;
        }
    }
}

impl Assembler {
    pub fn new(model: &Model) -> Result<Self, LinearError> {
        let n_nodes = model.nodes.len();
        let mut next = 6 * n_nodes;
        let mut elem_dofs = vec![];
        let mut lam_start = vec![];
        for e in &model.elements {
            let mut d: Vec<usize> = e
                .node_list()
                .iter()
                .flat_map(|&n| 6 * n..6 * n + 6)
                .collect();
            lam_start.push(next);
            for _ in 0..e.n_lambda() {
                d.push(next);
                next += 1;
            }
            elem_dofs.push(d);
        }
        let ndof = next;
        let step_dofs: Vec<Vec<usize>> = model
            .step_elements
            .iter()
            .map(|s| s.nodes().iter().flat_map(|&n| 6 * n..6 * n + 3).collect())
            .collect();
        // pattern: dense element blocks + diagonal
        let mut cols: Vec<Vec<usize>> = (0..ndof).map(|i| vec![i]).collect();
        for d in elem_dofs.iter().chain(step_dofs.iter()) {
            for &j in d {
                cols[j].extend(d.iter().copied());
            }
        }
        let mut col_ptr = vec![0usize];
        let mut row_idx = vec![];
        for cl in cols.iter_mut() {
            cl.sort_unstable();
            cl.dedup();
            row_idx.extend(cl.iter().copied());
            col_ptr.push(row_idx.len());
        }
        let pos = |i: usize, j: usize| -> usize {
            let s = &row_idx[col_ptr[j]..col_ptr[j + 1]];
            col_ptr[j] + s.binary_search(&i).expect("pattern entry")
        };
        let block = |d: &Vec<usize>| -> Vec<usize> {
            let n = d.len();
            let mut p = vec![0; n * n];
            for (a, &i) in d.iter().enumerate() {
                for (b, &j) in d.iter().enumerate() {
                    p[a * n + b] = pos(i, j);
                }
            }
            p
        };
        let elem_pos = elem_dofs.iter().map(block).collect();
        let step_pos = step_dofs.iter().map(block).collect();
        let lu = match border_partition(n_nodes, &model.border_nodes, &col_ptr, &row_idx) {
            Some(part) => {
                let mut b =
                    BorderedLu::new(ndof, &col_ptr, &row_idx, &part).map_err(|e| match e {
                        BorderedError::Linear(l) => l,
                        // the blocks are the pattern's components: they cannot couple
                        BorderedError::Partition(p) => unreachable!("derived partition: {p}"),
                    })?;
                // Blocks factored in parallel, but not inside a pool: a sweep's cases already
                // fill the cores, and a join there may run a whole other case first. Solves
                // one block after the other: rayon's queue allocates on a hand-off now and
                // then, and a block's solve gained nothing from one (docs/performance.md).
                b.parallel = rayon::current_thread_index().is_none();
                b.parallel_solve = false;
                Lu::Bordered(Box::new(b))
            }
            None => Self::single_lu(ndof, &col_ptr, &row_idx)?,
        };
        let nnz = row_idx.len();
        Ok(Assembler {
            n_nodes,
            ndof,
            elem_dofs,
            lam_start,
            elem_pos,
            step_pos,
            col_ptr,
            row_idx,
            values: vec![0.0; nnz],
            lu,
            factored: false,
            step_out: ElementOutput::default(),
            multilane: true,
            joint_tangent_dual: false,
            beam_tangent_dual: false,
        })
    }

    /// The symbolic analysis of one sparse LU of the whole pattern.
    fn single_lu(ndof: usize, col_ptr: &[usize], row_idx: &[usize]) -> Result<Lu, LinearError> {
        let sym = SymbolicSparseColMatRef::new_checked(ndof, ndof, col_ptr, None, row_idx);
        // Fill-reducing column ordering (COLAMD) once, here; supernodal numeric factorization:
        // on the rotor's banded pattern (half-bandwidth ~57) its dense kernels beat the
        // simplicial left-looking LU faer picks by its flop heuristic (docs/performance.md).
        let params = LuSymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let symbolic =
            factorize_symbolic_lu(sym, params).map_err(|e| LinearError::of_faer(e, ndof))?;
        let req = symbolic
            .factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default())
            .or(symbolic.solve_in_place_scratch::<f64>(1, Par::Seq));
        let buf = MemBuffer::try_new(req).map_err(|_| LinearError::OutOfMemory { ndof })?;
        Ok(Lu::Single {
            symbolic,
            numeric: NumericLu::new(),
            buf,
        })
    }

    /// The number of blocks of the bordered LU (0: one LU of the whole matrix).
    pub fn bordered_blocks(&self) -> usize {
        match &self.lu {
            Lu::Single { .. } => 0,
            Lu::Bordered(b) => b.blocks(),
        }
    }

    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Diagonal entry (after assembly).
    pub fn diag(&self, i: usize) -> f64 {
        let s = &self.row_idx[self.col_ptr[i]..self.col_ptr[i + 1]];
        self.values[self.col_ptr[i] + s.binary_search(&i).unwrap()]
    }

    /// Replace the entries of rows `>= first_row` by those of `other` (same pattern).
    pub fn overwrite_rows_from(&mut self, other: &[f64], first_row: usize) {
        for (p, &r) in self.row_idx.iter().enumerate() {
            if r >= first_row {
                self.values[p] = other[p];
            }
        }
    }

    /// Rows `rows` of the assembled matrix, dense over columns `0..ncols` (the constraint
    /// gradient without forming the whole matrix).
    pub fn dense_rows(&self, rows: std::ops::Range<usize>, ncols: usize) -> Vec<Vec<f64>> {
        let mut m = vec![vec![0.0; ncols]; rows.len()];
        for j in 0..ncols.min(self.ndof) {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                let r = self.row_idx[p];
                if rows.contains(&r) {
                    m[r - rows.start][j] += self.values[p];
                }
            }
        }
        m
    }

    /// Dense copy of the assembled matrix (tests, modal analysis).
    pub fn to_dense(&self) -> Vec<Vec<f64>> {
        let mut m = vec![vec![0.0; self.ndof]; self.ndof];
        for j in 0..self.ndof {
            for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                m[self.row_idx[p]][j] += self.values[p];
            }
        }
        m
    }

    /// Assemble residual `res` (all dofs) and, if `matrix`, the matrix whose column for node dof
    /// (n, comp) is the derivative of the residual along `seed(n, comp)` and for a multiplier is
    /// the derivative w.r.t. `lambda_hat`. `lam_hat` holds scaled multipliers (all multiplier
    /// dofs, indexed from 0). Step elements get `(t_i, dt, x_i)` and contribute `-force`.
    #[allow(clippy::too_many_arguments)]
    pub fn assemble(
        &mut self,
        model: &mut Model,
        kin: &[NodeKin<f64>],
        lam_hat: &[f64],
        ctx: &EvalCtx,
        seed: &dyn Fn(usize, usize) -> Seed,
        step: Option<(f64, f64, &[[f64; 3]])>,
        matrix: bool,
        res: &mut [f64],
    ) -> Result<(), ElementError> {
        res.iter_mut().for_each(|r| *r = 0.0);
        if matrix {
            self.values.iter_mut().for_each(|v| *v = 0.0);
        }
        let nl6 = 6 * self.n_nodes;
        let mut kf = [NodeKin::<f64>::ground(); 4];
        let mut kd = [NodeKin::<Dual<f64>>::ground(); 4];
        let mut lam_f = [0.0f64; 6];
        let mut lam_d = [Dual::<f64>::cst(0.0); 6];
        let mut out_f = [0.0f64; MAXL];
        let mut out_d = [Dual::<f64>::cst(0.0); MAXL];
        for (ei, e) in model.elements.iter().enumerate() {
            let dofs = &self.elem_dofs[ei];
            let n = dofs.len();
            let nnodes = match e {
                Element::Beam(_) => 4,
                Element::Joint(j) => 1 + j.node_a.is_some() as usize,
                _ => 1,
            };
            for l in 0..nnodes {
                kf[l] = kin[dofs[6 * l] / 6];
            }
            let nlam = n - 6 * nnodes;
            for l in 0..nlam {
                lam_f[l] = lam_hat[dofs[6 * nnodes + l] - nl6];
            }
            if let (Element::Joint(j), false) = (e, self.joint_tangent_dual) {
                let out = matrix.then_some((&mut self.values[..], &self.elem_pos[ei][..]));
                assemble_joint(j, &kf[..nnodes], &lam_f[..nlam], ctx, seed, dofs, res, out);
                continue;
            }
            out_f[..n].iter_mut().for_each(|x| *x = 0.0);
            match e {
                Element::Beam(b) => {
                    let kk = [kf[0], kf[1], kf[2], kf[3]];
                    b.residual_f64(&kk, ctx, &mut out_f[..n])
                }
                _ => element_residual(e, &kf[..nnodes], &lam_f[..nlam], ctx, &mut out_f[..n]),
            }
            for a in 0..n {
                res[dofs[a]] += out_f[a];
            }
            if !matrix {
                continue;
            }
            let pos = &self.elem_pos[ei];
            if let (Element::Beam(bm), true, false) = (e, self.multilane, self.beam_tangent_dual) {
                // all 24 columns in closed form
                let kk = [kf[0], kf[1], kf[2], kf[3]];
                // filled in place: built through nested `from_fn` the 3 kB array is copied
                let mut seeds = [[Seed::default(); 6]; 4];
                for (l, sl) in seeds.iter_mut().enumerate() {
                    for (c, s) in sl.iter_mut().enumerate() {
                        *s = seed(dofs[6 * l] / 6, c);
                    }
                }
                let mut t = [0.0; 576];
                bm.tangent(&kk, ctx, &seeds, &mut t);
                for (p, v) in pos.iter().zip(t.iter()) {
                    self.values[*p] += v;
                }
                continue;
            }
            if let (Element::Beam(bm), true) = (e, self.multilane) {
                // all 24 columns from one multi-lane evaluation
                let mut k24 = [NodeKin::<DualN<24>>::ground(); 4];
                for l in 0..4 {
                    k24[l] =
                        kf[l].seeded_lanes(l, &std::array::from_fn(|c| seed(dofs[6 * l] / 6, c)));
                }
                let mut o24 = [DualN::<24>::default(); 24];
                bm.residual(&k24, ctx, &mut o24);
                for a in 0..24 {
                    for b in 0..24 {
                        self.values[pos[a * 24 + b]] += o24[a].d[b];
                    }
                }
                continue;
            }
            for l in 0..nnodes {
                kd[l] = kf[l].seeded(None);
            }
            for l in 0..nlam {
                lam_d[l] = Dual::new(lam_f[l], 0.0);
            }
            for b in 0..n {
                if b < 6 * nnodes {
                    let (l, comp) = (b / 6, b % 6);
                    let s = seed(dofs[6 * l] / 6, comp);
                    kd[l] = kf[l].seeded(Some(&s));
                    out_d[..n].iter_mut().for_each(|x| *x = Dual::cst(0.0));
                    element_residual(e, &kd[..nnodes], &lam_d[..nlam], ctx, &mut out_d[..n]);
                    kd[l] = kf[l].seeded(None);
                } else {
                    let l = b - 6 * nnodes;
                    lam_d[l].d = 1.0;
                    out_d[..n].iter_mut().for_each(|x| *x = Dual::cst(0.0));
                    element_residual(e, &kd[..nnodes], &lam_d[..nlam], ctx, &mut out_d[..n]);
                    lam_d[l].d = 0.0;
                }
                for a in 0..n {
                    self.values[pos[a * n + b]] += out_d[a].d;
                }
            }
        }
        if let Some((t_i, dt, x_i)) = step {
            for (si, s) in model.step_elements.iter_mut().enumerate() {
                let nd = s.nodes();
                let xi = [x_i[nd[0]], x_i[nd[1]]];
                let xf = [kin[nd[0]].x, kin[nd[1]].x];
                self.step_out = ElementOutput::default();
                s.want_jacobian(matrix);
                s.evaluate(t_i, dt, xi, xf, &mut self.step_out)?;
                for k in 0..2 {
                    for i in 0..3 {
                        res[6 * nd[k] + i] -= self.step_out.force[k][i];
                    }
                }
                if matrix {
                    let pos = &self.step_pos[si];
                    for k in 0..2 {
                        for l in 0..2 {
                            for j in 0..3 {
                                let sd = seed(nd[l], j).dx;
                                for i in 0..3 {
                                    let d: f64 =
                                        (0..3).map(|m| self.step_out.jac[k][l][i][m] * sd[m]).sum();
                                    self.values[pos[(3 * k + i) * 6 + 3 * l + j]] -= d;
                                }
                            }
                        }
                    }
                }
            }
        }
        let _ = c::<f64>(0.0);
        Ok(())
    }

    /// The model's force scale at `kin` (Newton's convergence floor, `NewtonOptions::floor`):
    /// the norm over the node dofs of the sum of the magnitudes of what every element adds to
    /// the residual, `|| sum_e |r_e| ||`: loads, gravity, inertia at the motion of `kin` (e.g.
    /// centrifugal), internal forces, and each step element's [`force_scale`] along its line.
    /// The residual is a sum of these, so its round-off is relative to this sum, not to the
    /// residual itself (which is ~0 for a model starting in equilibrium). Joints are left out:
    /// their reactions balance the rest. `res` is scratch (`ndof` long), no allocation.
    ///
    /// [`force_scale`]: crate::structure::model::StepElement::force_scale
    pub fn force_scale(
        &self,
        model: &Model,
        kin: &[NodeKin<f64>],
        ctx: &EvalCtx,
        res: &mut [f64],
    ) -> f64 {
        let nl6 = 6 * self.n_nodes;
        res[..nl6].iter_mut().for_each(|r| *r = 0.0);
        let mut kf = [NodeKin::<f64>::ground(); 4];
        let mut out = [0.0f64; MAXL];
        for (ei, e) in model.elements.iter().enumerate() {
            let nnodes = match e {
                Element::Beam(_) => 4,
                Element::Joint(_) => continue,
                _ => 1,
            };
            let dofs = &self.elem_dofs[ei];
            let n = 6 * nnodes;
            for l in 0..nnodes {
                kf[l] = kin[dofs[6 * l] / 6];
            }
            out[..n].iter_mut().for_each(|x| *x = 0.0);
            match e {
                Element::Beam(b) => {
                    let kk = [kf[0], kf[1], kf[2], kf[3]];
                    b.residual_f64(&kk, ctx, &mut out[..n])
                }
                _ => element_residual(e, &kf[..nnodes], &[], ctx, &mut out[..n]),
            }
            for a in 0..n {
                res[dofs[a]] += out[a].abs();
            }
        }
        for s in &model.step_elements {
            let nd = s.nodes();
            let u: [f64; 3] = std::array::from_fn(|k| kin[nd[1]].x[k] - kin[nd[0]].x[k]);
            let l = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
            let f = s.force_scale();
            for node in nd {
                for k in 0..3 {
                    // along the line of action; without one (zero length) on every axis
                    let e = if l > 0.0 { (u[k] / l).abs() } else { 1.0 };
                    res[6 * node + k] += f * e;
                }
            }
        }
        let f = super::newton::norm(&res[..nl6]);
        if f.is_finite() {
            f
        } else {
            0.0
        }
    }

    /// Numeric LU of the assembled matrix (symbolic analysis reused).
    pub fn factor(&mut self) -> Result<(), LinearError> {
        self.factored = false;
        match &mut self.lu {
            Lu::Single {
                symbolic,
                numeric,
                buf,
            } => {
                let sym = SymbolicSparseColMatRef::new_checked(
                    self.ndof,
                    self.ndof,
                    &self.col_ptr,
                    None,
                    &self.row_idx,
                );
                let a = SparseColMatRef::new(sym, &self.values);
                let stack = MemStack::new(buf);
                symbolic
                    .factorize_numeric_lu(numeric, a, Par::Seq, stack, Default::default())
                    .map_err(|e| LinearError::of_lu(e, self.ndof))?;
            }
            Lu::Bordered(lu) => lu.factor(&self.values).map_err(|e| match e {
                LinearError::Singular(s) => LinearError::Singular(format!(
                    "{s} (bordered LU of {} blocks coupled through the border nodes' unknowns)",
                    lu.blocks()
                )),
                other => other,
            })?,
        }
        self.factored = true;
        Ok(())
    }

    /// Solve in place with the last factorisation.
    pub fn solve(&mut self, rhs: &mut [f64]) {
        assert!(self.factored);
        match &mut self.lu {
            Lu::Single {
                symbolic,
                numeric,
                buf,
            } => {
                let lu = faer::sparse::linalg::lu::LuRef::new_unchecked(symbolic, numeric);
                let stack = MemStack::new(buf);
                let n = rhs.len();
                let m = MatMut::from_column_major_slice_mut(rhs, n, 1);
                lu.solve_in_place_with_conj(Conj::No, m, Par::Seq, stack);
            }
            Lu::Bordered(lu) => lu.solve(rhs),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::border_partition;

    /// CSC of the symmetric pattern of the dense element blocks `elems` (and the diagonal).
    fn pattern(ndof: usize, elems: &[Vec<usize>]) -> (Vec<usize>, Vec<usize>) {
        let mut cols: Vec<Vec<usize>> = (0..ndof).map(|i| vec![i]).collect();
        for d in elems {
            for &j in d {
                cols[j].extend(d);
            }
        }
        let (mut cp, mut ri) = (vec![0], vec![]);
        for c in &mut cols {
            c.sort_unstable();
            c.dedup();
            ri.extend(c.iter());
            cp.push(ri.len());
        }
        (cp, ri)
    }

    #[test]
    fn blocks_are_the_components_off_the_border() {
        // nodes 0 (border), 1-2 and 3 (blocks); a joint 0-1 (multipliers 24, 25) goes with
        // its block, a joint on the border node alone (multiplier 26) to the border
        let node = |n: usize| (6 * n..6 * n + 6).collect::<Vec<_>>();
        let joint = |a: usize, b: usize, l: &[usize]| [node(a), node(b), l.to_vec()].concat();
        let elems = vec![
            joint(0, 1, &[24, 25]),
            [node(1), node(2)].concat(),
            [node(0), node(3)].concat(),
            [node(0), vec![26]].concat(),
        ];
        let (cp, ri) = pattern(27, &elems);
        let p = border_partition(4, &[0], &cp, &ri).expect("two blocks");
        assert_eq!(p.blocks.len(), 2);
        assert_eq!(
            p.blocks[0],
            [(6..18).collect::<Vec<_>>(), vec![24, 25]].concat()
        );
        assert_eq!(p.blocks[1], node(3));
        assert_eq!(p.border, [node(0), vec![26]].concat());
        // without a border, or one block only: one LU
        assert!(border_partition(4, &[], &cp, &ri).is_none());
        assert!(border_partition(4, &[3], &cp, &ri).is_none());
    }
}
