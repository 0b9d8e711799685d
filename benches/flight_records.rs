//! Flight records: reading (CSV, MCAP) and replaying a 100-revolution record of 1024 azimuths x
//! 9 stations. Results in docs/performance.md.
use criterion::{criterion_group, criterion_main, Criterion};
use rotorsim::flight::{
    AirloadReplay, DamperSample, FlightMeta, FlightRecord, ReplayMode, ReplayOptions,
};
use std::hint::black_box;
use std::path::Path;

fn big_record() -> FlightRecord {
    let (n_rev, n_az) = (100u32, 1024usize);
    let st = vec![0.225, 0.4, 0.55, 0.675, 0.775, 0.865, 0.92, 0.965, 0.99];
    let az: Vec<f64> = (0..n_az).map(|j| j as f64 * 360.0 / n_az as f64).collect();
    let mut v = [Vec::new(), Vec::new(), Vec::new()];
    for r in 0..n_rev {
        for &p in &az {
            for &s in &st {
                let x = p.to_radians();
                v[0].push(3000.0 * s * (1.0 + 0.3 * x.sin()) + 0.001 * r as f64);
                v[1].push(-200.0 * s * x.cos());
                v[2].push(-30.0 * s * (2.0 * x).sin());
            }
        }
    }
    let damper = (0..n_rev)
        .flat_map(|r| {
            az.iter().map(move |&p| DamperSample {
                revolution: r,
                azimuth_deg: p,
                force_N: 1.0e4 * p.to_radians().sin(),
                stroke_m: Some(0.013 + 0.003 * p.to_radians().cos()),
            })
        })
        .collect();
    let meta = serde_json::json!({
        "synthetic": true, "counter": "bench", "rotor_speed_rad_s": 27.0, "radius_m": 8.178,
        "controls_deg": {"collective": 11.0, "lateral_cyclic": 2.0, "longitudinal_cyclic": -8.0}
    });
    let meta =
        FlightMeta::from_json(meta.as_object().unwrap().clone(), Path::new("bench")).unwrap();
    let [n, c, m] = v;
    FlightRecord::new(meta, st, (0..n_rev).collect(), az, n, c, m, damper).unwrap()
}

fn bench(c: &mut Criterion) {
    let rec = big_record();
    let dir = std::env::temp_dir().join(format!("rotorsim-flight-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let stem = dir.join("big");
    rec.write_csv(&stem).unwrap();
    rec.write_mcap(&dir.join("big.mcap")).unwrap();

    let mut g = c.benchmark_group("flight_100rev_1024az_9st");
    g.sample_size(10);
    g.bench_function("read_csv", |b| {
        b.iter(|| black_box(FlightRecord::read(&stem).unwrap()))
    });
    g.bench_function("read_mcap", |b| {
        b.iter(|| black_box(FlightRecord::read(&dir.join("big.mcap")).unwrap()))
    });
    g.bench_function("write_mcap", |b| {
        b.iter(|| rec.write_mcap(&dir.join("w.mcap")).unwrap())
    });
    g.bench_function("replay_new_sequence", |b| {
        b.iter(|| {
            black_box(
                AirloadReplay::new(&rec, ReplayMode::Sequence, ReplayOptions::default()).unwrap(),
            )
        })
    });
    g.bench_function("replay_new_average", |b| {
        b.iter(|| {
            black_box(
                AirloadReplay::new(&rec, ReplayMode::Average, ReplayOptions::default()).unwrap(),
            )
        })
    });
    g.finish();

    // Query cost: 1000 queries per iteration (50 radii x 20 times) in a hot-loop pattern.
    let seq = AirloadReplay::new(&rec, ReplayMode::Sequence, ReplayOptions::default()).unwrap();
    let h10 = AirloadReplay::new(
        &rec,
        ReplayMode::Average,
        ReplayOptions {
            harmonics: Some(10),
            ..Default::default()
        },
    )
    .unwrap();
    let mut g = c.benchmark_group("flight_replay_query_x1000");
    for (name, rp) in [("sequence_linear", &seq), ("average_10_harmonics", &h10)] {
        g.bench_function(name, |b| {
            let mut t0 = 0.0;
            b.iter(|| {
                let mut acc = 0.0;
                for k in 0..20 {
                    let t = t0 + k as f64 * 1.3e-3;
                    for i in 0..50 {
                        let r = 0.5 + i as f64 * 0.155;
                        acc += rp.section_loads(black_box(t), r).normal_N_per_m;
                    }
                }
                t0 += 0.0173;
                black_box(acc)
            })
        });
    }
    g.finish();
    std::fs::remove_dir_all(&dir).ok();
}

criterion_group!(benches, bench);
criterion_main!(benches);
