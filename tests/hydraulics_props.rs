//! Property tests of the element laws and the monotone table.
use proptest::prelude::*;
use rotorsim::hydraulics::dashpot::MonotoneTable;
use rotorsim::hydraulics::{CheckValve, FlowLaw};

proptest! {
    #[test]
    fn flow_law_is_odd_monotone_and_lipschitz(dp in -1.0e8f64..1.0e8, dp_l in 1.0f64..1.0e5, rho in 700.0f64..1000.0) {
        let law = FlowLaw { rho, dp_laminar: dp_l };
        let (u, du) = law.unit_flow(dp);
        let (um, dum) = law.unit_flow(-dp);
        prop_assert_eq!(u, -um);
        prop_assert_eq!(du, dum);
        prop_assert!(du > 0.0);
        // The slope never exceeds its value at dp = 0 (Lipschitz constant of the law).
        let (_, du0) = law.unit_flow(0.0);
        prop_assert!(du <= du0 * (1.0 + 1e-12));
        prop_assert!(u.signum() == dp.signum() || dp == 0.0);
    }

    #[test]
    fn check_valve_only_fills(p in -1.0e6f64..1.0e8, p_s in 0.0f64..2.0e6) {
        let law = FlowLaw { rho: 850.0, dp_laminar: 1.0e3 };
        let cv = CheckValve { area: 5e-6, cd: 0.611 };
        let (q, dq) = cv.inflow(&law, p_s, p);
        prop_assert!(q >= 0.0 && dq <= 0.0);
        if p >= p_s { prop_assert_eq!(q, 0.0); }
    }

    #[test]
    fn monotone_table_stays_monotone(steps in proptest::collection::vec((0.01f64..1.0, 0.0f64..5000.0), 1..8), v in 0.0f64..10.0, dv in 0.0f64..1.0) {
        let mut x = vec![0.0];
        let mut y = vec![0.0];
        for (a, b) in &steps {
            x.push(x.last().unwrap() + a);
            y.push(y.last().unwrap() + b);
        }
        let t = MonotoneTable::new(x, y).unwrap();
        let (f0, d0) = t.eval(v);
        let (f1, _) = t.eval(v + dv);
        prop_assert!(f1 >= f0 - 1e-9 * f0.abs().max(1.0));
        prop_assert!(d0 >= -1e-9);
    }
}
