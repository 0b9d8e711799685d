//! Rotor deck -> multibody model, and the forced-response simulation interface used by
//! `rotorsim run`.
//!
//! Split of responsibilities: this module builds a rotor (deck, expansion to a model deck,
//! the UH-60A multibody model, airload replay, swashplate controls, damper coupling) and
//! exposes it through [`ForcedResponse`]; `crate::run` drives any [`ForcedResponse`] to a
//! periodic solution and writes the outputs (summary.json, last_rev.csv, report.html,
//! result.mcap). Keep the trait small and stable: both sides code against it.

/// Wall-clock split of a simulation (seconds since construction).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timing {
    /// Total time spent in `step` [s].
    pub total_s: f64,
    /// Of which inside the hydraulic device (trial steps, sub-stepping) [s].
    pub hydraulics_s: f64,
    /// Structural steps taken and Newton iterations in total.
    pub steps: usize,
    pub iterations: usize,
    /// Factorizations of the structural iteration matrix.
    pub factorizations: usize,
    /// Steps accepted at the relaxed tolerance after Newton stalled at a valve event.
    pub relaxed_steps: usize,
}

/// Names of the channels every [`ForcedResponse`] reports first, in this order. Sign
/// conventions are those of docs/formats.md (stroke positive in extension, force positive
/// when the damper pushes its end points apart). Tip motion is in the hub (rotating) frame,
/// relative to the undeformed blade: flap up positive, lag positive aft (against rotation),
/// elastic twist nose-up positive.
pub const BASE_CHANNELS: [&str; 6] = [
    "damper_force_N",
    "damper_stroke_m",
    "damper_stroke_rate_m_s",
    "tip_flap_m",
    "tip_lag_m",
    "tip_twist_rad",
];

/// Eq. (5) of a relief valve seen at the damper: off its seat the poppet balances
/// `A_front p_k - A_back p_other = F_p + k x + c v + m a`, so with `A_back/A_front = A_other/A_k`
/// (the shipped dampers) the damper force beyond the cracking force is
/// `(A_k / A_front) (k x + c v + m a)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReliefRegulation {
    /// `A_k / A_front` [-].
    pub area_ratio: f64,
    /// Poppet spring k [N/m] and dashpot c [N s/m].
    pub k_n_per_m: f64,
    pub c_n_s_per_m: f64,
    /// `F_p / A_front` [Pa] and `A_back / A_front` [-]: the valve cracks when the relieved
    /// chamber's pressure exceeds `F_p / A_front + (A_back / A_front) p_other` (Eq. 5).
    pub preload_pressure_pa: f64,
    pub back_area_ratio: f64,
}

impl ReliefRegulation {
    /// Pressure of the relieved chamber at which the valve cracks, the other chamber at
    /// `p_other` [Pa] (Eq. 5 with the poppet at rest on its seat).
    pub fn cracking_pressure_pa(&self, p_other: f64) -> f64 {
        self.preload_pressure_pa + self.back_area_ratio * p_other
    }

    /// Per valve from the circuit's areas and relief valves (None without both valves).
    pub fn of(params: &crate::hydraulics::circuit::CircuitParams) -> Option<[Self; 2]> {
        let a = [params.chambers[0].area, params.chambers[1].area];
        let r = |k: usize| {
            params.relief[k].map(|v| ReliefRegulation {
                area_ratio: a[k] / v.a_front,
                k_n_per_m: v.k,
                c_n_s_per_m: v.c,
                preload_pressure_pa: v.f_p / v.a_front,
                back_area_ratio: v.a_back / v.a_front,
            })
        };
        Some([r(0)?, r(1)?])
    }
}

/// What a run with aerodynamics reports besides its channels.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct AirloadInfo {
    /// "measured", "computed", "hybrid" or "hybrid-periodic".
    pub source: String,
    /// The hybrid's reference motion in words ("" for the other sources).
    pub reference: String,
    /// The inflow model ("uniform", "drees", "pitt-peters").
    pub inflow: String,
    /// The aerofoils, inboard first.
    pub airfoils: Vec<String>,
    /// Aerofoil-table queries clamped to a table's edge (never extrapolated; once per edge),
    /// of `table_queries` in all, and where (with the tables' limits).
    pub clamped_queries: u64,
    pub table_queries: u64,
    pub clamps: String,
    /// The record's thrust coefficient over solidity (its metadata), for comparison.
    pub record_ct_over_sigma: Option<f64>,
    /// Whether the record is synthetic (shown beside the comparison).
    pub record_synthetic: bool,
}

impl AirloadInfo {
    /// The clamped queries in words: their share of the lookups, then where, e.g. "12.3% of
    /// 310,000 aerofoil-table lookups clamped to the tables' edges (values at the edge, not
    /// extrapolated): 38,000 queries below the table's Mach range (Mach 0.3)"; empty if none.
    pub fn clamp_statement(&self) -> String {
        if self.clamped_queries == 0 {
            return String::new();
        }
        format!(
            "{:.1}% of {} aerofoil-table lookups clamped to the tables' edges (the value at the edge, not extrapolated): {}",
            100.0 * self.clamped_queries as f64 / self.table_queries.max(1) as f64,
            self.table_queries,
            self.clamps
        )
    }

    /// The source with the hybrid's reference, in words.
    pub fn source_text(&self) -> String {
        match self.reference.as_str() {
            "" => self.source.clone(),
            r => format!("{} (reference: {r})", self.source),
        }
    }
}

/// One time-marching forced-response simulation of a rotor blade with one damper model.
pub trait ForcedResponse: Send {
    /// Model label: "linear", "nonlinear" or "physical".
    fn label(&self) -> &str;
    /// Rotor period 2 pi / Omega [s].
    fn period_s(&self) -> f64;
    /// Structural time step [s] (period / steps per revolution).
    fn time_step_s(&self) -> f64;
    /// Current time [s]; starts at 0 (azimuth 0 of the reference blade).
    fn time_s(&self) -> f64;
    /// Azimuth of the reference blade [deg] (docs/formats.md: 0 over the tail, increasing with
    /// rotation), not wrapped.
    fn azimuth_deg(&self) -> f64 {
        self.time_s() / self.period_s() * 360.0
    }
    /// Advance one structural step. Numerical failure returns an error naming the time, the
    /// Newton iteration and the residual.
    fn step(&mut self) -> anyhow::Result<()>;
    /// Channel names with units: [`BASE_CHANNELS`] first, then model-specific ones (for the
    /// physical damper the device channels: p0_Pa, p1_Pa, q_orifice_m3_s, x_valve0_m, ...;
    /// valve velocities as v_valve0_m_s, v_valve1_m_s).
    fn channel_names(&self) -> Vec<String>;
    /// Current channel values, same order as `channel_names`. Must not allocate.
    fn channels(&self, out: &mut [f64]);
    /// Force limits of the device [N] (min, max) where it has them (physical damper: the
    /// relief-valve limits), else None.
    fn force_limits_n(&self) -> Option<(f64, f64)> {
        None
    }
    /// Relief-valve regulation (physical damper): per valve, what turns the poppet's spring and
    /// damping forces into damper force beyond the cracking force (Eq. 5); else None.
    /// Whether the channels derived from the state for output only (blade loads) are
    /// computed (default); off, they read NaN. Revolutions whose samples are never reported
    /// (the perturbed revolutions of shooting) turn them off.
    fn set_output_channels(&mut self, _on: bool) {}
    fn output_channels(&self) -> bool {
        true
    }
    /// Number of identical blades of the rotor (None: not a rotor with blade loads).
    fn blades(&self) -> Option<usize> {
        None
    }
    fn relief_regulation(&self) -> Option<[ReliefRegulation; 2]> {
        None
    }
    fn timing(&self) -> Timing;
    /// The current state, for periodic solutions and warm starts; None when this simulation
    /// cannot save it (it can then only be marched).
    fn save_state(&self) -> Option<SimState> {
        None
    }
    /// Continue from `s` (saved by this simulation or by one of the same model).
    fn restore_state(&mut self, _s: &SimState) -> anyhow::Result<()> {
        anyhow::bail!("{}: cannot restore a saved state", self.label())
    }
    /// Time from which the forcing repeats every period [s] (end of the ramps).
    fn periodic_from_s(&self) -> f64 {
        0.0
    }
    /// The airloads' source, inflow and aerofoil-table clamps (None: replayed airloads only).
    fn airload_info(&self) -> Option<AirloadInfo> {
        None
    }
    /// Hybrid airloads referenced to the periodic solution itself, not yet adopted: the run
    /// first finds the periodic solution under the measured airloads.
    fn reference_pending(&self) -> bool {
        false
    }
    /// Adopts the revolution just integrated (from a periodic state) as the hybrid's
    /// reference: from now on the lifting line's difference from it acts.
    fn adopt_reference(&mut self) {}
    /// Which motion dominates a (complex) mode given in the coordinates of
    /// [`SimState::coords`]: "lag", "flap", "torsion", ... ("" when unknown).
    fn mode_label(&self, _re: &[f64], _im: &[f64]) -> String {
        String::new()
    }
    /// Relaxation times of the model's internal relaxation states (the bearing elastomers'
    /// Maxwell branches) [s]: each adds a real Floquet multiplier near `exp(-T / tau)` to the
    /// structure's modes (empty: none).
    fn relaxation_times_s(&self) -> Vec<f64> {
        Vec::new()
    }
}

/// A saved state of a [`ForcedResponse`]: the perturbable coordinates (periodic solvers work
/// on them; scaled to comparable units, e.g. velocities times 1/Omega) and the rest, restored
/// as is.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SimState {
    /// Time [s].
    pub t_s: f64,
    /// Perturbable coordinates (their meaning is the simulation's).
    pub coords: Vec<f64>,
    /// The structural solver's state (multibody simulations).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub solver: Option<crate::solver::SolverSnapshot>,
    /// Other state values (e.g. a device's), in the simulation's layout.
    #[serde(default)]
    pub aux: Vec<f64>,
}

pub mod aero;
pub mod assumed;
pub mod blades;
pub mod deck;

/// Largest rotor speed of a fan plot or a decay, in multiples of the deck's nominal: the
/// centrifugal load grows with its square and rotors run within about 1.2 of nominal; far
/// beyond, the equilibrium and the modes mean nothing (non-finite modes, diverged statics).
pub const MAX_SPEED_FRACTION: f64 = 3.0;
pub mod expand;
pub mod fan;
pub mod hinged;
pub mod loads;
pub mod sim;
pub mod transient;

use crate::flight::FlightRecord;
use crate::hydraulics::{DamperDeck, DamperModel, IntegratorOptions};
use crate::overrides::Override;
use std::path::Path;

/// Options of one forced-response run.
#[derive(Clone, Copy, Debug)]
pub struct RunOptions {
    /// Structural steps per rotor revolution (paper: 256).
    pub steps_per_rev: usize,
    /// Hydraulic integrator and sub-steps per structural step (paper: RK4, 25).
    pub hydraulics: IntegratorOptions,
    /// Generalized-alpha spectral radius at infinity.
    pub rho_inf: f64,
    /// Newton method of the structural step (modified: factorization reused while it
    /// contracts, in the frame turning with the shaft).
    pub newton: crate::solver::NewtonMethod,
    /// Newton tolerance of a structural step: `||r|| <= rtol ||r_pred||`, `r_pred` the residual
    /// of the zero-acceleration predictor (default [`sim::RTOL`]).
    pub newton_rtol: f64,
    /// Whether the deck's perturbation damping (`blade.perturbation_damping_*`) is applied.
    /// It vanishes on the periodic solution and only speeds up marching; shooting turns it off
    /// (its delayed history would be part of the revolution map's state).
    pub perturbation_damping: bool,
    /// Where this blade sits in a whole-rotor run: its azimuth ahead of blade 1 [deg], which
    /// turns the cyclic and the airloads it sees; None for the single-blade run (its hub loads
    /// are then built from the blade by symmetry).
    pub blade_azimuth_deg: Option<f64>,
    /// Where the airloads come from (docs/aerodynamics.md).
    pub airloads: aero::AirloadSource,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            steps_per_rev: 256,
            hydraulics: IntegratorOptions::default(),
            rho_inf: 0.9,
            newton: crate::solver::NewtonMethod::Modified,
            newton_rtol: sim::RTOL,
            perturbation_damping: true,
            blade_azimuth_deg: None,
            airloads: aero::AirloadSource::Measured,
        }
    }
}

/// A rotor deck (rotors/*.toml): rotor, blade, root retention, bearing, pitch control, damper
/// attachment geometry and the `[damper]` table. Schema: docs/rotor_deck.md. It is the base deck
/// (what a single-blade command reads); per-blade differences (`[blades.K...]`, `--set
/// blades.K...`) give each blade's deck through [`RotorDeck::blade`] (src/rotor/blades.rs).
#[derive(Clone, Debug)]
pub struct RotorDeck {
    /// File the deck was read from (relative paths inside it resolve against its folder).
    pub path: std::path::PathBuf,
    /// The parsed tables of the base deck (`blades` None).
    pub spec: deck::RotorSpec,
    /// The deck's tables as read, overrides applied (what a blade's deck starts from).
    table: toml::Table,
    /// The per-blade differences, applied only to the blades' decks.
    blades: blades::PerBlade,
    /// The typed `[damper]` table, read on first use (a command that runs no damper does not
    /// need it to be valid).
    damper: std::sync::OnceLock<Result<DamperDeck, String>>,
    /// The values the deck file labels `# ASSUMED`, read once with the deck.
    assumed: assumed::Scan,
}

/// A rotor deck of either kind, both with the `[rotor]` table (docs/rotor_deck.md): the
/// elastomeric rotor (retention, bearing, pitch link, damper) or a hinged blade (`[[hinge]]`
/// tables, "Hinged-blade decks"). The one place that tells the kinds apart.
#[derive(Clone, Debug)]
pub enum AnyRotorDeck {
    Elastomeric(Box<RotorDeck>),
    Hinged(hinged::HingedSpec),
}

/// The kind of rotor deck a file holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RotorKind {
    Elastomeric,
    Hinged,
}

impl RotorKind {
    /// The kind of deck `text` is: hinged when it has `[[hinge]]` tables (text that is not TOML
    /// reads as elastomeric, whose reader names the error).
    pub fn of_text(text: &str) -> Self {
        let hinged = toml::from_str::<toml::Table>(text).is_ok_and(|t| t.contains_key("hinge"));
        if hinged {
            RotorKind::Hinged
        } else {
            RotorKind::Elastomeric
        }
    }

    /// The kind of the deck file at `path` (a file that cannot be read: elastomeric, whose
    /// reader names the error).
    pub fn of_file(path: &Path) -> Self {
        std::fs::read_to_string(path).map_or(RotorKind::Elastomeric, |t| Self::of_text(&t))
    }
}

impl AnyRotorDeck {
    /// Reads the deck at `path` as the kind it is.
    pub fn from_file(path: &Path) -> anyhow::Result<Self> {
        Ok(match RotorKind::of_file(path) {
            RotorKind::Elastomeric => {
                AnyRotorDeck::Elastomeric(Box::new(RotorDeck::from_file(path)?))
            }
            RotorKind::Hinged => AnyRotorDeck::Hinged(hinged::HingedSpec::from_file(path)?),
        })
    }

    /// The shared `[rotor]` table.
    pub fn rotor(&self) -> &deck::RotorTable {
        match self {
            AnyRotorDeck::Elastomeric(d) => &d.spec.rotor,
            AnyRotorDeck::Hinged(h) => &h.rotor,
        }
    }
}

impl RotorDeck {
    pub fn from_file(path: &Path) -> anyhow::Result<Self> {
        Self::from_file_with(path, &[])
    }
    /// Reads the deck with `overrides` applied to its values before validation (`--set`): each
    /// is validated like the deck itself, the `[damper]` table by the damper deck's rules. The
    /// `blades.*` overrides are kept for the blades' decks; they and the deck's `[blades]` table
    /// are checked here ([`RotorDeck::check_blades`]).
    pub fn from_file_with(path: &Path, overrides: &[Override]) -> anyhow::Result<Self> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| crate::hydraulics::DeckError::read(&file, e).in_deck(deck::ROTOR_DECK))?;
        let spec = deck::RotorSpec::parse(&text, &file)?;
        let root = crate::overrides::parse_deck(&text, &file)?;
        let assumed = assumed::scan(&text, &root);
        let (sets, overrides): (Vec<Override>, Vec<Override>) = overrides
            .iter()
            .cloned()
            .partition(blades::is_blade_override);
        let (root, mut spec) = if overrides.is_empty() {
            (root, spec)
        } else {
            let root = crate::overrides::apply_all(root, &file, &overrides, |t, ov| {
                // the schema's message without its position: the user wrote the value on the
                // command line, which the caller names
                if let Err(e) = deck::RotorSpec::schema(t) {
                    let table = ov.key.rsplit_once('.').map_or("", |(t, _)| t);
                    return Err(deck::deck_error(&file, table, e.message().trim_end()).into());
                }
                deck::RotorSpec::from_table(t, &file)?;
                if ov.is_damper() {
                    DamperDeck::from_toml_table(t.clone(), &file)?;
                }
                Ok(())
            })?;
            let spec = deck::RotorSpec::from_table(&root, &file)?;
            (root, spec)
        };
        let per_blade = spec.blades.take();
        let deck = RotorDeck {
            path: path.to_path_buf(),
            spec,
            table: root,
            blades: blades::PerBlade {
                table: per_blade,
                sets,
            },
            damper: Default::default(),
            assumed,
        };
        deck.check_blades()?;
        Ok(deck)
    }
    /// The files the deck was read from: the deck, its blade section table, then the blades'
    /// other section tables.
    pub fn input_files(&self) -> Vec<std::path::PathBuf> {
        let dir = self.path.parent().unwrap_or(Path::new(""));
        let mut v = vec![self.path.clone(), dir.join(&self.spec.blade.sections_csv)];
        v.extend(self.blade_section_files());
        v
    }
    /// The values the deck file labels `# ASSUMED` (keys as `--set` takes them, with the file's
    /// values and lines; overrides do not change what is labelled).
    pub fn assumed(&self) -> &assumed::Scan {
        &self.assumed
    }
    /// The deck's values as read, overrides applied (keys as `--set` takes them).
    pub fn table(&self) -> &toml::Table {
        &self.table
    }
    /// The deck's `[damper]` table (overrides applied).
    pub fn damper(&self) -> anyhow::Result<DamperDeck> {
        self.damper
            .get_or_init(|| {
                let root = toml::Table::from_iter(
                    self.spec.damper.clone().map(|d| ("damper".to_string(), d)),
                );
                DamperDeck::from_toml_table(root, &self.path.display().to_string())
                    .map_err(|e| e.to_string())
            })
            .clone()
            .map_err(|e| anyhow::anyhow!(e))
    }
    /// The generated multibody model deck (TOML text, docs/model_deck.md).
    pub fn expand(&self, opts: &expand::ExpandOptions) -> String {
        expand::expand(&self.spec, opts)
    }
}

/// Build the forced-response simulation of `rotor` with damper `damper` (its `model` variant)
/// under the airloads and controls of `record`.
pub fn build(
    rotor: &RotorDeck,
    damper: &DamperDeck,
    model: DamperModel,
    record: &FlightRecord,
    opts: &RunOptions,
) -> anyhow::Result<Box<dyn ForcedResponse>> {
    Ok(Box::new(sim::build_sim(
        &rotor.spec,
        &rotor.path,
        damper,
        model,
        record,
        opts,
    )?))
}
