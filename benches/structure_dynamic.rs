//! Benchmark: 40-element cantilever released from a static tip deflection,
//! generalized-alpha steps on one core. Reports cost per step; iterations per step are printed
//! so that the cost per Newton iteration follows.
use criterion::{criterion_group, criterion_main, Criterion};
use rotorsim::solver::verification::{cantilever, uniform_section};
use rotorsim::solver::{static_solve, DynamicSolver, State, StaticOptions};
use rotorsim::structure::Element;

fn released_cantilever(n_elem: usize) -> DynamicSolver {
    let sec = uniform_section(1e6, 1e6, 100.0, 100.0, 100.0, 1.0, 1e-4, 5e-5, 5e-5);
    let (mut m, _, load) = cantilever(n_elem, 10.0, &sec);
    if let Element::Load(p) = &mut m.elements[load] {
        p.force_n = [0.0, 0.0, 0.05];
    }
    let mut st = State::from_model(&m);
    static_solve(&mut m, &mut st, &StaticOptions::default(), |_, _, _, _| {}).unwrap();
    if let Element::Load(p) = &mut m.elements[load] {
        p.force_n = [0.0; 3];
    }
    DynamicSolver::new(m, st, 0.1, 0.9).unwrap()
}

fn bench(c: &mut Criterion) {
    // iterations per step over a 1000-step release run
    let mut s = released_cantilever(40);
    let t0 = std::time::Instant::now();
    for _ in 0..1000 {
        s.step().unwrap();
    }
    let wall = t0.elapsed().as_secs_f64();
    eprintln!(
        "cantilever40: 1000 steps, {} Newton iterations ({:.3} per step), {:.3} s wall ({:.3} ms/step, {:.3} ms/iteration)",
        s.total_iterations,
        s.total_iterations as f64 / 1000.0,
        wall,
        wall,
        1e3 * wall / s.total_iterations as f64
    );
    let mut g = c.benchmark_group("structure_dynamic");
    g.sample_size(20);
    let mut s = released_cantilever(40);
    g.bench_function("cantilever40_step", |b| {
        b.iter(|| {
            if s.steps >= 1000 {
                s = released_cantilever(40);
            }
            s.step().unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
