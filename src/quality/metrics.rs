//! Per-image measures of rendering noise, on 8-bit sRGB images as written to
//! PNG: the luma plane they are read through, speckles (isolated dots the
//! neighbours do not explain), pops (a pixel that changes from one frame to
//! the next far more than its neighbours do), and the mean squared error and
//! PSNR against a reference.
//!
//! Every count is an integer and every sum over pixels is exact (`u64`) or
//! taken in row order, so the numbers never depend on the thread count.

use image::RgbImage;
use rayon::prelude::*;

/// A speckle stands out from the median of its neighbours by more than
/// this, in 8-bit luma units…
pub const SPECKLE_CONTRAST: f64 = 60.0;
/// …while those neighbours span at most this (max − min): they agree, so
/// nothing around the pixel explains it.
pub const SPECKLE_NEIGHBOUR_SPREAD: f64 = 60.0;
/// A pop changes by more than this between two frames, in 8-bit luma units…
pub const POP_CHANGE: f64 = 40.0;
/// …and by more than this many times the mean change of its 8 neighbours.
pub const POP_NEIGHBOUR_RATIO: f64 = 4.0;

/// Rec. 709 luma weights (ITU-R BT.709-6, item 3.2), applied to the 8-bit
/// sRGB values as they are, not to linear light: the measure is of what
/// the file shows.
const LUMA_WEIGHTS: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// The offsets of a pixel's 8 neighbours.
const NEIGHBOURS: [(i64, i64); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

/// An image's values, row by row: luma 0.2126 R + 0.7152 G + 0.0722 B of
/// each pixel's 8-bit sRGB values (0 to 255).
#[derive(Clone, Debug)]
pub struct Luma {
    pub width: u32,
    pub height: u32,
    values: Vec<f64>,
}

impl Luma {
    pub fn of(img: &RgbImage) -> Luma {
        let values = img
            .pixels()
            .map(|p| {
                let [r, g, b] = p.0.map(f64::from);
                LUMA_WEIGHTS[0] * r + LUMA_WEIGHTS[1] * g + LUMA_WEIGHTS[2] * b
            })
            .collect();
        Luma {
            width: img.width(),
            height: img.height(),
            values,
        }
    }

    fn at(&self, x: i64, y: i64) -> f64 {
        self.values[(y * i64::from(self.width) + x) as usize]
    }

    /// The values of the 8 neighbours of interior pixel (`x`, `y`).
    fn neighbours(&self, x: i64, y: i64) -> [f64; 8] {
        NEIGHBOURS.map(|(dx, dy)| self.at(x + dx, y + dy))
    }

    /// How many interior pixels (not on the border, where the 8
    /// neighbours are all there) pass `test`, counted row by row in parallel.
    fn count_interior(&self, test: impl Fn(i64, i64) -> bool + Sync) -> u64 {
        if self.width < 3 || self.height < 3 {
            return 0;
        }
        let (width, height) = (i64::from(self.width), i64::from(self.height));
        (1..height - 1)
            .into_par_iter()
            .map(|y| (1..width - 1).filter(|&x| test(x, y)).count() as u64)
            .sum()
    }
}

/// Speckles in `img`: interior pixels whose value differs by more than 60
/// from the median of their 8 neighbours (the mean of the 4th and 5th
/// smallest), while those neighbours agree among themselves (max − min of
/// their values at most 60). An isolated dot that the neighbours do not
/// explain: unconverged samples, a firefly, a missed surface.
#[cfg(test)]
pub fn speckles(img: &RgbImage) -> u64 {
    speckles_in(&Luma::of(img))
}

/// `speckles` of an image already read as luma.
pub fn speckles_in(luma: &Luma) -> u64 {
    luma.count_interior(|x, y| is_speckle(luma.at(x, y), luma.neighbours(x, y)))
}

fn is_speckle(value: f64, mut neighbours: [f64; 8]) -> bool {
    // Most pixels of a detailed frame fail on the spread: no sort for them.
    let low = neighbours.iter().copied().fold(f64::INFINITY, f64::min);
    let high = neighbours.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if high - low > SPECKLE_NEIGHBOUR_SPREAD {
        return false;
    }
    neighbours.sort_by(f64::total_cmp);
    let median = (neighbours[3] + neighbours[4]) / 2.0;
    (value - median).abs() > SPECKLE_CONTRAST
}

/// Pops from `prev` to `next`, two frames of one size: interior pixels
/// whose value changes by more than 40 between them, and by more than 4×
/// the mean change (in absolute value) of their 8 neighbours. A dot that
/// flashes on or off while the picture around it holds still or moves
/// smoothly; a whole frame brightening is no pop.
///
/// # Panics
/// If the two frames differ in size (`measure` checks that first).
#[cfg(test)]
pub fn pops(prev: &RgbImage, next: &RgbImage) -> u64 {
    pops_between(&Luma::of(prev), &Luma::of(next))
}

/// `pops` between two images already read as luma.
///
/// # Panics
/// If the two differ in size.
pub fn pops_between(prev: &Luma, next: &Luma) -> u64 {
    assert!(
        (prev.width, prev.height) == (next.width, next.height),
        "pops between frames of one size"
    );
    let change = |x: i64, y: i64| (next.at(x, y) - prev.at(x, y)).abs();
    prev.count_interior(|x, y| {
        let own = change(x, y);
        let around: f64 = NEIGHBOURS
            .iter()
            .map(|(dx, dy)| change(x + dx, y + dy))
            .sum();
        own > POP_CHANGE && own > POP_NEIGHBOUR_RATIO * around / 8.0
    })
}

/// Mean squared error between `a` and `b`, two images of one size, over
/// the three channels of every pixel, in 8-bit units² (every channel one
/// off: 1). The sum is exact, in integers.
///
/// # Panics
/// If the two differ in size.
pub fn mse(a: &RgbImage, b: &RgbImage) -> f64 {
    assert!(
        a.dimensions() == b.dimensions(),
        "mse of images of one size"
    );
    let squared: u64 = (a.as_raw().par_chunks(3 * a.width().max(1) as usize))
        .zip(b.as_raw().par_chunks(3 * b.width().max(1) as usize))
        .map(|(ra, rb)| {
            ra.iter()
                .zip(rb)
                .map(|(&p, &q)| u64::from(p.abs_diff(q)).pow(2))
                .sum::<u64>()
        })
        .sum();
    let samples = a.as_raw().len();
    if samples == 0 {
        return 0.0;
    }
    squared as f64 / samples as f64
}

/// Peak signal-to-noise ratio for a mean squared error in 8-bit units².
pub fn psnr_db(mse: f64) -> f64 {
    crate::math::psnr_db(mse, 255.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    fn grey(width: u32, height: u32, v: u8) -> RgbImage {
        RgbImage::from_pixel(width, height, Rgb([v, v, v]))
    }

    /// Grey 50 and 150 alternating like a chessboard.
    fn checkerboard(width: u32, height: u32) -> RgbImage {
        RgbImage::from_fn(width, height, |x, y| {
            let v = if (x + y) % 2 == 0 { 50 } else { 150 };
            Rgb([v, v, v])
        })
    }

    fn with_dot(mut img: RgbImage, x: u32, y: u32, v: u8) -> RgbImage {
        img.put_pixel(x, y, Rgb([v, v, v]));
        img
    }

    #[test]
    fn luma_weighs_the_channels_by_rec_709() {
        let img = RgbImage::from_fn(3, 1, |x, _| {
            let mut p = [0u8; 3];
            p[x as usize] = 100;
            Rgb(p)
        });
        let luma = Luma::of(&img);
        assert!((luma.at(0, 0) - 21.26).abs() < 1e-9);
        assert!((luma.at(1, 0) - 71.52).abs() < 1e-9);
        assert!((luma.at(2, 0) - 7.22).abs() < 1e-9);
    }

    #[test]
    fn a_flat_image_has_no_speckles() {
        assert_eq!(speckles(&grey(9, 7, 100)), 0);
    }

    #[test]
    fn one_bright_dot_on_flat_grey_is_one_speckle() {
        assert_eq!(speckles(&with_dot(grey(9, 7, 100), 4, 3, 200)), 1);
        // A dark one counts as well.
        assert_eq!(speckles(&with_dot(grey(9, 7, 100), 4, 3, 0)), 1);
    }

    #[test]
    fn a_dot_of_50_is_no_speckle() {
        assert_eq!(speckles(&with_dot(grey(9, 7, 100), 4, 3, 150)), 0);
    }

    #[test]
    fn a_dot_on_a_noisy_background_is_no_speckle() {
        // Its neighbours span 50 to 150: they disagree, so explain nothing.
        assert_eq!(speckles(&checkerboard(9, 7)), 0);
        assert_eq!(speckles(&with_dot(checkerboard(9, 7), 4, 3, 250)), 0);
    }

    #[test]
    fn a_dot_on_the_border_is_not_counted() {
        for (x, y) in [(0, 3), (8, 3), (4, 0), (4, 6), (0, 0), (8, 6)] {
            assert_eq!(speckles(&with_dot(grey(9, 7, 100), x, y, 200)), 0);
        }
    }

    #[test]
    fn two_apart_dots_are_two_speckles_and_images_too_small_have_none() {
        let img = with_dot(with_dot(grey(12, 7, 100), 2, 2, 200), 8, 4, 200);
        assert_eq!(speckles(&img), 2);
        assert_eq!(speckles(&grey(2, 2, 100)), 0);
        assert_eq!(speckles(&grey(0, 0, 100)), 0);
    }

    #[test]
    fn a_pixel_that_changes_alone_by_100_is_one_pop() {
        let prev = grey(9, 7, 100);
        assert_eq!(pops(&prev, &with_dot(prev.clone(), 4, 3, 200)), 1);
        assert_eq!(pops(&with_dot(prev.clone(), 4, 3, 200), &prev), 1);
    }

    #[test]
    fn a_whole_frame_brightening_by_100_has_no_pops() {
        assert_eq!(pops(&grey(9, 7, 50), &grey(9, 7, 150)), 0);
    }

    #[test]
    fn a_change_of_30_is_no_pop() {
        let prev = grey(9, 7, 100);
        assert_eq!(pops(&prev, &with_dot(prev.clone(), 4, 3, 130)), 0);
    }

    #[test]
    fn a_change_not_4_times_its_neighbours_is_no_pop() {
        // The pixel changes by 100, its 8 neighbours by 50: mean 50, 4× is 200.
        let prev = grey(9, 7, 100);
        let mut next = grey(9, 7, 100);
        for y in 2..=4 {
            for x in 3..=5 {
                next.put_pixel(x, y, Rgb([150, 150, 150]));
            }
        }
        next.put_pixel(4, 3, Rgb([200, 200, 200]));
        assert_eq!(pops(&prev, &next), 0);
    }

    #[test]
    fn mse_and_psnr_of_known_differences() {
        let a = grey(4, 3, 100);
        assert_eq!(mse(&a, &a), 0.0);
        assert_eq!(psnr_db(mse(&a, &a)), f64::INFINITY);
        // Every channel one off: mse 1, 20·log10(255) = 48.1308 dB.
        let b = grey(4, 3, 101);
        assert_eq!(mse(&a, &b), 1.0);
        assert!((psnr_db(1.0) - 48.1308).abs() < 1e-4);
        // One channel of one pixel 12 off: 144 over 36 samples.
        let mut c = a.clone();
        c.put_pixel(1, 1, Rgb([112, 100, 100]));
        assert_eq!(mse(&a, &c), 4.0);
        // 255² / 4 is 16256.25: 42.11 dB.
        assert!((psnr_db(4.0) - 42.1102).abs() < 1e-4);
    }
}
