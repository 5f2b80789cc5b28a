#!/usr/bin/env bash
# Browser check of `batten report`: build the reports of a bundled curve and of the bundled
# dented hood surface, load each in headless Chromium, check that the page loaded (the DOM
# has the comparison table and the inline SVG plots or PNG pictures) and that its
# screenshot is not blank.
#
# Usage: scripts/check_report_browser.sh [OUT_DIR]
#   OUT_DIR keeps report.html, surface-report.html, and for each page (curve, surface)
#   PAGE-dom.html and PAGE-screenshot.png (default: a temporary directory,
#   removed at the end). Needs chromium (Debian: apt-get install chromium) and python3.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v chromium >/dev/null 2>&1; then
  echo "check_report_browser: chromium not found (apt-get install chromium)" >&2
  exit 1
fi

profile=$(mktemp -d)
if [ $# -ge 1 ]; then
  out=$1
  mkdir -p "$out"
  trap 'rm -rf "$profile"' EXIT
else
  out=$(mktemp -d)
  trap 'rm -rf "$profile" "$out"' EXIT
fi

example=examples/data/strophoid-noisy.csv
cargo build --release -q -p batten-cli
target/release/batten report "$example" --methods han,mst,kjellander --tolerance 0.1 \
  -o "$out/report.html"
test -s "$out/report.html"
# The surface page: curvature maps, isophotes and zebra as inline PNG images.
target/release/batten report examples/data/hood-dented.json -o "$out/surface-report.html"
test -s "$out/surface-report.html"

chrome() {
  timeout 120 chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync \
    --user-data-dir="$profile" "$@"
}

cat >"$profile/check.py" <<'EOF'
import re, struct, sys, zlib

dom = open(sys.argv[1], encoding="utf-8").read()
page = sys.argv[3]
checks = {
    "the comparison table": '<table class="compare">' in dom,
    "the metrics table": '<table class="metrics">' in dom,
}
svgs = len(re.findall(r"<svg[ >]", dom))
imgs = len(re.findall(r'<img [^>]*src="data:image/png;base64,', dom))
if page == "curve":
    checks["a method's section"] = "<h2>han</h2>" in dom
    checks["8 inline SVG plots (input + 3 methods, comb and curvature each)"] = svgs == 8
else:
    checks["the methods' sections"] = "<h2>salvi</h2>" in dom and "<h2>eck-hadenfeld</h2>" in dom
    checks["3 inline PNG pictures (input + 2 methods)"] = imgs == 3
for what, ok in checks.items():
    if not ok:
        sys.exit(f"check_report_browser: the {page} page lacks {what} ({svgs} svg, {imgs} img)")


def png_pixels(path):
    """Decode an 8-bit RGB or RGBA, non-interlaced PNG (what Chromium writes): width,
    height, bytes per pixel and the unfiltered rows."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit("check_report_browser: the screenshot is not a PNG")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, color, _, _, interlace = header
    if depth != 8 or color not in (2, 6) or interlace != 0:
        sys.exit(f"check_report_browser: unexpected PNG format {header}")
    bpp = 3 if color == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * bpp
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 255
        rows.append(line)
        prev = line
    return width, height, bpp, rows


width, height, bpp, rows = png_pixels(sys.argv[2])
ink = coloured = 0
for line in rows:
    for i in range(0, len(line), bpp):
        r, g, b = line[i], line[i + 1], line[i + 2]
        if min(r, g, b) < 235:
            ink += 1
            if max(r, g, b) - min(r, g, b) > 60:
                coloured += 1
total = width * height
# Text, tables, axes and curves: well over 1% of the pixels; curves and combs in colour.
if ink < total // 100 or coloured < 2000:
    sys.exit(f"check_report_browser: the screenshot looks blank: {ink} dark and {coloured} "
             f"coloured pixels of {total}")
print(f"check_report_browser: {page} page ok: {svgs} svg and {imgs} img plots in the DOM; "
      f"screenshot {width}x{height}, {ink} dark pixels ({100 * ink / total:.1f}%), "
      f"{coloured} coloured")
EOF

for page in curve surface; do
  html=$out/report.html
  [ "$page" = surface ] && html=$out/surface-report.html
  url="file://$(realpath "$html")"
  chrome --dump-dom "$url" >"$out/$page-dom.html" 2>/dev/null
  chrome --screenshot="$out/$page-screenshot.png" --window-size=1200,2000 "$url" >/dev/null 2>&1
  test -s "$out/$page-screenshot.png"
  python3 "$profile/check.py" "$out/$page-dom.html" "$out/$page-screenshot.png" "$page"
done
