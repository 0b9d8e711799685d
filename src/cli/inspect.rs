//! `rotorsim inspect RECORD`: what a flight record holds.
use crate::flight::FlightRecord;
use clap::Args;
use std::fmt::Write as _;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct InspectArgs {
    /// The record: an .mcap file, a CSV stem (flightdata/c8534like) or one of its files.
    pub record: PathBuf,
}

pub fn run(args: InspectArgs) -> anyhow::Result<()> {
    // The error names the file, line or channel already.
    let rec = FlightRecord::read(&args.record)?;
    out!("{}", summary(&rec, &args.record.display().to_string()));
    Ok(())
}

fn range(v: impl Iterator<Item = f64>) -> (f64, f64) {
    v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    })
}

/// The text `inspect` prints.
pub fn summary(rec: &FlightRecord, name: &str) -> String {
    let mut s = String::new();
    let m = &rec.meta;
    let banner = if m.synthetic {
        "*** SYNTHETIC (not flight-test data) ***"
    } else {
        "measured (flight-test data)"
    };
    let _ = writeln!(s, "flight record {name}");
    let _ = writeln!(s, "  {banner}");
    if let Some(c) = &m.counter {
        let _ = writeln!(s, "  counter: {c}");
    }
    if let Some(d) = &m.description {
        let _ = writeln!(s, "  description: {d}");
    }
    let _ = writeln!(
        s,
        "  rotor speed: {} rad/s, radius: {} m",
        m.rotor_speed_rad_s, m.radius_m
    );
    let _ = writeln!(
        s,
        "  controls [deg]: collective {}, lateral cyclic {}, longitudinal cyclic {}",
        m.controls_deg.collective,
        m.controls_deg.lateral_cyclic,
        m.controls_deg.longitudinal_cyclic
    );
    let known = [
        "counter",
        "synthetic",
        "description",
        "rotor_speed_rad_s",
        "radius_m",
        "controls_deg",
    ];
    for (k, v) in m.raw.iter().filter(|(k, _)| !known.contains(&k.as_str())) {
        let _ = writeln!(s, "  {k}: {v}");
    }
    let revs = rec.revolutions();
    let az = rec.azimuths_deg();
    let st = rec.stations_r_over_r();
    let _ = writeln!(s, "channels:");
    let _ = writeln!(
        s,
        "  airloads: normal_force_N_per_m, chord_force_N_per_m, pitching_moment_N_m_per_m (section frame: +z, -y = drag, nose up about +x)"
    );
    let _ = writeln!(
        s,
        "    revolutions: {} ({}..={}){}",
        revs.len(),
        revs[0],
        revs[revs.len() - 1],
        gaps(&rec.missing_revolutions())
    );
    let d = if az.len() > 1 {
        format!(", step {} deg", az[1] - az[0])
    } else {
        String::new()
    };
    let uniform = az
        .windows(2)
        .all(|w| ((w[1] - w[0]) - 360.0 / az.len() as f64).abs() < 1e-9);
    let _ = writeln!(
        s,
        "    azimuths per revolution: {} ({} .. {} deg{d}, {})",
        az.len(),
        az[0],
        az[az.len() - 1],
        if uniform { "uniform" } else { "non-uniform" }
    );
    let _ = writeln!(s, "    stations r/R ({}): {:?}", st.len(), st);
    for (name, unit, v) in [
        ("normal force", "N/m", rec.normal_n_per_m()),
        ("chord force", "N/m", rec.chord_n_per_m()),
        ("pitching moment", "N m/m", rec.moment_n_m_per_m()),
    ] {
        let (lo, hi) = range(v.iter().copied());
        let _ = writeln!(s, "    {name}: {lo} .. {hi} {unit}");
    }
    let dm = rec.damper();
    let drevs = rec.damper_revolutions();
    let _ = writeln!(
        s,
        "  damper: damper_force_N{}",
        if rec.has_stroke() {
            ", damper_stroke_m"
        } else {
            " (no stroke)"
        }
    );
    let per_rev = dm.len() / drevs.len().max(1);
    let _ = writeln!(
        s,
        "    samples: {} ({} revolutions x {} azimuths)",
        dm.len(),
        drevs.len(),
        per_rev
    );
    let (lo, hi) = range(dm.iter().map(|x| x.force_N));
    let _ = writeln!(s, "    force: {lo} .. {hi} N");
    if rec.has_stroke() {
        let (lo, hi) = range(dm.iter().filter_map(|x| x.stroke_m));
        let _ = writeln!(s, "    stroke: {lo} .. {hi} m");
    }
    if let Some(mo) = &rec.motion {
        let _ = writeln!(s, "{}", motion_line(mo, m.rotor_speed_rad_s));
    }
    let t_end = rec.time_s(revs[revs.len() - 1], az[az.len() - 1]);
    let _ = writeln!(
        s,
        "  time span: {} .. {t_end} s (time = (revolution * 360 + azimuth) / Omega)",
        rec.time_s(revs[0], az[0])
    );
    if m.synthetic {
        let _ = writeln!(s, "  {banner}");
    }
    s
}

fn gaps(missing: &[u32]) -> String {
    if missing.is_empty() {
        String::new()
    } else {
        format!(", GAPS: missing revolution(s) {missing:?}")
    }
}

/// One line on the measured blade motion: revolutions, azimuths, and per channel the mean and
/// the 1/rev amplitude of the revolution average [deg].
fn motion_line(mo: &crate::flight::BladeMotion, omega_rad_s: f64) -> String {
    let revs = mo.revolutions();
    let head = format!(
        "  motion (blade 1): flap_deg, lag_deg, pitch_deg; {} revolutions ({}..={}){} x {} azimuths",
        revs.len(),
        revs[0],
        revs[revs.len() - 1],
        gaps(&crate::flight::record::missing_revolutions_of(revs)),
        mo.azimuths_deg().len()
    );
    let stats = match mo.periodic(1.min(mo.max_harmonics()), omega_rad_s) {
        Ok(p) => {
            let mean = p.mean_rad().map(f64::to_degrees);
            match p.amplitude_rad(1) {
                Some(a) => {
                    let a = a.map(f64::to_degrees);
                    format!(
                        "flap {:.4} deg mean, {:.4} deg 1/rev; lag {:.4} mean, {:.4} 1/rev; pitch {:.4} mean, {:.4} 1/rev",
                        mean[0], a[0], mean[1], a[1], mean[2], a[2]
                    )
                }
                None => format!(
                    "flap {:.4} deg mean; lag {:.4} mean; pitch {:.4} mean (too few azimuths for 1/rev)",
                    mean[0], mean[1], mean[2]
                ),
            }
        }
        Err(_) => "mean and 1/rev not shown: the azimuth grid is not uniform".into(),
    };
    format!("{head}; {stats}")
}
