//! The replay's own timing against closed forms: a stroke history sampled at 2 kHz and replayed
//! through a damper must give the force at the sample instants with no lag of the replay's own.
//! Driven along the chord between samples, a dashpot answered with the interval's mean rate, the
//! rate half a sample earlier (a 250 us lag at 2 kHz); the Hermite path between samples with
//! the samples' rates (src/hydraulics/path.rs) removes it.
use rotorsim::hydraulics::bench::{replay, replay_force, BenchTest};
use rotorsim::hydraulics::{
    DamperDeck, DamperModel, Device, IntegratorOptions, LinearDashpot, Scheme,
};
use std::f64::consts::PI;
use std::path::Path;

const RATE_HZ: f64 = 2000.0;

/// A stroke as a sum of sines `(omega, amplitude, phase)` and its exact rate.
struct Stroke(Vec<(f64, f64, f64)>);

impl Stroke {
    fn at(&self, t: f64) -> (f64, f64) {
        self.0.iter().fold((0.0, 0.0), |(x, v), &(w, a, p)| {
            (x + a * (w * t + p).sin(), v + a * w * (w * t + p).cos())
        })
    }
}

fn samples(stroke: &Stroke, duration_s: f64, rate_hz: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = (duration_s * rate_hz).round() as usize + 1;
    let t: Vec<f64> = (0..n).map(|k| k as f64 / rate_hz).collect();
    let (x, v) = t.iter().map(|&s| stroke.at(s)).unzip();
    (t, x, v)
}

/// Lag `tau` [s] and gain `g` of `model` against `exact` by least squares of
/// `model ~ g (exact - tau exact')` over the samples from `from` on (exact' by the closed form).
fn lag_and_gain(model: &[f64], exact: &[f64], exact_rate: &[f64], from: usize) -> (f64, f64) {
    // normal equations in (g, g tau)
    let (mut a11, mut a12, mut a22, mut b1, mut b2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for i in from..model.len() {
        let (f, d) = (exact[i], -exact_rate[i]);
        a11 += f * f;
        a12 += f * d;
        a22 += d * d;
        b1 += f * model[i];
        b2 += d * model[i];
    }
    let det = a11 * a22 - a12 * a12;
    let g = (b1 * a22 - b2 * a12) / det;
    let gt = (a11 * b2 - a12 * b1) / det;
    (gt / g, g)
}

/// The case: 2 mm at 4.3 Hz through an exact linear dashpot of 68 000 N s/m.
#[test]
fn a_linear_dashpot_replays_without_lag() {
    let c = 68_000.0;
    let w = 2.0 * PI * 4.3;
    let stroke = Stroke(vec![(w, 2e-3, 0.0)]);
    let (t, x, v) = samples(&stroke, 2.0, RATE_HZ);
    let exact: Vec<f64> = v.iter().map(|r| -c * r).collect();
    let exact_rate: Vec<f64> = t
        .iter()
        .map(|&s| c * 2e-3 * w * w * (w * s).sin())
        .collect();
    let model = replay_force(&LinearDashpot::new(c), &t, &x).unwrap();
    let (lag, gain) = lag_and_gain(&model, &exact, &exact_rate, 10);
    assert!(lag.abs() < 1e-6, "lag {lag} s");
    assert!((gain - 1.0).abs() < 1e-4, "gain {gain}");
    let rms = (model[10..]
        .iter()
        .zip(&exact[10..])
        .map(|(a, b)| (a - b) * (a - b))
        .sum::<f64>()
        / (model.len() - 10) as f64)
        .sqrt();
    // 3674 N peak: the chord's half sample gave 17.5 N
    assert!(rms < 0.05, "RMS {rms} N");
    // the chord between samples (one straight step per sample) lags by half a sample
    let mut dev = LinearDashpot::new(c);
    let chord: Vec<f64> = std::iter::once(0.0)
        .chain((0..t.len() - 1).map(|k| {
            let f = dev.trial_step(t[k], t[k + 1] - t[k], x[k], x[k + 1]);
            dev.commit();
            f.unwrap().force_end
        }))
        .collect();
    let (chord_lag, _) = lag_and_gain(&chord, &exact, &exact_rate, 10);
    assert!(
        (chord_lag - 0.5 / RATE_HZ).abs() < 1e-6,
        "chord lag {chord_lag} s"
    );
    eprintln!(
        "dashpot: lag {lag:.3e} s, gain {gain:.8}, RMS {rms:.4} N; chord lag {chord_lag:.4e} s"
    );
    // the replay with channels (bench --measured) is the same force
    let test = BenchTest::from_arrays("sine", t.clone(), x.clone()).unwrap();
    let r = replay(&LinearDashpot::new(c), &test).unwrap();
    assert_eq!(r.force_model_n, model);
}

/// Harmonics 1-4 of 18.01 rad/s with Schroeder phases (the bench's multi-sine).
#[test]
fn a_multisine_replays_without_lag() {
    let c = 68_000.0;
    let w0 = 18.01;
    let terms: Vec<(f64, f64, f64)> = (1..=4)
        .map(|k| {
            let ph = -PI * (k * (k - 1)) as f64 / 4.0;
            (k as f64 * w0, 2e-3 / k as f64, ph)
        })
        .collect();
    let stroke = Stroke(terms.clone());
    let (t, x, v) = samples(&stroke, 1.5, RATE_HZ);
    let exact: Vec<f64> = v.iter().map(|r| -c * r).collect();
    let accel = |s: f64| {
        terms
            .iter()
            .map(|&(w, a, p)| -a * w * w * (w * s + p).sin())
            .sum::<f64>()
    };
    let exact_rate: Vec<f64> = t.iter().map(|&s| -c * accel(s)).collect();
    let model = replay_force(&LinearDashpot::new(c), &t, &x).unwrap();
    let (lag, gain) = lag_and_gain(&model, &exact, &exact_rate, 10);
    assert!(lag.abs() < 1e-6, "lag {lag} s");
    assert!((gain - 1.0).abs() < 1e-4, "gain {gain}");
    eprintln!("multisine: lag {lag:.3e} s, gain {gain:.8}");
}

fn physical(deck: &DamperDeck, substeps: usize) -> Box<dyn rotorsim::hydraulics::Device> {
    deck.build(
        DamperModel::Physical,
        IntegratorOptions {
            scheme: Scheme::Rk4,
            substeps,
        },
    )
    .unwrap()
}

/// The physical damper of the shipped deck at small and moderate amplitude, against a finely
/// resolved reference: the same stroke sampled 32 times as often (the stroke's exact rates at
/// the fine samples), read at the coarse instants. Sub-steps of 10 us in both.
#[test]
fn the_physical_damper_replays_without_lag() {
    let deck = DamperDeck::from_file(Path::new("rotors/uh60a.toml")).unwrap();
    let w = 2.0 * PI * 4.3;
    for amp in [1e-4, 2e-3] {
        let stroke = Stroke(vec![(w, amp, 0.0)]);
        let (t, x, _) = samples(&stroke, 0.7, RATE_HZ);
        let model = replay_force(physical(&deck, 50).as_ref(), &t, &x).unwrap();
        let fine = 32;
        let (tf, xf, _) = samples(&stroke, 0.7, RATE_HZ * fine as f64);
        let reference: Vec<f64> = replay_force(physical(&deck, 2).as_ref(), &tf, &xf)
            .unwrap()
            .into_iter()
            .step_by(fine)
            .collect();
        assert_eq!(reference.len(), model.len());
        // the reference's rate by central differences of its fine force, at the coarse samples
        let fine_force = replay_force(physical(&deck, 2).as_ref(), &tf, &xf).unwrap();
        let h = 1.0 / (RATE_HZ * fine as f64);
        let rate: Vec<f64> = (0..model.len())
            .map(|i| {
                let j = (i * fine).clamp(1, fine_force.len() - 2);
                (fine_force[j + 1] - fine_force[j - 1]) / (2.0 * h)
            })
            .collect();
        // after the first cycle (the damper settles from rest)
        let from = (RATE_HZ / 4.3).ceil() as usize;
        let (lag, gain) = lag_and_gain(&model, &reference, &rate, from);
        eprintln!("physical {amp} m: lag {lag:.3e} s, gain {gain:.8}");
        assert!(lag.abs() < 1e-6, "amplitude {amp} m: lag {lag} s");
        assert!((gain - 1.0).abs() < 1e-4, "amplitude {amp} m: gain {gain}");
    }
}
