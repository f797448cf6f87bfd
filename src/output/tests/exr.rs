use super::{film, write_plain};
use crate::math::Vec3;
use crate::output::frames::{file_state, write_frame};
use crate::output::FileState;
use crate::output::{Aov, Format, HASH_KEY};
use crate::render::{Film, FrameStats};
use std::path::Path;

/// What an EXR written by `write_plain` with hash "abc" records.
const EXR_KEY: &str = "abc";

#[test]
fn exr_tiles_read_back_as_the_film_across_partial_tiles() {
    // A size of 3×2 of exrs' 64-pixel tiles, cut short at the right and
    // the bottom; every layer and values that differ per pixel and
    // channel (some negative, some past f16's range), with and without
    // the extra layers.
    let (w, h) = (150u32, 70u32);
    let n = (w * h) as usize;
    let v = |i: usize, k: usize| match (i * 7 + k * 3) % 41 {
        40 => 1e5,
        j => j as f32 * 0.37 - 3.0,
    };
    let vectors = |k: usize| {
        (0..n)
            .map(|i| Vec3::new(v(i, k), v(i, k + 1), v(i, k + 2)))
            .collect()
    };
    let full = Film {
        width: w,
        height: h,
        colour: vectors(0),
        alpha: (0..n).map(|i| v(i, 3) / 4.0).collect(),
        depth: (0..n).map(|i| v(i, 4) * 1e5).collect(),
        evaluations: (0..n).map(|i| i as u32 * 97).collect(),
        normal: Some(vectors(5)),
        albedo: Some(vectors(8)),
        traps: Some(
            (0..n)
                .map(|i| [v(i, 11), v(i, 12), v(i, 13), v(i, 14)])
                .collect(),
        ),
        coverage: None,
        stats: FrameStats::default(),
    };
    let plain = Film {
        normal: None,
        albedo: None,
        traps: None,
        ..full.clone()
    };
    let all = [Aov::Normal, Aov::Albedo, Aov::Traps, Aov::Steps];
    // Alpha is the film's where the background is transparent.
    let transparent = crate::output::Encoding {
        transparent: true,
        ..Default::default()
    };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tiles.exr");
    // The film's layers are written wherever it has them; the step
    // count, which every film has, where `Aov::Steps` asks for it.
    let cases = [
        (&full, &all[..], 16),
        (&full, &[Aov::Steps][..], 16),
        (&plain, &[][..], 5),
    ];
    for (film, aovs, channels) in cases {
        write_frame(&path, Format::Exr, film, "h", aovs, &transparent).unwrap();
        let image = exr::prelude::read_all_flat_layers_from_file(&path).unwrap();
        let layer = &image.layer_data[0];
        assert_eq!(layer.size, exr::math::Vec2(w as usize, h as usize));
        assert_eq!(layer.channel_data.list.len(), channels);
        if channels == 5 {
            let names = layer.channel_data.list.iter().map(|c| c.name.to_string());
            assert_eq!(names.collect::<Vec<_>>(), ["A", "B", "G", "R", "depth.Z"]);
        }
        for i in 0..n {
            for (name, value) in expected_samples(film, !aovs.is_empty(), i) {
                assert_eq!(read_sample(layer, name, i), value, "{name} at pixel {i}");
            }
        }
    }
}

/// What the EXR of `film` should hold at pixel `i` in each channel it
/// has, as read back (f16 channels rounded to f16, beyond its range held
/// at its largest).
fn expected_samples(film: &Film, steps: bool, i: usize) -> Vec<(&'static str, f32)> {
    let half = |x: f32| {
        let rounded = exr::prelude::f16::from_f32(x).to_f32();
        if rounded.is_infinite() {
            65504.0f32.copysign(x)
        } else {
            rounded
        }
    };
    let mut expected = vec![
        ("R", half(film.colour[i].x)),
        ("G", half(film.colour[i].y)),
        ("B", half(film.colour[i].z)),
        ("A", half(film.alpha[i])),
        ("depth.Z", film.depth[i]),
    ];
    if let Some(normal) = &film.normal {
        expected.extend([
            ("N.X", normal[i].x),
            ("N.Y", normal[i].y),
            ("N.Z", normal[i].z),
        ]);
    }
    if let Some(albedo) = &film.albedo {
        expected.extend([
            ("albedo.R", half(albedo[i].x)),
            ("albedo.G", half(albedo[i].y)),
            ("albedo.B", half(albedo[i].z)),
        ]);
    }
    if let Some(traps) = &film.traps {
        expected.extend([
            ("trap.origin", traps[i][0]),
            ("trap.x", traps[i][1]),
            ("trap.y", traps[i][2]),
            ("trap.z", traps[i][3]),
        ]);
    }
    if steps {
        expected.push(("DE", film.evaluations[i] as f32));
    }
    expected
}

/// Sample `i` of the channel `name` of `layer`, as f32.
fn read_sample(
    layer: &exr::image::Layer<exr::image::AnyChannels<exr::image::FlatSamples>>,
    name: &str,
    i: usize,
) -> f32 {
    let c = layer
        .channel_data
        .list
        .iter()
        .find(|c| c.name.to_string() == name)
        .unwrap_or_else(|| panic!("channel {name} missing"));
    c.sample_data.value_by_flat_index(i).to_f32()
}

#[test]
fn an_exr_whose_offset_table_is_damaged_is_not_current() {
    // The file keeps its length, but its last offset points at the chunk
    // before: the end check finds the last chunk short of the end, and
    // --verify checks that too.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("frame_00000.exr");
    // Big enough for several chunks.
    let (w, h) = (200, 100);
    let n = (w * h) as usize;
    let film = Film {
        width: w,
        height: h,
        colour: (0..n).map(|i| Vec3::splat(i as f32 / n as f32)).collect(),
        alpha: vec![1.0; n],
        depth: vec![2.5; n],
        evaluations: vec![7; n],
        ..film()
    };
    write_plain(&path, Format::Exr, &film, "abc");
    assert_eq!(
        file_state(&path, Format::Exr, EXR_KEY, true),
        FileState::Current
    );
    let mut bytes = std::fs::read(&path).unwrap();
    let meta = exr::meta::MetaData::read_from_buffered(&bytes[..], false).unwrap();
    let chunks = meta.headers[0].chunk_count;
    assert!(chunks >= 2, "{chunks} chunks");
    let at = |b: &[u8], p: usize| u64::from_le_bytes(b[p..p + 8].try_into().unwrap());
    // The table sits just before the first chunk, which its first entry names.
    let table = (8..bytes.len() - 8)
        .find(|&p| at(&bytes, p) == (p + 8 * chunks) as u64)
        .expect("the offset table");
    let (last, before) = (table + 8 * (chunks - 1), table + 8 * (chunks - 2));
    let previous = at(&bytes, before).to_le_bytes();
    bytes[last..last + 8].copy_from_slice(&previous);
    std::fs::write(&path, &bytes).unwrap();
    for thorough in [false, true] {
        let state = file_state(&path, Format::Exr, EXR_KEY, thorough);
        assert_eq!(state, FileState::Damaged, "thorough: {thorough}");
    }
}

#[test]
fn a_scan_line_exr_is_checked_to_its_end_too() {
    // Our writer makes tiled files; another tool re-saving one keeps
    // the hash in scan-line blocks, whose chunks start with a y (4
    // bytes) rather than a tile's four numbers (16).
    use exr::prelude::*;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("frame_00000.exr");
    let mut attributes = LayerAttributes::named("");
    attributes.other.insert(
        Text::from(HASH_KEY),
        exr::meta::attribute::AttributeValue::Text(Text::from("abc")),
    );
    let encoding = Encoding {
        blocks: Blocks::ScanLines,
        compression: Compression::ZIP1,
        line_order: LineOrder::Increasing,
    };
    let channels = SpecificChannels::rgb(|p: Vec2<usize>| (p.x() as f32, p.y() as f32, 0.5f32));
    let layer = Layer::new((64, 40), attributes, encoding, channels);
    Image::from_layer(layer).write().to_file(&path).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let meta = exr::meta::MetaData::read_from_buffered(&bytes[..], false).unwrap();
    assert!(matches!(
        meta.headers[0].blocks,
        exr::meta::BlockDescription::ScanLines
    ));
    assert!(meta.headers[0].chunk_count > 2);
    for thorough in [false, true] {
        let state = |p: &Path| file_state(p, Format::Exr, "abc", thorough);
        assert_eq!(state(&path), FileState::Current, "thorough: {thorough}");
        let cut = dir.path().join("cut.exr");
        std::fs::write(&cut, &bytes[..bytes.len() - 3]).unwrap();
        assert_eq!(state(&cut), FileState::Damaged, "thorough: {thorough}");
        let long = dir.path().join("long.exr");
        std::fs::write(&long, [&bytes[..], &[0]].concat()).unwrap();
        assert_eq!(state(&long), FileState::Damaged, "thorough: {thorough}");
    }
}
