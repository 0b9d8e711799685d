use rotorsim::solver::verification::mesh_convergence;

#[test]
fn mesh_convergence_observed_orders() {
    for (q, ns, errs, ord) in mesh_convergence().unwrap() {
        println!("{q}");
        for (n, e) in ns.iter().zip(&errs) {
            println!("  {n:>3} elements: error {e:.3e}");
        }
        println!("  observed orders: {ord:.2?}");
        // cubic elements: at least third order (observed 5-6, superconvergent at the nodes)
        assert!(ord.iter().all(|&o| o > 3.0), "{q}: {ord:?}");
    }
}
