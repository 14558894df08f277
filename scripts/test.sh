#!/usr/bin/env bash
# The project's test command (README quick start, and what CI runs).
# Installs Mesa's software Vulkan driver (lavapipe) when no Vulkan driver is present, ffmpeg
# (for `render --video`) and Xvfb with xdotool (for `view`'s window) when they are missing, then
# runs the whole test suite: cargo's, then the Python package's (pytest). Extra arguments go
# to `cargo test`.
set -euo pipefail
cd "$(dirname "$0")/.."

have_vulkan_driver() {
    # Capture first: with pipefail, `grep -q` closing the pipe early would fail the pipeline.
    local libs icds
    libs=$(ldconfig -p 2>/dev/null || true)
    icds=$(ls /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json /usr/local/share/vulkan/icd.d/*.json 2>/dev/null || true)
    [[ "$libs" == *libvulkan.so.1* && -n "$icds" ]]
}

missing=()
if ! have_vulkan_driver; then
    echo "No Vulkan driver found: installing Mesa's software Vulkan driver (lavapipe)..."
    missing+=(mesa-vulkan-drivers libvulkan1)
fi
if ! command -v ffmpeg >/dev/null 2>&1; then
    echo "No ffmpeg found: installing it (render --video encodes with it)..."
    missing+=(ffmpeg)
fi
# `twister view`'s tests run its window under a virtual X server, keys sent by xdotool.
if ! command -v Xvfb >/dev/null 2>&1 || ! command -v xdotool >/dev/null 2>&1; then
    echo "No Xvfb or xdotool found: installing them (the live window's tests)..."
    missing+=(xvfb xauth xdotool)
fi
if [[ "$(ldconfig -p 2>/dev/null || true)" != *libxkbcommon-x11.so.0* ]]; then
    missing+=(libxkbcommon-x11-0)
fi
# The Python package's and the Blender add-on's tests run in virtual environments.
if ! python3 -c "import ensurepip, venv" >/dev/null 2>&1; then
    echo "No Python venv module found: installing it (the Python package's tests)..."
    missing+=(python3-venv)
fi
if [ ${#missing[@]} -gt 0 ]; then
    sudo=""
    if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
    export DEBIAN_FRONTEND=noninteractive DEBCONF_NOWARNINGS=yes
    $sudo apt-get update -qq
    $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# Quiet Mesa's device-select layer, which complains when XDG_RUNTIME_DIR is unset.
export NODEVICE_SELECT=1

# Tests that need the third-party assets (TWISTER_ASSETS, default ../shared/assets) run where
# they are found; the others leave a file each here, counted below (cargo hides what passing
# tests print). Under CI (CI=true) a missing asset fails its test instead.
skips="$PWD/target/asset-skips"
rm -rf "$skips"
export TWISTER_ASSET_SKIPS="$skips"
status=0
cargo test "$@" || status=$?

# The Python package (python/): installed into a virtual environment under target/ as users
# install it (`pip install ./python`; here with cargo's dev profile, which shares the build
# above), then its tests (pytest), which compare it with the binary just built.
venv=target/python-venv
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
pip=("$venv/bin/python" -m pip -q --disable-pip-version-check)
"${pip[@]}" install numpy pytest matplotlib
rm -rf target/wheels
MATURIN_PEP517_ARGS="--profile dev" "${pip[@]}" wheel --no-deps -w target/wheels ./python
"${pip[@]}" install --force-reinstall --no-deps target/wheels/twister-*.whl
"$venv/bin/python" -m pytest -q -p no:cacheprovider python/tests || status=$?

# The Blender add-on (blender/): its tests run in Blender as a Python module (bpy 4.5, which
# needs Python 3.11), with the package above installed, against Cycles.
if command -v python3.11 >/dev/null 2>&1; then
    bvenv=target/blender-venv
    if [ ! -x "$bvenv/bin/python" ]; then
        python3.11 -m venv "$bvenv"
    fi
    bpip=("$bvenv/bin/python" -m pip -q --disable-pip-version-check)
    "${bpip[@]}" install "bpy==4.5.*" pytest
    "${bpip[@]}" install --force-reinstall --no-deps target/wheels/twister-*.whl
    TWISTER_BIN="$PWD/target/debug/twister" "$bvenv/bin/python" -m pytest -q -p no:cacheprovider blender/tests || status=$?
elif [ "${CI:-}" = "true" ]; then
    echo "the Blender add-on's tests need Python 3.11 (bpy 4.5): not found"
    status=1
else
    echo "blender add-on tests not run: they need Python 3.11 (bpy 4.5)"
fi

if [ -d "$skips" ]; then
    n=$(find "$skips" -type f | wc -l)
    echo "asset tests not run: $n (${TWISTER_ASSETS:-../shared/assets} not found; set TWISTER_ASSETS)"
fi
exit "$status"
