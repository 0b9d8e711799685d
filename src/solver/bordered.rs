//! Bordered block-diagonal LU (static condensation): diagonal blocks coupled only through a
//! small border, as the blades of a rotor are coupled only through the hub,
//!
//! ```text
//! [A_1        B_1] [x_1]   [r_1]
//! [     ...   ...] [...] = [...]
//! [       A_n B_n] [x_n]   [r_n]
//! [C_1 .. C_n  D ] [x_b]   [r_b]
//! ```
//!
//! Each block is factored on its own (sparse LU, in parallel) with `W_k = A_k^-1 B_k`; the
//! border is solved on the dense Schur complement `S = D - sum C_k W_k`, then
//! `x_k = A_k^-1 r_k - W_k x_b`. The cost grows linearly with the number of blocks where one LU
//! of the whole matrix would couple their fill through the border.
use super::assembly::LinearError;
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor as dense_lu, solve as dense_solve};
use faer::perm::PermRef;
use faer::sparse::linalg::lu::{
    factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu, SymbolicLu,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, MatRef, Par};
use rayon::prelude::*;
use thiserror::Error;

/// Which unknowns form each block and which the border.
#[derive(Debug, Clone, Default)]
pub struct Partition {
    pub blocks: Vec<Vec<usize>>,
    pub border: Vec<usize>,
}

/// A partition that does not fit the matrix.
#[derive(Debug, Error, PartialEq)]
pub enum PartitionError {
    #[error(
        "unknown {dof} is in no block and not in the border (the partition must cover 0..{n})"
    )]
    Uncovered { dof: usize, n: usize },
    #[error("unknown {dof} is listed twice in the partition")]
    Twice { dof: usize },
    #[error("unknown {dof} is out of range (the matrix has {n})")]
    OutOfRange { dof: usize, n: usize },
    #[error("entry ({row}, {col}) couples block {row_block} with block {col_block}: blocks may be coupled only through the border")]
    CouplesBlocks {
        row: usize,
        col: usize,
        row_block: usize,
        col_block: usize,
    },
}

#[derive(Clone, Copy)]
enum Owner {
    Block(usize, usize),
    Border(usize),
}

/// One diagonal block: its sparse LU, its coupling to the border and its workspaces.
struct Block {
    dofs: Vec<usize>,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Position in the global values of each entry of the block's CSC.
    src: Vec<usize>,
    values: Vec<f64>,
    symbolic: SymbolicLu<usize>,
    numeric: NumericLu<usize, f64>,
    buf: MemBuffer,
    /// B_k: (local row, column of `bcols`, global position).
    b: Vec<(usize, usize, usize)>,
    /// The border columns B_k has entries in (a blade meets the hub, not the whole border).
    bcols: Vec<usize>,
    /// C_k: (border row, local column, global position), and its values at the last factor.
    c: Vec<(usize, usize, usize)>,
    cv: Vec<f64>,
    /// W_k = A_k^-1 B_k over `bcols`, column-major n_k x bcols.len().
    w: Vec<f64>,
    /// Right-hand side and solution of the block.
    x: Vec<f64>,
}

impl Block {
    fn factor(&mut self, values: &[f64]) -> Result<(), LinearError> {
        let n = self.dofs.len();
        let nb = self.bcols.len();
        for (v, &p) in self.values.iter_mut().zip(&self.src) {
            *v = values[p];
        }
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx);
        let a = SparseColMatRef::new(sym, &self.values);
        let stack = MemStack::new(&mut self.buf);
        self.symbolic
            .factorize_numeric_lu(&mut self.numeric, a, Par::Seq, stack, Default::default())
            .map_err(|e| LinearError::of_lu(e, n))?;
        for (v, &(_, _, p)) in self.cv.iter_mut().zip(&self.c) {
            *v = values[p];
        }
        self.w.fill(0.0);
        for &(i, j, p) in &self.b {
            self.w[i + j * n] = values[p];
        }
        if nb > 0 {
            let lu = LuRef::new_unchecked(&self.symbolic, &self.numeric);
            let stack = MemStack::new(&mut self.buf);
            let m = MatMut::from_column_major_slice_mut(&mut self.w, n, nb);
            lu.solve_in_place_with_conj(Conj::No, m, Par::Seq, stack);
            // a zero pivot shows as a non-finite coupling: faer does not report it
            if self.w.iter().any(|w| !w.is_finite()) {
                return Err(LinearError::Singular(
                    "a zero pivot (the block's coupling to the border is not finite)".into(),
                ));
            }
        }
        Ok(())
    }

    /// x = A_k^-1 x, in place.
    fn solve(&mut self) {
        let n = self.dofs.len();
        let lu = LuRef::new_unchecked(&self.symbolic, &self.numeric);
        let stack = MemStack::new(&mut self.buf);
        let m = MatMut::from_column_major_slice_mut(&mut self.x, n, 1);
        lu.solve_in_place_with_conj(Conj::No, m, Par::Seq, stack);
    }
}

/// The LU of a bordered block-diagonal matrix, built once for a sparsity pattern.
pub struct BorderedLu {
    n: usize,
    border: Vec<usize>,
    blocks: Vec<Block>,
    /// D: (border row, border column, global position).
    d: Vec<(usize, usize, usize)>,
    /// The Schur complement and its dense LU (column-major), with its row permutation.
    schur: Vec<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    buf: MemBuffer,
    xb: Vec<f64>,
    /// Factor the blocks in parallel (rayon) or one after the other.
    pub parallel: bool,
    /// Solve the blocks in parallel (rayon) or one after the other.
    pub parallel_solve: bool,
    factored: bool,
}

impl BorderedLu {
    /// The symbolic analysis of the `n x n` pattern (CSC, rows sorted in each column) under
    /// `partition`.
    pub fn new(
        n: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        partition: &Partition,
    ) -> Result<Self, BorderedError> {
        let mut owner: Vec<Option<Owner>> = vec![None; n];
        let mut claim = |dof: usize, o: Owner| -> Result<(), PartitionError> {
            let slot = owner
                .get_mut(dof)
                .ok_or(PartitionError::OutOfRange { dof, n })?;
            if slot.is_some() {
                return Err(PartitionError::Twice { dof });
            }
            *slot = Some(o);
            Ok(())
        };
        let mut blocks_dofs = partition.blocks.clone();
        for d in &mut blocks_dofs {
            d.sort_unstable();
        }
        for (k, dofs) in blocks_dofs.iter().enumerate() {
            for (i, &dof) in dofs.iter().enumerate() {
                claim(dof, Owner::Block(k, i))?;
            }
        }
        for (a, &dof) in partition.border.iter().enumerate() {
            claim(dof, Owner::Border(a))?;
        }
        let owner: Vec<Owner> = owner
            .into_iter()
            .enumerate()
            .map(|(dof, o)| o.ok_or(PartitionError::Uncovered { dof, n }))
            .collect::<Result<_, _>>()?;
        let nb = partition.border.len();
        let nblocks = blocks_dofs.len();
        // entries of each block by local column
        let mut cols: Vec<Vec<Vec<(usize, usize)>>> = blocks_dofs
            .iter()
            .map(|d| vec![Vec::new(); d.len()])
            .collect();
        let mut b: Vec<Vec<(usize, usize, usize)>> = vec![Vec::new(); nblocks];
        let mut c: Vec<Vec<(usize, usize, usize)>> = vec![Vec::new(); nblocks];
        let mut d = Vec::new();
        for j in 0..n {
            for p in col_ptr[j]..col_ptr[j + 1] {
                let i = row_idx[p];
                match (owner[i], owner[j]) {
                    (Owner::Block(k, li), Owner::Block(l, lj)) if k == l => {
                        cols[k][lj].push((li, p))
                    }
                    (Owner::Block(k, _), Owner::Block(l, _)) => {
                        return Err(PartitionError::CouplesBlocks {
                            row: i,
                            col: j,
                            row_block: k,
                            col_block: l,
                        }
                        .into())
                    }
                    (Owner::Block(k, li), Owner::Border(bj)) => b[k].push((li, bj, p)),
                    (Owner::Border(ai), Owner::Block(k, lj)) => c[k].push((ai, lj, p)),
                    (Owner::Border(ai), Owner::Border(bj)) => d.push((ai, bj, p)),
                }
            }
        }
        let mut blocks = Vec::with_capacity(nblocks);
        for (k, dofs) in blocks_dofs.into_iter().enumerate() {
            let nk = dofs.len();
            let mut bk = std::mem::take(&mut b[k]);
            let mut bcols: Vec<usize> = bk.iter().map(|e| e.1).collect();
            bcols.sort_unstable();
            bcols.dedup();
            for e in &mut bk {
                e.1 = bcols.binary_search(&e.1).expect("border column of B_k");
            }
            let nbk = bcols.len();
            let mut cp = vec![0usize; nk + 1];
            let mut ri = Vec::new();
            let mut src = Vec::new();
            for (lj, col) in cols[k].iter_mut().enumerate() {
                col.sort_unstable();
                for &(li, p) in col.iter() {
                    ri.push(li);
                    src.push(p);
                }
                cp[lj + 1] = ri.len();
            }
            let sym = SymbolicSparseColMatRef::new_checked(nk, nk, &cp, None, &ri);
            // supernodal, as the structural solver's LU: on a blade's banded pattern its dense
            // kernels beat the simplicial LU (docs/performance.md)
            let params = LuSymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            };
            let symbolic =
                factorize_symbolic_lu(sym, params).map_err(|e| LinearError::of_faer(e, nk))?;
            let req = StackReq::any_of(&[
                symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
                symbolic.solve_in_place_scratch::<f64>(nbk.max(1), Par::Seq),
            ]);
            let buf = MemBuffer::try_new(req)
                .map_err(|_| BorderedError::Linear(LinearError::OutOfMemory { ndof: nk }))?;
            let nnz = ri.len();
            blocks.push(Block {
                dofs,
                col_ptr: cp,
                row_idx: ri,
                src,
                values: vec![0.0; nnz],
                symbolic,
                numeric: NumericLu::new(),
                buf,
                b: bk,
                bcols,
                cv: vec![0.0; c[k].len()],
                c: std::mem::take(&mut c[k]),
                w: vec![0.0; nk * nbk],
                x: vec![0.0; nk],
            });
        }
        let req = StackReq::any_of(&[
            dense_lu::lu_in_place_scratch::<usize, f64>(nb, nb, Par::Seq, Default::default()),
            dense_solve::solve_in_place_scratch::<usize, f64>(nb, 1, Par::Seq),
        ]);
        let buf = MemBuffer::try_new(req)
            .map_err(|_| BorderedError::Linear(LinearError::OutOfMemory { ndof: nb }))?;
        Ok(BorderedLu {
            n,
            border: partition.border.clone(),
            blocks,
            d,
            schur: vec![0.0; nb * nb],
            perm: vec![0; nb],
            perm_inv: vec![0; nb],
            buf,
            xb: vec![0.0; nb],
            parallel: true,
            parallel_solve: true,
            factored: false,
        })
    }

    /// Unknowns of the whole system.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// Number of diagonal blocks.
    pub fn blocks(&self) -> usize {
        self.blocks.len()
    }

    /// Numeric factorization of the matrix with `values` on the pattern of [`Self::new`].
    pub fn factor(&mut self, values: &[f64]) -> Result<(), LinearError> {
        self.factored = false;
        let nb = self.border.len();
        let block = |(k, b): (usize, &mut Block)| {
            b.factor(values).map_err(|e| match e {
                LinearError::Singular(s) => LinearError::Singular(format!("block {k}: {s}")),
                other => other,
            })
        };
        if self.parallel {
            self.blocks
                .par_iter_mut()
                .enumerate()
                .map(block)
                .collect::<Result<(), _>>()?;
        } else {
            self.blocks.iter_mut().enumerate().try_for_each(block)?;
        }
        // S = D - sum C_k W_k
        self.schur.fill(0.0);
        for &(a, b, p) in &self.d {
            self.schur[a + b * nb] += values[p];
        }
        for blk in &self.blocks {
            let nk = blk.dofs.len();
            for &(a, i, p) in &blk.c {
                let v = values[p];
                for (m, &b) in blk.bcols.iter().enumerate() {
                    self.schur[a + b * nb] -= v * blk.w[i + m * nk];
                }
            }
        }
        if nb > 0 {
            // pivots against the whole matrix's scale: a border without stiffness is singular
            // however its round-off compares with itself
            let scale = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let stack = MemStack::new(&mut self.buf);
            let s = MatMut::from_column_major_slice_mut(&mut self.schur, nb, nb);
            dense_lu::lu_in_place(
                s,
                &mut self.perm,
                &mut self.perm_inv,
                Par::Seq,
                stack,
                Default::default(),
            );
            for i in 0..nb {
                let u = self.schur[i + i * nb];
                if !(u.is_finite() && u.abs() > scale * f64::EPSILON * self.n as f64) {
                    return Err(LinearError::Singular(format!(
                        "the border's Schur complement is singular (pivot {i} of {nb}: {u:.3e}, the matrix's largest entry {scale:.3e}): the border is not restrained by the blocks and its own stiffness"
                    )));
                }
            }
        }
        self.factored = true;
        Ok(())
    }

    /// Solves in place with the last factorization.
    pub fn solve(&mut self, rhs: &mut [f64]) {
        assert!(self.factored && rhs.len() == self.n);
        let nb = self.border.len();
        let fill_and_solve = |b: &mut Block| {
            for (x, &g) in b.x.iter_mut().zip(&b.dofs) {
                *x = rhs[g];
            }
            b.solve();
        };
        if self.parallel_solve {
            self.blocks.par_iter_mut().for_each(fill_and_solve);
        } else {
            self.blocks.iter_mut().for_each(fill_and_solve);
        }
        if nb > 0 {
            for (x, &g) in self.xb.iter_mut().zip(&self.border) {
                *x = rhs[g];
            }
            for blk in &self.blocks {
                for (&(a, i, _), v) in blk.c.iter().zip(&blk.cv) {
                    self.xb[a] -= v * blk.x[i];
                }
            }
            let n = nb;
            let lu = MatRef::from_column_major_slice(&self.schur, n, n);
            let perm = PermRef::new_checked(&self.perm, &self.perm_inv, n);
            let stack = MemStack::new(&mut self.buf);
            let m = MatMut::from_column_major_slice_mut(&mut self.xb, n, 1);
            dense_solve::solve_in_place_with_conj(lu, lu, perm, Conj::No, m, Par::Seq, stack);
        }
        for blk in &self.blocks {
            let nk = blk.dofs.len();
            for (i, &g) in blk.dofs.iter().enumerate() {
                let mut x = blk.x[i];
                for (m, &b) in blk.bcols.iter().enumerate() {
                    x -= blk.w[i + m * nk] * self.xb[b];
                }
                rhs[g] = x;
            }
        }
        for (b, &g) in self.border.iter().enumerate() {
            rhs[g] = self.xb[b];
        }
    }
}

/// Why a [`BorderedLu`] could not be built.
#[derive(Debug, Error)]
pub enum BorderedError {
    #[error(transparent)]
    Partition(#[from] PartitionError),
    #[error(transparent)]
    Linear(#[from] LinearError),
}
