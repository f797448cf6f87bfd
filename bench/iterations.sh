#!/bin/sh
# What `iterations: Auto` does to a zoom's detail: renders every 8th frame
# of TIMELINE as written (its hand-keyed iterations track, "before"), of a
# copy with `iterations: Auto` (MARGIN, the track removed, "after"), and of
# a copy with a generous fixed count (REFERENCE iterations, the track
# removed, "reference"), at 320x180 with 16 samples a pixel on 2 threads,
# and prints bench/detail.py's measures of before and after: the share of
# frames whose high-frequency energy falls below frame 0's, and the share
# that lose more than 5% of the reference frame's energy.
#
# usage: bench/iterations.sh [OUT] [MARGIN] [TIMELINE] [REFERENCE]
#        (after `cargo build --release`)
#   OUT        work folder [default: out/iterations]
#   MARGIN     Auto's margin [default: 2]
#   TIMELINE   a zoom with a scene `iterations: N` and an iterations track
#              [default: timelines/zoom.ron]
#   REFERENCE  the reference's fixed count [default: 40]
set -eu
bin=${MANDELREEL:-target/release/mandelreel}
out=${1:-out/iterations}
margin=${2:-2}
timeline=${3:-timelines/zoom.ron}
reference=${4:-40}
mkdir -p "$out"

# A copy with the scene's count replaced by $2 and the iterations track cut.
copy() {
    python3 - "$timeline" "$1" "$2" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
text, n = re.subn(r"iterations: \d+,[^\n]*", f"iterations: {sys.argv[3]},", text, count=1)
track = re.compile(r'\n[ \t]*(//[^\n]*\n[ \t]*)*"fractal\.iterations": \([^()]*\[[^\]]*\],?\s*\),?')
text, m = track.subn("", text, count=1)
if n != 1 or m != 1:
    sys.exit(f"{sys.argv[1]} has no iterations line or track to replace")
open(sys.argv[2], "w").write(text)
PY
}
copy "$out/auto.ron" "Auto(margin: $margin)"
copy "$out/reference.ron" "$reference"

frames=$("$bin" info "$timeline" | sed -n 's/^frames: *\([0-9]*\).*/\1/p' | head -n 1)
frames=${frames:-120}
for name in before after reference; do
    tl=$timeline
    [ $name = after ] && tl=$out/auto.ron
    [ $name = reference ] && tl=$out/reference.ron
    frame=0
    while [ $frame -lt "$frames" ]; do
        "$bin" render "$tl" --frames $frame --size 320x180 --samples 16 --threads 2 \
            --out "$out/$name" --quiet >/dev/null
        frame=$((frame + 8))
    done
done
for name in before after; do
    echo "$name:"
    python3 bench/detail.py "$out/$name"/*.png --reference "$out/reference"/*.png
done
