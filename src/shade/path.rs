//! The path tracer: cosine-weighted bounces, next-event estimation
//! towards lights of real angular size and the environment map, Russian
//! roulette; paths advance together a bounce at a time.

use super::look::Look;
use super::look::MAX_LIGHTS;
use super::shadow::shadow_origin;
use super::sky::Sky;
use super::{StageCounts, SurfacePoint};
use crate::fractal::Fractal;
use crate::march::{march_many, normals_many, MarchResult, MarchSettings, Ray};
use crate::math::{DVec3, Real, Vec3};
use serde::{Deserialize, Serialize};

/// Global illumination by path tracing (Christensen, "Path Tracing 3D
/// Fractals"): Lambertian surfaces with the orbit-trap albedo,
/// cosine-weighted bounces, next-event estimation towards a sun of real
/// angular size, a sky dome, and Russian roulette after the third bounce so
/// the estimate stays unbiased. Replaces the direct-lighting effects (its sun
/// casts the shadows and its sky gives the occlusion).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PathTracing {
    /// Most bounces of a path (Russian roulette usually ends it sooner).
    pub max_bounces: u32,
    /// Apparent diameter of every light (the main one, `look.light_direction`
    /// with irradiance `look.light_colour`, and the extra ones); 0.53° is the
    /// real sun's.
    pub sun_angle_degrees: Real,
    pub sky: Sky,
    /// Scales the sky's radiance.
    pub sky_intensity: f32,
}

impl Default for PathTracing {
    fn default() -> Self {
        PathTracing {
            max_bounces: 6,
            sun_angle_degrees: 0.53,
            sky: Sky::Gradient,
            sky_intensity: 1.0,
        }
    }
}

/// A direction around the unit vector `axis` with local coordinates
/// (`x`, `y`, `z`), z along the axis.
pub(super) fn around(axis: DVec3, x: Real, y: Real, z: Real) -> DVec3 {
    // Branch-free orthonormal basis (Duff et al. 2017).
    let sign = 1.0f64.copysign(axis.z);
    let a = -1.0 / (sign + axis.z);
    let b = axis.x * axis.y * a;
    let t = DVec3::new(1.0 + sign * axis.x * axis.x * a, sign * b, -sign * axis.x);
    let u = DVec3::new(b, sign + axis.y * axis.y * a, -axis.y);
    (t * x + u * y + axis * z).normalize()
}

/// Cosine-weighted direction on the hemisphere around `normal` from two
/// uniform numbers: pdf cos θ / π, which cancels Lambert's cos θ / π.
pub fn cosine_direction(normal: DVec3, u: Real, v: Real) -> DVec3 {
    let r = u.sqrt();
    let phi = std::f64::consts::TAU * v;
    around(
        normal,
        r * phi.cos(),
        r * phi.sin(),
        (1.0 - u).max(0.0).sqrt(),
    )
}

/// Uniform direction in the cone of half-angle `half_angle` around `axis`.
pub fn cone_direction(axis: DVec3, half_angle: Real, u: Real, v: Real) -> DVec3 {
    let cos_max = half_angle.cos();
    let cos_t = 1.0 - u * (1.0 - cos_max);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * v;
    around(axis, sin_t * phi.cos(), sin_t * phi.sin(), cos_t)
}

/// Radiance of a path-traced camera sample that hit `at`. `random(d)` is the
/// sample's d-th uniform number (deterministic per pixel and sample).
/// `trace_paths` for one path: the tests' reference for it.
#[cfg(test)]
#[allow(clippy::too_many_arguments)] // the sample's whole context, passed plainly
pub fn trace_path(
    look: &Look,
    pt: &PathTracing,
    fractal: &Fractal,
    settings: &MarchSettings,
    at: &SurfacePoint,
    up: DVec3,
    environment: Option<&crate::environment::EnvironmentMap>,
    random: &dyn Fn(u32) -> Real,
    counts: &mut StageCounts,
) -> Vec3 {
    let mut traced = PathScratch::default();
    let palette = super::palette_table(look, fractal);
    trace_paths(
        look,
        pt,
        fractal,
        settings,
        &[Some(*at)],
        up,
        environment,
        palette.as_ref(),
        &|_, d| random(d),
        &mut traced,
    );
    let (radiance, stages) = traced.out[0];
    counts.bounces += stages.bounces;
    counts.sun_rays += stages.sun_rays;
    radiance
}

/// Buffers of `trace_paths`, kept by the caller from row to row: the
/// result per path (radiance and the estimates it took) in `out`.
#[derive(Default)]
pub struct PathScratch {
    pub out: Vec<(Vec3, StageCounts)>,
    /// Each start's path while it goes on.
    paths: Vec<Option<Path>>,
    rays: Vec<crate::march::Ray>,
    /// What each shadow ray brings if it gets through, and to which path.
    gains: Vec<(usize, Vec3)>,
    marched: Vec<crate::march::MarchResult>,
    /// The paths that go on from a bounce's hit, and which ray found it.
    going_on: Vec<(usize, usize)>,
}

/// One path between bounces.
#[derive(Clone, Copy)]
struct Path {
    here: SurfacePoint,
    throughput: Vec3,
}

/// What every path of one `trace_paths` call shares.
struct Tracing<'a> {
    look: &'a Look,
    pt: &'a PathTracing,
    fractal: &'a Fractal,
    settings: &'a MarchSettings,
    up: DVec3,
    environment: Option<&'a crate::environment::EnvironmentMap>,
    random: &'a dyn Fn(usize, u32) -> Real,
    rotation: Real,
    sun_half_angle: Real,
    sky_scale: f32,
}

/// Multiple importance sampling (power heuristic) between the map's own
/// sampling and the cosine-weighted bounce, when the sky is a map.
fn power(a: Real, b: Real) -> Real {
    a * a / (a * a + b * b)
}

/// The shadow or bounce ray that leaves `here` along `dir`.
fn leave(here: &SurfacePoint, dir: DVec3) -> Ray {
    Ray {
        origin: shadow_origin(here),
        dir,
        pixel_angle: 0.0,
        start_footprint: here.footprint,
    }
}

impl Tracing<'_> {
    /// Dimension `k` of bounce `bounce` of `path`. Dimensions 0–3 belong to
    /// the pixel and lens; 32 per bounce after that: 0–2 the bounce and
    /// roulette, then two per light.
    fn dim(&self, bounce: u32, path: usize, k: u32) -> Real {
        (self.random)(path, 4 + 32 * bounce + k)
    }

    fn march_all(&self, rays: &[Ray], marched: &mut Vec<MarchResult>) {
        marched.clear();
        marched.resize(rays.len(), MarchResult::default());
        march_many(rays, self.fractal, self.settings, marched);
    }

    /// Next-event estimation: one ray towards a point on each light's disc,
    /// then the map's light, sampled where it is bright; each adds what it
    /// brings where nothing blocks it, in that order. The rays go to `rays`,
    /// what each brings to `gains`.
    fn next_events(
        &self,
        bounce: u32,
        paths: &mut [Option<Path>],
        rays: &mut Vec<Ray>,
        gains: &mut Vec<(usize, Vec3)>,
    ) {
        let dim = |path: usize, k: u32| self.dim(bounce, path, k);
        rays.clear();
        gains.clear();
        for (i, path) in paths.iter_mut().enumerate() {
            let Some(path) = path else { continue };
            let here = &path.here;
            let albedo = self.look.albedo(&here.traps, here.palette_colour);
            for (l, (to_light, brightness)) in self.look.lights().enumerate() {
                let k = 3 + 2 * l as u32;
                let dir = if self.sun_half_angle > 0.0 {
                    cone_direction(to_light, self.sun_half_angle, dim(i, k), dim(i, k + 1))
                } else {
                    to_light
                };
                let cos_light = here.normal.dot(dir);
                if cos_light > 0.0 {
                    // Lambert: albedo/π × irradiance × cos θ, with the irradiance
                    // spread over π so an albedo-1 plane facing the light returns it.
                    rays.push(leave(here, dir));
                    gains.push((i, path.throughput * albedo * brightness * cos_light as f32));
                }
            }
            if let Some(map) = self.environment {
                let k = 3 + 2 * MAX_LIGHTS as u32;
                let (dir, pdf) = map.sample(
                    dim(i, k),
                    dim(i, k + 1),
                    (dim(i, k + 2), dim(i, k + 3)),
                    self.rotation,
                );
                let cos = here.normal.dot(dir);
                if cos > 0.0 && pdf > 0.0 {
                    let weight = power(pdf, cos / std::f64::consts::PI);
                    let scale = (cos / std::f64::consts::PI / pdf * weight) as f32;
                    rays.push(leave(here, dir));
                    gains.push((
                        i,
                        path.throughput
                            * albedo
                            * map.radiance(dir, self.rotation)
                            * (self.sky_scale * scale),
                    ));
                }
            }
            // The bounce is cosine-weighted, so the throughput only takes the albedo.
            path.throughput *= albedo;
        }
    }

    /// What each bounce ray (`rays`, `marched`) does to its path: a miss
    /// adds the sky and ends it, as do the last bounce and Russian roulette;
    /// the paths that go on are listed in `going_on` with their ray.
    #[allow(clippy::too_many_arguments)] // the bounce's buffers, passed plainly
    fn after_bounce(
        &self,
        bounce: u32,
        bounces: u32,
        paths: &mut [Option<Path>],
        rays: &[Ray],
        marched: &[MarchResult],
        out: &mut [(Vec3, StageCounts)],
        going_on: &mut Vec<(usize, usize)>,
    ) {
        let dim = |path: usize, k: u32| self.dim(bounce, path, k);
        going_on.clear();
        let walked = paths.iter_mut().enumerate().filter(|(_, p)| p.is_some());
        for (r, ((i, slot), (ray, result))) in
            walked.zip(rays.iter().zip(marched.iter())).enumerate()
        {
            let (radiance, counts) = &mut out[i];
            counts.bounces += result.evaluations as u64;
            let path = slot.as_mut().expect("only paths that go on are walked");
            if result.hit.is_none() {
                let dir = ray.dir;
                let sky = match self.environment {
                    Some(map) => {
                        let cos_pdf = path.here.normal.dot(dir).max(0.0) / std::f64::consts::PI;
                        map.radiance(dir, self.rotation)
                            * power(cos_pdf, map.pdf(dir, self.rotation)) as f32
                    }
                    None => self.pt.sky.radiance(self.look, dir, self.up, None),
                };
                *radiance += path.throughput * sky * self.sky_scale;
                *slot = None;
                continue;
            }
            if bounce + 1 == bounces {
                *slot = None; // the path ends here: its hit needs no normal
                continue;
            }
            // Russian roulette from the third bounce: unbiased, and paths that
            // carry little light end early.
            if bounce >= 2 {
                let survive = path.throughput.max_element().clamp(0.05, 0.95);
                if dim(i, 2) as f32 >= survive {
                    *slot = None;
                    continue;
                }
                path.throughput /= survive;
            }
            going_on.push((i, r));
        }
    }
}

/// Path-traced radiance of every camera sample of `starts` that hit (`None`
/// gives black and no work), into `scratch.out` in the same order. The
/// paths advance together a bounce at a time, so each bounce's shadow and
/// bounce rays march side by side (`march_many`); every path takes exactly
/// the steps, random numbers (`random(path, d)`) and additions it would
/// alone, so its radiance and counts are the same to the bit. `palette` is
/// the frame's (`palette_table`), made once for all its bands.
#[allow(clippy::too_many_arguments)] // the samples' whole context, passed plainly
pub fn trace_paths(
    look: &Look,
    pt: &PathTracing,
    fractal: &Fractal,
    settings: &MarchSettings,
    starts: &[Option<SurfacePoint>],
    up: DVec3,
    environment: Option<&crate::environment::EnvironmentMap>,
    palette: Option<&super::PaletteTable>,
    random: &dyn Fn(usize, u32) -> Real,
    scratch: &mut PathScratch,
) {
    let tracing = Tracing {
        look,
        pt,
        fractal,
        settings,
        up,
        environment,
        random,
        rotation: pt.sky.rotation(),
        sun_half_angle: 0.5 * pt.sun_angle_degrees.to_radians(),
        sky_scale: pt.sky_intensity,
    };
    let PathScratch {
        out,
        paths,
        rays,
        gains,
        marched,
        going_on,
    } = scratch;
    out.clear();
    out.resize(starts.len(), (Vec3::ZERO, StageCounts::default()));
    paths.clear();
    paths.extend(starts.iter().map(|at| {
        at.map(|here| Path {
            here,
            throughput: Vec3::ONE,
        })
    }));
    let bounces = pt.max_bounces.max(1);
    for bounce in 0..bounces {
        if paths.iter().all(Option::is_none) {
            break;
        }
        tracing.next_events(bounce, paths, rays, gains);
        tracing.march_all(rays, marched);
        for (&(i, gain), shadow) in gains.iter().zip(marched.iter()) {
            out[i].1.sun_rays += shadow.evaluations as u64;
            if shadow.hit.is_none() {
                out[i].0 += gain;
            }
        }
        // Bounce.
        rays.clear();
        rays.extend(paths.iter().enumerate().filter_map(|(i, path)| {
            let here = &path.as_ref()?.here;
            let (u, v) = (tracing.dim(bounce, i, 0), tracing.dim(bounce, i, 1));
            Some(leave(here, cosine_direction(here.normal, u, v)))
        }));
        tracing.march_all(rays, marched);
        tracing.after_bounce(bounce, bounces, paths, rays, marched, out, going_on);
        // The hits the paths go on from, their normals four to a kernel call.
        let hits = going_on.iter().map(|&(i, r)| {
            let hit = marched[r].hit.as_ref().expect("a path goes on from a hit");
            (i, &rays[r], hit)
        });
        normals_many(hits, fractal, settings, |i, ray, hit, (nrm, spent)| {
            out[i].1.bounces += spent as u64;
            let path = paths[i].as_mut().expect("a path that goes on");
            path.here = SurfacePoint {
                t: path.here.t + hit.t,
                ..SurfacePoint::from_hit(ray, hit, nrm).coloured(palette, fractal, &hit.estimate)
            };
        });
    }
}
