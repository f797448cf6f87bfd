//! Surface normals from a tetrahedral central difference of the estimate.

use super::{Hit, MarchSettings, Ray};
use crate::fractal::{Estimate, Fractal, TETRAHEDRON, VECTOR};
use crate::math::{normalize_or, DVec3, Real};

/// Surface normal at `hit` from a tetrahedral central difference of the
/// estimate, with a step proportional to the pixel footprint. Returns the normal
/// and the number of orbits used; falls back to facing the ray.
pub fn normal(ray: &Ray, hit: &Hit, fractal: &Fractal, settings: &MarchSettings) -> (DVec3, u32) {
    // The four estimates are independent: evaluated side by side.
    let (points, footprint) = normal_points(ray, hit, settings);
    let estimates = fractal.estimate_lanes(points, [footprint; 4]);
    normal_from(ray, &estimates)
}

/// `normal` for many hits, four to a call of the lane kernel (its 16
/// estimates), so a hit does not pay for a call of its own: `out(i, ray,
/// hit, …)` gets what `normal` gives for each hit (`i` as given with it),
/// bit for bit (each lane of the kernel is independent of the others).
pub fn normals_many<'h>(
    hits: impl IntoIterator<Item = (usize, &'h Ray, &'h Hit)>,
    fractal: &Fractal,
    settings: &MarchSettings,
    mut out: impl FnMut(usize, &'h Ray, &'h Hit, (DVec3, u32)),
) {
    let mut hits = hits.into_iter().peekable();
    let mut estimates = [Estimate::IDLE; VECTOR];
    while hits.peek().is_some() {
        // The last call's spare lanes idle outside the bailout ball.
        let mut batch = [None; VECTOR / 4];
        let mut points = [crate::fractal::IDLE_POINT; VECTOR];
        let mut footprints = [1.0; VECTOR];
        for (k, (slot, hit)) in batch.iter_mut().zip(hits.by_ref()).enumerate() {
            let (p, f) = normal_points(hit.1, hit.2, settings);
            points[4 * k..4 * k + 4].copy_from_slice(&p);
            footprints[4 * k..4 * k + 4].fill(f);
            *slot = Some(hit);
        }
        // A normal reads only the distances.
        fractal.distance_lanes_into(&points, &footprints, &mut estimates);
        for (k, &(i, ray, hit)) in batch.iter().flatten().enumerate() {
            out(i, ray, hit, normal_from(ray, &estimates[4 * k..4 * k + 4]));
        }
    }
}

/// The four points `normal` estimates around `hit` (a tetrahedron a
/// `normal_step` of footprints across, stepped back along the ray so that
/// it straddles the surface rather than sits inside, where the estimate is
/// flat zero), and the footprint there.
pub(super) fn normal_points(ray: &Ray, hit: &Hit, settings: &MarchSettings) -> ([DVec3; 4], Real) {
    let footprint = ray.footprint(hit.t);
    let h = settings.normal_step * footprint;
    let centre = hit.point - ray.dir * h;
    (TETRAHEDRON.map(|k| centre + k * h), footprint)
}

/// The normal from the estimates at `normal_points`, and the orbits they
/// took; facing the ray where the gradient is zero.
pub(super) fn normal_from(ray: &Ray, estimates: &[Estimate]) -> (DVec3, u32) {
    let mut gradient = DVec3::ZERO;
    let mut orbits = 0;
    for (k, e) in TETRAHEDRON.iter().zip(estimates) {
        gradient += *k * e.distance;
        orbits += e.orbits;
    }
    (normalize_or(gradient, -ray.dir), orbits)
}
