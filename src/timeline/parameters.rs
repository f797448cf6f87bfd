//! Every parameter a track can animate, described once: its name, shape,
//! the range a scene holds it to and how a track's value sets it. Track
//! names, `Track`'s setter, `validate_scene`'s range checks of these fields
//! and the docs' table of parameters all come from `GROUPS`.

use super::checks::{colour, counted, non_negative, positive, rule, Checked};
use super::limits::{MAX_ITERATIONS, MAX_MARCH_STEPS};
use super::messages::Shown;
use crate::camera::Projection;
use crate::exact::{Coordinates, Digits};
use crate::math::{DVec3, Real, Vec3};
use crate::scene::Scene;
use crate::shade::{Stop, MAX_STOPS};
use Shape::{Number, Triple};

/// A parameter's value: one number, or a triple such as a position or colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shape {
    Number,
    Triple,
}

impl Shape {
    /// How many numbers a value of this shape holds.
    pub const fn components(self) -> usize {
        match self {
            Number => 1,
            Triple => 3,
        }
    }
}

/// One animatable parameter.
#[derive(Clone, Copy, Debug)]
pub struct Parameter {
    /// The track's name, the field's path in the scene.
    pub name: &'static str,
    pub shape: Shape,
    /// The docs' value column: the shape, and what is special about it.
    /// Read by the test that holds docs/timeline.md's table to this one.
    #[cfg_attr(not(test), allow(dead_code))]
    pub doc: &'static str,
    /// The scene's value within its range, else what is wrong with it
    /// (validation adds the field). A disabled effect's fields pass.
    pub check: fn(&Scene) -> Checked,
    /// Writes a track's sampled value, `shape.components()` numbers.
    pub set: fn(&mut Scene, &[Real]),
    /// Where the parameter may be written as digits (a point a deep frame
    /// needs more exactly than f64 holds): how a scene holds them.
    pub digits: Option<Exact>,
}

/// A parameter's value with its digits, in a scene.
#[derive(Clone, Copy, Debug)]
pub struct Exact {
    /// The value with its digits, where the scene has digits for it.
    pub get: fn(&Scene) -> Option<Coordinates>,
    /// Writes a value and its digits.
    pub set: fn(&mut Scene, Coordinates),
}

/// The docs' value of a point whose keys may be strings of digits.
const DIGITS_TRIPLE: &str = "triple, or strings of digits (deep zooms)";

/// The track that sets the camera–target distance, interpolated in log space.
pub const ZOOM_TRACK: &str = "camera.distance";

/// The largest camera position or target component a scene may have: the
/// bulb is a unit across, so from farther it is below a pixel of any field
/// of view, and the view's length would overflow.
const MAX_COORDINATE: Real = 1e15;

/// The largest Julia constant component a scene may have. Past a bailout
/// plus its power every point escapes at the first step and the set is
/// empty; far past it |z|² overflows (f32 near 1e19, f64 near 1e154), which
/// would read as a surface.
const MAX_JULIA: Real = 1e15;

/// The largest bounding sphere a scene may have: the set lies within the
/// bailout, a few units across; a sphere far larger leaves rays to run out
/// of steps in empty space.
const MAX_BOUNDING_RADIUS: Real = 1e6;

/// Membership steps longer than this many footprints would step over
/// whole features: the setting is a fraction of a pixel, or a few.
const MAX_MEMBERSHIP_STEP: Real = 16.0;
/// Shorter steps would spend a ray's `max_steps` creeping along the
/// surface, and then stop it anywhere.
const MIN_MEMBERSHIP_STEP: Real = 0.01;

/// The narrowest field of view. A ray's points are its origin plus a
/// distance along it, so they are placed no finer than 2⁻⁵² of the camera's
/// distance, while a pixel is as wide as its angle times that distance: a
/// pixel's angle must stay well above 2⁻⁵² (64 times, 1.4e-14 radians) for
/// marching to resolve it. 1e-7° over 32 768 rows is 5.3e-14 radians a
/// pixel. (A camera a billion units away frames the bulb at 1.03e-7°.)
pub const MIN_FOV_DEGREES: Real = 1e-7;

/// Every animatable parameter, group by group in the order validation
/// checks them (`validate_scene` runs each group's checks between the
/// scene's other ones; quality's and look's in `validate::*_CHECKS` order).
pub const GROUPS: [&[Parameter]; 10] = [
    CAMERA,
    FRACTAL,
    QUALITY,
    LOOK,
    PALETTE,
    SHADOWS,
    AMBIENT_OCCLUSION,
    SPECULAR,
    FOG,
    GLOW,
];

/// Every parameter a track can animate, with its number of components.
pub const PARAMETERS: &[(&str, usize)] = &{
    let mut all = [("", 0); COUNT];
    let (mut g, mut i) = (0, 0);
    while g < GROUPS.len() {
        let mut k = 0;
        while k < GROUPS[g].len() {
            all[i] = (GROUPS[g][k].name, GROUPS[g][k].shape.components());
            (i, k) = (i + 1, k + 1);
        }
        g += 1;
    }
    all
};

/// How many parameters `GROUPS` holds.
const COUNT: usize = {
    let (mut n, mut g) = (0, 0);
    while g < GROUPS.len() {
        n += GROUPS[g].len();
        g += 1;
    }
    n
};

/// Every animatable parameter, in the table's order.
pub fn all() -> impl Iterator<Item = &'static Parameter> {
    GROUPS.iter().flat_map(|group| group.iter())
}

/// The parameter a track named `name` animates.
pub fn find(name: &str) -> Option<&'static Parameter> {
    all().find(|p| p.name == name)
}

/// The docs' table of parameters, in Markdown: a row for the parameters
/// of a group described alike, in the table's order.
#[cfg(test)]
pub fn markdown_table() -> String {
    let mut rows: Vec<(&str, &str, Vec<String>)> = Vec::new();
    for p in all() {
        let group = p.name.split('.').next().unwrap_or(p.name);
        let name = format!("`{}`", p.name);
        match rows
            .iter_mut()
            .find(|(g, doc, _)| *g == group && *doc == p.doc)
        {
            Some((_, _, names)) => names.push(name),
            None => rows.push((group, p.doc, vec![name])),
        }
    }
    let mut table = String::from("| parameter | value |\n|---|---|\n");
    for (_, doc, names) in rows {
        table += &format!("| {} | {doc} |\n", names.join(", "));
    }
    table
}

fn triple(v: &[Real]) -> DVec3 {
    DVec3::new(v[0], v[1], v[2])
}

fn colour_of(v: &[Real]) -> Vec3 {
    Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
}

fn number(v: &[Real]) -> Real {
    v[0]
}

fn number_f32(v: &[Real]) -> f32 {
    v[0] as f32
}

fn count(v: &[Real]) -> u32 {
    v[0].round().clamp(0.0, u32::MAX as Real) as u32
}

/// Each component finite and within ±`limit`.
fn within(v: DVec3, limit: Real) -> Checked {
    rule(v.is_finite() && v.abs().max_element() <= limit, || {
        format!(
            "each component must be finite and within ±{limit:e}, got {}",
            v.shown()
        )
    })
}

fn finite<T: Shown>(finite: bool, v: T) -> Checked {
    rule(finite, || format!("must be finite, got {}", v.shown()))
}

/// A direction: finite and not zero.
fn direction(v: DVec3) -> Checked {
    rule(v.is_finite() && v.length() > 0.0, || {
        format!("must be a finite non-zero vector, got {}", v.shown())
    })
}

/// From 0 to 1, a fraction.
fn fraction(v: f32) -> Checked {
    rule(v.is_finite() && (0.0..=1.0).contains(&v), || {
        format!("must be in [0, 1], got {}", v.shown())
    })
}

pub(super) const CAMERA: &[Parameter] = &[
    Parameter {
        name: "camera.position",
        shape: Triple,
        digits: Some(Exact {
            get: |s| exact(s.camera.position, &s.camera.position_digits),
            set: |s, p| {
                s.camera.position = p.value;
                (s.camera.position_digits, s.camera.offset) = (p.digits, None);
            },
        }),
        doc: DIGITS_TRIPLE,
        check: |s| within(s.camera.position, MAX_COORDINATE),
        set: |s, v| {
            s.camera.position = triple(v);
            (s.camera.position_digits, s.camera.offset) = (None, None);
        },
    },
    Parameter {
        name: "camera.target",
        shape: Triple,
        digits: Some(Exact {
            get: |s| exact(s.camera.target, &s.camera.target_digits),
            set: |s, p| {
                s.camera.target = p.value;
                s.camera.target_digits = p.digits;
            },
        }),
        doc: DIGITS_TRIPLE,
        check: |s| within(s.camera.target, MAX_COORDINATE),
        set: |s, v| {
            s.camera.target = triple(v);
            s.camera.target_digits = None;
        },
    },
    Parameter {
        name: "camera.up",
        shape: Triple,
        digits: None,
        doc: "triple",
        check: |s| finite(s.camera.up.is_finite(), s.camera.up),
        set: |s, v| s.camera.up = triple(v),
    },
    Parameter {
        name: "camera.roll_degrees",
        shape: Number,
        digits: None,
        doc: "number",
        check: |s| finite(s.camera.roll_degrees.is_finite(), s.camera.roll_degrees),
        set: |s, v| s.camera.roll_degrees = v[0],
    },
    Parameter {
        name: "camera.fov_degrees",
        shape: Number,
        digits: None,
        doc: "number",
        check: |s| fov(s.camera.fov_degrees),
        set: |s, v| s.camera.fov_degrees = v[0],
    },
    Parameter {
        name: ZOOM_TRACK,
        shape: Number,
        digits: None,
        doc: "number > 0: the surface zoom (below)",
        // Not a field of the scene: its keys are checked (`Track::build`),
        // and the position it places the camera at.
        check: |_| Ok(()),
        set: |s, v| {
            let c = &mut s.camera;
            let away = crate::math::normalize_or(c.relative_position(), DVec3::Z);
            c.offset = Some(away * v[0]);
            c.position = c.target + away * v[0];
            c.position_digits = None;
        },
    },
    Parameter {
        name: "camera.aperture_radius",
        shape: Number,
        digits: None,
        doc: "number",
        check: |s| {
            let r = s.camera.aperture_radius;
            rule(r.is_finite() && r >= 0.0, || {
                format!("must be 0 (a pinhole) or positive, got {}", r.shown())
            })
        },
        set: |s, v| s.camera.aperture_radius = v[0],
    },
    Parameter {
        name: "camera.focus_distance",
        shape: Number,
        digits: None,
        doc: "number",
        check: |s| s.camera.focus_distance.map_or(Ok(()), positive),
        set: |s, v| s.camera.focus_distance = Some(v[0]),
    },
    Parameter {
        name: FISHEYE_DEGREES,
        shape: Number,
        digits: None,
        doc: "number (the scene's projection must be a `Fisheye`)",
        check: |s| match s.camera.projection {
            Projection::Fisheye { degrees } => fisheye_degrees(degrees),
            Projection::Perspective | Projection::Equirectangular => Ok(()),
        },
        set: |s, v| {
            if let Projection::Fisheye { degrees } = &mut s.camera.projection {
                *degrees = v[0];
            }
        },
    },
    Parameter {
        name: EYE_SEPARATION,
        shape: Number,
        digits: None,
        doc: "number (the scene must have `camera.stereo`)",
        check: |s| {
            s.camera.stereo.map_or(Ok(()), |stereo| {
                let e = stereo.eye_separation;
                rule(e.is_finite() && (0.0..=1.0).contains(&e), || {
                    format!(
                        "must be from 0 to 1 (a share of the camera–target distance), got {}",
                        e.shown()
                    )
                })
            })
        },
        set: |s, v| {
            s.camera
                .stereo
                .iter_mut()
                .for_each(|e| e.eye_separation = v[0])
        },
    },
];

/// The fisheye's angle across its circle, animatable.
pub const FISHEYE_DEGREES: &str = "camera.projection.degrees";
/// The stereo eyes' separation, animatable.
pub const EYE_SEPARATION: &str = "camera.stereo.eye_separation";

/// A fisheye's angle: its pixels span `degrees` over the circle's
/// diameter, so `MIN_FOV_DEGREES` bounds it for the same reason as a
/// pinhole's field of view.
fn fisheye_degrees(degrees: Real) -> Checked {
    let ok = degrees.is_finite() && (MIN_FOV_DEGREES..=360.0).contains(&degrees);
    rule(ok, || {
        format!(
            "a fisheye's angle must be from {MIN_FOV_DEGREES:e} to 360 degrees, got {}{}",
            degrees.shown(),
            if degrees > 0.0 && degrees < MIN_FOV_DEGREES {
                " (narrower, a pixel would span less than f64 can tell apart along a ray)"
            } else {
                ""
            }
        )
    })
}

/// What `scene`'s camera lacks for parameter `name` to mean anything, if
/// it does: a fisheye's angle needs a fisheye, the eyes' separation stereo.
/// A track or an explorer's value for it is refused then, as for an
/// effect the scene leaves off.
pub fn camera_lacks(scene: &Scene, name: &str) -> Option<&'static str> {
    let c = &scene.camera;
    match name {
        FISHEYE_DEGREES if !matches!(c.projection, Projection::Fisheye { .. }) => {
            Some("a fisheye projection: set scene.camera.projection to Fisheye(degrees: …)")
        }
        EYE_SEPARATION if c.stereo.is_none() => {
            Some("stereo: add stereo: (eye_separation: …, layout: SideBySide) to scene.camera")
        }
        _ => None,
    }
}

fn fov(fov: Real) -> Checked {
    rule(
        fov.is_finite() && (MIN_FOV_DEGREES..179.0).contains(&fov),
        || {
            format!(
                "must be from {MIN_FOV_DEGREES:e} to below 179 degrees, got {}{}",
                fov.shown(),
                if fov > 0.0 && fov < MIN_FOV_DEGREES {
                    " (narrower, a pixel would span less than f64 can tell apart along a \
                     ray; move the camera closer instead)"
                } else {
                    ""
                }
            )
        },
    )
}

pub(super) const FRACTAL: &[Parameter] = &[
    Parameter {
        name: "fractal.power",
        shape: Number,
        digits: None,
        doc: "number",
        check: |s| {
            let p = s.fractal.power;
            rule(p.is_finite() && (1.0..=64.0).contains(&p), || {
                format!("must be between 1 and 64, got {}", p.shown())
            })
        },
        set: |s, v| s.fractal.power = v[0],
    },
    Parameter {
        name: "fractal.iterations",
        shape: Number,
        digits: None,
        doc: "number, rounded to a whole count",
        check: |s| counted(s.fractal.iterations, MAX_ITERATIONS),
        set: |s, v| s.fractal.iterations = count(v),
    },
    Parameter {
        name: "fractal.bailout",
        shape: Number,
        digits: None,
        doc: "number",
        check: |s| bailout(s.fractal.bailout, s.fractal.power),
        set: |s, v| s.fractal.bailout = v[0],
    },
    Parameter {
        name: "fractal.julia",
        shape: Triple,
        digits: Some(Exact {
            get: |s| exact(s.fractal.julia?, &s.fractal.julia_digits),
            set: |s, p| {
                s.fractal.julia = Some(p.value);
                s.fractal.julia_digits = p.digits;
            },
        }),
        doc: "triple, or strings of digits: the Julia-c morph (switches to Julia mode)",
        check: |s| s.fractal.julia.map_or(Ok(()), |k| within(k, MAX_JULIA)),
        set: |s, v| {
            s.fractal.julia = Some(triple(v));
            s.fractal.julia_digits = None;
        },
    },
];

/// `value` with `digits`, where there are digits.
fn exact(value: DVec3, digits: &Option<Digits>) -> Option<Coordinates> {
    let digits = digits.clone()?;
    Some(Coordinates {
        value,
        digits: Some(digits),
    })
}

/// Above 1, and small enough for the power (checked first) to raise it to.
fn bailout(bailout: Real, power: Real) -> Checked {
    rule(bailout.is_finite() && bailout > 1.0, || {
        format!("must be a finite number above 1, got {}", bailout.shown())
    })?;
    // An orbit at the bailout is raised to the power once more: keep that finite.
    rule(power * bailout.ln() < 600.0, || {
        format!(
            "bailout^power must stay below e^600 (f64 overflows near e^709), got {}^{}",
            bailout.shown(),
            power.shown()
        )
    })
}

pub(super) const QUALITY: &[Parameter] = &[
    Parameter {
        name: "quality.hit_threshold",
        shape: Number,
        digits: None,
        doc: "number",
        check: |s| positive(s.quality.hit_threshold),
        set: |s, v| s.quality.hit_threshold = v[0],
    },
    Parameter {
        name: "quality.membership_step",
        shape: Number,
        digits: None,
        doc: "number",
        check: |s| {
            let step = s.quality.membership_step;
            rule(
                step == 0.0 || (MIN_MEMBERSHIP_STEP..=MAX_MEMBERSHIP_STEP).contains(&step),
                || {
                    format!(
                        "must be 0 (trust the estimate) or from {MIN_MEMBERSHIP_STEP} to \
                         {MAX_MEMBERSHIP_STEP} footprints, got {}",
                        step.shown()
                    )
                },
            )
        },
        set: |s, v| s.quality.membership_step = v[0],
    },
    Parameter {
        name: "quality.fudge",
        shape: Number,
        digits: None,
        doc: "number",
        check: |s| {
            let f = s.quality.fudge;
            rule(f.is_finite() && f > 0.0 && f <= 1.0, || {
                format!("must be in (0, 1], got {}", f.shown())
            })
        },
        set: |s, v| s.quality.fudge = v[0],
    },
    Parameter {
        name: "quality.max_steps",
        shape: Number,
        digits: None,
        doc: "number, rounded",
        check: |s| counted(s.quality.max_steps, MAX_MARCH_STEPS),
        set: |s, v| s.quality.max_steps = count(v),
    },
    Parameter {
        name: "quality.normal_step",
        shape: Number,
        digits: None,
        doc: "number",
        check: |s| positive(s.quality.normal_step),
        set: |s, v| s.quality.normal_step = v[0],
    },
    Parameter {
        name: "quality.bounding_radius",
        shape: Number,
        digits: None,
        doc: "number",
        check: |s| {
            let r = s.quality.bounding_radius;
            positive(r)?;
            rule(r <= MAX_BOUNDING_RADIUS, || {
                format!("must be at most {MAX_BOUNDING_RADIUS:e}, got {}", r.shown())
            })
        },
        set: |s, v| s.quality.bounding_radius = v[0],
    },
    Parameter {
        name: "quality.over_relaxation",
        shape: Number,
        digits: None,
        doc: "number",
        check: |s| {
            let w = s.quality.over_relaxation;
            rule(w.is_finite() && (1.0..2.0).contains(&w), || {
                format!("must be in [1, 2), got {}", w.shown())
            })
        },
        set: |s, v| s.quality.over_relaxation = v[0],
    },
];

/// A colour of the look: a triple, each component finite and not negative.
macro_rules! look_colour {
    ($name:literal, $field:ident) => {
        Parameter {
            name: $name,
            shape: Triple,
            digits: None,
            doc: "triple",
            check: |s| colour(s.look.$field),
            set: |s, v| s.look.$field = colour_of(v),
        }
    };
}

pub(super) const LOOK: &[Parameter] = &[
    Parameter {
        name: "look.light_direction",
        shape: Triple,
        digits: None,
        doc: "triple",
        check: |s| direction(s.look.light_direction),
        set: |s, v| s.look.light_direction = triple(v),
    },
    look_colour!("look.light_colour", light_colour),
    look_colour!("look.ambient", ambient),
    look_colour!("look.base_colour", base_colour),
    look_colour!("look.trap_x_colour", trap_x_colour),
    look_colour!("look.trap_y_colour", trap_y_colour),
    look_colour!("look.trap_z_colour", trap_z_colour),
    Parameter {
        name: "look.trap_occlusion",
        shape: Number,
        digits: None,
        doc: "number",
        check: |s| fraction(s.look.trap_occlusion),
        set: |s, v| s.look.trap_occlusion = v[0] as f32,
    },
    Parameter {
        name: "look.exposure",
        shape: Number,
        digits: None,
        doc: "number",
        check: |s| non_negative(s.look.exposure),
        set: |s, v| s.look.exposure = v[0] as f32,
    },
    look_colour!("look.background_top", background_top),
    look_colour!("look.background_bottom", background_bottom),
];

/// A palette's number: a track may animate it only where the scene's look
/// has a palette (`Timeline::parse` checks), which its setter relies on.
const PALETTE_NUMBER: &str = "number (the look must have a `palette`)";
/// A stop's value: only a stop the palette has.
const STOP_POSITION: &str = "number in [0, 1], at or after the stop before (the stop must exist)";
const STOP_COLOUR: &str = "triple (the stop must exist)";

/// A field of the look's palette: checked and set only where the look has one.
macro_rules! palette_field {
    ($name:literal, $field:ident, $check:expr) => {
        Parameter {
            name: $name,
            shape: Number,
            digits: None,
            doc: PALETTE_NUMBER,
            check: |s| s.look.palette.as_ref().map_or(Ok(()), |p| $check(p.$field)),
            set: |s, v| {
                s.look
                    .palette
                    .iter_mut()
                    .for_each(|p| p.$field = v[0] as f32)
            },
        }
    };
}

/// Stop `$i`'s position and colour: checked and set only where the
/// palette has that stop. A position lies in [0, 1], at or after the
/// position before it.
macro_rules! palette_stop {
    ($i:literal) => {
        [
            Parameter {
                name: concat!("look.palette.stops[", $i, "].position"),
                shape: Number,
                digits: None,
                doc: STOP_POSITION,
                check: |s| stop_check(s, $i, |before, stop| stop_position(before, stop.position)),
                set: |s, v| stop_set(s, $i, |stop| stop.position = v[0] as f32),
            },
            Parameter {
                name: concat!("look.palette.stops[", $i, "].colour"),
                shape: Triple,
                digits: None,
                doc: STOP_COLOUR,
                check: |s| stop_check(s, $i, |_, stop| colour(stop.colour)),
                set: |s, v| stop_set(s, $i, |stop| stop.colour = colour_of(v)),
            },
        ]
    };
}

/// `check` of stop `i` (given the position before it) where the scene's
/// palette has it.
fn stop_check(s: &Scene, i: usize, check: impl Fn(f32, &Stop) -> Checked) -> Checked {
    let Some(stops) = s.look.palette.as_ref().map(|p| &p.stops) else {
        return Ok(());
    };
    let before = i
        .checked_sub(1)
        .and_then(|b| stops.get(b))
        .map_or(0.0, |b| b.position);
    stops.get(i).map_or(Ok(()), |stop| check(before, stop))
}

/// `set` applied to stop `i` where the scene's palette has it.
fn stop_set(s: &mut Scene, i: usize, set: impl FnOnce(&mut Stop)) {
    if let Some(stop) = s.look.palette.as_mut().and_then(|p| p.stops.get_mut(i)) {
        set(stop);
    }
}

/// A stop's position: in [0, 1], and not before the stop before it (at
/// `before`; equal makes a hard edge).
fn stop_position(before: f32, position: f32) -> Checked {
    fraction(position)?;
    rule(position >= before, || {
        format!(
            "stops go in order of position: {} comes before the stop before it, at {}",
            position.shown(),
            before.shown()
        )
    })
}

/// Any finite number.
fn finite_f32(v: f32) -> Checked {
    finite(v.is_finite(), v)
}

const STOPS: [[Parameter; 2]; MAX_STOPS] = [
    palette_stop!(0),
    palette_stop!(1),
    palette_stop!(2),
    palette_stop!(3),
    palette_stop!(4),
    palette_stop!(5),
    palette_stop!(6),
    palette_stop!(7),
];

pub(super) const PALETTE: &[Parameter] = &{
    let mut all = [STOPS[0][0]; 3 + 2 * MAX_STOPS];
    all[0] = palette_field!("look.palette.scale", scale, finite_f32);
    all[1] = palette_field!("look.palette.offset", offset, finite_f32);
    all[2] = palette_field!("look.palette.mix", mix, fraction);
    let mut i = 0;
    while i < 2 * MAX_STOPS {
        all[3 + i] = STOPS[i / 2][i % 2];
        i += 1;
    }
    all
};

/// An effect's number: a track may animate it only where the scene enables
/// the effect (`Timeline::parse` checks), which its setter relies on.
const EFFECT_NUMBER: &str = "number (the effect must be enabled in `scene.effects`)";

pub(super) const SHADOWS: &[Parameter] = &[Parameter {
    name: "effects.shadows.softness",
    shape: Number,
    digits: None,
    doc: EFFECT_NUMBER,
    check: |s| {
        s.effects.shadows.as_ref().map_or(Ok(()), |sh| {
            rule(sh.softness.is_finite() && sh.softness >= 0.0, || {
                format!("must be 0 (hard) or positive, got {}", sh.softness.shown())
            })
        })
    },
    set: |s, v| s.effects.shadows.iter_mut().for_each(|x| x.softness = v[0]),
}];

/// A field of an optional effect: checked and set only where the scene
/// enables the effect.
macro_rules! effect_field {
    ($name:literal, $effect:ident . $field:ident, $shape:ident, $check:path, $value:path) => {
        Parameter {
            name: $name,
            shape: $shape,
            digits: None,
            doc: match $shape {
                Number => EFFECT_NUMBER,
                Triple => "triple",
            },
            check: |s| {
                s.effects
                    .$effect
                    .as_ref()
                    .map_or(Ok(()), |e| $check(e.$field))
            },
            set: |s, v| {
                s.effects
                    .$effect
                    .iter_mut()
                    .for_each(|e| e.$field = $value(v))
            },
        }
    };
}

pub(super) const AMBIENT_OCCLUSION: &[Parameter] = &[
    effect_field!(
        "effects.ambient_occlusion.radius",
        ambient_occlusion.radius,
        Number,
        positive,
        number
    ),
    effect_field!(
        "effects.ambient_occlusion.strength",
        ambient_occlusion.strength,
        Number,
        fraction,
        number_f32
    ),
];

pub(super) const SPECULAR: &[Parameter] = &[
    effect_field!(
        "effects.specular.strength",
        specular.strength,
        Number,
        non_negative,
        number_f32
    ),
    effect_field!(
        "effects.specular.shininess",
        specular.shininess,
        Number,
        positive,
        number_f32
    ),
];

pub(super) const FOG: &[Parameter] = &[
    effect_field!(
        "effects.fog.density",
        fog.density,
        Number,
        non_negative,
        number
    ),
    effect_field!("effects.fog.colour", fog.colour, Triple, colour, colour_of),
];

pub(super) const GLOW: &[Parameter] = &[
    effect_field!(
        "effects.glow.strength",
        glow.strength,
        Number,
        non_negative,
        number_f32
    ),
    effect_field!("effects.glow.width", glow.width, Number, positive, number),
    effect_field!(
        "effects.glow.colour",
        glow.colour,
        Triple,
        colour,
        colour_of
    ),
];

#[cfg(test)]
mod tests;
