//! A grammar of the timeline schema (the serde structs of `timeline`,
//! `scene`, `shade`, `fractal` and `march`) that writes RON: timelines of
//! sensible values, many of them valid, for `mutate` to break. Each field
//! has the range its values are drawn from and a chance of being written.

use mandelreel::timeline::PARAMETERS;
use proptest::prelude::*;
use proptest::sample::select;

/// A RON value as the generator builds it.
#[derive(Clone, Debug)]
pub enum Ron {
    /// Written as it is: a number, a name, a string literal, or a piece of
    /// RON made by an edit.
    Atom(String),
    /// `Name(a, b)`, or `(a, b)` with an empty name.
    Tuple(String, Vec<Ron>),
    /// `Name(field: value, …)`, or `(…)` with an empty name.
    Struct(String, Vec<(String, Ron)>),
    List(Vec<Ron>),
    Map(Vec<(Ron, Ron)>),
}

impl Ron {
    /// The RON text, ending in a newline.
    pub fn text(&self) -> String {
        let mut out = String::new();
        self.write(&mut out, 0, false);
        out.push('\n');
        out
    }

    /// A struct's fields and a map's entries go one a line, so errors have
    /// lines to point at; inside a list or a tuple, all on one line.
    fn write(&self, out: &mut String, depth: usize, inline: bool) {
        let pad = |out: &mut String, d: usize| {
            if !inline {
                out.push('\n');
                out.push_str(&"    ".repeat(d));
            }
        };
        match self {
            Ron::Atom(a) => out.push_str(a),
            Ron::Tuple(name, items) => {
                out.push_str(name);
                write_items(out, "(", items, ")", depth);
            }
            Ron::List(items) => write_items(out, "[", items, "]", depth),
            Ron::Struct(name, fields) => {
                out.push_str(name);
                out.push('(');
                for (field, value) in fields {
                    pad(out, depth + 1);
                    out.push_str(field);
                    out.push_str(": ");
                    value.write(out, depth + 1, inline);
                    out.push_str(if inline { ", " } else { "," });
                }
                pad(out, depth);
                out.push(')');
            }
            Ron::Map(entries) => {
                out.push('{');
                for (key, value) in entries {
                    pad(out, depth + 1);
                    key.write(out, depth + 1, true);
                    out.push_str(": ");
                    value.write(out, depth + 1, true);
                    out.push(',');
                }
                pad(out, depth);
                out.push('}');
            }
        }
    }
}

fn write_items(out: &mut String, open: &str, items: &[Ron], close: &str, depth: usize) {
    out.push_str(open);
    for (i, item) in items.iter().enumerate() {
        if i > 0 {
            out.push_str(", ");
        }
        item.write(out, depth + 1, true);
    }
    out.push_str(close);
}

/// What a field holds, with the range its sensible values come from.
#[derive(Clone, Copy, Debug)]
pub enum Kind {
    Real(f64, f64),
    Count(u64, u64),
    Triple(f64, f64),
    /// `size: (width, height)`.
    Size,
    Bool,
    Word(&'static [&'static str]),
    Struct(&'static [Field]),
    /// `None`, `Some(x)` or plain `x` (RON's implicit `Some`).
    Optional(&'static Kind),
    /// `extra_lights`: a list of lights.
    Lights,
    Sky,
    Tracks,
}

/// A field of a struct and the percentage of timelines that write it.
#[derive(Clone, Copy, Debug)]
pub struct Field {
    pub name: &'static str,
    pub kind: Kind,
    pub percent: u32,
}

const fn field(name: &'static str, kind: Kind, percent: u32) -> Field {
    Field {
        name,
        kind,
        percent,
    }
}

const COLOUR: Kind = Kind::Triple(0.0, 1.5);
const DIRECTION: Kind = Kind::Triple(-1.0, 1.0);

pub const TIMELINE: &[Field] = &[
    field("fps", Kind::Real(1.0, 60.0), 97),
    field("frames", Kind::Count(1, 48), 90),
    field("duration_seconds", Kind::Real(0.1, 2.0), 10),
    field("size", Kind::Size, 97),
    field("loop", Kind::Bool, 15),
    field("scene", Kind::Struct(SCENE), 90),
    field("tracks", Kind::Tracks, 80),
];

const SCENE: &[Field] = &[
    field("camera", Kind::Struct(CAMERA), 60),
    field("fractal", Kind::Struct(FRACTAL), 50),
    field("quality", Kind::Struct(QUALITY), 40),
    field("look", Kind::Struct(LOOK), 40),
    field("effects", Kind::Struct(EFFECTS), 50),
    field("samples_per_pixel", Kind::Count(1, 16), 30),
    field("seed", Kind::Count(0, u64::MAX), 20),
];

const CAMERA: &[Field] = &[
    field("position", Kind::Triple(-3.0, 3.0), 70),
    field("target", Kind::Triple(-0.5, 0.5), 40),
    field("up", DIRECTION, 20),
    field("roll_degrees", Kind::Real(-180.0, 180.0), 20),
    field("fov_degrees", Kind::Real(5.0, 120.0), 40),
    field("aperture_radius", Kind::Real(0.0, 0.1), 20),
    field("focus_distance", Kind::Optional(&Kind::Real(0.5, 5.0)), 15),
];

const FRACTAL: &[Field] = &[
    field(
        "formula",
        Kind::Word(&["Quilez", "WhiteNylander", "Asin", "Quaternion"]),
        30,
    ),
    field("power", Kind::Real(2.0, 12.0), 50),
    field("iterations", Kind::Count(1, 20), 40),
    field("bailout", Kind::Real(2.0, 16.0), 20),
    field("julia", Kind::Optional(&DIRECTION), 20),
    field("de", Kind::Word(DE_METHODS), 30),
    field("precision", Kind::Word(&["F64", "F32"]), 20),
];

const DE_METHODS: &[&str] = &[
    "Analytic",
    "Potential",
    "SinhPotential",
    "EscapeLength",
    "Jacobian",
];

const QUALITY: &[Field] = &[
    field("hit_threshold", Kind::Real(0.1, 1.0), 30),
    field("fudge", Kind::Real(0.1, 1.0), 30),
    field("max_steps", Kind::Count(10, 500), 30),
    field("normal_step", Kind::Real(0.1, 1.0), 20),
    field("bounding_radius", Kind::Real(1.2, 4.0), 20),
    field("over_relaxation", Kind::Real(1.0, 1.9), 20),
    field("cone_rays", Kind::Count(1, 16), 20),
];

const LOOK: &[Field] = &[
    field("light_direction", DIRECTION, 30),
    field("light_colour", COLOUR, 20),
    field("extra_lights", Kind::Lights, 20),
    field("ambient", COLOUR, 15),
    field("base_colour", COLOUR, 15),
    field("trap_x_colour", COLOUR, 15),
    field("trap_y_colour", COLOUR, 15),
    field("trap_z_colour", COLOUR, 15),
    field("trap_occlusion", Kind::Real(0.0, 1.0), 15),
    field("background_top", COLOUR, 15),
    field("background_bottom", COLOUR, 15),
    field("exposure", Kind::Real(0.0, 4.0), 15),
    field("tone_map", Kind::Word(&["Clip", "Filmic"]), 15),
];

const LIGHT: &[Field] = &[
    field("direction", DIRECTION, 80),
    field("colour", COLOUR, 60),
    field("intensity", Kind::Real(0.0, 3.0), 50),
];

const EFFECTS: &[Field] = &[
    field("shadows", Kind::Optional(&Kind::Struct(SHADOWS)), 25),
    field("ambient_occlusion", Kind::Optional(&Kind::Struct(AO)), 25),
    field("specular", Kind::Optional(&Kind::Struct(SPECULAR)), 25),
    field("fog", Kind::Optional(&Kind::Struct(FOG)), 25),
    field("glow", Kind::Optional(&Kind::Struct(GLOW)), 25),
    field(
        "motion_blur",
        Kind::Optional(&Kind::Struct(MOTION_BLUR)),
        25,
    ),
    field(
        "path_tracing",
        Kind::Optional(&Kind::Struct(PATH_TRACING)),
        20,
    ),
];

const SHADOWS: &[Field] = &[
    field("softness", Kind::Real(0.0, 32.0), 50),
    field("max_steps", Kind::Count(1, 256), 30),
];
const AO: &[Field] = &[
    field("samples", Kind::Count(1, 8), 50),
    field("radius", Kind::Real(0.01, 0.2), 50),
    field("strength", Kind::Real(0.0, 1.0), 50),
];
const SPECULAR: &[Field] = &[
    field("strength", Kind::Real(0.0, 1.0), 50),
    field("shininess", Kind::Real(1.0, 64.0), 50),
];
const FOG: &[Field] = &[
    field("density", Kind::Real(0.0, 1.0), 50),
    field("colour", COLOUR, 50),
];
const GLOW: &[Field] = &[
    field("colour", COLOUR, 50),
    field("strength", Kind::Real(0.0, 1.0), 50),
    field("width", Kind::Real(0.5, 8.0), 50),
];
const MOTION_BLUR: &[Field] = &[field("shutter", Kind::Real(0.05, 1.0), 60)];
const PATH_TRACING: &[Field] = &[
    field("max_bounces", Kind::Count(1, 8), 40),
    field("sun_angle_degrees", Kind::Real(0.0, 5.0), 30),
    field("sky", Kind::Sky, 70),
    field("sky_intensity", Kind::Real(0.0, 2.0), 30),
];

/// Paths an environment map is read from, relative to the timeline's
/// folder, where `fuzz::Fixtures` makes them: a good map, bad files, a
/// folder, a FIFO, devices that never end, nothing at all.
pub const MAP_PATHS: &[&str] = &[
    "sky.exr",
    "empty.exr",
    "junk.exr",
    "junk.hdr",
    "liar.exr",
    "liar.hdr",
    "folder",
    "missing.exr",
    "fifo",
    "/dev/null",
    "/dev/zero",
    "/dev/urandom",
    "",
    ".",
    "/",
];

/// A whole timeline, as a tree for `mutate`'s tree edits.
pub fn timeline() -> BoxedStrategy<Ron> {
    value(Kind::Struct(TIMELINE))
}

/// A sensible value of `kind`.
pub fn value(kind: Kind) -> BoxedStrategy<Ron> {
    match kind {
        Kind::Real(lo, hi) => real(lo, hi).prop_map(Ron::Atom).boxed(),
        Kind::Count(lo, hi) => (lo..=hi).prop_map(|n| Ron::Atom(n.to_string())).boxed(),
        Kind::Triple(lo, hi) => triple(lo, hi),
        Kind::Size => (1u32..=64, 1u32..=64)
            .prop_map(|(w, h)| tuple(vec![w.to_string(), h.to_string()]))
            .boxed(),
        Kind::Bool => select(&["true", "false"][..])
            .prop_map(|b| Ron::Atom(b.into()))
            .boxed(),
        Kind::Word(words) => select(words).prop_map(|w| Ron::Atom(w.into())).boxed(),
        Kind::Struct(fields) => structure(fields),
        Kind::Optional(inner) => prop_oneof![
            1 => Just(Ron::Atom("None".into())),
            2 => value(*inner).prop_map(|v| Ron::Tuple("Some".into(), vec![v])),
            3 => value(*inner),
        ]
        .boxed(),
        Kind::Lights => proptest::collection::vec(structure(LIGHT), 0..4)
            .prop_map(Ron::List)
            .boxed(),
        Kind::Sky => sky(),
        Kind::Tracks => proptest::collection::vec(track(), 0..4)
            .prop_map(Ron::Map)
            .boxed(),
    }
}

/// A number in [lo, hi], written as a decimal or, where one fits, an integer.
fn real(lo: f64, hi: f64) -> BoxedStrategy<String> {
    let decimal = (lo..=hi).prop_map(|x| format!("{x:.4}"));
    let whole = (lo.ceil() as i64)..=(hi.floor() as i64);
    if whole.is_empty() {
        return decimal.boxed();
    }
    prop_oneof![3 => decimal, 1 => whole.prop_map(|n| n.to_string())].boxed()
}

fn tuple(items: Vec<String>) -> Ron {
    Ron::Tuple(String::new(), items.into_iter().map(Ron::Atom).collect())
}

/// `(x, y, z)`, or now and then `[x, y, z]`: a key's value takes both, a
/// scene's field only the first.
fn triple(lo: f64, hi: f64) -> BoxedStrategy<Ron> {
    (real(lo, hi), real(lo, hi), real(lo, hi), 0..30)
        .prop_map(|(x, y, z, list)| match tuple(vec![x, y, z]) {
            Ron::Tuple(_, items) if list == 0 => Ron::List(items),
            t => t,
        })
        .boxed()
}

/// Each field written with its own chance, in the schema's order.
fn structure(fields: &'static [Field]) -> BoxedStrategy<Ron> {
    let each: Vec<_> = fields
        .iter()
        .map(|f| {
            let chance = f64::from(f.percent) / 100.0;
            proptest::option::weighted(chance, value(f.kind))
                .prop_map(move |v| v.map(|v| (f.name.to_string(), v)))
        })
        .collect();
    each.prop_map(|present| Ron::Struct(String::new(), present.into_iter().flatten().collect()))
        .boxed()
}

fn sky() -> BoxedStrategy<Ron> {
    let named = |name: &str, fields: Vec<(&str, Ron)>| {
        let fields = fields.into_iter().map(|(f, v)| (f.to_string(), v));
        Ron::Struct(name.into(), fields.collect())
    };
    prop_oneof![
        Just(Ron::Atom("Gradient".into())),
        triple(0.0, 2.0).prop_map(|c| Ron::Tuple("Constant".into(), vec![c])),
        real(1.7, 12.0).prop_map(move |t| named("Preetham", vec![("turbidity", Ron::Atom(t))])),
        (select(MAP_PATHS), proptest::option::of(real(-360.0, 360.0))).prop_map(
            move |(path, rotation)| {
                let mut fields = vec![("path", Ron::Atom(format!("\"{path}\"")))];
                fields.extend(rotation.map(|r| ("rotation_degrees", Ron::Atom(r))));
                named("Environment", fields)
            }
        ),
    ]
    .boxed()
}

/// `"name": (interpolation: …, keys: […])` for an animatable parameter,
/// keys from 0 s at increasing times, values from the field's own range.
fn track() -> BoxedStrategy<(Ron, Ron)> {
    select(PARAMETERS)
        .prop_flat_map(|(name, arity)| {
            let key_value = match (arity, parameter_kind(name)) {
                (1, Kind::Real(lo, hi)) => real(lo, hi).prop_map(Ron::Atom).boxed(),
                (1, Kind::Count(lo, hi)) => real(lo as f64, hi as f64).prop_map(Ron::Atom).boxed(),
                (_, Kind::Triple(lo, hi)) => triple(lo, hi),
                _ => real(0.1, 2.0).prop_map(Ron::Atom).boxed(),
            };
            let keys = proptest::collection::vec((0.05f64..1.5, key_value), 1..6);
            const MODES: &[&str] = &["Step", "Linear", "CatmullRom", "Smooth"];
            (Just(name), proptest::option::of(select(MODES)), keys)
        })
        .prop_map(|(name, mode, keys)| {
            let mut time = 0.0;
            let keys = keys.into_iter().map(|(step, value)| {
                let key = Ron::Struct(
                    String::new(),
                    vec![
                        ("time".into(), Ron::Atom(format!("{time:.3}"))),
                        ("value".into(), value),
                    ],
                );
                time += step;
                key
            });
            let mut fields: Vec<(String, Ron)> = mode
                .map(|m| ("interpolation".to_string(), Ron::Atom(m.into())))
                .into_iter()
                .collect();
            fields.push(("keys".into(), Ron::List(keys.collect())));
            (
                Ron::Atom(format!("\"{name}\"")),
                Ron::Struct(String::new(), fields),
            )
        })
        .boxed()
}

/// The kind of an animatable parameter, found by its path in the scene's
/// schema (`camera.fov_degrees` → `Real(5, 120)`).
fn parameter_kind(name: &str) -> Kind {
    if name == "camera.distance" {
        return Kind::Real(0.5, 5.0);
    }
    let mut kind = Kind::Struct(SCENE);
    for part in name.split('.') {
        let fields = match kind {
            Kind::Struct(fields) => fields,
            Kind::Optional(Kind::Struct(fields)) => fields,
            _ => return Kind::Real(0.1, 2.0),
        };
        match fields.iter().find(|f| f.name == part) {
            Some(f) => kind = f.kind,
            None => return Kind::Real(0.1, 2.0),
        }
    }
    match kind {
        Kind::Optional(inner) => *inner,
        k => k,
    }
}

/// Every name the schema knows: fields and the words of its enums.
pub fn schema_words() -> Vec<&'static str> {
    let mut words = Vec::new();
    collect_words(TIMELINE, &mut words);
    words.extend(LIGHT.iter().map(|f| f.name));
    words.extend([
        "Some",
        "None",
        "Gradient",
        "Constant",
        "Preetham",
        "Environment",
        "turbidity",
        "path",
        "rotation_degrees",
        "interpolation",
        "keys",
        "time",
        "value",
        "Step",
        "Linear",
        "CatmullRom",
        "Smooth",
    ]);
    words.sort_unstable();
    words.dedup();
    words
}

fn collect_words(fields: &'static [Field], words: &mut Vec<&'static str>) {
    for f in fields {
        words.push(f.name);
        match f.kind {
            Kind::Struct(inner) | Kind::Optional(&Kind::Struct(inner)) => {
                collect_words(inner, words)
            }
            Kind::Word(list) => words.extend(list),
            _ => {}
        }
    }
}
