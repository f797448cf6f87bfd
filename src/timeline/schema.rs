//! The timeline file as written: its fields, tracks and keys, read by serde
//! from RON before anything is validated.

use crate::exact::{Component, Coordinates};
use crate::math::Real;
use crate::scene::Scene;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// How a track moves between its keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Interpolation {
    /// Hold each key's value until the next key.
    Step,
    /// Straight lines between keys.
    Linear,
    /// Catmull–Rom cubic through the keys (the default): smooth paths.
    CatmullRom,
    /// Ease in and out of every key (cosine), stopping at each.
    Smooth,
}

/// A key's value: a number or a triple such as a position or colour.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum KeyValue {
    Number(Real),
    Triple(Real, Real, Real),
    /// A triple with a component written as a string of digits, for a
    /// point a deep frame needs more exactly than f64 holds.
    Digits(Coordinates),
}

/// A number, or a triple written `(x, y, z)` (or `[x, y, z]`, or inside
/// `Some(…)` as `julia` is in a scene). Written by hand rather than derived
/// as an untagged enum, whose one message for every mistake ("did not
/// match any variant") names neither shape.
impl<'de> Deserialize<'de> for KeyValue {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct Shape;
        impl<'de> serde::de::Visitor<'de> for Shape {
            type Value = KeyValue;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or a triple (x, y, z)")
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> std::result::Result<KeyValue, E> {
                Ok(KeyValue::Number(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> std::result::Result<KeyValue, E> {
                Ok(KeyValue::Number(v as Real))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> std::result::Result<KeyValue, E> {
                Ok(KeyValue::Number(v as Real))
            }
            fn visit_some<D: serde::Deserializer<'de>>(
                self,
                d: D,
            ) -> std::result::Result<KeyValue, D::Error> {
                d.deserialize_any(Shape)
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                mut seq: A,
            ) -> std::result::Result<KeyValue, A::Error> {
                let mut parts = Vec::new();
                while let Some(part) = seq.next_element::<Component>()? {
                    parts.push(part);
                }
                let digits = parts.iter().any(|p| matches!(p, Component::Digits(..)));
                let number = |p: &Component| match p {
                    Component::Number(v) | Component::Digits(_, v) => *v,
                };
                match (parts.len(), digits) {
                    (3, false) => Ok(KeyValue::Triple(
                        number(&parts[0]),
                        number(&parts[1]),
                        number(&parts[2]),
                    )),
                    (3, true) => {
                        let triple: [Component; 3] = parts
                            .try_into()
                            .unwrap_or_else(|_| unreachable!("three parts"));
                        Ok(KeyValue::Digits(Coordinates::from_components(triple)))
                    }
                    (1, false) => Ok(KeyValue::Number(number(&parts[0]))),
                    (1, true) => Err(serde::de::Error::custom(
                        "strings of digits are for the components of a triple (x, y, z); a number is written as a number",
                    )),
                    (n, _) => Err(serde::de::Error::custom(format!(
                        "expected a number or a triple (x, y, z), got {n} numbers"
                    ))),
                }
            }
        }
        d.deserialize_any(Shape)
    }
}

impl KeyValue {
    pub(super) fn components(&self) -> Vec<Real> {
        match *self {
            KeyValue::Number(v) => vec![v],
            KeyValue::Triple(x, y, z) => vec![x, y, z],
            KeyValue::Digits(ref c) => c.value.to_array().to_vec(),
        }
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct KeySpec {
    pub(super) time: Real,
    pub(super) value: KeyValue,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TrackSpec {
    #[serde(default)]
    pub(super) interpolation: Option<Interpolation>,
    pub(super) keys: Vec<KeySpec>,
}

/// The file as written, before validation.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TimelineFile {
    pub(super) fps: Real,
    #[serde(default)]
    pub(super) frames: Option<u32>,
    #[serde(default)]
    pub(super) duration_seconds: Option<Real>,
    pub(super) size: (u32, u32),
    /// The film is one period of a seamless loop (`Timeline::looping`).
    #[serde(default, rename = "loop")]
    pub(super) looping: bool,
    #[serde(default)]
    pub(super) scene: Scene,
    #[serde(default, deserialize_with = "tracks_once_each")]
    pub(super) tracks: BTreeMap<String, TrackSpec>,
}

/// The tracks by parameter name, refusing a name given twice (a map would
/// keep the last and drop the other without a word).
fn tracks_once_each<'de, D: serde::Deserializer<'de>>(
    deserializer: D,
) -> std::result::Result<BTreeMap<String, TrackSpec>, D::Error> {
    struct Tracks;
    impl<'de> serde::de::Visitor<'de> for Tracks {
        type Value = BTreeMap<String, TrackSpec>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("a map of tracks by parameter name")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            mut map: A,
        ) -> std::result::Result<Self::Value, A::Error> {
            let mut tracks = BTreeMap::new();
            while let Some(name) = map.next_key::<String>()? {
                if tracks.contains_key(&name) {
                    return Err(serde::de::Error::custom(format!(
                        "the track \"{name}\" is given twice; one track per parameter"
                    )));
                }
                tracks.insert(name, map.next_value()?);
            }
            Ok(tracks)
        }
    }
    deserializer.deserialize_map(Tracks)
}
