//! The triplex power in each convention.

use super::*;

#[test]
fn power_two_is_complex_squaring_on_each_conventions_meridian() {
    // Each convention reduces to complex squaring on one half-plane through its pole axis
    // (the asin form on its whole equator). a > 0 keeps us on the half-plane φ = 0.
    let (a, b) = (0.3, -0.7);
    let sq = |z: DVec3, f: Formula| power(f, z, 2.0);
    // White–Nylander: (x > 0, 0, z) with z the real part, x the imaginary.
    let w = sq(DVec3::new(a, 0.0, b), Formula::WhiteNylander);
    assert!(
        (w - DVec3::new(2.0 * a * b, 0.0, b * b - a * a)).length() < 1e-12,
        "{w}"
    );
    // Quilez: (0, y, z > 0) with y the real part, z the imaginary.
    let w = sq(DVec3::new(0.0, b, a), Formula::Quilez);
    assert!(
        (w - DVec3::new(0.0, b * b - a * a, 2.0 * a * b)).length() < 1e-12,
        "{w}"
    );
    // Asin: the plane z = 0, x real and y imaginary.
    let w = sq(DVec3::new(a, b, 0.0), Formula::Asin);
    assert!(
        (w - DVec3::new(a * a - b * b, 2.0 * a * b, 0.0)).length() < 1e-12,
        "{w}"
    );
}

#[test]
fn power_scales_length_by_r_to_the_n() {
    let z = DVec3::new(0.4, 0.5, -0.6);
    for f in Formula::ALL {
        let w = power(f, z, 8.0);
        assert!((w.length() - z.length().powi(8)).abs() < 1e-12);
    }
}

#[test]
fn conventions_are_rotations_of_each_other() {
    // Quilez's y-up bulb is the White–Nylander bulb with its axes relabelled:
    // WN (x, y, z) is Quilez (y, z, x). Check membership agrees point by point.
    let q = bulb(Formula::Quilez);
    let w = bulb(Formula::WhiteNylander);
    let mut agree = 0;
    let total = 200;
    for i in 0..total {
        let t = i as f64 * 0.618_033_988_7;
        let p = DVec3::new((t * 3.1).sin(), (t * 1.7).cos(), (t * 2.3).sin()) * 1.1;
        let pq = DVec3::new(p.y, p.z, p.x);
        if q.estimate(pq, 0.0).escaped == w.estimate(p, 0.0).escaped {
            agree += 1;
        }
    }
    assert_eq!(agree, total);
}

#[test]
fn asin_form_at_a_general_point() {
    // p = (0.3, 0.4, 0.5): r = √0.5, θ = asin(0.5/r) = π/4, cos φ = 0.6, sin φ = 0.8.
    // Cubing: r³ = 0.5^1.5, 3θ = 3π/4, cos 3φ = 4c³ − 3c = −0.936, sin 3φ = 3s − 4s³ = 0.352.
    // So z³ = 0.5^1.5 · (cos 3θ cos 3φ, cos 3θ sin 3φ, sin 3θ) = (0.234, −0.088, 0.25).
    let w = power(Formula::Asin, DVec3::new(0.3, 0.4, 0.5), 3.0);
    assert!(
        (w - DVec3::new(0.234, -0.088, 0.25)).length() < 1e-12,
        "{w}"
    );
}

#[test]
fn whole_powers_match_the_trigonometric_form_in_every_convention() {
    let formulas = Formula::ALL;
    let (mut compared, mut polynomial) = (0, 0);
    for (i, p) in points(1500, 0.05..3.0, 11).into_iter().enumerate() {
        let z = [p.x, p.y, p.z];
        let r = p.length();
        for formula in formulas {
            for n in [2, 3, 5, 8, 9, 16] {
                let Some(fast) = triplex_power_int(formula, z, n) else {
                    continue; // within 1e-6 of this convention's pole axis
                };
                compared += 1;
                let trig = triplex_power_trig(formula, z, r, n as Real);
                let scale = r.powi(n as i32);
                for k in 0..3 {
                    assert!(
                        (fast[k] - trig[k]).abs() <= 1e-12 * scale,
                        "{formula:?} n={n} at {p}: {fast:?} vs {trig:?}"
                    );
                }
            }
        }
        // Quilez's expanded polynomial, kept for the benchmark, agrees too.
        if i % 3 == 0 {
            if let Some(poly) = power8_polynomial(z) {
                polynomial += 1;
                let fast = triplex_power_int(Formula::Quilez, z, 8).expect("off axis");
                for k in 0..3 {
                    assert!((poly[k] - fast[k]).abs() <= 1e-12 * r.powi(8));
                }
            }
        }
    }
    // Points skipped near a pole axis are few: nearly all were compared.
    assert!(compared > 1500 * 3 * 6 * 99 / 100, "{compared} compared");
    assert!(
        polynomial > 490,
        "{polynomial} compared with the polynomial"
    );
    // The integer power by squaring is exact for small integers.
    for n in 1..=20 {
        assert_eq!(
            powi(3.0, n, |a, b| a * b),
            Real::powi(3.0, n as i32),
            "3^{n}"
        );
    }
    assert_eq!(whole_power(8.0), Some(8));
    assert_eq!(whole_power(7.5), None);
    assert_eq!(whole_power(1.0), None);
}

#[test]
fn power8_on_the_pole_axis_falls_back_to_the_exact_value() {
    // On the y axis Quilez's polynomial divides by zero; z⁸ is (0, y⁸, 0) there.
    for y in [0.7, -0.7, 1.3] {
        let w = triplex_power(Formula::Quilez, [0.0, y, 0.0], Real::abs(y), 8.0);
        assert!(w[0].abs() < 1e-15 && w[2].abs() < 1e-15, "{w:?}");
        assert!((w[1] - Real::powi(y, 8)).abs() < 1e-15, "{w:?}");
    }
    assert!(power8_polynomial([0.0, 0.5, 0.0]).is_none());
    for formula in Formula::ALL {
        let pole: Triplex<Real> = formula.shape().join(0.5, [0.0, 0.0]);
        assert!(triplex_power_int(formula, pole, 8).is_none(), "{formula:?}");
        // The pole itself takes the trigonometric form, finite there.
        let w = triplex_power(formula, pole, 0.5, 8.0);
        assert!(w.iter().all(|v| v.is_finite()), "{formula:?}: {w:?}");
        assert!((w.iter().map(|v| v * v).sum::<Real>().sqrt() - Real::powi(0.5, 8)).abs() < 1e-15);
    }
}
