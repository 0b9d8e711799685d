use rotorsim::solver::statics::check_constraints;
use rotorsim::solver::{static_solve, DynamicSolver, NewtonError, State, StaticOptions};
use rotorsim::structure::deck::parse_deck;
use rotorsim::structure::*;
use std::path::Path;

const BASE: &str = r#"
[[beam]]
name = "b"
elements = 2
start_m = [0.0, 0.0, 0.0]
end_m = [1.0, 0.0, 0.0]
section = { EA_N = 1e6, GA2_N = 1e6, GA3_N = 1e6, GJ_Nm2 = 1.0, EI2_Nm2 = 1.0, EI3_Nm2 = 1.0, m_kg_per_m = 1.0, I1_kgm = 1e-3, I2_kgm = 5e-4, I3_kgm = 5e-4 }

[[joint]]
name = "root"
type = "clamp"
node_b = "b.n0"
"#;

fn err(text: &str) -> String {
    match parse_deck(text, "test.toml", Path::new(".")) {
        Ok(_) => panic!("deck accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn unknown_key_is_rejected_with_file_and_line() {
    let e = err(&format!(
        "{BASE}\n[[load]]\nname = \"f\"\nnode = \"b.n6\"\nforce = [0.0, 0.0, 1.0]\n"
    ));
    println!("{e}");
    assert!(
        e.contains("test.toml") && e.contains("unknown field `force`") && e.contains("line"),
        "{e}"
    );
}

#[test]
fn missing_section_table_is_reported() {
    let e = err(&BASE
        .replace(
            "section = {",
            "sections_csv = \"/nonexistent/sections.csv\"\nx = {",
        )
        .replace("x = {", "#"));
    println!("{e}");
    assert!(
        e.contains("sections_csv") && e.contains("/nonexistent/sections.csv"),
        "{e}"
    );
    let e = err(&BASE.replace("section = {", "# section = {"));
    println!("{e}");
    assert!(e.contains("missing section data"), "{e}");
}

#[test]
fn joint_with_missing_node_is_reported() {
    let e = err(&BASE.replace("node_b = \"b.n0\"", "node_b = \"b.n99\""));
    println!("{e}");
    assert!(
        e.contains("joint[0] `root`.node_b") && e.contains("`b.n99` does not exist"),
        "{e}"
    );
}

#[test]
fn unconnected_node_is_reported() {
    let e = err(&format!(
        "{BASE}\n[[node]]\nname = \"lonely\"\nposition_m = [0.0, 1.0, 0.0]\n"
    ));
    println!("{e}");
    assert!(
        e.contains("node `lonely`") && e.contains("not connected"),
        "{e}"
    );
}

#[test]
fn singular_constraint_set_is_reported() {
    let text =
        format!("{BASE}\n[[joint]]\nname = \"again\"\ntype = \"revolute\"\nnode_b = \"b.n0\"\n");
    let (_, mut m) = parse_deck(&text, "test.toml", Path::new(".")).unwrap();
    let st = State::from_model(&m);
    let e = check_constraints(&mut m, &st).unwrap_err();
    println!("{e}");
    assert!(
        e.contains("singular constraint set") && e.contains("`again`"),
        "{e}"
    );
}

#[test]
fn newton_divergence_reports_time_iteration_and_residual() {
    // a follower tip load far beyond anything Newton can reach in one step, with 3 iterations
    let (_, mut m) = parse_deck(BASE, "test.toml", Path::new(".")).unwrap();
    let tip = m.node_id("b.n6").unwrap();
    m.add_element(Element::Load(PointLoad {
        name: "f".into(),
        node: tip,
        force_n: [0.0, 0.0, 1e3],
        moment_nm: [0.0; 3],
        follower: true,
        time: TimeTable::constant(),
    }))
    .unwrap();
    let mut st = State::from_model(&m);
    let mut opts = StaticOptions::default();
    opts.newton.max_iterations = 3;
    let e = static_solve(&mut m, &mut st, &opts, |_, _, _, _| {}).unwrap_err();
    println!("{e}");
    assert!(
        matches!(e, NewtonError::StaticDiverged { iterations: 3, .. }),
        "{e}"
    );
    let s = e.to_string();
    assert!(
        s.contains("load factor 1") && s.contains("3 iterations") && s.contains("residual norm"),
        "{s}"
    );
    // dynamic: same message carries the physical time
    let (_, mut m) = parse_deck(BASE, "test.toml", Path::new(".")).unwrap();
    m.add_element(Element::Load(PointLoad {
        name: "f".into(),
        node: tip,
        force_n: [0.0, 0.0, 1e5],
        moment_nm: [0.0; 3],
        follower: true,
        time: TimeTable {
            points: vec![(0.0, 0.0), (0.02, 0.0), (0.03, 1.0)],
        },
    }))
    .unwrap();
    let st = State::from_model(&m);
    let mut s = DynamicSolver::new(m, st, 0.01, 0.9).unwrap();
    s.newton.max_iterations = 4;
    let mut last = None;
    for _ in 0..10 {
        if let Err(e) = s.step() {
            last = Some(e);
            break;
        }
    }
    let e = last.expect("diverges");
    println!("{e}");
    assert!(e.to_string().contains("t = 0.03"), "{e}");
    // the state stays at the last converged step
    assert!((s.state.t - 0.02).abs() < 1e-12);
}

#[test]
fn cli_marks_output_incomplete_on_divergence() {
    let dir = std::env::temp_dir().join(format!("rotorsim_div_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let deck = dir.join("d.toml");
    let text = format!("{BASE}\n[[load]]\nname = \"f\"\nnode = \"b.n6\"\nforce_N = [0.0, 0.0, 1e5]\nfollower = true\n\n[static]\nload_steps = 1\nmax_iterations = 3\n");
    std::fs::write(&deck, text).unwrap();
    let out = dir.join("out");
    let r = rotorsim::checks::static_job::StaticSettings::default()
        .job(deck, out.clone())
        .execute(&|_| {});
    let e = r.unwrap_err();
    println!("{e:#}");
    assert!(out.join("INCOMPLETE").exists());
    let reason = std::fs::read_to_string(out.join("INCOMPLETE")).unwrap();
    assert!(reason.contains("did not converge"), "{reason}");
}

const BUSHING: &str = r#"
[[node]]
name = "air"
position_m = [0.0, 0.0, 0.0]

[[rigid_body]]
name = "body"
node = "air"
mass_kg = 500.0
inertia_kgm2 = [[200.0, 0.0, 0.0], [0.0, 300.0, 0.0], [0.0, 0.0, 400.0]]

[[joint]]
name = "mount"
type = "bushing"
node_b = "air"
stiffness_N_per_m = [2e5, 3e5, 5e5]
rot_stiffness_Nm_per_rad = [4e5, 9e5, 0.0]
"#;

#[test]
fn bad_bushings_name_the_file_the_joint_and_the_key() {
    assert!(parse_deck(BUSHING, "test.toml", Path::new(".")).is_ok());
    let cases = [
        (
            BUSHING.replace("[2e5, 3e5, 5e5]", "[2e5, -3e5, 5e5]"),
            "joint[0] `mount`.stiffness_N_per_m",
            ">= 0",
        ),
        (
            BUSHING.replace("[4e5, 9e5, 0.0]", "[4e5, 9e5]"),
            "joint[0] `mount`.rot_stiffness_Nm_per_rad",
            "expected 3 values",
        ),
        (
            format!("{BUSHING}damping_Ns_per_m = [1.0, nan, 0.0]\n"),
            "joint[0] `mount`.damping_Ns_per_m",
            ">= 0",
        ),
        (
            format!("{BUSHING}rot_damping_Nms_per_rad = [1.0, 2.0, 3.0, 4.0]\n"),
            "joint[0] `mount`.rot_damping_Nms_per_rad",
            "expected 3 values",
        ),
        (
            format!("{BUSHING}stifness_N_per_m = [1.0, 2.0, 3.0]\n"),
            "joint[0] `mount`",
            "unknown field `stifness_N_per_m`",
        ),
        (
            BUSHING
                .replace("[2e5, 3e5, 5e5]", "[0.0, 0.0, 0.0]")
                .replace("[4e5, 9e5, 0.0]", "[0.0, 0.0, 0.0]"),
            "joint[0] `mount`.stiffness_N_per_m",
            "does nothing",
        ),
        (
            format!("{BUSHING}stiffness_Nm_per_rad = 10.0\n"),
            "joint[0] `mount`.stiffness_Nm_per_rad",
            "not allowed on a bushing",
        ),
        (
            format!("{BASE}stiffness_N_per_m = [1.0, 2.0, 3.0]\n"),
            "joint[0] `root`.stiffness_N_per_m",
            "only for type = \"bushing\"",
        ),
    ];
    for (text, key, what) in cases {
        let e = err(&text);
        println!("{e}");
        assert!(
            e.contains("test.toml") && e.contains(key) && e.contains(what),
            "{e}"
        );
    }
}
