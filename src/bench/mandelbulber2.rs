//! Depth error against the accuracy reference: mandelreel's frame, and
//! Mandelbulber2's z-buffer read back and fitted to absolute depths.

use super::options::{log, Options};
use super::rows::Row;
use super::scenes::BenchScene;
use crate::error::Error;
use crate::error::Result;
use crate::math::Real;
use crate::timeline::Timeline;
use std::path::Path;
use std::process::Command;

/// What Mandelbulber2 writes for a pixel whose ray met nothing.
const MANDELBULBER_NO_HIT: u16 = u16::MAX;

/// Mandelbulber2's 16-bit z-buffer (`<name>_zbuffer.png`) as values in 0..1
/// (its log(z / z_min) / log(z_max / z_min)), `None` where its ray missed.
/// The file keeps no z_min or z_max, so absolute depths need `fit_log_depths`.
fn read_mandelbulber_zbuffer(path: &Path) -> Result<(u32, u32, Vec<Option<f64>>)> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let bad = |why: String| Error::Image {
        path: path.to_path_buf(),
        message: why,
    };
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .map_err(|e| bad(e.to_string()))?;
    let info = reader.info();
    if info.color_type != png::ColorType::Grayscale || info.bit_depth != png::BitDepth::Sixteen {
        return Err(bad("not a 16-bit greyscale z-buffer".into()));
    }
    let (w, h) = (info.width, info.height);
    let mut bytes = vec![0; reader.output_buffer_size().unwrap_or(0)];
    reader
        .next_frame(&mut bytes)
        .map_err(|e| bad(e.to_string()))?;
    let values = bytes
        .chunks_exact(2)
        .map(|b| u16::from_be_bytes([b[0], b[1]]))
        .map(|v| (v != MANDELBULBER_NO_HIT).then_some(v as f64 / 60000.0))
        .collect();
    Ok((w, h, values))
}

/// Absolute depths for Mandelbulber2's log-scaled z-buffer values: the
/// least-squares line ln(depth) = a + b·value through the pixels where it
/// and the reference both hit. The most favourable scaling there is, so the
/// error left over is a lower bound on Mandelbulber2's. `cos` per pixel turns
/// distance along the ray into distance along the view axis (all 1 for
/// distances along the ray); the fit is made in that measure and the result
/// given along the ray. Returns the depths and the fit's mean squared residual.
fn fit_log_depths(
    values: &[Option<f64>],
    reference: &[Option<Real>],
    cos: &[Real],
) -> (Vec<Option<Real>>, f64) {
    let pairs: Vec<(f64, f64)> = values
        .iter()
        .zip(reference)
        .zip(cos)
        .filter_map(|((v, r), c)| Some((v.as_ref()?, r.as_ref()?, c)))
        .map(|(&v, &r, &c)| (v, (r * c).ln()))
        // A hit at distance 0 (a camera inside the set) has no logarithm.
        .filter(|(v, l)| v.is_finite() && l.is_finite())
        .collect();
    let n = pairs.len().max(1) as f64;
    let (mx, my) = pairs
        .iter()
        .fold((0.0, 0.0), |(x, y), (v, l)| (x + v / n, y + l / n));
    let (sxy, sxx) = pairs.iter().fold((0.0, 0.0), |(xy, xx), (v, l)| {
        (xy + (v - mx) * (l - my), xx + (v - mx) * (v - mx))
    });
    let b = if sxx > 0.0 { sxy / sxx } else { 0.0 };
    let a = my - b * mx;
    let residual = pairs
        .iter()
        .map(|(v, l)| (a + b * v - l).powi(2))
        .sum::<f64>()
        / n;
    let depths = values
        .iter()
        .zip(cos)
        .map(|(v, c)| v.map(|v| (a + b * v).exp() / c))
        .collect();
    (depths, residual)
}

/// The membership walk step whose depth error `bench` reports.
const WALK_STEP: Real = 0.25;

/// Depth rows for the first scene at `size`: mandelreel's frame, and
/// Mandelbulber2's z-buffer where it is installed, against the membership
/// reference of the accuracy sweep.
pub(super) fn depth_rows(
    scene: &BenchScene,
    timeline: &Timeline,
    options: &Options,
    (w, h): (u32, u32),
    out: &Path,
    base: Row,
) -> Result<Vec<Row>> {
    use crate::accuracy::{depth_errors, film_hits, footprints_at, reference_depths};
    let frame = timeline.scene_at(0);
    let reference_scene = crate::accuracy::reference_scene(&frame);
    let (reference, _) = reference_depths(&reference_scene, w, h, crate::accuracy::REFERENCE_STEP);
    let footprints = footprints_at(&frame, w, h, &reference);
    let row = |renderer: &str, e: crate::accuracy::DepthErrors| Row {
        scene: format!("{} depth@{w}x{h}", scene.name),
        renderer: renderer.into(),
        frames: 1,
        pixels: w as u64 * h as u64,
        depth_error_mean_px: Some(e.mean_px),
        depth_error_p99_px: Some(e.p99_px),
        hit_mismatch: Some(e.hit_mismatch),
        ..base.clone()
    };
    let film = crate::render::render_frame(&frame, 0, w, h, &|| {});
    let hits = film_hits(&film);
    // The same fit as Mandelbulber2's gets (a line through ln depth is a
    // line through its log-scaled values), to compare like with like.
    let ln_hits: Vec<Option<f64>> = hits.iter().map(|t| t.map(f64::ln)).collect();
    let (fitted, _) = fit_log_depths(&ln_hits, &reference, &vec![1.0; hits.len()]);
    let mut rows = vec![
        row("mandelreel", depth_errors(&hits, &reference, &footprints)),
        row(
            "mandelreel (fitted)",
            depth_errors(&fitted, &reference, &footprints),
        ),
    ];
    // The membership walk, for its error beside the estimate's (its cost
    // is in `mandelreel accuracy`'s table).
    let mut walking = frame.clone();
    walking.quality.membership_step = WALK_STEP;
    let walked = film_hits(&crate::render::render_frame(&walking, 0, w, h, &|| {}));
    rows.push(row(
        &format!("mandelreel (membership_step {WALK_STEP})"),
        depth_errors(&walked, &reference, &footprints),
    ));
    let (Some(program), Some(fract)) = (&options.mandelbulber, &scene.fract) else {
        return Ok(rows);
    };
    let status = Command::new(program)
        .args(["-n", "-C", "-f", "png", "-r", &format!("{w}x{h}"), "-o"])
        .arg(out.join("depth"))
        .args(["-O", "opencl_enabled=0#zbuffer_enabled=1"])
        .arg(fract)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .status()
        .map_err(|e| Error::io(program, e))?;
    let zbuffer = out.join("depth_zbuffer.png");
    if !status.success() || !zbuffer.exists() {
        log(
            options.quiet,
            "depth: Mandelbulber2 wrote no z-buffer; its depth row is left out",
        );
        return Ok(rows);
    }
    let (zw, zh, values) = match read_mandelbulber_zbuffer(&zbuffer) {
        Ok(read) => read,
        Err(e) => {
            log(
                options.quiet,
                &format!("depth: {e}; Mandelbulber2's depth row is left out"),
            );
            return Ok(rows);
        }
    };
    if (zw, zh) != (w, h) {
        log(
            options.quiet,
            &format!("depth: Mandelbulber2's z-buffer is {zw}x{zh}, not {w}x{h}"),
        );
        return Ok(rows);
    }
    // Its z may be distance along the ray or along the view axis: fit both,
    // keep the one that fits better.
    let camera = frame.camera.frame();
    let along_axis: Vec<Real> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            camera
                .ray(x as Real + 0.5, y as Real + 0.5, w, h)
                .dir
                .dot(camera.forward)
        })
        .collect();
    let along_ray = vec![1.0; along_axis.len()];
    let (ray_fit, ray_residual) = fit_log_depths(&values, &reference, &along_ray);
    let (axis_fit, axis_residual) = fit_log_depths(&values, &reference, &along_axis);
    let depths = if axis_residual < ray_residual {
        axis_fit
    } else {
        ray_fit
    };
    rows.push(row(
        "mandelbulber2 (fitted)",
        depth_errors(&depths, &reference, &footprints),
    ));
    Ok(rows)
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mandelbulber_zbuffer_fits_back_to_its_depths() {
        // Depths written as Mandelbulber2 writes them (log-scaled between
        // their minimum and maximum, ×60000, 65535 for a miss) come back
        // through the fit to within the 16-bit steps; a wrong scale would not.
        let truth: Vec<Option<Real>> = (0..64)
            .map(|i| (i % 7 != 3).then(|| 1.3 + 0.9 * ((i * 37 % 64) as Real / 63.0)))
            .collect();
        let (lo, hi) = (1.3_f64, 2.2_f64);
        let words: Vec<u16> = truth
            .iter()
            .map(|t| match t {
                Some(z) => ((z / lo).ln() / (hi / lo).ln() * 60000.0) as u16,
                None => MANDELBULBER_NO_HIT,
            })
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x_zbuffer.png");
        let mut encoder = png::Encoder::new(std::fs::File::create(&path).unwrap(), 8, 8);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Sixteen);
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_be_bytes()).collect();
        let mut writer = encoder.write_header().unwrap();
        writer.write_image_data(&bytes).unwrap();
        writer.finish().unwrap();
        let (w, h, values) = read_mandelbulber_zbuffer(&path).unwrap();
        assert_eq!((w, h), (8, 8));
        assert_eq!(values.iter().filter(|v| v.is_none()).count(), 9);
        let ones = vec![1.0; 64];
        let (depths, residual) = fit_log_depths(&values, &truth, &ones);
        assert!(residual < 1e-8, "{residual}");
        for (d, t) in depths.iter().zip(&truth) {
            match (d, t) {
                (Some(d), Some(t)) => assert!((d / t - 1.0).abs() < 1e-4, "{d} vs {t}"),
                (None, None) => {}
                _ => panic!("hit and miss differ"),
            }
        }
        // Measured along the view axis, the right cosines fit as well and
        // give back distances along the ray.
        let cos: Vec<Real> = (0..64).map(|i| 0.8 + 0.003 * i as Real).collect();
        let axial: Vec<Option<f64>> = truth
            .iter()
            .zip(&cos)
            .map(|(t, c)| {
                t.map(|t| ((t * c / lo).ln() / (hi / lo).ln() * 60000.0).floor() / 60000.0)
            })
            .collect();
        let (depths, residual) = fit_log_depths(&axial, &truth, &cos);
        assert!(residual < 1e-8, "{residual}");
        let (_, wrong) = fit_log_depths(&axial, &truth, &ones);
        assert!(wrong > 100.0 * residual, "{wrong} vs {residual}");
        for (d, t) in depths
            .iter()
            .zip(&truth)
            .filter_map(|(d, t)| Some((d.as_ref()?, t.as_ref()?)))
        {
            assert!((d / t - 1.0).abs() < 1e-4, "{d} vs {t}");
        }
    }
}
