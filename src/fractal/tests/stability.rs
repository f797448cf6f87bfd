//! The stability catalogue (docs/stability.md): each case fails on the
//! naive formula, shown first, and passes on ours.

use super::*;

fn every_variant() -> Vec<Fractal> {
    let mut v = Vec::new();
    for formula in Formula::ALL {
        for de in DeMethod::ALL {
            for precision in [Precision::F64, Precision::F32] {
                for julia in [None, Some(DVec3::new(0.3, -0.5, 0.2))] {
                    v.push(Fractal {
                        formula,
                        de,
                        precision,
                        julia,
                        ..Fractal::default()
                    });
                }
            }
        }
    }
    v
}

#[test]
fn origin_and_tiny_radii_stay_finite_and_inside() {
    // Naive: the polar angle of the origin is acos(0/0) = NaN.
    let r: Real = 0.0;
    assert!((0.0 / r).acos().is_nan());
    let tiny = [
        DVec3::ZERO,
        DVec3::new(1e-300, 0.0, 0.0),
        DVec3::new(0.0, 1e-300, 0.0),
        DVec3::new(0.0, 0.0, -1e-300),
        DVec3::splat(1e-200),
    ];
    for f in every_variant() {
        for p in tiny {
            let e = f.estimate(p, 1e-3);
            assert!(e.distance.is_finite() && e.distance >= 0.0, "{f:?} at {p}");
            assert!(e.traps.origin.is_finite() && e.traps.planes.is_finite());
            if f.julia.is_none() {
                assert!(
                    !e.escaped && e.distance == 0.0,
                    "{f:?}: the origin is inside the bulb"
                );
            }
        }
    }
}

#[test]
fn pole_axis_points_give_the_trig_value_without_nan() {
    // Naive: Quilez's polynomial on its axis (x = z = 0) is 0 · ∞ = NaN.
    let (x, y, z): (Real, Real, Real) = (0.0, 0.7, 0.0);
    let k3 = x * x + z * z;
    let k2 = 1.0 / (k3 * k3 * k3 * k3 * k3 * k3 * k3).sqrt();
    assert!((64.0 * x * y * z * k2).is_nan());
    for formula in Formula::ALL {
        for axis in [
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            -DVec3::X,
            -DVec3::Y,
            -DVec3::Z,
        ] {
            for radius in [1e-8, 0.3, 1.0, 1.9] {
                let p = axis * radius;
                let w = power(formula, p, 8.0);
                let exact = triplex_power_trig(formula, [p.x, p.y, p.z], radius, 8.0);
                assert!(w.is_finite(), "{formula:?} at {p}: {w}");
                let scale = radius.powi(8);
                assert!(
                    (w - DVec3::from_array(exact)).length() <= 1e-12 * scale,
                    "{formula:?} at {p}"
                );
            }
        }
    }
    // Beside each formula's pole axis, inside the bulb's hand-over band
    // (1e-7) and just outside it where complex squaring runs (1e-5), the
    // result still agrees with the trigonometric form; the quaternion's
    // complex squaring runs in both.
    for formula in Formula::ALL {
        let shape = formula.shape();
        let pole = DVec3::from_array(shape.join(1.0, [0.0, 0.0]));
        let across = DVec3::from_array(shape.join(0.0, [0.6, 0.8]));
        for offset in [1e-7, 1e-5] {
            for radius in [0.3, 1.0, 1.9] {
                let p = (pole + across * offset) * radius;
                let q = [p.x, p.y, p.z];
                let squaring = offset > 1e-6 || !shape.turns_azimuth;
                assert_eq!(triplex_power_int(formula, q, 8).is_some(), squaring);
                let w = power(formula, p, 8.0);
                let exact = triplex_power_trig(formula, q, p.length(), 8.0);
                let scale = p.length().powi(8);
                assert!(
                    (w - DVec3::from_array(exact)).length() <= 1e-9 * scale,
                    "{formula:?} at {p}: {w} vs {exact:?}"
                );
            }
        }
    }
    // And every estimator, including the dual numbers whose acos has an
    // infinite derivative there, returns a finite distance on the axes.
    for f in every_variant() {
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            for radius in [0.5, 1.15, 1.4] {
                let d = f.estimate(axis * radius, 1e-4).distance;
                assert!(d.is_finite() && d >= 0.0, "{f:?} at {}: {d}", axis * radius);
            }
        }
    }
}

#[test]
fn huge_radii_bail_out_before_the_power() {
    // Naive: raising 1e300 to the 8th overflows, and ln(∞)·∞/∞ is NaN.
    let big: Real = 1e300;
    let r8 = big.powf(8.0);
    assert!(r8.is_infinite() && (0.5 * r8.ln() * r8 / r8).is_nan());
    for f in every_variant() {
        for radius in [1e30, 1e100, 1e300, 1e308, Real::MAX] {
            let e = f.estimate(DVec3::new(0.6, 0.0, 0.8) * radius, 1.0);
            assert!(e.escaped && e.iterations == 0);
            assert!(
                e.distance.is_finite() && e.distance > 0.0,
                "{f:?} at {radius}: {}",
                e.distance
            );
            assert!(e.distance <= radius, "{f:?} at {radius}: {}", e.distance);
        }
    }
}

#[test]
fn estimate_shrinks_towards_the_surface_down_to_1e_13() {
    // Find where a ray enters the set, then back off by 1e-3 … 1e-13.
    let f = Fractal::default();
    let dir = DVec3::new(0.3, -0.2, -1.0).normalize();
    let origin = DVec3::new(0.1, 0.35, 2.0);
    let mut t = 0.0;
    while !f.contains(origin + dir * (t + 1e-4)) {
        t += 1e-4;
        assert!(t < 4.0);
    }
    let (mut lo, mut hi) = (t, t + 1e-4);
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if f.contains(origin + dir * mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let mut previous = Real::INFINITY;
    for k in 3..=13 {
        let delta = 10f64.powi(-k);
        let d = f.estimate(origin + dir * (lo - delta), 0.0).distance;
        assert!(d.is_finite() && d > 0.0, "1e-{k}: {d}");
        // Non-increasing as the point closes in. (Below about 1/dr of the
        // iteration limit it levels off: the surface at that scale is the
        // iteration-limit boundary, which the marcher finds by bisection.)
        assert!(d <= previous * (1.0 + 1e-9), "1e-{k}: {d} after {previous}");
        previous = d;
    }
}

#[test]
fn other_powers_and_dust_julia_sets() {
    for n in [1.5, 2.0, 3.0, 8.0, 12.5] {
        let f = Fractal {
            power: n,
            ..Fractal::default()
        };
        assert!(
            !f.estimate(DVec3::new(0.0, 0.1, 0.0), 1e-3).escaped,
            "power {n}"
        );
        for p in points(100, 1.0..1.5, 31) {
            let d = f.estimate(p, 1e-3).distance;
            assert!(d.is_finite() && d >= 0.0, "power {n} at {p}: {d}");
        }
    }
    // A Julia constant far outside the connected region: everything escapes at once.
    let dust = Fractal {
        julia: Some(DVec3::splat(2.0)),
        ..Fractal::default()
    };
    for p in points(100, 0.0..1.5, 37) {
        let e = dust.estimate(p, 1e-3);
        assert!(e.escaped && e.iterations <= 2 && e.distance > 0.0);
    }
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]
        #[test]
        fn estimate_is_finite_and_non_negative_anywhere(
            x in -3.0f64..3.0, y in -3.0f64..3.0, z in -3.0f64..3.0,
            power in 1.5f64..12.0,
            julia in proptest::option::of((-1.5f64..1.5, -1.5f64..1.5, -1.5f64..1.5)),
            method in 0usize..5,
            single in any::<bool>(),
        ) {
            let f = Fractal {
                power,
                julia: julia.map(|(a, b, c)| DVec3::new(a, b, c)),
                de: DeMethod::ALL[method],
                precision: if single { Precision::F32 } else { Precision::F64 },
                ..Fractal::default()
            };
            let e = f.estimate(DVec3::new(x, y, z), 1e-3);
            prop_assert!(e.distance.is_finite() && e.distance >= 0.0, "{}", e.distance);
            prop_assert!(e.traps.origin.is_finite());
            // Outside the bailout ball everything has escaped, with a positive distance.
            if DVec3::new(x, y, z).length() > f.bailout {
                prop_assert!(e.escaped && e.distance > 0.0);
            }
        }
    }
}

#[test]
fn no_point_past_the_set_radius_is_in_the_set() {
    // The bound the far estimate rests on, for powers, bailouts (1e30
    // lowered to the escape radius), Julia constants and precisions:
    // every point just past `set_radius` escapes, and its estimate is
    // finite and positive, never more than its distance to the origin.
    for power in [2.0, 3.0, 8.0, 12.5] {
        for bailout in [2.0, 4.0, 100.0, 1e30] {
            for julia in [
                None,
                Some(DVec3::new(0.3, -0.5, 0.2)),
                Some(DVec3::splat(2.0)),
            ] {
                for precision in [Precision::F64, Precision::F32] {
                    let f = Fractal {
                        power,
                        bailout,
                        julia,
                        precision,
                        ..Fractal::default()
                    };
                    let escape = match precision {
                        Precision::F64 => f.escape_radius::<f64>(),
                        Precision::F32 => f.escape_radius::<f32>(),
                    };
                    assert!(
                        escape > 1.0
                            && escape <= bailout
                            && (escape.powf(power) * 2.0).powi(2).is_finite()
                    );
                    let radius = f.set_radius(escape);
                    assert!(
                        radius >= 1.0_f64.min(escape) && radius <= escape,
                        "{f:?}: {radius}"
                    );
                    for scale in [1.001, 1.3, 3.0] {
                        for p in points(300, 0.999..1.0, 17) {
                            let p = p.normalize() * radius * scale;
                            assert!(!f.contains(p), "{f:?}: {p} past {radius} is in the set");
                            let e = f.estimate(p, 1e-3);
                            assert!(e.escaped, "{f:?} at {p}");
                            assert!(
                                e.distance.is_finite()
                                    && e.distance > 0.0
                                    && e.distance <= p.length(),
                                "{f:?} at {p}: {}",
                                e.distance
                            );
                        }
                    }
                }
            }
        }
    }
}
