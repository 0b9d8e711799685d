//! Benchmark: factor and solve of N blade-sized blocks coupled through a hub, by one sparse LU
//! of the whole matrix (faer supernodal, as the structural solver factors one blade today)
//! against the bordered LU (each block on its own, in parallel, the hub on its Schur
//! complement), for 1, 4 and 8 blocks, in one run (compare as ratios: the machine is noisy).
//!
//! The blocks have the single-blade model's size and bandwidth (510 unknowns, half-bandwidth
//! 57: `RotorSpec::size_estimate` of rotors/uh60a.toml and the assembled pattern), the border
//! the hub's 6 unknowns coupled to the first 12 of each block (its root joint). Values are
//! random and diagonally dominant: the cost of a sparse LU is set by the pattern.
//!
//! `cargo bench --bench bordered`
use criterion::{criterion_group, criterion_main, Criterion};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::lu::{factorize_symbolic_lu, LuRef, LuSymbolicParams, NumericLu};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rotorsim::solver::bordered::{BorderedLu, Partition};
use std::hint::black_box;

const BLOCK: usize = 510;
const BAND: usize = 57;
const HUB: usize = 6;
const ROOT: usize = 12;

/// CSC of `blocks` banded blocks followed by the hub's unknowns.
fn matrix(blocks: usize) -> (usize, Vec<usize>, Vec<usize>, Vec<f64>, Partition) {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let n = blocks * BLOCK + HUB;
    let hub0 = blocks * BLOCK;
    let (mut cp, mut ri, mut v) = (vec![0], vec![], vec![]);
    for j in 0..n {
        let mut col: Vec<usize> = vec![];
        if j < hub0 {
            let (k, lj) = (j / BLOCK, j % BLOCK);
            let lo = lj.saturating_sub(BAND);
            let hi = (lj + BAND).min(BLOCK - 1);
            col.extend((lo..=hi).map(|li| k * BLOCK + li));
            if lj < ROOT {
                col.extend(hub0..n);
            }
        } else {
            for k in 0..blocks {
                col.extend((0..ROOT).map(|li| k * BLOCK + li));
            }
            col.extend(hub0..n);
        }
        for i in col {
            ri.push(i);
            v.push(if i == j {
                4.0 * BAND as f64
            } else {
                rng.random_range(-1.0..1.0)
            });
        }
        cp.push(ri.len());
    }
    let part = Partition {
        blocks: (0..blocks)
            .map(|k| (k * BLOCK..(k + 1) * BLOCK).collect())
            .collect(),
        border: (hub0..n).collect(),
    };
    (n, cp, ri, v, part)
}

fn lu(c: &mut Criterion) {
    let mut g = c.benchmark_group("bordered_lu");
    for blocks in [1usize, 4, 8] {
        let (n, cp, ri, v, part) = matrix(blocks);
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        // one LU of the whole matrix, set up as the structural solver's
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &cp, None, &ri);
        let params = LuSymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let symbolic = factorize_symbolic_lu(sym, params).unwrap();
        let mut buf = MemBuffer::new(StackReq::any_of(&[
            symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(1, Par::Seq),
        ]));
        let mut numeric = NumericLu::<usize, f64>::new();
        let mut x = rhs.clone();
        g.bench_function(format!("whole/{blocks}"), |b| {
            b.iter(|| {
                let a = SparseColMatRef::new(sym, &v);
                symbolic
                    .factorize_numeric_lu(
                        &mut numeric,
                        a,
                        Par::Seq,
                        MemStack::new(&mut buf),
                        Default::default(),
                    )
                    .unwrap();
                x.copy_from_slice(&rhs);
                let lu = LuRef::new_unchecked(&symbolic, &numeric);
                let m = MatMut::from_column_major_slice_mut(&mut x, n, 1);
                lu.solve_in_place_with_conj(Conj::No, m, Par::Seq, MemStack::new(&mut buf));
                black_box(&x);
            })
        });
        for parallel in [false, true] {
            let mut b_lu = BorderedLu::new(n, &cp, &ri, &part).unwrap();
            b_lu.parallel = parallel;
            b_lu.parallel_solve = parallel;
            let name = if parallel { "parallel" } else { "serial" };
            g.bench_function(format!("bordered_{name}/{blocks}"), |b| {
                b.iter(|| {
                    b_lu.factor(&v).unwrap();
                    x.copy_from_slice(&rhs);
                    b_lu.solve(&mut x);
                    black_box(&x);
                })
            });
        }
        // solve only (modified Newton reuses the factors)
        let mut b_lu = BorderedLu::new(n, &cp, &ri, &part).unwrap();
        b_lu.factor(&v).unwrap();
        g.bench_function(format!("bordered_solve/{blocks}"), |b| {
            b.iter(|| {
                x.copy_from_slice(&rhs);
                b_lu.solve(&mut x);
                black_box(&x);
            })
        });
    }
    g.finish();
}

criterion_group!(benches, lu);
criterion_main!(benches);
