//! The distance estimators: bounds, agreement and finiteness.

use super::*;

#[test]
fn origin_is_inside_the_mandelbrot_bulb() {
    for f in Formula::ALL {
        let e = bulb(f).estimate(DVec3::ZERO, 0.0);
        assert!(!e.escaped);
        assert_eq!(e.distance, 0.0);
    }
}

#[test]
fn distance_outside_is_positive_finite_and_a_lower_bound() {
    // Near the bulb the estimate is a safe step: positive, and no larger than
    // R, the distance to the origin, which is inside. (Far away, beyond the
    // bounding sphere the marcher never leaves, the scalar estimate grows
    // like ½·R·ln R and is no longer a bound; there it must only stay finite.)
    for f in Formula::ALL {
        let far = bulb(f).estimate(DVec3::new(0.0, 10.0, 0.0), 0.0);
        assert!(far.distance.is_finite() && far.distance > 0.0);
        for &radius in &[1.3, 2.0, 3.0] {
            for dir in [
                DVec3::X,
                DVec3::Y,
                DVec3::Z,
                DVec3::new(1.0, -2.0, 0.5).normalize(),
            ] {
                let e = bulb(f).estimate(dir * radius, 0.0);
                assert!(e.escaped, "{f:?} at {radius}");
                assert!(e.distance.is_finite() && e.distance > 0.0);
                assert!(e.distance < radius, "{f:?} r={radius} de={}", e.distance);
            }
        }
    }
}

#[test]
fn far_away_estimate_grows_with_distance() {
    let f = bulb(Formula::Quilez);
    let near = f.estimate(DVec3::new(0.0, 0.0, 2.0), 0.0).distance;
    let far = f.estimate(DVec3::new(0.0, 0.0, 3.5), 0.0).distance;
    assert!(far > near);
}

#[test]
fn julia_mode_differs_from_mandelbrot_mode() {
    let p = DVec3::new(0.6, 0.3, 0.4);
    let m = bulb(Formula::Quilez).estimate(p, 0.0);
    let j = Fractal {
        julia: Some(DVec3::new(0.8, -0.3, 0.1)),
        ..bulb(Formula::Quilez)
    }
    .estimate(p, 0.0);
    assert_ne!(m.distance, j.distance);
    // A Julia set with c = 0 is the unit ball: inside below radius 1, escaping above it.
    let unit = Fractal {
        julia: Some(DVec3::ZERO),
        iterations: 30,
        ..bulb(Formula::Quilez)
    };
    assert!(!unit.estimate(DVec3::new(0.0, 0.99, 0.0), 0.0).escaped);
    let outside = unit.estimate(DVec3::new(0.0, 1.05, 0.0), 0.0);
    assert!(outside.escaped);
    // The true distance to the unit sphere is 0.05; the ½ in the estimate makes it
    // a lower bound that is within a factor of two of the truth.
    assert!(
        outside.distance <= 0.05 && outside.distance > 0.025,
        "{}",
        outside.distance
    );
}

/// Distance from `p` to the set along `dir`, by dense membership stepping
/// and bisection; `None` if nothing is met within `reach`.
fn distance_along(f: &Fractal, p: DVec3, dir: DVec3, reach: Real) -> Option<Real> {
    let step = reach / 4000.0;
    let mut t = 0.0;
    while t < reach {
        if f.contains(p + dir * (t + step)) {
            let (mut lo, mut hi) = (t, t + step);
            for _ in 0..40 {
                let mid = 0.5 * (lo + hi);
                if f.contains(p + dir * mid) {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            return Some(lo);
        }
        t += step;
    }
    None
}

#[test]
fn analytic_estimate_tracks_the_brute_force_distance() {
    // From points near the bulb, the nearest surface along 26 directions
    // bounds the true distance from above. The estimate must not exceed it
    // by much (it is meant to be a lower bound) nor fall far below it (it
    // would crawl): dropping the Mandelbrot-mode +1 or the ½ fails this.
    let f = Fractal::default();
    let dirs: Vec<DVec3> = (-1..=1)
        .flat_map(|x| {
            (-1..=1).flat_map(move |y| {
                (-1..=1).map(move |z| DVec3::new(x as Real, y as Real, z as Real))
            })
        })
        .filter(|d| *d != DVec3::ZERO)
        .map(|d| d.normalize())
        .collect();
    let mut ratios = Vec::new();
    for p in points(40, 1.1..1.3, 5) {
        let e = f.estimate(p, 0.0);
        if !e.escaped {
            continue;
        }
        let nearest = dirs
            .iter()
            .filter_map(|&d| distance_along(&f, p, d, 0.5))
            .fold(Real::INFINITY, Real::min);
        if nearest.is_finite() {
            ratios.push(e.distance / nearest);
        }
    }
    assert!(ratios.len() > 20);
    ratios.sort_by(|a, b| a.total_cmp(b));
    let median = ratios[ratios.len() / 2];
    assert!(ratios[ratios.len() - 1] < 1.5, "overestimates: {ratios:?}");
    assert!(
        median > 0.2 && median < 1.0,
        "median ratio {median}: {ratios:?}"
    );
}

#[test]
fn every_method_and_precision_is_finite_and_positive_outside() {
    // Near the bulb (radius ≤ 1.5) no true distance exceeds 1.5: an estimate
    // above that would be a step that jumps the surface (an infinite
    // estimate would become a huge step). Points on and next to
    // the axes are included, where derivatives blow up.
    let mut probes = points(200, 1.2..1.5, 3);
    for axis in [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::Y] {
        for r in [1.2, 1.3, 1.45] {
            probes.push(axis * r);
            probes.push(axis * r + DVec3::new(1e-9, 0.0, 1e-9));
        }
    }
    for de in DeMethod::ALL {
        for precision in [Precision::F64, Precision::F32] {
            let f = Fractal {
                de,
                precision,
                ..Fractal::default()
            };
            for &p in &probes {
                let e = f.estimate(p, 1e-3);
                if e.escaped {
                    assert!(
                        e.distance.is_finite() && e.distance > 0.0 && e.distance < 1.5,
                        "{de:?} {precision:?} at {p}: {}",
                        e.distance
                    );
                }
            }
            assert_eq!(f.estimate(DVec3::ZERO, 1e-3).distance, 0.0);
        }
    }
}

#[test]
fn jacobian_on_the_pole_axis_is_conservative() {
    // Naive: dual numbers through acos at ±1 give an infinite derivative,
    // so ‖J‖ is NaN. Ours bounds it by n·dr there: no larger than analytic.
    let one = Dual::variable(1.0f64, 0);
    assert!(!one.acos().d[0].is_finite());
    let jac = Fractal {
        de: DeMethod::Jacobian,
        ..Fractal::default()
    };
    let analytic = Fractal::default();
    for r in [1.15, 1.3] {
        let p = DVec3::Y * r;
        let (j, a) = (
            jac.estimate(p, 1e-4).distance,
            analytic.estimate(p, 1e-4).distance,
        );
        assert!(
            j.is_finite() && j > 0.0 && j <= a,
            "r {r}: jacobian {j}, analytic {a}"
        );
    }
}

#[test]
fn methods_agree_with_analytic_near_the_surface() {
    // Near the surface every estimator approximates the same distance; the
    // scalar ones differ by bounded factors (Christensen's "Distance Estimated 3D Fractals", part V, compares them). The
    // stated tolerance: within a factor of 3 of the analytic estimate for
    // 90% of points 1e-4..1e-2 from the surface.
    let analytic = Fractal::default();
    let mut near = Vec::new();
    for p in points(2000, 0.9..1.3, 17) {
        let e = analytic.estimate(p, 0.0);
        if e.escaped && e.distance > 1e-4 && e.distance < 1e-2 {
            near.push((p, e.distance));
        }
    }
    assert!(
        near.len() > 30,
        "only {} points near the surface",
        near.len()
    );
    for de in DeMethod::ALL {
        let f = Fractal {
            de,
            ..Fractal::default()
        };
        let good = near
            .iter()
            .filter(|(p, d)| {
                let r = f.estimate(*p, 1e-6).distance / d;
                r > 1.0 / 3.0 && r < 3.0
            })
            .count();
        let mut r: Vec<Real> = near
            .iter()
            .map(|(p, d)| f.estimate(*p, 1e-6).distance / d)
            .collect();
        r.sort_by(|a, b| a.total_cmp(b));
        eprintln!(
            "{de:?}: ratio to analytic, quantiles 5% {:.3} 50% {:.3} 95% {:.3}",
            r[r.len() / 20],
            r[r.len() / 2],
            r[r.len() * 19 / 20]
        );
        assert!(
            good * 10 >= near.len() * 9,
            "{de:?}: {good} of {}",
            near.len()
        );
    }
}

#[test]
fn spectral_norm_of_known_matrices() {
    let d = glam::DMat3::from_diagonal(DVec3::new(1.0, -5.0, 2.0));
    assert!((spectral_norm(d) - 5.0).abs() < 1e-9);
    // A rotation stretches nothing.
    let rot = glam::DMat3::from_rotation_y(0.7) * glam::DMat3::from_rotation_x(0.3);
    assert!((spectral_norm(rot) - 1.0).abs() < 1e-9);
    // Rank one: u vᵀ has norm |u||v|.
    let u = DVec3::new(1.0, 2.0, 2.0);
    let v = DVec3::new(0.0, 3.0, 4.0);
    let outer = glam::DMat3::from_cols(u * v.x, u * v.y, u * v.z);
    assert!((spectral_norm(outer) - 15.0).abs() < 1e-9);
}

#[test]
fn dual_number_jacobian_matches_finite_differences() {
    // Whole powers run complex squaring through the dual numbers;
    // fractional ones (7.5, 5.5) the trigonometric form.
    let cases = [
        (Formula::Quilez, 8.0),
        (Formula::Quilez, 7.0),
        (Formula::WhiteNylander, 3.0),
        (Formula::Asin, 8.0),
        (Formula::Quilez, 7.5),
        (Formula::Asin, 5.5),
    ];
    for (formula, power) in cases {
        let f = Fractal {
            formula,
            power,
            iterations: 4,
            ..Fractal::default()
        };
        check_jacobian(&f);
    }
}

fn check_jacobian(f: &Fractal) {
    let mut checked = 0;
    for p in points(50, 0.3..1.1, 23) {
        let dual: Orbit<Dual<Real>> = f.orbit(
            [
                Dual::variable(p.x, 0),
                Dual::variable(p.y, 1),
                Dual::variable(p.z, 2),
            ],
            f.iterations,
            false,
        );
        if dual.r.v > f.bailout {
            // Escaped orbits grow like r^(8^k): finite differences lose all digits there.
            continue;
        }
        // Fourth-order central differences, accurate to ~1e-9 relative here.
        let h = 2e-6;
        let at = |q: DVec3| -> Orbit<Real> { f.orbit([q.x, q.y, q.z], f.iterations, false) };
        for axis in 0..3 {
            let mut step = DVec3::ZERO;
            step[axis] = h;
            let samples = [
                at(p + 2.0 * step),
                at(p + step),
                at(p - step),
                at(p - 2.0 * step),
            ];
            for row in 0..3 {
                let [a, b, c, d] = samples.map(|o| o.z[row]);
                let fd = (-a + 8.0 * b - 8.0 * c + d) / (12.0 * h);
                let ad = dual.z[row].d[axis];
                assert!(
                    (fd - ad).abs() <= 1e-7 * (1.0 + ad.abs()),
                    "{:?} {p} J[{row}][{axis}]: {ad} vs {fd}",
                    f.formula
                );
            }
        }
        checked += 1;
    }
    assert!(
        checked >= 10,
        "{:?} power {}: only {checked} bounded orbits",
        f.formula,
        f.power
    );
}

/// Shading reads a hit's escape radius and final angle from its estimate
/// (`Estimate::end`) instead of iterating again, wherever `ends_f64_orbits`:
/// one estimate or 16 side by side, deep or not, every estimator that says
/// so ends where the f64 orbit ends, to the bit.
#[test]
fn an_estimate_ends_where_its_f64_orbit_ends() {
    let mut fractals = variants();
    for de in [
        DeMethod::Potential,
        DeMethod::SinhPotential,
        DeMethod::EscapeLength,
    ] {
        fractals.push(Fractal {
            de,
            ..Fractal::default()
        });
    }
    let mut pts = points(320, 0.0..2.5, 9);
    pts.extend([
        DVec3::new(0.0, 0.0, 0.7),
        DVec3::ZERO,
        DVec3::new(4.1, 0.3, -0.2),
    ]);
    for f in &fractals {
        assert!(f.ends_f64_orbits());
        assert_ends(f, &pts, 1e-4);
    }
    // A deep frame's points are offsets from its anchor, near the surface.
    let anchor = DVec3::new(0.31, 0.62, 0.58);
    let big = anchor
        .to_array()
        .map(|c| crate::exact::big_from_f64(c, 128));
    let plain = Fractal {
        iterations: 24,
        ..Fractal::default()
    };
    let reference = deep::Reference::new(&plain, big, 128).expect("a whole power");
    let deep = Fractal {
        deep: Some(std::sync::Arc::new(reference)),
        ..plain.clone()
    };
    let offsets: Vec<DVec3> = points(64, 0.0..1.0, 4).iter().map(|p| *p * 1e-7).collect();
    // At a footprint finer than f64 resolves there, on the perturbed orbit;
    // at a coarser one, the frame hands the point to the plain f64 orbit.
    assert_ends(&deep, &offsets, 1e-12);
    for p in &offsets {
        let world = anchor + *p;
        let orbit = plain.orbit_at([world.x, world.y, world.z], plain.iterations, true);
        let e = deep.estimate(*p, 1e-4);
        assert_eq!(
            e.end.map(Real::to_bits),
            orbit.z.map(Real::to_bits),
            "at {p}"
        );
    }
    // f32 estimates end on f32's orbit, and the Jacobian method's on its
    // dual numbers': shading iterates again for those.
    assert!(!Fractal {
        precision: Precision::F32,
        ..Fractal::default()
    }
    .ends_f64_orbits());
    assert!(!Fractal {
        de: DeMethod::Jacobian,
        ..Fractal::default()
    }
    .ends_f64_orbits());
}

/// Each of `pts`, estimated alone and 16 at a time at footprint `scale`,
/// ends where `f`'s f64 orbit of it ends.
fn assert_ends(f: &Fractal, pts: &[DVec3], scale: Real) {
    for chunk in pts.chunks(16) {
        let mut lanes = [IDLE_POINT; 16];
        lanes[..chunk.len()].copy_from_slice(chunk);
        let together = f.estimate_lanes(lanes, [scale; 16]);
        for (p, lane) in chunk.iter().zip(together) {
            let orbit = f.orbit_at([p.x, p.y, p.z], f.iterations, true);
            for e in [lane, f.estimate(*p, scale)] {
                let bits = |z: [Real; 3]| z.map(Real::to_bits);
                assert_eq!(bits(e.end), bits(orbit.z), "{f:?} at {p}");
                assert_eq!(e.end_radius().to_bits(), orbit.r.to_bits(), "at {p}");
                assert_eq!(e.iterations, orbit.iterations, "at {p}");
            }
        }
    }
}

#[test]
fn julia_lanes_off_the_critical_point_skip_the_bound_as_bounded_would() {
    // Julia's critical-point bound keeps an estimate shorter than |p|; the
    // squared test must let those lanes through without `bounded`, and
    // never let through one that `bounded`'s square roots would catch.
    assert!(no_bound_applies(
        DVec3::new(1.0, 0.0, 0.0),
        5,
        2.0,
        true,
        0.1
    ));
    assert!(!no_bound_applies(
        DVec3::new(0.1, 0.0, 0.0),
        5,
        2.0,
        true,
        0.2
    ));
    let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as Real / (1u64 << 53) as Real
    };
    let near = 1.5;
    // `bounded`'s own tests on |p| keep every estimate this lets through.
    let julia = Fractal {
        julia: Some(DVec3::new(0.3, -0.2, 0.1)),
        ..Fractal::default()
    };
    let escape = julia.escape_radius::<Real>();
    assert!(escape.min(2.0) >= near, "escape radius {escape}");
    for _ in 0..200_000 {
        let p = DVec3::new(next(), next(), next()) * (2.0 * near / 3f64.sqrt());
        let length = p.length();
        // Distances on both sides of |p|, some within rounding of it.
        let distance = match (next() * 3.0) as u32 {
            0 => length * (1.0 + (next() - 0.5) * 1e-15),
            1 => length * 2.0 * next(),
            _ => -next(),
        };
        let by_roots = length <= near && distance > 0.0 && distance < length;
        if no_bound_applies(p, 3, near, true, distance) {
            assert!(by_roots, "p {p}, distance {distance}");
            let kept = julia.bounded_by_roots::<Real>(p, escape, 0.0, distance, 3, true);
            assert_eq!(kept, (distance, 0), "p {p}");
        }
    }
}

#[test]
fn the_critical_point_bound_finds_the_stretch_root_from_above() {
    use crate::fractal::estimate::stretch_root;
    let stretch = |n: Real, rho: Real, d: Real| n * (rho + d).powf(n - 1.0) * d;
    for n in [2.0, 3.0, 7.5, 8.0, 16.0] {
        for rho in [0.0, 1e-3, 0.5, 1.5] {
            for target in [1e-12, 1e-3, 1.0, 1e6] {
                // An independent root: plain bisection, far past f64's resolution.
                let (mut lo, mut hi) = (0.0, (target / n).powf(1.0 / n));
                let start = hi;
                for _ in 0..200 {
                    let mid = 0.5 * (lo + hi);
                    if stretch(n, rho, mid) > target {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                let root = stretch_root(n, rho, target, start);
                let case = format!("n {n}, ρ {rho}, target {target}");
                assert!(
                    (root - lo).abs() <= 1e-12 * lo,
                    "{case}: {root} against {lo}"
                );
                assert!(root <= start, "{case}: past where it started");
            }
        }
    }
    // No root to find: the stretch is already 0 at δ = 0.
    assert_eq!(stretch_root(8.0, 0.0, 0.0, 0.0), 0.0);
}
