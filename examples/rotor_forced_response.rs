//! Quick forced response of rotors/uh60a.toml under flightdata/c8534like: prints the channels
//! every 1/8 revolution and the cost per step. Usage: `cargo run --release --example
//! rotor_forced_response -- [linear|nonlinear|physical] [revs] [steps_per_rev]`.
use rotorsim::flight::FlightRecord;
use rotorsim::hydraulics::DamperModel;
use rotorsim::rotor::{build, RotorDeck, RunOptions};
fn main() -> anyhow::Result<()> {
    let model: DamperModel = std::env::args()
        .nth(1)
        .unwrap_or("linear".into())
        .parse()
        .map_err(anyhow::Error::msg)?;
    let revs: f64 = std::env::args().nth(2).unwrap_or("1".into()).parse()?;
    let spr: usize = std::env::args().nth(3).unwrap_or("256".into()).parse()?;
    let deck_path = std::env::var("ROTOR_DECK").unwrap_or("rotors/uh60a.toml".into());
    let deck = RotorDeck::from_file(std::path::Path::new(&deck_path))?;
    let damper = deck.damper()?;
    let rec = FlightRecord::read(std::path::Path::new("flightdata/c8534like.meta.json"))?;
    let t0 = std::time::Instant::now();
    let mut sim = build(
        &deck,
        &damper,
        model,
        &rec,
        &RunOptions {
            steps_per_rev: spr,
            ..Default::default()
        },
    )?;
    println!("build {:.2} s", t0.elapsed().as_secs_f64());
    let names = sim.channel_names();
    let mut ch = vec![0.0; names.len()];
    let n = (revs * spr as f64) as usize;
    // per revolution: force range and the largest change of the force from the previous
    // revolution at the same azimuth, relative to the force range
    let mut prev: Vec<f64> = vec![];
    let mut cur: Vec<f64> = Vec::with_capacity(spr);
    for k in 0..n {
        sim.step()?;
        sim.channels(&mut ch);
        cur.push(ch[0]);
        if cur.len() == spr {
            let (lo, hi) = cur
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |a, &v| {
                    (a.0.min(v), a.1.max(v))
                });
            let dmax = if prev.len() == spr {
                cur.iter()
                    .zip(&prev)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max)
                    / (hi - lo)
            } else {
                f64::NAN
            };
            println!("rev {:3}: force {lo:9.1} .. {hi:9.1} N, change vs previous rev {dmax:.2e}, tip flap {:.4} m lag {:.4} m twist {:.4} rad", (k + 1) / spr, ch[3], ch[4], ch[5]);
            prev = std::mem::take(&mut cur);
        }
    }
    let t = sim.timing();
    println!(
        "{:?} ms/step {:.3} ms/iter {:.3}",
        t,
        t.total_s / t.steps as f64 * 1e3,
        t.total_s / t.iterations as f64 * 1e3
    );
    println!("{:?}", names);
    Ok(())
}
