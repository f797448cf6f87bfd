#!/bin/sh
# What `iterations: Auto` does to a zoom's detail: renders every 8th frame
# of timelines/zoom.ron as written (its hand-keyed iterations track) and of a
# copy with `iterations: Auto` (MARGIN, the track removed), at 320x180 with
# 16 samples a pixel on 2 threads, and prints bench/detail.py's measure of
# each: the share of frames whose high-frequency energy falls below frame 0's.
#
# usage: bench/iterations.sh [OUT] [MARGIN]   (after `cargo build --release`)
#   OUT     work folder [default: out/iterations]
#   MARGIN  Auto's margin [default: 2]
set -eu
bin=${MANDELREEL:-target/release/mandelreel}
out=${1:-out/iterations}
margin=${2:-2}
mkdir -p "$out"

# The Auto copy: the scene's count replaced, the iterations track cut out.
python3 - "$margin" "$out/zoom_auto.ron" <<'PY'
import re, sys
text = open("timelines/zoom.ron").read()
text, n = re.subn(r"iterations: \d+,[^\n]*", f"iterations: Auto(margin: {sys.argv[1]}),", text, count=1)
start = text.find("        // Deeper views need longer")
end = text.find("    },\n)")
if n != 1 or start < 0 or end < 0:
    sys.exit("zoom.ron has no iterations line or track to replace")
open(sys.argv[2], "w").write(text[:start].rstrip() + "\n" + text[end:])
PY

for name in before after; do
    tl=timelines/zoom.ron
    [ $name = after ] && tl=$out/zoom_auto.ron
    frame=0
    while [ $frame -lt 120 ]; do
        "$bin" render "$tl" --frames $frame --size 320x180 --samples 16 --threads 2 \
            --out "$out/$name" --quiet >/dev/null
        frame=$((frame + 8))
    done
    printf '%s: ' $name
    python3 bench/detail.py "$out/$name"/*.png
done
