//! What a hit looks like: orbit-trap colour, one directional light with Lambert
//! diffuse plus ambient, and the background gradient for misses.
//!
//! Colouring idea from ../shared/seeds/000 (Quilez, "Coloring"): the three plane
//! traps blend a base colour towards three others, and the origin trap darkens
//! crevices like a cheap occlusion term.

use crate::fractal::OrbitTraps;
use crate::math::{mix, DVec3, Real, Vec3};
use serde::{Deserialize, Serialize};

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

    /// Radiance of a surface point with `normal` and orbit `traps`.
    pub fn surface(&self, normal: DVec3, traps: &OrbitTraps) -> Vec3 {
        let to_light = crate::math::normalize_or(self.light_direction, DVec3::Y);
        let lambert = normal.dot(to_light).max(0.0) as f32;
        self.albedo(traps) * (self.ambient + self.light_colour * lambert)
    }

    /// Radiance of the background seen along `dir`, with `up` the camera's up vector.
    pub fn background(&self, dir: DVec3, up: DVec3) -> Vec3 {
        let t = (0.5 + 0.5 * dir.dot(up)) as f32;
        mix(self.background_bottom, self.background_top, t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
