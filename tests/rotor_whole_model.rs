//! The whole rotor's model deck (`rotorsim expand --all-blades`): every blade a full copy of the
//! single blade's model, named `b<k>.` and turned (k-1) 360/N deg about the shaft on one hub.
//! Its rotating equilibrium is the single blade's, turned: every node of every blade lies where
//! the single blade's node of the same name lies, turned by the blade's azimuth.
mod support;

use rotorsim::rotor::expand::{expand_rotor, Controls, ExpandOptions};
use rotorsim::rotor::sim::{expanded_model, whole_rotor_model};
use rotorsim::rotor::RotorDeck;
use rotorsim::solver::statics::{static_solve, StaticOptions};
use rotorsim::solver::State;
use rotorsim::structure::model::Model;

fn equilibrium(model: &mut Model, omega: f64) -> State {
    let mut st = State::from_model(model);
    static_solve(
        model,
        &mut st,
        &StaticOptions {
            load_steps: 1,
            omega: Some([0.0, 0.0, omega]),
            ..Default::default()
        },
        |_, _, _, _| {},
    )
    .unwrap();
    st
}

/// Expansion options with collective and cyclic pitch (the swashplate shared by the blades).
fn pitched() -> ExpandOptions {
    ExpandOptions {
        controls: Controls {
            th0_deg: 10.0,
            th1c_deg: 2.0,
            th1s_deg: -6.0,
        },
        table_revs: 1,
        ..Default::default()
    }
}

#[test]
fn the_whole_rotor_at_rest_on_its_shaft_is_the_single_blade_turned() {
    let path = support::root().join("rotors/uh60a.toml");
    let deck = RotorDeck::from_file(&path).unwrap();
    let opts = pitched();
    let n = deck.spec.rotor.blades;
    let specs = vec![deck.spec.clone(); n];
    let text = expand_rotor(&specs, &opts);
    assert!(text.contains("name = \"b4.blade\""), "blade 4 is named b4.");
    let om = deck.spec.rotor.omega_rad_s;
    let mut single = expanded_model(&deck.spec, &opts, &path).unwrap();
    let mut whole = whole_rotor_model(&specs, &opts, &path).unwrap();
    assert_eq!(
        whole.nodes.len(),
        n * single.nodes.len() + 1,
        "every node once per blade (each its own first retention node), and the hub"
    );
    let s1 = equilibrium(&mut single, om);
    let sw = equilibrium(&mut whole, om);
    let scale = deck.spec.rotor.radius_m;
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    for k in 1..=n {
        let (sn, cs) = ((k - 1) as f64 * 360.0 / n as f64).to_radians().sin_cos();
        for (i, node) in single.nodes.iter().enumerate() {
            // the single blade's retention starts at the hub node, a copy's at its own
            let name = if node.name == "hub" {
                "seg1.n0"
            } else {
                &node.name
            };
            let j = whole.node_id(&format!("b{k}.{name}")).unwrap();
            let x = s1.x[i];
            let want = [cs * x[0] - sn * x[1], sn * x[0] + cs * x[1], x[2]];
            let got = sw.x[j];
            for c in 0..3 {
                worst = worst.max((got[c] - want[c]).abs() / scale);
            }
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked} nodes");
    // the equilibrium is solved to the statics' tolerance, on the same discretization
    assert!(worst < 1e-9, "largest distance {worst:.2e} R");
    // and it is not the undeformed position: the blades deflect under the collective and
    // the centrifugal load, so the comparison is of a solved state
    let moved = whole
        .nodes
        .iter()
        .zip(&sw.x)
        .map(|(nd, x)| (0..3).map(|c| (x[c] - nd.x0[c]).abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    assert!(moved > 1e-3 * scale, "largest deflection {moved} m");
}

/// The whole rotor on its airframe is factored by parts: the hub and the airframe's chain are
/// the border of a bordered LU, and its rotating equilibrium is the one LU's of the same model
/// to the statics' tolerance.
#[test]
fn the_whole_rotor_on_its_airframe_is_factored_blade_by_blade() {
    use rotorsim::solver::Assembler;
    let path = support::root().join("rotors/uh60a_airframe.toml");
    let deck = RotorDeck::from_file(&path).unwrap();
    let opts = pitched();
    let n = deck.spec.rotor.blades;
    let specs = vec![deck.spec.clone(); n];
    let om = deck.spec.rotor.omega_rad_s;
    let mut bordered = whole_rotor_model(&specs, &opts, &path).unwrap();
    let border: Vec<&str> = bordered
        .border_nodes
        .iter()
        .map(|&i| bordered.nodes[i].name.as_str())
        .collect();
    assert_eq!(border, ["hub", "airframe.x", "airframe.y"]);
    // the dampers (step elements, which the run adds) are all that ties each blade's clamped
    // damper mount on the hub to its blade: without them, two blocks a blade
    assert_eq!(Assembler::new(&bordered).unwrap().bordered_blocks(), 2 * n);
    let mut single = whole_rotor_model(&specs, &opts, &path).unwrap();
    single.border_nodes.clear();
    assert_eq!(Assembler::new(&single).unwrap().bordered_blocks(), 0);
    let sb = equilibrium(&mut bordered, om);
    let ss = equilibrium(&mut single, om);
    let scale = deck.spec.rotor.radius_m;
    let worst =
        sb.x.iter()
            .zip(&ss.x)
            .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs() / scale))
            .fold(0.0, f64::max);
    assert!(worst < 1e-9, "largest difference {worst:.2e} R");
}
