#!/bin/sh
# The README's strips and docs/gallery.md's stills: four frames of each
# example at 1280x720, rendered with the dist build, each frame timed.
#
# usage: docs/tools/gallery.sh [SIZE]   (after `cargo build --profile dist`)
#   SIZE  frame size [default: 1280x720]; the times are for this size
# Writes docs/gallery/NAME_strip.png (the four frames side by side, 640
# wide each), docs/gallery/NAME_N.jpg (each frame whole) and prints a
# Markdown table of the seconds each frame took. MANDELREEL names another
# binary; GALLERY_OUT and GALLERY_DOCS other folders for the frames and
# the pictures. Needs ffmpeg (for the JPEGs).
set -eu
bin=${MANDELREEL:-target/dist/mandelreel}
size=${1:-1280x720}
out=${GALLERY_OUT:-out/gallery}
docs=${GALLERY_DOCS:-docs/gallery}
mkdir -p "$out" "$docs"

echo "| film | frame | seconds |"
echo "|---|---|---|"
strip() {
    name=$1
    shift
    rm -rf "$out/$name"
    for frame in "$@"; do
        start=$(date +%s.%N)
        "$bin" render "timelines/$name.ron" --frames "$frame" --size "$size" \
            --out "$out/$name" --quiet >/dev/null
        end=$(date +%s.%N)
        awk -v s="$start" -v e="$end" -v n="$name" -v f="$frame" \
            'BEGIN { printf "| %s | %d | %.1f |\n", n, f, e - s }'
        png=$(printf '%s/%s/frame_%05d.png' "$out" "$name" "$frame")
        ffmpeg -y -loglevel error -i "$png" -q:v 3 "$docs/${name}_$frame.jpg"
    done
    "$bin" sheet "$out/$name" --count $# --columns $# --thumb-width 640 \
        --out "$docs/${name}_strip.png" >/dev/null
}

strip zoom 0 40 80 119
strip julia_morph 0 36 72 108
strip deep_zoom 0 180 360 539
strip quaternion 0 24 48 72
