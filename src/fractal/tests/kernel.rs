//! The vector kernel, held bit for bit to the scalar orbit.

use super::*;
use std::marker::PhantomData;

#[test]
fn lanes_are_bit_identical_to_one_estimate_at_a_time() {
    let mut fractals = variants();
    fractals.push(Fractal {
        de: DeMethod::Potential,
        ..Fractal::default()
    });
    // Radii that escape outside the logarithm's range, which lanes
    // finish one at a time: a huge bailout (which `escape_radius` now
    // lowers to about 5.6e18 for power 8, so no lane reaches +∞ any
    // more; it still checks the lowered radius in both paths), and a
    // tiny bailout, outside which most points start.
    for bailout in [1e40, 0.3] {
        fractals.push(Fractal {
            bailout,
            ..Fractal::default()
        });
    }
    // The f32 kernel, which widens its lanes to finish in f64, on each of
    // them, and at bailouts whose square no f32 holds.
    let f64_ones = fractals.clone();
    fractals.extend(f64_ones.into_iter().map(|f| Fractal {
        precision: Precision::F32,
        ..f
    }));
    for bailout in [3.3, 10.1] {
        fractals.push(Fractal {
            bailout,
            precision: Precision::F32,
            ..Fractal::default()
        });
    }
    let mut pts = points(400, 0.0..2.5, 5);
    // Lanes that take the trigonometric form (on and beside every
    // convention's pole axis, the origin) or never iterate (far out,
    // the idle point) mixed in among ordinary ones.
    for (k, p) in [
        DVec3::new(0.0, 0.0, 0.7),
        DVec3::new(0.0, -0.6, 0.0),
        DVec3::new(1e-9, 0.0, 0.5),
        DVec3::new(0.0, 1e-9, -0.4),
        DVec3::ZERO,
        DVec3::new(40.0, -3.0, 2.0),
        IDLE_POINT,
        DVec3::new(4.1, 0.3, -0.2),
        DVec3::new(-0.2, 4.05, 0.4),
        DVec3::new(0.1, 0.05, -0.2),
    ]
    .into_iter()
    .enumerate()
    {
        pts.insert(k * 13 + 3, p);
    }
    fn check<const N: usize>(f: &Fractal, pts: &[DVec3]) {
        for chunk in pts.chunks_exact(N) {
            let p: [DVec3; N] = chunk.try_into().expect("chunks of N");
            let scales: [Real; N] = std::array::from_fn(|k| [1e-3, 1e-4, 2e-3, 1e-5][k % 4]);
            let before = iterations_on_this_thread();
            let lanes = f.estimate_lanes(p, scales);
            let lane_iterations = iterations_on_this_thread() - before;
            let before = iterations_on_this_thread();
            let one: Vec<Estimate> = (0..N).map(|k| f.estimate(p[k], scales[k])).collect();
            assert_eq!(iterations_on_this_thread() - before, lane_iterations);
            for k in 0..N {
                assert_eq!(lanes[k].distance.to_bits(), one[k].distance.to_bits());
                assert_eq!(lanes[k], one[k], "{f:?} at {}", p[k]);
            }
        }
    }
    for f in &fractals {
        // Fewer points than a vector, exactly one, and more than one.
        check::<4>(f, &pts);
        check::<12>(f, &pts);
        check::<16>(f, &pts);
        check::<20>(f, &pts);
    }
}

#[test]
fn every_instruction_set_gives_the_scalar_orbit_bit_for_bit() {
    // The kernel as each instruction set pulp can pick runs it (plain
    // scalar always, AVX2 and AVX-512 where this processor has them),
    // against `orbit` one point at a time: every field, to the bit.
    use pulp::WithSimd;
    let mut outside_ln_range = 0;
    let mut pts = points(96, 0.0..2.5, 9);
    pts.extend([
        DVec3::new(0.0, 0.0, 0.7),
        DVec3::new(0.0, -0.6, 0.0),
        DVec3::ZERO,
    ]);
    pts.extend([
        DVec3::new(40.0, -3.0, 2.0),
        IDLE_POINT,
        DVec3::splat(Real::NAN),
    ]);
    pts.extend([
        DVec3::new(Real::NAN, 0.2, 0.1),
        DVec3::new(1e-40, 2e-40, 0.0),
    ]);
    pts.resize(
        pts.len().next_multiple_of(VECTOR),
        DVec3::new(0.3, 0.2, -0.1),
    );
    for f in [
        Fractal::default(),
        Fractal {
            formula: Formula::Asin,
            bailout: 10.0,
            ..Fractal::default()
        },
        Fractal {
            formula: Formula::WhiteNylander,
            power: 5.0,
            julia: Some(DVec3::new(0.3, -0.5, 0.2)),
            ..Fractal::default()
        },
        // Escaped radii below the logarithm's range, and a bailout past
        // what f64 can reach in one step, lowered by `escape_radius`
        // (timelines allow neither; the kernel must still agree).
        Fractal {
            bailout: 0.45,
            julia: Some(DVec3::new(0.47, 0.01, 0.0)),
            ..Fractal::default()
        },
        Fractal {
            bailout: 1e150,
            ..Fractal::default()
        },
    ] {
        let n = whole_power(f.power).unwrap();
        for chunk in pts.chunks_exact(VECTOR) {
            let points: [DVec3; VECTOR] = chunk.try_into().unwrap();
            let orbits: Vec<Orbit<f64>> = points
                .iter()
                .map(|p| f.orbit([p.x, p.y, p.z], f.iterations, true))
                .collect();
            outside_ln_range += orbits
                .iter()
                .filter(|o| o.escaped && o.iterations > 0 && !crate::math::in_ln_range(o.r))
                .count();
            let expected: Vec<String> = orbits.iter().map(|o| format!("{o:?}")).collect();
            // Estimates too: their logarithm and division run in the registers.
            let estimated: Vec<String> = points
                .iter()
                .map(|&p| format!("{:?}", f.estimate(p, 1e-4)))
                .collect();
            // The first `live` lanes as the scalar path gives them; lanes
            // in registers (of `width` lanes) holding no wanted lane are
            // left untouched.
            let check = |(orbits, estimates): ([Orbit<f64>; VECTOR], [Estimate; VECTOR]),
                         live: usize,
                         width: usize,
                         arch: &str| {
                let skipped = live.next_multiple_of(width);
                for (k, o) in orbits.iter().enumerate() {
                    let o = format!("{o:?}");
                    if k < live {
                        assert_eq!(o, expected[k], "{arch} {live} at {}", points[k]);
                    } else if k >= skipped {
                        assert_eq!(o, format!("{:?}", Orbit::<f64>::IDLE), "{arch} {live}");
                    }
                }
                for (k, e) in estimates.iter().enumerate() {
                    let e = format!("{e:?}");
                    if k < live {
                        assert_eq!(e, estimated[k], "{arch} {live} at {}", points[k]);
                    } else if k >= skipped {
                        assert_eq!(e, format!("{:?}", Estimate::IDLE), "{arch} {live}");
                    }
                }
            };
            // What rendering runs (the widest set found), then each set,
            // with every lane wanted and with the last ones padding.
            fn on<S: pulp::Simd>(
                simd: S,
                f: &Fractal,
                points: [DVec3; VECTOR],
                live: usize,
                n: u32,
            ) -> ([Orbit<f64>; VECTOR], [Estimate; VECTOR]) {
                let mut out = ([Orbit::IDLE; VECTOR], [Estimate::IDLE; VECTOR]);
                let fractal = f;
                let points = &points;
                Kernel::<f64, _, true> {
                    fractal,
                    points,
                    live,
                    n,
                    out: &mut out.0,
                    lane: PhantomData,
                }
                .with_simd(simd);
                Kernel::<f64, _, true> {
                    fractal,
                    points,
                    live,
                    n,
                    out: &mut out.1,
                    lane: PhantomData,
                }
                .with_simd(simd);
                // As `estimate_lanes_into` finishes the kernel's estimates.
                f.bound_lanes::<f64>(&points[..live], &mut out.1[..live]);
                out
            }
            check(
                (
                    f.orbit_lanes(points).expect("a whole power"),
                    f.estimate_lanes(points, [1e-4; VECTOR]),
                ),
                VECTOR,
                VECTOR,
                "dispatched",
            );
            for live in [VECTOR, 1, 4, 5, 8, 9, 12, 13] {
                check(
                    on(pulp::Scalar::new(), &f, points, live, n),
                    live,
                    1,
                    "scalar",
                );
                #[cfg(target_arch = "x86_64")]
                {
                    if let Some(v3) = pulp::x86::V3::try_new() {
                        check(on(v3, &f, points, live, n), live, 4, "AVX2");
                    }
                    if let Some(v4) = pulp::x86::V4::try_new() {
                        check(on(v4, &f, points, live, n), live, 8, "AVX-512");
                    }
                }
            }
        }
    }
    // The lanes whose logarithm the kernel leaves to `f64::ln` were met.
    assert!(outside_ln_range > 0);
}

#[test]
fn the_f32_kernel_gives_the_scalar_f32_estimate_bit_for_bit_on_each_instruction_set() {
    // f32 orbits in registers of eight (AVX2) or one at a time (scalar),
    // widened to finish in f64, against `estimate` in f32 one point at a
    // time: every field, to the bit, with padding lanes left alone.
    let mut pts = points(192, 0.0..2.5, 11);
    pts.extend([
        DVec3::new(0.0, 0.0, 0.7),
        DVec3::new(0.0, -0.6, 0.0),
        DVec3::new(1e-9, 0.0, 0.5),
        DVec3::ZERO,
        DVec3::new(40.0, -3.0, 2.0),
        IDLE_POINT,
        DVec3::splat(Real::NAN),
        DVec3::new(1e-40, 2e-40, 0.0),
    ]);
    pts.resize(
        pts.len().next_multiple_of(VECTOR),
        DVec3::new(0.3, 0.2, -0.1),
    );
    let f32_of = |f: Fractal| Fractal {
        precision: Precision::F32,
        ..f
    };
    for f in [
        f32_of(Fractal::default()),
        f32_of(Fractal {
            formula: Formula::Asin,
            bailout: 10.1,
            ..Fractal::default()
        }),
        f32_of(Fractal {
            formula: Formula::WhiteNylander,
            power: 5.0,
            julia: Some(DVec3::new(0.3, -0.5, 0.2)),
            ..Fractal::default()
        }),
        f32_of(Fractal {
            formula: Formula::Quaternion,
            power: 2.0,
            iterations: 30,
            ..Fractal::default()
        }),
        // A bailout past what f32 reaches in one step: `escape_radius`
        // lowers it, in both paths.
        f32_of(Fractal {
            bailout: 1e6,
            ..Fractal::default()
        }),
    ] {
        for chunk in pts.chunks_exact(VECTOR) {
            let points: [DVec3; VECTOR] = chunk.try_into().unwrap();
            let expected: Vec<String> = points
                .iter()
                .map(|&p| format!("{:?}", f.estimate(p, 1e-4)))
                .collect();
            let check = |estimates: [Estimate; VECTOR], live: usize, width: usize, arch: &str| {
                let skipped = live.next_multiple_of(width);
                for (k, e) in estimates.iter().enumerate() {
                    let e = format!("{e:?}");
                    if k < live {
                        assert_eq!(e, expected[k], "{arch} {live} at {}", points[k]);
                    } else if k >= skipped {
                        assert_eq!(e, format!("{:?}", Estimate::IDLE), "{arch} {live}");
                    }
                }
            };
            let dispatched = f.estimate_lanes(points, [1e-4; VECTOR]);
            check(dispatched, VECTOR, VECTOR, "dispatched");
            for live in [VECTOR, 1, 5, 8, 9, 13] {
                check(
                    kernel_estimates::<_, f32, true>(pulp::Scalar::new(), &f, &points, live, IDLE),
                    live,
                    1,
                    "scalar",
                );
                #[cfg(target_arch = "x86_64")]
                if let Some(v3) = pulp::x86::V3::try_new() {
                    let estimates = kernel_estimates::<_, f32, true>(v3, &f, &points, live, IDLE);
                    check(estimates, live, 8, "AVX2");
                }
            }
        }
    }
}

#[test]
fn estimates_without_traps_keep_every_other_field_bit_for_bit_on_each_instruction_set() {
    // The kernel without orbit traps (`distance_lanes_into`, for walks
    // that read only distances) against the kernel with them, on every
    // instruction set and in both lane floats: the same distance,
    // iterations, escape and cost to the bit, and `out`'s traps and ends
    // left as they were.
    let mut pts = points(160, 0.0..2.5, 13);
    pts.extend([
        DVec3::new(0.0, 0.0, 0.7),
        DVec3::ZERO,
        DVec3::new(40.0, -3.0, 2.0),
        IDLE_POINT,
        DVec3::splat(Real::NAN),
    ]);
    pts.resize(
        pts.len().next_multiple_of(VECTOR),
        DVec3::new(0.3, 0.2, -0.1),
    );
    let before = Estimate {
        traps: OrbitTraps {
            origin: 7.0,
            planes: DVec3::new(5.0, 6.0, 7.0),
        },
        end: [9.0, -9.0, 8.0],
        ..Estimate::IDLE
    };
    fn compare(with: &[Estimate], without: &[Estimate], before: &Estimate, what: &str) {
        for (k, (a, b)) in with.iter().zip(without).enumerate() {
            let fields = |e: &Estimate| (e.distance.to_bits(), e.iterations, e.escaped, e.orbits);
            assert_eq!(fields(a), fields(b), "{what}, lane {k}");
            let orbit = |e: &Estimate| format!("{:?} {:?}", e.traps, e.end);
            assert_eq!(orbit(b), orbit(before), "{what}, lane {k}");
        }
    }
    fn both<S: pulp::Simd, E: KernelLane>(
        simd: S,
        f: &Fractal,
        points: &[DVec3; VECTOR],
        before: Estimate,
        what: &str,
    ) {
        for live in [VECTOR, 1, 5, 9, 13] {
            let with = kernel_estimates::<S, E, true>(simd, f, points, live, before);
            let without = kernel_estimates::<S, E, false>(simd, f, points, live, before);
            compare(
                &with[..live],
                &without[..live],
                &before,
                &format!("{what} {live}"),
            );
        }
    }
    let mut fractals = variants();
    let f64_ones = fractals.clone();
    fractals.extend(f64_ones.into_iter().map(|f| Fractal {
        precision: Precision::F32,
        ..f
    }));
    let mut met_traps = 0;
    for f in fractals.iter().filter(|f| whole_power(f.power).is_some()) {
        for chunk in pts.chunks_exact(VECTOR) {
            let points: &[DVec3; VECTOR] = chunk.try_into().unwrap();
            // What rendering runs.
            let mut with = [before; VECTOR];
            let mut without = [before; VECTOR];
            f.estimate_lanes_into(points, &[1e-4; VECTOR], &mut with);
            f.distance_lanes_into(points, &[1e-4; VECTOR], &mut without);
            let orbit = |e: &Estimate| format!("{:?} {:?}", e.traps, e.end);
            met_traps += with.iter().filter(|e| orbit(e) != orbit(&before)).count();
            compare(&with, &without, &before, &format!("{f:?} dispatched"));
            // Fewer points than a call takes: the rest of the call is padding.
            let short: &[DVec3; 5] = chunk[..5].try_into().unwrap();
            let (mut with, mut without) = ([before; 5], [before; 5]);
            f.estimate_lanes_into(short, &[1e-4; 5], &mut with);
            f.distance_lanes_into(short, &[1e-4; 5], &mut without);
            compare(&with, &without, &before, &format!("{f:?} 5 points"));
            let what = format!("{f:?}");
            match f.precision {
                Precision::F64 => both::<_, f64>(pulp::Scalar::new(), f, points, before, &what),
                Precision::F32 => both::<_, f32>(pulp::Scalar::new(), f, points, before, &what),
            }
            #[cfg(target_arch = "x86_64")]
            if let Some(v3) = pulp::x86::V3::try_new() {
                match f.precision {
                    Precision::F64 => both::<_, f64>(v3, f, points, before, &what),
                    Precision::F32 => both::<_, f32>(v3, f, points, before, &what),
                }
            }
            #[cfg(target_arch = "x86_64")]
            if let (Some(v4), Precision::F64) = (pulp::x86::V4::try_new(), f.precision) {
                both::<_, f64>(v4, f, points, before, &what);
            }
        }
    }
    // The kernel with traps wrote its own traps and ends over `before`'s,
    // so the kernel without them leaving `before`'s is a difference.
    assert!(met_traps > 0);
}

const IDLE: Estimate = Estimate::IDLE;

/// The kernel's estimates of the first `live` of `points` on `simd`, in
/// `E`, with traps or (`TRAPS` false) without, finished as
/// `estimate_lanes_into` finishes them, into an array of `fill`.
fn kernel_estimates<S: pulp::Simd, E: KernelLane, const TRAPS: bool>(
    simd: S,
    f: &Fractal,
    points: &[DVec3; VECTOR],
    live: usize,
    fill: Estimate,
) -> [Estimate; VECTOR] {
    use pulp::WithSimd;
    let mut out = [fill; VECTOR];
    let n = whole_power(f.power).expect("a whole power");
    Kernel::<E, _, TRAPS> {
        fractal: f,
        points,
        live,
        n,
        out: &mut out,
        lane: PhantomData,
    }
    .with_simd(simd);
    f.bound_lanes::<E>(&points[..live], &mut out[..live]);
    out
}
