//! `rotorsim modes`: natural frequencies and mode shapes of a model deck, about the
//! static equilibrium, optionally in a frame rotating at each of `[modes] speeds_rad_s` (fan).
//! `rotorsim modes --rotor DECK --speeds 0:1.2:0.1`: fan plot of a rotor deck with
//! the digitized UH-60A reference over it (src/rotor/fan.rs).
use crate::io::{csv_string, OutDir};
use crate::rotor::MAX_SPEED_FRACTION;
use crate::solver::modal::{modes, ModalOptions, Mode};
use crate::solver::statics::check_constraints;
use crate::solver::{static_solve, State, StaticOptions};
use crate::structure::deck::load_deck_within;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ModesArgs {
    /// Model deck (TOML, see docs/model_deck.md); or give --rotor.
    #[arg(required_unless_present = "rotor", conflicts_with = "rotor")]
    pub deck: Option<PathBuf>,
    /// Rotor deck (docs/rotor_deck.md): fan plot over the speeds of --speeds.
    #[arg(long)]
    pub rotor: Option<PathBuf>,
    /// Rotor speeds as fractions of the nominal Omega, START:STOP:STEP (inclusive) or a
    /// comma-separated list.
    #[arg(long, default_value = "0:1.2:0.1")]
    pub speeds: String,
    /// Digitized reference fan plot drawn over the model's (default: the UH-60A fan plot of
    /// ../shared/data/uh60a/raw/ next to the source tree, when present).
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Modes per speed (rotor decks).
    #[arg(long, default_value_t = 14)]
    pub count: usize,
    /// Output directory (modes.csv, mode_shapes.csv, fan.csv).
    #[arg(long)]
    pub out: PathBuf,
}

fn mode_rows(ms: &[Mode]) -> Vec<Vec<f64>> {
    ms.iter()
        .enumerate()
        .map(|(i, m)| {
            vec![
                (i + 1) as f64,
                m.freq_hz,
                m.omega_rad_s,
                m.damping_ratio,
                m.fractions[0],
                m.fractions[1],
                m.fractions[2],
                m.fractions[3],
            ]
        })
        .collect()
}

pub fn run(args: ModesArgs) -> anyhow::Result<()> {
    if let Some(r) = &args.rotor {
        return run_rotor(r, &args);
    }
    let path = args
        .deck
        .clone()
        .ok_or_else(|| anyhow::anyhow!("give a model deck or --rotor"))?;
    let (deck, mut model) = load_deck_within(&path, |d| {
        let (ndof, _) = d.size_estimate();
        let hint = match d.beams.iter().max_by_key(|b| b.elements) {
            Some(b) => format!(
                "the largest element count is [[beam]] `{}` elements = {}; use fewer or longer elements",
                b.name, b.elements
            ),
            None => "use fewer nodes, bodies or joints".into(),
        };
        crate::solver::budget::dense_modal_of(ndof)
            .check(
                &format!("modal analysis of {ndof:.0} unknowns (dense)"),
                &hint,
            )
            .map_err(|e| e.to_string())
    })?;
    let file = path.display().to_string();
    let st0 = State::from_model(&model);
    check_constraints(&mut model, &st0).map_err(|e| anyhow::anyhow!("deck {file}: {e}"))?;
    let out = OutDir::create(&args.out, &deck.input_files(&path))?;
    let md = &deck.modes;
    let axis = md.axis;
    let na = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    let mut speeds = vec![0.0];
    speeds.extend(md.speeds_rad_s.iter().copied().filter(|&s| s != 0.0));
    let header = [
        "mode",
        "freq_Hz",
        "omega_rad_s",
        "damping_ratio",
        "flap_fraction",
        "lag_fraction",
        "torsion_fraction",
        "axial_fraction",
    ];
    let mut fan = vec![];
    let mut st = st0.clone();
    for (k, &sp) in speeds.iter().enumerate() {
        let omega = [axis[0] / na * sp, axis[1] / na * sp, axis[2] / na * sp];
        let rot = if sp != 0.0 { Some(omega) } else { None };
        let opts = StaticOptions {
            load_steps: deck.statics.load_steps,
            omega: rot,
            ..Default::default()
        };
        if let Err(e) = static_solve(&mut model, &mut st, &opts, |_, _, _, _| {}) {
            out.mark_incomplete(&format!("equilibrium at {sp} rad/s failed: {e}"))?;
            anyhow::bail!("equilibrium at Omega = {sp} rad/s: {e}");
        }
        let ms = match modes(
            &mut model,
            &st,
            &ModalOptions {
                n_modes: md.count,
                omega: rot,
                shift_rad_s: 0.0,
            },
        ) {
            Ok(m) => m,
            Err(e) => {
                out.mark_incomplete(&e.to_string())?;
                return Err(e.into());
            }
        };
        outln!("Omega = {sp} rad/s");
        for (i, m) in ms.iter().enumerate() {
            outln!(
                "  mode {:>2}: {:>12.6} Hz  {:<8} damping {:.2e}",
                i + 1,
                m.freq_hz,
                m.kind.as_str(),
                m.damping_ratio
            );
        }
        if k == 0 {
            out.write("modes.csv", csv_string(&header, mode_rows(&ms)).as_bytes())?;
            let mut sh = vec!["node_index".to_string()];
            for i in 0..ms.len() {
                for c in ["ux_m", "uy_m", "uz_m", "rx_rad", "ry_rad", "rz_rad"] {
                    sh.push(format!("mode{}_{c}", i + 1));
                }
            }
            let shs: Vec<&str> = sh.iter().map(|s| s.as_str()).collect();
            let rows: Vec<Vec<f64>> = (0..model.nodes.len())
                .map(|n| {
                    let mut r = vec![n as f64];
                    for m in &ms {
                        r.extend(m.shape[n]);
                    }
                    r
                })
                .collect();
            out.write("mode_shapes.csv", csv_string(&shs, rows).as_bytes())?;
        }
        let mut row = vec![sp];
        row.extend(ms.iter().map(|m| m.freq_hz));
        row.resize(1 + md.count, f64::NAN);
        fan.push(row);
    }
    if speeds.len() > 1 {
        let mut h = vec!["omega_rad_s".to_string()];
        h.extend((1..=md.count).map(|i| format!("mode{i}_Hz")));
        let hs: Vec<&str> = h.iter().map(|s| s.as_str()).collect();
        out.write("fan.csv", csv_string(&hs, &fan).as_bytes())?;
        let sp: Vec<f64> = fan.iter().map(|r| r[0]).collect();
        let mut plot = crate::report::plot::Plot::new(
            "Fan plot (modes sorted by frequency)",
            "rotor speed [rad/s]",
            "frequency [Hz]",
        );
        for k in 1..=md.count {
            let f: Vec<f64> = fan.iter().map(|r| r[k]).collect();
            if f.iter().all(|v| v.is_finite()) {
                plot = plot.line(&format!("mode {k}"), &sp, &f);
            }
        }
        for n in 1..=4 {
            let f: Vec<f64> = sp
                .iter()
                .map(|w| n as f64 * w / (2.0 * std::f64::consts::PI))
                .collect();
            plot = plot.dashed(&format!("{n}/rev"), &sp, &f);
        }
        out.write("fan.svg", plot.to_svg(900, 600)?.as_bytes())?;
    }
    out.finish()?;
    Ok(())
}

/// Parse `START:STOP:STEP` (inclusive, rounded to the step) or `a,b,c`.
pub fn parse_speeds(s: &str) -> anyhow::Result<Vec<f64>> {
    let v = crate::run::ranges::parse_range(
        "--speeds",
        s,
        "expected START:STOP:STEP, e.g. 0:1.2:0.1, or a list 0.5,1.0",
        MAX_SPEEDS,
        "a fan plot may have (each is a static solve and an eigen-analysis)",
    )?;
    if v.iter().any(|x| !x.is_finite() || *x < 0.0) {
        return Err(crate::run::ranges::range_error(
            "--speeds",
            s,
            "fractions must be finite and non-negative",
            "expected START:STOP:STEP, e.g. 0:1.2:0.1, or a list 0.5,1.0",
        ));
    }
    Ok(v)
}

/// Speeds of one fan plot at most: each is a static solve and an eigen-analysis.
const MAX_SPEEDS: usize = 10_000;

/// Refuses speed fractions far beyond the deck's nominal speed (`key` in `deck`).
fn check_fractions(
    fractions: &[f64],
    nominal: f64,
    unit: &str,
    deck: &std::path::Path,
    key: &str,
) -> anyhow::Result<()> {
    if let Some(&f) = fractions.iter().find(|&&f| f > MAX_SPEED_FRACTION) {
        anyhow::bail!(
            "--speeds: fraction {f} of the nominal speed ({} {key} = {nominal} {unit}) is beyond \
             sense: expected at most {MAX_SPEED_FRACTION} (the speeds are fractions of the \
             nominal, not {unit})",
            deck.display()
        );
    }
    Ok(())
}

/// Refuses a modal solution with a non-finite frequency (a zero-frequency mode may have an
/// undefined damping ratio; a frequency is always defined).
fn check_finite_modes<'a>(
    speeds: impl Iterator<Item = (f64, &'a [Mode])>,
    deck: &std::path::Path,
) -> anyhow::Result<()> {
    for (fraction, ms) in speeds {
        if let Some((i, m)) = ms.iter().enumerate().find(|(_, m)| !m.freq_hz.is_finite()) {
            anyhow::bail!(
                "{}: the modal analysis at speed fraction {fraction} gave mode {} a non-finite \
                 frequency ({} Hz, damping ratio {}): the equilibrium or the eigen-solution \
                 broke down; check the deck's stiffness and mass values",
                deck.display(),
                i + 1,
                m.freq_hz,
                m.damping_ratio
            );
        }
    }
    Ok(())
}

/// Default digitized UH-60A fan plot: `data/fanplot_uh60a_bowen-davies-PhD.txt` next to the
/// rotor deck (shipped copy, rotors/data/), else ../shared next to the source tree.
pub fn default_reference(rotor_deck: &std::path::Path) -> PathBuf {
    const NAME: &str = "fanplot_uh60a_bowen-davies-PhD.txt";
    let local = rotor_deck
        .parent()
        .map(|d| d.join("data").join(NAME))
        .unwrap_or_default();
    if local.exists() {
        return local;
    }
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/uh60a/raw")
        .join(NAME)
}

fn run_rotor(path: &std::path::Path, args: &ModesArgs) -> anyhow::Result<()> {
    use crate::rotor::fan::{fan, read_reference, TRACKED};
    if args.count == 0 {
        anyhow::bail!("--count 0: expected at least 1 mode per speed");
    }
    if std::fs::read_to_string(path).is_ok_and(|t| crate::rotor::hinged::is_hinged(&t)) {
        return run_hinged(path, args);
    }
    let deck = crate::rotor::RotorDeck::from_file(path)?;
    let fractions = parse_speeds(&args.speeds)?;
    check_fractions(
        &fractions,
        deck.spec.rotor.omega_rad_s,
        "rad/s",
        path,
        "rotor.omega_rad_s",
    )?;
    let (ndof, _) = deck.spec.size_estimate();
    let one = crate::solver::budget::dense_modal_of(ndof);
    deck.spec.check_budget(
        path,
        &format!(
            "a fan plot of {} speed(s), a dense modal analysis each,",
            fractions.len()
        ),
        crate::solver::budget::Estimate {
            cpu_s: one.cpu_s * fractions.len() as f64,
            bytes: one.bytes,
        },
    )?;
    let mut inputs = deck.input_files();
    let reference = match &args.reference {
        Some(p) => {
            inputs.push(p.clone());
            Some(read_reference(p)?)
        }
        None => {
            let p = default_reference(path);
            if p.exists() {
                let r = read_reference(&p)?;
                inputs.push(p);
                Some(r)
            } else {
                None
            }
        }
    };
    let out = OutDir::create(&args.out, &inputs)?;
    let pts = match fan(&deck, &fractions, args.count.max(5)).and_then(|p| {
        check_finite_modes(p.iter().map(|p| (p.fraction, &p.modes[..])), path)?;
        Ok(p)
    }) {
        Ok(p) => p,
        Err(e) => {
            out.mark_incomplete(&e.to_string())?;
            return Err(e);
        }
    };
    let om_n = deck.spec.rotor.omega_rad_s;
    // fan.csv: tracked modes, then all modes sorted by frequency
    let mut h: Vec<String> = vec!["speed_fraction".into(), "omega_rad_s".into()];
    h.extend(TRACKED.iter().map(|t| format!("{t}_Hz")));
    h.push("lag_hinge_k_Nm_per_rad".into());
    h.push("lag_hinge_c_Nms_per_rad".into());
    h.extend((1..=args.count.max(5)).map(|i| format!("mode{i}_Hz")));
    let hs: Vec<&str> = h.iter().map(|s| s.as_str()).collect();
    let rows: Vec<Vec<f64>> = pts
        .iter()
        .map(|p| {
            let mut r = vec![p.fraction, p.omega_rad_s];
            r.extend(p.tracked_hz);
            r.push(p.lag_k_nm_per_rad);
            r.push(p.lag_c_nms_per_rad);
            r.extend(p.modes.iter().map(|m| m.freq_hz));
            r.resize(hs.len(), f64::NAN);
            r
        })
        .collect();
    out.write("fan.csv", csv_string(&hs, &rows).as_bytes())?;
    // modes.csv: every mode at every speed with its fractions
    let mh = [
        "speed_fraction",
        "mode",
        "freq_Hz",
        "freq_per_rev",
        "damping_ratio",
        "flap_fraction",
        "lag_fraction",
        "torsion_fraction",
        "axial_fraction",
    ];
    let mut mrows = vec![];
    for p in &pts {
        for (i, m) in p.modes.iter().enumerate() {
            let per_rev = if p.omega_rad_s > 0.0 {
                m.omega_rad_s / p.omega_rad_s
            } else {
                f64::NAN
            };
            mrows.push(vec![
                p.fraction,
                (i + 1) as f64,
                m.freq_hz,
                per_rev,
                m.damping_ratio,
                m.fractions[0],
                m.fractions[1],
                m.fractions[2],
                m.fractions[3],
            ]);
        }
    }
    out.write("modes.csv", csv_string(&mh, &mrows).as_bytes())?;
    // comparison with the reference at the speeds it has
    let mut cmp = vec![];
    outln!(
        "rotor {}: damper as lag-hinge spring/damper (stroke = arm x lag)",
        path.display()
    );
    outln!(
        "{:>6} {:>9} {:>10} {:>10} {:>8}",
        "x",
        "mode",
        "model_Hz",
        "ref_Hz",
        "err_%"
    );
    if let Some(rf) = &reference {
        for p in &pts {
            if let Some((_, r)) = rf.iter().find(|(x, _)| (x - p.fraction).abs() < 1e-6) {
                for (k, (&m, &re)) in p.tracked_hz.iter().zip(r.iter()).enumerate() {
                    cmp.push((p.fraction, k, m, re, 100.0 * (m - re) / re));
                }
            }
        }
        let ch = [
            "speed_fraction",
            "mode_index",
            "model_Hz",
            "reference_Hz",
            "error_pct",
        ];
        let crow: Vec<Vec<f64>> = cmp
            .iter()
            .map(|c| vec![c.0, c.1 as f64, c.2, c.3, c.4])
            .collect();
        let mut text = csv_string(&ch, &crow);
        text.push_str("# mode_index: 0 lag1, 1 flap1, 2 flap2, 3 flap3, 4 torsion1\n");
        out.write("fan_comparison.csv", text.as_bytes())?;
        for c in &cmp {
            outln!(
                "{:>6.2} {:>9} {:>10.4} {:>10.4} {:>8.2}",
                c.0,
                TRACKED[c.1],
                c.2,
                c.3,
                c.4
            );
        }
    }
    // fan.svg
    let x: Vec<f64> = pts.iter().map(|p| p.fraction).collect();
    let mut plot = crate::report::plot::Plot::new(
        "UH-60A fan plot: model (lines) and digitized reference (points in the colour of their mode, Bowen-Davies 2015)",
        "rotor speed Omega / Omega_nominal [-]",
        "frequency [Hz]",
    );
    for (k, t) in TRACKED.iter().enumerate() {
        let y: Vec<f64> = pts.iter().map(|p| p.tracked_hz[k]).collect();
        plot = plot.line(t, &x, &y);
        if let Some(rf) = &reference {
            let rx: Vec<f64> = rf.iter().map(|r| r.0).collect();
            let ry: Vec<f64> = rf.iter().map(|r| r.1[k]).collect();
            plot = plot.points("", &rx, &ry);
        }
    }
    let xmax = x.iter().cloned().fold(0.0, f64::max).max(1e-3);
    plot = per_rev_lines(plot, xmax, xmax * om_n / (2.0 * std::f64::consts::PI));
    out.write("fan.svg", plot.to_svg(1000, 700)?.as_bytes())?;
    out.finish()?;
    outln!("wrote {}", args.out.display());
    Ok(())
}

/// Fan plot of a hinged-blade deck (docs/rotor_deck.md, "Hinged-blade decks"): rigid and
/// elastic modes, damped frequencies, the deck's reference table over it; the reference's
/// speeds are added to `--speeds` so that every reference row is compared.
fn run_hinged(path: &std::path::Path, args: &ModesArgs) -> anyhow::Result<()> {
    use crate::rotor::hinged::{fan, read_reference, HingedSpec, TRACKED};
    let spec = HingedSpec::from_file(path)?;
    let mut fractions = parse_speeds(&args.speeds)?;
    let rpm_n = spec.rpm();
    check_fractions(
        &fractions,
        spec.rotor.omega_rad_s,
        "rad/s",
        path,
        "rotor.omega_rad_s",
    )?;
    let mut inputs = vec![path.to_path_buf()];
    let ref_path = args.reference.clone().or_else(|| spec.reference_path(path));
    let label = spec
        .fan_reference
        .as_ref()
        .map_or("reference".to_string(), |r| r.label.clone());
    let reference = match &ref_path {
        Some(p) => {
            inputs.push(p.clone());
            Some(read_reference(p)?)
        }
        None => None,
    };
    if let Some(rf) = &reference {
        fractions.extend(rf.iter().map(|r| r.rpm / rpm_n));
    }
    fractions.sort_by(f64::total_cmp);
    fractions.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    let out = OutDir::create(&args.out, &inputs)?;
    let pts = match fan(&spec, path, &fractions, args.count.max(TRACKED.len())).and_then(|p| {
        check_finite_modes(p.iter().map(|p| (p.fraction, &p.modes[..])), path)?;
        Ok(p)
    }) {
        Ok(p) => p,
        Err(e) => {
            out.mark_incomplete(&e.to_string())?;
            return Err(e);
        }
    };
    let rpm = |x: f64| x * rpm_n;
    let mut h: Vec<String> = vec!["speed_fraction".into(), "omega_rad_s".into(), "rpm".into()];
    h.extend(TRACKED.iter().map(|t| format!("{t}_Hz")));
    h.extend(TRACKED.iter().map(|t| format!("{t}_damping_ratio")));
    let hs: Vec<&str> = h.iter().map(|s| s.as_str()).collect();
    let rows: Vec<Vec<f64>> = pts
        .iter()
        .map(|p| {
            let mut r = vec![p.fraction, p.omega_rad_s, rpm(p.fraction)];
            r.extend(p.tracked_hz);
            r.extend(p.tracked_zeta);
            r
        })
        .collect();
    let mut text = csv_string(&hs, &rows);
    text.push_str("# *_Hz: damped frequency Im(s)/2pi; NaN: no oscillatory mode of that kind (a free hinge at rest)\n");
    out.write("fan.csv", text.as_bytes())?;
    let mh = [
        "speed_fraction",
        "mode",
        "freq_Hz",
        "damped_freq_Hz",
        "damping_ratio",
        "flap_fraction",
        "lag_fraction",
        "torsion_fraction",
        "axial_fraction",
    ];
    let mut mrows = vec![];
    for p in &pts {
        for (i, m) in p.modes.iter().enumerate() {
            mrows.push(vec![
                p.fraction,
                (i + 1) as f64,
                m.freq_hz,
                crate::rotor::hinged::damped_hz(m),
                m.damping_ratio,
                m.fractions[0],
                m.fractions[1],
                m.fractions[2],
                m.fractions[3],
            ]);
        }
    }
    out.write("modes.csv", csv_string(&mh, &mrows).as_bytes())?;
    outln!(
        "hinged-blade rotor {}: {} rpm nominal",
        path.display(),
        rpm_n
    );
    if let Some(rf) = &reference {
        outln!(
            "{:>6} {:>10} {:>10} {:>10} {:>8}",
            "rpm",
            "mode",
            "model_Hz",
            "ref_Hz",
            "err_%"
        );
        let mut crow = vec![];
        for r in rf {
            let Some(p) = pts
                .iter()
                .find(|p| (rpm(p.fraction) - r.rpm).abs() < 1e-6 * rpm_n)
            else {
                continue;
            };
            for (k, name) in TRACKED.iter().enumerate() {
                let (m, re) = (p.tracked_hz[k], r.hz[k]);
                let err = if re != 0.0 {
                    100.0 * (m - re) / re
                } else {
                    f64::NAN
                };
                crow.push(vec![r.rpm, k as f64, m, re, err]);
                outln!(
                    "{:>6.0} {:>10} {:>10.4} {:>10.2} {:>8.2}",
                    r.rpm,
                    name,
                    m,
                    re,
                    err
                );
            }
        }
        let ch = ["rpm", "mode_index", "model_Hz", "reference_Hz", "error_pct"];
        let mut text = csv_string(&ch, &crow);
        let names: Vec<String> = TRACKED
            .iter()
            .enumerate()
            .map(|(k, t)| format!("{k} {t}"))
            .collect();
        text.push_str(&format!("# mode_index: {}\n", names.join(", ")));
        out.write("fan_comparison.csv", text.as_bytes())?;
    }
    let x: Vec<f64> = pts.iter().map(|p| rpm(p.fraction)).collect();
    let mut plot = crate::report::plot::Plot::new(
        &format!("Fan plot: model (lines) and {label} (points, in the colour of their mode)"),
        "rotor speed [rpm]",
        "frequency [Hz]",
    );
    let xmax = x.iter().cloned().fold(0.0, f64::max).max(1e-3);
    for (k, t) in TRACKED.iter().enumerate() {
        let (xs, ys): (Vec<f64>, Vec<f64>) = pts
            .iter()
            .zip(&x)
            .filter(|(p, _)| p.tracked_hz[k].is_finite())
            .map(|(p, x)| (*x, p.tracked_hz[k]))
            .unzip();
        plot = plot.line(t, &xs, &ys);
        if let Some(rf) = &reference {
            let rx: Vec<f64> = rf.iter().map(|r| r.rpm).collect();
            let ry: Vec<f64> = rf.iter().map(|r| r.hz[k]).collect();
            // unnamed: drawn in its mode's colour, no legend entry of its own
            plot = plot.points("", &rx, &ry);
        }
    }
    plot = per_rev_lines(plot, xmax, xmax / 60.0);
    out.write("fan.svg", plot.to_svg(1000, 700)?.as_bytes())?;
    out.finish()?;
    outln!("wrote {}", args.out.display());
    Ok(())
}

/// The 1/rev..6/rev lines of a fan plot, from the origin to (`xmax`, n `f1`), `f1` the 1/rev
/// frequency [Hz] at `xmax`: one grey legend entry, the lines read by their slope.
fn per_rev_lines(
    mut plot: crate::report::plot::Plot,
    xmax: f64,
    f1: f64,
) -> crate::report::plot::Plot {
    for n in 1..=6 {
        let name = if n == 1 { "1/rev to 6/rev" } else { "" };
        plot = plot.dashed(name, &[0.0, xmax], &[0.0, n as f64 * f1]);
    }
    plot
}
