//! Palettes: OKLab interpolation, the stops and wrap modes, the orbit
//! quantities (deep frames' among them), what a palette does to albedo,
//! and that what its hits share is worked out once, to the bit.

use super::*;

/// A palette looked at through a table of its own, made for the default
/// fractal (or `fractal`) at each call: the tests' shorthand.
trait Looked {
    fn at(&self, t: f32) -> Vec3;
    fn colour(&self, x: f32) -> Vec3;
    fn quantity(&self, fractal: &Fractal, point: DVec3, e: &crate::fractal::Estimate) -> f32;
}

impl Looked for Palette {
    fn at(&self, t: f32) -> Vec3 {
        self.table(&Fractal::default()).at(t)
    }
    fn colour(&self, x: f32) -> Vec3 {
        self.table(&Fractal::default()).colour(x)
    }
    fn quantity(&self, fractal: &Fractal, point: DVec3, e: &crate::fractal::Estimate) -> f32 {
        self.table(fractal).quantity(fractal, point, e)
    }
}

/// Linear sRGB to OKLab by the published matrices (Ottosson 2020), in f64:
/// the reference the crate's f32 conversion is checked against.
fn oklab_of(c: [f64; 3]) -> [f64; 3] {
    let m1 = [
        [0.4122214708, 0.5363325363, 0.0514459929],
        [0.2119034982, 0.6806995451, 0.1073969566],
        [0.0883024619, 0.2817188376, 0.6299787005],
    ];
    let m2 = [
        [0.2104542553, 0.7936177850, -0.0040720468],
        [1.9779984951, -2.4285922050, 0.4505937099],
        [0.0259040371, 0.7827717662, -0.8086757660],
    ];
    let lms = m1.map(|row| (row[0] * c[0] + row[1] * c[1] + row[2] * c[2]).cbrt());
    m2.map(|row| row[0] * lms[0] + row[1] * lms[1] + row[2] * lms[2])
}

/// OKLab back to linear sRGB by the published inverse matrices.
fn linear_of(lab: [f64; 3]) -> [f64; 3] {
    let m1 = [
        [1.0, 0.3963377774, 0.2158037573],
        [1.0, -0.1055613458, -0.0638541728],
        [1.0, -0.0894841775, -1.2914855480],
    ];
    let m2 = [
        [4.0767416621, -3.3077115913, 0.2309699292],
        [-1.2684380046, 2.6097574011, -0.3413193965],
        [-0.0041960863, -0.7034186147, 1.7076147010],
    ];
    let lms = m1.map(|row| (row[0] * lab[0] + row[1] * lab[1] + row[2] * lab[2]).powi(3));
    m2.map(|row| row[0] * lms[0] + row[1] * lms[1] + row[2] * lms[2])
}

fn stop(position: f32, colour: Vec3) -> Stop {
    Stop { position, colour }
}

const RED: Vec3 = Vec3::new(1.0, 0.0, 0.0);
const BLUE: Vec3 = Vec3::new(0.0, 0.0, 1.0);
const GREEN: Vec3 = Vec3::new(0.0, 1.0, 0.0);

fn two_stops(wrap: Wrap) -> Palette {
    Palette {
        stops: vec![stop(0.25, RED), stop(0.75, BLUE)],
        wrap,
        scale: 1.0,
        ..Palette::default()
    }
}

#[test]
fn the_midpoint_of_two_stops_is_their_oklab_average() {
    let p = two_stops(Wrap::Clamp);
    let (a, b) = (oklab_of([1.0, 0.0, 0.0]), oklab_of([0.0, 0.0, 1.0]));
    let expected = linear_of([0, 1, 2].map(|k| 0.5 * (a[k] + b[k])));
    let got = p.at(0.5);
    for k in 0..3 {
        assert!(
            (got[k] as f64 - expected[k].max(0.0)).abs() < 1e-4,
            "{got:?} vs {expected:?}"
        );
    }
    // Not the RGB average, which is darker in the middle.
    assert!((got - Vec3::new(0.5, 0.0, 0.5)).length() > 0.05);
    // A quarter of the way, from the stops' own conversions too.
    let expected = linear_of([0, 1, 2].map(|k| 0.75 * a[k] + 0.25 * b[k]));
    let got = p.at(0.375);
    for k in 0..3 {
        assert!((got[k] as f64 - expected[k].max(0.0)).abs() < 1e-4);
    }
}

#[test]
fn stops_give_their_own_colours_and_the_ends_follow_the_wrap() {
    for wrap in [Wrap::Repeat, Wrap::Mirror, Wrap::Clamp] {
        let p = two_stops(wrap);
        assert!((p.at(0.25) - RED).length() < 1e-4, "{wrap:?}");
        assert!((p.at(0.75) - BLUE).length() < 1e-4, "{wrap:?}");
    }
    // Clamp and Mirror hold the end stops' colours outside them.
    for wrap in [Wrap::Mirror, Wrap::Clamp] {
        let p = two_stops(wrap);
        assert!((p.at(0.0) - RED).length() < 1e-4);
        assert!((p.at(1.0) - BLUE).length() < 1e-4);
    }
    // Repeat runs from the last stop on into the first across the seam:
    // 0 and 1 are the same place, halfway from blue (0.75) to red (1.25).
    let p = two_stops(Wrap::Repeat);
    let seam = mix_oklab(BLUE, RED, 0.5);
    assert!((p.at(0.0) - seam).length() < 1e-4);
    assert!((p.at(0.999_999) - seam).length() < 1e-4);
    assert!((p.colour(1.0) - seam).length() < 1e-4);
}

#[test]
fn wrap_modes_fold_the_quantity_as_documented() {
    let close = |a: f32, b: f32| (a - b).abs() < 1e-6;
    assert!(close(Wrap::Repeat.fold(1.25), 0.25));
    assert!(close(Wrap::Repeat.fold(-0.25), 0.75));
    assert!(close(Wrap::Mirror.fold(1.25), 0.75));
    assert!(close(Wrap::Mirror.fold(-0.25), 0.25));
    assert!(close(Wrap::Mirror.fold(2.25), 0.25));
    assert!(close(Wrap::Clamp.fold(1.25), 1.0));
    assert!(close(Wrap::Clamp.fold(-3.0), 0.0));
    // Scale and offset place the quantity before it folds.
    let p = Palette {
        scale: 2.0,
        offset: 0.25,
        ..two_stops(Wrap::Mirror)
    };
    assert!((p.colour(0.25) - p.at(0.75)).length() < 1e-6);
}

#[test]
fn equal_positions_make_a_hard_edge_and_one_stop_is_flat() {
    let p = Palette {
        stops: vec![
            stop(0.0, RED),
            stop(0.5, RED),
            stop(0.5, GREEN),
            stop(1.0, GREEN),
        ],
        wrap: Wrap::Clamp,
        ..Palette::default()
    };
    assert!((p.at(0.499) - RED).length() < 1e-3);
    assert!((p.at(0.501) - GREEN).length() < 1e-3);
    let flat = Palette {
        stops: vec![stop(0.3, GREEN)],
        ..Palette::default()
    };
    for t in [0.0, 0.3, 0.9] {
        assert!((flat.at(t) - GREEN).length() < 1e-4);
    }
}

/// Points along a line from outside the bulb towards it, `step` apart.
fn along(from: DVec3, to: DVec3, count: usize) -> impl Iterator<Item = DVec3> {
    (0..=count).map(move |i| from + (to - from) * (i as Real / count as Real))
}

#[test]
fn the_smooth_count_is_continuous_where_the_escape_count_steps() {
    let fractal = Fractal::default();
    let escape = fractal.escape_radius::<Real>();
    let smooth = |p: DVec3| {
        let o = fractal.orbit([p.x, p.y, p.z], fractal.iterations, true);
        let nu = smooth_iterations(o.iterations, o.r, escape, fractal.power);
        (o.iterations, nu, o.escaped)
    };
    let points: Vec<DVec3> = along(DVec3::new(0.3, 0.2, 1.6), DVec3::ZERO, 20_000).collect();
    let mut steps = 0;
    for pair in points.windows(2) {
        let (mut p, mut q) = (pair[0], pair[1]);
        let ((i, _, out_p), (j, _, out_q)) = (smooth(p), smooth(q));
        if !(out_p && out_q && j == i + 1) {
            continue;
        }
        // Closer in on the step: neighbours 1e-14 apart either side of it.
        for _ in 0..40 {
            let mid = (p + q) * 0.5;
            match smooth(mid).0 {
                k if k == i => p = mid,
                _ => q = mid,
            }
        }
        let ((_, a, _), (_, b, _)) = (smooth(p), smooth(q));
        steps += 1;
        assert!((a - b).abs() < 1e-3, "{i}: {a} then {j}: {b}");
    }
    assert!(
        steps >= 2,
        "the line crosses {steps} steps of the escape count"
    );
}

#[test]
fn a_palette_with_no_mix_leaves_the_trap_colours() {
    let traps = OrbitTraps {
        origin: 0.3,
        planes: DVec3::new(0.05, 0.2, 0.7),
    };
    let plain = Look::default();
    let mut with = plain.clone();
    with.palette = Some(Palette {
        mix: 0.0,
        ..Palette::default()
    });
    let a = plain.albedo(&traps, None);
    let colour = Some(Palette::default().colour(0.4));
    assert_eq!(a.to_array(), with.albedo(&traps, colour).to_array());
    with.palette.as_mut().unwrap().mix = 1.0;
    assert_ne!(a, with.albedo(&traps, colour));
}

#[test]
fn a_deep_frames_quantities_are_the_plain_orbits() {
    use crate::exact::big_from_f64;
    use crate::fractal::deep::Reference;
    let plain = Fractal {
        iterations: 24,
        ..Fractal::default()
    };
    let anchor = DVec3::new(0.31, 0.62, 0.58);
    let bits = 128;
    let big = anchor.to_array().map(|c| big_from_f64(c, bits));
    let reference = Reference::new(&plain, big, bits).expect("a whole power");
    let deep = Fractal {
        deep: Some(std::sync::Arc::new(reference)),
        ..plain.clone()
    };
    for by in [OrbitQuantity::SmoothIterations, OrbitQuantity::Angle] {
        let p = Palette {
            by,
            ..Palette::default()
        };
        for delta in [DVec3::new(1e-7, -2e-7, 3e-8), DVec3::new(-4e-9, 1e-9, 2e-9)] {
            let a = p.quantity(&deep, delta, &deep.estimate(delta, 1e-9));
            let q = anchor + delta;
            let b = p.quantity(&plain, q, &plain.estimate(q, 1e-9));
            assert!((a - b).abs() < 1e-3, "{by:?}: deep {a}, plain {b}");
        }
    }
}

/// `Palette::at` worked out without the OKLab table: both stops converted
/// at the call (`mix_oklab`), the neighbour across a repeating seam shifted.
fn at_converting(p: &Palette, t: f32) -> Vec3 {
    let (first, last, n) = (p.stops[0], p.stops[p.stops.len() - 1], p.stops.len());
    let shifted = |s: Stop, by: f32| stop(s.position + by, s.colour);
    let next = p.stops.partition_point(|s| s.position <= t);
    let (a, b) = match (next, p.wrap) {
        (0, Wrap::Repeat) => (shifted(last, -1.0), first),
        (0, _) => return first.colour,
        (k, Wrap::Repeat) if k == n => (last, shifted(first, 1.0)),
        (k, _) if k == n => return last.colour,
        (k, _) => (p.stops[k - 1], p.stops[k]),
    };
    let span = b.position - a.position;
    let f = if span > 0.0 {
        (t - a.position) / span
    } else {
        1.0
    };
    mix_oklab(a.colour, b.colour, f.clamp(0.0, 1.0))
}

/// Gradient places from before the first stop to past the last.
fn places() -> impl Iterator<Item = f32> {
    (0..=1000).map(|i| i as f32 / 1000.0 * 1.2 - 0.1)
}

#[test]
fn a_palette_converts_each_stop_once_not_at_every_hit() {
    let p = Palette::default();
    let before = crate::shade::palette::CONVERSIONS.with(|n| n.get());
    let table = p.table(&Fractal::default());
    for t in places() {
        table.colour(t);
    }
    let converted = crate::shade::palette::CONVERSIONS.with(|n| n.get()) - before;
    assert_eq!(converted, p.stops.len() as u64);
}

#[test]
fn the_converted_stops_give_every_colour_to_the_bit() {
    let bits = |c: Vec3| c.to_array().map(f32::to_bits);
    for wrap in [Wrap::Repeat, Wrap::Mirror, Wrap::Clamp] {
        let mut uneven = Palette {
            wrap,
            ..Palette::default()
        };
        uneven.stops.push(stop(0.85, GREEN));
        for p in [two_stops(wrap), uneven] {
            for t in places() {
                assert_eq!(bits(p.at(t)), bits(at_converting(&p, t)), "{wrap:?} at {t}");
            }
        }
    }
}

#[test]
fn a_stop_edited_after_shading_shows_its_new_colour() {
    let mut p = two_stops(Wrap::Clamp);
    let before = p.at(0.5);
    p.stops[1].colour = GREEN;
    let fresh = two_stops(Wrap::Clamp);
    let fresh = Palette {
        stops: vec![fresh.stops[0], stop(0.75, GREEN)],
        ..fresh
    };
    assert_eq!(p.at(0.5), fresh.at(0.5));
    assert_ne!(p.at(0.5), before);
}

/// The quantities as the hit's orbit, iterated again in f64, gives them.
fn quantity_from_orbit(by: OrbitQuantity, fractal: &Fractal, point: DVec3) -> f32 {
    let o = fractal.orbit_at([point.x, point.y, point.z], fractal.iterations, true);
    match by {
        OrbitQuantity::Angle => {
            use crate::fractal::Formula;
            let phi = match fractal.formula {
                Formula::Quilez => o.z[0].atan2(o.z[2]),
                Formula::WhiteNylander | Formula::Asin => o.z[1].atan2(o.z[0]),
                Formula::Quaternion => o.z[2].atan2(o.z[1]),
            };
            (phi / std::f64::consts::TAU + 0.5) as f32
        }
        _ => smooth_iterations(
            o.iterations,
            o.r,
            fractal.escape_radius::<Real>(),
            fractal.power,
        ),
    }
}

#[test]
fn a_hits_quantities_from_its_estimate_are_its_orbits_to_the_bit() {
    use crate::fractal::{DeMethod, Formula, Precision};
    let mut fractals = vec![];
    for formula in [Formula::Quilez, Formula::WhiteNylander, Formula::Quaternion] {
        for julia in [None, Some(DVec3::new(0.3, -0.5, 0.2))] {
            fractals.push(Fractal {
                formula,
                julia,
                ..Fractal::default()
            });
        }
    }
    // Those whose estimates end elsewhere iterate again.
    for (de, precision) in [
        (DeMethod::Potential, Precision::F64),
        (DeMethod::Jacobian, Precision::F64),
        (DeMethod::Analytic, Precision::F32),
    ] {
        fractals.push(Fractal {
            de,
            precision,
            power: 7.5,
            ..Fractal::default()
        });
    }
    let points = crate::math::shell_points(192, 0.9..1.3, 3);
    for f in &fractals {
        for by in [OrbitQuantity::SmoothIterations, OrbitQuantity::Angle] {
            let p = Palette {
                by,
                ..Palette::default()
            };
            for chunk in points.chunks(16) {
                let lanes: [DVec3; 16] = chunk.try_into().expect("192 points, 16 at a time");
                let estimates = f.estimate_lanes(lanes, [1e-4; 16]);
                for (q, e) in lanes.iter().zip(&estimates) {
                    let want = quantity_from_orbit(by, f, *q);
                    let got = p.quantity(f, *q, e);
                    assert_eq!(got.to_bits(), want.to_bits(), "{by:?} {f:?} at {q}");
                }
            }
        }
    }
}
