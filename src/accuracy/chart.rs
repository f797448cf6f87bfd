//! The accuracy chart: error against cost on log axes, one panel for mean
//! depth error and one for image RMSE. Every variant is numbered beside its
//! point and named in a key below the panels; the scene's own settings are
//! ringed; variants that overshoot or disagree with the reference on
//! hit/miss are outlined in red; each panel draws its Pareto front
//! (`front_of`, median time) as a step line. The reference is the
//! yardstick and is not plotted.

use super::{front_of, Measurement, TIMING_NOISE};
use crate::error::{Error, Result};
use plotters::prelude::*;
use std::path::Path;

/// The PNG's size in pixels.
pub const CHART_SIZE: (u32, u32) = (1600, 1000);
/// Height of the title and the two panels; the key fills the rest below.
const PANELS_HEIGHT: u32 = 640;
/// Errors below these are drawn at them: a zero has no place on a log axis.
pub const DEPTH_FLOOR_PX: f64 = 0.01;
pub const RMSE_FLOOR: f64 = 1e-4;
/// A share of pixels changing hit/miss worth a red outline (0.1%).
const MISMATCH_NOTE: f64 = 0.001;
const POINT_RADIUS: i32 = 5;
const KEY_LINE: i32 = 17;
/// One colour per knob, in the order knobs first appear; red marks flags.
const KNOB_COLOURS: [RGBColor; 12] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
    RGBColor(57, 59, 121),
    RGBColor(0, 100, 0),
    RGBColor(205, 133, 63),
];
const FLAG: RGBColor = RGBColor(220, 0, 0);

/// A pixel rectangle, `[x0, x1) × [y0, y1)`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Rect {
    x0: i32,
    y0: i32,
    x1: i32,
    y1: i32,
}

impl Rect {
    fn sized(x0: i32, y0: i32, w: i32, h: i32) -> Rect {
        Rect {
            x0,
            y0,
            x1: x0 + w,
            y1: y0 + h,
        }
    }
    fn around((x, y): (i32, i32), r: i32) -> Rect {
        Rect::sized(x - r, y - r, 2 * r + 1, 2 * r + 1)
    }
    fn contains(&self, o: &Rect) -> bool {
        o.x0 >= self.x0 && o.y0 >= self.y0 && o.x1 <= self.x1 && o.y1 <= self.y1
    }
    #[cfg(test)]
    fn contains_point(&self, (x, y): (i32, i32)) -> bool {
        x >= self.x0 && x < self.x1 && y >= self.y0 && y < self.y1
    }
    fn overlaps(&self, o: &Rect) -> bool {
        self.x0 < o.x1 && o.x0 < self.x1 && self.y0 < o.y1 && o.y0 < self.y1
    }
    /// `o` moved the least distance to lie inside (its top-left corner
    /// inside where `o` is larger).
    fn clamp(&self, o: Rect) -> Rect {
        let (w, h) = (o.x1 - o.x0, o.y1 - o.y0);
        let x0 = o.x0.min(self.x1 - w).max(self.x0);
        let y0 = o.y0.min(self.y1 - h).max(self.y0);
        Rect::sized(x0, y0, w, h)
    }
    /// The point of the rectangle nearest to `p`.
    fn nearest(&self, (x, y): (i32, i32)) -> (i32, i32) {
        (x.clamp(self.x0, self.x1 - 1), y.clamp(self.y0, self.y1 - 1))
    }
}

/// Where things landed, for the tests.
#[derive(Debug, Default)]
#[cfg_attr(not(test), allow(dead_code))]
struct Geometry {
    /// Each panel's plotting area, its points and its point labels.
    plots: Vec<Rect>,
    points: Vec<Vec<(i32, i32)>>,
    labels: Vec<Vec<Rect>>,
    /// The key below the panels and each of its entries.
    key: Rect,
    key_entries: Vec<Rect>,
}

/// One panel: which error against cost.
struct Panel {
    title: &'static str,
    axis: &'static str,
    floor: f64,
    error: fn(&Measurement) -> f64,
}

const PANELS: [Panel; 2] = [
    Panel {
        title: "Depth error against cost",
        axis: "mean depth error (pixel footprints; 0 drawn at 0.01)",
        floor: DEPTH_FLOOR_PX,
        error: |r| r.depth_error_mean_px,
    },
    Panel {
        title: "Image error against cost",
        axis: "image RMSE vs reference (sRGB; 0 drawn at 1e-4)",
        floor: RMSE_FLOOR,
        error: |r| r.image_rmse,
    },
];

/// Worth a red outline: marched through the surface, or disagrees with the
/// reference on hit/miss for a noticeable share of pixels.
fn flagged(r: &Measurement) -> bool {
    r.overshoot > 0.0 || r.hit_mismatch >= MISMATCH_NOTE
}

/// The range of a log axis holding every value with a margin, at least
/// half a decade wide.
fn log_range(values: &[f64]) -> (f64, f64) {
    let positive = values.iter().copied().filter(|v| v.is_finite() && *v > 0.0);
    let lo = positive.clone().fold(f64::INFINITY, f64::min);
    let hi = positive.fold(0.0, f64::max);
    if !lo.is_finite() || hi <= 0.0 {
        return (1e-3, 1.0);
    }
    let (lo, hi) = (lo / 1.6, hi * 1.6);
    let mid = (lo * hi).sqrt();
    let half = 3f64.sqrt();
    (lo.min(mid / half), hi.max(mid * half))
}

/// Mantissas of log-axis ticks, from coarse to fine.
const MANTISSAS: [&[f64]; 5] = [
    &[1.0],
    &[1.0, 3.0],
    &[1.0, 2.0, 5.0],
    &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0],
    &[
        1.0, 1.2, 1.4, 1.6, 1.8, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 6.0, 7.0, 8.0, 9.0,
    ],
];

/// Values m × 10^k in `[lo, hi]` for the mantissas `m`, ascending.
fn decade_values(lo: f64, hi: f64, mantissas: &[f64]) -> Vec<f64> {
    let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    (k0..=k1)
        .flat_map(|k| mantissas.iter().map(move |m| m * 10f64.powi(k)))
        .filter(|&v| v >= lo * (1.0 - 1e-9) && v <= hi * (1.0 + 1e-9))
        .collect()
}

/// Labelled ticks of a log axis over `[lo, hi]`: the coarsest of 1, 1-3,
/// 1-2-5, 1…9 per decade that gives at least five, thinned to `most`.
fn log_ticks(lo: f64, hi: f64, most: usize) -> Vec<f64> {
    let mut ticks = Vec::new();
    for mantissas in MANTISSAS {
        ticks = decade_values(lo, hi, mantissas);
        if ticks.len() >= 5 {
            break;
        }
    }
    let step = ticks.len().div_ceil(most.max(1)).max(1);
    ticks.into_iter().step_by(step).collect()
}

/// A tick value in few characters: `0.002`, `1.5`, `20`, `1e-4`.
fn tick_label(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 {
        return "0".into();
    }
    let trim = |s: String| {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    };
    if (1e-3..1e5).contains(&a) {
        let decimals = (2 - a.log10().floor() as i32).max(0) as usize;
        trim(format!("{v:.decimals$}"))
    } else {
        let s = format!("{v:.2e}");
        let (mantissa, exponent) = s.split_once('e').expect("{:e} writes an exponent");
        format!("{}e{exponent}", trim(mantissa.to_string()))
    }
}

/// The staircase through a front's points: from each point along to the
/// next one's cost, then down to its error.
fn step_path(front: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut points = front.to_vec();
    points.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut path = Vec::with_capacity(2 * points.len());
    for (i, &(x, y)) in points.iter().enumerate() {
        if i > 0 {
            path.push((x, path.last().map_or(y, |p: &(f64, f64)| p.1)));
        }
        path.push((x, y));
    }
    path
}

/// Places a label of each size beside its point inside `plot`: the first
/// spot, in rings of eight directions further and further out, that
/// covers no point and no label placed before it; failing that, the spot
/// with the fewest clashes.
fn place_labels(points: &[(i32, i32)], sizes: &[(i32, i32)], plot: Rect) -> Vec<Rect> {
    let disks: Vec<Rect> = points
        .iter()
        .map(|&p| Rect::around(p, POINT_RADIUS))
        .collect();
    let mut placed: Vec<Rect> = Vec::with_capacity(points.len());
    for (&(x, y), &(w, h)) in points.iter().zip(sizes) {
        let mut best: Option<(usize, Rect)> = None;
        'search: for ring in 0..10 {
            let gap = POINT_RADIUS + 2 + 8 * ring;
            for (dx, dy) in [
                (1, 0),
                (-1, 0),
                (0, -1),
                (0, 1),
                (1, -1),
                (-1, -1),
                (1, 1),
                (-1, 1),
            ] {
                let x0 = match dx {
                    1 => x + gap,
                    -1 => x - gap - w,
                    _ => x - w / 2,
                };
                let y0 = match dy {
                    -1 => y - gap - h,
                    1 => y + gap,
                    _ => y - h / 2,
                };
                let spot = Rect::sized(x0, y0, w, h);
                if !plot.contains(&spot) {
                    continue;
                }
                let clashes = placed
                    .iter()
                    .chain(&disks)
                    .filter(|r| r.overlaps(&spot))
                    .count();
                if best.is_none_or(|(c, _)| clashes < c) {
                    best = Some((clashes, spot));
                }
                if clashes == 0 {
                    break 'search;
                }
            }
        }
        let spot = best.map_or_else(
            || plot.clamp(Rect::sized(x + POINT_RADIUS + 2, y - h / 2, w, h)),
            |(_, spot)| spot,
        );
        placed.push(spot);
    }
    placed
}

/// Draws the chart (see the module's comment) and writes it as a PNG of
/// `CHART_SIZE`.
pub fn write_chart(rows: &[Measurement], title: &str, path: &Path) -> Result<()> {
    let chart_error = |message: String| Error::Image {
        path: path.to_path_buf(),
        message,
    };
    let (pixels, _) = draw(rows, title).map_err(chart_error)?;
    let (w, h) = CHART_SIZE;
    let image = image::RgbImage::from_raw(w, h, pixels).expect("buffer matches the chart size");
    crate::output::atomic::write_atomic(path, |w, _| {
        image
            .write_to(w, image::ImageFormat::Png)
            .map_err(|e| chart_error(e.to_string()))
    })
}

/// A variant's marker: a dot in its knob's colour, a red outline when
/// `flag`ged, a big ring for the scene's own settings.
fn marker(p: (i32, i32), fill: RGBColor, flag: bool, scene: bool) -> Vec<Circle<(i32, i32), i32>> {
    let mut circles = vec![Circle::new(p, POINT_RADIUS, fill.filled())];
    if flag {
        circles.push(Circle::new(p, POINT_RADIUS + 2, FLAG.stroke_width(2)));
    }
    if scene {
        circles.push(Circle::new(p, 2 * POINT_RADIUS + 2, BLACK.stroke_width(2)));
    }
    circles
}

fn text<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

/// Renders the chart into an RGB buffer of `CHART_SIZE`.
type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// What every part of the chart draws a variant with: the variants plotted
/// (every row but the reference, with its row index), their colours and labels.
struct Variants<'r> {
    rows: &'r [Measurement],
    plotted: Vec<(usize, &'r Measurement)>,
    colours: Vec<RGBColor>,
    labels: Vec<String>,
}

impl<'r> Variants<'r> {
    fn of(rows: &'r [Measurement]) -> Variants<'r> {
        let plotted: Vec<(usize, &Measurement)> = rows
            .iter()
            .enumerate()
            .filter(|(_, r)| r.knob != "reference")
            .collect();
        let mut knobs: Vec<&str> = Vec::new();
        for (_, r) in &plotted {
            if r.knob != "scene" && !knobs.contains(&r.knob) {
                knobs.push(r.knob);
            }
        }
        let colours = plotted
            .iter()
            .map(|(_, r)| {
                knobs
                    .iter()
                    .position(|k| *k == r.knob)
                    .map_or(BLACK, |i| KNOB_COLOURS[i % KNOB_COLOURS.len()])
            })
            .collect();
        // Numbered from 1 in table order (the scene is first).
        let labels = plotted
            .iter()
            .enumerate()
            .map(|(n, (_, r))| {
                if r.knob == "scene" {
                    format!("{} scene", n + 1)
                } else {
                    (n + 1).to_string()
                }
            })
            .collect();
        Variants {
            rows,
            plotted,
            colours,
            labels,
        }
    }
}

fn draw(rows: &[Measurement], title: &str) -> std::result::Result<(Vec<u8>, Geometry), String> {
    crate::output::font::register()?;
    let (w, h) = CHART_SIZE;
    let mut pixels = vec![255u8; (w * h * 3) as usize];
    let mut geometry = Geometry::default();
    let variants = Variants::of(rows);
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(text)?;
        let (top, _) = root.split_vertically(PANELS_HEIGHT);
        let top = top.titled(title, ("sans-serif", 22)).map_err(text)?;
        for (area, panel) in top.split_evenly((1, 2)).iter().zip(&PANELS) {
            let (plot, points, spots) = draw_panel(&root, area, panel, &variants)?;
            geometry.plots.push(plot);
            geometry.points.push(points);
            geometry.labels.push(spots);
        }
        geometry.key = Rect::sized(
            0,
            PANELS_HEIGHT as i32,
            w as i32,
            (h - PANELS_HEIGHT) as i32,
        );
        geometry.key_entries = draw_key(&root, geometry.key, &variants)?;
        root.present().map_err(text)?;
    }
    Ok((pixels, geometry))
}

/// One panel: its axes, the Pareto front as a step line, the points and
/// their labels; returns the plotting area, the points and the labels' spots.
#[allow(clippy::type_complexity)]
fn draw_panel(
    root: &Area,
    area: &Area,
    panel: &Panel,
    variants: &Variants,
) -> std::result::Result<(Rect, Vec<(i32, i32)>, Vec<Rect>), String> {
    let plotted = &variants.plotted;
    let xs: Vec<f64> = plotted.iter().map(|(_, r)| r.seconds).collect();
    let ys: Vec<f64> = plotted
        .iter()
        .map(|(_, r)| (panel.error)(r).max(panel.floor))
        .collect();
    let (x0, x1) = log_range(&xs);
    let (y0, y1) = log_range(&ys);
    let light = |lo, hi| decade_values(lo, hi, MANTISSAS[3]);
    let mut chart = ChartBuilder::on(area)
        .caption(panel.title, ("sans-serif", 17))
        .margin(10)
        .margin_right(28)
        .x_label_area_size(48)
        .y_label_area_size(80)
        .build_cartesian_2d(
            (x0..x1)
                .log_scale()
                .with_key_points(log_ticks(x0, x1, 9))
                .with_light_points(light(x0, x1)),
            (y0..y1)
                .log_scale()
                .with_key_points(log_ticks(y0, y1, 9))
                .with_light_points(light(y0, y1)),
        )
        .map_err(text)?;
    chart
        .configure_mesh()
        .x_desc("median wall time per frame (s)")
        .y_desc(panel.axis)
        .x_label_formatter(&|v| tick_label(*v))
        .y_label_formatter(&|v| tick_label(*v))
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 14))
        .bold_line_style(BLACK.mix(0.2))
        .light_line_style(BLACK.mix(0.07))
        .draw()
        .map_err(text)?;
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let plot = Rect {
        x0: xr.start,
        y0: yr.start,
        x1: xr.end,
        y1: yr.end,
    };
    let points: Vec<(i32, i32)> = xs
        .iter()
        .zip(&ys)
        .map(|(&x, &y)| chart.backend_coord(&(x, y)))
        .collect();

    // The front under the points.
    let on_front = front_of(variants.rows, panel.error);
    let front: Vec<(f64, f64)> = plotted
        .iter()
        .zip(xs.iter().zip(&ys))
        .filter(|((i, _), _)| on_front[*i])
        .map(|(_, (&x, &y))| (x, y))
        .collect();
    let path: Vec<(i32, i32)> = step_path(&front)
        .iter()
        .map(|p| chart.backend_coord(p))
        .collect();
    root.draw(&PathElement::new(path, BLACK.stroke_width(2)))
        .map_err(text)?;
    for (((_, r), &p), &fill) in plotted.iter().zip(&points).zip(&variants.colours) {
        for c in marker(p, fill, flagged(r), r.knob == "scene") {
            root.draw(&c).map_err(text)?;
        }
    }
    let spots = draw_labels(root, &points, &variants.labels, plot)?;
    Ok((plot, points, spots))
}

/// Each point's label beside it, where it overlaps nothing, with a leader
/// line where it had to move away; returns where the labels went.
fn draw_labels(
    root: &Area,
    points: &[(i32, i32)],
    labels: &[String],
    plot: Rect,
) -> std::result::Result<Vec<Rect>, String> {
    let label_font = ("sans-serif", 12).into_font().color(&BLACK);
    let sizes = labels
        .iter()
        .map(|l| {
            let (w, h) = root.estimate_text_size(l, &label_font).map_err(text)?;
            Ok((w as i32 + 1, h as i32))
        })
        .collect::<std::result::Result<Vec<_>, String>>()?;
    let spots = place_labels(points, &sizes, plot);
    for ((label, spot), &p) in labels.iter().zip(&spots).zip(points) {
        if !Rect::around(p, POINT_RADIUS + 3).overlaps(spot) {
            let leader = vec![p, spot.nearest(p)];
            root.draw(&PathElement::new(leader, BLACK.mix(0.35)))
                .map_err(text)?;
        }
        root.draw(&Text::new(
            label.clone(),
            (spot.x0, spot.y0),
            label_font.clone(),
        ))
        .map_err(text)?;
    }
    Ok(spots)
}

/// The key below both panels: what the marks mean, then every variant by
/// number; returns where each variant's entry went.
fn draw_key(root: &Area, key: Rect, variants: &Variants) -> std::result::Result<Vec<Rect>, String> {
    let key_font = ("sans-serif", 13).into_font().color(&BLACK);
    let mut y = key.y0 + 8;
    let mut x = 20;
    let legend = [
        (
            "colour: knob; number: the list below",
            KNOB_COLOURS[0],
            false,
            false,
        ),
        ("big ring: the scene's own settings", BLACK, false, true),
        (
            "red outline: overshoot > 0 or hit/miss differs on >= 0.1% of pixels",
            KNOB_COLOURS[0],
            true,
            false,
        ),
    ];
    for (words, fill, flag, scene) in legend {
        for c in marker((x + 12, y + 8), fill, flag, scene) {
            root.draw(&c).map_err(text)?;
        }
        root.draw(&Text::new(words, (x + 30, y), key_font.clone()))
            .map_err(text)?;
        x += 50 + root.estimate_text_size(words, &key_font).map_err(text)?.0 as i32;
    }
    y += 22;
    root.draw(&PathElement::new(
        vec![(20, y + 8), (44, y + 8), (44, y + 2)],
        BLACK.stroke_width(2),
    ))
    .map_err(text)?;
    let note = format!(
        "step line: Pareto front of median time against that panel's error (times within {:.0}% are one cost); \
         0 errors drawn at the floor; the reference is not plotted",
        100.0 * (TIMING_NOISE - 1.0)
    );
    root.draw(&Text::new(note, (50, y), key_font.clone()))
        .map_err(text)?;
    y += 30;
    draw_key_entries(root, key, y, variants, &key_font)
}

/// The numbered list of variants, in columns from `top` to the key's foot.
fn draw_key_entries(
    root: &Area,
    key: Rect,
    top: i32,
    variants: &Variants,
    key_font: &TextStyle,
) -> std::result::Result<Vec<Rect>, String> {
    let plotted = &variants.plotted;
    let rows_per_column = ((key.y1 - 6 - top) / KEY_LINE).max(1) as usize;
    let columns = plotted.len().div_ceil(rows_per_column).max(4);
    let column_width = (key.x1 - key.x0 - 20) / columns as i32;
    let char_width = root
        .estimate_text_size("0000000000", key_font)
        .map_err(text)?
        .0 as i32
        / 10;
    let fits = ((column_width - 28) / char_width.max(1)).max(4) as usize;
    let mut entries = Vec::new();
    for (n, ((_, r), &fill)) in plotted.iter().zip(&variants.colours).enumerate() {
        let (cx, cy) = (
            10 + (n / rows_per_column) as i32 * column_width,
            top + (n % rows_per_column) as i32 * KEY_LINE,
        );
        for c in marker((cx + 10, cy + 8), fill, flagged(r), false) {
            root.draw(&c).map_err(text)?;
        }
        let mut words = format!("{:>2} {} {}", n + 1, r.knob, r.setting);
        if flagged(r) {
            words += &format!(
                " (over {:.2}%, hit/miss {:.2}%)",
                100.0 * r.overshoot,
                100.0 * r.hit_mismatch
            );
        }
        if words.chars().count() > fits {
            words = words.chars().take(fits - 1).collect::<String>() + "~";
        }
        let style = if flagged(r) {
            key_font.clone().color(&FLAG)
        } else {
            key_font.clone()
        };
        let size = root.estimate_text_size(&words, &style).map_err(text)?;
        root.draw(&Text::new(words, (cx + 22, cy), style))
            .map_err(text)?;
        entries.push(Rect::sized(
            cx,
            cy,
            22 + size.0 as i32,
            KEY_LINE.max(size.1 as i32),
        ));
    }
    Ok(entries)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(ticks: &[f64]) -> Vec<String> {
        ticks.iter().map(|&v| tick_label(v)).collect()
    }

    #[test]
    fn log_ticks_give_several_labels_per_axis() {
        // Two decades: 1-2-5 is the coarsest set with at least five.
        assert_eq!(
            labels(&log_ticks(0.002, 0.09, 9)),
            ["0.002", "0.005", "0.01", "0.02", "0.05"]
        );
        // Under a decade: every integer mantissa.
        assert_eq!(
            labels(&log_ticks(0.0031, 0.0095, 9)),
            ["0.004", "0.005", "0.006", "0.007", "0.008", "0.009"]
        );
        // Sixteen decades: one per decade, thinned to the limit, still spanning.
        let wide = log_ticks(1e-8, 1e8, 6);
        assert!((4..=6).contains(&wide.len()), "{wide:?}");
        assert_eq!(tick_label(wide[0]), "1e-8");
        assert!(wide.last().is_some_and(|&v| v >= 1e6));
        for ticks in [log_ticks(0.002, 0.09, 9), wide] {
            assert!(ticks.windows(2).all(|w| w[0] < w[1]));
        }
    }

    #[test]
    fn log_range_holds_every_value_and_half_a_decade() {
        let (lo, hi) = log_range(&[0.004, 0.0041]);
        assert!(lo < 0.004 && hi > 0.0041 && hi / lo >= 3.0 - 1e-9);
        let (lo, hi) = log_range(&[1e-4, 0.3, 0.0]);
        assert!(lo < 1e-4 && hi > 0.3);
    }

    #[test]
    fn tick_labels_are_short() {
        let cases = [
            (0.002, "0.002"),
            (0.0015, "0.0015"),
            (1.5, "1.5"),
            (20.0, "20"),
            (0.1 + 0.2, "0.3"),
            (1e-4, "1e-4"),
            (2.5e-5, "2.5e-5"),
            (1e5, "1e5"),
        ];
        for (v, label) in cases {
            assert_eq!(tick_label(v), label, "{v}");
        }
    }

    #[test]
    fn step_path_goes_along_then_down() {
        assert_eq!(
            step_path(&[(2.0, 0.5), (1.0, 1.0), (4.0, 0.1)]),
            [(1.0, 1.0), (2.0, 1.0), (2.0, 0.5), (4.0, 0.5), (4.0, 0.1)]
        );
    }

    #[test]
    fn labels_stay_inside_the_plot_and_apart() {
        let plot = Rect::sized(100, 50, 400, 300);
        // Spread points, one in a corner: each label touches its own point's
        // neighbourhood and no other label or point.
        let spread = [(110, 55), (300, 200), (340, 200), (495, 345)];
        let spots = place_labels(&spread, &[(14, 12); 4], plot);
        for (spot, &p) in spots.iter().zip(&spread) {
            assert!(plot.contains(spot), "{spot:?}");
            assert!(
                Rect::around(p, POINT_RADIUS + 4).overlaps(spot),
                "{spot:?} far from {p:?}"
            );
            for &q in &spread {
                assert!(!Rect::around(q, POINT_RADIUS).overlaps(spot));
            }
        }
        // A pile of 24 points on one pixel: every label still inside, none on another.
        let pile = [(300, 200); 24];
        let spots = place_labels(&pile, &[(14, 12); 24], plot);
        for (i, a) in spots.iter().enumerate() {
            assert!(plot.contains(a));
            assert!(!spots[i + 1..].iter().any(|b| b.overlaps(a)), "{a:?}");
        }
    }

    fn row(knob: &'static str, setting: &str, seconds: f64, depth: f64, rmse: f64) -> Measurement {
        Measurement {
            knob,
            setting: setting.into(),
            seconds,
            de_evaluations: (seconds * 1e6) as u64,
            depth_error_mean_px: depth,
            depth_error_p99_px: depth,
            hit_mismatch: 0.0,
            overshoot: 0.0,
            image_rmse: rmse,
            psnr_db: 0.0,
            pareto: false,
        }
    }

    /// The sweep's shape: a reference, the scene, a pile of variants at
    /// the scene's cost and error, a zero-error one, and spread ones.
    fn sweep(flag: bool) -> Vec<Measurement> {
        let mut rows = vec![
            row("reference", "high", 6.0, 0.0, 0.0),
            row("scene", "as in the timeline", 0.004, 33.0, 0.16),
        ];
        for i in 0..20 {
            rows.push(row(
                "fudge",
                &format!("0.{i}"),
                0.004 + 1e-5 * i as f64,
                33.0,
                0.16,
            ));
        }
        rows.push(row("samples_per_pixel", "16", 0.065, 0.0, 0.0));
        for i in 1..20 {
            let t = 0.002 * 1.2f64.powi(i);
            rows.push(row(
                "de",
                &format!("v{i}"),
                t,
                40.0 / i as f64,
                0.2 / i as f64,
            ));
        }
        if flag {
            rows[5].overshoot = 0.01;
        }
        rows
    }

    fn flag_pixels(pixels: &[u8], area: &Rect) -> usize {
        let w = CHART_SIZE.0 as i32;
        (area.y0..area.y1)
            .flat_map(|y| (area.x0..area.x1).map(move |x| (3 * (y * w + x)) as usize))
            .filter(|&i| pixels[i..i + 3] == [FLAG.0, FLAG.1, FLAG.2])
            .count()
    }

    #[test]
    fn points_and_labels_inside_the_plots_key_outside() {
        let rows = sweep(true);
        let (pixels, g) = draw(&rows, "test").unwrap();
        let (w, h) = CHART_SIZE;
        assert_eq!(pixels.len(), (w * h * 3) as usize);
        let image = Rect::sized(0, 0, w as i32, h as i32);
        assert_eq!(g.plots.len(), 2);
        assert!(!g.plots[0].overlaps(&g.plots[1]));
        for (panel, plot) in g.plots.iter().enumerate() {
            assert!(
                plot.x1 - plot.x0 > 500 && plot.y1 - plot.y0 > 400,
                "{plot:?}"
            );
            // Every candidate, the zero-error one included; not the reference.
            assert_eq!(g.points[panel].len(), rows.len() - 1);
            for &p in &g.points[panel] {
                assert!(
                    plot.contains_point(p),
                    "panel {panel}: {p:?} outside {plot:?}"
                );
            }
            for spot in &g.labels[panel] {
                assert!(plot.contains(spot), "panel {panel}: label {spot:?}");
            }
            assert!(!g.key.overlaps(plot));
        }
        assert!(image.contains(&g.key));
        assert_eq!(g.key_entries.len(), rows.len() - 1);
        for (i, e) in g.key_entries.iter().enumerate() {
            assert!(g.key.contains(e), "{e:?}");
            assert!(!g.key_entries[i + 1..].iter().any(|f| f.overlaps(e)));
        }
        // The overshooting variant is outlined in red in both panels; without it, no red.
        for plot in &g.plots {
            assert!(flag_pixels(&pixels, plot) > 20);
        }
        let (clean, g) = draw(&sweep(false), "test").unwrap();
        for plot in &g.plots {
            assert_eq!(flag_pixels(&clean, plot), 0);
        }
    }
}
