#!/usr/bin/env bash
# The review page of `formation track --review` in headless Chromium, from file:// with no
# server: a script injected into a copy of the page drives it with real mouse and keyboard events
# (delete a bird, drag one, add one by a click, step frames), presses Save and captures the
# download; the saved annotations must hold exactly those edits and `formation extract` must
# read them. The page must load without a console message. With --screenshot FILE, also writes
# the screenshot used in docs/annotating.md.
set -euo pipefail
f=${FORMATION:-./target/release/formation}
dir="$(mktemp -d)"
trap '[ -n "${KEEP:-}" ] || rm -rf "$dir"' EXIT
browser=$(command -v chromium-headless-shell || command -v chromium || true)
[ -n "$browser" ] || { echo "no headless Chromium (apt-get install chromium-headless-shell)"; exit 1; }
flags=(--headless --no-sandbox --disable-gpu --no-first-run --disable-background-networking
       --disable-component-update --disable-sync --user-data-dir="$dir/profile")
$f track tests/data/track_frames --quiet -o "$dir/a.json" --review "$dir/review.html"
if grep -Eq '(src|href)="(https?:)?//' "$dir/review.html"; then echo "review page fetches from the network"; exit 1; fi
if [ "${1:-}" = "--screenshot" ]; then
    "$browser" "${flags[@]}" --hide-scrollbars --window-size=1000,640 \
        --screenshot="$2" "file://$dir/review.html" 2>/dev/null
fi
# The edits, in image pixels: frame 0's birds are read from the page's own data.
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
  const log = [];
  const birds = A.frames[0].birds;
  const gone = birds[0], moved = birds[1];
  log.push("delete " + gone.id);
  at("mousedown", gone.x, gone.y); window.dispatchEvent(new MouseEvent("mouseup")); key("Delete");
  log.push("move " + moved.id);
  at("mousedown", moved.x, moved.y); at("mousemove", moved.x + 3, moved.y + 30); window.dispatchEvent(new MouseEvent("mouseup"));
  log.push("add");
  at("mousedown", 20, 75); window.dispatchEvent(new MouseEvent("mouseup"));
  key("ArrowRight");
  log.push(document.getElementById("where").textContent);
  key("ArrowLeft");
  log.push(document.getElementById("where").textContent);
  const real = URL.createObjectURL.bind(URL);
  URL.createObjectURL = blob => {
    blob.text().then(t => {
      const pre = document.createElement("pre"); pre.id = "saved"; pre.textContent = t; document.body.appendChild(pre);
    });
    return real(blob);
  };
  const out = document.createElement("pre"); out.id = "log"; out.textContent = log.join("\n"); document.body.appendChild(out);
  document.getElementById("save").click();
});
</script>
JS
sed -e "/<\/body>/e cat $dir/drive.js" "$dir/review.html" > "$dir/test.html"
"$browser" "${flags[@]}" --enable-logging=stderr --v=0 --virtual-time-budget=5000 \
    --dump-dom "file://$dir/test.html" >"$dir/dom.html" 2>"$dir/chromium.log"
if grep -q ':CONSOLE' "$dir/chromium.log"; then
    echo "review page: console messages:"; grep ':CONSOLE' "$dir/chromium.log"; exit 1
fi
python3 - "$dir" <<'PY'
import html, json, re, sys
d = sys.argv[1]
dom = open(f"{d}/dom.html").read()
m = re.search(r'<pre id="saved">(.*?)</pre>', dom, re.S)
assert m, "Save gave nothing"
saved = json.loads(html.unescape(m.group(1)))
log = html.unescape(re.search(r'<pre id="log">(.*?)</pre>', dom, re.S).group(1)).split("\n")
before = json.load(open(f"{d}/a.json"))
gone, moved = int(log[0].split()[1]), int(log[1].split()[1])
assert log[3].startswith("frame 1 "), log
assert log[4].startswith("frame 0 "), log
b0 = {b["id"]: b for b in before["frames"][0]["birds"]}
s0 = {b["id"]: b for b in saved["frames"][0]["birds"]}
assert gone not in s0, "the deleted bird is still there"
assert abs(s0[moved]["x"] - (b0[moved]["x"] + 3)) < 0.6 and abs(s0[moved]["y"] - (b0[moved]["y"] + 30)) < 0.6, s0[moved]
new = [b for i, b in s0.items() if i not in b0]
assert len(new) == 1 and abs(new[0]["x"] - 20) < 0.6 and abs(new[0]["y"] - 75) < 0.6, new
assert len(s0) == len(b0), (len(s0), len(b0))
assert saved["frames"][1] == before["frames"][1], "frame 1 changed"
json.dump(saved, open(f"{d}/saved.json", "w"))
print(f"review page: deleted bird {gone}, moved bird {moved}, added bird {new[0]['id']}, stepped frames, saved")
PY
$f extract "$dir/saved.json" --quiet --json > "$dir/params.json"
python3 - "$dir" <<'PY'
import json, sys
d = sys.argv[1]
p = json.load(open(f"{d}/params.json"))
saved = json.load(open(f"{d}/saved.json"))
ids0 = sorted(b["id"] for b in saved["frames"][0]["birds"])
assert sorted(p["frames"][0]["order"]) == ids0, (p["frames"][0]["order"], ids0)
print(f"extract read the saved annotations: frame 0 birds {ids0}")
PY
