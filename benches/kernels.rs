//! Kernel benchmarks: each distance estimator in f64 and f32, and one
//! power-8 triplex iteration by trigonometry, by Quilez's expanded polynomial
//! and by complex squaring (the path the renderer takes).
//! Run with `cargo bench`; CI only builds them.

use mandelreel::fractal::{
    power8_polynomial, triplex_power_int, triplex_power_trig, DeMethod, Estimate, Formula, Fractal,
    Precision,
};
use mandelreel::math::DVec3;

fn main() {
    divan::main();
}

/// Points near the power-8 bulb's surface, where marching spends its time.
fn points() -> Vec<DVec3> {
    (0..256)
        .map(|i| {
            let a = i as f64 * 2.399_963;
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / 256.0;
            let s = (1.0 - z * z).sqrt();
            DVec3::new(s * a.cos(), z, s * a.sin()) * 1.05
        })
        .collect()
}

/// The same points in the kernel's number type.
fn triplexes<T: mandelreel::math::Number>() -> Vec<[T; 3]> {
    points()
        .iter()
        .map(|p| [T::from_real(p.x), T::from_real(p.y), T::from_real(p.z)])
        .collect()
}

const METHODS: [DeMethod; 5] = DeMethod::ALL;

#[divan::bench(args = METHODS)]
fn estimate_f64(bencher: divan::Bencher, de: DeMethod) {
    bench_estimate(bencher, de, Precision::F64);
}

#[divan::bench(args = METHODS)]
fn estimate_f32(bencher: divan::Bencher, de: DeMethod) {
    bench_estimate(bencher, de, Precision::F32);
}

fn bench_estimate(bencher: divan::Bencher, de: DeMethod, precision: Precision) {
    bench_fractal(
        bencher,
        Fractal {
            de,
            precision,
            ..Fractal::default()
        },
    );
}

/// Analytic estimates of `f` at the benchmark points.
fn bench_fractal(bencher: divan::Bencher, f: Fractal) {
    let pts = points();
    bencher
        .counter(divan::counter::ItemsCount::new(pts.len()))
        .bench(|| {
            pts.iter()
                .map(|&p| f.estimate(divan::black_box(p), 1e-4).distance)
                .sum::<f64>()
        });
}

/// One power-8 step at each benchmark point, by `power` (returning one component).
fn bench_power<T: mandelreel::math::Number + Sync>(
    bencher: divan::Bencher,
    power: impl Fn([T; 3]) -> f64 + Sync,
) {
    let pts = triplexes::<T>();
    bencher
        .counter(divan::counter::ItemsCount::new(pts.len()))
        .bench(|| pts.iter().map(|&z| power(divan::black_box(z))).sum::<f64>());
}

#[divan::bench(types = [f64, f32])]
fn power8_trig<T: mandelreel::math::Number + Sync>(bencher: divan::Bencher) {
    bench_power::<T>(bencher, |z| {
        let r = (z[0] * z[0] + z[1] * z[1] + z[2] * z[2]).sqrt();
        triplex_power_trig(Formula::Quilez, z, r, 8.0)[1].value()
    });
}

#[divan::bench(types = [f64, f32])]
fn power8_polynomial_form<T: mandelreel::math::Number + Sync>(bencher: divan::Bencher) {
    bench_power::<T>(bencher, |z| {
        power8_polynomial(z).map_or(0.0, |w| w[1].value())
    });
}

#[divan::bench(types = [f64, f32])]
fn power8_complex_squaring<T: mandelreel::math::Number + Sync>(bencher: divan::Bencher) {
    bench_power::<T>(bencher, |z| {
        triplex_power_int(Formula::Quilez, z, 8).map_or(0.0, |w| w[1].value())
    });
}

const FORMULAS: [Formula; 4] = Formula::ALL;

/// The analytic estimate in each convention (all take the whole-power path).
#[divan::bench(args = FORMULAS)]
fn estimate_formula(bencher: divan::Bencher, formula: Formula) {
    bench_fractal(
        bencher,
        Fractal {
            formula,
            ..Fractal::default()
        },
    );
}

/// The analytic estimate at the same points, `N` at a time through the lanes.
#[divan::bench(consts = [1, 4, 8, 16])]
fn estimate_lanes<const N: usize>(bencher: divan::Bencher) {
    bench_lanes::<N>(bencher, points(), 1, Precision::F64);
}

/// Orbits that never escape (points deep inside): the cost of 12 iterations,
/// counted per iteration.
#[divan::bench(consts = [1, 4, 8, 16])]
fn inside_lanes<const N: usize>(bencher: divan::Bencher) {
    bench_lanes::<N>(bencher, inside(), 12, Precision::F64);
}

/// `estimate_lanes` without orbit traps (`distance_lanes_into`), as shadow,
/// occlusion, normal and cone walks take them.
#[divan::bench(consts = [16])]
fn distance_lanes<const N: usize>(bencher: divan::Bencher) {
    bench_lanes_with::<N>(bencher, points(), 1, Precision::F64, false);
}

/// `estimate_lanes` in f32 (eight lanes to an AVX2 register).
#[divan::bench(consts = [16])]
fn estimate_lanes_f32<const N: usize>(bencher: divan::Bencher) {
    bench_lanes::<N>(bencher, points(), 1, Precision::F32);
}

/// `inside_lanes` in f32.
#[divan::bench(consts = [16])]
fn inside_lanes_f32<const N: usize>(bencher: divan::Bencher) {
    bench_lanes::<N>(bencher, inside(), 12, Precision::F32);
}

fn inside() -> Vec<DVec3> {
    points().iter().map(|p| *p * 0.4).collect()
}

fn bench_lanes<const N: usize>(
    bencher: divan::Bencher,
    pts: Vec<DVec3>,
    items_per_point: usize,
    precision: Precision,
) {
    bench_lanes_with::<N>(bencher, pts, items_per_point, precision, true);
}

/// `bench_lanes`, with orbit traps or without.
fn bench_lanes_with<const N: usize>(
    bencher: divan::Bencher,
    pts: Vec<DVec3>,
    items_per_point: usize,
    precision: Precision,
    traps: bool,
) {
    let f = Fractal {
        precision,
        ..Fractal::default()
    };
    bencher
        .counter(divan::counter::ItemsCount::new(pts.len() * items_per_point))
        .bench(|| {
            pts.chunks_exact(N)
                .map(|c| {
                    let p: [DVec3; N] = std::array::from_fn(|k| c[k]);
                    let mut out = [Estimate::IDLE; N];
                    if traps {
                        f.estimate_lanes_into(divan::black_box(&p), &[1e-4; N], &mut out);
                    } else {
                        f.distance_lanes_into(divan::black_box(&p), &[1e-4; N], &mut out);
                    }
                    out.iter().map(|e| e.distance).sum::<f64>()
                })
                .sum::<f64>()
        });
}
