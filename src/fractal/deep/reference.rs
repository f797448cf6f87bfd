//! Reference orbits in high precision (dashu's binary floats), rounded to
//! f64 point by point: the orbits every pixel of a deep frame is a small
//! difference from.

use super::super::{Formula, Triplex};
use crate::exact::{big_from_f64, Big};
use crate::math::Real;

/// The whole power `n` of `z` in high precision, by de Moivre as
/// `power::triplex_power_int` takes it; on the pole axis the azimuth is 0.
fn power(formula: Formula, z: &[Big; 3], n: u32, bits: usize) -> [Big; 3] {
    let zero = || big_from_f64(0.0, bits);
    let one = || big_from_f64(1.0, bits);
    let shape = formula.shape();
    let (pole, [e1, e2]) = shape.split(z.each_ref());
    let rho2 = e1 * e1 + e2 * e2;
    let m = if shape.turns_azimuth { n } else { 1 };
    let (cp, sp, rho) = if rho2 == zero() {
        (one(), zero(), zero())
    } else {
        let rho = rho2.sqrt();
        let (a, b) = complex_power(e1, e2, m);
        let rho_m = power_of(&rho, m);
        (a / &rho_m, b / &rho_m, rho)
    };
    let (along, across) = if shape.from_equator {
        let (rc, rs) = complex_power(&rho, pole, n);
        (rs, rc)
    } else {
        complex_power(pole, &rho, n)
    };
    shape.join(along, [&across * &cp, across * sp])
}

fn power_of(x: &Big, n: u32) -> Big {
    let mut out = x.clone();
    for _ in 1..n {
        out = &out * x;
    }
    out
}

fn complex_power(re: &Big, im: &Big, n: u32) -> (Big, Big) {
    let (mut a, mut b) = (re.clone(), im.clone());
    for _ in 1..n {
        (a, b) = (&a * re - &b * im, &a * im + &b * re);
    }
    (a, b)
}

/// The orbit of `start` under z ↦ zⁿ + `c`, in `bits` of precision: at
/// most `limit` + 1 points, ending with the first past `escape`.
pub(super) fn orbit(
    formula: Formula,
    n: u32,
    start: [Big; 3],
    c: &[Big; 3],
    limit: u32,
    escape: Real,
    bits: usize,
) -> Vec<[Big; 3]> {
    let mut points = vec![start];
    // One point past the escape radius, so that a point whose orbit is just
    // inside it when the reference's is just outside has a next one.
    let mut past = 0;
    for _ in 0..limit {
        let z = &points[points.len() - 1];
        if rounded(z).iter().map(|v| v * v).sum::<Real>() > escape * escape {
            past += 1;
            if past == 2 {
                break;
            }
        }
        let w = power(formula, z, n, bits);
        points.push([0, 1, 2].map(|i| &w[i] + &c[i]));
    }
    points
}

/// |z|² − `escape`², computed in high precision and then rounded: a point
/// of the orbit Z + δ is past the escape radius where this plus 2Z·δ + δ²
/// is positive, a test f64 takes exactly where |Z + δ|² itself cannot.
pub(super) fn excess(z: &[Big; 3], escape: Real, bits: usize) -> Real {
    let e = big_from_f64(escape, bits);
    let sum = &z[0] * &z[0] + &z[1] * &z[1] + &z[2] * &z[2] - &e * &e;
    sum.to_f64().value()
}

/// A high-precision point rounded to f64.
pub(super) fn rounded(z: &[Big; 3]) -> Triplex<Real> {
    z.each_ref().map(|v| v.to_f64().value())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fractal::triplex_power_trig;

    #[test]
    fn the_high_precision_power_is_the_trigonometric_one() {
        for formula in Formula::ALL {
            for n in [2, 3, 8] {
                for z in [
                    [0.3, -0.7, 0.4],
                    [-0.9, 0.1, 0.25],
                    [0.0, 0.5, 0.0],
                    [0.0, 0.0, -0.6],
                ] {
                    let big = z.map(|v| big_from_f64(v, 128));
                    let got = power(formula, &big, n, 128).map(|v| v.to_f64().value());
                    let r = (z[0] * z[0] + z[1] * z[1] + z[2] * z[2]).sqrt();
                    let want = triplex_power_trig(formula, z, r, n as Real);
                    for (g, w) in got.iter().zip(want) {
                        assert!(
                            (g - w).abs() < 1e-12 * r.powi(n as i32),
                            "{formula:?} {n} {z:?}: {got:?} vs {want:?}"
                        );
                    }
                }
            }
        }
    }
}
