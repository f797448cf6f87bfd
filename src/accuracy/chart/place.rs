//! Where the chart's point labels go: beside their point where there is
//! room, else at the nearest free spot (the chart draws a leader line to
//! it), never over another label, a point or the front's line.

/// A pixel rectangle, `[x0, x1) × [y0, y1)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(super) struct Rect {
    pub x0: i32,
    pub y0: i32,
    pub x1: i32,
    pub y1: i32,
}

impl Rect {
    pub fn sized(x0: i32, y0: i32, w: i32, h: i32) -> Rect {
        Rect {
            x0,
            y0,
            x1: x0 + w,
            y1: y0 + h,
        }
    }
    pub fn around((x, y): (i32, i32), r: i32) -> Rect {
        Rect::sized(x - r, y - r, 2 * r + 1, 2 * r + 1)
    }
    /// The smallest rectangle holding both corners (a line segment, `half`
    /// pixels wider on each side).
    pub fn spanning((ax, ay): (i32, i32), (bx, by): (i32, i32), half: i32) -> Rect {
        Rect {
            x0: ax.min(bx) - half,
            y0: ay.min(by) - half,
            x1: ax.max(bx) + half + 1,
            y1: ay.max(by) + half + 1,
        }
    }
    pub fn contains(&self, o: &Rect) -> bool {
        o.x0 >= self.x0 && o.y0 >= self.y0 && o.x1 <= self.x1 && o.y1 <= self.y1
    }
    #[cfg(test)]
    pub fn contains_point(&self, (x, y): (i32, i32)) -> bool {
        x >= self.x0 && x < self.x1 && y >= self.y0 && y < self.y1
    }
    pub fn overlaps(&self, o: &Rect) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }
    /// The point of the rectangle nearest to `p`.
    pub fn nearest(&self, (x, y): (i32, i32)) -> (i32, i32) {
        (x.clamp(self.x0, self.x1 - 1), y.clamp(self.y0, self.y1 - 1))
    }
    /// Squared distance from `p` to the rectangle.
    fn distance2(&self, p: (i32, i32)) -> i64 {
        let (nx, ny) = self.nearest(p);
        let (dx, dy) = ((nx - p.0) as i64, (ny - p.1) as i64);
        dx * dx + dy * dy
    }
    fn grown(&self, by: i32) -> Rect {
        Rect {
            x0: self.x0 - by,
            y0: self.y0 - by,
            x1: self.x1 + by,
            y1: self.y1 + by,
        }
    }
}

/// Pixels kept clear between a label and any point, line or other label.
pub(super) const LABEL_GAP: i32 = 4;
/// Spacing of the grid the fallback search tries.
const SEARCH_STEP: usize = 4;

/// The spots beside `p` tried first, in order: right, left, then below
/// and above, right of it, left of it and centred.
fn beside((x, y): (i32, i32), (w, h): (i32, i32), clear: i32) -> [Rect; 8] {
    let (right, left) = (x + clear, x - clear - w);
    let (below, above) = (y + clear, y - clear - h);
    [
        Rect::sized(right, y - h / 2, w, h),
        Rect::sized(left, y - h / 2, w, h),
        Rect::sized(right, below, w, h),
        Rect::sized(right, above, w, h),
        Rect::sized(left, below, w, h),
        Rect::sized(left, above, w, h),
        Rect::sized(x - w / 2, below, w, h),
        Rect::sized(x - w / 2, above, w, h),
    ]
}

/// How near (in pixels) a roomy spot found by the grid search must be to
/// be preferred to a crowded spot beside the point.
const ROOMY_REACH: i64 = 60;

/// Places a label of `sizes[i]` for each anchor `anchors[i]` (a point and
/// the radius of its mark, which is among the `obstacles`), in order,
/// inside `plot`, never over another label. Free: inside `plot` and at
/// least `LABEL_GAP` from every obstacle and every label placed before;
/// roomy: free and twice that from any other point's mark, so a label is
/// not read as a neighbour's. Tried in turn: a roomy spot beside the
/// point, the nearest roomy spot on a grid over the plot if within
/// `ROOMY_REACH`, a free spot beside the point, the nearest free one.
/// `None` where no spot is free.
pub(super) fn place_labels(
    anchors: &[((i32, i32), i32)],
    sizes: &[(i32, i32)],
    obstacles: &[Rect],
    plot: Rect,
) -> Vec<Option<Rect>> {
    let mut placed: Vec<Rect> = Vec::with_capacity(anchors.len());
    let mut spots = Vec::with_capacity(anchors.len());
    for (&(p, radius), &size) in anchors.iter().zip(sizes) {
        let own = Rect::around(p, radius);
        let clear = |spot: &Rect, margin: i32| {
            plot.contains(spot)
                && !obstacles.iter().any(|o| {
                    let margin = if *o == own { LABEL_GAP } else { margin };
                    o.grown(margin).overlaps(spot)
                })
                && !placed.iter().any(|l| l.grown(LABEL_GAP).overlaps(spot))
        };
        let free = |spot: &Rect| clear(spot, LABEL_GAP);
        let roomy = |spot: &Rect| clear(spot, 2 * LABEL_GAP);
        let near = beside(p, size, radius + LABEL_GAP + 1);
        let spot = near
            .iter()
            .copied()
            .find(roomy)
            .or_else(|| {
                nearest_free(p, size, plot, &roomy)
                    .filter(|s| s.distance2(p) <= ROOMY_REACH * ROOMY_REACH)
            })
            .or_else(|| near.iter().copied().find(free))
            .or_else(|| nearest_free(p, size, plot, &free));
        if let Some(spot) = spot {
            placed.push(spot);
        }
        spots.push(spot);
    }
    spots
}

/// The free spot of `size` nearest to `p` among those on a grid over `plot`.
fn nearest_free(
    p: (i32, i32),
    (w, h): (i32, i32),
    plot: Rect,
    free: &dyn Fn(&Rect) -> bool,
) -> Option<Rect> {
    let xs = (plot.x0..=plot.x1 - w).step_by(SEARCH_STEP);
    xs.flat_map(|x| {
        (plot.y0..=plot.y1 - h)
            .step_by(SEARCH_STEP)
            .map(move |y| Rect::sized(x, y, w, h))
    })
    .filter(|s| free(s))
    .min_by_key(|s| s.distance2(p))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// No two labels overlap, each is inside the plot and over no obstacle.
    fn assert_apart(spots: &[Option<Rect>], obstacles: &[Rect], plot: Rect) {
        let spots: Vec<Rect> = spots.iter().flatten().copied().collect();
        for (i, a) in spots.iter().enumerate() {
            assert!(plot.contains(a), "{a:?} outside {plot:?}");
            assert!(!obstacles.iter().any(|o| o.overlaps(a)), "{a:?}");
            assert!(!spots[i + 1..].iter().any(|b| b.overlaps(a)), "{a:?}");
        }
    }

    #[test]
    fn a_lone_label_sits_beside_its_point() {
        let plot = Rect::sized(100, 50, 400, 300);
        let spread = [((110, 55), 5), ((300, 200), 5), ((495, 345), 5)];
        let disks: Vec<Rect> = spread.iter().map(|&(p, r)| Rect::around(p, r)).collect();
        let spots = place_labels(&spread, &[(40, 14); 3], &disks, plot);
        assert_apart(&spots, &disks, plot);
        for (spot, &(p, r)) in spots.iter().zip(&spread) {
            let spot = spot.expect("room enough");
            // At most the clearance away on each axis (diagonal spots).
            assert!(
                spot.distance2(p) <= 2 * ((r + LABEL_GAP + 2) as i64).pow(2),
                "{spot:?} {p:?}"
            );
        }
    }

    #[test]
    fn a_pile_of_twenty_wide_labels_never_overlaps() {
        let plot = Rect::sized(100, 50, 700, 600);
        // Twenty points within 12×6 pixels, as the variants at the scene's
        // cost pile up, with labels as wide as "membership_step 0.125".
        let pile: Vec<((i32, i32), i32)> = (0..20)
            .map(|i| ((400 + i % 5 * 3, 300 + i / 5 * 2), 5))
            .collect();
        let disks: Vec<Rect> = pile.iter().map(|&(p, r)| Rect::around(p, r)).collect();
        let spots = place_labels(&pile, &[(170, 14); 20], &disks, plot);
        assert!(spots.iter().all(Option::is_some), "room for all: {spots:?}");
        assert_apart(&spots, &disks, plot);
        // The nearest free spots: all within a few label heights of the pile.
        for s in spots.iter().flatten() {
            assert!(s.distance2((400, 300)) < 200 * 200, "{s:?}");
        }
    }

    #[test]
    fn a_full_plot_leaves_labels_out_rather_than_overlap() {
        let plot = Rect::sized(0, 0, 100, 40);
        let anchors = [((50, 20), 3); 6];
        let spots = place_labels(&anchors, &[(60, 14); 6], &[], plot);
        assert!(spots.iter().any(Option::is_none));
        assert_apart(&spots, &[], plot);
    }
}
