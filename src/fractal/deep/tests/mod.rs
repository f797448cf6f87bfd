use super::*;
use crate::fractal::Formula;
use std::sync::Arc;

const FORMULAS: [Formula; 4] = Formula::ALL;

fn fractals() -> Vec<Fractal> {
    let mut all = Vec::new();
    for formula in FORMULAS {
        for julia in [None, Some(DVec3::new(0.35, -0.4, 0.2))] {
            all.push(Fractal {
                formula,
                julia,
                iterations: 24,
                ..Fractal::default()
            });
        }
    }
    // Powers that are not 8: Horner's rule (3), the product form (4) and
    // the quaternion's classic square.
    for (power, formula) in [
        (3.0, Formula::Quilez),
        (4.0, Formula::Asin),
        (2.0, Formula::Quaternion),
    ] {
        all.push(Fractal {
            formula,
            power,
            iterations: 24,
            ..Fractal::default()
        });
    }
    all
}

/// A point within 1e-15 of the set's surface along `dir` (bisection of
/// membership from outside the set towards the origin).
fn surface_point(fractal: &Fractal, dir: DVec3) -> DVec3 {
    let dir = dir.normalize();
    let (mut inside, mut outside) = (0.0, 2.0);
    if !fractal.contains(DVec3::ZERO) {
        // A Julia set without the origin: look from the other side.
        inside = 2.0;
        while inside > 0.0 && !fractal.contains(dir * inside) {
            inside -= 0.01;
        }
        outside = inside + 0.01;
    }
    for _ in 0..60 {
        let mid = 0.5 * (inside + outside);
        if fractal.contains(dir * mid) {
            inside = mid;
        } else {
            outside = mid;
        }
    }
    dir * outside
}

fn big(v: DVec3, bits: usize) -> [Big; 3] {
    v.to_array().map(|c| big_from_f64(c, bits))
}

/// The orbit of anchor + `delta` computed directly in high precision.
fn direct(
    fractal: &Fractal,
    anchor: DVec3,
    delta: DVec3,
    limit: u32,
    bits: usize,
) -> Vec<[Big; 3]> {
    let a = big(anchor, bits);
    let d = big(delta, bits);
    let p: [Big; 3] = [0, 1, 2].map(|i| &a[i] + &d[i]);
    let n = whole_power(fractal.power).unwrap();
    let escape = fractal.escape_radius::<Real>();
    match fractal.julia {
        None => {
            let mut points = reference::orbit(
                fractal.formula,
                n,
                big(DVec3::ZERO, bits),
                &p,
                limit + 1,
                escape,
                bits,
            );
            points.remove(0);
            points
        }
        Some(k) => reference::orbit(fractal.formula, n, p, &big(k, bits), limit, escape, bits),
    }
}

fn directions(count: usize) -> Vec<DVec3> {
    crate::math::shell_points(count, 1.0..1.0001, 7)
        .into_iter()
        .map(DVec3::normalize)
        .collect()
}

/// Compares δ after each step, at 1e-30 from `anchor` along `dir`, with
/// the difference of the two high-precision orbits (to `tolerance` of δ),
/// while no rebase has happened; the steps compared.
fn compare_differences(
    fractal: &Fractal,
    anchor: DVec3,
    dir: DVec3,
    tolerance: Real,
    steps: u32,
) -> u32 {
    let bits = 256;
    let reference = Reference::new(fractal, big(anchor, bits), bits).unwrap();
    let delta = dir * 1e-30;
    let exact = direct(fractal, anchor, delta, fractal.iterations, bits);
    let escape = fractal.escape_radius::<Real>();
    let n = whole_power(fractal.power).unwrap();
    let main: Vec<[Big; 3]> = match fractal.julia {
        None => {
            let zero = big(DVec3::ZERO, bits);
            let mut z = reference::orbit(
                fractal.formula,
                n,
                zero,
                &big(anchor, bits),
                fractal.iterations + 1,
                escape,
                bits,
            );
            z.remove(0);
            z
        }
        Some(k) => reference::orbit(
            fractal.formula,
            n,
            big(anchor, bits),
            &big(k, bits),
            fractal.iterations,
            escape,
            bits,
        ),
    };
    let mut compared = 0;
    for k in 1..(exact.len().min(main.len()) as u32).min(steps + 1) {
        let walked = reference.walk(fractal, delta.to_array(), k, false);
        if walked.rebased > 0 {
            break;
        }
        let want = [0, 1, 2].map(|i| {
            (&exact[k as usize][i] - &main[k as usize][i])
                .to_f64()
                .value()
        });
        let size = DVec3::from_array(want).length();
        let error = (DVec3::from_array(walked.delta) - DVec3::from_array(want)).length();
        assert!(
            error <= tolerance * size,
            "{:?} julia {:?} step {k}: δ {:?} vs {want:?}",
            fractal.formula,
            fractal.julia,
            walked.delta
        );
        compared += 1;
    }
    compared
}

#[test]
fn perturbed_differences_keep_their_precision_thirty_decades_down() {
    let mut compared = 0;
    for fractal in fractals() {
        for dir in directions(3) {
            let anchor = surface_point(&fractal, dir + DVec3::new(0.1, 0.2, 0.0));
            compared += compare_differences(&fractal, anchor, dir, 1e-9, 1000);
        }
    }
    assert!(compared > 100, "only {compared} steps compared");
}

#[test]
fn an_anchor_on_the_pole_axis_keeps_its_precision() {
    let mut compared = 0;
    for fractal in fractals().into_iter().filter(|f| f.julia.is_none()) {
        let pole = match fractal.formula {
            Formula::Quilez => DVec3::Y,
            _ => DVec3::Z,
        };
        let anchor = surface_point(&fractal, pole);
        // Near the axis the azimuth multiplies by 8 a step while the
        // distance from the axis barely grows, so δ's own rounding grows
        // ~20 times a step there, as any f64 orbit's would: 10 steps.
        let dir = DVec3::new(0.3, 0.5, -0.8).normalize();
        compared += compare_differences(&fractal, anchor, dir, 1e-6, 10);
    }
    assert!(compared >= 40, "only {compared} steps compared");
}

#[test]
fn rebased_orbits_follow_the_direct_orbit() {
    let bits = 192;
    let (mut rebased, mut compared) = (0, 0);
    for fractal in fractals() {
        let anchor = surface_point(&fractal, DVec3::new(0.5, 0.6, 0.4));
        let reference = Reference::new(&fractal, big(anchor, bits), bits).unwrap();
        for (i, dir) in directions(40).into_iter().enumerate() {
            let delta = dir * 10f64.powi(-2 - (i % 8) as i32);
            let limit = 8;
            let walked = reference.walk(&fractal, delta.to_array(), limit, true);
            let exact = direct(&fractal, anchor, delta, limit, bits);
            let escape = fractal.escape_radius::<Real>();
            // The direct orbit stops at its first point past the escape radius.
            let past = |z: &[Big; 3]| {
                DVec3::from_array(reference::rounded(z)).length_squared() > escape * escape
            };
            let end = exact.iter().position(past).unwrap_or(exact.len() - 1);
            let z = reference::rounded(&exact[end]);
            let r2 = DVec3::from_array(z).length_squared();
            if (r2 / (escape * escape) - 1.0).abs() < 1e-6 {
                continue; // on the bailout: either count is right
            }
            let orbit = walked.orbit;
            assert_eq!(
                orbit.iterations as usize, end,
                "{:?} {delta}",
                fractal.formula
            );
            let error = (DVec3::from_array(orbit.z) - DVec3::from_array(z)).length();
            assert!(
                error <= 1e-7 * DVec3::from_array(z).length().max(1e-3),
                "{:?} {delta}: {:?} vs {z:?}",
                fractal.formula,
                orbit.z
            );
            rebased += (walked.rebased > 0) as u32;
            compared += 1;
        }
    }
    assert!(compared > 200, "{compared}");
    assert!(rebased > 20, "only {rebased} orbits were rebased");
}

#[test]
fn deep_estimates_match_plain_ones_where_f64_is_exact() {
    for mut fractal in fractals() {
        // An anchor of 20 bits and offsets of 40: every sum is exact in f64.
        let anchor =
            (surface_point(&fractal, DVec3::new(0.3, 0.8, 0.5)) * 1048576.0).round() / 1048576.0;
        let plain = fractal.clone();
        fractal.deep = Some(Arc::new(
            Reference::new(&fractal, big(anchor, 128), 128).unwrap(),
        ));
        for (i, dir) in directions(12).into_iter().enumerate() {
            let delta =
                (dir * 2f64.powi(-8 - i as i32) * 1099511627776.0).round() / 1099511627776.0;
            let deep = fractal.estimate(delta, 1e-9);
            let want = plain.estimate(anchor + delta, 1e-9);
            assert_eq!(deep.escaped, want.escaped, "{delta}");
            assert_eq!(deep.iterations, want.iterations, "{delta}");
            assert!(
                (deep.distance - want.distance).abs() <= 1e-9 * want.distance,
                "{:?}: {} vs {}",
                fractal.formula,
                deep.distance,
                want.distance
            );
            assert_eq!(fractal.contains(delta), plain.contains(anchor + delta));
        }
    }
}

/// `plain` with a 160-bit reference at a point of its surface, and the point.
fn deep_on_the_surface(plain: &Fractal) -> (Fractal, DVec3) {
    let bits = 160;
    let anchor = surface_point(plain, DVec3::new(0.4, 0.7, 0.5));
    let reference = Reference::new(plain, big(anchor, bits), bits).unwrap();
    let fractal = Fractal {
        deep: Some(Arc::new(reference)),
        ..plain.clone()
    };
    (fractal, anchor)
}

/// `N` offsets along `directions`, the `i`th 10^`decade(i)` long.
fn offsets<const N: usize>(decade: impl Fn(usize) -> i32) -> [DVec3; N] {
    let dirs = directions(N);
    std::array::from_fn(|i| dirs[i] * 10f64.powi(decade(i)))
}

#[test]
fn lanes_are_bit_identical_to_the_scalar_orbit() {
    let mut compared = 0;
    for plain in fractals() {
        let (fractal, _) = deep_on_the_surface(&plain);
        // Offsets from far below a pixel to ones that rebase and escape.
        let points: [DVec3; 48] = offsets(|i| -(i as i32 % 12) * 3);
        let scales = [1e-12; 48];
        for chunk in [&points[..16], &points[16..32], &points[32..]] {
            let lanes = fractal
                .estimate_lanes::<16>(chunk.try_into().unwrap(), scales[..16].try_into().unwrap());
            for (p, lane) in chunk.iter().zip(lanes) {
                let one = fractal.estimate(*p, 1e-12);
                assert_eq!(
                    lane, one,
                    "{:?} julia {:?} at {p}",
                    fractal.formula, fractal.julia
                );
                compared += 1;
            }
        }
        // A partial register too.
        let five = fractal.estimate_lanes::<5>(points[..5].try_into().unwrap(), [1e-12; 5]);
        for (p, lane) in points.iter().zip(five) {
            assert_eq!(lane, fractal.estimate(*p, 1e-12));
        }
    }
    assert_eq!(compared, fractals().len() * 48);
}

#[test]
fn points_f64_resolves_are_the_plain_kernels() {
    let mut perturbed = 0;
    for plain in fractals() {
        let (fractal, anchor) = deep_on_the_surface(&plain);
        // Offsets of a whole to a thousandth of the anchor's size, their
        // footprints at `F64_RESOLVES` (even) and half of it (odd).
        let points: [DVec3; 32] = offsets(|i| -(i as i32 % 4));
        let scales: [Real; 32] = std::array::from_fn(|i| {
            let size = (anchor + points[i]).abs().max_element() * F64_RESOLVES;
            size * [1.0, 0.5][i % 2]
        });
        let lanes = fractal.estimate_lanes::<32>(points, scales);
        for (i, lane) in lanes.into_iter().enumerate() {
            let one = fractal.estimate(points[i], scales[i]);
            assert_eq!(lane, one, "{:?} at {}", fractal.formula, points[i]);
            let f64_alone = plain.estimate(anchor + points[i], scales[i]);
            match i % 2 {
                0 => assert_eq!(one, f64_alone, "{:?} at {}", fractal.formula, points[i]),
                _ => perturbed += usize::from(one != f64_alone),
            }
        }
    }
    // Below the footprint the estimates stay perturbed, whose last bits differ.
    assert!(perturbed > 8, "{perturbed}");
}

#[test]
fn a_julia_constant_written_in_digits_is_the_one_iterated() {
    let text = "(julia: Some((\"0.35\", \"-0.40000000000000000001\", \"0.2\")), iterations: 24)";
    let mut digits: Fractal = ron::from_str(text).unwrap();
    assert_eq!(digits.julia, Some(DVec3::new(0.35, -0.4, 0.2)));
    let mut plain = Fractal {
        julia_digits: None,
        ..digits.clone()
    };
    // Ordinary fractals serialise as they always have.
    assert_eq!(
        serde_json::to_string(&plain).unwrap(),
        r#"{"formula":"Quilez","power":8.0,"iterations":24,"bailout":4.0,"julia":[0.35,-0.4,0.2],"de":"Analytic","precision":"F64"}"#
    );
    assert!(serde_json::to_string(&digits)
        .unwrap()
        .contains("-0.40000000000000000001"));
    // Moving the constant by 1e-20 moves the surface by about as much: at
    // a point 1e-15 from it the estimate changes in its fifth digit, where
    // the same constant gives the same bits.
    let anchor = surface_point(&plain, DVec3::new(0.4, 0.6, 0.5));
    for f in [&mut plain, &mut digits] {
        f.deep = Some(Arc::new(Reference::new(f, big(anchor, 256), 256).unwrap()));
    }
    let (a, b) = (
        plain.estimate(DVec3::ZERO, 1e-20),
        digits.estimate(DVec3::ZERO, 1e-20),
    );
    assert!(a.escaped && b.escaped);
    let change = (a.distance - b.distance).abs() / a.distance;
    assert!(change > 1e-8, "{} vs {}", a.distance, b.distance);
}

mod properties {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// The perturbed orbit of anchor + δ is the orbit iterated directly
        /// in high precision: the same escape, and the same end point to 1e-7
        /// of its size, in every convention and mode, from far below a pixel
        /// to offsets that rebase. (Plain f64 is no yardstick: near the pole
        /// axis its own rounding grew to 1e-4 of the end point where the
        /// perturbed orbit kept 1e-9.)
        #[test]
        fn the_perturbed_orbit_is_the_exact_one(
            which in 0usize..8,
            dir in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
            bits_down in 8i32..100,
            towards in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
        ) {
            let fractal = fractals()[which].clone();
            let towards = DVec3::new(towards.0, towards.1, towards.2);
            prop_assume!(towards.length() > 0.1);
            let anchor = surface_point(&fractal, towards);
            let dir = DVec3::new(dir.0, dir.1, dir.2);
            prop_assume!(dir.length() > 0.1);
            let delta = dir.normalize() * 2f64.powi(-bits_down);
            let reference = Reference::new(&fractal, big(anchor, 160), 160).unwrap();
            // 12 steps: f64's rounding grows with every step of a chaotic
            // orbit, and a rebased one is f64's from there on.
            let orbit = reference.orbit(&fractal, delta.to_array(), 12, true);
            let exact = direct(&fractal, anchor, delta, 12, 160);
            let escape = fractal.escape_radius::<Real>();
            let size = |z: &[Big; 3]| DVec3::from_array(reference::rounded(z)).length_squared();
            let end = exact.iter().position(|z| size(z) > escape * escape).unwrap_or(exact.len() - 1).min(12);
            // On the bailout either count is right.
            prop_assume!((size(&exact[end]) / (escape * escape) - 1.0).abs() > 1e-6);
            prop_assert_eq!(orbit.iterations as usize, end);
            let want = DVec3::from_array(reference::rounded(&exact[end]));
            let error = (DVec3::from_array(orbit.z) - want).length();
            prop_assert!(error <= 1e-7 * want.length().max(1e-3), "{:?} vs {}", orbit.z, want);
        }
    }
}

/// (Z + δ)ⁿ − Zⁿ by the perturbed step, against the high-precision
/// difference, for reference points `rho` from the pole axis and offsets
/// whose squares f64 cannot hold (`step::Far`).
#[test]
fn the_step_keeps_its_precision_three_hundred_decades_down_by_the_axis() {
    let bits = 1400;
    let power = |formula, z: &[Big; 3], n| {
        let zero = big(DVec3::ZERO, bits);
        reference::orbit(formula, n, z.clone(), &zero, 1, 1e300, bits).remove(1)
    };
    let mut compared = 0;
    for formula in Formula::ALL {
        for n in [3, 8] {
            for log2_rho in [-1, -100, -600, -1068] {
                // ρ times the equatorial direction (0.6, 0.8), and pole 1.1.
                let rho = big_from_f64(1.0, bits) >> (-log2_rho) as isize;
                let (e1, e2) = (
                    &rho * big_from_f64(0.6, bits),
                    &rho * big_from_f64(0.8, bits),
                );
                let pole = big_from_f64(1.1, bits);
                let z = formula.shape().join(pole, [e1, e2]);
                let point = step::Point::new(formula, &z, n).expect("off the axis");
                for depth in [1e-200, 1e-300] {
                    for dir in directions(3) {
                        let delta = (dir * depth).to_array();
                        let got = point.power_difference(formula, delta);
                        let moved: [Big; 3] =
                            [0, 1, 2].map(|i| &z[i] + big_from_f64(delta[i], bits));
                        let (a, b) = (power(formula, &moved, n), power(formula, &z, n));
                        let want = [0, 1, 2].map(|i| (&a[i] - &b[i]).to_f64().value());
                        let size = crate::math::length(DVec3::from_array(want));
                        let error =
                            crate::math::length(DVec3::from_array(got) - DVec3::from_array(want));
                        assert!(
                            error <= 1e-9 * size,
                            "{formula:?} n {n} ρ 2^{log2_rho} δ {depth:e}: {got:?} vs {want:?}"
                        );
                        compared += 1;
                    }
                }
            }
        }
    }
    assert_eq!(compared, Formula::ALL.len() * 2 * 4 * 2 * 3);
}
