//! A catalogue of bad inputs across every command of the binary. Each case writes its files
//! (shipped decks and records with edits, or inline text) into a fresh folder, runs the binary
//! and asserts: no panic, a non-zero exit within the time limit, and a message that names the
//! file and the key or line (the expected substrings). Adding a case is one line of `CASES`.
//! Every failing case is listed, not only the first.
//!
//! In `args` and `expect`, `{T}` is the case's folder and `{R}` the package root. Shipped rotor
//! decks refer to `data/...` and model decks to `../../rotors/...` relative to themselves: the
//! copies refer to the shipped files by absolute path.
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

mod support;
use support::{root, tmp};

/// Where a case's file comes from.
#[derive(Clone, Copy)]
enum Src {
    /// A shipped file (path relative to the package root).
    Repo(&'static str),
    /// Inline text.
    Text(&'static str),
    /// The first N bytes of a shipped file.
    Trunc(&'static str, usize),
    /// A shipped CSV record triple (stem relative to the package root): dst is the new stem;
    /// each edit applies to the first of the three files that holds it.
    Record(&'static str),
    /// An empty folder.
    Dir,
}
use Src::*;

/// A file of a case: destination name in the case folder, source, and edits (first
/// occurrence of `from` replaced by `to`; an edit that matches nothing fails the case).
type F = (&'static str, Src, &'static [(&'static str, &'static str)]);

struct Case {
    name: &'static str,
    files: &'static [F],
    args: &'static [&'static str],
    expect: &'static [&'static str],
}

const fn case(
    name: &'static str,
    files: &'static [F],
    args: &'static [&'static str],
    expect: &'static [&'static str],
) -> Case {
    Case {
        name,
        files,
        args,
        expect,
    }
}

const UH60A: &str = "rotors/uh60a.toml";
const DAMPER: &str = "flightdata/damper_nominal.toml";
const CANT: &str = "docs/examples/cantilever.toml";
const ACT: &str = "docs/examples/actuator_pitch_beam.toml";
/// Three cycles of a 25 Hz stroke of 1 mm with the force of a linear damper.
const BENCH_OK: &str = "time_s,stroke_m,force_N\n0.000,0.000000e+00,10681.415\n0.001,1.564345e-04,10549.909\n0.002,3.090170e-04,10158.629\n0.003,4.539905e-04,9517.210\n0.004,5.877853e-04,8641.446\n0.005,7.071068e-04,7552.901\n0.006,8.090170e-04,6278.378\n0.007,8.910065e-04,4849.261\n0.008,9.510565e-04,3300.739\n0.009,9.876883e-04,1670.941\n0.010,1.000000e-03,0.000\n0.011,9.876883e-04,-1670.941\n0.012,9.510565e-04,-3300.739\n0.013,8.910065e-04,-4849.261\n0.014,8.090170e-04,-6278.378\n0.015,7.071068e-04,-7552.901\n0.016,5.877853e-04,-8641.446\n0.017,4.539905e-04,-9517.210\n0.018,3.090170e-04,-10158.629\n0.019,1.564345e-04,-10549.909\n0.020,1.224647e-19,-10681.415\n0.021,-1.564345e-04,-10549.909\n0.022,-3.090170e-04,-10158.629\n0.023,-4.539905e-04,-9517.210\n0.024,-5.877853e-04,-8641.446\n0.025,-7.071068e-04,-7552.901\n0.026,-8.090170e-04,-6278.378\n0.027,-8.910065e-04,-4849.261\n0.028,-9.510565e-04,-3300.739\n0.029,-9.876883e-04,-1670.941\n0.030,-1.000000e-03,-0.000\n0.031,-9.876883e-04,1670.941\n0.032,-9.510565e-04,3300.739\n0.033,-8.910065e-04,4849.261\n0.034,-8.090170e-04,6278.378\n0.035,-7.071068e-04,7552.901\n0.036,-5.877853e-04,8641.446\n0.037,-4.539905e-04,9517.210\n0.038,-3.090170e-04,10158.629\n0.039,-1.564345e-04,10549.909\n0.040,-2.449294e-19,10681.415\n0.041,1.564345e-04,10549.909\n0.042,3.090170e-04,10158.629\n0.043,4.539905e-04,9517.210\n0.044,5.877853e-04,8641.446\n0.045,7.071068e-04,7552.901\n0.046,8.090170e-04,6278.378\n0.047,8.910065e-04,4849.261\n0.048,9.510565e-04,3300.739\n0.049,9.876883e-04,1670.941\n0.050,1.000000e-03,-0.000\n0.051,9.876883e-04,-1670.941\n0.052,9.510565e-04,-3300.739\n0.053,8.910065e-04,-4849.261\n0.054,8.090170e-04,-6278.378\n0.055,7.071068e-04,-7552.901\n0.056,5.877853e-04,-8641.446\n0.057,4.539905e-04,-9517.210\n0.058,3.090170e-04,-10158.629\n0.059,1.564345e-04,-10549.909\n0.060,3.673940e-19,-10681.415\n0.061,-1.564345e-04,-10549.909\n0.062,-3.090170e-04,-10158.629\n0.063,-4.539905e-04,-9517.210\n0.064,-5.877853e-04,-8641.446\n0.065,-7.071068e-04,-7552.901\n0.066,-8.090170e-04,-6278.378\n0.067,-8.910065e-04,-4849.261\n0.068,-9.510565e-04,-3300.739\n0.069,-9.876883e-04,-1670.941\n0.070,-1.000000e-03,0.000\n0.071,-9.876883e-04,1670.941\n0.072,-9.510565e-04,3300.739\n0.073,-8.910065e-04,4849.261\n0.074,-8.090170e-04,6278.378\n0.075,-7.071068e-04,7552.901\n0.076,-5.877853e-04,8641.446\n0.077,-4.539905e-04,9517.210\n0.078,-3.090170e-04,10158.629\n0.079,-1.564345e-04,10549.909\n0.080,-4.898587e-19,10681.415\n0.081,1.564345e-04,10549.909\n0.082,3.090170e-04,10158.629\n0.083,4.539905e-04,9517.210\n0.084,5.877853e-04,8641.446\n0.085,7.071068e-04,7552.901\n0.086,8.090170e-04,6278.378\n0.087,8.910065e-04,4849.261\n0.088,9.510565e-04,3300.739\n0.089,9.876883e-04,1670.941\n0.090,1.000000e-03,0.000\n0.091,9.876883e-04,-1670.941\n0.092,9.510565e-04,-3300.739\n0.093,8.910065e-04,-4849.261\n0.094,8.090170e-04,-6278.378\n0.095,7.071068e-04,-7552.901\n0.096,5.877853e-04,-8641.446\n0.097,4.539905e-04,-9517.210\n0.098,3.090170e-04,-10158.629\n0.099,1.564345e-04,-10549.909\n0.100,-1.164033e-18,-10681.415\n0.101,-1.564345e-04,-10549.909\n0.102,-3.090170e-04,-10158.629\n0.103,-4.539905e-04,-9517.210\n0.104,-5.877853e-04,-8641.446\n0.105,-7.071068e-04,-7552.901\n0.106,-8.090170e-04,-6278.378\n0.107,-8.910065e-04,-4849.261\n0.108,-9.510565e-04,-3300.739\n0.109,-9.876883e-04,-1670.941\n0.110,-1.000000e-03,0.000\n0.111,-9.876883e-04,1670.941\n0.112,-9.510565e-04,3300.739\n0.113,-8.910065e-04,4849.261\n0.114,-8.090170e-04,6278.378\n0.115,-7.071068e-04,7552.901\n0.116,-5.877853e-04,8641.446\n0.117,-4.539905e-04,9517.210\n0.118,-3.090170e-04,10158.629\n0.119,-1.564345e-04,10549.909\n0.120,-7.347881e-19,10681.415\n";

/// BENCH_OK with its time column in milliseconds under a `time_s` header.
const BENCH_MS: &str = "time_s,stroke_m,force_N\n0,0.000000e+00,10681.415\n1,1.564345e-04,10549.909\n2,3.090170e-04,10158.629\n3,4.539905e-04,9517.210\n4,5.877853e-04,8641.446\n5,7.071068e-04,7552.901\n6,8.090170e-04,6278.378\n7,8.910065e-04,4849.261\n8,9.510565e-04,3300.739\n9,9.876883e-04,1670.941\n10,1.000000e-03,0.000\n11,9.876883e-04,-1670.941\n12,9.510565e-04,-3300.739\n13,8.910065e-04,-4849.261\n14,8.090170e-04,-6278.378\n15,7.071068e-04,-7552.901\n16,5.877853e-04,-8641.446\n17,4.539905e-04,-9517.210\n18,3.090170e-04,-10158.629\n19,1.564345e-04,-10549.909\n20,1.224647e-19,-10681.415\n21,-1.564345e-04,-10549.909\n22,-3.090170e-04,-10158.629\n23,-4.539905e-04,-9517.210\n24,-5.877853e-04,-8641.446\n25,-7.071068e-04,-7552.901\n26,-8.090170e-04,-6278.378\n27,-8.910065e-04,-4849.261\n28,-9.510565e-04,-3300.739\n29,-9.876883e-04,-1670.941\n30,-1.000000e-03,-0.000\n31,-9.876883e-04,1670.941\n32,-9.510565e-04,3300.739\n33,-8.910065e-04,4849.261\n34,-8.090170e-04,6278.378\n35,-7.071068e-04,7552.901\n36,-5.877853e-04,8641.446\n37,-4.539905e-04,9517.210\n38,-3.090170e-04,10158.629\n39,-1.564345e-04,10549.909\n40,-2.449294e-19,10681.415\n41,1.564345e-04,10549.909\n42,3.090170e-04,10158.629\n43,4.539905e-04,9517.210\n44,5.877853e-04,8641.446\n45,7.071068e-04,7552.901\n46,8.090170e-04,6278.378\n47,8.910065e-04,4849.261\n48,9.510565e-04,3300.739\n49,9.876883e-04,1670.941\n50,1.000000e-03,-0.000\n51,9.876883e-04,-1670.941\n52,9.510565e-04,-3300.739\n53,8.910065e-04,-4849.261\n54,8.090170e-04,-6278.378\n55,7.071068e-04,-7552.901\n56,5.877853e-04,-8641.446\n57,4.539905e-04,-9517.210\n58,3.090170e-04,-10158.629\n59,1.564345e-04,-10549.909\n60,3.673940e-19,-10681.415\n61,-1.564345e-04,-10549.909\n62,-3.090170e-04,-10158.629\n63,-4.539905e-04,-9517.210\n64,-5.877853e-04,-8641.446\n65,-7.071068e-04,-7552.901\n66,-8.090170e-04,-6278.378\n67,-8.910065e-04,-4849.261\n68,-9.510565e-04,-3300.739\n69,-9.876883e-04,-1670.941\n70,-1.000000e-03,0.000\n71,-9.876883e-04,1670.941\n72,-9.510565e-04,3300.739\n73,-8.910065e-04,4849.261\n74,-8.090170e-04,6278.378\n75,-7.071068e-04,7552.901\n76,-5.877853e-04,8641.446\n77,-4.539905e-04,9517.210\n78,-3.090170e-04,10158.629\n79,-1.564345e-04,10549.909\n80,-4.898587e-19,10681.415\n81,1.564345e-04,10549.909\n82,3.090170e-04,10158.629\n83,4.539905e-04,9517.210\n84,5.877853e-04,8641.446\n85,7.071068e-04,7552.901\n86,8.090170e-04,6278.378\n87,8.910065e-04,4849.261\n88,9.510565e-04,3300.739\n89,9.876883e-04,1670.941\n90,1.000000e-03,0.000\n91,9.876883e-04,-1670.941\n92,9.510565e-04,-3300.739\n93,8.910065e-04,-4849.261\n94,8.090170e-04,-6278.378\n95,7.071068e-04,-7552.901\n96,5.877853e-04,-8641.446\n97,4.539905e-04,-9517.210\n98,3.090170e-04,-10158.629\n99,1.564345e-04,-10549.909\n100,-1.164033e-18,-10681.415\n101,-1.564345e-04,-10549.909\n102,-3.090170e-04,-10158.629\n103,-4.539905e-04,-9517.210\n104,-5.877853e-04,-8641.446\n105,-7.071068e-04,-7552.901\n106,-8.090170e-04,-6278.378\n107,-8.910065e-04,-4849.261\n108,-9.510565e-04,-3300.739\n109,-9.876883e-04,-1670.941\n110,-1.000000e-03,0.000\n111,-9.876883e-04,1670.941\n112,-9.510565e-04,3300.739\n113,-8.910065e-04,4849.261\n114,-8.090170e-04,6278.378\n115,-7.071068e-04,7552.901\n116,-5.877853e-04,8641.446\n117,-4.539905e-04,9517.210\n118,-3.090170e-04,10158.629\n119,-1.564345e-04,10549.909\n120,-7.347881e-19,10681.415\n";

/// run on the rigid reduction with a rotor deck r.toml.
const RUN_R: &[&str] = &[
    "run",
    "--model",
    "rigid",
    "--rotor",
    "{T}/r.toml",
    "--revs",
    "3",
    "--out",
    "{T}/out",
];
const EXPAND_R: &[&str] = &["expand", "--rotor", "{T}/r.toml"];
const RUN_COMPUTED: &[&str] = &[
    "run",
    "--rotor",
    "{T}/r.toml",
    "--airloads",
    "computed",
    "--revs",
    "3",
    "--out",
    "{T}/out",
];
const MODES_R: &[&str] = &[
    "modes",
    "--rotor",
    "{T}/r.toml",
    "--speed-fractions",
    "1",
    "--out",
    "{T}/out",
];
const BENCH_D: &[&str] = &[
    "bench",
    "--deck",
    "{T}/d.toml",
    "--peak-velocity",
    "1",
    "--cycles",
    "2",
    "--out",
    "{T}/out",
];
const STATIC_M: &[&str] = &["static", "{T}/m.toml", "--out", "{T}/out"];
const DYN_M: &[&str] = &["dynamic", "{T}/m.toml", "--out", "{T}/out"];
const MODES_M: &[&str] = &["modes", "{T}/m.toml", "--out", "{T}/out"];
const BENCH_M: &[&str] = &[
    "bench",
    "--deck",
    "{R}/flightdata/damper_nominal.toml",
    "--measured",
    "{T}/t.csv",
    "--out",
    "{T}/out",
];
const DIAG_M: &[&str] = &[
    "diagnose",
    "--deck",
    "{R}/flightdata/damper_nominal.toml",
    "--measured",
    "{T}/t.csv",
    "--out",
    "{T}/out",
];
const INSPECT: &[&str] = &["inspect", "{T}/rec"];
const RUN_FLIGHT: &[&str] = &[
    "run", "--model", "rigid", "--flight", "{T}/rec", "--revs", "3", "--out", "{T}/out",
];

const R: &[F] = &[("r.toml", Repo(UH60A), &[])];
macro_rules! rotor {
    ($from:expr, $to:expr) => {
        &[("r.toml", Repo(UH60A), &[($from, $to)])]
    };
}
macro_rules! tm4760 {
    ($from:expr, $to:expr) => {
        &[("r.toml", Repo("rotors/tm4760.toml"), &[($from, $to)])]
    };
}
macro_rules! damper {
    ($from:expr, $to:expr) => {
        &[("d.toml", Repo(DAMPER), &[($from, $to)])]
    };
}
macro_rules! cant {
    ($from:expr, $to:expr) => {
        &[("m.toml", Repo(CANT), &[($from, $to)])]
    };
}
macro_rules! act {
    ($from:expr, $to:expr) => {
        &[("m.toml", Repo(ACT), &[($from, $to)])]
    };
}
macro_rules! bench_csv {
    ($text:expr) => {
        &[("t.csv", Text($text), &[])]
    };
}
macro_rules! record {
    ($from:expr, $to:expr) => {
        &[("rec", Record("flightdata/c8534like"), &[($from, $to)])]
    };
}

#[rustfmt::skip]
const CASES: &[Case] = &[
    // ---- results that are not what they claim, aborts, vague messages ----
    case("modes rotor speed far beyond nominal", &[], &["modes", "--rotor", "{R}/rotors/tm4760.toml", "--speeds", "1e6", "--count", "4", "--out", "{T}/out"], &["--speeds", "tm4760.toml", "rotor.omega_rad_s", "beyond sense"]),
    case("modes speed list of 1e18 entries", &[], &["modes", "--rotor", "{R}/rotors/tm4760.toml", "--speeds", "0:1e9:1e-9", "--out", "{T}/out"], &["--speeds", "1.00e18 values", "10000"]),
    case("modes model deck of 200000 elements", cant!("elements = 8", "elements = 200000"), MODES_M, &["m.toml", "elements = 200000", "memory"]),
    case("modes rotor deck of 200000 elements", rotor!("elements = 13 ", "elements = 200000 "), MODES_R, &["r.toml", "blade.elements = 200000", "memory"]),
    case("decay duration 1e9 s", &[], &["decay", "--rotor", "{R}/rotors/tm4760.toml", "--duration-s", "1e9", "--out", "{T}/out"], &["tm4760.toml", "--duration-s 1e9", "memory"]),
    case("decay rotor speed 1000x nominal", &[], &["decay", "--rotor", "{R}/rotors/tm4760.toml", "--rpm", "660000", "--out", "{T}/out"], &["--rpm 660000", "tm4760.toml", "rotor.omega_rad_s", "beyond sense"]),
    case("decay --speed-rad-s 1000x nominal", &[], &["decay", "--rotor", "{R}/rotors/tm4760.toml", "--speed-rad-s", "69115", "--out", "{T}/out"], &["--speed-rad-s 69115", "tm4760.toml", "rotor.omega_rad_s", "beyond sense"]),
    case("decay step 1e-12 s", &[], &["decay", "--rotor", "{R}/rotors/tm4760.toml", "--step-s", "1e-12", "--out", "{T}/out"], &["tm4760.toml", "--step-s 1e-12"]),
    case("decay rho_inf above 1", &[], &["decay", "--rotor", "{R}/rotors/tm4760.toml", "--rho-inf", "1.5", "--out", "{T}/out"], &["--rho-inf", "expected a number in [0, 1]", "got 1.5"]),
    case("decay rho_inf NaN", &[], &["decay", "--rotor", "{R}/rotors/tm4760.toml", "--rho-inf", "nan", "--out", "{T}/out"], &["--rho-inf", "expected a number in [0, 1]", "got NaN"]),
    case("decay Newton tolerance zero", &[], &["decay", "--rotor", "{R}/rotors/tm4760.toml", "--newton-rtol", "0", "--out", "{T}/out"], &["--newton-rtol", "expected a number in (0, 1)", "got 0"]),
    case("decay Newton correction tolerance negative", &[], &["decay", "--rotor", "{R}/rotors/tm4760.toml", "--newton-xtol=-1e-9", "--out", "{T}/out"], &["--newton-xtol", "expected a number in (0, 1)", "got -0.000000001"]),
    case("decay Newton tolerance 2", &[], &["decay", "--rotor", "{R}/rotors/tm4760.toml", "--newton-rtol", "2", "--out", "{T}/out"], &["--newton-rtol", "expected a number in (0, 1)", "got 2"]),
    case("rigid run record radius 10x the deck's", record!("\"radius_m\": 8.178", "\"radius_m\": 0.8178"), RUN_FLIGHT, &["radius_m = 0.8178", "rotor.radius_m = 8.1786", "uh60a.toml"]),
    case("elastic run record radius 10x the deck's", record!("\"radius_m\": 8.178", "\"radius_m\": 81.78"), &["run", "--flight", "{T}/rec", "--revs", "3", "--out", "{T}/out"], &["radius_m = 81.78", "rotor.radius_m"]),
    case("rigid run record of a 5-bladed rotor", record!("\"number_of_blades\": 4", "\"number_of_blades\": 5"), RUN_FLIGHT, &["number_of_blades = 5", "rotor.blades = 4"]),
    case("bench chamber areas 16 m^2", damper!("A0_m2 = 1.6e-3\nA1_m2 = 1.6e-3", "A0_m2 = 16.0\nA1_m2 = 16.0"), BENCH_D, &["d.toml", "V0_m3 / A0_m2", "travel", "stroke"]),
    case("run bearing loss factor beside a damping", rotor!("pitch_loss_factor = 0.1 ", "pitch_loss_factor = 0.1\npitch_damping_Nms_per_rad = 272.0 "), RUN_R, &["r.toml", "bearing.pitch_damping_Nms_per_rad", "bearing.pitch_loss_factor", "remove one of the two"]),
    case("run bearing loss factor 1.5", rotor!("pitch_loss_factor = 0.1 ", "pitch_loss_factor = 1.5 "), RUN_R, &["r.toml", "bearing.pitch_loss_factor", "1.5", "between 0 and 1"]),
    case("run bearing elastomer reference outside its band", rotor!("pitch_loss_factor = 0.1 ", "pitch_loss_factor = 0.1\npitch_reference_per_rev = 9.0 "), RUN_R, &["r.toml", "bearing.pitch_reference_per_rev", "9", "[0.25, 4]"]),
    case("run chamber areas 16 m^2", rotor!("A0_m2 = 1.6e-3\nA1_m2 = 1.6e-3", "A0_m2 = 16.0\nA1_m2 = 16.0"), RUN_R, &["r.toml", "A1_m2 = 16", "travel"]),
    case("damper viscosity negative", damper!("dp_laminar_Pa = 1.0e3", "dp_laminar_Pa = 1.0e3\nmu_Pa_s = -0.01\norifice_length_m = 3.0e-3"), BENCH_D, &["d.toml", "mu_Pa_s"]),
    case("damper viscosity without the orifice length", damper!("dp_laminar_Pa = 1.0e3", "dp_laminar_Pa = 1.0e3\nmu_Pa_s = 0.01122"), BENCH_D, &["d.toml", "orifice_length_m"]),
    case("damper orifice length beyond 1 m", damper!("dp_laminar_Pa = 1.0e3", "dp_laminar_Pa = 1.0e3\nmu_Pa_s = 0.01122\norifice_length_m = 5.0"), BENCH_D, &["d.toml", "orifice_length_m"]),
    case("damper seal friction without its stiffness", damper!("dp_laminar_Pa = 1.0e3", "dp_laminar_Pa = 1.0e3\nseal_friction_N = 150.0"), BENCH_D, &["d.toml", "seal_presliding_stiffness_N_per_m"]),
    case("damper seal friction negative", damper!("dp_laminar_Pa = 1.0e3", "dp_laminar_Pa = 1.0e3\nseal_friction_N = -150.0\nseal_presliding_stiffness_N_per_m = 5.0e6"), BENCH_D, &["d.toml", "seal_friction_N"]),
    case("bench bulk modulus 1e30 Pa", damper!("bulk_alpha_per_Pa = 6.667e-10", "bulk_alpha_per_Pa = 1e-30"), BENCH_D, &["d.toml", "damper.physical.bulk_alpha_per_Pa = 1e-30", "stiffer than any solid"]),
    case("run bulk modulus 1e30 Pa", rotor!("bulk_alpha_per_Pa = 6.667e-10", "bulk_alpha_per_Pa = 1e-30"), RUN_R, &["r.toml", "damper.physical.bulk_alpha_per_Pa = 1e-30", "t = ", "residual"]),
    case("bench csv time in milliseconds", bench_csv!(BENCH_MS), BENCH_M, &["t.csv", "time_ms", "samples every 1 s"]),
    // ---- rotor decks (run, expand, modes --rotor) ----
    case("hinged deck hinges out of order", tm4760!("r_m = 0.0762                          # 3.00 in; free", "r_m = 0.05 #"), MODES_R, &["r.toml", "hinge[1].r_m"]),
    case("hinged deck unknown hinge axis", tm4760!("axis = \"flap\"", "axis = \"twist\""), MODES_R, &["r.toml", "twist"]),
    case("hinged deck negative hinge damping", tm4760!("damping_Nms_per_rad = 0.2867869", "damping_Nms_per_rad = -0.2867869"), MODES_R, &["r.toml", "hinge[0].damping_Nms_per_rad"]),
    case("hinged deck segment without elements", tm4760!("elements = 1", "elements = 0"), MODES_R, &["r.toml", "blade.segment[0].elements"]),
    case("hinged deck radius off the tip", tm4760!("radius_m = 1.397", "radius_m = 1.5"), MODES_R, &["r.toml", "rotor.radius_m"]),
    case("hinged deck segment EI zero", tm4760!("EI2_Nm2 = 14353.98", "EI2_Nm2 = 0.0"), MODES_R, &["r.toml", "blade.segment[0].section.EI2_Nm2"]),
    case("hinged deck given to run", tm4760!("blades = 4", "blades = 4"), RUN_R, &["r.toml", "hinged-blade"]),
    case("rotor omega NaN", rotor!("omega_rad_s = 27.0", "omega_rad_s = nan"), RUN_R, &["r.toml", "rotor.omega_rad_s"]),
    case("rotor radius negative", rotor!("radius_m = 8.1786", "radius_m = -8.1786"), EXPAND_R, &["r.toml", "radius_m"]),
    case("rotor blades zero", rotor!("blades = 4 ", "blades = 0 "), MODES_R, &["r.toml", "rotor.blades"]),
    case("rotor blades wrong type", rotor!("blades = 4 ", "blades = \"four\" "), EXPAND_R, &["r.toml", "blades"]),
    case("rotor unknown key", rotor!("[rotor]\n", "[rotor]\nomega_rpm = 258.0\n"), EXPAND_R, &["r.toml", "omega_rpm"]),
    case("rotor missing key", rotor!("radius_m = 8.1786", ""), EXPAND_R, &["r.toml", "radius_m"]),
    case("rotor blade elements zero", rotor!("elements = 13", "elements = 0"), EXPAND_R, &["r.toml", "blade.elements"]),
    case("rotor root beyond tip", rotor!("root_r_m = 0.8178", "root_r_m = 9.5"), EXPAND_R, &["r.toml", "root_r_m"]),
    case("rotor hinge outboard of horn", rotor!("hinge_r_m = 0.381", "hinge_r_m = 0.9"), EXPAND_R, &["r.toml", "hinge_r_m"]),
    case("rotor sections csv missing", rotor!("sections_csv = \"data/blade_sections_yeo.csv\"", "sections_csv = \"data/no_such_sections.csv\""), EXPAND_R, &["no_such_sections.csv"]),
    case("rotor twist not increasing", rotor!("[1.68344, 9.823]", "[1.0, 9.823]"), EXPAND_R, &["r.toml", "twist_deg"]),
    case("rotor lag stiffness negative", rotor!("lag_stiffness_Nm_per_rad = 20400.0", "lag_stiffness_Nm_per_rad = -20400.0"), RUN_R, &["r.toml", "bearing.lag_stiffness_Nm_per_rad"]),
    case("rotor link length zero", rotor!("link_length_m = 0.45", "link_length_m = 0.0"), EXPAND_R, &["r.toml", "link_length_m"]),
    case("rotor damper arm NaN", rotor!("arm_m = 0.175", "arm_m = nan"), RUN_R, &["r.toml", "arm_m"]),
    case("rotor damping gain inf", rotor!("perturbation_damping_gain = 0.01", "perturbation_damping_gain = inf"), EXPAND_R, &["r.toml", "perturbation_damping_gain"]),
    case("rotor airload frame unknown", rotor!("airload_frame = \"control_pitch\"", "airload_frame = \"sideways\""), EXPAND_R, &["r.toml", "airload_frame"]),
    case("rotor TOML syntax", rotor!("[bearing]", "[bearing"), EXPAND_R, &["r.toml", "line"]),
    case("rotor segment elements negative", rotor!("segment1 = { elements = 3", "segment1 = { elements = -3"), EXPAND_R, &["r.toml", "elements"]),
    case("rotor damper orifice negative", rotor!("A_orf_m2 = 1.8e-6", "A_orf_m2 = -1.8e-6"), RUN_R, &["r.toml", "A_orf_m2"]),
    case("rotor cyclic ramp negative", rotor!("cyclic_ramp_revs = 2.0", "cyclic_ramp_revs = -2.0"), EXPAND_R, &["r.toml", "cyclic_ramp_revs"]),
    // per-blade differences: a [blades.K...] table inserted before [damper], or a --set blades.K...
    case("rotor blade number beyond rotor.blades", rotor!("[damper]\nmodel", "[blades.5.bearing]\nlag_stiffness_Nm_per_rad = 1.0\n\n[damper]\nmodel"), EXPAND_R, &["r.toml, blades.5", "rotor.blades = 4", "blades.1 to blades.4"]),
    case("rotor blade number zero", rotor!("[damper]\nmodel", "[blades.0.bearing]\nlag_stiffness_Nm_per_rad = 1.0\n\n[damper]\nmodel"), MODES_R, &["r.toml, blades.0", "blades.1 to blades.4"]),
    case("rotor blade number not a number", rotor!("[damper]\nmodel", "[blades.third.bearing]\nlag_stiffness_Nm_per_rad = 1.0\n\n[damper]\nmodel"), RUN_R, &["r.toml, blades.third", "not a blade number"]),
    case("rotor blade entry not a table", rotor!("[damper]\nmodel", "[blades]\n2 = 1.0\n\n[damper]\nmodel"), EXPAND_R, &["r.toml, blades.2", "expected a table"]),
    case("rotor blade sets the rotor speed", rotor!("[damper]\nmodel", "[blades.2.rotor]\nomega_rad_s = 30.0\n\n[damper]\nmodel"), RUN_R, &["r.toml, blades.2.rotor.omega_rad_s", "shared by all blades"]),
    case("rotor blade damper unknown key", rotor!("[damper]\nmodel", "[blades.3.damper.physical]\nA_orf_mm2 = 4.0e-6\n\n[damper]\nmodel"), RUN_R, &["r.toml, blades.3.damper.physical.A_orf_mm2", "unknown key"]),
    case("rotor blade bearing negative", rotor!("[damper]\nmodel", "[blades.2.bearing]\nlag_stiffness_Nm_per_rad = -1.0\n\n[damper]\nmodel"), EXPAND_R, &["r.toml, blades.2.bearing.lag_stiffness_Nm_per_rad", "non-negative"]),
    case("rotor blade sections csv missing", rotor!("[damper]\nmodel", "[blades.4.blade]\nsections_csv = \"no_such_sections.csv\"\n\n[damper]\nmodel"), RUN_R, &["r.toml, blades.4.blade.sections_csv", "no_such_sections.csv"]),
    case("run --set blade number beyond rotor.blades", R, &["run", "--model", "rigid", "--rotor", "{T}/r.toml", "--revs", "3", "--out", "{T}/out", "--set", "blades.5.damper.physical.A_orf_m2=2.0e-6"], &["--set blades.5.damper.physical.A_orf_m2", "r.toml, blades.5", "rotor.blades = 4"]),
    case("run --set blade unknown key", R, &["run", "--model", "rigid", "--rotor", "{T}/r.toml", "--revs", "3", "--out", "{T}/out", "--set", "blades.3.damper.physical.A_orf_mm2=2.0e-6"], &["--set blades.3.damper.physical.A_orf_mm2", "r.toml, blades.3.damper.physical.A_orf_mm2", "unknown key"]),
    case("run --set blade without a deck key", R, &["run", "--model", "rigid", "--rotor", "{T}/r.toml", "--revs", "3", "--out", "{T}/out", "--set", "blades.2=1.0"], &["--set blades.2=1.0", "r.toml, blades.2", "blades.K.<deck key>"]),
    case("run --all-blades with the rigid model", R, &["run", "--model", "rigid", "--all-blades", "--rotor", "{T}/r.toml", "--revs", "3", "--out", "{T}/out"], &["--all-blades", "--model uh60a", "--model rigid"]),
    case("expand of blades whose dampers differ", rotor!("[damper]\nmodel", "[blades.3.damper.physical]\nA_orf_m2 = 4.0e-6\n\n[damper]\nmodel"), EXPAND_R, &["r.toml", "blade 3's damper differs", "blades.3.damper.physical.A_orf_m2"]),
    case("rotor airframe negative mass", rotor!("[damper]\nmodel", "[airframe]\nx = { mass_kg = -5000.0, stiffness_N_per_m = 8.0e5 }\n\n[damper]\nmodel"), EXPAND_R, &["r.toml, airframe.x.mass_kg", "positive", "-5000"]),
    case("rotor airframe negative stiffness", rotor!("[damper]\nmodel", "[airframe]\nroll = { inertia_kg_m2 = 9000.0, stiffness_Nm_per_rad = -1.0 }\n\n[damper]\nmodel"), EXPAND_R, &["r.toml, airframe.roll.stiffness_Nm_per_rad", "positive"]),
    case("rotor airframe unknown direction", rotor!("[damper]\nmodel", "[airframe]\nyaw = { inertia_kg_m2 = 9000.0, stiffness_Nm_per_rad = 1.0 }\n\n[damper]\nmodel"), EXPAND_R, &["r.toml", "yaw"]),
    case("run --set airframe negative damping", R, &["run", "--rotor", "{T}/r.toml", "--revs", "3", "--out", "{T}/out", "--set", "airframe.y.mass_kg=5000", "--set", "airframe.y.stiffness_N_per_m=8e5", "--set", "airframe.y.damping_Ns_per_m=-1"], &["airframe.y.damping_Ns_per_m", "non-negative"]),
    case("run --set airframe incomplete direction", R, &["run", "--rotor", "{T}/r.toml", "--revs", "3", "--out", "{T}/out", "--set", "airframe.x.mass_kg=5000"], &["--set airframe.x.mass_kg=5000", "r.toml, airframe.x", "stiffness_N_per_m"]),
    case("run --set blade airframe", R, &["run", "--rotor", "{T}/r.toml", "--revs", "3", "--out", "{T}/out", "--set", "blades.2.airframe.x.mass_kg=5000"], &["blades.2.airframe", "[airframe]"]),
    case("rotor airframe mode participation unsupported", rotor!("[damper]\nmodel", "[[airframe.mode]]\nfrequency_Hz = 3.0\ngeneralized_mass_kg = 2000.0\nparticipation = { x = 1.0, y = 0.5 }\n\n[damper]\nmodel"), EXPAND_R, &["r.toml, airframe.mode[0].participation", "roll with y"]),
    case("rotor airframe mode direction twice", rotor!("[damper]\nmodel", "[[airframe.mode]]\nfrequency_Hz = 3.0\ngeneralized_mass_kg = 2000.0\nparticipation = { y = 1.0 }\n\n[[airframe.mode]]\nfrequency_Hz = 2.0\ngeneralized_mass_kg = 900.0\nparticipation = { roll = 1.0, y = 1.2 }\n\n[damper]\nmodel"), EXPAND_R, &["r.toml, airframe.mode[1].participation", "y moves in an earlier mode"]),
    case("rotor airframe mode negative mass", rotor!("[damper]\nmodel", "[[airframe.mode]]\nfrequency_Hz = 3.0\ngeneralized_mass_kg = -2000.0\nparticipation = { z = 1.0 }\n\n[damper]\nmodel"), EXPAND_R, &["r.toml, airframe.mode[0].generalized_mass_kg", "positive"]),
    case("rotor aero chord negative", rotor!("chord_m = 0.5273", "chord_m = -0.5"), RUN_COMPUTED, &["r.toml, aero.chord_m", "positive", "-0.5"]),
    case("rotor aero inflow unknown", rotor!("inflow = \"drees\"", "inflow = \"vortex\""), RUN_COMPUTED, &["r.toml, aero.inflow", "pitt-peters", "vortex"]),
    case("rotor aero tip loss above 1", rotor!("tip_loss_factor = 0.97", "tip_loss_factor = 1.2"), RUN_COMPUTED, &["r.toml, aero.tip_loss_factor", "(0, 1]"]),
    case("rotor aero c81 missing", &[("r.toml", Repo(UH60A), &[("c81 = \"../data/airfoils/naca0012.c81\"", "c81 = \"no_such_table.c81\"")])], RUN_COMPUTED, &["r.toml, aero.airfoil", "no_such_table.c81", "cannot read"]),
    case("rotor aero c81 malformed", &[("r.toml", Repo(UH60A), &[("c81 = \"../data/airfoils/naca0012.c81\"", "c81 = \"bad.c81\"")]), ("bad.c81", Text("BAD 0012                       2 2 2 2 2 2\n       0.0    0.5\n-10.0  -1.1   -1.0\n 10.0  1.1x   1.0\n       0.0    0.5\n-10.0  0.01   0.01\n 10.0  0.01   0.01\n       0.0    0.5\n-10.0  0.0    0.0\n 10.0  0.0    0.0\n"), &[])], RUN_COMPUTED, &["bad.c81 line 4", "columns", "1.1x"]),
    case("stability speeds out of order", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10,5", "--out", "{T}/out"], &["--speeds", "must increase"]),
    case("stability speeds not finite", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "1:nan:1", "--out", "{T}/out"], &["--speeds", "finite"]),
    case("stability --damper unknown", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--damper", "magic", "--out", "{T}/out"], &["--damper", "magic"]),
    case("stability --time not a number", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--time", "25,x", "--out", "{T}/out"], &["--time", "`x` is not a number"]),
    case("stability --kick-m-s not positive", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--time", "25", "--kick-m-s", "0", "--out", "{T}/out"], &["--kick-m-s", "positive"]),
    case("stability --time-duration-s huge", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--time", "25", "--time-duration-s", "1e12", "--out", "{T}/out"], &["--time-duration-s", "steps", "shorten"]),
    case("stability --steps-per-rev out of range", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--time", "25", "--steps-per-rev", "4", "--out", "{T}/out"], &["--steps-per-rev", "8 to"]),
    case("stability --amplitudes-m out of order", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--amplitudes-m", "1e-3,1e-4", "--out", "{T}/out"], &["--amplitudes-m", "must increase"]),
    case("stability --amplitudes-m not a number", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--amplitudes-m", "1e-3,big", "--out", "{T}/out"], &["--amplitudes-m", "`big` is not a number"]),
    case("stability --amplitudes-m beyond the model", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--amplitudes-m", "0.2", "--out", "{T}/out"], &["--amplitudes-m", "deg of lag", "damper arm"]),
    case("stability --amplitude-at-rad-s alone", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--amplitude-at-rad-s", "27", "--out", "{T}/out"], &["--amplitude-at-rad-s", "needs --amplitudes-m"]),
    case("stability --hover with --time", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--hover", "--time", "25", "--out", "{T}/out"], &["--hover", "--time", "ground resonance", "--amplitudes-m, runs in hover"]),
    case("stability --hover --collective-deg out of range", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--hover", "--collective-deg", "45", "--out", "{T}/out"], &["--collective-deg 45", "-30 and 30 deg"]),
    case("stability --hover --density-kg-m3 zero", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--hover", "--density-kg-m3", "0", "--out", "{T}/out"], &["--density-kg-m3 0", "air density"]),
    case("stability --hover --speed-of-sound-m-s too low", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--hover", "--speed-of-sound-m-s", "5", "--out", "{T}/out"], &["--speed-of-sound-m-s 5", "above 100 m/s"]),
    case("stability --hover --strips too few", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--hover", "--strips", "2", "--out", "{T}/out"], &["--strips 2", "8 to 2000"]),
    case("stability --hover deck without airframe", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--hover", "--out", "{T}/out"], &["r.toml", "no [airframe]", "roll and pitch"]),
    case("stability --hover airframe only vertical", rotor!("[damper]\nmodel", "[airframe]\nz = { mass_kg = 5000.0, stiffness_N_per_m = 8.0e5 }\n\n[damper]\nmodel"), &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--hover", "--out", "{T}/out"], &["r.toml", "no direction the air-resonance model takes", "roll or pitch"]),
    case("rotor airframe rotation centre not finite", rotor!("[damper]\nmodel", "[airframe]\nroll = { inertia_kg_m2 = 9000.0, stiffness_Nm_per_rad = 1.0e5, center_z_m = nan }\n\n[damper]\nmodel"), EXPAND_R, &["r.toml, airframe.roll.center_z_m", "finite", "NaN"]),
    case("stability deck without airframe", R, &["stability", "--rotor", "{T}/r.toml", "--speeds", "10:20:5", "--out", "{T}/out"], &["r.toml", "no [airframe]", "add [airframe]"]),
    case("run --airloads unknown", R, &["run", "--rotor", "{T}/r.toml", "--airloads", "cfd", "--revs", "3", "--out", "{T}/out"], &["--airloads", "cfd", "measured, computed, hybrid or hybrid-periodic"]),
    case("rotor aero cut-out beyond the tip", rotor!("cutout_r_m = 1.220", "cutout_r_m = 9.0"), RUN_COMPUTED, &["r.toml, aero.cutout_r_m", "rotor.radius_m"]),
    case("rotor aero airfoil segments not increasing", rotor!("[[aero.airfoil]]\nr_end_m = 8.1786", "[[aero.airfoil]]\nr_end_m = 5.0\n\n[[aero.airfoil]]\nr_end_m = 4.0"), RUN_COMPUTED, &["r.toml, aero.airfoil[1].r_end_m", "increasing"]),
    case("rotor aero unknown key", rotor!("chord_m = 0.5273", "chord_mm = 0.5273"), RUN_COMPUTED, &["r.toml", "chord_mm"]),
    case("run --airloads hybrid without motion and no periodic solution", &[("r.toml", Repo(UH60A), &[]), ("rec", Record("flightdata/c8534like"), &[])], &["run", "--rotor", "{T}/r.toml", "--flight", "{T}/rec", "--airloads", "hybrid", "--revs", "3", "--out", "{T}/out"], &["hybrid airloads need the periodic solution under the measured airloads", "residual", "after 3 revolutions", "--revs"]),
    case("run --airloads computed on the rigid model", R, &["run", "--model", "rigid", "--rotor", "{T}/r.toml", "--airloads", "computed", "--revs", "3", "--out", "{T}/out"], &["--airloads computed", "--model uh60a", "--model rigid"]),
    // ---- damper decks (bench, diagnose, run --damper-deck) ----
    case("damper model unknown", damper!("model = \"physical\"", "model = \"magic\""), BENCH_D, &["d.toml", "model"]),
    case("damper linear c negative", damper!("c_N_s_per_m = 68000.0", "c_N_s_per_m = -68000.0"), BENCH_D, &["d.toml", "c_N_s_per_m"]),
    case("damper nonlinear velocities unsorted", damper!("[0.0, 0.05, 0.10, 0.20, 0.40]", "[0.0, 0.10, 0.05, 0.20, 0.40]"), BENCH_D, &["d.toml", "velocity_m_s"]),
    case("damper nonlinear lengths differ", damper!("14000.0, 15500.0]", "14000.0]"), BENCH_D, &["d.toml", "force_N"]),
    case("damper V0 zero", damper!("V0_m3 = 6.0e-5", "V0_m3 = 0.0"), BENCH_D, &["d.toml", "V0_m3"]),
    case("damper rho NaN", damper!("rho_kg_m3 = 850.0", "rho_kg_m3 = nan"), BENCH_D, &["d.toml", "rho_kg_m3"]),
    case("damper Cd zero", damper!("Cd = 0.611", "Cd = 0.0"), BENCH_D, &["d.toml", "Cd"]),
    case("damper relief mass negative", damper!("m_kg = 0.01", "m_kg = -0.01"), BENCH_D, &["d.toml", "relief_valve_0", "m_kg"]),
    case("damper missing key", damper!("A0_m2 = 1.6e-3\n", ""), BENCH_D, &["d.toml", "A0_m2"]),
    case("damper unknown key", damper!("Cd = 0.611\n", "Cd = 0.611\nCx = 1.0\n"), BENCH_D, &["d.toml", "Cx"]),
    case("damper laminar dp zero", damper!("dp_laminar_Pa = 1.0e3", "dp_laminar_Pa = 0.0"), BENCH_D, &["d.toml", "dp_laminar_Pa"]),
    case("damper check valve inf", damper!("check_valve_area_m2 = 5.0e-6", "check_valve_area_m2 = inf"), BENCH_D, &["d.toml", "check_valve_area_m2"]),
    case("damper relief spring NaN", damper!("k_N_per_m = 2.0e4", "k_N_per_m = nan"), BENCH_D, &["d.toml", "k_N_per_m"]),
    case("damper wrong type", damper!("p_s_Pa = 5.0e5", "p_s_Pa = \"high\""), &["run", "--model", "rigid", "--damper-deck", "{T}/d.toml", "--revs", "3", "--out", "{T}/out"], &["d.toml", "p_s_Pa"]),
    case("damper no [damper] table", &[("d.toml", Repo(CANT), &[])], BENCH_D, &["d.toml", "[damper]"]),
    case("damper deck diagnose bulk negative", &[("d.toml", Repo(DAMPER), &[("bulk_alpha_per_Pa = 6.667e-10", "bulk_alpha_per_Pa = -1.0")]), ("t.csv", Text(BENCH_OK), &[])], &["diagnose", "--deck", "{T}/d.toml", "--measured", "{T}/t.csv", "--out", "{T}/out"], &["d.toml", "bulk_alpha_per_Pa"]),
    case("damper leakage viscosity times land negative", damper!("[damper.physical.relief_valve_0]", "[damper.physical.extensions]\nleakage_m3_per_s_Pa = 1e-11\nleakage_viscosity_length_Pa_s_m = -1.0\n\n[damper.physical.relief_valve_0]"), BENCH_D, &["d.toml", "damper.physical.extensions.leakage_viscosity_length_Pa_s_m", "non-negative"]),
    case("damper oil without its reference temperature", damper!("[damper.physical.relief_valve_0]", "[damper.physical.oil]\ntemperature_K = 233.15\n\n[damper.physical.relief_valve_0]"), BENCH_D, &["d.toml", "damper.physical.oil.reference_temperature_K"]),
    case("damper oil temperature in C given as K", damper!("[damper.physical.relief_valve_0]", "[damper.physical.oil]\nreference_temperature_K = 293.15\ntemperature_K = -40.0\n\n[damper.physical.relief_valve_0]"), BENCH_D, &["d.toml", "damper.physical.oil.temperature_K", "150 to 600"]),
    case("damper oil coefficient NaN", damper!("[damper.physical.relief_valve_0]", "[damper.physical.oil]\nreference_temperature_K = 293.15\nviscosity_thermal_coefficient_per_K = nan\n\n[damper.physical.relief_valve_0]"), BENCH_D, &["d.toml", "damper.physical.oil.viscosity_thermal_coefficient_per_K"]),
    case("damper oil coefficient beyond sense", damper!("[damper.physical.relief_valve_0]", "[damper.physical.oil]\nreference_temperature_K = 293.15\ndensity_thermal_coefficient_per_K = 5.0\n\n[damper.physical.relief_valve_0]"), BENCH_D, &["d.toml", "damper.physical.oil.density_thermal_coefficient_per_K", "0 to 0.1"]),
    case("damper oil unknown key", damper!("[damper.physical.relief_valve_0]", "[damper.physical.oil]\nreference_temperature_K = 293.15\ntemperature_C = 20.0\n\n[damper.physical.relief_valve_0]"), BENCH_D, &["d.toml", "damper.physical.oil.temperature_C", "unknown key"]),
    case("run --set oil temperature without the oil's law", &[("d.toml", Repo(DAMPER), &[])], &["run", "--model", "rigid", "--damper-deck", "{T}/d.toml", "--revs", "3", "--out", "{T}/out", "--set", "damper.physical.oil.temperature_K=233.15"], &["--set damper.physical.oil.temperature_K", "d.toml", "reference_temperature_K"]),
    case("damper deck missing (run)", &[], &["run", "--model", "rigid", "--damper-deck", "{T}/none.toml", "--out", "{T}/out"], &["none.toml"]),
    // ---- model decks (static, dynamic, modes) ----
    case("model EA NaN", cant!("EA_N = 1e6", "EA_N = nan"), STATIC_M, &["m.toml", "EA_N"]),
    case("model mass negative", cant!("m_kg_per_m = 1.0", "m_kg_per_m = -1.0"), STATIC_M, &["m.toml", "m_kg_per_m"]),
    case("model inertia negative", cant!("I2_kgm = 5e-5", "I2_kgm = -5e-5"), DYN_M, &["m.toml", "I2_kgm"]),
    case("model elastomer on a clamp", cant!("type = \"clamp\"\nnode_b = \"beam.n0\"", "type = \"clamp\"\nnode_b = \"beam.n0\"\nelastomer = { loss_factor = 0.1, band_rad_s = [6.0, 80.0], reference_rad_s = 20.0 }"), STATIC_M, &["m.toml", "joint[0] `root`.elastomer", "free revolute axis"]),
    case("model elastomer loss factor NaN", cant!("type = \"clamp\"\nnode_b = \"beam.n0\"", "type = \"revolute\"\nnode_b = \"beam.n0\"\nstiffness_Nm_per_rad = 100.0\nelastomer = { loss_factor = nan, band_rad_s = [6.0, 80.0], reference_rad_s = 20.0 }"), STATIC_M, &["m.toml", "joint[0] `root`.elastomer", "loss factor NaN"]),
    case("model elements zero", cant!("elements = 8", "elements = 0"), STATIC_M, &["m.toml", "elements"]),
    case("model beam of zero length", cant!("end_m = [10.0, 0.0, 0.0]", "end_m = [0.0, 0.0, 0.0]"), STATIC_M, &["m.toml", "end_m"]),
    case("model start NaN", cant!("start_m = [0.0, 0.0, 0.0]", "start_m = [nan, 0.0, 0.0]"), STATIC_M, &["m.toml", "start_m"]),
    case("model e2 along beam", cant!("e2_direction = [0.0, 1.0, 0.0]", "e2_direction = [1.0, 0.0, 0.0]"), STATIC_M, &["m.toml", "e2_direction"]),
    case("model joint type unknown", cant!("type = \"clamp\"", "type = \"weld\""), STATIC_M, &["m.toml", "weld"]),
    case("model bushing lock axis unknown", cant!("type = \"clamp\"", "type = \"bushing\"\nlocked = [\"x\", \"y\", \"z\", \"rx\", \"ry\", \"yaw\"]"), STATIC_M, &["m.toml", "locked", "yaw"]),
    case("model locked on a clamp", cant!("type = \"clamp\"", "type = \"clamp\"\nlocked = [\"x\"]"), STATIC_M, &["m.toml", "locked", "bushing"]),
    case("model joint node unknown", cant!("node_b = \"beam.n0\"", "node_b = \"beam.n99\""), STATIC_M, &["m.toml", "beam.n99"]),
    case("model sensor node unknown", cant!("name = \"tip\"\nnode = \"beam.n24\"", "name = \"tip\"\nnode = \"beam.n77\""), STATIC_M, &["m.toml", "beam.n77"]),
    case("model sensor beyond beam", cant!("s_m = 0.0", "s_m = 20.0"), STATIC_M, &["m.toml", "s_m"]),
    case("model sensor name duplicate", cant!("name = \"root_reaction\"", "name = \"tip\""), STATIC_M, &["m.toml", "sensor", "tip"]),
    case("model sensor name empty", cant!("name = \"root_reaction\"", "name = \"\""), STATIC_M, &["m.toml", "sensor", "name"]),
    case("model load NaN", cant!("force_N = [0.0, 0.0, 0.05]", "force_N = [0.0, 0.0, nan]"), STATIC_M, &["m.toml", "force_N"]),
    case("model load table unsorted", cant!("[0.1, 1.0], [0.1000001, 0.0]", "[0.1, 1.0], [0.05, 0.0]"), DYN_M, &["m.toml", "time_table"]),
    case("model static load steps zero", cant!("load_steps = 2", "load_steps = 0"), STATIC_M, &["m.toml", "load_steps"]),
    case("model dynamic step zero", cant!("time_step_s = 0.1", "time_step_s = 0.0"), DYN_M, &["m.toml", "time_step_s"]),
    case("model dynamic step negative", cant!("time_step_s = 0.1", "time_step_s = -0.1"), DYN_M, &["m.toml", "time_step_s"]),
    case("model dynamic rho_inf > 1", cant!("rho_inf = 0.9", "rho_inf = 2.0"), DYN_M, &["m.toml", "rho_inf"]),
    case("dynamic option rho_inf negative", &[("m.toml", Repo(CANT), &[])], &["dynamic", "{T}/m.toml", "--rho-inf", "-0.1", "--out", "{T}/out"], &["--rho-inf", "expected a number in [0, 1]", "got -0.1"]),
    case("dynamic option Newton tolerance 1", &[("m.toml", Repo(CANT), &[])], &["dynamic", "{T}/m.toml", "--newton-rtol", "1", "--out", "{T}/out"], &["--newton-rtol", "expected a number in (0, 1)", "got 1"]),
    case("model dynamic end NaN", cant!("end_time_s = 40.0", "end_time_s = nan"), DYN_M, &["m.toml", "end_time_s"]),
    case("model dynamic end 1e12 (cost guard)", cant!("end_time_s = 40.0", "end_time_s = 1e12"), DYN_M, &["m.toml", "end_time_s"]),
    case("model dynamic table missing", cant!("[dynamic]\ntime_step_s = 0.1\nend_time_s = 40.0\nrho_inf = 0.9\nstart_from_static = true", ""), DYN_M, &["m.toml", "dynamic.time_step_s"]),
    case("model modes count zero", cant!("[static]", "[modes]\ncount = 0\n\n[static]"), MODES_M, &["m.toml", "count"]),
    case("model modes axis zero", cant!("[static]", "[modes]\naxis = [0.0, 0.0, 0.0]\n\n[static]"), MODES_M, &["m.toml", "axis"]),
    case("model modes speed NaN", cant!("[static]", "[modes]\nspeeds_rad_s = [0.0, nan]\n\n[static]"), MODES_M, &["m.toml", "speeds_rad_s"]),
    case("model unknown top-level key", cant!("title = ", "titel = \"x\"\ntitle = "), STATIC_M, &["m.toml", "titel"]),
    case("model TOML syntax", cant!("[[joint]]", "[[joint]"), STATIC_M, &["m.toml", "line"]),
    case("model revolute axis zero", act!("axis = [0.0, 1.0, 0.0]", "axis = [0.0, 0.0, 0.0]"), DYN_M, &["m.toml", "axis"]),
    case("model rigid body mass negative", act!("mass_kg = 10.0", "mass_kg = -10.0"), DYN_M, &["m.toml", "mass_kg"]),
    case("model rigid body inertia NaN", act!("inertia_kgm2 = [[0.0,", "inertia_kgm2 = [[nan,"), DYN_M, &["m.toml", "inertia_kgm2"]),
    case("model hydraulic deck missing", act!("deck = \"../../rotors/paper_table1_actuator_extend.toml\"", "deck = \"../../rotors/no_such_actuator.toml\""), DYN_M, &["m.toml", "no_such_actuator.toml"]),
    case("model hydraulic substeps zero", act!("substeps = 48", "substeps = 0"), DYN_M, &["m.toml", "substeps"]),
    case("model hydraulic scheme unknown", act!("scheme = \"rk4\"", "scheme = \"euler\""), DYN_M, &["m.toml", "scheme"]),
    case("model hydraulic table unsorted", act!("[0.5, 1.0], [1.0, 0.0]", "[0.5, 1.0], [0.2, 0.0]"), DYN_M, &["m.toml", "orifice_area_table"]),
    case("model hydraulic node unknown", act!("node_b = \"horn.n3\"", "node_b = \"horn.n9\""), DYN_M, &["m.toml", "horn.n9"]),
    case("model hydraulic position NaN", act!("position_m = [-0.16, 0.0, -0.2]", "position_m = [-0.16, nan, -0.2]"), DYN_M, &["m.toml", "position_m"]),
    case("model output_every zero", act!("output_every = 5", "output_every = 0"), DYN_M, &["m.toml", "output_every"]),
    // ---- bench CSV (bench --measured, diagnose --measured) ----
    case("bench csv no stroke column", bench_csv!("time_s,force_N\n0,0\n0.001,1\n"), BENCH_M, &["t.csv", "stroke_m"]),
    case("bench csv time not increasing", bench_csv!("time_s,stroke_m,force_N\n0.0,0.0,0\n0.002,0.001,1\n0.001,0.002,2\n"), BENCH_M, &["t.csv", "line 4", "time"]),
    case("bench csv NaN stroke", bench_csv!("time_s,stroke_m,force_N\n0.0,0.0,0\n0.001,nan,1\n0.002,0.002,2\n"), BENCH_M, &["t.csv", "line 3", "stroke_m"]),
    case("bench csv unknown unit", bench_csv!("time_s,stroke_ft,force_N\n0.0,0.0,0\n0.001,0.001,1\n"), BENCH_M, &["t.csv", "stroke_ft"]),
    case("bench csv not a number", bench_csv!("time_s,stroke_m,force_N\n0.0,0.0,0\n0.001,abc,1\n"), DIAG_M, &["t.csv", "line 3", "abc"]),
    case("bench csv empty", bench_csv!(""), BENCH_M, &["t.csv"]),
    case("bench csv header only", bench_csv!("time_s,stroke_m,force_N\n"), DIAG_M, &["t.csv", "two samples"]),
    case("bench csv short row", bench_csv!("time_s,stroke_m,force_N\n0.0,0.0,0\n0.001\n0.002,0.001,1\n"), BENCH_M, &["t.csv", "line 3"]),
    case("bench csv sampled too coarsely (diagnose)", bench_csv!("time_s,stroke_m,force_N\n0.0,0.0,0\n0.01,0.001,50\n0.02,0.0,0\n0.03,-0.001,-50\n0.04,0.0,0\n0.05,0.001,50\n0.06,0.0,0\n0.07,-0.001,-50\n0.08,0.0,0\n0.09,0.001,50\n0.10,0.0,0\n"), DIAG_M, &["t.csv", "sample rate"]),
    case("bench csv empty stroke cell (bench)", &[("t.csv", Text(BENCH_OK), &[("0.005,7.071068e-04,7552.901", "0.005,,7552.901")])], BENCH_M, &["t.csv", "line 7", "stroke_m"]),
    case("bench csv stroke dropout too long to bridge (diagnose)", &[("t.csv", Text(BENCH_OK), &[("0.005,7.071068e-04,7552.901", "0.005,,7552.901")])], DIAG_M, &["t.csv", "the stroke is missing from 0.005000 s", "1/64 of the stroking period"]),
    case("bench csv stroke dropout at the first row (diagnose)", &[("t.csv", Text(BENCH_OK), &[("0.000,0.000000e+00,10681.415", "0.000,,10681.415")])], DIAG_M, &["t.csv", "the stroke is missing from 0.000000 s", "start of the test"]),
    case("bench csv no force (diagnose)", bench_csv!("time_s,stroke_m\n0.0,0.0\n0.001,0.001\n0.002,0.002\n"), DIAG_M, &["t.csv", "force"]),
    case("bench csv oil temperature unit unknown (diagnose)", bench_csv!("time_s,stroke_m,force_N,oil_temperature_F\n0.0,0.0,0\n0.001,0.001,1\n"), DIAG_M, &["t.csv", "oil_temperature_F", "oil_temperature_C"]),
    case("bench csv oil temperature in C given as K (diagnose)", bench_csv!("time_s,stroke_m,force_N,oil_temperature_K\n0.0,0.0,0,20.0\n0.001,0.001,1,20.1\n"), DIAG_M, &["t.csv", "line 2", "oil_temperature_C"]),
    case("bench csv oil temperature empty cell (diagnose)", bench_csv!("time_s,stroke_m,force_N,oil_temperature_K\n0.0,0.0,0,293.0\n0.001,0.001,1,\n"), DIAG_M, &["t.csv", "line 3", "oil_temperature_K"]),
    case("bench csv missing file", &[], BENCH_M, &["t.csv"]),
    case("bench csv is a folder", &[("t.csv", Dir, &[])], DIAG_M, &["t.csv"]),
    case("bench csv duplicate quantity", bench_csv!("time_s,stroke_m,stroke_in,force_N\n0.0,0.0,0.0,0\n0.001,0.001,0.04,1\n"), BENCH_M, &["t.csv", "stroke"]),
    // ---- flight records (inspect, convert, run, diagnose) ----
    case("record missing", &[], INSPECT, &["rec"]),
    case("record meta wrong type", record!("\"rotor_speed_rad_s\": 27.0", "\"rotor_speed_rad_s\": \"fast\""), INSPECT, &["rec.meta.json", "rotor_speed_rad_s"]),
    case("record meta negative speed", record!("\"rotor_speed_rad_s\": 27.0", "\"rotor_speed_rad_s\": -27.0"), INSPECT, &["rec.meta.json", "rotor_speed_rad_s"]),
    case("record meta oil temperature in C", record!("\"rotor_speed_rad_s\": 27.0", "\"rotor_speed_rad_s\": 27.0, \"damper_oil_temperature_K\": 20.0"), INSPECT, &["rec.meta.json", "damper_oil_temperature_K", "150 to 600"]),
    case("record meta missing key", record!("\"rotor_speed_rad_s\": 27.0,", ""), INSPECT, &["rec.meta.json", "rotor_speed_rad_s"]),
    case("record meta not JSON", record!("\"counter\": \"8534-like\",", "\"counter\" \"8534-like\","), INSPECT, &["rec.meta.json", "line"]),
    case("record airloads wrong column", record!("normal_force_N_per_m", "normal_force_X"), INSPECT, &["rec.airloads.csv", "normal_force"]),
    case("record damper NaN", record!("0,1.406250,14125.110", "0,1.406250,nan"), INSPECT, &["rec.damper.csv", "line 3"]),
    case("record damper row deleted", record!("0,1.406250,14125.110,1.296075813e-02\n", ""), RUN_FLIGHT, &["rec.damper.csv"]),
    case("record airloads not a number", record!("0,0.000000,0.4000,1812.761", "0,0.000000,0.4000,x1812"), &["convert", "{T}/rec", "{T}/out.mcap"], &["rec.airloads.csv", "line 3"]),
    case("record meta disagrees with data", record!("\"revolutions\": 5", "\"revolutions\": 7"), INSPECT, &["rec.meta.json", "revolutions"]),
    case("mcap garbage", &[("rec.mcap", Text("this is not an mcap file\n"), &[])], &["inspect", "{T}/rec.mcap"], &["rec.mcap"]),
    case("mcap truncated (convert)", &[("rec.mcap", Trunc("flightdata/c8534like.mcap", 70000), &[])], &["convert", "{T}/rec.mcap", "{T}/out"], &["rec.mcap"]),
    case("mcap truncated (run)", &[("rec.mcap", Trunc("flightdata/c8534like.mcap", 2000), &[])], &["run", "--model", "rigid", "--flight", "{T}/rec.mcap", "--revs", "3", "--out", "{T}/out"], &["rec.mcap"]),
    case("mcap empty (diagnose)", &[("rec.mcap", Text(""), &[])], &["diagnose", "--rotor", "{R}/rotors/uh60a.toml", "--flight", "{T}/rec.mcap", "--out", "{T}/out"], &["rec.mcap"]),
    // ---- paths ----
    case("model deck missing", &[], STATIC_M, &["m.toml"]),
    case("model deck is a folder", &[("m.toml", Dir, &[])], DYN_M, &["m.toml"]),
    case("rotor deck is a folder", &[("r.toml", Dir, &[])], EXPAND_R, &["r.toml"]),
    case("rotor deck missing (modes)", &[], MODES_R, &["r.toml"]),
    case("out under a file (run)", &[("f", Text("x"), &[])], &["run", "--model", "rigid", "--revs", "3", "--out", "{T}/f/out"], &["{T}/f"]),
    case("out is a file (static)", &[("m.toml", Repo(CANT), &[]), ("o", Text("x"), &[])], &["static", "{T}/m.toml", "--out", "{T}/o"], &["{T}/o"]),
    case("out under a file (verify)", &[("f", Text("x"), &[])], &["verify", "--out", "{T}/f/v"], &["{T}/f"]),
    case("out under a file (bench)", &[("f", Text("x"), &[])], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--peak-velocity", "1", "--cycles", "2", "--out", "{T}/f/b"], &["{T}/f"]),
    case("out is a non-result folder", &[("o/notes.txt", Text("mine"), &[])], &["run", "--model", "rigid", "--revs", "3", "--out", "{T}/o"], &["{T}/o"]),
    case("convert output under a file", &[("f", Text("x"), &[])], &["convert", "{R}/flightdata/c8534like", "{T}/f/x.mcap"], &["{T}/f"]),
    case("initial state missing", &[], &["run", "--model", "rigid", "--revs", "3", "--initial-state", "{T}/state.json", "--out", "{T}/out"], &["state.json"]),
    case("out under a file (dynamic)", &[("m.toml", Repo(CANT), &[]), ("f", Text("x"), &[])], &["dynamic", "{T}/m.toml", "--out", "{T}/f/d"], &["{T}/f"]),
    // ---- options ----
    case("run revs not a number", &[], &["run", "--revs", "abc", "--out", "{T}/out"], &["--revs", "abc"]),
    case("run revs 1e9 (cost guard)", &[], &["run", "--model", "rigid", "--revs", "1000000000", "--out", "{T}/out"], &["--revs"]),
    case("run damper unknown", &[], &["run", "--damper", "magic", "--out", "{T}/out"], &["--damper", "magic"]),
    case("run periodic-tol negative", &[], &["run", "--model", "rigid", "--periodic-tol=-1", "--out", "{T}/out"], &["--periodic-tol"]),
    case("run periodic-tol NaN", &[], &["run", "--model", "rigid", "--periodic-tol", "nan", "--out", "{T}/out"], &["--periodic-tol"]),
    case("run steps-per-rev zero", &[], &["run", "--model", "rigid", "--steps-per-rev", "0", "--out", "{T}/out"], &["--steps-per-rev"]),
    case("run substeps zero", &[], &["run", "--model", "rigid", "--substeps", "0", "--out", "{T}/out"], &["--substeps"]),
    case("run scheme unknown", &[], &["run", "--scheme", "euler", "--out", "{T}/out"], &["--scheme", "euler"]),
    case("run rk4 at an unstable sub-step (viscous orifice)", &[], &["run", "--rotor", "rotors/uh60a_hover.toml", "--scheme", "rk4", "--out", "{T}/out"], &["--scheme rk4", "--substeps 59"]),
    case("run model unknown", &[], &["run", "--model", "stiff", "--out", "{T}/out"], &["--model", "stiff"]),
    case("run newton unknown", &[], &["run", "--newton", "half", "--out", "{T}/out"], &["--newton", "half"]),
    case("run periodic unknown", &[], &["run", "--periodic", "guess", "--out", "{T}/out"], &["--periodic", "guess"]),
    case("run steps-per-rev huge (cost guard)", &[], &["run", "--model", "rigid", "--steps-per-rev", "4000000000", "--revs", "3", "--out", "{T}/out"], &["--steps-per-rev"]),
    case("bench omega NaN", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--omega", "nan", "--out", "{T}/out"], &["--omega"]),
    case("bench omega negative", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--omega=-27", "--out", "{T}/out"], &["--omega"]),
    case("bench peak velocity list", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--peak-velocity", "1,x", "--out", "{T}/out"], &["--peak-velocity", "x"]),
    case("bench peak velocity negative", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--peak-velocity=-1", "--out", "{T}/out"], &["--peak-velocity"]),
    case("bench velocity unit unknown", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--velocity-unit", "furlong/s", "--out", "{T}/out"], &["--velocity-unit", "furlong"]),
    case("bench cycles zero", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--cycles", "0", "--out", "{T}/out"], &["--cycles"]),
    case("bench integrator unknown", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--integrator", "euler", "--out", "{T}/out"], &["--integrator", "euler"]),
    case("bench damper unknown", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--damper", "magic", "--out", "{T}/out"], &["--damper", "magic"]),
    case("bench skip-cycles beyond the data", bench_csv!(BENCH_OK), &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--measured", "{T}/t.csv", "--skip-cycles", "5", "--out", "{T}/out"], &["--skip-cycles 5", "t.csv", "3.00 cycles"]),
    case("bench skip-cycles with no cycle", bench_csv!("time_s,stroke_m,force_N\n0.0,0.0,0\n0.001,0.001,1\n0.002,0.002,2\n"), &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--measured", "{T}/t.csv", "--skip-cycles", "1", "--out", "{T}/out"], &["--skip-cycles", "t.csv", "cycle"]),
    case("bench skip-cycles without a replay", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--skip-cycles", "2", "--out", "{T}/out"], &["--skip-cycles", "--measured"]),
    case("bench skip-cycles not a number", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--skip-cycles", "two", "--out", "{T}/out"], &["--skip-cycles", "two"]),
    case("bench output-rate zero", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--output-rate", "0", "--out", "{T}/out"], &["--output-rate", "positive"]),
    case("bench output-rate negative", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--output-rate=-5000", "--out", "{T}/out"], &["--output-rate", "positive"]),
    case("bench output-rate NaN", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--output-rate", "nan", "--out", "{T}/out"], &["--output-rate"]),
    case("bench output-rate below the step rate", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--output-rate", "100", "--out", "{T}/out"], &["--output-rate 100", "step rate 1100.9 Hz"]),
    case("bench output-rate with a replay", bench_csv!(BENCH_OK), &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--measured", "{T}/t.csv", "--output-rate", "5000", "--out", "{T}/out"], &["--output-rate", "--measured"]),
    case("bench cycles huge (cost guard)", &[], &["bench", "--deck", "{R}/flightdata/damper_nominal.toml", "--cycles", "1000000000", "--out", "{T}/out"], &["--cycles"]),
    case("modes speeds malformed", R, &["modes", "--rotor", "{T}/r.toml", "--speeds", "1:a", "--out", "{T}/out"], &["--speeds"]),
    case("modes speeds step zero", R, &["modes", "--rotor", "{T}/r.toml", "--speeds", "0:1:0", "--out", "{T}/out"], &["--speeds"]),
    case("modes count zero", R, &["modes", "--rotor", "{T}/r.toml", "--count", "0", "--out", "{T}/out"], &["--count"]),
    case("modes without a deck", &[], &["modes", "--out", "{T}/out"], &["<DECK>"]),
    case("expand revs zero", R, &["expand", "--rotor", "{T}/r.toml", "--revs", "0"], &["--revs"]),
    case("expand damper unknown", R, &["expand", "--rotor", "{T}/r.toml", "--damper", "all"], &["--damper"]),
    case("expand flight missing", R, &["expand", "--rotor", "{T}/r.toml", "--flight", "{T}/nothing"], &["nothing"]),
    case("diagnose max-substep negative", bench_csv!(BENCH_OK), &["diagnose", "--deck", "{R}/flightdata/damper_nominal.toml", "--measured", "{T}/t.csv", "--max-substep=-1", "--out", "{T}/out"], &["--max-substep"]),
    case("diagnose fit-cycles zero", bench_csv!(BENCH_OK), &["diagnose", "--deck", "{R}/flightdata/damper_nominal.toml", "--measured", "{T}/t.csv", "--fit-cycles", "0", "--out", "{T}/out"], &["--fit-cycles"]),
    case("diagnose rotor model unknown", &[], &["diagnose", "--rotor", "{R}/rotors/uh60a.toml", "--flight", "{R}/flightdata/c8534like", "--model", "sdof", "--out", "{T}/out"], &["--model", "sdof"]),
    case("diagnose nothing to diagnose", &[], &["diagnose", "--deck", "{R}/flightdata/damper_nominal.toml", "--out", "{T}/out"], &["--measured"]),
    case("unknown command", &[], &["simulate"], &["simulate"]),    case("sweep jobs zero", &[], &["sweep", "sweeps/ci_rigid.toml", "--out", "{T}/out", "--jobs", "0"], &["--jobs", "at least 1"]),
    case("sweep shards zero", &[], &["sweep", "sweeps/ci_rigid.toml", "--out", "{T}/out", "--emit-slurm", "{T}/job.sh", "--shards", "0"], &["--shards", "at least 1"]),
    case("sweep plan of 10^9 cases (size guard)", &[("p.toml", Text("[base]\nmodel = \"rigid\"\n[vary]\nrevs = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\nsubsteps = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\nsteps_per_rev = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n\"damper.physical.A_orf_m2\" = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n\"damper.physical.Cd\" = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n\"damper.physical.rho_kg_m3\" = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n\"damper.physical.V0_m3\" = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n\"damper.physical.V1_m3\" = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n\"bearing.lag_damping_Nms_per_rad\" = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\n"), &[])], &["sweep", "{T}/p.toml", "--out", "{T}/out"], &["{T}/p.toml", "1000000000 cases", "\"revs\" 10 x", "beyond the 1000000"]),
    case("sweep stability case speeds out of order", &[("p.toml", Text("[base]\nrotor = \"rotors/uh60a_airframe.toml\"\nstability_speeds = \"30,20\"\n[vary]\n\"damper.linear.c_N_s_per_m\" = [68000.0]\n"), &[])], &["sweep", "{T}/p.toml", "--out", "{T}/out"], &["case c001: stability_speeds", "must increase"]),
    case("sweep stability case with a run option", &[("p.toml", Text("[base]\nrotor = \"rotors/uh60a_airframe.toml\"\nstability_speeds = \"20:30:5\"\nflight = \"flightdata/c8534like\"\n[vary]\n\"damper.linear.c_N_s_per_m\" = [68000.0]\n"), &[])], &["sweep", "{T}/p.toml", "--out", "{T}/out"], &["case c001", "flight", "not an option of a stability case"]),
    case("sweep stability case without an airframe", &[("p.toml", Text("[base]\nrotor = \"rotors/uh60a.toml\"\nstability_speeds = \"20:30:5\"\n[vary]\n\"damper.linear.c_N_s_per_m\" = [68000.0]\n"), &[])], &["sweep", "{T}/p.toml", "--out", "{T}/out"], &["case c001", "rotors/uh60a.toml", "no [airframe]"]),
    case("sensitivity --vary unknown key", R, &["sensitivity", "--rotor", "{T}/r.toml", "--model", "rigid", "--vary", "bearing.lag_damping_Nms_per_radian=1:2", "--out", "{T}/out"], &["--vary bearing.lag_damping_Nms_per_radian=1:2", "{T}/r.toml", "no value at `bearing.lag_damping_Nms_per_radian`"]),
    case("sensitivity --vary LOW above HIGH", R, &["sensitivity", "--rotor", "{T}/r.toml", "--vary", "bearing.lag_damping_Nms_per_rad=544:136", "--out", "{T}/out"], &["--vary", "bearing.lag_damping_Nms_per_rad=544:136", "LOW (544) must be below HIGH (136)"]),
    case("sensitivity --vary not a number", R, &["sensitivity", "--rotor", "{T}/r.toml", "--vary", "bearing.lag_damping_Nms_per_rad=low:544", "--out", "{T}/out"], &["--vary", "LOW `low` is not a finite number"]),
    case("sensitivity --vary without a range", R, &["sensitivity", "--rotor", "{T}/r.toml", "--vary", "bearing.lag_damping_Nms_per_rad=136", "--out", "{T}/out"], &["--vary", "expected LOW:HIGH"]),
    case("sensitivity --vary value the deck refuses", R, &["sensitivity", "--rotor", "{T}/r.toml", "--model", "rigid", "--vary", "bearing.lag_damping_Nms_per_rad=-5:10", "--out", "{T}/out"], &["--vary bearing.lag_damping_Nms_per_rad=-5:10", "bearing.lag_damping_Nms_per_rad"]),
    case("sensitivity --vary a table", R, &["sensitivity", "--rotor", "{T}/r.toml", "--model", "rigid", "--vary", "pitch_control.link_section=1:2", "--out", "{T}/out"], &["--vary pitch_control.link_section=1:2", "not a number"]),
    case("sensitivity deck without ASSUMED labels", &[("r.toml", Repo("rotors/hammond1974.toml"), &[("# ASSUMED", "# chosen"), ("# ASSUMED", "# chosen"), ("# ASSUMED", "# chosen"), ("# ASSUMED", "# chosen")])], &["sensitivity", "--rotor", "{T}/r.toml", "--out", "{T}/out"], &["nothing to vary", "--rotor {T}/r.toml", "labels no value `# ASSUMED`"]),
    case("sensitivity deck the rotor reader refuses", &[("r.toml", Repo("rotors/hammond1974.toml"), &[("omega_rad_s = 25.0", "omega_rad_s = -25.0")])], &["sensitivity", "--rotor", "{T}/r.toml", "--out", "{T}/out"], &["--rotor {T}/r.toml", "rotor.omega_rad_s"]),
    case("sensitivity --damper all", R, &["sensitivity", "--rotor", "{T}/r.toml", "--damper", "all", "--out", "{T}/out"], &["--damper all", "one damper model"]),
    case("sweep case deck value out of range", &[("p.toml", Text("[base]\nmodel = \"rigid\"\n[vary]\n\"damper.physical.A_orf_m2\" = [1.8e-6, -1.0e-6]\n"), &[])], &["sweep", "{T}/p.toml", "--out", "{T}/out"], &["{T}/p.toml", "case c002", "damper.physical.A_orf_m2", "-0.000001"]),
];

fn subst(s: &str, t: &Path) -> String {
    s.replace("{T}", &t.display().to_string())
        .replace("{R}", &root().display().to_string())
}

/// Writes a case's files; Err names an edit that matched nothing.
fn write_files(dir: &Path, files: &[F]) -> Result<(), String> {
    for &(dst, src, edits) in files {
        let path = dir.join(dst);
        if let Some(p) = path.parent() {
            std::fs::create_dir_all(p).unwrap();
        }
        let mut texts: Vec<(PathBuf, String)> = match src {
            Repo(p) => vec![(
                path.clone(),
                std::fs::read_to_string(root().join(p)).unwrap(),
            )],
            Text(t) => vec![(path.clone(), t.to_string())],
            Trunc(p, n) => {
                let b = std::fs::read(root().join(p)).unwrap();
                std::fs::write(&path, &b[..n.min(b.len())]).unwrap();
                vec![]
            }
            Record(stem) => ["meta.json", "airloads.csv", "damper.csv"]
                .iter()
                .map(|ext| {
                    let s = std::fs::read_to_string(root().join(format!("{stem}.{ext}"))).unwrap();
                    (dir.join(format!("{dst}.{ext}")), s)
                })
                .collect(),
            Dir => {
                std::fs::create_dir_all(&path).unwrap();
                vec![]
            }
        };
        for &(from, to) in edits {
            let Some(t) = texts.iter_mut().find(|(_, t)| t.contains(from)) else {
                return Err(format!("edit `{from}` matches nothing in {dst}"));
            };
            t.1 = t.1.replacen(from, to, 1);
        }
        for (p, t) in texts {
            std::fs::write(p, support::absolutize(t)).unwrap();
        }
    }
    Ok(())
}

const LIMIT: Duration = Duration::from_secs(30);

/// Runs one case; Err says how it failed.
fn run_case(i: usize, c: &Case) -> Result<(), String> {
    let dir = tmp(&format!("bad{i}"));
    write_files(&dir, c.files)?;
    let args: Vec<String> = c.args.iter().map(|a| subst(a, &dir)).collect();
    let mut child = Command::new(env!("CARGO_BIN_EXE_rotorsim"))
        .args(&args)
        .current_dir(root())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = child.stderr.take().unwrap();
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut stderr, &mut s);
        s
    });
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        if start.elapsed() > LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let err = reader.join().unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let Some(status) = status else {
        return Err(format!("still running after {LIMIT:?} (hang)"));
    };
    let mut why = Vec::new();
    if status.code() == Some(101) || err.contains("panicked") {
        why.push("panicked".to_string());
    }
    if status.success() {
        why.push("exit 0 (wrong success)".to_string());
    }
    if status.code().is_none() {
        why.push(format!("killed by a signal ({status})"));
    }
    for e in c.expect {
        let e = subst(e, &dir);
        if !err.contains(&e) {
            why.push(format!("message lacks `{e}`"));
        }
    }
    if why.is_empty() {
        Ok(())
    } else {
        // the last lines of stderr: the error, not the progress before it
        let lines: Vec<&str> = err.trim().lines().collect();
        let tail = match lines.iter().position(|l| l.starts_with("error")) {
            Some(k) => lines[k..].join("\n              "),
            None => lines[lines.len().saturating_sub(2)..].join("\n              "),
        };
        Err(format!("{}\n      stderr: {tail}", why.join("; ")))
    }
}

#[test]
fn every_bad_input_is_refused_with_file_and_key_named() {
    assert!(CASES.len() >= 60, "{} cases", CASES.len());
    let only = std::env::var("BAD_INPUTS_ONLY").ok();
    let failures = std::sync::Mutex::new(Vec::new());
    let next = std::sync::atomic::AtomicUsize::new(0);
    std::thread::scope(|s| {
        for _ in 0..2 {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                let Some(c) = CASES.get(i) else { break };
                if only.as_deref().is_some_and(|o| !c.name.contains(o)) {
                    continue;
                }
                if let Err(e) = run_case(i, c) {
                    failures
                        .lock()
                        .unwrap()
                        .push(format!("  [{i}] {}: {e}", c.name));
                }
            });
        }
    });
    let mut f = failures.into_inner().unwrap();
    f.sort();
    assert!(
        f.is_empty(),
        "{} of {} bad inputs not refused as they should be:\n{}",
        f.len(),
        CASES.len(),
        f.join("\n")
    );
}

#[test]
fn case_names_are_unique() {
    let mut names: Vec<_> = CASES.iter().map(|c| c.name).collect();
    names.sort_unstable();
    let n = names.len();
    names.dedup();
    assert_eq!(names.len(), n, "two cases share a name");
}
