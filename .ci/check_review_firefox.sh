#!/usr/bin/env bash
# The review page (of `formation track --review` and of `formation annotate`) in headless
# Firefox, from file:// with no server. Firefox has no DOM dump on its command line, so a script
# injected into a copy of the page makes the same edits as .ci/check_review.sh (delete a bird, drag
# one, add one by a click, step frames), presses Save, checks the saved annotations itself (the
# deleted bird gone, the moved one moved, one new bird, frame 1 unchanged) and paints the page
# green when they hold, red otherwise; the screenshot's colour is the verdict.
set -euo pipefail
f=${FORMATION:-./target/release/formation}
dir="$(mktemp -d)"
trap '[ -n "${KEEP:-}" ] || rm -rf "$dir"' EXIT
browser=$(command -v firefox-esr || command -v firefox || true)
[ -n "$browser" ] || { echo "no Firefox (apt-get install firefox-esr)"; exit 1; }
$f track tests/data/track_frames --quiet -o "$dir/a.json" --review "$dir/track.html"
# The same birds as a long CSV, reviewed with `annotate` over the same frames.
python3 - "$dir" <<'PY'
import json, sys
d = sys.argv[1]
a = json.load(open(f"{d}/a.json"))
with open(f"{d}/a.csv", "w") as fh:
    fh.write("frame,bird,x,y\n")
    for k, fr in enumerate(a["frames"]):
        for b in fr["birds"]:
            fh.write(f"{k},{b['id']},{b['x']},{b['y']}\n")
PY
$f annotate "$dir/a.csv" --images tests/data/track_frames --wingspan-px 12 --heading right \
    --quiet -o "$dir/annotate.html"
cat > "$dir/drive.js" <<'JS'
<script>
window.addEventListener("load", () => {
  const cv = document.getElementById("c"), A = JSON.parse(document.getElementById("data").textContent).annotations;
  const W = A.image_size[0], H = A.image_size[1];
  const at = (type, x, y) => {
    const r = cv.getBoundingClientRect();
    cv.dispatchEvent(new MouseEvent(type, { bubbles: true, clientX: r.left + x * r.width / W, clientY: r.top + y * r.height / H }));
  };
  const key = k => document.body.dispatchEvent(new KeyboardEvent("keydown", { key: k, bubbles: true }));
  const before = JSON.parse(JSON.stringify(A));
  const birds = A.frames[0].birds;
  const gone = birds[0], moved = { ...birds[1] };
  let saved = null;
  const RealBlob = window.Blob;
  window.Blob = function (parts, opts) { saved = parts.join(""); return new RealBlob(parts, opts); };
  HTMLAnchorElement.prototype.click = function () {};
  at("mousedown", gone.x, gone.y); window.dispatchEvent(new MouseEvent("mouseup")); key("Delete");
  at("mousedown", moved.x, moved.y); at("mousemove", moved.x + 3, moved.y + 30); window.dispatchEvent(new MouseEvent("mouseup"));
  at("mousedown", 20, 75); window.dispatchEvent(new MouseEvent("mouseup"));
  key("ArrowRight");
  const stepped = document.getElementById("where").textContent.startsWith("frame 1 ");
  key("ArrowLeft");
  document.getElementById("save").click();
  const problems = [];
  try {
    const s = JSON.parse(saved);
    const s0 = new Map(s.frames[0].birds.map(b => [b.id, b]));
    const b0 = new Map(before.frames[0].birds.map(b => [b.id, b]));
    if (s0.has(gone.id)) problems.push("deleted bird still there");
    const m = s0.get(moved.id);
    if (!m || Math.abs(m.x - moved.x - 3) > 0.6 || Math.abs(m.y - moved.y - 30) > 0.6) problems.push("moved bird not moved");
    const added = [...s0.values()].filter(b => !b0.has(b.id));
    if (added.length !== 1 || Math.abs(added[0].x - 20) > 0.6 || Math.abs(added[0].y - 75) > 0.6) problems.push("no added bird");
    if (JSON.stringify(s.frames[1].birds) !== JSON.stringify(before.frames[1].birds)) problems.push("frame 1 changed");
    if (!stepped) problems.push("arrow keys do not step");
  } catch (e) { problems.push("save: " + e); }
  document.body.innerHTML = "";
  document.body.style.background = problems.length ? "rgb(255,0,0)" : "rgb(0,255,0)";
  document.title = problems.length ? "FAILED " + problems.join("; ") : "OK";
});
</script>
JS
for page in track annotate; do
    sed -e "/<\/body>/e cat $dir/drive.js" "$dir/$page.html" > "$dir/test_$page.html"
    rm -f "$dir/$page.png"
    HOME="$dir/home" timeout 120 "$browser" --headless --no-remote --profile "$(mkdir -p "$dir/profile_$page" && echo "$dir/profile_$page")" \
        --window-size=400,300 --screenshot "$dir/$page.png" "file://$dir/test_$page.html" >"$dir/firefox_$page.log" 2>&1 || true
    [ -s "$dir/$page.png" ] || { echo "Firefox wrote no screenshot of the $page page"; cat "$dir/firefox_$page.log"; exit 1; }
    python3 - "$dir/$page.png" "$page" <<'PY'
import struct, sys, zlib
# The verdict is the page's colour: read the PNG's first row (8-bit RGB or RGBA, filter 0 or 1..4).
data = open(sys.argv[1], "rb").read()
w, h, depth, ctype = struct.unpack(">IIBB", data[16:26])
chunks, i = b"", 8
while i < len(data):
    n, kind = struct.unpack(">I4s", data[i:i + 8])
    if kind == b"IDAT":
        chunks += data[i + 8:i + 8 + n]
    i += 12 + n
raw = zlib.decompress(chunks)
bpp = {2: 3, 6: 4}[ctype]
row = raw[1:1 + w * bpp]
assert raw[0] in (0, 1), "filter %d" % raw[0]
if raw[0] == 1:  # Sub: each byte adds the one bpp before it
    row = bytearray(row)
    for k in range(bpp, len(row)):
        row[k] = (row[k] + row[k - bpp]) & 255
px = tuple(row[(w // 2) * bpp:(w // 2) * bpp + 3])
verdict = {(0, 255, 0): "OK", (255, 0, 0): "FAILED"}.get(px, "no verdict (colour %s)" % (px,))
print(f"review page in Firefox ({sys.argv[2]}): {verdict}")
sys.exit(0 if verdict == "OK" else 1)
PY
done
