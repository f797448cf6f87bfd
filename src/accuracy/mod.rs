//! What accuracy costs in time: `mandelreel accuracy` renders one frame of a
//! user's own scene as a reference that trusts no distance estimate, then
//! sweeps every quality knob, distance estimator and precision one at a time
//! around the scene's settings and measures, for each, the wall time, the
//! orbits computed, the depth error against the reference and the image error.
//!
//! The reference has two parts: hit depths found by membership stepping and
//! bisection (`march::march_by_membership`), and a shaded image of the same
//! fractal with every marching knob set high (`reference_scene`).

use crate::scene::Scene;
use serde::Serialize;

mod chart;
mod front;
mod metrics;
mod reference;
mod report;
mod surface;
mod sweep;
mod timing;

pub use chart::write_chart;
pub use front::{flagged, front_of, recommended, OVERSHOOT_FLAG, TIMING_NOISE, VISIBLE_PSNR_DB};
pub use metrics::{depth_errors, film_hits, footprints_at, DepthErrors};
pub use reference::{reference_depths, reference_scene, Convergence, REFERENCE_STEP};
pub use report::{to_csv, to_markdown};
pub use sweep::measure;

/// What one variant cost and how far it is from the reference.
#[derive(Clone, Debug, Serialize)]
pub struct Measurement {
    pub knob: &'static str,
    pub setting: String,
    pub seconds: f64,
    /// Orbits computed (distance-estimator evaluations, membership tests, normals).
    pub de_evaluations: u64,
    /// Mean and 99th percentile of |depth − reference depth| in pixel footprints,
    /// over pixels that both hit.
    pub depth_error_mean_px: f64,
    pub depth_error_p99_px: f64,
    /// Share of pixels where this variant and the reference disagree on hit or miss.
    pub hit_mismatch: f64,
    /// Share of pixels whose hit lies more than one footprint past the reference
    /// crossing: the marcher went through the surface (the failure that matters;
    /// stopping early, where a pixel's cone grazes a sub-pixel feature in front
    /// of the centre ray's crossing, is what a footprint threshold is meant to do).
    pub overshoot: f64,
    /// Root-mean-square difference of the sRGB images (0..1 per channel).
    pub image_rmse: f64,
    /// Peak signal-to-noise ratio of that difference in dB (infinite when identical).
    pub psnr_db: f64,
    /// Median 3D distance from the hits of a grid of centre rays to the set,
    /// in footprints (`surface::median_distance`); none on a deep frame.
    pub surface_distance_px: Option<f64>,
    /// On the Pareto front of median time against image error, timing noise
    /// allowed for (`pareto_front`).
    pub pareto: bool,
}

/// Everything `accuracy` measured.
#[derive(Clone, Debug)]
pub struct Report {
    pub rows: Vec<Measurement>,
    pub reference: Scene,
    pub convergence: Convergence,
}

/// A row of the given time and image error, for the tests of the front and the report.
#[cfg(test)]
fn row(knob: &'static str, seconds: f64, rmse: f64) -> Measurement {
    Measurement {
        knob,
        setting: String::new(),
        seconds,
        // Work in proportion to time, so no two rows here are the same work.
        de_evaluations: (seconds * 1000.0) as u64,
        depth_error_mean_px: 0.0,
        depth_error_p99_px: 0.0,
        hit_mismatch: 0.0,
        overshoot: 0.0,
        image_rmse: rmse,
        psnr_db: metrics::psnr(rmse),
        surface_distance_px: None,
        pareto: false,
    }
}
