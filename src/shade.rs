//! What a hit looks like: orbit-trap colour, Lambert diffuse from the main
//! light and up to `MAX_LIGHTS` − 1 extra ones plus ambient, the background
//! gradient for misses, and the optional effects a scene declares (shadows,
//! ambient occlusion, specular, fog, glow, motion blur, and the path tracer
//! with its skies).
//! An effect that is off (`None`) runs no code and spends no estimate.
//!
//! Colouring idea from ../shared/seeds/000 (Quilez, "Coloring"): the three plane
//! traps blend a base colour towards three others, and the origin trap darkens
//! crevices like a cheap occlusion term. Soft shadows follow Quilez's penumbra
//! estimate (the smallest k·h/t along the shadow march); distance-field
//! occlusion compares the estimate with the distance stepped along the normal.

use crate::fractal::{Fractal, OrbitTraps};
use crate::march::MarchSettings;
use crate::math::{mix, normalize_or, sphere_interval, DVec3, Real, Vec3};
use serde::{Deserialize, Serialize};

/// The effects a scene calls for; each is off unless given.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Effects {
    pub shadows: Option<Shadows>,
    pub ambient_occlusion: Option<AmbientOcclusion>,
    pub specular: Option<Specular>,
    pub fog: Option<Fog>,
    pub glow: Option<Glow>,
    pub motion_blur: Option<MotionBlur>,
    pub path_tracing: Option<PathTracing>,
}

/// Global illumination by path tracing (seed 001, Christensen, "path tracing
/// 3D fractals"): Lambertian surfaces with the orbit-trap albedo,
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

/// The light arriving from directions that leave the scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Sky {
    /// The background gradient (`look.background_top` / `_bottom`).
    Gradient,
    /// The same radiance from every direction (a white furnace at (1, 1, 1)).
    Constant(Vec3),
    /// The Preetham daylight model for the sun at `look.light_direction`,
    /// +y up, with atmospheric turbidity (2 very clear … 10 hazy); zenith
    /// luminance 1, below the horizon the horizon's colour at half brightness.
    Preetham { turbidity: Real },
    /// An equirectangular HDR map (.exr or .hdr; a path relative to the
    /// timeline), +y up, turned about +y; sampled by importance.
    Environment {
        path: std::path::PathBuf,
        #[serde(default)]
        rotation_degrees: Real,
        /// SHA-256 of the file, filled in when the timeline is read: part of
        /// each frame's hash, so a changed map re-renders.
        #[serde(default, skip_deserializing)]
        digest: String,
    },
}

/// Samples spread over an open shutter, each seeing the timeline at its own time.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MotionBlur {
    /// How long the shutter is open, as a fraction of the frame interval (180° = 0.5).
    pub shutter: Real,
}

impl Default for MotionBlur {
    fn default() -> Self {
        MotionBlur { shutter: 0.5 }
    }
}

impl Effects {
    /// Names of the enabled effects, for `info`.
    pub fn enabled(&self) -> Vec<&'static str> {
        let mut v = Vec::new();
        if self.shadows.is_some() {
            v.push("shadows");
        }
        if self.ambient_occlusion.is_some() {
            v.push("ambient_occlusion");
        }
        if self.specular.is_some() {
            v.push("specular");
        }
        if self.fog.is_some() {
            v.push("fog");
        }
        if self.glow.is_some() {
            v.push("glow");
        }
        if self.motion_blur.is_some() {
            v.push("motion_blur");
        }
        if self.path_tracing.is_some() {
            v.push("path_tracing");
        }
        v
    }
}

/// Shadows from the light: a march from each lit hit towards the light.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Shadows {
    /// Penumbra sharpness k of Quilez's k·h/t estimate; 0 gives hard shadows.
    pub softness: Real,
    /// Steps of the shadow march before the light counts as reached.
    pub max_steps: u32,
}

impl Default for Shadows {
    fn default() -> Self {
        Shadows {
            softness: 16.0,
            max_steps: 128,
        }
    }
}

/// Occlusion from the distance field: a few estimates along the normal.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AmbientOcclusion {
    pub samples: u32,
    /// Reach along the normal as a fraction of the camera distance to the hit,
    /// so a zoom sees the same occlusion at every scale.
    pub radius: Real,
    /// 0 = no darkening, 1 = full.
    pub strength: f32,
}

impl Default for AmbientOcclusion {
    fn default() -> Self {
        AmbientOcclusion {
            samples: 5,
            radius: 0.05,
            strength: 1.0,
        }
    }
}

/// Blinn–Phong highlight of the light.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Specular {
    pub strength: f32,
    pub shininess: f32,
}

impl Default for Specular {
    fn default() -> Self {
        Specular {
            strength: 0.3,
            shininess: 32.0,
        }
    }
}

/// Exponential fog over the distance to each hit (the background is left as is).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Fog {
    /// Extinction per camera–target distance (scale-free, so zooms keep their haze).
    pub density: Real,
    pub colour: Vec3,
}

impl Default for Fog {
    fn default() -> Self {
        Fog {
            density: 0.5,
            colour: Vec3::new(0.10, 0.09, 0.12),
        }
    }
}

/// Glow around the surface where rays miss it narrowly.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Glow {
    pub colour: Vec3,
    pub strength: f32,
    /// Fall-off distance, in pixel footprints.
    pub width: Real,
}

impl Default for Glow {
    fn default() -> Self {
        Glow {
            colour: Vec3::new(0.9, 0.6, 0.3),
            strength: 0.6,
            width: 4.0,
        }
    }
}

/// A directional light: where it comes from and how bright it is.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Light {
    /// Direction towards the light (need not be unit length).
    pub direction: DVec3,
    pub colour: Vec3,
    pub intensity: f32,
}

impl Default for Light {
    fn default() -> Self {
        Light {
            direction: DVec3::new(-0.5, 0.3, -0.8),
            colour: Vec3::new(0.45, 0.5, 0.6),
            intensity: 1.0,
        }
    }
}

/// Most lights a scene may have (the key light and seven more).
pub const MAX_LIGHTS: usize = 8;

/// Estimates spent by the shading stages of one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StageCounts {
    pub shadows: u64,
    pub occlusion: u64,
    /// Path tracing: marching of bounce rays, and of rays towards the sun.
    pub bounces: u64,
    pub sun_rays: u64,
}

/// A hit as shading needs it.
#[derive(Clone, Copy, Debug)]
pub struct SurfacePoint {
    pub point: DVec3,
    pub normal: DVec3,
    /// Direction from the camera towards the point.
    pub view_dir: DVec3,
    /// Camera distance to the point, and one pixel's width there.
    pub t: Real,
    pub footprint: Real,
    pub traps: OrbitTraps,
}

impl SurfacePoint {
    /// Where `ray` met the surface (`hit`), with the surface `normal` there.
    pub fn from_hit(ray: &crate::march::Ray, hit: &crate::march::Hit, normal: DVec3) -> Self {
        SurfacePoint {
            point: hit.point,
            normal,
            view_dir: ray.dir,
            t: hit.t,
            footprint: ray.footprint(hit.t),
            traps: hit.estimate.traps,
        }
    }
}

/// Light reaching `from` along `to_light`: 1 unoccluded, 0 blocked, in between
/// in a penumbra (`softness` > 0). Returns the factor and the estimates spent.
pub fn shadow(
    fractal: &Fractal,
    settings: &MarchSettings,
    shadows: &Shadows,
    from: DVec3,
    to_light: DVec3,
    footprint: Real,
) -> (f32, u64) {
    crate::march::walk_one(
        ShadowWalk::start(settings, shadows, from, to_light, footprint),
        fractal,
        settings,
    )
}

/// Where a surface point's shadow rays start: a couple of footprints off
/// the surface, so it does not shadow itself.
fn shadow_origin(at: &SurfacePoint) -> DVec3 {
    at.point + at.normal * (2.0 * at.footprint)
}

/// A shadow ray between estimates (see `shadow`), so many can be walked
/// side by side (`march::walk_many`).
#[derive(Clone, Copy, Debug)]
pub struct ShadowWalk {
    from: DVec3,
    to_light: DVec3,
    footprint: Real,
    t: Real,
    t_exit: Real,
    eps: Real,
    softness: Real,
    light: Real,
    steps_left: u32,
    spent: u64,
}

impl ShadowWalk {
    /// Starts a couple of footprints off the surface; the output at once
    /// for a ray that misses the bounding sphere or may take no step.
    pub fn start(
        settings: &MarchSettings,
        shadows: &Shadows,
        from: DVec3,
        to_light: DVec3,
        footprint: Real,
    ) -> Result<ShadowWalk, (f32, u64)> {
        let Some((_, t_exit)) = sphere_interval(from, to_light, settings.bounding_radius) else {
            return Err((1.0, 0));
        };
        let walk = ShadowWalk {
            from,
            to_light,
            footprint,
            t: 2.0 * footprint,
            t_exit,
            eps: settings.hit_threshold * footprint,
            softness: shadows.softness,
            light: 1.0,
            steps_left: shadows.max_steps,
            spent: 0,
        };
        match walk.finished() {
            true => Err(walk.output()),
            false => Ok(walk),
        }
    }

    fn finished(&self) -> bool {
        self.steps_left == 0 || self.t > self.t_exit
    }

    fn output(&self) -> (f32, u64) {
        (self.light.clamp(0.0, 1.0) as f32, self.spent)
    }
}

impl crate::march::Walk for ShadowWalk {
    type Output = (f32, u64);

    fn next_point(&self) -> (DVec3, Real) {
        (self.from + self.to_light * self.t, self.footprint)
    }

    fn advance(
        &mut self,
        e: &crate::fractal::Estimate,
        _: Real,
        _: &Fractal,
        settings: &MarchSettings,
    ) -> Option<(f32, u64)> {
        self.spent += e.orbits as u64;
        if !e.escaped || e.distance < self.eps {
            return Some((0.0, self.spent));
        }
        if self.softness > 0.0 {
            self.light = self.light.min(self.softness * e.distance / self.t);
        }
        self.t += e.distance * settings.fudge;
        self.steps_left -= 1;
        self.finished().then(|| self.output())
    }
}

/// Ambient light reaching a surface point: 1 in the open, less in crevices.
/// One point alone: the tests' reference for `occlusions`.
#[cfg(test)]
pub fn occlusion(
    fractal: &Fractal,
    ao: &AmbientOcclusion,
    point: DVec3,
    normal: DVec3,
    t: Real,
    footprint: Real,
) -> (f32, u64) {
    // One walk alone, estimate by estimate: the reference `occlusions`'
    // lanes are held to.
    let walk = OcclusionWalk::start(ao, 0, point, normal, t, footprint);
    crate::march::walk_one(Ok(walk), fractal, &MarchSettings::default()).1
}

/// `occlusion` at many surface points (index, point, normal, distance from
/// the camera, footprint), each an `OcclusionWalk`, walked side by side
/// (`march::walk_many`) so a point's few samples do not pay for a call of
/// the lane kernel of their own. `out(i, …)` gets point `i`'s, bit for bit
/// what it would get alone: each point sums its samples in order.
pub fn occlusions(
    fractal: &Fractal,
    ao: &AmbientOcclusion,
    points: impl IntoIterator<Item = (usize, DVec3, DVec3, Real, Real)>,
    mut out: impl FnMut(usize, (f32, u64)),
) {
    let walks = points.into_iter().map(|(i, point, normal, t, footprint)| {
        Ok(OcclusionWalk::start(ao, i, point, normal, t, footprint))
    });
    // `walk_many` needs no quality settings for these walks.
    let settings = MarchSettings::default();
    crate::march::walk_many(walks, fractal, &settings, |_, (i, found)| out(i, found));
}

/// One surface point's ambient occlusion (see `occlusions`): `samples`
/// estimates at evenly spaced distances along the normal, out to `radius`
/// times the camera distance, each weighing 0.6 of the one before.
#[derive(Clone, Copy, Debug)]
struct OcclusionWalk {
    /// The point's index, handed back with its output.
    index: usize,
    point: DVec3,
    normal: DVec3,
    /// Distance from the camera, and the footprint there.
    t: Real,
    footprint: Real,
    radius: Real,
    strength: Real,
    /// The sample to take next, 1 to `n`, and how far along the normal it
    /// lies (`distance`).
    k: u32,
    n: u32,
    along: Real,
    blocked: Real,
    weights: Real,
    weight: Real,
    spent: u64,
}

impl OcclusionWalk {
    fn start(
        ao: &AmbientOcclusion,
        index: usize,
        point: DVec3,
        normal: DVec3,
        t: Real,
        footprint: Real,
    ) -> OcclusionWalk {
        let mut walk = OcclusionWalk {
            index,
            point,
            normal,
            t,
            footprint,
            radius: ao.radius,
            strength: ao.strength as Real,
            k: 1,
            n: ao.samples.max(1),
            along: 0.0,
            blocked: 0.0,
            weights: 0.0,
            weight: 1.0,
            spent: 0,
        };
        walk.along = walk.distance();
        walk
    }

    /// How far along the normal sample `k` lies.
    fn distance(&self) -> Real {
        self.radius * self.t * self.k as Real / self.n as Real
    }
}

impl crate::march::Walk for OcclusionWalk {
    type Output = (usize, (f32, u64));

    fn next_point(&self) -> (DVec3, Real) {
        (self.point + self.normal * self.along, self.footprint)
    }

    fn advance(
        &mut self,
        e: &crate::fractal::Estimate,
        _: Real,
        _: &Fractal,
        _: &MarchSettings,
    ) -> Option<Self::Output> {
        let d = self.along;
        self.spent += e.orbits as u64;
        // Where the field is nearer than the distance stepped, geometry crowds
        // in. The estimate is about half the true distance near the surface
        // (the ½ in ½·ln r·r/dr, kept for safe marching), so double it here.
        self.blocked += self.weight * ((d - 2.0 * e.distance) / d).clamp(0.0, 1.0);
        self.weights += self.weight;
        self.weight *= 0.6;
        if self.k < self.n {
            self.k += 1;
            self.along = self.distance();
            return None;
        }
        let ambient = 1.0 - self.strength * self.blocked / self.weights;
        Some((self.index, (ambient.clamp(0.0, 1.0) as f32, self.spent)))
    }
}

/// Colours and light of a scene. Colours are linear RGB.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Look {
    /// Direction towards the light (need not be unit length).
    pub light_direction: DVec3,
    pub light_colour: Vec3,
    /// More directional lights beside the key light above (fill, rim, a second sun).
    pub extra_lights: Vec<Light>,
    /// Light that reaches every surface regardless of orientation.
    pub ambient: Vec3,
    /// Surface colour where no trap pulls.
    pub base_colour: Vec3,
    /// Colours the x=0, y=0 and z=0 plane traps blend towards.
    pub trap_x_colour: Vec3,
    pub trap_y_colour: Vec3,
    pub trap_z_colour: Vec3,
    /// How strongly the origin trap darkens crevices (0 = not at all).
    pub trap_occlusion: f32,
    /// Background at the top and bottom of the frame (by the camera's up vector).
    pub background_top: Vec3,
    pub background_bottom: Vec3,
    /// How linear light becomes 8-bit display values (PNG frames; an EXR
    /// keeps the linear light as rendered): multiplied by `exposure`, then
    /// mapped by `tone_map`. Left out of a scene's serialised form at
    /// their defaults, so frames rendered before they existed keep their
    /// hashes.
    #[serde(skip_serializing_if = "ToneMap::is_clip")]
    pub tone_map: ToneMap,
    #[serde(skip_serializing_if = "is_one")]
    pub exposure: f32,
}

fn is_one(x: &f32) -> bool {
    *x == 1.0
}

/// The curve from exposed linear light to display values in [0, 1].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ToneMap {
    /// Values above 1 are white: each channel clips on its own, so a bright
    /// orange highlight turns yellow, then white.
    #[default]
    Clip,
    /// A filmic curve (Narkowicz's rational fit of the ACES reference
    /// transform, per channel): highlights roll off towards white instead
    /// of clipping, and mid-tones lift (0.18 shows as 0.27); 1 shows as
    /// 0.80, 4 as 0.97, and white is reached near 7.2.
    Filmic,
}

impl ToneMap {
    fn is_clip(&self) -> bool {
        *self == ToneMap::Clip
    }

    /// The display value of exposed linear `x` (at or above 0), before the
    /// sRGB curve; `Clip` leaves `x` as it is (the sRGB coding clips).
    #[inline]
    pub fn apply(self, x: f32) -> f32 {
        match self {
            ToneMap::Clip => x,
            ToneMap::Filmic => {
                // White from about 7.2 on; capped so x² cannot overflow
                // (infinity over infinity would show black).
                let x = if x > 0.0 { x.min(64.0) } else { 0.0 };
                (x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14)
            }
        }
    }
}

impl Look {
    /// Whether display values are the linear light itself (clipped), as
    /// before tone maps existed: PNG coding then takes its plain path.
    pub fn is_plain_display(&self) -> bool {
        self.tone_map == ToneMap::Clip && self.exposure == 1.0
    }

    /// The display value of linear `x` (`exposure`, then `tone_map`).
    #[inline]
    pub fn display(&self, x: f32) -> f32 {
        self.tone_map.apply(x * self.exposure)
    }
}

impl Default for Look {
    fn default() -> Self {
        Look {
            light_direction: DVec3::new(0.6, 0.8, 0.5),
            light_colour: Vec3::new(1.0, 0.95, 0.85),
            extra_lights: Vec::new(),
            ambient: Vec3::new(0.12, 0.13, 0.16),
            base_colour: Vec3::new(0.75, 0.72, 0.68),
            trap_x_colour: Vec3::new(0.75, 0.28, 0.08),
            trap_y_colour: Vec3::new(0.10, 0.35, 0.65),
            trap_z_colour: Vec3::new(0.85, 0.65, 0.20),
            trap_occlusion: 0.8,
            background_top: Vec3::new(0.02, 0.03, 0.06),
            background_bottom: Vec3::new(0.10, 0.09, 0.12),
            tone_map: ToneMap::Clip,
            exposure: 1.0,
        }
    }
}

impl Look {
    /// Every light as (unit direction towards it, brightness): the key light first.
    pub fn lights(&self) -> impl Iterator<Item = (DVec3, Vec3)> + '_ {
        std::iter::once((
            normalize_or(self.light_direction, DVec3::Y),
            self.light_colour,
        ))
        .chain(
            self.extra_lights
                .iter()
                .map(|l| (normalize_or(l.direction, DVec3::Y), l.colour * l.intensity)),
        )
    }

    /// Albedo of the surface from its orbit traps.
    pub fn albedo(&self, traps: &OrbitTraps) -> Vec3 {
        // A plane trap pulls hardest when the orbit passed close to that plane.
        let pull = |d: Real| (1.0 - (d * 4.0).min(1.0)) as f32;
        let mut c = self.base_colour;
        c = mix(c, self.trap_x_colour, pull(traps.planes.x));
        c = mix(c, self.trap_y_colour, pull(traps.planes.y) * 0.8);
        c = mix(c, self.trap_z_colour, pull(traps.planes.z) * 0.6);
        // Orbits that dive near the origin lie deep in crevices.
        let depth = (traps.origin.sqrt() as f32).clamp(0.0, 1.0);
        c * (1.0 - self.trap_occlusion + self.trap_occlusion * depth)
    }

    /// Radiance of a hit with the scene's effects, its shadow rays walked one
    /// at a time: the tests' reference for `shade_with`, which rendering
    /// uses. Stages of effects that are off never run; `counts` hears what
    /// the others spent.
    #[cfg(test)]
    pub fn shade(
        &self,
        effects: &Effects,
        fractal: &Fractal,
        settings: &MarchSettings,
        at: &SurfacePoint,
        counts: &mut StageCounts,
    ) -> Vec3 {
        let mut shadows = self
            .shadow_walks(effects, settings, at)
            .map(|walk| crate::march::walk_one(walk, fractal, settings));
        let occluded = effects
            .ambient_occlusion
            .as_ref()
            .map(|ao| occlusion(fractal, ao, at.point, at.normal, at.t, at.footprint));
        self.shade_with(effects, at, counts, &mut shadows, occluded)
    }

    /// The lights that face the surface at `at`: (direction towards the
    /// light, brightness, Lambert cosine), in the order of `lights`.
    fn facing<'a>(&'a self, at: &'a SurfacePoint) -> impl Iterator<Item = (DVec3, Vec3, f32)> + 'a {
        self.lights().filter_map(|(to_light, brightness)| {
            let lambert = at.normal.dot(to_light).max(0.0) as f32;
            (lambert > 0.0).then_some((to_light, brightness, lambert))
        })
    }

    /// The shadow rays `shade` would walk at `at`, in the order it walks
    /// them: to be walked side by side and handed to `shade_with`.
    pub fn shadow_walks<'a>(
        &'a self,
        effects: &'a Effects,
        settings: &'a MarchSettings,
        at: &'a SurfacePoint,
    ) -> impl Iterator<Item = Result<ShadowWalk, (f32, u64)>> + 'a {
        effects.shadows.iter().flat_map(move |sh| {
            self.facing(at).map(move |(to_light, _, _)| {
                ShadowWalk::start(settings, sh, shadow_origin(at), to_light, at.footprint)
            })
        })
    }

    /// `shade` with the shadow rays' outcomes (factor, estimates spent)
    /// taken from `shadows`, one per ray `shadow_walks` lists, in its order
    /// (asked only with shadows on), and the ambient occlusion `occlusion`
    /// gives at `at` (needed only with it on).
    pub fn shade_with(
        &self,
        effects: &Effects,
        at: &SurfacePoint,
        counts: &mut StageCounts,
        shadows: &mut dyn Iterator<Item = (f32, u64)>,
        occluded: Option<(f32, u64)>,
    ) -> Vec3 {
        debug_assert_eq!(occluded.is_some(), effects.ambient_occlusion.is_some());
        let mut ambient = 1.0f32;
        if let Some((a, spent)) = occluded {
            ambient = a;
            counts.occlusion += spent;
        }
        let albedo = self.albedo(&at.traps);
        let mut c = albedo * self.ambient * ambient;
        for (to_light, brightness, lambert) in self.facing(at) {
            let mut light = 1.0f32;
            if effects.shadows.is_some() {
                let (f, spent) = shadows.next().expect("an outcome per shadow ray");
                light = f;
                counts.shadows += spent;
            }
            c += albedo * brightness * (lambert * light);
            if let Some(sp) = &effects.specular {
                let half = normalize_or(to_light - at.view_dir, at.normal);
                let highlight = (at.normal.dot(half).max(0.0) as f32).powf(sp.shininess);
                c += brightness * (sp.strength * highlight * light);
            }
        }
        c
    }

    /// Radiance of the background seen along `dir`, with `up` the camera's up vector.
    pub fn background(&self, dir: DVec3, up: DVec3) -> Vec3 {
        let t = (0.5 + 0.5 * dir.dot(up)) as f32;
        mix(self.background_bottom, self.background_top, t)
    }
}

/// A direction around the unit vector `axis` with local coordinates
/// (`x`, `y`, `z`), z along the axis.
fn around(axis: DVec3, x: Real, y: Real, z: Real) -> DVec3 {
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

impl Sky {
    /// Radiance arriving along `dir` (the sun is separate).
    pub fn radiance(
        &self,
        look: &Look,
        dir: DVec3,
        up: DVec3,
        environment: Option<&crate::environment::EnvironmentMap>,
    ) -> Vec3 {
        match self {
            Sky::Gradient => look.background(dir, up),
            Sky::Constant(c) => *c,
            Sky::Preetham { turbidity } => preetham(
                dir,
                normalize_or(look.light_direction, DVec3::Y),
                *turbidity,
            ),
            // The map is fetched once per frame by the caller, never per ray.
            Sky::Environment { .. } => {
                environment.map_or(Vec3::ZERO, |map| map.radiance(dir, self.rotation()))
            }
        }
    }

    /// Turn of an environment map about +y, in radians (0 for other skies).
    pub fn rotation(&self) -> Real {
        match self {
            Sky::Environment {
                rotation_degrees, ..
            } => rotation_degrees.to_radians(),
            _ => 0.0,
        }
    }

    /// The loaded map of an `Environment` sky. A timeline loads and checks
    /// it when read, so it is in the cache; for a scene built otherwise a
    /// map that fails to load gives `None`, a black sky.
    pub fn environment(&self) -> Option<std::sync::Arc<crate::environment::EnvironmentMap>> {
        match self {
            Sky::Environment { path, digest, .. } => crate::environment::cached(path, digest).ok(),
            _ => None,
        }
    }
}

/// The Preetham, Shirley and Smits (1999) analytic daylight sky: the Perez
/// distribution of luminance and chromaticity over the sky, fitted to
/// turbidity. Linear sRGB, zenith luminance 1.
pub fn preetham(dir: DVec3, to_sun: DVec3, turbidity: Real) -> Vec3 {
    let t = turbidity;
    let perez = |theta: Real, gamma: Real, c: [Real; 5]| {
        (1.0 + c[0] * (c[1] / theta.cos().max(0.01)).exp())
            * (1.0 + c[2] * (c[3] * gamma).exp() + c[4] * gamma.cos().powi(2))
    };
    let lum = [
        0.1787 * t - 1.4630,
        -0.3554 * t + 0.4275,
        -0.0227 * t + 5.3251,
        0.1206 * t - 2.5771,
        -0.0670 * t + 0.3703,
    ];
    let cx = [
        -0.0193 * t - 0.2592,
        -0.0665 * t + 0.0008,
        -0.0004 * t + 0.2125,
        -0.0641 * t - 0.8989,
        -0.0033 * t + 0.0452,
    ];
    let cy = [
        -0.0167 * t - 0.2608,
        -0.0950 * t + 0.0092,
        -0.0079 * t + 0.2102,
        -0.0441 * t - 1.6537,
        -0.0109 * t + 0.0529,
    ];
    let theta_s = to_sun
        .y
        .clamp(-1.0, 1.0)
        .acos()
        .min(std::f64::consts::FRAC_PI_2);
    let (s1, s2, s3) = (theta_s, theta_s * theta_s, theta_s * theta_s * theta_s);
    let zenith_x = t * t * (0.00166 * s3 - 0.00375 * s2 + 0.00209 * s1)
        + t * (-0.02903 * s3 + 0.06377 * s2 - 0.03202 * s1 + 0.00394)
        + (0.11693 * s3 - 0.21196 * s2 + 0.06052 * s1 + 0.25886);
    let zenith_y = t * t * (0.00275 * s3 - 0.00610 * s2 + 0.00317 * s1)
        + t * (-0.04214 * s3 + 0.08970 * s2 - 0.04153 * s1 + 0.00516)
        + (0.15346 * s3 - 0.26756 * s2 + 0.06670 * s1 + 0.26688);
    // Below the horizon: the horizon's colour at half brightness.
    let (d, dim) = if dir.y < 0.0 {
        (normalize_or(DVec3::new(dir.x, 0.0, dir.z), DVec3::X), 0.5)
    } else {
        (dir, 1.0)
    };
    let theta = d.y.clamp(0.0, 1.0).acos().min(1.5608); // 89.4°: keeps 1/cos θ finite
    let gamma = d.dot(to_sun).clamp(-1.0, 1.0).acos();
    let relative = |c: [Real; 5]| perez(theta, gamma, c) / perez(0.0, theta_s, c);
    let luminance = relative(lum) * dim;
    let x = zenith_x * relative(cx);
    let y = (zenith_y * relative(cy)).max(1e-6);
    // xyY → XYZ → linear sRGB (D65).
    let (cap_x, cap_z) = (x / y * luminance, (1.0 - x - y) / y * luminance);
    let rgb = Vec3::new(
        (3.2406 * cap_x - 1.5372 * luminance - 0.4986 * cap_z) as f32,
        (-0.9689 * cap_x + 1.8758 * luminance + 0.0415 * cap_z) as f32,
        (0.0557 * cap_x - 0.2040 * luminance + 1.0570 * cap_z) as f32,
    );
    crate::math::finite_or_zero(rgb.max(Vec3::ZERO))
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
    trace_paths(
        look,
        pt,
        fractal,
        settings,
        &[Some(*at)],
        up,
        environment,
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

/// Path-traced radiance of every camera sample of `starts` that hit (`None`
/// gives black and no work), into `scratch.out` in the same order. The
/// paths advance together a bounce at a time, so each bounce's shadow and
/// bounce rays march side by side (`march_many`); every path takes exactly
/// the steps, random numbers (`random(path, d)`) and additions it would
/// alone, so its radiance and counts are the same to the bit.
#[allow(clippy::too_many_arguments)] // the samples' whole context, passed plainly
pub fn trace_paths(
    look: &Look,
    pt: &PathTracing,
    fractal: &Fractal,
    settings: &MarchSettings,
    starts: &[Option<SurfacePoint>],
    up: DVec3,
    environment: Option<&crate::environment::EnvironmentMap>,
    random: &dyn Fn(usize, u32) -> Real,
    scratch: &mut PathScratch,
) {
    use crate::march::{march_many, normals_many, MarchResult, Ray};
    let rotation = pt.sky.rotation();
    // Multiple importance sampling (power heuristic) between the map's own
    // sampling and the cosine-weighted bounce, when the sky is a map.
    let power = |a: Real, b: Real| a * a / (a * a + b * b);
    let sun_half_angle = 0.5 * pt.sun_angle_degrees.to_radians();
    let sky_scale = pt.sky_intensity;
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
    let leave = |here: &SurfacePoint, dir: DVec3| Ray {
        origin: shadow_origin(here),
        dir,
        pixel_angle: 0.0,
        start_footprint: here.footprint,
    };
    let march_all = |rays: &[Ray], marched: &mut Vec<MarchResult>| {
        marched.clear();
        marched.resize(rays.len(), MarchResult::default());
        march_many(rays, fractal, settings, marched);
    };
    let bounces = pt.max_bounces.max(1);
    for bounce in 0..bounces {
        if paths.iter().all(Option::is_none) {
            break;
        }
        // Dimensions 0–3 belong to the pixel and lens; 32 per bounce after that:
        // 0–2 the bounce and roulette, then two per light.
        let dim = |path: usize, k: u32| random(path, 4 + 32 * bounce + k);
        // Next-event estimation: one ray towards a point on each light's disc,
        // then the map's light, sampled where it is bright; each adds what it
        // brings where nothing blocks it, in that order.
        rays.clear();
        gains.clear();
        for (i, path) in paths.iter_mut().enumerate() {
            let Some(path) = path else { continue };
            let here = &path.here;
            let albedo = look.albedo(&here.traps);
            for (l, (to_light, brightness)) in look.lights().enumerate() {
                let k = 3 + 2 * l as u32;
                let dir = if sun_half_angle > 0.0 {
                    cone_direction(to_light, sun_half_angle, dim(i, k), dim(i, k + 1))
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
            if let Some(map) = environment {
                let k = 3 + 2 * MAX_LIGHTS as u32;
                let (dir, pdf) = map.sample(
                    dim(i, k),
                    dim(i, k + 1),
                    (dim(i, k + 2), dim(i, k + 3)),
                    rotation,
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
                            * map.radiance(dir, rotation)
                            * (sky_scale * scale),
                    ));
                }
            }
            // The bounce is cosine-weighted, so the throughput only takes the albedo.
            path.throughput *= albedo;
        }
        march_all(rays, marched);
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
            Some(leave(
                here,
                cosine_direction(here.normal, dim(i, 0), dim(i, 1)),
            ))
        }));
        march_all(rays, marched);
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
                let sky = match environment {
                    Some(map) => {
                        let cos_pdf = path.here.normal.dot(dir).max(0.0) / std::f64::consts::PI;
                        map.radiance(dir, rotation) * power(cos_pdf, map.pdf(dir, rotation)) as f32
                    }
                    None => pt.sky.radiance(look, dir, up, None),
                };
                *radiance += path.throughput * sky * sky_scale;
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
                ..SurfacePoint::from_hit(ray, hit, nrm)
            };
        });
    }
}

/// Fog over a hit `distance` away, with `scale` the camera–target distance.
pub fn fogged(c: Vec3, fog: &Fog, distance: Real, scale: Real) -> Vec3 {
    let clear = (-fog.density * distance / scale.max(1e-300)).exp() as f32;
    mix(fog.colour, c, clear)
}

/// Glow added to a ray that came within `closest` footprints of the surface.
pub fn glow(glow: &Glow, closest: Real) -> Vec3 {
    if !closest.is_finite() {
        return Vec3::ZERO;
    }
    glow.colour * (glow.strength * (-closest / glow.width.max(1e-9)).exp() as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_filmic_curve_rolls_off_below_white_and_defaults_are_not_serialised() {
        let f = |x: f32| ToneMap::Filmic.apply(x);
        assert_eq!(f(0.0), 0.0);
        // Narkowicz's fit at a few points, by hand: 0.18·0.4818/0.32493 …
        for (x, y) in [(0.18, 0.2669), (1.0, 0.8038), (4.0, 0.9734)] {
            assert!((f(x) - y).abs() < 1e-3, "f({x}) = {}", f(x));
        }
        let mut last = 0.0;
        // Rising, and below white until about 7.2 (where the fit crosses 1).
        for k in 1..=720 {
            let y = f(k as f32 * 0.01);
            assert!(y > last && y < 1.0, "not rising below 1 at {k}");
            last = y;
        }
        assert!(f(1e6) < 1.04 && f(-1.0) == 0.0 && f(f32::NAN) == 0.0);
        for huge in [1e19, 1e30, f32::MAX, f32::INFINITY] {
            assert!(f(huge) > 1.0, "f({huge}) = {}: white, not black", f(huge));
        }
        assert_eq!(ToneMap::Clip.apply(3.0), 3.0);
        // Left at their defaults, exposure and tone map are not serialised:
        // frames rendered before they existed keep their hashes.
        let json = serde_json::to_string(&Look::default()).unwrap();
        assert!(
            !json.contains("tone_map") && !json.contains("exposure"),
            "{json}"
        );
        let filmic = Look {
            tone_map: ToneMap::Filmic,
            exposure: 2.0,
            ..Look::default()
        };
        let json = serde_json::to_string(&filmic).unwrap();
        assert!(
            json.contains("\"tone_map\":\"Filmic\"") && json.contains("\"exposure\":2.0"),
            "{json}"
        );
        assert!(filmic.display(0.5) == f(1.0) && !filmic.is_plain_display());
    }

    /// Where `ray` meets the surface, as shading takes it.
    fn surface_at(
        ray: &crate::march::Ray,
        fractal: &Fractal,
        settings: &MarchSettings,
    ) -> Option<SurfacePoint> {
        let hit = crate::march::march(ray, fractal, settings).hit?;
        let (normal, _) = crate::march::normal(ray, &hit, fractal, settings);
        Some(SurfacePoint::from_hit(ray, &hit, normal))
    }

    /// Where `count` rays from around the bulb (`seed` picks them) meet it.
    fn bulb_points(
        count: usize,
        seed: u64,
        fractal: &Fractal,
        settings: &MarchSettings,
    ) -> Vec<SurfacePoint> {
        crate::math::shell_points(count, 2.5..2.6, seed)
            .into_iter()
            .filter_map(|origin| {
                let ray = crate::march::Ray {
                    origin,
                    dir: (DVec3::new(0.1, -0.2, 0.15) - origin).normalize(),
                    pixel_angle: 1e-3,
                    start_footprint: 0.0,
                };
                surface_at(&ray, fractal, settings)
            })
            .collect()
    }

    fn unit_ball() -> Fractal {
        Fractal::unit_ball()
    }

    #[test]
    fn occlusion_packed_across_points_is_each_points_own() {
        // Real surface points, their samples packed across points (a call
        // holding the end of one point's samples and the start of the
        // next's), against each point alone, bit for bit.
        let fractal = Fractal::default();
        let settings = MarchSettings::default();
        let points = bulb_points(40, 5, &fractal, &settings);
        assert!(points.len() > 10, "{} surface points", points.len());
        for samples in [1, 3, 5, 16, 21] {
            let ao = AmbientOcclusion {
                samples,
                radius: 0.2,
                ..AmbientOcclusion::default()
            };
            let mut packed = vec![None; points.len()];
            let sites = points
                .iter()
                .enumerate()
                .map(|(i, at)| (i, at.point, at.normal, at.t, at.footprint));
            occlusions(&fractal, &ao, sites, |i, out| {
                assert!(packed[i].replace(out).is_none(), "point {i} twice")
            });
            // The documented sum, one scalar estimate at a time.
            let by_hand = |at: &SurfacePoint| {
                let (mut blocked, mut weights, mut weight, mut spent) = (0.0, 0.0, 1.0, 0);
                for k in 1..=samples {
                    let d = ao.radius * at.t * k as Real / samples as Real;
                    let e = fractal.estimate(at.point + at.normal * d, at.footprint);
                    spent += e.orbits as u64;
                    blocked += weight * ((d - 2.0 * e.distance) / d).clamp(0.0, 1.0);
                    weights += weight;
                    weight *= 0.6;
                }
                let ambient = 1.0 - ao.strength as Real * blocked / weights;
                (ambient.clamp(0.0, 1.0) as f32, spent)
            };
            let mut occluded = 0;
            for (at, packed) in points.iter().zip(&packed) {
                let (a, spent) = occlusion(&fractal, &ao, at.point, at.normal, at.t, at.footprint);
                let (b, packed_spent) = packed.expect("every point");
                assert_eq!(
                    (a.to_bits(), spent),
                    (b.to_bits(), packed_spent),
                    "{samples}"
                );
                let (c, hand_spent) = by_hand(at);
                assert_eq!((a.to_bits(), spent), (c.to_bits(), hand_spent), "{samples}");
                occluded += (a < 0.99) as usize;
            }
            assert!(occluded > 2, "{occluded} occluded with {samples} samples");
        }
    }

    #[test]
    fn shadow_rays_walked_side_by_side_match_one_at_a_time() {
        // Surface points on the bulb lit by three lights, some facing away:
        // `shade` with its own shadow rays against `shade_with` fed the
        // outcomes `walk_many` found for `shadow_walks`, bit for bit.
        let fractal = Fractal::default();
        let settings = MarchSettings::default();
        let mut look = Look::default();
        for (direction, intensity) in [(DVec3::new(-1.0, 0.2, 0.3), 0.5), (DVec3::NEG_Y, 0.3)] {
            look.extra_lights.push(Light {
                direction,
                intensity,
                ..Light::default()
            });
        }
        let effects = Effects {
            shadows: Some(Shadows {
                max_steps: 40,
                ..Shadows::default()
            }),
            ..Effects::default()
        };
        // Real surface points: where rays from around the bulb meet it.
        let points = bulb_points(80, 3, &fractal, &settings);
        let walks: Vec<_> = points
            .iter()
            .flat_map(|at| look.shadow_walks(&effects, &settings, at))
            .collect();
        let mut outcomes = vec![(f32::NAN, 0); walks.len()];
        crate::march::walk_many(walks, &fractal, &settings, |i, out| outcomes[i] = out);
        let mut outcomes = outcomes.into_iter();
        let (mut shaded, mut partly) = (0, 0);
        for at in &points {
            let (mut one, mut many) = (StageCounts::default(), StageCounts::default());
            let alone = look.shade(&effects, &fractal, &settings, at, &mut one);
            let mut next = std::iter::from_fn(|| {
                let out = outcomes.next().expect("an outcome per walk");
                shaded += (out.0 < 1.0) as u32;
                partly += (out.0 > 0.0 && out.0 < 1.0) as u32;
                Some(out)
            });
            let batched = look.shade_with(&effects, at, &mut many, &mut next, None);
            assert_eq!(
                alone.to_array().map(f32::to_bits),
                batched.to_array().map(f32::to_bits)
            );
            assert_eq!(one, many);
        }
        assert!(outcomes.next().is_none(), "a walk no light asked for");
        assert!(
            shaded > 10 && partly > 3,
            "{shaded} shaded, {partly} in penumbra"
        );
    }

    #[test]
    fn shadow_is_one_in_the_open_and_zero_behind_the_ball() {
        let settings = MarchSettings::default();
        for softness in [0.0, 16.0] {
            let sh = Shadows {
                softness,
                ..Shadows::default()
            };
            // On top of the ball, light from above: open sky.
            let (open, spent) = shadow(
                &unit_ball(),
                &settings,
                &sh,
                DVec3::new(0.0, 1.01, 0.0),
                DVec3::Y,
                1e-3,
            );
            assert_eq!(open, 1.0, "softness {softness}");
            assert!(spent > 0);
            // Below the ball, light from above: blocked.
            let (blocked, _) = shadow(
                &unit_ball(),
                &settings,
                &sh,
                DVec3::new(0.0, -1.01, 0.0),
                DVec3::Y,
                1e-3,
            );
            assert_eq!(blocked, 0.0, "softness {softness}");
        }
        // A ray that grazes the ball is in the penumbra: strictly between.
        let sh = Shadows::default();
        let (partial, _) = shadow(
            &unit_ball(),
            &settings,
            &sh,
            DVec3::new(1.02, -1.0, 0.0),
            DVec3::Y,
            1e-3,
        );
        assert!(partial > 0.0 && partial < 1.0, "{partial}");
    }

    #[test]
    fn occlusion_is_one_in_the_open_and_less_in_a_crevice() {
        let ao = AmbientOcclusion::default();
        // On the ball's surface facing out, nothing is near: fully open.
        let (open, spent) = occlusion(
            &unit_ball(),
            &ao,
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::Y,
            1.0,
            1e-3,
        );
        assert!(open > 0.999, "{open}");
        assert_eq!(spent, ao.samples as u64);
        // Facing into the ball, the field closes in on every sample.
        let (closed, _) = occlusion(
            &unit_ball(),
            &ao,
            DVec3::new(0.0, 1.0, 0.0),
            -DVec3::Y,
            1.0,
            1e-3,
        );
        assert!(closed < 0.2, "{closed}");
    }

    #[test]
    fn cosine_sampling_has_the_right_mean_cosine() {
        // E[cos θ] under the pdf cos θ/π is 2/3.
        let n = DVec3::new(0.3, -0.5, 0.8).normalize();
        let count = 20_000u64;
        let mut sum = 0.0;
        for i in 0..count {
            let d = cosine_direction(
                n,
                crate::math::sample_1d(1, 0, i, 0, 0),
                crate::math::sample_1d(1, 0, i, 0, 1),
            );
            assert!((d.length() - 1.0).abs() < 1e-12 && d.dot(n) >= 0.0);
            sum += d.dot(n);
        }
        assert!(
            (sum / count as f64 - 2.0 / 3.0).abs() < 0.01,
            "{}",
            sum / count as f64
        );
        // Cone samples stay within the cone.
        let half = 0.5f64.to_radians();
        for i in 0..1000u64 {
            let d = cone_direction(
                n,
                half,
                crate::math::sample_1d(2, 0, i, 0, 0),
                crate::math::sample_1d(2, 0, i, 0, 1),
            );
            assert!(d.dot(n) >= half.cos() - 1e-12);
        }
    }

    /// A Look whose albedo is `a` everywhere (no trap colouring, no occlusion).
    fn grey(a: f32) -> Look {
        Look {
            base_colour: Vec3::splat(a),
            trap_x_colour: Vec3::splat(a),
            trap_y_colour: Vec3::splat(a),
            trap_z_colour: Vec3::splat(a),
            trap_occlusion: 0.0,
            light_colour: Vec3::ZERO,
            ..Look::default()
        }
    }

    fn furnace(look: &Look, fractal: &Fractal, samples: u64, bounces: u32) -> f64 {
        furnace_with(look, fractal, samples, bounces, None)
    }

    fn furnace_with(
        look: &Look,
        fractal: &Fractal,
        samples: u64,
        bounces: u32,
        environment: Option<&crate::environment::EnvironmentMap>,
    ) -> f64 {
        // Paths from points on the surface, under a sky of radiance 1 and no sun.
        let pt = PathTracing {
            max_bounces: bounces,
            sky: Sky::Constant(Vec3::ONE),
            ..PathTracing::default()
        };
        let settings = MarchSettings::default();
        let mut total = 0.0;
        let mut counts = StageCounts::default();
        let mut taken = 0;
        for i in 0..samples {
            // Start from where a ray from outside meets the surface.
            let u = |d: u32| crate::math::sample_1d(9, 1, i, 0, d);
            let from = DVec3::new(u(0) - 0.5, u(1) - 0.5, u(2) - 0.5).normalize() * 2.0;
            let ray = crate::march::Ray {
                origin: from,
                dir: -from.normalize(),
                pixel_angle: 1e-3,
                start_footprint: 0.0,
            };
            let Some(at) = surface_at(&ray, fractal, &settings) else {
                continue;
            };
            let random = |d: u32| crate::math::sample_1d(5, 2, i, 0, d);
            total += trace_path(
                look,
                &pt,
                fractal,
                &settings,
                &at,
                DVec3::Y,
                environment,
                &random,
                &mut counts,
            )
            .x as f64;
            taken += 1;
        }
        assert!(taken > samples / 2);
        total / taken as f64
    }

    #[test]
    fn paths_traced_together_match_paths_traced_alone() {
        // A row of camera samples on the bulb (misses among them), traced side
        // by side and one at a time: every radiance and count to the bit, with
        // a sun and an extra light, and with an uneven environment map too.
        let fractal = Fractal::default();
        let settings = MarchSettings::default();
        let look = Look {
            extra_lights: vec![Light {
                direction: DVec3::new(-1.0, 0.3, 0.2),
                colour: Vec3::new(0.4, 0.5, 0.9),
                intensity: 0.7,
            }],
            ..Look::default()
        };
        let starts: Vec<Option<SurfacePoint>> = (0..48)
            .map(|i| {
                let x = i as Real / 48.0 * 2.4 - 1.2;
                let ray = crate::march::Ray {
                    origin: DVec3::new(x, 0.3, 2.6),
                    dir: DVec3::new(0.0, -0.1, -1.0).normalize(),
                    pixel_angle: 2e-3,
                    start_footprint: 0.0,
                };
                surface_at(&ray, &fractal, &settings)
            })
            .collect();
        assert!(
            starts.iter().any(Option::is_none)
                && starts.iter().filter(|s| s.is_some()).count() > 20
        );
        let pixels: Vec<Vec3> = (0..128)
            .map(|i| Vec3::new(0.2 + (i % 7) as f32, 0.5, 0.1 * (i / 16) as f32))
            .collect();
        let map = crate::environment::EnvironmentMap::from_pixels(16, 8, pixels);
        for environment in [None, Some(&map)] {
            let pt = PathTracing {
                max_bounces: 6,
                ..PathTracing::default()
            };
            let random = |path: usize, d: u32| crate::math::sample_1d(3, 7, path as u64, 0, d);
            let mut together = PathScratch::default();
            trace_paths(
                &look,
                &pt,
                &fractal,
                &settings,
                &starts,
                DVec3::Y,
                environment,
                &random,
                &mut together,
            );
            let mut bounced = 0;
            for (i, start) in starts.iter().enumerate() {
                let (radiance, counts) = together.out[i];
                let Some(at) = start else {
                    assert_eq!(radiance, Vec3::ZERO);
                    assert_eq!(counts.bounces + counts.sun_rays, 0);
                    continue;
                };
                let mut alone = StageCounts::default();
                let single = trace_path(
                    &look,
                    &pt,
                    &fractal,
                    &settings,
                    at,
                    DVec3::Y,
                    environment,
                    &|d| random(i, d),
                    &mut alone,
                );
                assert_eq!(
                    radiance.to_array().map(f32::to_bits),
                    single.to_array().map(f32::to_bits),
                    "path {i}"
                );
                assert_eq!(
                    (counts.bounces, counts.sun_rays),
                    (alone.bounces, alone.sun_rays),
                    "path {i}"
                );
                bounced += (counts.bounces > 0) as usize;
            }
            assert!(bounced > 20);
        }
    }

    #[test]
    fn white_furnace_returns_the_albedo_on_a_convex_ball() {
        // On a convex ball every bounce escapes to the sky: radiance = albedo × 1,
        // exactly, on every path.
        let r = furnace(&grey(0.5), &unit_ball(), 200, 8);
        assert!((r - 0.5).abs() < 1e-3, "{r}");
    }

    #[test]
    fn white_furnace_holds_with_a_uniform_environment_map() {
        // A map of radiance 1 everywhere, lit through map sampling and bounce
        // sampling combined by their weights: still the albedo on the ball,
        // now within Monte Carlo error.
        let map = crate::environment::EnvironmentMap::from_pixels(16, 8, vec![Vec3::ONE; 128]);
        let r = furnace_with(&grey(0.5), &unit_ball(), 4000, 8, Some(&map));
        assert!((r - 0.5).abs() < 0.02, "{r}");
    }

    #[test]
    fn white_furnace_conserves_energy_in_the_bulb() {
        // Albedo 1 in a sky of radiance 1: however the paths wander in the
        // bulb's crevices, the expected radiance is 1 (Russian roulette keeps
        // it unbiased). 2000 paths: a few percent of Monte Carlo error.
        let r = furnace(&grey(1.0), &Fractal::default(), 2000, 64);
        assert!((r - 1.0).abs() < 0.05, "{r}");
        // A darker albedo a: a path escaping after k bounces brings a^k ≤ a, and
        // the crevices trap light, so 0 < radiance < a.
        let dark = furnace(&grey(0.6), &Fractal::default(), 2000, 64);
        assert!(dark > 0.2 && dark < 0.6, "{dark}");
    }

    #[test]
    fn every_light_adds_its_light_and_casts_its_shadow() {
        let one = Look {
            light_direction: DVec3::Y,
            ..Look::default()
        };
        let two = Look {
            extra_lights: vec![Light {
                direction: DVec3::X,
                colour: Vec3::ONE,
                intensity: 0.5,
            }],
            ..one.clone()
        };
        // On top of the ball, facing up and out along x: both lights reach it.
        let at = SurfacePoint {
            point: DVec3::new(1.0, 1.0, 0.0).normalize(),
            normal: DVec3::new(1.0, 1.0, 0.0).normalize(),
            view_dir: -DVec3::Z,
            t: 2.0,
            footprint: 1e-3,
            traps: OrbitTraps {
                origin: 1.0,
                planes: DVec3::splat(1.0),
            },
        };
        let effects = Effects {
            shadows: Some(Shadows::default()),
            ..Effects::default()
        };
        let (mut c1, mut c2) = (StageCounts::default(), StageCounts::default());
        let a = one.shade(
            &effects,
            &unit_ball(),
            &MarchSettings::default(),
            &at,
            &mut c1,
        );
        let b = two.shade(
            &effects,
            &unit_ball(),
            &MarchSettings::default(),
            &at,
            &mut c2,
        );
        let albedo = one.albedo(&at.traps);
        let extra = albedo * Vec3::ONE * (0.5 * std::f32::consts::FRAC_1_SQRT_2);
        assert!((b - a - extra).length() < 1e-5, "{b} vs {a} + {extra}");
        // One shadow march per light that faces the surface.
        assert!(c2.shadows > c1.shadows && c1.shadows > 0);
    }

    #[test]
    fn preetham_sky_is_brightest_near_the_sun_and_one_at_the_zenith() {
        let sun = DVec3::new(0.0, 0.5, 0.866).normalize();
        let luminance = |c: Vec3| 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
        let zenith = preetham(DVec3::Y, sun, 3.0);
        assert!((luminance(zenith) - 1.0).abs() < 0.05, "{zenith}");
        let near_sun = preetham(DVec3::new(0.0, 0.45, 0.89).normalize(), sun, 3.0);
        let away = preetham(DVec3::new(0.0, 0.45, -0.89).normalize(), sun, 3.0);
        assert!(
            luminance(near_sun) > 2.0 * luminance(away),
            "{near_sun} vs {away}"
        );
        // Clear skies are blue away from the sun.
        assert!(away.z > away.x, "{away}");
        // Finite everywhere, the ground and a sun at the zenith or below the horizon too.
        for s in [DVec3::Y, DVec3::new(1.0, -0.2, 0.0).normalize(), sun] {
            for d in [
                DVec3::Y,
                -DVec3::Y,
                DVec3::X,
                DVec3::new(0.3, -0.9, 0.1).normalize(),
            ] {
                for t in [2.0, 10.0] {
                    assert!(preetham(d, s, t).is_finite());
                }
            }
        }
    }

    #[test]
    fn fog_and_glow_fall_off_as_declared() {
        let fog = Fog {
            density: 1.0,
            colour: Vec3::ONE,
        };
        let c = Vec3::ZERO;
        assert_eq!(fogged(c, &fog, 0.0, 1.0), c);
        // One camera–target distance away at density 1: e^-1 of the surface is left.
        let f = fogged(c, &fog, 2.0, 2.0);
        assert!((f.x - (1.0 - (-1.0f32).exp())).abs() < 1e-6);
        let g = Glow {
            colour: Vec3::ONE,
            strength: 1.0,
            width: 2.0,
        };
        assert_eq!(glow(&g, 0.0), Vec3::ONE);
        assert!((glow(&g, 2.0).x - (-1.0f32).exp()).abs() < 1e-6);
        assert_eq!(glow(&g, Real::INFINITY), Vec3::ZERO);
    }

    fn traps_far() -> OrbitTraps {
        OrbitTraps {
            origin: 1.0,
            planes: DVec3::splat(1.0),
        }
    }

    #[test]
    fn lambert_is_ambient_only_facing_away_and_brightest_facing_light() {
        let look = Look::default();
        let light = look.light_direction.normalize();
        // With no effects, shading needs no estimates: the fractal is never asked.
        let plain = |normal: DVec3| {
            let at = SurfacePoint {
                point: DVec3::new(0.0, 5.0, 0.0),
                normal,
                view_dir: -normal,
                t: 1.0,
                footprint: 1e-3,
                traps: traps_far(),
            };
            let mut counts = StageCounts::default();
            let c = look.shade(
                &Effects::default(),
                &Fractal::default(),
                &MarchSettings::default(),
                &at,
                &mut counts,
            );
            assert_eq!(counts, StageCounts::default());
            c
        };
        let lit = plain(light);
        let unlit = plain(-light);
        let albedo = look.albedo(&traps_far());
        assert!((unlit - albedo * look.ambient).length() < 1e-6);
        assert!((lit - albedo * (look.ambient + look.light_colour)).length() < 1e-6);
    }

    #[test]
    fn far_traps_give_base_colour_and_plane_traps_pull() {
        let look = Look::default();
        assert!((look.albedo(&traps_far()) - look.base_colour).length() < 1e-6);
        let on_x_plane = OrbitTraps {
            planes: DVec3::new(0.0, 1.0, 1.0),
            ..traps_far()
        };
        assert!((look.albedo(&on_x_plane) - look.trap_x_colour).length() < 1e-6);
        let crevice = OrbitTraps {
            origin: 0.0,
            ..traps_far()
        };
        assert!(look.albedo(&crevice).length() < look.albedo(&traps_far()).length());
    }

    #[test]
    fn background_blends_bottom_to_top() {
        let look = Look::default();
        assert!((look.background(DVec3::Y, DVec3::Y) - look.background_top).length() < 1e-6);
        assert!((look.background(-DVec3::Y, DVec3::Y) - look.background_bottom).length() < 1e-6);
    }
}
