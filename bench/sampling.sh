#!/bin/sh
# What adaptive sampling buys: renders frames of the examples with uniform
# 1, 4 and 16 samples a pixel and with adaptive sampling capped at 16, one after
# another in one run, each timed, and measures each with `mandelreel quality`
# against a 64-sample reference rendered with another seed (so that no
# candidate shares its random numbers). Prints a markdown table.
#
# usage: bench/sampling.sh [OUT] [NOISE...]   (after `cargo build --release`)
#   OUT    work folder [default: out/sampling]; references found there are kept
#   NOISE  adaptive noise levels to measure [default: 0.02 0.04]
# Frames: zoom.ron 60..120 and julia_morph.ron 48..96, at their own size.
set -eu
bin=${MANDELREEL:-target/release/mandelreel}
out=${1:-out/sampling}
[ $# -gt 0 ] && shift
noises=${*:-0.02 0.04}
mkdir -p "$out"

# timelines/NAME.ron with its samples_per_pixel line replaced by LINE.
variant() {
    sed "s|^        samples_per_pixel: .*|        $3|" "timelines/$1.ron" >"$out/$1_$2.ron"
    grep -q "^        $3" "$out/$1_$2.ron" || { echo "no samples_per_pixel line in timelines/$1.ron" >&2; exit 1; }
}

# Renders variant NAME of timeline TL over FRAMES, timed; prints its row.
measure() {
    tl=$1 frames=$2 name=$3
    rm -rf "${out:?}/${tl}_$name"
    start=$(date +%s.%N)
    "$bin" render "$out/${tl}_$name.ron" --frames "$frames" --out "$out/${tl}_$name" --quiet --stats \
        >"$out/${tl}_$name.log" 2>&1
    end=$(date +%s.%N)
    seconds=$(echo "$end - $start" | bc)
    # Samples a pixel, from --stats: "… N of M samples hit …".
    spp=$(grep -o 'of [0-9]* samples' "$out/${tl}_$name.log" | awk -v px="$pixels" \
        '{ s += $2; n++ } END { printf "%.2f", s / n / px }')
    "$bin" quality "$out/${tl}_$name" --reference "$out/${tl}_reference" --json >"$out/${tl}_$name.json"
    python3 - "$out/${tl}_$name.json" "$tl" "$name" "$seconds" "$spp" <<'EOF'
import json, sys
q = json.load(open(sys.argv[1]))
tl, name, seconds, spp = sys.argv[2], sys.argv[3], float(sys.argv[4]), sys.argv[5]
print(f"| {tl} | {name} | {seconds:.1f} | {spp} | {q['psnr_db']:.2f} | {q['speckles']} | {q['pops']} |")
EOF
}

echo "| timeline | sampling | seconds | samples/pixel | PSNR (dB) | speckles | pops |"
echo "|---|---|---:|---:|---:|---:|---:|"
for spec in "zoom 60..120" "julia_morph 48..96"; do
    set -- $spec
    tl=$1 frames=$2
    pixels=$(grep -o 'size: *([0-9]*, *[0-9]*)' "timelines/$tl.ron" | tr -dc '0-9,' | awk -F, '{ print $1 * $2 }')
    # Frames already rendered from the same inputs are skipped.
    variant "$tl" reference "samples_per_pixel: 64, seed: 982451653,"
    "$bin" render "$out/${tl}_reference.ron" --frames "$frames" --out "$out/${tl}_reference" --quiet >/dev/null
    for n in 1 4 16; do
        variant "$tl" "uniform-$n" "samples_per_pixel: $n,"
        measure "$tl" "$frames" "uniform-$n"
    done
    for noise in $noises; do
        variant "$tl" "adaptive-$noise" "samples_per_pixel: 16, adaptive: (first: 2, noise: $noise),"
        measure "$tl" "$frames" "adaptive-$noise"
    done
done
