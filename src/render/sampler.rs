//! Where each camera sample looks and when: its point in the pixel, the
//! instant of the shutter it sees, its point on the lens and its path's
//! random numbers, all from the stateless hash (`math::sample_1d`), so no
//! sample depends on the order samples are taken in.

use crate::math::{sample_1d, Real};
use crate::scene::Scene;

/// A camera sample's numbers: the jitter in its pixel, its point on the
/// lens; the path tracer takes the dimensions after these.
const JITTER: [u32; 2] = [0, 1];
const LENS: [u32; 2] = [2, 3];

/// Sample `s` of `n` of `pixel`: its offset in the pixel. Under adaptive
/// sampling, where a pixel may stop after any wave, every prefix of its
/// samples is stratified; otherwise the `n` samples are.
pub(super) fn offset(scene: &Scene, frame: u32, pixel: u64, s: u32, n: u32) -> (Real, Real) {
    match scene.adaptive {
        Some(_) if n > 1 => progressive_subpixel(scene, frame, pixel, s),
        _ => subpixel(scene, frame, pixel, s, n),
    }
}

/// Which of `instants` scenes (spread over the shutter) sample `s` sees.
pub(super) fn instant(scene: &Scene, s: u32, instants: usize) -> usize {
    match scene.adaptive {
        Some(_) => progressive_instant(s, instants),
        None => s as usize % instants,
    }
}

/// Sample `s`'s point on the lens, in the unit square.
pub(super) fn lens(scene: &Scene, frame: u32, pixel: u64, s: u32) -> (Real, Real) {
    let u = sample_1d(scene.seed, frame, pixel, s, LENS[0]);
    let v = sample_1d(scene.seed, frame, pixel, s, LENS[1]);
    (u, v)
}

/// Number `d` of sample `s`'s path (`shade::trace_paths` counts its own
/// dimensions from the first after the lens's).
pub(super) fn path_number(scene: &Scene, frame: u32, pixel: u64, s: u32, d: u32) -> Real {
    sample_1d(scene.seed, frame, pixel, s, d)
}

/// Sub-pixel offset of sample `s` of `n`: the centre for one sample; a
/// jittered point in cell `s` of a k×k grid when n = k²; otherwise stratified
/// in n rows with x uniform, which still covers the whole pixel evenly.
fn subpixel(scene: &Scene, frame: u32, pixel: u64, s: u32, n: u32) -> (Real, Real) {
    if n == 1 {
        return (0.5, 0.5);
    }
    let jx = sample_1d(scene.seed, frame, pixel, s, JITTER[0]);
    let jy = sample_1d(scene.seed, frame, pixel, s, JITTER[1]);
    let k = (n as Real).sqrt().round() as u32;
    if k * k == n {
        let (cx, cy) = (s % k, s / k);
        ((cx as Real + jx) / k as Real, (cy as Real + jy) / k as Real)
    } else {
        (jx, (s as Real + jy) / n as Real)
    }
}

/// Sub-pixel offset of sample `s` under adaptive sampling, where a pixel
/// may stop after any wave: an Owen-scrambled Sobol sequence (Burley,
/// "Practical Hash-based Owen Scrambling", JCGT 2020), scrambled by a hash
/// of the pixel. Its first 2^k samples are stratified as a (0, k, 2)-net:
/// the first 4 one to each quarter of the pixel, all 16 one to each cell
/// of a 4×4 grid, as a uniform 16 jitters them.
fn progressive_subpixel(scene: &Scene, frame: u32, pixel: u64, s: u32) -> (Real, Real) {
    let hash = sample_1d(scene.seed, frame, pixel, u32::MAX, 0);
    let seed = (hash * 4_294_967_296.0) as u32;
    let x = sobol_burley::sample(s, 0, seed);
    let y = sobol_burley::sample(s, 1, seed);
    (x as Real, y as Real)
}

/// The instant (of `instants`, spread over the shutter) that sample `s`
/// sees under adaptive sampling: a stride through them that is prime to
/// their count, near the golden section, so that a pixel's first samples
/// are spread over the shutter rather than bunched at its opening.
fn progressive_instant(s: u32, instants: usize) -> usize {
    let n = instants.max(1);
    let golden = (n as f64 * 0.618_033_988_749_895).round() as usize;
    let stride = (golden.max(1)..=n).find(|&k| gcd(k, n) == 1).unwrap_or(1);
    (s as usize * stride) % n
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::adaptive_scene as adaptive;

    #[test]
    fn subpixel_offsets_stay_in_the_pixel_and_cover_it() {
        let scene = Scene::default();
        assert_eq!(subpixel(&scene, 0, 0, 0, 1), (0.5, 0.5));
        let pts: Vec<_> = (0..4).map(|s| subpixel(&scene, 0, 9, s, 4)).collect();
        for &(x, y) in &pts {
            assert!((0.0..1.0).contains(&x) && (0.0..1.0).contains(&y));
        }
        // Three samples: one in each horizontal third, averaging over the whole pixel.
        let thirds: std::collections::HashSet<_> = (0..3)
            .map(|s| (subpixel(&scene, 0, 9, s, 3).1 * 3.0) as u8)
            .collect();
        assert_eq!(thirds.len(), 3);
        // Four samples: one in each quadrant of a 2×2 grid.
        let quadrants: std::collections::HashSet<_> = pts
            .iter()
            .map(|&(x, y)| ((x * 2.0) as u8, (y * 2.0) as u8))
            .collect();
        assert_eq!(quadrants.len(), 4);
    }

    #[test]
    fn every_first_power_of_two_samples_stratify_the_pixel() {
        // The first 2^k samples of every pixel tried put one sample in each
        // cell of every grid of 2^k cells (2^a by 2^(k-a)): the first 2 one in
        // each half, either way; the first 16 one in each cell of a 4×4 grid.
        let scene = adaptive(2, 64);
        for pixel in 0..500 {
            let points: Vec<_> = (0..64)
                .map(|s| progressive_subpixel(&scene, 7, pixel, s))
                .collect();
            assert!(points
                .iter()
                .all(|&(x, y)| (0.0..1.0).contains(&x) && (0.0..1.0).contains(&y)));
            for k in 1..=6u32 {
                for a in 0..=k {
                    let (cols, rows) = (1usize << a, 1usize << (k - a));
                    let mut cells = vec![0; cols * rows];
                    for &(x, y) in &points[..1 << k] {
                        let cell = (y * rows as Real) as usize * cols + (x * cols as Real) as usize;
                        cells[cell] += 1;
                    }
                    assert!(
                        cells.iter().all(|&c| c == 1),
                        "pixel {pixel}: {k} {a}: {cells:?}"
                    );
                }
            }
        }
        // Pixels do not share a pattern.
        let first = |pixel| progressive_subpixel(&scene, 7, pixel, 0);
        assert_ne!(first(1), first(2));
    }

    #[test]
    fn instants_are_all_seen_and_early_ones_spread_over_the_shutter() {
        for n in 1..50 {
            let mut seen: Vec<usize> = (0..n as u32).map(|s| progressive_instant(s, n)).collect();
            let first_four: Vec<usize> = seen.iter().take(4).copied().collect();
            seen.sort();
            assert_eq!(seen, (0..n).collect::<Vec<_>>(), "{n} instants");
            if n >= 8 {
                // The first four reach both halves of the shutter.
                assert!(first_four.iter().any(|&i| i < n / 2));
                assert!(first_four.iter().any(|&i| i >= n / 2));
            }
        }
    }
}
