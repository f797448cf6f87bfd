//! What a hit looks like: orbit-trap colour, one directional light with Lambert
//! diffuse plus ambient, the background gradient for misses, and the optional
//! effects a scene declares (shadows, ambient occlusion, specular, fog, glow).
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

/// Estimates spent by the shading stages of one sample.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StageCounts {
    pub shadows: u64,
    pub occlusion: u64,
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
    let Some((_, t_exit)) = sphere_interval(from, to_light, settings.bounding_radius) else {
        return (1.0, 0);
    };
    let eps = settings.hit_threshold * footprint;
    let mut t = 2.0 * footprint;
    let mut light: Real = 1.0;
    let mut spent = 0;
    for _ in 0..shadows.max_steps {
        if t > t_exit {
            break;
        }
        let e = fractal.estimate(from + to_light * t, footprint);
        spent += e.orbits as u64;
        if !e.escaped || e.distance < eps {
            return (0.0, spent);
        }
        if shadows.softness > 0.0 {
            light = light.min(shadows.softness * e.distance / t);
        }
        t += e.distance * settings.fudge;
    }
    (light.clamp(0.0, 1.0) as f32, spent)
}

/// Ambient light reaching a surface point: 1 in the open, less in crevices.
pub fn occlusion(
    fractal: &Fractal,
    ao: &AmbientOcclusion,
    point: DVec3,
    normal: DVec3,
    t: Real,
    footprint: Real,
) -> (f32, u64) {
    let mut blocked = 0.0;
    let mut weights = 0.0;
    let mut weight = 1.0;
    let mut spent = 0;
    let n = ao.samples.max(1);
    for i in 1..=n {
        let d = ao.radius * t * i as Real / n as Real;
        let e = fractal.estimate(point + normal * d, footprint);
        spent += e.orbits as u64;
        // Where the field is nearer than the distance stepped, geometry crowds
        // in. The estimate is about half the true distance near the surface
        // (the ½ in ½·ln r·r/dr, kept for safe marching), so double it here.
        blocked += weight * ((d - 2.0 * e.distance) / d).clamp(0.0, 1.0);
        weights += weight;
        weight *= 0.6;
    }
    let ambient = 1.0 - ao.strength as Real * blocked / weights;
    (ambient.clamp(0.0, 1.0) as f32, spent)
}

/// Colours and light of a scene. Colours are linear RGB.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Look {
    /// Direction towards the light (need not be unit length).
    pub light_direction: DVec3,
    pub light_colour: Vec3,
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
}

impl Default for Look {
    fn default() -> Self {
        Look {
            light_direction: DVec3::new(0.6, 0.8, 0.5),
            light_colour: Vec3::new(1.0, 0.95, 0.85),
            ambient: Vec3::new(0.12, 0.13, 0.16),
            base_colour: Vec3::new(0.75, 0.72, 0.68),
            trap_x_colour: Vec3::new(0.75, 0.28, 0.08),
            trap_y_colour: Vec3::new(0.10, 0.35, 0.65),
            trap_z_colour: Vec3::new(0.85, 0.65, 0.20),
            trap_occlusion: 0.8,
            background_top: Vec3::new(0.02, 0.03, 0.06),
            background_bottom: Vec3::new(0.10, 0.09, 0.12),
        }
    }
}

impl Look {
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

    /// Radiance of a surface point with `normal` and orbit `traps`, no effects.
    pub fn surface(&self, normal: DVec3, traps: &OrbitTraps) -> Vec3 {
        let to_light = normalize_or(self.light_direction, DVec3::Y);
        let lambert = normal.dot(to_light).max(0.0) as f32;
        self.albedo(traps) * (self.ambient + self.light_colour * lambert)
    }

    /// Radiance of a hit with the scene's effects. Stages of effects that are
    /// off never run; `counts` hears what the others spent.
    pub fn shade(
        &self,
        effects: &Effects,
        fractal: &Fractal,
        settings: &MarchSettings,
        at: &SurfacePoint,
        counts: &mut StageCounts,
    ) -> Vec3 {
        let to_light = normalize_or(self.light_direction, DVec3::Y);
        let lambert = at.normal.dot(to_light).max(0.0) as f32;
        let mut light = 1.0f32;
        if let (Some(sh), true) = (&effects.shadows, lambert > 0.0) {
            // Start a couple of footprints off the surface so it does not shadow itself.
            let from = at.point + at.normal * (2.0 * at.footprint);
            let (f, spent) = shadow(fractal, settings, sh, from, to_light, at.footprint);
            light = f;
            counts.shadows += spent;
        }
        let mut ambient = 1.0f32;
        if let Some(ao) = &effects.ambient_occlusion {
            let (a, spent) = occlusion(fractal, ao, at.point, at.normal, at.t, at.footprint);
            ambient = a;
            counts.occlusion += spent;
        }
        let mut c = self.albedo(&at.traps)
            * (self.ambient * ambient + self.light_colour * (lambert * light));
        if let (Some(sp), true) = (&effects.specular, lambert > 0.0) {
            let half = normalize_or(to_light - at.view_dir, at.normal);
            let highlight = (at.normal.dot(half).max(0.0) as f32).powf(sp.shininess);
            c += self.light_colour * (sp.strength * highlight * light);
        }
        c
    }

    /// Radiance of the background seen along `dir`, with `up` the camera's up vector.
    pub fn background(&self, dir: DVec3, up: DVec3) -> Vec3 {
        let t = (0.5 + 0.5 * dir.dot(up)) as f32;
        mix(self.background_bottom, self.background_top, t)
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
    use crate::fractal::Formula;

    fn unit_ball() -> Fractal {
        Fractal {
            formula: Formula::Quilez,
            julia: Some(DVec3::ZERO),
            iterations: 40,
            ..Fractal::default()
        }
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
        let lit = look.surface(light, &traps_far());
        let unlit = look.surface(-light, &traps_far());
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
