use rotorsim::hydraulics::*;
fn main() {
    let deck = DamperDeck::from_file(std::path::Path::new("rotors/uh60a.toml")).unwrap();
    let dev = deck
        .build(
            DamperModel::Physical,
            IntegratorOptions {
                scheme: Scheme::Implicit,
                substeps: 25,
            },
        )
        .unwrap();
    let v: f64 = std::env::args().nth(1).unwrap().parse().unwrap();
    let r = bench::harmonic_run(dev.as_ref(), 27.02, v * 0.0254, 10, 256, false);
    println!("{:?}", r.map(|r| r.peak_force_pos_n));
}
