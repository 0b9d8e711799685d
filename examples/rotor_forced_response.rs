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
    let deck = RotorDeck::from_file(std::path::Path::new("rotors/uh60a.toml"))?;
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
    for k in 0..n {
        sim.step()?;
        if k % (spr / 8) == 0 || k == n - 1 {
            sim.channels(&mut ch);
            println!(
                "psi {:8.1} {}",
                sim.azimuth_deg(),
                ch.iter()
                    .take(9)
                    .map(|v| format!("{v:10.4e}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            );
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
