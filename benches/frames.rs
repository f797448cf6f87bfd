//! Writing a finished 1080p frame in each format and EXR compression: the
//! time `cargo bench --bench frames` reports, and the file sizes it prints
//! first. The frame is zoom.ron's frame 60 at its own samples a pixel
//! (`FRAME_SIZE=WxH` for another size than 1080p).

use mandelreel::output::exr::ExrCompression;
use mandelreel::output::{write_frame, Encoding, Format};
use mandelreel::render::Film;
use std::sync::OnceLock;

const COMPRESSIONS: [ExrCompression; 10] = ExrCompression::ALL;
const PNGS: [Format; 3] = [Format::Png, Format::Png16, Format::Png16Alpha];

fn film() -> &'static Film {
    static FILM: OnceLock<Film> = OnceLock::new();
    FILM.get_or_init(|| {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let timeline = mandelreel::timeline::Timeline::load(&root.join("timelines/zoom.ron"))
            .expect("the example zoom loads");
        let (w, h) = std::env::var("FRAME_SIZE")
            .ok()
            .and_then(|s| mandelreel::job::request::parse_size("FRAME_SIZE", &s).ok())
            .unwrap_or((1920, 1080));
        mandelreel::render::render_frame(&timeline.scene_at(60), 60, w, h, &|| {})
    })
}

/// Writes the film as `format` into a fresh folder; returns the file's size.
fn write(format: Format, exr_compression: ExrCompression) -> u64 {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let path = dir.path().join(format!("frame.{}", format.extension()));
    let encoding = Encoding {
        exr_compression,
        ..Encoding::default()
    };
    write_frame(&path, format, film(), "bench", &[], &encoding).expect("the frame writes");
    std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0)
}

fn main() {
    let (w, h) = (film().width, film().height);
    println!("{w}x{h} frame 60 of zoom.ron: bytes per file");
    for c in COMPRESSIONS {
        println!("  exr {:<6} {:>10}", c.name(), write(Format::Exr, c));
    }
    for f in PNGS {
        println!(
            "  {:<10} {:>10}",
            f.name(),
            write(f, ExrCompression::default())
        );
    }
    divan::main();
}

#[divan::bench(args = COMPRESSIONS, sample_count = 10)]
fn exr(compression: ExrCompression) -> u64 {
    write(Format::Exr, compression)
}

#[divan::bench(args = PNGS, sample_count = 10)]
fn png(format: Format) -> u64 {
    write(format, ExrCompression::default())
}
