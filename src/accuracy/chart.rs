//! The accuracy chart: error against cost on log axes, one panel for mean
//! depth error and one for image RMSE, drawn to answer "which setting
//! should I use". Each panel draws its Pareto front (`front_of`, median
//! time) as a step line and names those points beside them; the other
//! variants are small grey dots, left to the table. The scene's own
//! settings are ringed, the `recommended` setting starred, and variants
//! `flagged` for overshoot ringed in red. A key of
//! four lines says so. The reference is the yardstick and is not plotted.

mod axis;
mod place;

use super::{
    flagged, front_of, recommended, Measurement, OVERSHOOT_FLAG, TIMING_NOISE, VISIBLE_PSNR_DB,
};
use crate::error::{Error, Result};
use axis::{decade_values, log_range, log_ticks, step_path, tick_label, MANTISSAS};
use place::{place_labels, Rect, LABEL_GAP};
use plotters::coord::combinators::{LogCoord, WithKeyPoints};
use plotters::prelude::*;
use std::path::Path;

/// The PNG's size in pixels.
pub const CHART_SIZE: (u32, u32) = (1600, 900);
/// Height of the title and the two panels; the key fills the rest below.
const PANELS_HEIGHT: u32 = 796;
/// Errors below these are drawn at them: a zero has no place on a log axis.
pub const DEPTH_FLOOR_PX: f64 = 0.01;
pub const RMSE_FLOOR: f64 = 1e-4;
/// Text sizes in pixels. Even, because plotters 0.3.7 puts each glyph at
/// `(size / 2 + top) as i32`, which at odd sizes rounds short glyphs up
/// and tall ones down: the decimal point floats a pixel above the digits.
const TITLE_SIZE: u32 = 22;
const CAPTION_SIZE: u32 = 18;
const TEXT_SIZE: u32 = 14;
const KEY_LINE: i32 = 24;
/// Marks: a front point, a dominated one, the scene's ring, the star.
const FRONT_RADIUS: i32 = 5;
const DOMINATED_RADIUS: i32 = 3;
const SCENE_RADIUS: i32 = 12;
const STAR_RADIUS: i32 = 14;
const FRONT: RGBColor = RGBColor(31, 119, 180);
const DOMINATED: RGBColor = RGBColor(175, 175, 175);
const STAR: RGBColor = RGBColor(0, 160, 70);
const STAR_TEXT: RGBColor = RGBColor(0, 110, 45);
const FLAG: RGBColor = RGBColor(220, 0, 0);

/// Where things landed, for the tests.
#[derive(Debug, Default)]
#[cfg_attr(not(test), allow(dead_code))]
struct Geometry {
    /// Each panel's plotting area, its points (every variant, in `rows`
    /// order less the reference) and its labels with their rows' indices.
    plots: Vec<Rect>,
    points: Vec<Vec<(i32, i32)>>,
    labels: Vec<Vec<(usize, Rect)>>,
    /// The key below the panels and each of its lines.
    key: Rect,
    key_lines: Vec<Rect>,
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

/// What a variant is to the chart, which decides its mark and label.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Role {
    Recommended,
    Scene,
    Front,
    Dominated,
}

impl Role {
    fn radius(self) -> i32 {
        match self {
            Role::Recommended => STAR_RADIUS,
            Role::Scene => SCENE_RADIUS,
            Role::Front => FRONT_RADIUS,
            Role::Dominated => DOMINATED_RADIUS,
        }
    }
}

/// How far outside its dot a red ring is drawn, and its width.
const FLAG_RING: (i32, u32) = (2, 2);

/// How far a variant's mark reaches from its point, its red ring included.
fn mark_radius(role: Role, r: &Measurement) -> i32 {
    let ring = match role {
        Role::Front | Role::Dominated if flagged(r) => FLAG_RING.0 + FLAG_RING.1 as i32 / 2,
        _ => 0,
    };
    role.radius() + ring
}

/// Each row's role in a panel whose front is `on_front`: the recommended
/// setting and the scene's own are named wherever they fall.
fn roles(rows: &[Measurement], on_front: &[bool], pick: Option<usize>) -> Vec<Role> {
    rows.iter()
        .enumerate()
        .map(|(i, r)| {
            if Some(i) == pick {
                Role::Recommended
            } else if r.knob == "scene" {
                Role::Scene
            } else if on_front[i] {
                Role::Front
            } else {
                Role::Dominated
            }
        })
        .collect()
}

/// A variant's name on the chart: its knob and setting, without the
/// setting's note in brackets, which the table keeps.
fn label_text(r: &Measurement) -> String {
    if r.knob == "scene" {
        return "scene's own settings".into();
    }
    let setting = match r.setting.split_once(" (") {
        Some((head, _)) => head,
        None => &r.setting,
    };
    format!("{} {setting}", r.knob)
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

fn text<E: std::fmt::Display>(e: E) -> String {
    e.to_string()
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

fn font(size: u32) -> TextStyle<'static> {
    (crate::output::font::FAMILY, size)
        .into_font()
        .color(&BLACK)
}

/// The points of a five-pointed star of outer radius `r` around `(x, y)`.
fn star_points((x, y): (i32, i32), r: i32) -> Vec<(i32, i32)> {
    (0..10)
        .map(|k| {
            let radius = if k % 2 == 0 {
                r as f64
            } else {
                0.45 * r as f64
            };
            let angle = std::f64::consts::PI * (k as f64 / 5.0 - 0.5);
            (
                x + (radius * angle.cos()).round() as i32,
                y + (radius * angle.sin()).round() as i32,
            )
        })
        .collect()
}

/// A variant's mark: a star under the recommended one, a ring round the
/// scene's, a dot (grey and small when dominated), a red ring when flagged.
fn draw_marker(
    root: &Area,
    p: (i32, i32),
    role: Role,
    flag: bool,
) -> std::result::Result<(), String> {
    match role {
        Role::Recommended => root
            .draw(&Polygon::new(star_points(p, STAR_RADIUS), STAR.filled()))
            .map_err(text)?,
        Role::Scene => root
            .draw(&Circle::new(p, SCENE_RADIUS, BLACK.stroke_width(2)))
            .map_err(text)?,
        Role::Front | Role::Dominated => {}
    }
    let (radius, fill) = match role {
        Role::Dominated => (DOMINATED_RADIUS, DOMINATED),
        _ => (FRONT_RADIUS, FRONT),
    };
    root.draw(&Circle::new(p, radius, fill.filled()))
        .map_err(text)?;
    if flag {
        let (gap, width) = FLAG_RING;
        root.draw(&Circle::new(p, radius + gap, FLAG.stroke_width(width)))
            .map_err(text)?;
    }
    Ok(())
}

fn draw(rows: &[Measurement], title: &str) -> std::result::Result<(Vec<u8>, Geometry), String> {
    crate::output::font::register()?;
    let (w, h) = CHART_SIZE;
    let mut pixels = vec![255u8; (w * h * 3) as usize];
    let mut geometry = Geometry::default();
    let pick = recommended(rows);
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(text)?;
        let (top, _) = root.split_vertically(PANELS_HEIGHT);
        let top = top.titled(title, font(TITLE_SIZE)).map_err(text)?;
        for (area, panel) in top.split_evenly((1, 2)).iter().zip(&PANELS) {
            let (plot, points, labels) = draw_panel(&root, area, panel, rows, pick)?;
            geometry.plots.push(plot);
            geometry.points.push(points);
            geometry.labels.push(labels);
        }
        geometry.key = Rect::sized(
            0,
            PANELS_HEIGHT as i32,
            w as i32,
            (h - PANELS_HEIGHT) as i32,
        );
        geometry.key_lines = draw_key(&root, geometry.key, rows, pick)?;
        root.present().map_err(text)?;
    }
    Ok((pixels, geometry))
}

/// One panel: its axes, the Pareto front as a step line, the points and
/// the labels of the front, the scene and the recommended setting; returns
/// the plotting area, the points and the labels with their rows.
#[allow(clippy::type_complexity)]
fn draw_panel(
    root: &Area,
    area: &Area,
    panel: &Panel,
    rows: &[Measurement],
    pick: Option<usize>,
) -> std::result::Result<(Rect, Vec<(i32, i32)>, Vec<(usize, Rect)>), String> {
    let plotted: Vec<usize> = (0..rows.len())
        .filter(|&i| rows[i].knob != "reference")
        .collect();
    let at = |i: usize| (rows[i].seconds, (panel.error)(&rows[i]).max(panel.floor));
    let (xs, ys): (Vec<f64>, Vec<f64>) = plotted.iter().map(|&i| at(i)).unzip();
    let chart = draw_axes(area, panel, &xs, &ys)?;
    let (xr, yr) = chart.plotting_area().get_pixel_range();
    let plot = Rect {
        x0: xr.start,
        y0: yr.start,
        x1: xr.end,
        y1: yr.end,
    };
    // Every row's pixel, the reference's too (never drawn), so rows index it.
    let pixels: Vec<(i32, i32)> = (0..rows.len())
        .map(|i| chart.backend_coord(&at(i)))
        .collect();
    let points: Vec<(i32, i32)> = plotted.iter().map(|&i| pixels[i]).collect();
    let on_front = front_of(rows, panel.error);
    let front: Vec<(f64, f64)> = plotted
        .iter()
        .filter(|&&i| on_front[i])
        .map(|&i| at(i))
        .collect();
    let path: Vec<(i32, i32)> = step_path(&front)
        .iter()
        .map(|p| chart.backend_coord(p))
        .collect();
    let marks = Marks {
        rows,
        plotted: &plotted,
        pixels: &pixels,
        role: roles(rows, &on_front, pick),
    };
    let labels = draw_marks(root, &marks, path, plot)?;
    Ok((plot, points, labels))
}

/// A panel's variants as drawn: every row's pixel and role, and which rows
/// are plotted.
struct Marks<'a> {
    rows: &'a [Measurement],
    plotted: &'a [usize],
    pixels: &'a [(i32, i32)],
    role: Vec<Role>,
}

/// The front's step line `path`, every plotted variant's mark, and the
/// labels of the named ones; returns the labels with their rows.
fn draw_marks(
    root: &Area,
    marks: &Marks,
    path: Vec<(i32, i32)>,
    plot: Rect,
) -> std::result::Result<Vec<(usize, Rect)>, String> {
    let Marks {
        rows,
        plotted,
        pixels,
        role,
    } = marks;
    // Dominated points first, so the named ones are drawn over them, and
    // red rings over the plain dots of their kind.
    let mut order = plotted.to_vec();
    order.sort_by_key(|&i| (role[i] != Role::Dominated, flagged(&rows[i])));
    let mut obstacles: Vec<Rect> = path
        .windows(2)
        .map(|s| Rect::spanning(s[0], s[1], 1))
        .collect();
    root.draw(&PathElement::new(path, BLACK.stroke_width(2)))
        .map_err(text)?;
    for i in order {
        draw_marker(root, pixels[i], role[i], flagged(&rows[i]))?;
        obstacles.push(Rect::around(pixels[i], mark_radius(role[i], &rows[i])));
    }
    let named: Vec<(usize, (i32, i32))> = named_in_order(rows, plotted, role)
        .into_iter()
        .map(|i| (i, pixels[i]))
        .collect();
    draw_labels(root, rows, &named, role, &obstacles, plot)
}

/// The panel's two log axes over every value, with their grid and labels.
type LogAxes = Cartesian2d<WithKeyPoints<LogCoord<f64>>, WithKeyPoints<LogCoord<f64>>>;

/// Draws a panel's caption, axes, grid and tick labels around `xs`, `ys`.
fn draw_axes<'a, 'b>(
    area: &'a Area<'b>,
    panel: &Panel,
    xs: &[f64],
    ys: &[f64],
) -> std::result::Result<ChartContext<'a, BitMapBackend<'b>, LogAxes>, String> {
    let (x0, x1) = log_range(xs);
    let (y0, y1) = log_range(ys);
    let light = |lo, hi| decade_values(lo, hi, MANTISSAS[3]);
    let mut chart = ChartBuilder::on(area)
        .caption(panel.title, font(CAPTION_SIZE))
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
        .label_style(font(TEXT_SIZE))
        .axis_desc_style(font(TEXT_SIZE))
        .bold_line_style(BLACK.mix(0.2))
        .light_line_style(BLACK.mix(0.07))
        .draw()
        .map_err(text)?;
    Ok(chart)
}

/// The rows a panel names, in the order their labels are placed: the
/// recommended setting, the scene's own, then the front from cheap to dear.
fn named_in_order(rows: &[Measurement], plotted: &[usize], role: &[Role]) -> Vec<usize> {
    let mut named: Vec<usize> = plotted
        .iter()
        .copied()
        .filter(|&i| role[i] != Role::Dominated)
        .collect();
    named.sort_by(|&a, &b| {
        let rank = |i: usize| match role[i] {
            Role::Recommended => 0,
            Role::Scene => 1,
            _ => 2,
        };
        rank(a)
            .cmp(&rank(b))
            .then(rows[a].seconds.total_cmp(&rows[b].seconds))
    });
    named
}

/// Each named row's label on a white ground beside its point, or where
/// `place_labels` found room, with a leader line back to the point;
/// returns where the labels went.
fn draw_labels(
    root: &Area,
    rows: &[Measurement],
    named: &[(usize, (i32, i32))],
    role: &[Role],
    obstacles: &[Rect],
    plot: Rect,
) -> std::result::Result<Vec<(usize, Rect)>, String> {
    let words: Vec<String> = named
        .iter()
        .map(|&(i, _)| match role[i] {
            Role::Recommended => format!("recommended: {}", label_text(&rows[i])),
            _ => label_text(&rows[i]),
        })
        .collect();
    let sizes = words
        .iter()
        .map(|w| {
            let (width, _) = root.estimate_text_size(w, &font(TEXT_SIZE)).map_err(text)?;
            Ok((width as i32 + 4, TEXT_SIZE as i32))
        })
        .collect::<std::result::Result<Vec<_>, String>>()?;
    let anchors: Vec<((i32, i32), i32)> = named
        .iter()
        .map(|&(i, p)| (p, mark_radius(role[i], &rows[i])))
        .collect();
    let spots = place_labels(&anchors, &sizes, obstacles, plot);
    let mut placed = Vec::new();
    for ((&(i, p), words), spot) in named.iter().zip(words).zip(spots) {
        let Some(spot) = spot else { continue };
        if spot.nearest(p) != p
            && !Rect::around(p, mark_radius(role[i], &rows[i]) + LABEL_GAP + 2).overlaps(&spot)
        {
            root.draw(&PathElement::new(vec![p, spot.nearest(p)], BLACK.mix(0.4)))
                .map_err(text)?;
        }
        root.draw(&Rectangle::new(
            [(spot.x0, spot.y0), (spot.x1 - 1, spot.y1 - 1)],
            WHITE.mix(0.85).filled(),
        ))
        .map_err(text)?;
        let colour = if role[i] == Role::Recommended {
            STAR_TEXT
        } else {
            BLACK
        };
        // The font's ink starts two pixels above where its text is put.
        root.draw(&Text::new(
            words,
            (spot.x0 + 2, spot.y0 + 3),
            font(TEXT_SIZE).color(&colour),
        ))
        .map_err(text)?;
        placed.push((i, spot));
    }
    Ok(placed)
}

/// What a key entry shows before its words.
#[derive(Clone, Copy)]
enum KeyMark {
    Point(Role, bool),
    Step,
    Nothing,
}

/// The key's lines: the recommendation, then what each mark means.
fn key_lines(rows: &[Measurement], pick: Option<usize>) -> Vec<Vec<(KeyMark, String)>> {
    let percent = |share: f64| format!("{}%", tick_label(100.0 * share));
    vec![
        vec![(KeyMark::Point(Role::Recommended, false), advice(rows, pick))],
        vec![(KeyMark::Nothing, star_rule())],
        vec![
            (KeyMark::Step, format!("Pareto front, named: the cheapest setting for its error (times within {} are one cost)", percent(TIMING_NOISE - 1.0))),
            (KeyMark::Point(Role::Dominated, false), "grey: matched or beaten at no more cost (in the table)".into()),
        ],
        vec![
            (KeyMark::Point(Role::Scene, false), "the scene's own settings".into()),
            (
                KeyMark::Point(Role::Front, true),
                format!("red ring: {}", flag_rule()),
            ),
            (KeyMark::Nothing, "errors of 0 drawn at the floor; reference not plotted".into()),
        ],
    ]
}

/// The recommended setting `pick` (`recommended`) against the scene's own,
/// in words, as the key and the table's report give it.
pub fn advice(rows: &[Measurement], pick: Option<usize>) -> String {
    let scene = rows.iter().find(|r| r.knob == "scene");
    match (pick, scene) {
        (Some(i), Some(s)) if rows[i].knob == "scene" => format!(
            "recommended: the scene's own settings ({:.3} s, PSNR {:.1} dB)",
            s.seconds, s.psnr_db
        ),
        (Some(i), Some(s)) => format!(
            "recommended: {} ({:.3} s, {:.2}x the scene's time; PSNR {:.1} dB, the scene's {:.1} dB)",
            label_text(&rows[i]),
            rows[i].seconds,
            rows[i].seconds / s.seconds.max(1e-9),
            rows[i].psnr_db,
            s.psnr_db
        ),
        (Some(i), None) => format!("recommended: {}", label_text(&rows[i])),
        (None, _) if rows.iter().any(|r| r.knob != "reference" && !r.psnr_db.is_nan()) => {
            "no recommendation: every variant has a red ring".into()
        }
        (None, _) => "no recommendation: no variant has a measured image error".into(),
    }
}

/// What a red ring marks, in words.
pub fn flag_rule() -> String {
    format!(
        "overshoot on {}% of pixels or more",
        tick_label(100.0 * OVERSHOOT_FLAG)
    )
}

/// How the star is chosen, in words.
pub fn star_rule() -> String {
    format!(
        "the star: of the variants without a red ring, the cheapest whose image is within {VISIBLE_PSNR_DB} dB PSNR of the best"
    )
}

/// Draws the key's lines below the panels; returns where each went.
fn draw_key(
    root: &Area,
    key: Rect,
    rows: &[Measurement],
    pick: Option<usize>,
) -> std::result::Result<Vec<Rect>, String> {
    let style = font(TEXT_SIZE);
    let mut placed = Vec::new();
    for (n, line) in key_lines(rows, pick).into_iter().enumerate() {
        let y = key.y0 + 4 + n as i32 * KEY_LINE;
        let mut x = key.x0 + 20;
        for (mark, words) in line {
            let centre = (x + STAR_RADIUS, y + KEY_LINE / 2);
            match mark {
                KeyMark::Point(role, flag) => draw_marker(root, centre, role, flag)?,
                KeyMark::Step => root
                    .draw(&PathElement::new(
                        vec![
                            (x, centre.1 - 6),
                            (x + 14, centre.1 - 6),
                            (x + 14, centre.1 + 6),
                            (x + 28, centre.1 + 6),
                        ],
                        BLACK.stroke_width(2),
                    ))
                    .map_err(text)?,
                KeyMark::Nothing => {}
            }
            let indent = match mark {
                KeyMark::Nothing => 0,
                _ => 2 * STAR_RADIUS + 8,
            };
            let colour = match mark {
                KeyMark::Point(Role::Recommended, _) => STAR_TEXT,
                _ => BLACK,
            };
            let (width, _) = root.estimate_text_size(&words, &style).map_err(text)?;
            root.draw(&Text::new(words, (x + indent, y + 7), style.color(&colour)))
                .map_err(text)?;
            x += indent + width as i32 + 36;
        }
        placed.push(Rect::sized(key.x0 + 20, y, x - 36 - key.x0 - 20, KEY_LINE));
    }
    Ok(placed)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The lowest row of dark ink of `words` drawn at `size`.
    fn ink_bottom(words: &str, size: u32) -> i32 {
        crate::output::font::register().unwrap();
        let (w, h) = (60usize, 60usize);
        let mut pixels = vec![255u8; w * h * 3];
        {
            let root =
                BitMapBackend::with_buffer(&mut pixels, (w as u32, h as u32)).into_drawing_area();
            root.draw(&Text::new(words, (5, 20), font(size))).unwrap();
        }
        let dark = |x: usize, y: usize| pixels[3 * (y * w + x)] < 128;
        (0..h)
            .filter(|&y| (0..w).any(|x| dark(x, y)))
            .max()
            .unwrap() as i32
    }

    #[test]
    fn the_decimal_point_sits_on_the_baseline() {
        // '1' stands flat on the baseline, as '.' does.
        for size in [TITLE_SIZE, CAPTION_SIZE, TEXT_SIZE] {
            assert_eq!(ink_bottom(".", size), ink_bottom("1", size), "size {size}");
        }
    }

    #[test]
    fn labels_drop_the_settings_note() {
        let r = row("adaptive", "noise 0.04 (at most 16 spp)", 1.0, 1.0, 0.1);
        assert_eq!(label_text(&r), "adaptive noise 0.04");
        let r = row("hit_threshold", "0.125", 1.0, 1.0, 0.1);
        assert_eq!(label_text(&r), "hit_threshold 0.125");
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
            psnr_db: crate::math::psnr_db_of_rmse(rmse, 1.0),
            surface_distance_px: None,
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
                33.0 - 0.1 * i as f64,
                0.16 + 0.001 * i as f64,
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
                plot.x1 - plot.x0 > 500 && plot.y1 - plot.y0 > 500,
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
            for (i, (_, spot)) in g.labels[panel].iter().enumerate() {
                assert!(plot.contains(spot), "panel {panel}: label {spot:?}");
                assert!(!g.labels[panel][i + 1..]
                    .iter()
                    .any(|(_, s)| s.overlaps(spot)));
            }
            assert!(!g.key.overlaps(plot));
        }
        assert!(image.contains(&g.key));
        // The overshooting variant is ringed in red in both panels; without it, no red.
        for plot in &g.plots {
            assert!(flag_pixels(&pixels, plot) > 20);
        }
        let (clean, g) = draw(&sweep(false), "test").unwrap();
        for plot in &g.plots {
            assert_eq!(flag_pixels(&clean, plot), 0);
        }
    }

    #[test]
    fn only_the_front_the_scene_and_the_recommended_are_named() {
        let rows = sweep(false);
        let pick = recommended(&rows).expect("nothing is flagged");
        // The zero-error variant: the best image by far.
        assert_eq!(rows[pick].knob, "samples_per_pixel");
        let (_, g) = draw(&rows, "test").unwrap();
        for (panel, labels) in PANELS.iter().zip(&g.labels) {
            let on_front = front_of(&rows, panel.error);
            let mut named: Vec<usize> = labels.iter().map(|&(i, _)| i).collect();
            named.sort();
            let expected: Vec<usize> = (0..rows.len())
                .filter(|&i| on_front[i] || rows[i].knob == "scene" || i == pick)
                .collect();
            assert_eq!(named, expected, "{}", panel.title);
            // Far fewer than the variants: the pile is one front point at most.
            assert!(named.len() < rows.len() / 2, "{named:?}");
        }
    }

    #[test]
    fn the_key_is_four_lines_whatever_the_variants() {
        for rows in [sweep(false), sweep(false)[..3].to_vec()] {
            let (_, g) = draw(&rows, "test").unwrap();
            assert_eq!(g.key_lines.len(), 4);
            for (i, line) in g.key_lines.iter().enumerate() {
                assert!(g.key.contains(line), "{line:?} outside {:?}", g.key);
                assert!(!g.key_lines[i + 1..].iter().any(|l| l.overlaps(line)));
            }
        }
    }
}
