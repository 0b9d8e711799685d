//! Benchmark: cost per call of the closed-form element tangents against the dual-number
//! reference they replace, in one run (compare them as ratios: the machine is noisy).
//! - beam: the cubic element's closed-form tangent (`Beam::tangent`), one 24-lane DualN
//!   evaluation of the residual, and the f64 residual, on the curved, pre-twisted element of
//!   the tangent tests (`structure::beam_tangent_fixture`);
//! - joints: residual and tangent of every joint kind, grounded or not, with a spring and a
//!   damper, closed form against dual (tests/joint_support).
//!
//! `cargo bench --bench structure_tangent`
#[path = "../tests/joint_support/mod.rs"]
mod joint_support;
use criterion::{criterion_group, criterion_main, Criterion};
use rotorsim::structure::beam_tangent_fixture as fixture;
use rotorsim::structure::EvalCtx;
use std::hint::black_box;

fn beam(c: &mut Criterion) {
    let mut rng = fixture::Rng(7);
    let (b, x0, r0) = fixture::test_beam(&mut rng, 0.01, true);
    let k = fixture::config(&mut rng, &x0, &r0, 0.25);
    let cx = EvalCtx {
        t: 0.3,
        load_factor: 0.7,
        gravity: [0.5, -1.0, -9.81],
        cscale: 1.0,
        inertia: true,
        dt: 0.0,
    };
    // the dynamic solver's seeds at h = 2 ms
    let s = fixture::seeds(&mut rng, 2e-3, 1e3, 7e5, [true; 6]);
    let mut g = c.benchmark_group("beam_tangent");
    let mut t = [0.0; 576];
    g.bench_function("closed_form", |bn| {
        bn.iter(|| b.tangent(black_box(&k), &cx, &s, &mut t))
    });
    g.bench_function("dual24", |bn| {
        bn.iter(|| fixture::dual_tangent(&b, black_box(&k), &cx, &s))
    });
    let mut r = [0.0; 24];
    g.bench_function("residual_f64", |bn| {
        bn.iter(|| b.residual(black_box(&k), &cx, &mut r))
    });
    g.finish();
}

fn joints(c: &mut Criterion) {
    use joint_support::*;
    let mut rng = Rng(7);
    let mut g = c.benchmark_group("joint_tangent");
    for kind in KINDS {
        for grounded in [false, true] {
            let cs = case(&mut rng, kind, grounded, Extra::SpringDamper, true);
            let n = sizes(&cs).1;
            let mut r = vec![0.0; n];
            let mut k = vec![0.0; n * n];
            let (a, b, lam, ctx, s) = (&cs.a, &cs.b, &cs.lam[..], &cs.ctx, &cs.seeds[..]);
            let name = format!("{kind:?}_{}", if grounded { "grounded" } else { "free" });
            g.bench_function(format!("{name}/residual_dual"), |bn| {
                bn.iter(|| cs.j.residual::<f64>(a, b, lam, ctx, black_box(&mut r)))
            });
            g.bench_function(format!("{name}/residual_closed"), |bn| {
                bn.iter(|| cs.j.residual_f64(a, b, lam, ctx, black_box(&mut r)))
            });
            g.bench_function(format!("{name}/tangent_dual"), |bn| {
                bn.iter(|| cs.j.tangent_dual(a, b, lam, ctx, s, black_box(&mut k)))
            });
            g.bench_function(format!("{name}/tangent_closed"), |bn| {
                bn.iter(|| cs.j.tangent(a, b, lam, ctx, s, black_box(&mut k)))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, beam, joints);
criterion_main!(benches);
