//! Cones never start a ray past the surface, and blocks cover a band.

use super::*;

/// A pinhole camera at `origin` looking at the centre: the ray `u`
/// pixels right and `v` pixels up of the middle, pixels `angle` apart.
fn pinhole(origin: DVec3, angle: Real) -> impl Fn(Real, Real) -> Ray {
    let ahead = (-origin).normalize();
    let right = ahead.cross(DVec3::Z).normalize();
    let up = right.cross(ahead);
    move |u, v| Ray {
        origin,
        dir: (ahead + right * (u * angle) + up * (v * angle)).normalize(),
        pixel_angle: angle,
        start_footprint: 0.0,
    }
}

/// Rows of camera rays: one origin, directions `angle` apart, the rows
/// far apart.
fn camera_rows(origin: DVec3, rows: usize, width: usize, angle: Real) -> Vec<Vec<Ray>> {
    let ray = pinhole(origin, angle);
    (0..rows)
        .map(|row| {
            let v = (row as Real - rows as Real / 2.0) * 97.0;
            (0..width)
                .map(|x| ray(x as Real - width as Real / 2.0, v))
                .collect()
        })
        .collect()
}

/// Bands of camera rays four neighbouring pixels high and `width` wide,
/// each band's rays in the renderer's order (`cone_blocks` for the
/// default cone of 16 rays, blocks of 4×4 pixels), with its blocks'
/// sizes (narrower at the right edge where 4 does not divide `width`).
/// The bands are far apart.
fn camera_blocks(
    origin: DVec3,
    bands: usize,
    width: usize,
    angle: Real,
) -> Vec<(Vec<Ray>, Vec<u32>)> {
    let ray = pinhole(origin, angle);
    let block = cone_block(MarchSettings::default().cone_rays);
    (0..bands)
        .map(|band| {
            let v0 = (band as Real - bands as Real / 2.0) * 97.0;
            let (mut order, mut runs) = (vec![], vec![]);
            cone_blocks(width, CONE_BLOCK_ROWS, block, &mut order, &mut runs);
            let rays = order
                .iter()
                .map(|&p| {
                    ray(
                        (p % width) as Real - width as Real / 2.0,
                        v0 + (p / width) as Real,
                    )
                })
                .collect();
            (rays, runs)
        })
        .collect()
}

/// The default bulb, the benchmark's (asin, bailout 10) and a Julia set.
fn cone_test_fractals() -> [Fractal; 3] {
    use crate::fractal::Formula;
    let (asin, julia) = (Formula::Asin, Some(DVec3::new(0.3, -0.5, 0.2)));
    [
        Fractal::default(),
        Fractal {
            formula: asin,
            bailout: 10.0,
            ..Fractal::default()
        },
        Fractal {
            julia,
            power: 3.0,
            ..Fractal::default()
        },
    ]
}

#[test]
fn a_cone_never_starts_a_ray_past_the_surface() {
    // Each run's cone against every one of its rays' first crossing,
    // found by membership steps (no distance estimate trusted): runs of
    // 8 and 16 rays along a row and blocks of 4×4 pixels (the default),
    // pinhole rays and rays whose origins spread over a lens, as depth
    // of field gives them.
    let settings = MarchSettings::default();
    let (mut advanced, mut crossings) = (0, 0);
    let origin = DVec3::new(0.3, -2.6, 0.4);
    // Each set of rays with its runs' lengths.
    let mut layouts: Vec<(Vec<Ray>, Vec<u32>)> = vec![];
    for rays in camera_rows(origin, 6, 32, 2e-3) {
        for n in [8, 16] {
            layouts.push((rays.clone(), vec![n; rays.len() / n as usize]));
        }
    }
    layouts.extend(camera_blocks(origin, 3, 32, 2e-3));
    for f in &cone_test_fractals() {
        for aperture in [0.0, 0.01] {
            for (rays, runs) in &layouts {
                let rays: Vec<Ray> = rays
                    .iter()
                    .copied()
                    .enumerate()
                    .map(|(k, ray)| {
                        let (a, r) = (k as Real * 2.4, (k % 5) as Real / 4.0);
                        // Through a point of the lens towards where the
                        // pinhole ray is 2.5 along: focused there.
                        let lens = DVec3::new(a.cos(), 0.0, a.sin()) * (aperture * r);
                        let focus = ray.at(2.5);
                        Ray {
                            origin: ray.origin + lens,
                            dir: (focus - ray.origin - lens).normalize(),
                            ..ray
                        }
                    })
                    .collect();
                let first_crossings: Vec<Option<Real>> = rays
                    .iter()
                    .map(|ray| march_by_membership(ray, f, &settings, 0.25, 1e-9, 100_000).0)
                    .collect();
                for span in run_spans(runs) {
                    let run = &rays[span.clone()];
                    let (t_free, _) = walk_one(
                        ConeWalk::start(run, &intervals(run, &settings)),
                        f,
                        &settings,
                    );
                    for (ray, crossing) in run.iter().zip(&first_crossings[span]) {
                        let enter = settings
                            .interval(ray)
                            .map_or(Real::INFINITY, |(enter, _)| enter);
                        if aperture == 0.0 {
                            advanced += (t_free > enter + 20.0 * ray.footprint(enter)) as usize;
                        }
                        if let Some(t) = *crossing {
                            crossings += 1;
                            assert!(t_free <= t, "{f:?}: cone to {t_free}, surface at {t}");
                        }
                    }
                }
            }
        }
    }
    // The pinhole cones did go ahead of most rays, and most rays meet
    // the surface (3 fractals × 2 lenses × (2 × 192 + 384) rays).
    assert!(
        advanced > 1500 && crossings > 2500,
        "{advanced} advanced, {crossings} crossings"
    );
}

#[test]
fn a_cone_that_lands_inside_starts_its_rays_a_step_back() {
    // A fudge of 3 trusts the unit ball's exact distance three times
    // over, so the cone's step lands inside the ball: its rays must
    // start from the point before, in front of the surface (t = 2 on
    // the axis, a little more off it).
    let settings = MarchSettings {
        fudge: 3.0,
        ..MarchSettings::default()
    };
    let origin = DVec3::new(0.0, 0.0, 3.0);
    let run: Vec<Ray> = (0..8)
        .map(|k| ray(origin, DVec3::new(1e-3 * k as Real, 0.0, -1.0)))
        .collect();
    let (t_free, evaluations) = walk_one(
        ConeWalk::start(&run, &intervals(&run, &settings)),
        &unit_ball(),
        &settings,
    );
    // From the sphere (t = 1.5) it stepped to the centre, inside: back.
    assert_eq!(evaluations, 2);
    assert!((1.5..2.0).contains(&t_free), "cone stopped at {t_free}");
}

#[test]
fn rays_after_a_cone_find_the_surface_they_find_alone() {
    let settings = MarchSettings::default();
    let origin = DVec3::new(-2.2, -1.1, 0.9);
    // Rows of 64 in runs of 8 and in runs of uneven lengths, one of them
    // a single ray; bands in blocks of 4×4 pixels (the default), 30
    // pixels wide, so the last block of each band is 2×4.
    let rows = |runs: &[u32]| -> Vec<(Vec<Ray>, Vec<u32>)> {
        let rows = camera_rows(origin, 6, 64, 1.5e-3);
        rows.into_iter().map(|rays| (rays, runs.to_vec())).collect()
    };
    let cases = [
        rows(&[8; 8]),
        rows(&[13, 7, 16, 1, 27]),
        camera_blocks(origin, 3, 30, 1.5e-3),
    ];
    for f in &cone_test_fractals() {
        for (case, groups) in cases.iter().enumerate() {
            let (mut both, mut near, mut differ, mut rays_seen) = (0, 0, 0, 0);
            let mut evaluations = [0u64; 2];
            for (rays, runs) in groups {
                let mut marched = [(); 2].map(|_| vec![MarchResult::default(); rays.len()]);
                let alone_runs = vec![1; rays.len()];
                for (k, runs) in [&alone_runs, runs].into_iter().enumerate() {
                    let (results, scratch) = (&mut marched[k], &mut ConeScratch::default());
                    march_camera_rays(rays, f, &settings, runs, results, scratch);
                    evaluations[k] += results.iter().map(|m| m.evaluations as u64).sum::<u64>();
                }
                let alone: Vec<MarchResult> =
                    rays.iter().map(|ray| march(ray, f, &settings)).collect();
                // One ray a cone is every ray alone, to the bit.
                assert_eq!(format!("{alone:?}"), format!("{:?}", marched[0]));
                // A run of one among longer runs marches alone too.
                for span in run_spans(runs).filter(|span| span.len() == 1) {
                    let (a, c) = (&alone[span.start], &marched[1][span.start]);
                    assert_eq!(format!("{a:?}"), format!("{c:?}"), "run of one at {span:?}");
                }
                rays_seen += rays.len();
                for ((ray, a), c) in rays.iter().zip(&alone).zip(&marched[1]) {
                    match (a.hit, c.hit) {
                        (Some(a), Some(c)) => {
                            both += 1;
                            near += ((a.t - c.t).abs() <= 2.0 * ray.footprint(a.t)) as usize;
                        }
                        (None, None) => {}
                        _ => differ += 1,
                    }
                }
            }
            // The same surface within a couple of footprints, nearly
            // everywhere, for fewer estimates.
            assert!(both > 100, "{f:?}, case {case}: {both} hits");
            assert!(
                near * 100 >= both * 95,
                "{f:?}, case {case}: {near} of {both} within 2 footprints"
            );
            assert!(
                differ * 100 <= 3 * rays_seen,
                "{f:?}, case {case}: {differ} hit/miss differ"
            );
            assert!(
                evaluations[1] * 10 < evaluations[0] * 9,
                "{f:?}, case {case}: {evaluations:?}"
            );
        }
    }
}

#[test]
fn cone_blocks_have_the_shortest_diagonal_four_rows_allow() {
    let shapes: Vec<_> = [1, 2, 3, 4, 6, 8, 12, 16, 32, 64, 9]
        .map(cone_block)
        .to_vec();
    assert_eq!(
        shapes,
        [
            (1, 1),
            (2, 1),
            (3, 1),
            (2, 2),
            (3, 2),
            (4, 2),
            (3, 4),
            (4, 4),
            (8, 4),
            (16, 4),
            (9, 1)
        ]
    );
    assert!(shapes.iter().all(|&(_, rows)| rows <= CONE_BLOCK_ROWS));
    assert_eq!(cone_block(MarchSettings::default().cone_rays), (4, 4));
}

#[test]
fn cone_blocks_cover_a_band_in_rectangles() {
    // Widths that the block divides and that it does not, full and
    // short bands, and every block shape the renderer uses.
    for (w, rows) in [(8, 4), (10, 4), (7, 3), (5, 1), (1, 4)] {
        for n in [1, 2, 4, 8, 12, 16, 32] {
            let (bw, bh) = cone_block(n);
            let (mut order, mut runs) = (vec![], vec![]);
            cone_blocks(w, rows, (bw, bh), &mut order, &mut runs);
            // Every pixel of the band exactly once.
            let mut sorted = order.clone();
            sorted.sort_unstable();
            assert_eq!(
                sorted,
                (0..w * rows).collect::<Vec<_>>(),
                "{w}x{rows} n={n}"
            );
            // Each run is a rectangle of at most bw×bh pixels, row by row.
            let mut at = 0;
            for &run in &runs {
                let block = &order[at..at + run as usize];
                at += run as usize;
                let xs = block.iter().map(|p| p % w);
                let ys = block.iter().map(|p| p / w);
                let (x0, x1) = (xs.clone().min().unwrap(), xs.max().unwrap());
                let (y0, y1) = (ys.clone().min().unwrap(), ys.max().unwrap());
                assert!(x1 - x0 < bw && y1 - y0 < bh, "{w}x{rows} n={n}: {block:?}");
                assert_eq!(block.len(), (x1 - x0 + 1) * (y1 - y0 + 1), "{block:?}");
                assert!(block.windows(2).all(|p| p[0] < p[1]), "{block:?}");
            }
            assert_eq!(at, order.len());
            // As few blocks as the band holds, the first a whole one.
            assert_eq!(runs.len(), w.div_ceil(bw) * rows.div_ceil(bh));
            assert_eq!(runs[0] as usize, bw.min(w) * bh.min(rows));
        }
    }
}
