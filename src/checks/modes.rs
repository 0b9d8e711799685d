//! `rotorsim modes` as a library job ([`ModesJob`]): natural frequencies and mode shapes of a
//! model deck about its static equilibrium, optionally in a frame rotating at each of
//! `[modes] speeds_rad_s` (a fan); or the fan plot of a rotor deck over speed fractions of its
//! nominal speed, with a digitized reference over it (src/rotor/fan.rs; a hinged-blade deck's
//! fan: src/rotor/hinged.rs). The job checks the options and the deck before the result folder
//! exists and writes it; nothing here prints (the command prints from the [`ModesOutcome`] and
//! the per-speed callback).
use crate::io::{csv_string, OutDir};
use crate::report::plot::Plot;
use crate::rotor::MAX_SPEED_FRACTION;
use crate::solver::modal::{modes, ModalOptions, Mode};
use crate::solver::statics::check_constraints;
use crate::solver::{static_solve, State, StaticOptions};
use crate::structure::deck::load_deck_within;
use anyhow::{anyhow, bail};
use std::path::{Path, PathBuf};

/// Speed fractions of a rotor deck's fan plot by default (`--speed-fractions`).
pub const DEFAULT_SPEEDS: &str = "0:1.2:0.1";
/// Modes per speed of a rotor deck's fan plot by default (`--count`).
pub const DEFAULT_COUNT: usize = 14;

/// Every option of `rotorsim modes` but its result folder, as given: the command's arguments
/// (clap) and the Python package's keyword arguments (serde, through JSON) are this one type;
/// [`ModesSettings::job`] reads it into a [`ModesJob`]. [`ModesSettings::default`] gives the
/// command line's defaults (no deck).
#[derive(clap::Args, serde::Serialize, serde::Deserialize, Clone, Debug, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct ModesSettings {
    /// Model deck (TOML, see docs/model_deck.md); or give --rotor.
    #[arg(required_unless_present = "rotor", conflicts_with = "rotor")]
    pub deck: Option<PathBuf>,
    /// Rotor deck (docs/rotor_deck.md): fan plot over the speeds of --speeds or
    /// --speed-fractions.
    #[arg(long)]
    pub rotor: Option<PathBuf>,
    /// Rotor speeds [rad/s], START:STOP:STEP (inclusive) or a comma-separated list.
    #[arg(long, conflicts_with = "speed_fractions")]
    pub speeds: Option<String>,
    /// Rotor speeds as fractions of the deck's nominal speed (rotor.omega_rad_s) instead of
    /// --speeds, START:STOP:STEP (inclusive) or a comma-separated list.
    #[arg(long, default_value = DEFAULT_SPEEDS)]
    pub speed_fractions: String,
    /// Digitized reference fan plot drawn over the model's (default: the UH-60A fan plot of
    /// ../shared/data/uh60a/raw/ next to the source tree, when present).
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Modes per speed (rotor decks).
    #[arg(long, default_value_t = DEFAULT_COUNT)]
    pub count: usize,
}

impl Default for ModesSettings {
    fn default() -> Self {
        crate::run::settings::command_line_defaults("modes")
    }
}

impl crate::run::settings::JobSettings for ModesSettings {
    const COMMAND: &'static str = "modes";
}

impl ModesSettings {
    /// The modes run these settings ask for into `out` (its options checked when it runs).
    pub fn job(&self, out: impl Into<PathBuf>) -> anyhow::Result<ModesJob> {
        // the command line refuses both; settings read from JSON are checked here
        if self.speeds.is_some() && self.speed_fractions != DEFAULT_SPEEDS {
            bail!("--speeds and --speed-fractions: give one (rad/s, or fractions of the nominal speed)");
        }
        Ok(ModesJob {
            deck: self.deck.clone(),
            rotor: self.rotor.clone(),
            speeds: self.speed_fractions.clone(),
            speeds_rad_s: self.speeds.clone(),
            reference: self.reference.clone(),
            count: self.count,
            out: out.into(),
        })
    }
}

/// `rotorsim modes` as a library call: the command's options, typed ([`ModesJob::new`] gives
/// its defaults), checked and run by [`ModesJob::execute`] into its result folder. The command
/// line and the Python package both run through it.
#[derive(Clone, Debug)]
pub struct ModesJob {
    /// Model deck (its `[modes]` table says how many modes and at which speeds); or `rotor`.
    pub deck: Option<PathBuf>,
    /// Rotor deck (or hinged-blade deck): its fan plot over `speeds`.
    pub rotor: Option<PathBuf>,
    /// Rotor decks: speeds as fractions of the nominal, START:STOP:STEP (inclusive) or a
    /// comma-separated list (unless `speeds_rad_s`).
    pub speeds: String,
    /// Rotor decks: speeds in rad/s instead of `speeds`.
    pub speeds_rad_s: Option<String>,
    /// Rotor decks: the digitized reference fan plot drawn over the model's (None: the default
    /// one, [`default_reference`], when present; a hinged-blade deck's own `[fan_reference]`).
    pub reference: Option<PathBuf>,
    /// Rotor decks: modes per speed.
    pub count: usize,
    pub out: PathBuf,
}

/// What was analysed.
#[derive(Clone, Debug, PartialEq)]
pub enum ModesAnalysis {
    /// A model deck; its speeds are in rad/s.
    Model,
    /// A rotor deck's fan plot; its speeds are fractions of the nominal.
    Rotor,
    /// A hinged-blade deck's fan plot, of nominal speed `rpm_nominal`.
    Hinged { rpm_nominal: f64 },
}

/// The modes at one speed, sorted by frequency.
#[derive(Clone, Debug)]
pub struct SpeedModes {
    /// Fraction of the nominal speed (rotor decks; None for a model deck).
    pub fraction: Option<f64>,
    /// Rotor speed [rad/s].
    pub omega_rad_s: f64,
    pub modes: Vec<Mode>,
}

/// A tracked mode of a rotor deck's fan against the reference at one speed.
#[derive(Clone, Debug)]
pub struct Compared {
    /// The reference's speed: a fraction of the nominal (rotor decks) or rpm (hinged-blade).
    pub speed: f64,
    /// The tracked mode (e.g. `lag1`, `rigid_flap`).
    pub mode: &'static str,
    pub model_hz: f64,
    pub reference_hz: f64,
    pub error_pct: f64,
}

/// What a modes run found, its folder published.
#[derive(Clone, Debug)]
pub struct ModesOutcome {
    pub analysis: ModesAnalysis,
    /// The deck analysed (model or rotor).
    pub deck: PathBuf,
    /// Every speed's modes, in the order computed.
    pub speeds: Vec<SpeedModes>,
    /// Rotor decks with a reference: the comparison at the reference's speeds (None: no
    /// reference).
    pub comparison: Option<Vec<Compared>>,
    /// The result folder.
    pub folder: PathBuf,
}

impl ModesJob {
    /// A modes run into `out` with the defaults of `rotorsim modes`; give `deck` or `rotor`.
    pub fn new(out: impl Into<PathBuf>) -> Self {
        ModesJob {
            deck: None,
            rotor: None,
            speeds: DEFAULT_SPEEDS.to_string(),
            speeds_rad_s: None,
            reference: None,
            count: DEFAULT_COUNT,
            out: out.into(),
        }
    }

    /// Checks the options and the deck (before the result folder exists), then computes the
    /// modes and writes them: modes.csv and mode_shapes.csv of a model deck (fan.csv and
    /// fan.svg when it has speeds); fan.csv, modes.csv, fan.svg and, with a reference,
    /// fan_comparison.csv of a rotor deck. `on_speed` gets each speed's modes as they are found
    /// (a rotor deck's fan is computed whole: its speeds come once it is). A failure after the
    /// folder exists leaves it marked incomplete.
    pub fn execute(&self, on_speed: &mut dyn FnMut(&SpeedModes)) -> anyhow::Result<ModesOutcome> {
        match (&self.deck, &self.rotor) {
            (Some(_), Some(_)) => bail!("give a model deck or --rotor, not both"),
            (None, Some(r)) => self.rotor_fan(r, on_speed),
            (Some(d), None) => self.model(d, on_speed),
            (None, None) => bail!("give a model deck or --rotor"),
        }
    }

    fn model(
        &self,
        path: &Path,
        on_speed: &mut dyn FnMut(&SpeedModes),
    ) -> anyhow::Result<ModesOutcome> {
        let (deck, mut model) = load_deck_within(path, |d| {
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
        check_constraints(&mut model, &st0).map_err(|e| anyhow!("deck {file}: {e}"))?;
        let out = OutDir::create(&self.out, &deck.input_files(path))?;
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
        let mut found = vec![];
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
                bail!("equilibrium at Omega = {sp} rad/s: {e}");
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
            let at = SpeedModes {
                fraction: None,
                omega_rad_s: sp,
                modes: ms,
            };
            on_speed(&at);
            let ms = &at.modes;
            if k == 0 {
                out.write("modes.csv", csv_string(&header, mode_rows(ms)).as_bytes())?;
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
                        for m in ms {
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
            found.push(at);
        }
        if speeds.len() > 1 {
            let mut h = vec!["omega_rad_s".to_string()];
            h.extend((1..=md.count).map(|i| format!("mode{i}_Hz")));
            let hs: Vec<&str> = h.iter().map(|s| s.as_str()).collect();
            out.write("fan.csv", csv_string(&hs, &fan).as_bytes())?;
            let sp: Vec<f64> = fan.iter().map(|r| r[0]).collect();
            let mut plot = Plot::new(
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
        Ok(ModesOutcome {
            analysis: ModesAnalysis::Model,
            deck: path.to_path_buf(),
            speeds: found,
            comparison: None,
            folder: self.out.clone(),
        })
    }

    fn rotor_fan(
        &self,
        path: &Path,
        on_speed: &mut dyn FnMut(&SpeedModes),
    ) -> anyhow::Result<ModesOutcome> {
        use crate::rotor::fan::{fan, read_reference, TRACKED};
        if self.count == 0 {
            bail!("--count 0: expected at least 1 mode per speed");
        }
        let deck = match crate::rotor::AnyRotorDeck::from_file(path)? {
            crate::rotor::AnyRotorDeck::Hinged(spec) => {
                return self.hinged_fan(spec, path, on_speed)
            }
            crate::rotor::AnyRotorDeck::Elastomeric(deck) => deck,
        };
        let fractions = self.fractions(deck.spec.rotor.omega_rad_s, path)?;
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
        let reference = match &self.reference {
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
        let out = OutDir::create(&self.out, &inputs)?;
        let count = self.count.max(5);
        let (pts, found) = finished_fan(
            &out,
            path,
            fan(&deck, &fractions, count),
            |p| (p.fraction, p.omega_rad_s, &p.modes),
            on_speed,
        )?;
        let om_n = deck.spec.rotor.omega_rad_s;
        // fan.csv: tracked modes, then all modes sorted by frequency
        let mut h: Vec<String> = vec!["speed_fraction".into(), "omega_rad_s".into()];
        h.extend(TRACKED.iter().map(|t| format!("{t}_Hz")));
        h.push("lag_hinge_k_Nm_per_rad".into());
        h.push("lag_hinge_c_Nms_per_rad".into());
        h.extend((1..=count).map(|i| format!("mode{i}_Hz")));
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
        let per_rev = |at: &SpeedModes, m: &Mode| {
            if at.omega_rad_s > 0.0 {
                m.omega_rad_s / at.omega_rad_s
            } else {
                f64::NAN
            }
        };
        let (mh, mrows) = fan_mode_rows(&found, "freq_per_rev", per_rev);
        out.write("modes.csv", csv_string(&mh, &mrows).as_bytes())?;
        // comparison with the reference at the speeds it has
        let comparison = match &reference {
            None => None,
            Some(rf) => Some(fan_comparison(&out, &pts, rf)?),
        };
        // fan.svg
        let x: Vec<f64> = pts.iter().map(|p| p.fraction).collect();
        let mut plot = Plot::new(
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
        Ok(ModesOutcome {
            analysis: ModesAnalysis::Rotor,
            deck: path.to_path_buf(),
            speeds: found,
            comparison,
            folder: self.out.clone(),
        })
    }

    /// Fan plot of a hinged-blade deck (docs/rotor_deck.md, "Hinged-blade decks"): rigid and
    /// elastic modes, damped frequencies, the deck's reference table over it; the reference's
    /// speeds are added to `speeds` so that every reference row is compared.
    fn hinged_fan(
        &self,
        spec: crate::rotor::hinged::HingedSpec,
        path: &Path,
        on_speed: &mut dyn FnMut(&SpeedModes),
    ) -> anyhow::Result<ModesOutcome> {
        use crate::rotor::hinged::{fan, read_reference, TRACKED};
        let mut fractions = self.fractions(spec.rotor.omega_rad_s, path)?;
        let rpm_n = spec.rpm();
        let mut inputs = vec![path.to_path_buf()];
        let ref_path = self.reference.clone().or_else(|| spec.reference_path(path));
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
        let out = OutDir::create(&self.out, &inputs)?;
        let (pts, found) = finished_fan(
            &out,
            path,
            fan(&spec, path, &fractions, self.count.max(TRACKED.len())),
            |p| (p.fraction, p.omega_rad_s, &p.modes),
            on_speed,
        )?;
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
        let (mh, mrows) = fan_mode_rows(&found, "damped_freq_Hz", |_, m| {
            crate::rotor::hinged::damped_hz(m)
        });
        out.write("modes.csv", csv_string(&mh, &mrows).as_bytes())?;
        let comparison = match &reference {
            None => None,
            Some(rf) => {
                let mut cmp = vec![];
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
                        cmp.push(Compared {
                            speed: r.rpm,
                            mode: name,
                            model_hz: m,
                            reference_hz: re,
                            error_pct: err,
                        });
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
                Some(cmp)
            }
        };
        let x: Vec<f64> = pts.iter().map(|p| rpm(p.fraction)).collect();
        let mut plot = Plot::new(
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
        Ok(ModesOutcome {
            analysis: ModesAnalysis::Hinged { rpm_nominal: rpm_n },
            deck: path.to_path_buf(),
            speeds: found,
            comparison,
            folder: self.out.clone(),
        })
    }
}

/// A fan's points once every mode is finite, with each speed as [`SpeedModes`] given to
/// `on_speed`; a fan that failed or is not finite publishes the folder incomplete with the
/// reason. `at` gives a point's speed fraction, speed and modes.
fn finished_fan<P>(
    out: &OutDir,
    path: &Path,
    pts: anyhow::Result<Vec<P>>,
    at: impl Fn(&P) -> (f64, f64, &Vec<Mode>),
    on_speed: &mut dyn FnMut(&SpeedModes),
) -> anyhow::Result<(Vec<P>, Vec<SpeedModes>)> {
    let pts = match pts.and_then(|p| {
        check_finite_modes(
            p.iter().map(|p| {
                let (fraction, _, modes) = at(p);
                (fraction, &modes[..])
            }),
            path,
        )?;
        Ok(p)
    }) {
        Ok(p) => p,
        Err(e) => {
            out.mark_incomplete(&e.to_string())?;
            return Err(e);
        }
    };
    let found: Vec<SpeedModes> = pts
        .iter()
        .map(|p| {
            let (fraction, omega_rad_s, modes) = at(p);
            SpeedModes {
                fraction: Some(fraction),
                omega_rad_s,
                modes: modes.clone(),
            }
        })
        .collect();
    for s in &found {
        on_speed(s);
    }
    Ok((pts, found))
}

/// modes.csv of a fan: every mode at every speed with its fractions; the fourth column is
/// `col4`, given by `f4` (per-rev frequency or damped frequency).
fn fan_mode_rows(
    found: &[SpeedModes],
    col4: &'static str,
    f4: impl Fn(&SpeedModes, &Mode) -> f64,
) -> ([&'static str; 9], Vec<Vec<f64>>) {
    let header = [
        "speed_fraction",
        "mode",
        "freq_Hz",
        col4,
        "damping_ratio",
        "flap_fraction",
        "lag_fraction",
        "torsion_fraction",
        "axial_fraction",
    ];
    let mut rows = vec![];
    for at in found {
        for (i, m) in at.modes.iter().enumerate() {
            rows.push(vec![
                at.fraction.unwrap_or(f64::NAN),
                (i + 1) as f64,
                m.freq_hz,
                f4(at, m),
                m.damping_ratio,
                m.fractions[0],
                m.fractions[1],
                m.fractions[2],
                m.fractions[3],
            ]);
        }
    }
    (header, rows)
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

/// Parse `START:STOP:STEP` (inclusive, rounded to the step) or `a,b,c`: the speed fractions of
/// `--speeds`, finite and non-negative.
pub fn parse_speeds(s: &str) -> anyhow::Result<Vec<f64>> {
    parse_speeds_as("--speed-fractions", s)
}

/// [`parse_speeds`] of the option `flag`.
fn parse_speeds_as(flag: &str, s: &str) -> anyhow::Result<Vec<f64>> {
    let v = crate::run::ranges::parse_range(
        flag,
        s,
        "expected START:STOP:STEP, e.g. 0:1.2:0.1, or a list 0.5,1.0",
        MAX_SPEEDS,
        "a fan plot may have (each is a static solve and an eigen-analysis)",
    )?;
    if v.iter().any(|x| !x.is_finite() || *x < 0.0) {
        return Err(crate::run::ranges::range_error(
            flag,
            s,
            "speeds must be finite and non-negative",
            "expected START:STOP:STEP, e.g. 0:1.2:0.1, or a list 0.5,1.0",
        ));
    }
    Ok(v)
}

/// Speeds of one fan plot at most: each is a static solve and an eigen-analysis.
const MAX_SPEEDS: usize = 10_000;

impl ModesJob {
    /// The fan's speeds as fractions of the deck's nominal speed `nominal` [rad/s] (the
    /// `rotor.omega_rad_s` of `deck`): `speeds_rad_s` over it, else `speeds`; refused far
    /// beyond it, and speeds in rad/s that look like fractions.
    fn fractions(&self, nominal: f64, deck: &Path) -> anyhow::Result<Vec<f64>> {
        const KEY: &str = "rotor.omega_rad_s";
        let (flag, fractions) = match &self.speeds_rad_s {
            Some(text) => {
                let w = parse_speeds_as("--speeds", text)?;
                crate::run::ranges::check_not_fractions("--speeds", &w, nominal, deck, KEY)?;
                ("--speeds", w.iter().map(|w| w / nominal).collect())
            }
            None => ("--speed-fractions", parse_speeds(&self.speeds)?),
        };
        if let Some(&f) = fractions.iter().find(|&&f| f > MAX_SPEED_FRACTION) {
            bail!(
                "{flag}: {} times the nominal speed ({} {KEY} = {nominal} rad/s) is beyond sense: \
                 expected at most {MAX_SPEED_FRACTION} times",
                f,
                deck.display()
            );
        }
        Ok(fractions)
    }
}

/// Refuses a modal solution with a non-finite frequency (a zero-frequency mode may have an
/// undefined damping ratio; a frequency is always defined).
fn check_finite_modes<'a>(
    speeds: impl Iterator<Item = (f64, &'a [Mode])>,
    deck: &Path,
) -> anyhow::Result<()> {
    for (fraction, ms) in speeds {
        if let Some((i, m)) = ms.iter().enumerate().find(|(_, m)| !m.freq_hz.is_finite()) {
            bail!(
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
pub fn default_reference(rotor_deck: &Path) -> PathBuf {
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

/// The 1/rev..6/rev lines of a fan plot, from the origin to (`xmax`, n `f1`), `f1` the 1/rev
/// frequency [Hz] at `xmax`: one grey legend entry, the lines read by their slope.
fn per_rev_lines(mut plot: Plot, xmax: f64, f1: f64) -> Plot {
    for n in 1..=6 {
        let name = if n == 1 { "1/rev to 6/rev" } else { "" };
        plot = plot.dashed(name, &[0.0, xmax], &[0.0, n as f64 * f1]);
    }
    plot
}

/// fan_comparison.csv: the tracked modes against the reference at the speeds it has.
fn fan_comparison(
    out: &OutDir,
    pts: &[crate::rotor::fan::FanPoint],
    rf: &[(f64, [f64; 5])],
) -> anyhow::Result<Vec<Compared>> {
    use crate::rotor::fan::TRACKED;
    let mut cmp = vec![];
    for p in pts {
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
    Ok(cmp
        .iter()
        .map(|c| Compared {
            speed: c.0,
            mode: TRACKED[c.1],
            model_hz: c.2,
            reference_hz: c.3,
            error_pct: c.4,
        })
        .collect())
}
