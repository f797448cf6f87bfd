//! Direct lighting: orbit-trap albedo, Lambert diffuse from each light
//! plus ambient, specular, and the background gradient for misses.

use super::look::Look;
#[cfg(test)]
use super::shadow::occlusion;
use super::shadow::{shadow_origin, ShadowWalk};
use super::{Effects, StageCounts, SurfacePoint};
#[cfg(test)]
use crate::fractal::Fractal;
use crate::fractal::OrbitTraps;
use crate::march::MarchSettings;
use crate::math::{mix, normalize_or, DVec3, Real, Vec3};

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

    /// Albedo of the surface from its orbit traps, and the palette's
    /// colour there (`SurfacePoint::palette_colour`) where the look has a
    /// palette.
    pub fn albedo(&self, traps: &OrbitTraps, palette_colour: Option<Vec3>) -> Vec3 {
        // A plane trap pulls hardest when the orbit passed close to that plane.
        let pull = |d: Real| (1.0 - (d * 4.0).min(1.0)) as f32;
        let mut c = self.base_colour;
        c = mix(c, self.trap_x_colour, pull(traps.planes.x));
        c = mix(c, self.trap_y_colour, pull(traps.planes.y) * 0.8);
        c = mix(c, self.trap_z_colour, pull(traps.planes.z) * 0.6);
        if let (Some(palette), Some(colour)) = (&self.palette, palette_colour) {
            c = mix(c, colour, palette.mix);
        }
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
    pub(super) fn facing<'a>(
        &'a self,
        at: &'a SurfacePoint,
    ) -> impl Iterator<Item = (DVec3, Vec3, f32)> + 'a {
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
        let albedo = self.albedo(&at.traps, at.palette_colour);
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
