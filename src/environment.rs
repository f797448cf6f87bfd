//! Image-based light: an equirectangular HDR environment map (OpenEXR or
//! Radiance .hdr) as the sky, with importance sampling of its bright regions
//! so a small sun-like highlight does not need thousands of samples.
//!
//! Directions use +y up; longitude 0 (the map's horizontal centre) looks
//! down −z, turned by `rotation_degrees` about +y.

use crate::error::{Error, Result};
use crate::math::{DVec3, Real, Vec3};
use std::collections::HashMap;
use std::f64::consts::PI;
use std::fs::File;
use std::io::{Seek, SeekFrom};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

/// A loaded map with the tables for sampling it in proportion to its light.
#[derive(Debug)]
pub struct EnvironmentMap {
    pub width: usize,
    pub height: usize,
    pub pixels: Vec<Vec3>,
    /// Cumulative weight of rows (marginal), then within each row (conditional).
    row_cdf: Vec<Real>,
    column_cdf: Vec<Real>,
    total: Real,
}

fn luminance(c: Vec3) -> Real {
    (0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z).max(0.0) as Real
}

impl EnvironmentMap {
    /// Builds the sampling tables for `pixels` (row-major from the top: +y).
    pub fn from_pixels(width: usize, height: usize, pixels: Vec<Vec3>) -> EnvironmentMap {
        let mut column_cdf = vec![0.0; width * height];
        let mut row_cdf = vec![0.0; height];
        let mut total = 0.0;
        for j in 0..height {
            // Rows near the poles cover less solid angle: weight by sin θ.
            let sin_theta = (PI * (j as Real + 0.5) / height as Real).sin();
            let mut row = 0.0;
            for i in 0..width {
                // A floor keeps every direction reachable (the estimator stays unbiased).
                row += (luminance(pixels[j * width + i]) + 1e-6) * sin_theta;
                column_cdf[j * width + i] = row;
            }
            total += row;
            row_cdf[j] = total;
        }
        EnvironmentMap {
            width,
            height,
            pixels,
            row_cdf,
            column_cdf,
            total,
        }
    }

    /// Reads an equirectangular map from an OpenEXR (.exr) or Radiance (.hdr)
    /// file: a regular file of at most `MAX_MAP_BYTES` and `MAX_MAP_PIXELS`.
    pub fn load(path: &Path) -> Result<EnvironmentMap> {
        EnvironmentMap::read(path, std::io::BufReader::new(open(path)?))
    }

    /// Decodes the map in `file` (named `path`), refusing one of more than
    /// `MAX_MAP_PIXELS` from its header, before its pixels are allocated.
    fn read(path: &Path, mut file: std::io::BufReader<File>) -> Result<EnvironmentMap> {
        let bad = |message: String| Error::Image {
            path: path.to_path_buf(),
            message,
        };
        let is_exr = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("exr"));
        if is_exr {
            use exr::prelude::*;
            let meta = exr::meta::MetaData::read_from_buffered(&mut file, false)
                .map_err(|e| bad(e.to_string()))?;
            for header in &meta.headers {
                check_size(header.layer_size.0, header.layer_size.1).map_err(bad)?;
            }
            // (exr's prelude has an `Error` of its own.)
            file.seek(SeekFrom::Start(0))
                .map_err(|e| crate::error::Error::io(path, e))?;
            let image = read()
                .no_deep_data()
                .largest_resolution_level()
                .rgba_channels(
                    |resolution, _| {
                        (
                            resolution.width(),
                            vec![Vec3::ZERO; resolution.width() * resolution.height()],
                        )
                    },
                    |(width, pixels): &mut (usize, Vec<Vec3>),
                     position,
                     (r, g, b, _a): (f32, f32, f32, f32)| {
                        pixels[position.y() * *width + position.x()] = Vec3::new(r, g, b);
                    },
                )
                .first_valid_layer()
                .all_attributes()
                .from_buffered(file)
                .map_err(|e| bad(e.to_string()))?;
            let (width, pixels) = image.layer_data.channel_data.pixels;
            let height = pixels.len() / width.max(1);
            Ok(EnvironmentMap::from_pixels(width, height, sanitise(pixels)))
        } else {
            use image::ImageDecoder as _;
            let mut reader = image::ImageReader::new(file);
            reader.set_format(image::ImageFormat::from_path(path).map_err(|e| bad(e.to_string()))?);
            let decoder = reader.into_decoder().map_err(|e| bad(e.to_string()))?;
            let (width, height) = decoder.dimensions();
            check_size(width as usize, height as usize).map_err(bad)?;
            let image = image::DynamicImage::from_decoder(decoder)
                .map_err(|e| bad(e.to_string()))?
                .into_rgb32f();
            let (width, height) = (image.width() as usize, image.height() as usize);
            // The decoded floats become the map's texels in place where
            // they can (a map at the limit is 100 MB a copy).
            let pixels = bytemuck::allocation::try_cast_vec(image.into_raw())
                .unwrap_or_else(|(_, raw)| raw.chunks_exact(3).map(Vec3::from_slice).collect());
            Ok(EnvironmentMap::from_pixels(width, height, sanitise(pixels)))
        }
    }

    /// Radiance arriving along `dir`.
    pub fn radiance(&self, dir: DVec3, rotation: Real) -> Vec3 {
        let (i, j) = self.texel(dir, rotation);
        self.pixels[j * self.width + i]
    }

    fn texel(&self, dir: DVec3, rotation: Real) -> (usize, usize) {
        let theta = dir.y.clamp(-1.0, 1.0).acos();
        let phi = (dir.x.atan2(-dir.z) - rotation).rem_euclid(2.0 * PI);
        let u = phi / (2.0 * PI);
        let v = theta / PI;
        (
            ((u * self.width as Real) as usize).min(self.width - 1),
            ((v * self.height as Real) as usize).min(self.height - 1),
        )
    }

    fn direction(&self, u: Real, v: Real, rotation: Real) -> DVec3 {
        let phi = u * 2.0 * PI + rotation;
        let theta = v * PI;
        DVec3::new(
            theta.sin() * phi.sin(),
            theta.cos(),
            -theta.sin() * phi.cos(),
        )
    }

    /// Density (per solid angle) with which `sample` picks `dir`.
    pub fn pdf(&self, dir: DVec3, rotation: Real) -> Real {
        let (i, j) = self.texel(dir, rotation);
        let previous = if i == 0 {
            0.0
        } else {
            self.column_cdf[j * self.width + i - 1]
        };
        let weight = self.column_cdf[j * self.width + i] - previous;
        let sin_theta = (PI * (j as Real + 0.5) / self.height as Real)
            .sin()
            .max(1e-9);
        (weight / self.total) * (self.width * self.height) as Real / (2.0 * PI * PI * sin_theta)
    }

    /// A direction drawn in proportion to the map's light, with its density.
    pub fn sample(&self, u: Real, v: Real, jitter: (Real, Real), rotation: Real) -> (DVec3, Real) {
        let row = self
            .row_cdf
            .partition_point(|&c| c < u * self.total)
            .min(self.height - 1);
        let start = if row == 0 { 0.0 } else { self.row_cdf[row - 1] };
        let row_weights = &self.column_cdf[row * self.width..(row + 1) * self.width];
        let target = v * (self.row_cdf[row] - start);
        let column = row_weights
            .partition_point(|&c| c < target)
            .min(self.width - 1);
        let dir = self.direction(
            (column as Real + jitter.0) / self.width as Real,
            (row as Real + jitter.1) / self.height as Real,
            rotation,
        );
        (dir, self.pdf(dir, rotation))
    }
}

/// Replaces non-finite or negative texels (some HDR files hold them) by black.
fn sanitise(pixels: Vec<Vec3>) -> Vec<Vec3> {
    pixels
        .into_iter()
        .map(|p| crate::math::finite_or_zero(p).max(Vec3::ZERO))
        .collect()
}

/// The most texels a map may have: 4096×2048, an equirectangular map a
/// texel to a 0.09° of longitude. Its texels and sampling tables take 20
/// bytes a texel (168 MB at the limit).
pub const MAX_MAP_PIXELS: usize = 4096 * 2048;

/// The longest map file read: a map at `MAX_MAP_PIXELS` as uncompressed
/// 32-bit RGBA OpenEXR is 134 MB.
pub const MAX_MAP_BYTES: u64 = 256 << 20;

/// A map's size refused when past `MAX_MAP_PIXELS` (or empty).
fn check_size(width: usize, height: usize) -> std::result::Result<(), String> {
    let pixels = (width as u64).saturating_mul(height as u64);
    if pixels == 0 || pixels > MAX_MAP_PIXELS as u64 {
        return Err(format!(
            "{width}x{height} texels; an environment map may have from 1 to {MAX_MAP_PIXELS} \
             (4096x2048): scale it down"
        ));
    }
    Ok(())
}

/// Opens a map file: a regular file (a FIFO is refused, not waited on) of
/// at most `MAX_MAP_BYTES`.
fn open(path: &Path) -> Result<File> {
    let file = crate::input::open_regular(path).map_err(|e| Error::io(path, e))?;
    let length = file.metadata().map_err(|e| Error::io(path, e))?.len();
    if length > MAX_MAP_BYTES {
        let message = format!(
            "{length} bytes, more than the {} an environment map may have",
            crate::input::bytes_shown(MAX_MAP_BYTES)
        );
        let cause = std::io::Error::new(std::io::ErrorKind::FileTooLarge, message);
        return Err(Error::io(path, cause));
    }
    Ok(file)
}

/// Loaded maps, by file and content digest.
type MapCache = Mutex<HashMap<(PathBuf, String), Arc<EnvironmentMap>>>;

fn cache() -> &'static MapCache {
    static CACHE: OnceLock<MapCache> = OnceLock::new();
    CACHE.get_or_init(Default::default)
}

/// Maps by file and content digest, loaded once per process.
pub fn cached(path: &Path, digest: &str) -> Result<Arc<EnvironmentMap>> {
    let key = (path.to_path_buf(), digest.to_string());
    if let Some(map) = cache()
        .lock()
        .expect("cache lock is never poisoned")
        .get(&key)
    {
        return Ok(map.clone());
    }
    let map = Arc::new(EnvironmentMap::load(path)?);
    cache()
        .lock()
        .expect("cache lock is never poisoned")
        .insert(key, map.clone());
    Ok(map)
}

/// The map at `path`, loaded and checked once per process, and the
/// SHA-256 of its bytes (frames re-render when it changes). The file is
/// opened once: the bytes hashed are the bytes decoded.
pub fn load_fingerprinted(path: &Path) -> Result<(String, Arc<EnvironmentMap>)> {
    use sha2::Digest as _;
    let mut file = open(path)?;
    let mut hasher = sha2::Sha256::new();
    std::io::copy(&mut file, &mut hasher).map_err(|e| Error::io(path, e))?;
    let digest: String = hasher
        .finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect();
    let key = (path.to_path_buf(), digest.clone());
    if let Some(map) = cache()
        .lock()
        .expect("cache lock is never poisoned")
        .get(&key)
    {
        return Ok((digest, map.clone()));
    }
    file.seek(SeekFrom::Start(0))
        .map_err(|e| Error::io(path, e))?;
    let map = Arc::new(EnvironmentMap::read(path, std::io::BufReader::new(file))?);
    cache()
        .lock()
        .expect("cache lock is never poisoned")
        .insert(key, map.clone());
    Ok((digest, map))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_map_past_the_texel_limit_is_refused_from_its_header() {
        // A 2×2 EXR whose header is made to say 4097×2048: refused from the
        // header, before any texel is allocated (reading first would take
        // 100 MB here, and as much as any header claims).
        use exr::prelude::*;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sky.exr");
        let pixels = SpecificChannels::rgba(|_| (0.5f32, 0.5f32, 0.5f32, 1.0f32));
        Image::from_channels((2, 2), pixels)
            .write()
            .to_file(&path)
            .unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        let name = b"dataWindow\0box2i\0";
        let at = bytes.windows(name.len()).position(|w| w == name).unwrap() + name.len() + 4;
        bytes[at + 8..at + 16].copy_from_slice(&[0, 16, 0, 0, 255, 7, 0, 0]);
        std::fs::write(&path, &bytes).unwrap();
        let e = EnvironmentMap::load(&path).unwrap_err().to_string();
        assert!(
            e.ends_with(
                "sky.exr: 4097x2048 texels; an environment map may have from 1 to \
                 8388608 (4096x2048): scale it down"
            ),
            "{e}"
        );
    }

    /// A dim sky with one small, very bright patch: the case importance sampling is for.
    fn spotlit() -> EnvironmentMap {
        let (w, h) = (64, 32);
        let mut pixels = vec![Vec3::splat(0.2); w * h];
        for j in 9..11 {
            for i in 40..42 {
                pixels[j * w + i] = Vec3::splat(500.0);
            }
        }
        EnvironmentMap::from_pixels(w, h, pixels)
    }

    /// A small EXR map whose header is changed to claim `width` columns
    /// of its 2048 rows: a damaged or hostile file, a few hundred bytes.
    fn claiming_exr(path: &Path, width: i32) {
        let white = |_, _| (1.0f32, 1.0f32, 1.0f32, 1.0f32);
        exr::prelude::write_rgba_file(path, 2, 2048, white).expect("write a map");
        let mut bytes = std::fs::read(path).expect("read it back");
        for name in [&b"dataWindow\0box2i\0"[..], b"displayWindow\0box2i\0"] {
            let found = bytes.windows(name.len()).position(|w| w == name);
            // Past the name, the type and the size: x min, y min, x max, y max.
            let at = found.expect("a window attribute") + name.len() + 4;
            bytes[at + 8..at + 12].copy_from_slice(&(width - 1).to_le_bytes());
        }
        std::fs::write(path, bytes).expect("write the map");
    }

    #[test]
    fn a_map_claiming_more_pixels_than_the_limit_is_refused_unread() {
        let dir = tempfile::tempdir().expect("temporary folder");
        let limit = "may have from 1 to 8388608 (4096x2048)";
        let exr = dir.path().join("vast.exr");
        claiming_exr(&exr, 4097);
        let message = EnvironmentMap::load(&exr).unwrap_err().to_string();
        assert!(
            message.contains("4097x2048 texels") && message.contains(limit),
            "{message}"
        );
        // At the limit the size passes, and the missing pixels fail.
        claiming_exr(&exr, 4096);
        let message = EnvironmentMap::load(&exr).unwrap_err().to_string();
        assert!(!message.contains(limit), "{message}");
        let hdr = dir.path().join("vast.hdr");
        std::fs::write(
            &hdr,
            "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2048 +X 4097\n",
        )
        .unwrap();
        let message = EnvironmentMap::load(&hdr).unwrap_err().to_string();
        assert!(
            message.contains("4097x2048 texels") && message.contains(limit),
            "{message}"
        );
    }

    #[test]
    fn directions_and_texels_agree() {
        let map = spotlit();
        for (u, v) in [(0.1, 0.2), (0.63, 0.3), (0.99, 0.9)] {
            let d = map.direction(u, v, 0.4);
            assert!((d.length() - 1.0).abs() < 1e-12);
            let (i, j) = map.texel(d, 0.4);
            assert_eq!((i, j), ((u * 64.0) as usize, (v * 32.0) as usize));
        }
    }

    #[test]
    fn importance_sampling_has_the_mean_of_uniform_sampling() {
        // ∫ L(ω) max(0, n·ω) dω over the sphere, two ways.
        let map = spotlit();
        let n = DVec3::new(0.2, 0.6, -0.3).normalize();
        let f = |d: DVec3| map.radiance(d, 0.0).x as Real * n.dot(d).max(0.0);
        let rand = |i: u64, d: u32| crate::math::sample_1d(3, 0, i, 0, d);
        let count = 200_000u64;
        let mut uniform = 0.0;
        for i in 0..count {
            let z = 1.0 - 2.0 * rand(i, 0);
            let phi = 2.0 * PI * rand(i, 1);
            let s = (1.0 - z * z).sqrt();
            uniform += f(DVec3::new(s * phi.cos(), z, s * phi.sin())) * 4.0 * PI;
        }
        let uniform = uniform / count as Real;
        let count_is = 20_000u64;
        let mut weighted = 0.0;
        for i in 0..count_is {
            let (d, pdf) = map.sample(rand(i, 2), rand(i, 3), (rand(i, 4), rand(i, 5)), 0.0);
            assert!(pdf > 0.0 && (d.length() - 1.0).abs() < 1e-9);
            weighted += f(d) / pdf;
        }
        let weighted = weighted / count_is as Real;
        assert!(
            (weighted / uniform - 1.0).abs() < 0.05,
            "{weighted} vs {uniform}"
        );
    }

    #[test]
    fn sampling_favours_the_bright_patch() {
        let map = spotlit();
        let rand = |i: u64, d: u32| crate::math::sample_1d(4, 0, i, 0, d);
        let bright = (0..2000u64)
            .filter(|&i| {
                let (d, _) = map.sample(rand(i, 0), rand(i, 1), (rand(i, 2), rand(i, 3)), 0.0);
                map.radiance(d, 0.0).x > 100.0
            })
            .count();
        // The patch is 4 of 2048 texels but holds most of the light.
        assert!(bright > 1500, "{bright} of 2000");
    }
}
