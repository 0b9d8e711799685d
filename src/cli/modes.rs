//! `rotorsim modes` (issue #3): natural frequencies and mode shapes of a model deck, about the
//! static equilibrium, optionally in a frame rotating at each of `[modes] speeds_rad_s` (fan).
use crate::io::{csv_string, OutDir};
use crate::solver::modal::{modes, ModalOptions, Mode};
use crate::solver::statics::check_constraints;
use crate::solver::{static_solve, State, StaticOptions};
use crate::structure::deck::load_deck;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct ModesArgs {
    /// Model deck (TOML, see docs/model_deck.md).
    pub deck: PathBuf,
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
    let (deck, mut model) = load_deck(&args.deck)?;
    let file = args.deck.display().to_string();
    let st0 = State::from_model(&model);
    check_constraints(&mut model, &st0).map_err(|e| anyhow::anyhow!("deck {file}: {e}"))?;
    let out = OutDir::create(&args.out)?;
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
            },
        ) {
            Ok(m) => m,
            Err(e) => {
                out.mark_incomplete(&e.to_string())?;
                return Err(e.into());
            }
        };
        println!("Omega = {sp} rad/s");
        for (i, m) in ms.iter().enumerate() {
            println!(
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
