//! How a frame is cut into bands of rows for the thread pool: the rows a
//! band holds, the bands a task takes, and an optional layer's bands.

use rayon::prelude::*;

/// The image rows rendered together: the rows a block of cone rays can
/// span (`march::CONE_BLOCK_ROWS`).
pub(super) const BAND_ROWS: usize = crate::march::CONE_BLOCK_ROWS;

/// Bands in one rayon task at most: one. Left to itself, rayon cuts an
/// indexed loop into a few runs of bands and a thread works through its run
/// in order, so a thread that runs out of work can take nothing from a
/// run another thread has begun, and a frame whose costly bands bunch
/// together ends on one thread.
pub(super) const BAND_TASKS: usize = 1;

/// Bands of `BAND_ROWS` rows of an optional layer for the parallel zip:
/// `Some(band)` per band when the layer is collected, `None` for each band
/// otherwise.
pub(super) fn optional_bands<T: Send>(
    layer: &mut [T],
    width: usize,
    height: usize,
) -> impl IndexedParallelIterator<Item = Option<&mut [T]>> {
    let rows: Vec<Option<&mut [T]>> = if layer.is_empty() {
        (0..height.div_ceil(BAND_ROWS)).map(|_| None).collect()
    } else {
        layer.chunks_mut(BAND_ROWS * width).map(Some).collect()
    };
    rows.into_par_iter()
}
