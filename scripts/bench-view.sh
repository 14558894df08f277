#!/usr/bin/env bash
# The live window's benchmark (issue 35): runs `twister view` (release build) for N frames with
# vsync off and reports its frames per second and its resident memory at frame 1,000 and at the
# last frame (a window that runs for hours must keep its memory flat). Without a display it runs
# under a virtual X server (xvfb-run; scripts/test.sh installs Xvfb).
#
#   scripts/bench-view.sh [FRAMES] [view options...]     default: 10000 frames of builtin:demo at 792x150
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${1:-10000}
shift || true
opts=("$@")
if [ ${#opts[@]} -eq 0 ]; then opts=(builtin:demo --width 792 --height 150); fi
cargo build --release --quiet
bin=target/release/twister
log=$(mktemp)
run=("$bin" view "${opts[@]}" --vsync off --exit-after "$frames" --trace-frames)
if [ -z "${DISPLAY:-}" ] && [ -z "${WAYLAND_DISPLAY:-}" ]; then
    xvfb-run -a -s "-screen 0 1920x1080x24" "${run[@]}" >"$log"
else
    "${run[@]}" >"$log"
fi
awk -v n="$frames" '
    /^frame / {
        split($0, f, " ");
        for (i in f) { split(f[i], kv, "="); v[kv[1]] = kv[2] }
        k = f[2] + 0;
        if (k == 1000 || (k == 1 && n < 1000)) { rss0 = v["rss_mib"]; at0 = k }
        if (k == n) { rss1 = v["rss_mib"]; fps = v["fps"]; ms = v["ms_render"] }
    }
    END {
        printf "frames %d, last second %.2f fps (the renderer %.1f ms a frame)\n", n, fps, ms;
        printf "resident memory: frame %d %.1f MiB, frame %d %.1f MiB (%+.1f MiB)\n", at0, rss0, n, rss1, rss1 - rss0;
    }' "$log"
rm -f "$log"
