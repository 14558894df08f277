#!/usr/bin/env bash
# Renders the Cycles references of tests/cycles.rs with Blender (3.4 or later: `apt-get install
# blender`) and checks twister against them. Not part of the test suite (CI has no Blender): the
# snapped renders are committed in tests/data/cycles/.
set -euo pipefail
cd "$(dirname "$0")/../.."
work=$(mktemp -d)
cargo run -q --release --example cycles_reference -- export "$work"
render() { blender -b -P scripts/cycles/render_cycles.py -- "$work/demo.obj" "$work/$1" "${6:-512}" "$2" "$3" "$4" "${5:-centre}" "${7:-equirect}" >/dev/null; }
render parallel parallel 60 75
render converge2m 2.0 60 75
render no_pole_merge parallel off off
# VR180: the front half, 256 × 256 per eye (tests/cycles.rs compares it).
render vr180 parallel 60 75 centre 256 vr180
cargo run -q --release --example cycles_reference -- snap "$work/vr180" tests/data/cycles/demo_vr180
# The fulldome master: an equidistant fisheye of 200°, mono, 256 × 256.
render fisheye200 mono 60 75 centre 256 fisheye:200
cargo run -q --release --example cycles_reference -- snap "$work/fisheye200" tests/data/cycles/demo_fisheye200
# The anti-aliasing reference: a one-pixel box filter, kept as rendered (not snapped).
render parallel_box parallel 60 75 box
cp "$work/parallel_box_L.png" tests/data/cycles/demo_parallel_box_L.png
cp "$work/parallel_box_R.png" tests/data/cycles/demo_parallel_box_R.png
for case in "parallel parallel" "converge2m 2.0" "no_pole_merge parallel off"; do
    set -- $case
    cargo run -q --release --example cycles_reference -- snap "$work/$1" "tests/data/cycles/demo_$1"
    echo "$1:"
    cargo run -q --release --example cycles_reference -- compare "tests/data/cycles/demo_$1" 512 "${@:2}"
done
rm -rf "$work"
