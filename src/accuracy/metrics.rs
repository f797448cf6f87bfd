//! Error metrics against the reference: depth error, hit/miss and overshoot
//! in pixel footprints, and the sRGB image's RMSE and PSNR.

use crate::color::linear_to_srgb;
use crate::math::Real;
use crate::render::Film;
use crate::scene::Scene;

/// The sRGB image of a film as its PNG shows it (`look`'s exposure and
/// tone map), as 0..1 floats.
pub(super) fn srgb(film: &Film, look: &crate::shade::Look) -> Vec<f32> {
    let display = look.display_transform();
    film.colour
        .iter()
        .flat_map(|c| [c.x, c.y, c.z])
        .map(|x| linear_to_srgb(display.apply(x)))
        .collect()
}

/// Errors of one variant against the reference.
pub(super) struct Errors {
    pub(super) depth: DepthErrors,
    pub(super) rmse: f64,
}

/// How far hit distances lie from the reference's, per pixel, in pixel
/// footprints at the reference depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthErrors {
    /// Mean and 99th percentile of |depth − reference depth| over pixels
    /// that both hit.
    pub mean_px: f64,
    pub p99_px: f64,
    /// Share of pixels where one hits and the other misses.
    pub hit_mismatch: f64,
    /// Share of pixels whose hit lies more than a footprint past the reference.
    pub overshoot: f64,
}

/// The hits of a rendered film: its nearest depth where any sample hit.
pub fn film_hits(film: &Film) -> Vec<Option<Real>> {
    film.alpha
        .iter()
        .zip(&film.depth)
        .map(|(&a, &d)| (a > 0.0).then_some(d as Real))
        .collect()
}

/// Each pixel's footprint at its reference depth (at distance 1 where the
/// reference misses), for `depth_errors`.
pub fn footprints_at(scene: &Scene, width: u32, height: u32, depths: &[Option<Real>]) -> Vec<Real> {
    let camera = scene.camera.frame();
    (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .map(|(x, y)| camera.ray(x as Real + 0.5, y as Real + 0.5, width, height))
        .map(|ray| ray.footprint(1.0))
        .zip(depths)
        // Footprints scale with distance: footprint(t) = t × footprint(1).
        .map(|(f, t)| t.map_or(f, |t| (t * f).max(1e-300)))
        .collect()
}

/// Depth errors of `hits` against `reference` (see `DepthErrors`).
pub fn depth_errors(
    hits: &[Option<Real>],
    reference: &[Option<Real>],
    footprints: &[Real],
) -> DepthErrors {
    let mut errors = Vec::new();
    let mut mismatches = 0usize;
    let mut overshoots = 0usize;
    for (i, (hit, reference)) in hits.iter().zip(reference).enumerate() {
        match (hit, reference) {
            (Some(t), Some(r)) => {
                let signed = (t - r) / footprints[i];
                if signed > 1.0 {
                    overshoots += 1;
                }
                errors.push(signed.abs())
            }
            (None, None) => {}
            _ => mismatches += 1,
        }
    }
    errors.sort_by(|a, b| a.total_cmp(b));
    let mean = if errors.is_empty() {
        0.0
    } else {
        errors.iter().sum::<f64>() / errors.len() as f64
    };
    let p99 = errors
        .get(((errors.len() as f64 * 0.99).ceil() as usize).saturating_sub(1))
        .copied()
        .unwrap_or(0.0);
    let pixels = reference.len().max(1) as f64;
    DepthErrors {
        mean_px: mean,
        p99_px: p99,
        hit_mismatch: mismatches as f64 / pixels,
        overshoot: overshoots as f64 / pixels,
    }
}

/// Errors of `hits` and `image` against the reference.
pub(super) fn compare(
    hits: &[Option<Real>],
    image: &[f32],
    reference_image: &[f32],
    reference_depth: &[Option<Real>],
    footprints: &[Real],
) -> Errors {
    let mse = image
        .iter()
        .zip(reference_image)
        .map(|(a, b)| ((a - b) as f64).powi(2))
        .sum::<f64>()
        / image.len().max(1) as f64;
    Errors {
        depth: depth_errors(hits, reference_depth, footprints),
        rmse: mse.sqrt(),
    }
}

/// PSNR of an RMSE in unit values.
pub(super) fn psnr(rmse: f64) -> f64 {
    crate::math::psnr_db_of_rmse(rmse, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_errors_of_known_hits() {
        // Five pixels, footprints 0.5, 1, 2, 1, 1: pixel 0 stops 1 footprint
        // short (0.5 before), pixel 1 3 footprints past (an overshoot),
        // pixel 2 exactly on, pixel 3 hits where the reference misses,
        // pixel 4 misses where the reference hits.
        let hits = [Some(1.5), Some(5.0), Some(4.0), Some(1.0), None];
        let reference = [Some(2.0), Some(2.0), Some(4.0), None, Some(3.0)];
        let e = depth_errors(&hits, &reference, &[0.5, 1.0, 2.0, 1.0, 1.0]);
        assert_eq!(e.mean_px, (1.0 + 3.0 + 0.0) / 3.0);
        assert_eq!(e.p99_px, 3.0);
        assert_eq!(e.hit_mismatch, 2.0 / 5.0);
        assert_eq!(e.overshoot, 1.0 / 5.0);
    }

    #[test]
    fn psnr_of_known_errors() {
        assert_eq!(psnr(0.0), f64::INFINITY);
        assert!((psnr(0.1) - 20.0).abs() < 1e-12);
        assert!((psnr(0.01) - 40.0).abs() < 1e-12);
    }
}
