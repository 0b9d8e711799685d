//! The whole rotor on an airframe (`[airframe]` in the rotor deck): the blades in one model,
//! coupled through a hub that moves with the airframe. A soft airframe changes the answer and
//! its equation of motion balances the rotor's loads on it, summed from every blade's loads
//! on the hub, at every step; a stiff one gives back the driven hub's answer.
mod support;

use rotorsim::hydraulics::DamperModel;
use rotorsim::overrides::Override;
use rotorsim::run::job::{DamperChoice, RunJob};
use rotorsim::run::summary::Stats;
use rotorsim::run::{ModelRun, Silent};
use std::path::Path;

const STEPS: usize = 128;

fn job(out: &Path, sets: &[String]) -> RunJob {
    let root = support::root();
    RunJob {
        rotor: root.join("rotors/uh60a.toml"),
        flight: root.join("flightdata/c8534like"),
        damper: DamperChoice::One(DamperModel::Linear),
        steps_per_rev: STEPS,
        periodic_tol: 1e-8,
        revs: 150,
        all_blades: true,
        overrides: sets.iter().map(|s| Override::parse(s).unwrap()).collect(),
        ..RunJob::new(out)
    }
}

fn run(name: &str, sets: &[String]) -> ModelRun {
    let out = support::tmp(name);
    let mut o = job(&out, sets).execute(&Silent).unwrap();
    let r = o.outcomes.remove(0).result.unwrap();
    assert!(r.periodic.converged, "{name}: {:?}", r.periodic);
    let _ = std::fs::remove_dir_all(out);
    r
}

/// An airframe in x and y (mass, spring for `hz`, damping ratio `zeta`) and, with `z`, in z.
fn airframe(mass: f64, hz: f64, zeta: f64, z: bool) -> Vec<String> {
    let k = mass * (2.0 * std::f64::consts::PI * hz).powi(2);
    let c = 2.0 * zeta * (k * mass).sqrt();
    let dirs: &[&str] = if z { &["x", "y", "z"] } else { &["x", "y"] };
    dirs.iter()
        .flat_map(|d| {
            [
                format!("airframe.{d}.mass_kg={mass}"),
                format!("airframe.{d}.stiffness_N_per_m={k}"),
                format!("airframe.{d}.damping_Ns_per_m={c}"),
            ]
        })
        .collect()
}

fn channel<'a>(r: &'a ModelRun, name: &str) -> &'a [f64] {
    r.channel(name)
        .unwrap_or_else(|| panic!("no channel {name} in {:?}", r.channel_names))
}

/// Largest difference of a channel between two runs, relative to its peak-to-peak in `a`.
fn rel_diff(a: &ModelRun, b: &ModelRun, name: &str) -> f64 {
    let (x, y) = (channel(a, name), channel(b, name));
    let ptp = Stats::of(x).peak_to_peak;
    x.iter()
        .zip(y)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max)
        / ptp
}

#[test]
fn soft_airframe_changes_the_answer_and_balances_momentum() {
    let fixed = run("airframe_fixed", &[]);
    // 15 Hz in x and y with 2% damping: just below the 4/rev (17.2 Hz) the hub passes to the
    // fixed frame, where an airframe mode moves the hub most
    let soft = run("airframe_soft", &airframe(2000.0, 15.0, 0.02, false));
    let ax = Stats::of(channel(&soft, "airframe_x_m")).peak_to_peak;
    assert!(ax > 1e-4, "the airframe moves: x peak-to-peak {ax} m");
    // the hub moves, so the blades feel it and the airframe's dynamics shape the hub loads
    let d = rel_diff(&fixed, &soft, "damper_force_N");
    assert!(
        d > 2e-3,
        "damper force moved by {d:.2e} of its peak-to-peak"
    );
    let h = rel_diff(&fixed, &soft, "hub_fx_fixed_N");
    assert!(h > 0.1, "hub x force moved by {h:.2e} of its peak-to-peak");
    // momentum: m a + c v + k u of the airframe equals the rotor's load on it (the sum of every
    // blade's loads on the hub) at every sample, within the residual tolerance of the step
    // that ended there (||r|| <= 1e-7 ||r_predictor||, in N)
    let check = soft.airframe_check.as_ref().expect("an airframe check");
    assert_eq!(check.directions.len(), 2);
    for d in &check.directions {
        assert!(d.max_hub_load > 1000.0, "{d:?}");
        assert!(
            d.max_over_step_tolerance <= 1.0,
            "{}: imbalance {} N, {} of the step's tolerance",
            d.direction,
            d.max_imbalance,
            d.max_over_step_tolerance
        );
    }
    // the whole model's Floquet multipliers, labelled by what dominates each mode
    assert!(!soft.periodic.floquet_multipliers.is_empty());
    assert!(soft
        .periodic
        .floquet_multipliers
        .iter()
        .all(|m| m.mode.starts_with("blade ") || m.mode.starts_with("airframe ")));
    // each blade's run is in the rotor's, with its own damper force
    assert_eq!(soft.blade_runs.len(), 4);
}

/// The stiffer the airframe, the closer the driven hub: the hub's motion, hence every
/// difference, falls as 1/k (quarter when the frequency doubles).
#[test]
fn stiff_airframe_converges_to_the_driven_hub() {
    let fixed = run("airframe_fixed_ref", &[]);
    // 5000 kg in x, y and z at 200 and 400 Hz: k = 7.9e9 and 3.2e10 N/m
    let s1 = run("airframe_stiff", &airframe(5000.0, 200.0, 0.05, true));
    let s2 = run("airframe_stiffer", &airframe(5000.0, 400.0, 0.05, true));
    for name in [
        "damper_force_N",
        "tip_flap_m",
        "root_fx_N",
        "root_mz_Nm",
        "hub_fx_fixed_N",
        "hub_fy_fixed_N",
        "hub_fz_fixed_N",
    ] {
        let (d1, d2) = (rel_diff(&fixed, &s1, name), rel_diff(&fixed, &s2, name));
        eprintln!(
            "{name}: {d1:.3e} at 200 Hz, {d2:.3e} at 400 Hz (ratio {:.3})",
            d2 / d1
        );
        // quasi-static size of the difference: the hub moves by F / k, the blades' inertia
        // answers with (m_rotor / M) (w / w_n)^2 of F; rotor mass at most 0.1 of the
        // airframe's (4 blades of about 100 kg on 5000 kg), w up to 8/rev in the fixed frame
        let w8 = 8.0 * 27.0 / (2.0 * std::f64::consts::PI * 200.0);
        let bound = 0.1 * w8 * w8;
        assert!(
            d1 < bound,
            "{name}: {d1:.2e} of its peak-to-peak at 200 Hz, above the quasi-static {bound:.1e}"
        );
        let ratio = d2 / d1;
        assert!(
            (0.15..0.35).contains(&ratio),
            "{name}: {d1:.2e} at 200 Hz, {d2:.2e} at 400 Hz (ratio {ratio:.3}, 1/k gives 0.25)"
        );
    }
}

/// The modal form: an x mode and a roll about a centre 1.5 m above the hub (it carries the
/// hub sideways). The x mode balances to the step's tolerance; the roll to second order in
/// its angle (its axis turns with the airframe).
#[test]
fn modal_airframe_balances_momentum() {
    let dir = support::tmp("airframe_modal_deck");
    let root = support::root();
    let text = std::fs::read_to_string(root.join("rotors/uh60a.toml"))
        .unwrap()
        .replace(
            "sections_csv = \"data/",
            &format!("sections_csv = \"{}/rotors/data/", root.display()),
        );
    let deck = dir.join("modal.toml");
    std::fs::write(
        &deck,
        format!(
            "{text}\n[[airframe.mode]]\nfrequency_Hz = 14.0\ndamping_ratio = 0.02\ngeneralized_mass_kg = 2000.0\nparticipation = {{ x = 1.0 }}\n\n[[airframe.mode]]\nfrequency_Hz = 12.0\ndamping_ratio = 0.03\ngeneralized_mass_kg = 3000.0\nparticipation = {{ y = 1.5, roll = 1.0 }}\n"
        ),
    )
    .unwrap();
    let out = support::tmp("airframe_modal");
    let j = RunJob {
        rotor: deck,
        all_blades: false,
        ..job(&out, &[])
    };
    let mut o = j.execute(&Silent).unwrap();
    let r = o.outcomes.remove(0).result.unwrap();
    assert!(r.periodic.converged, "{:?}", r.periodic);
    assert_eq!(
        r.blade_runs.len(),
        4,
        "an [airframe] implies the whole rotor"
    );
    let check = r.airframe_check.as_ref().expect("an airframe check");
    let by = |d: &str| check.directions.iter().find(|x| x.direction == d).unwrap();
    assert!(by("x").max_over_step_tolerance <= 1.0, "{:?}", by("x"));
    let roll = by("roll");
    let theta = Stats::of(channel(&r, "airframe_roll_rad")).peak_to_peak;
    assert!(
        roll.max_imbalance <= 10.0 * theta * roll.max_hub_load,
        "{roll:?}, roll peak-to-peak {theta} rad"
    );
    let _ = std::fs::remove_dir_all(out);
    let _ = std::fs::remove_dir_all(dir);
}
