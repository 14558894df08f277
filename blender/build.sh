#!/usr/bin/env bash
# Writes the add-on's installable zips into blender/dist/:
#   twister_blender-VERSION.zip         a Blender extension (4.2+: Edit > Preferences > Get Extensions > Install from Disk)
#   twister_blender-VERSION-legacy.zip  the same package as a legacy add-on (Add-ons > Install from Disk)
set -euo pipefail
cd "$(dirname "$0")"
python3 - <<'PY'
import pathlib, re, zipfile
src = pathlib.Path("twister_blender")
version = re.search(r'^version = "([^"]+)"', (src / "blender_manifest.toml").read_text(), re.M).group(1)
dist = pathlib.Path("dist")
dist.mkdir(exist_ok=True)
files = sorted(p for p in src.rglob("*") if p.is_file() and "__pycache__" not in p.parts)
for name, prefix in [(f"twister_blender-{version}.zip", ""), (f"twister_blender-{version}-legacy.zip", "twister_blender/")]:
    with zipfile.ZipFile(dist / name, "w", zipfile.ZIP_DEFLATED) as z:
        for p in files:
            z.write(p, prefix + str(p.relative_to(src)))
    print(dist / name)
PY
