#!/bin/sh
# Screenshots of the 3D view in report.html for docs/report.md: the default job's report,
# rendered by headless Chromium with WebGL on its software rasteriser (SwiftShader).
#
#   sh docs/view3d-screenshots.sh [OUT_DIR]     (from the repository root; default docs/images)
#
# Writes OUT_DIR/view3d-overall.png (the tool in the middle of roughing),
# view3d-blade-root.png (the blade-root finishing tool in the middle of its operation, seen
# down the tool) and view3d-worst-residual.png (the largest residual's marker and the move
# nearest it), 1280 x 800 px each. Needs `chromium` (Debian package) on PATH.
set -eu
out=${1:-docs/images}
mkdir -p "$out"
work=$(mktemp -d "${TMPDIR:-/tmp}/view3d-shots.XXXXXX")
cargo build --release -q -p impeller-cam
./target/release/impeller-cam run --out "$work/out" --quiet
report="$work/out/report.html"
for shot in "overall:focus=overall&at=rough" "blade-root:focus=op:blade-root&part=1&stock=0&links=0" \
    "worst-residual:focus=marker:residual"; do
    name=${shot%%:*}
    hash=${shot#*:}
    chromium --headless --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader \
        --no-first-run --disable-background-networking --disable-component-update \
        --disable-sync --hide-scrollbars --window-size=1280,800 --virtual-time-budget=30000 \
        --user-data-dir="$work/profile" --screenshot="$out/view3d-$name.png" \
        "file://$report#view3d&$hash" 2>/dev/null
    echo "wrote $out/view3d-$name.png"
done
ls -l "$report"
rm -rf "$work"
