//! The bordered block-diagonal LU (static condensation of blocks coupled through a border, as
//! blades through a hub) against a dense LU of the same matrix (nalgebra): the solution agrees
//! and the residual is at round-off; partitions that do not fit the matrix and singular blocks or
//! borders are refused with the entry or block named; a solve does not allocate.
use nalgebra::{DMatrix, DVector};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rotorsim::solver::bordered::{BorderedError, BorderedLu, Partition, PartitionError};

mod alloc_support;
use alloc_support::{allocations, assert_counting};

/// A random bordered matrix: blocks banded with random off-band entries, sparse couplings to
/// the border, a dense border; unknowns of blocks and border interleaved in the global
/// numbering (as a multibody model numbers them). Returns the dense matrix and the partition.
fn bordered(seed: u64, sizes: &[usize], nb: usize) -> (DMatrix<f64>, Partition) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let n: usize = sizes.iter().sum::<usize>() + nb;
    // a random permutation spreads blocks and border over the numbering
    let mut order: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        order.swap(i, rng.random_range(0..=i));
    }
    let mut next = order.into_iter();
    let blocks: Vec<Vec<usize>> = sizes
        .iter()
        .map(|&s| (0..s).map(|_| next.next().unwrap()).collect())
        .collect();
    let border: Vec<usize> = next.collect();
    let mut a = DMatrix::zeros(n, n);
    for dofs in &blocks {
        let s = dofs.len();
        for i in 0..s {
            for j in 0..s {
                let band = (i as isize - j as isize).abs() <= 3;
                if band || rng.random_bool(0.03) {
                    a[(dofs[i], dofs[j])] = rng.random_range(-1.0..1.0);
                }
            }
            a[(dofs[i], dofs[i])] += 8.0;
        }
        for &i in dofs {
            for &j in &border {
                if rng.random_bool(0.2) {
                    a[(i, j)] = rng.random_range(-1.0..1.0);
                }
                if rng.random_bool(0.2) {
                    a[(j, i)] = rng.random_range(-1.0..1.0);
                }
            }
        }
    }
    for &i in &border {
        for &j in &border {
            a[(i, j)] = rng.random_range(-1.0..1.0);
        }
        a[(i, i)] += 4.0 * nb as f64;
    }
    (a, Partition { blocks, border })
}

/// CSC pattern and values of the nonzeros of `a`.
fn csc(a: &DMatrix<f64>) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
    let n = a.ncols();
    let (mut cp, mut ri, mut v) = (vec![0], vec![], vec![]);
    for j in 0..n {
        for i in 0..n {
            if a[(i, j)] != 0.0 {
                ri.push(i);
                v.push(a[(i, j)]);
            }
        }
        cp.push(ri.len());
    }
    (cp, ri, v)
}

fn rhs(n: usize, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| rng.random_range(-1.0..1.0)).collect()
}

#[test]
fn solves_as_a_dense_lu_does_with_a_residual_at_round_off() {
    for (seed, sizes, nb) in [
        (1, vec![40, 40, 40, 40], 6),
        (2, vec![25, 60, 33], 11),
        (3, vec![50; 8], 6),
        (4, vec![30, 30], 0),
    ] {
        let (a, part) = bordered(seed, &sizes, nb);
        let n = a.nrows();
        let (cp, ri, v) = csc(&a);
        let r = rhs(n, seed + 100);
        let want = a
            .clone()
            .lu()
            .solve(&DVector::from_column_slice(&r))
            .unwrap();
        let mut lu = BorderedLu::new(n, &cp, &ri, &part).unwrap();
        let mut results = vec![];
        for parallel in [false, true] {
            lu.parallel = parallel;
            lu.parallel_solve = parallel;
            lu.factor(&v).unwrap();
            let mut x = r.clone();
            lu.solve(&mut x);
            let xv = DVector::from_column_slice(&x);
            let err = (&xv - &want).amax() / want.amax();
            assert!(
                err < 1e-12,
                "seed {seed}: differs from dense LU by {err:.2e}"
            );
            // backward error: ||A x - r|| / (||A|| ||x||) at round-off
            let res = (&a * &xv - DVector::from_column_slice(&r)).amax();
            let back = res / (a.amax() * xv.amax());
            assert!(back < 1e-14, "seed {seed}: backward error {back:.2e}");
            results.push(x);
        }
        assert_eq!(results[0], results[1], "parallel and serial differ");
    }
}

#[test]
fn a_solve_does_not_allocate() {
    let (a, part) = bordered(7, &[40, 40, 40, 40], 6);
    let n = a.nrows();
    let (cp, ri, v) = csc(&a);
    let mut lu = BorderedLu::new(n, &cp, &ri, &part).unwrap();
    lu.parallel = false;
    lu.parallel_solve = false;
    lu.factor(&v).unwrap();
    let mut x = rhs(n, 8);
    assert_counting();
    let before = allocations();
    for _ in 0..10 {
        lu.solve(&mut x);
    }
    assert_eq!(allocations(), before, "solve allocated");
}

#[test]
fn partitions_that_do_not_fit_are_refused_naming_the_unknown_or_entry() {
    let (a, part) = bordered(9, &[10, 10], 3);
    let n = a.nrows();
    let (cp, ri, _) = csc(&a);
    let err = |p: &Partition| match BorderedLu::new(n, &cp, &ri, p) {
        Err(BorderedError::Partition(e)) => e,
        Err(e) => panic!("{e}"),
        Ok(_) => panic!("accepted"),
    };
    let mut p = part.clone();
    let lost = p.border.pop().unwrap();
    assert_eq!(err(&p), PartitionError::Uncovered { dof: lost, n });
    let mut p = part.clone();
    p.border.push(p.blocks[0][0]);
    assert_eq!(
        err(&p),
        PartitionError::Twice {
            dof: p.blocks[0][0]
        }
    );
    let mut p = part.clone();
    p.border.push(n);
    assert_eq!(err(&p), PartitionError::OutOfRange { dof: n, n });
    // an entry coupling two blocks directly
    let mut a2 = a.clone();
    let (i, j) = (part.blocks[0][1], part.blocks[1][2]);
    a2[(i, j)] = 1.0;
    let (cp2, ri2, _) = csc(&a2);
    match BorderedLu::new(n, &cp2, &ri2, &part) {
        Err(BorderedError::Partition(PartitionError::CouplesBlocks { row, col, .. })) => {
            assert_eq!((row, col), (i, j))
        }
        other => panic!("{:?}", other.err()),
    }
}

#[test]
fn a_singular_block_or_border_is_named() {
    let (a, part) = bordered(11, &[12, 12, 12], 4);
    let n = a.nrows();
    // block 1 singular: one of its unknowns appears in no equation of the block (a column of
    // zeros), only in the border's
    let mut s = a.clone();
    let c = part.blocks[1][3];
    for &i in &part.blocks[1] {
        s[(i, c)] = 0.0;
    }
    let (cp, ri, v) = csc(&s);
    let mut lu = BorderedLu::new(n, &cp, &ri, &part).unwrap();
    let e = lu.factor(&v).unwrap_err().to_string();
    assert!(e.contains("block 1"), "{e}");
    // the border free: no stiffness of its own and no coupling to the blocks
    let mut f = a.clone();
    for &b in &part.border {
        for j in 0..n {
            f[(b, j)] = 0.0;
            f[(j, b)] = 0.0;
        }
        f[(b, b)] = 1e-300;
    }
    let (cp, ri, v) = csc(&f);
    let mut lu = BorderedLu::new(n, &cp, &ri, &part).unwrap();
    let e = lu.factor(&v).unwrap_err().to_string();
    assert!(e.contains("Schur complement is singular"), "{e}");
}
