//! The pitch-link load's contributors (docs/loads.md, "Pitch-link contributors"): they sum to
//! the link load, the bearing's part splits per harmonic into its spring and its damping as
//! its constitutive law says, and the arm is the horn's geometry.
//! Run: `cargo test --release --test pitch_link_contributors`.
mod support;

use rotorsim::rotor::deck::BearingAxis;
use rotorsim::rotor::loads::{PITCH_LINK_ARM_CHANNEL, PITCH_LINK_CONTRIBUTOR_CHANNELS};
use rotorsim::rotor::RotorDeck;
use rotorsim::structure::elastomer::MaxwellChain;
use std::path::Path;

/// Harmonic n of a uniformly sampled revolution, `(a, b)` of `a cos + b sin`.
fn harmonic(x: &[f64], n: usize) -> (f64, f64) {
    let len = x.len() as f64;
    x.iter().enumerate().fold((0.0, 0.0), |(a, b), (k, v)| {
        let t = 2.0 * std::f64::consts::PI * (n * k) as f64 / len;
        (a + 2.0 * v * t.cos() / len, b + 2.0 * v * t.sin() / len)
    })
}

fn run(out: &Path, rotor: &Path) {
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .current_dir(support::root())
        .args(["run", "--damper", "linear", "--rotor"])
        .arg(rotor)
        .arg("--out")
        .arg(out)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The summary's row `name` of the breakdown: amplitudes 1..5/rev.
fn row(summary: &serde_json::Value, name: &str) -> Vec<f64> {
    let rows = summary["models"]["linear"]["loads"]["pitch_link_contributors"]["rows"]
        .as_array()
        .unwrap();
    let r = rows
        .iter()
        .find(|r| r["name"].as_str().unwrap().starts_with(name))
        .unwrap_or_else(|| panic!("no row {name}"));
    r["amplitude_n"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap_or(f64::NAN))
        .collect()
}

/// Checks one run: the balance, the arm, and the bearing's split against `stiffness(n)`, the
/// bearing's storage and loss stiffness (K', K'') at n/rev [N m/rad].
fn check(out: &Path, stiffness: impl Fn(usize) -> (f64, f64)) {
    let col = support::csv_columns(&out.join("linear/last_rev.csv"));
    let link = col("pitch_link_force_N");
    let parts: Vec<Vec<f64>> = PITCH_LINK_CONTRIBUTOR_CHANNELS
        .iter()
        .map(|c| col(c))
        .collect();
    let scale = link.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // The contributors are the moment balance about the pitch axis of the blade outboard of
    // the bearing, from independent quantities: the link's tension at mid-length (its beam's
    // recovery), its joint's multipliers at the horn, the bearing's constitutive moment and
    // the blade's load densities. They agree to the structural step's Newton tolerance.
    let mut worst = 0.0f64;
    for i in 0..link.len() {
        let sum: f64 = parts.iter().map(|p| p[i]).sum();
        worst = worst.max((link[i] - sum).abs() / scale);
    }
    eprintln!("balance: worst |link - sum| / max |link| = {worst:.2e}");
    assert!(
        worst < 1e-4,
        "contributors miss the link load by {worst:.2e}"
    );
    // The link's own part (its shear at the horn, its upper half's 0.5 kg) is small: a wrong
    // arm would put the difference between the link's tension and the horn's moment here.
    let own = parts[4].iter().fold(0.0f64, |m, v| m.max(v.abs()));
    eprintln!("link's own part: {own:.1} N of {scale:.0} N");
    assert!(own < 0.02 * scale, "{own} N");
    // The arm: the 0.20 m horn turned by the bearing's pitch, tension pitching nose down. The
    // link leans from the vertical by at most 0.20 (1 - cos theta) / 0.45 and the flap and lag
    // angles tilt the pitch axis by a few degrees: under 2% at the deck's angles.
    let arm = col(PITCH_LINK_ARM_CHANNEL);
    let pitch = col("pitch_bearing_rad");
    for (a, th) in arm.iter().zip(&pitch) {
        let want = -0.20 * th.cos();
        assert!((a / want - 1.0).abs() < 0.02, "arm {a} at pitch {th}");
    }
    // The bearing's split per harmonic: its moment in phase with the pitch angle, K' |psi_n|,
    // and in quadrature, K'' |psi_n|, over the mean arm (K' and K'' from the closed form).
    // The moment is stepped at second order, (n Omega h)^2 / 12 = 5e-5 at 1/rev with 256
    // steps, and periodic to about 1e-5: 2e-3 of the 1/rev's size holds at 1 to 3/rev.
    let inv_arm = arm.iter().map(|a| 1.0 / a.abs()).sum::<f64>() / arm.len() as f64;
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let spring = row(&summary, "bearing in phase");
    let damping = row(&summary, "bearing in quadrature");
    let size = {
        let (a, b) = harmonic(&pitch, 1);
        let (ks, kl) = stiffness(1);
        ks.hypot(kl) * a.hypot(b) * inv_arm
    };
    for n in 1..=3 {
        let (a, b) = harmonic(&pitch, n);
        let (ks, kl) = stiffness(n);
        let (ws, wl) = (ks * a.hypot(b) * inv_arm, kl * a.hypot(b) * inv_arm);
        eprintln!(
            "{n}/rev: spring {:.1} N (K' |psi| / arm {ws:.1}), damping {:.1} N (K'' |psi| / arm {wl:.1})",
            spring[n - 1],
            damping[n - 1]
        );
        assert!((spring[n - 1] - ws).abs() < 2e-3 * size, "{n}/rev spring");
        assert!((damping[n - 1] - wl).abs() < 2e-3 * size, "{n}/rev damping");
    }
}

#[test]
fn the_shipped_elastomer_bearing() {
    let out = support::tmp("pitch_link_elastomer");
    let rotor = support::root().join("rotors/uh60a.toml");
    run(&out, &rotor);
    // the reference: the fitted chain's closed-form loss stiffness, not the run's stepping
    let d = RotorDeck::from_file(&rotor).unwrap();
    let om = d.spec.rotor.omega_rad_s;
    let b = &d.spec.bearing;
    let e = b.elastomer(BearingAxis::Pitch, om).expect("an elastomer");
    let c = MaxwellChain::fit(
        b.pitch_k,
        e.loss_factor,
        e.band_rad_s[0],
        e.band_rad_s[1],
        e.reference_rad_s,
    )
    .unwrap();
    check(&out, |n| c.complex(n as f64 * om));
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_dashpot_bearing_damps_as_c_psi_dot() {
    // The pitch axis a spring of 2000 N m/rad and a dashpot of 272 N m s/rad (the deck's
    // former values): its parts are k |psi_n| and c n Omega |psi_n| over the arm.
    let dir = support::tmp("pitch_link_dashpot");
    std::fs::create_dir_all(&dir).unwrap();
    let r = support::root();
    let text = support::absolutize(
        std::fs::read_to_string(r.join("rotors/uh60a.toml"))
            .unwrap()
            .replace(
                "pitch_loss_factor = 0.1 ",
                "pitch_damping_Nms_per_rad = 272.0 ",
            ),
    );
    assert!(text.contains("pitch_damping_Nms_per_rad = 272.0"));
    let rotor = dir.join("r.toml");
    std::fs::write(&rotor, text).unwrap();
    let out = dir.join("out");
    run(&out, &rotor);
    let om = RotorDeck::from_file(&rotor).unwrap().spec.rotor.omega_rad_s;
    check(&out, |n| (2000.0, 272.0 * n as f64 * om));
    let _ = std::fs::remove_dir_all(&dir);
}
