//! Whether a scene can be rendered: every animatable field within the range
//! its `parameters` entry gives, the fields no track animates within theirs,
//! and fields that depend on one another consistent (a view direction, path
//! tracing without the effects it replaces).

use super::checks::{colour, counted, non_negative, rule, Checked};
use super::limits::{
    refine_outside, MAX_BOUNCES, MAX_CONE_RAYS, MAX_OCCLUSION_SAMPLES, MAX_REFINE_STEPS,
    MAX_SAMPLES, MAX_SHADOW_STEPS,
};
use super::messages::Shown;
use super::parameters::Parameter;
use super::parameters::{
    AMBIENT_OCCLUSION, CAMERA, FOG, FRACTAL, GLOW, LOOK, PALETTE, QUALITY, SHADOWS, SPECULAR,
};
use crate::error::Result;
use crate::math::{direction, Real};
use crate::scene::Scene;
use crate::shade::{Effects, PathTracing, Sky};

/// A field's problem: its path in the scene and the message.
type Invalid = (String, String);

/// `checked`'s problem, at `field`.
fn at(field: &str, checked: Checked) -> Result<(), Invalid> {
    checked.map_err(|message| (field.to_string(), message))
}

/// The range checks of a group of animatable parameters, in its order.
fn animatable(s: &Scene, group: &[Parameter]) -> Result<(), Invalid> {
    group.iter().try_for_each(|p| at(p.name, (p.check)(s)))
}

/// Quality's and look's checks in the order validation has always made
/// them, which decides the field named when several are wrong; the table
/// lists them in the order the docs and the track message do.
pub(super) const QUALITY_CHECKS: [&str; 7] = [
    "quality.hit_threshold",
    "quality.normal_step",
    "quality.bounding_radius",
    "quality.membership_step",
    "quality.fudge",
    "quality.over_relaxation",
    "quality.max_steps",
];
pub(super) const LOOK_CHECKS: [&str; 11] = [
    "look.light_direction",
    "look.light_colour",
    "look.ambient",
    "look.base_colour",
    "look.trap_x_colour",
    "look.trap_y_colour",
    "look.trap_z_colour",
    "look.background_top",
    "look.background_bottom",
    "look.trap_occlusion",
    "look.exposure",
];

/// The range checks of `group`'s parameters named in `order`, in that order.
fn animatable_in(s: &Scene, group: &[Parameter], order: &[&str]) -> Result<(), Invalid> {
    order.iter().try_for_each(|name| {
        let p = group.iter().find(|p| p.name == *name);
        p.map_or(Ok(()), |p| at(p.name, (p.check)(s)))
    })
}

/// Checks one frame's scene; on failure returns the field path and the problem.
pub fn validate_scene(s: &Scene) -> Result<(), Invalid> {
    animatable(s, CAMERA)?;
    view(s)?;
    animatable(s, FRACTAL)?;
    animatable_in(s, QUALITY, &QUALITY_CHECKS)?;
    at(
        "quality.cone_rays",
        counted(s.quality.cone_rays, MAX_CONE_RAYS),
    )?;
    let refine = s.quality.refine_steps;
    at(
        "quality.refine_steps",
        rule(refine <= MAX_REFINE_STEPS, || refine_outside(refine)),
    )?;
    at(
        "samples_per_pixel",
        counted(s.samples_per_pixel, MAX_SAMPLES),
    )?;
    if let Some(a) = &s.adaptive {
        at("adaptive.first", counted(a.first, MAX_SAMPLES))?;
        at("adaptive.noise", noise(a.noise))?;
    }
    animatable_in(s, LOOK, &LOOK_CHECKS)?;
    palette(s)?;
    extra_lights(s)?;
    effects(s)
}

/// Adaptive sampling's noise: a display value's error, from 0.0001 (below
/// that no pixel would ever stop short of its cap) to 1.
fn noise(x: f32) -> Checked {
    rule((1e-4..=1.0).contains(&x), || {
        format!("must be from 0.0001 to 1 (an error in display values), got {x}")
    })
}

/// The view direction the camera's position, target and up give.
fn view(s: &Scene) -> Result<(), Invalid> {
    let c = &s.camera;
    let view = -c.relative_position();
    // Below a few ulps of the coordinates the view direction is noise,
    // unless the scene knows the position exactly (digits, or placed by
    // `camera.distance`).
    let exact = c.offset.is_some() || c.position_digits.is_some() || c.target_digits.is_some();
    let coincide = if exact {
        // Offsets are f64: past this a pixel nears the end of its range.
        rule(crate::math::length(view) >= crate::deep::DEEPEST, || {
            format!(
                "the camera is closer to its target than {:.0e}, the deepest a frame can be \
                 (offsets are f64, whose range ends at 2.2e-308)",
                crate::deep::DEEPEST
            )
        })
    } else {
        let scale = c
            .position
            .abs()
            .max_element()
            .max(c.target.abs().max_element())
            .max(1.0);
        rule(view.length() > 8.0 * Real::EPSILON * scale, || {
            format!(
                "the camera position and target coincide (closer than {:.1e}, the limit of f64 at this scale; write the target as a string of digits, or place the camera with camera.distance, to go deeper)",
                8.0 * Real::EPSILON * scale
            )
        })
    };
    at("camera.target", coincide)?;
    let parallel = rule(direction(view).cross(c.up).length() > 1e-9, || {
        format!(
            "must not be zero or parallel to the view direction, got {}",
            c.up.shown()
        )
    });
    at("camera.up", parallel)
}

/// The look's palette, where it has one: 1 to `MAX_STOPS` stops, then
/// each animatable part (stops in order, within [0, 1]).
fn palette(s: &Scene) -> Result<(), Invalid> {
    let Some(p) = &s.look.palette else {
        return Ok(());
    };
    let (count, most) = (p.stops.len(), crate::shade::MAX_STOPS);
    let stops = rule((1..=most).contains(&count), || {
        format!("a palette has 1 to {most} stops, got {count}")
    });
    at("look.palette.stops", stops)?;
    animatable(s, PALETTE)
}

fn extra_lights(s: &Scene) -> Result<(), Invalid> {
    let lights = &s.look.extra_lights;
    let most = crate::shade::MAX_LIGHTS - 1;
    let count = rule(lights.len() <= most, || {
        format!("at most {most} extra lights, got {}", lights.len())
    });
    at("look.extra_lights", count)?;
    for (i, light) in lights.iter().enumerate() {
        let field = |name: &str| format!("look.extra_lights[{i}].{name}");
        let direction = rule(
            light.direction.is_finite() && light.direction.length() > 0.0,
            || {
                format!(
                    "must be a finite non-zero vector, got {}",
                    light.direction.shown()
                )
            },
        );
        at(&field("direction"), direction)?;
        at(&field("colour"), colour(light.colour))?;
        at(&field("intensity"), non_negative(light.intensity))?;
    }
    Ok(())
}

/// Each enabled effect's settings, an effect's animatable ones among them.
fn effects(s: &Scene) -> Result<(), Invalid> {
    let e = &s.effects;
    animatable(s, SHADOWS)?;
    if let Some(sh) = &e.shadows {
        at(
            "effects.shadows.max_steps",
            counted(sh.max_steps, MAX_SHADOW_STEPS),
        )?;
    }
    if let Some(ao) = &e.ambient_occlusion {
        at(
            "effects.ambient_occlusion.samples",
            counted(ao.samples, MAX_OCCLUSION_SAMPLES),
        )?;
    }
    animatable(s, AMBIENT_OCCLUSION)?;
    animatable(s, SPECULAR)?;
    animatable(s, FOG)?;
    if let Some(pt) = &e.path_tracing {
        path_tracing(pt, e)?;
    }
    if let Some(m) = &e.motion_blur {
        let shutter = rule(
            m.shutter.is_finite() && m.shutter > 0.0 && m.shutter <= 1.0,
            || {
                format!(
                    "must be in (0, 1] of the frame interval, got {}",
                    m.shutter.shown()
                )
            },
        );
        at("effects.motion_blur.shutter", shutter)?;
    }
    animatable(s, GLOW)
}

fn path_tracing(pt: &PathTracing, e: &Effects) -> Result<(), Invalid> {
    let alone = rule(
        e.shadows.is_none() && e.ambient_occlusion.is_none() && e.specular.is_none(),
        || {
            "path tracing computes shadows and occlusion itself: remove shadows, ambient_occlusion and specular".into()
        },
    );
    at("effects.path_tracing", alone)?;
    at(
        "effects.path_tracing.max_bounces",
        counted(pt.max_bounces, MAX_BOUNCES),
    )?;
    let sun = pt.sun_angle_degrees;
    let sun_angle = rule(sun.is_finite() && (0.0..=30.0).contains(&sun), || {
        format!("must be 0..=30, got {}", sun.shown())
    });
    at("effects.path_tracing.sun_angle_degrees", sun_angle)?;
    at(
        "effects.path_tracing.sky_intensity",
        non_negative(pt.sky_intensity),
    )?;
    match pt.sky {
        Sky::Constant(c) => at("effects.path_tracing.sky", colour(c)),
        Sky::Preetham { turbidity } => {
            let ok = turbidity.is_finite() && (1.7..=12.0).contains(&turbidity);
            let checked = rule(ok, || {
                format!(
                    "Preetham turbidity must be 1.7..=12, got {}",
                    turbidity.shown()
                )
            });
            at("effects.path_tracing.sky.turbidity", checked)
        }
        Sky::Environment {
            rotation_degrees, ..
        } => {
            let checked = rule(rotation_degrees.is_finite(), || {
                format!(
                    "Environment rotation_degrees must be finite, got {}",
                    rotation_degrees.shown()
                )
            });
            at("effects.path_tracing.sky.rotation_degrees", checked)
        }
        Sky::Gradient => Ok(()),
    }
}
