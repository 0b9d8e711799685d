//! `rotorsim stability` as a library call: its settings and the job.
use super::*;
use crate::hydraulics::DamperModel;
use crate::io::OutDir;
use crate::rotor::RotorDeck;
use anyhow::{anyhow, bail};

/// Every option of `rotorsim stability` but its result folder, as given: the command's flags
/// (clap), a sweep plan's stability keys and the Python package's keyword arguments (serde,
/// through JSON) are this one type; [`StabilitySettings::job`] reads it into a
/// [`StabilityJob`]. [`StabilitySettings::default`] gives the command line's defaults (the
/// required `rotor` and `speeds` unset).
#[derive(clap::Args, serde::Serialize, serde::Deserialize, Clone, Debug, PartialEq)]
#[serde(default, deny_unknown_fields)]
pub struct StabilitySettings {
    /// Rotor deck with an `[airframe]` (docs/rotor_deck.md); per-blade differences
    /// (`[blades.K...]`, `--set blades.K...`) make the rotor anisotropic.
    #[arg(long, required = true)]
    pub rotor: Option<std::path::PathBuf>,
    /// Rotor speeds [rad/s]: START:STOP:STEP (inclusive) or a comma-separated list, increasing.
    #[arg(long, required = true)]
    pub speeds: Option<String>,
    /// Damper model linearised at each speed: linear, nonlinear or physical (default: the
    /// deck's `damper.model`).
    #[arg(long)]
    pub damper: Option<String>,
    /// Also march the whole multibody rotor on its airframe at these speeds [rad/s] (a list):
    /// kicked along x, its growth rate fitted (method `time` in stability.csv).
    #[arg(long)]
    pub time: Option<String>,
    /// Velocity of the time-domain kick along x [m/s].
    #[arg(long, default_value_t = 1e-4)]
    pub kick_m_s: f64,
    /// Simulated time of each time-domain run [s] (a growing one stops when the airframe
    /// moves 10 mm); the fit starts at 7/20 of it.
    #[arg(long, default_value_t = 20.0)]
    pub time_duration_s: f64,
    /// Structural steps per revolution of the time-domain runs (256 is up to 4.5% off in the
    /// growth rate near a coalescence, 512 within 1%).
    #[arg(long, default_value_t = 512)]
    pub steps_per_rev: usize,
    /// Nonlinear amplitude check: start the reduced rotor on its regressing lag mode at these
    /// damper stroke amplitudes [m] (an increasing list; `default` for 0.1 to 30 mm), each
    /// blade's damper a device with its valves live; growth rate against amplitude and the
    /// limit cycles (amplitude.csv).
    #[arg(long)]
    pub amplitudes_m: Option<String>,
    /// Rotor speed of the amplitude check [rad/s] (default: the deck's rotor.omega_rad_s).
    #[arg(long)]
    pub amplitude_at_rad_s: Option<f64>,
    /// Air resonance in hover instead of ground resonance: rigid blades that lag and flap,
    /// quasi-steady aerodynamics (the deck's `[aero]`), on the airframe's x, y, roll and pitch.
    #[arg(long)]
    pub hover: bool,
    /// Hover: blade pitch at 0.75 R [deg] (the deck's twist about it).
    #[arg(long, default_value_t = 8.0)]
    pub collective_deg: f64,
    /// Hover: air density [kg/m^3] (sea-level standard by default).
    #[arg(long, default_value_t = 1.225)]
    pub density_kg_m3: f64,
    /// Hover: speed of sound [m/s] (the aerofoil tables' Mach number).
    #[arg(long, default_value_t = 340.3)]
    pub speed_of_sound_m_s: f64,
    /// Hover: strips per blade from the hinge to the tip (mass and aerodynamics).
    #[arg(long, default_value_t = crate::resonance::air::DEFAULT_STRIPS)]
    pub strips: usize,
    /// Override a deck value by its dotted path before validation (repeatable), as for run.
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = crate::run::job::parse_set)]
    #[serde(with = "crate::run::job::set_texts")]
    pub set: Vec<crate::overrides::Override>,
}

impl Default for StabilitySettings {
    fn default() -> Self {
        crate::run::settings::command_line_defaults("stability")
    }
}

impl crate::run::settings::JobSettings for StabilitySettings {
    const COMMAND: &'static str = "stability";
}

impl StabilitySettings {
    /// The stability run these settings ask for into `out` (its options checked when it runs).
    pub fn job(&self, out: impl Into<std::path::PathBuf>) -> anyhow::Result<StabilityJob> {
        use crate::run::settings::required;
        let rotor = required(&self.rotor, "--rotor", "a rotor deck with an [airframe]")?;
        let speeds = required(&self.speeds, "--speeds", "rotor speeds in rad/s")?;
        Ok(StabilityJob {
            rotor: rotor.clone(),
            speeds: speeds.clone(),
            damper: self.damper.clone(),
            time_speeds: self.time.clone(),
            time: TimeOptions {
                kick_m_s: self.kick_m_s,
                duration_s: self.time_duration_s,
                fit_from_s: self.time_duration_s * 7.0 / 20.0,
                steps_per_rev: self.steps_per_rev,
            },
            amplitudes_m: self.amplitudes_m.clone(),
            amplitude_at_rad_s: self.amplitude_at_rad_s,
            hover: self.hover,
            hover_options: air::HoverOptions {
                collective_deg: self.collective_deg,
                density_kg_m3: self.density_kg_m3,
                speed_of_sound_m_s: self.speed_of_sound_m_s,
                strips: self.strips,
            },
            set: self.set.clone(),
            out: out.into(),
        })
    }
}

/// `rotorsim stability` as a library call: the command's options, typed ([`StabilityJob::new`]
/// gives its defaults), checked and run by [`StabilityJob::execute`] into its result folder.
/// The command line and the Python package both run through it.
#[derive(Clone, Debug)]
pub struct StabilityJob {
    /// Rotor deck with an `[airframe]`.
    pub rotor: std::path::PathBuf,
    /// Rotor speeds [rad/s]: START:STOP:STEP (inclusive) or a comma-separated list.
    pub speeds: String,
    /// Damper model linearised at each speed (None: the deck's `damper.model`).
    pub damper: Option<String>,
    /// Speeds [rad/s] of the whole multibody rotor's time-domain runs (a list).
    pub time_speeds: Option<String>,
    /// The time-domain runs (`fit_from_s` is 7/20 of `duration_s`, set by `execute`).
    pub time: TimeOptions,
    /// Stroke amplitudes [m] of the nonlinear amplitude check (a list, or `default`).
    pub amplitudes_m: Option<String>,
    /// Rotor speed of the amplitude check [rad/s] (None: the deck's).
    pub amplitude_at_rad_s: Option<f64>,
    /// Air resonance in hover instead of ground resonance, and its condition.
    pub hover: bool,
    pub hover_options: air::HoverOptions,
    /// Deck values overridden by dotted path before validation.
    pub set: Vec<crate::overrides::Override>,
    pub out: std::path::PathBuf,
}

/// What a stability run found, its folder published.
#[derive(Clone, Debug)]
pub struct StabilityOutcome {
    pub map: StabilityMap,
    /// The damper model linearised, and the speeds of the map [rad/s].
    pub model: DamperModel,
    pub speeds: Vec<f64>,
    /// The whole rotor's time-domain runs.
    pub time: Vec<TimeCheck>,
    pub amplitude: Option<amplitude::AmplitudeCheck>,
}

impl StabilityJob {
    /// The map of `rotor` over `speeds` into `out` with the defaults of `rotorsim stability`.
    pub fn new(
        rotor: impl Into<std::path::PathBuf>,
        speeds: &str,
        out: impl Into<std::path::PathBuf>,
    ) -> Self {
        StabilityJob {
            rotor: rotor.into(),
            speeds: speeds.to_string(),
            damper: None,
            time_speeds: None,
            time: TimeOptions::default(),
            amplitudes_m: None,
            amplitude_at_rad_s: None,
            hover: false,
            hover_options: Default::default(),
            set: vec![],
            out: out.into(),
        }
    }

    /// The amplitude check's speed and start amplitudes [m], read and checked (None: no check).
    fn amplitude_starts(&self, deck: &RotorDeck) -> anyhow::Result<Option<(f64, Vec<f64>)>> {
        let Some(a) = &self.amplitudes_m else {
            if self.amplitude_at_rad_s.is_some() {
                bail!("--amplitude-at-rad-s needs --amplitudes-m (the amplitudes to start from, or `default`)");
            }
            return Ok(None);
        };
        let amplitudes_m = if a.trim() == "default" {
            amplitude::DEFAULT_AMPLITUDES_M.to_vec()
        } else {
            crate::run::ranges::parse_range(
                "--amplitudes-m",
                a,
                "expected stroke amplitudes in m, e.g. 1e-4,1e-3,1e-2, or `default`",
                amplitude::MAX_AMPLITUDES,
                "an amplitude check may have",
            )?
        };
        let w = self
            .amplitude_at_rad_s
            .unwrap_or(deck.spec.rotor.omega_rad_s);
        if !(w.is_finite() && w > 0.0) {
            bail!("--amplitude-at-rad-s {w}: expected a positive rotor speed in rad/s");
        }
        amplitude::check_amplitudes(&amplitudes_m, deck.spec.damper_attachment.arm_m)?;
        Ok(Some((w, amplitudes_m)))
    }

    /// Checks the options and the deck (before the result folder exists), then computes the
    /// map, the time-domain runs and the amplitude check and writes them. `say` gets a line as
    /// each slow part starts. A failure after the folder exists leaves it marked incomplete.
    pub fn execute(&self, say: &mut dyn FnMut(&str)) -> anyhow::Result<StabilityOutcome> {
        let speeds = parse_speeds("--speeds", &self.speeds)?;
        let deck = RotorDeck::from_file_with(&self.rotor, &self.set)?;
        check_rad_s("--speeds", &speeds, &deck)?;
        let model = match &self.damper {
            Some(d) => d
                .parse::<DamperModel>()
                .map_err(|e| anyhow!("--damper {d}: {e}"))?,
            None => deck.damper()?.model,
        };
        // the time-domain runs: read and sized before the result folder exists
        let time_opts = TimeOptions {
            fit_from_s: self.time.duration_s * 7.0 / 20.0,
            ..self.time
        };
        let mut time_speeds: Vec<f64> = vec![];
        if let Some(t) = &self.time_speeds {
            time_speeds = parse_speeds("--time", t)?;
            check_rad_s("--time", &time_speeds, &deck)?;
            for &w in &time_speeds {
                time_opts.check(w)?;
            }
        }
        // the amplitude check: read and checked before the result folder exists
        let amplitude = self.amplitude_starts(&deck)?;
        let hover = self.hover_options;
        if self.hover {
            hover.check()?;
            if self.time_speeds.is_some() {
                bail!("--hover: the whole rotor's time domain (--time) is for ground resonance; run it without --hover (the amplitude check, --amplitudes-m, runs in hover)");
            }
        }
        let out = OutDir::create(&self.out, &deck.input_files())?;
        let result = if self.hover {
            air::air_resonance_map(&deck, model, &speeds, &hover)
        } else {
            stability_map(&deck, model, &speeds)
        };
        let map = match result {
            Ok(mut m) => {
                m.overrides = self
                    .set
                    .iter()
                    .map(|o| (o.key.clone(), o.value_text()))
                    .collect();
                m
            }
            Err(e) => {
                out.mark_incomplete(&format!("{e:#}"))?;
                return Err(e);
            }
        };
        let mut map = map;
        say("verdict bands: the map moved over the deck's assumed values...");
        let cond = if self.hover {
            band::Condition::Hover(&hover)
        } else {
            band::Condition::Ground
        };
        match band::verdicts(&deck, &self.set, model, &map, cond) {
            Ok(v) => map.verdicts = v,
            Err(e) => {
                out.mark_incomplete(&format!("{e:#}"))?;
                return Err(e.context("verdict bands"));
            }
        }
        let mut time = vec![];
        for &w in &time_speeds {
            say(&format!(
                "time domain at {w} rad/s ({} s of motion)...",
                self.time.duration_s
            ));
            match time_check(&self.rotor, &self.set, model, w, &time_opts) {
                Ok(c) => time.push(c),
                Err(e) => {
                    out.mark_incomplete(&format!("{e:#}"))?;
                    return Err(e.context(format!("time domain at {w} rad/s")));
                }
            }
        }
        let amp = match amplitude {
            None => None,
            Some((w, amplitudes_m)) => {
                say(&format!(
                    "amplitude check at {w} rad/s ({} starts, {} damper)...",
                    amplitudes_m.len(),
                    model.name()
                ));
                let opts = amplitude::AmplitudeOptions {
                    amplitudes_m,
                    hover: self.hover.then_some(hover),
                    ..Default::default()
                };
                match amplitude::amplitude_check(&deck, model, w, &opts) {
                    Ok(c) => Some(c),
                    Err(e) => {
                        out.mark_incomplete(&format!("{e:#}"))?;
                        return Err(e.context(format!("amplitude check at {w} rad/s")));
                    }
                }
            }
        };
        if let Some(c) = &amp {
            // the verdict on the checked mode at the check's speed says what the check found
            for v in &mut map.verdicts {
                if (v.omega_rad_s - c.omega_rad_s).abs() <= 1e-9 * c.omega_rad_s
                    && v.mode == c.linearised.label.as_str()
                {
                    v.amplitude_check = Some(c.headline.clone());
                }
            }
        }
        write_all(&map, &time, amp.as_ref(), &deck, &out)?;
        out.finish()?;
        Ok(StabilityOutcome {
            map,
            model,
            speeds,
            time,
            amplitude: amp,
        })
    }
}
