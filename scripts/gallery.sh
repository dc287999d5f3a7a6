#!/usr/bin/env bash
# Regenerates docs/gallery.md and its contact sheets docs/gallery/NAME.png: every scene in
# examples/ is run as it is (`piola run`) and rendered with the defaults (`piola render
# --contact-sheet`: the camera frames the bodies, up follows the scene's gravity), six evenly
# spaced frames per sheet, small enough to commit.
#
#   scripts/gallery.sh [PIOLA] [NAME...]   PIOLA defaults to build/release/piola; NAMEs
#                                          (example names without .json) limit the run to
#                                          those sheets, the page lists every sheet present
#   scripts/gallery.sh --page              only rewrites docs/gallery.md from the sheets
# Runs take minutes each on a 2-core machine (`piola check examples/NAME.json` estimates
# them); the frames go to a temporary folder, only the PNGs and the page are kept.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
names=()
if [[ ${1:-} != --page ]]; then
  piola=${1:-$root/build/release/piola}
  shift || true
  [[ -x $piola ]] || { echo "gallery.sh: no piola program at $piola (build it, or give its path)" >&2; exit 2; }
  names=("$@")
  if [[ ${#names[@]} -eq 0 ]]; then
    for scene in "$root"/examples/*.json; do names+=("$(basename "$scene" .json)"); done
  fi
fi
# Render flags beyond the defaults, where the defaults hide the story (and the page says so).
declare -A extra=([plastic_sphere_gears]="--hide-obstacle gear")
mkdir -p "$root/docs/gallery"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for name in "${names[@]+"${names[@]}"}"; do
  scene=$root/examples/$name.json
  [[ -f $scene ]] || { echo "gallery.sh: no example $scene" >&2; exit 2; }
  echo "gallery.sh: $name" >&2
  "$piola" run "$scene" -o "$work/$name" >"$work/$name.log" 2>&1 || { cat "$work/$name.log" >&2; exit 1; }
  "$piola" render "$work/$name" --contact-sheet --sheet-frames 6 --sheet-width 240 --no-movie \
    --width 640 --height 360 ${extra[$name]:-} >>"$work/$name.log" 2>&1 || { cat "$work/$name.log" >&2; exit 1; }
  cp "$work/$name/render/contact_sheet.png" "$root/docs/gallery/$name.png"
  rm -rf "${work:?}/$name"
done

# the page: one section per sheet, with the first sentence of the scene's description
python3 - "$root" "$(for k in "${!extra[@]}"; do printf '%s=%s\n' "$k" "${extra[$k]}"; done)" <<'PY'
import json, os, re, sys
root = sys.argv[1]
extra = dict(line.split("=", 1) for line in sys.argv[2].splitlines() if "=" in line)
out = ["# Gallery", "",
       "Every scene in `examples/`, run as it is and drawn by `piola render` with its defaults",
       "(the camera frames the deformable bodies; six evenly spaced frames, time in seconds).",
       "Regenerate with `scripts/gallery.sh` (all examples, minutes each on two cores) or",
       "`scripts/gallery.sh build/release/piola NAME` for one.", ""]
for png in sorted(os.listdir(os.path.join(root, "docs", "gallery"))):
    name = png[:-4]
    scene = os.path.join(root, "examples", name + ".json")
    if not png.endswith(".png") or not os.path.exists(scene):
        continue
    text = json.load(open(scene)).get("description", "")
    first = re.split(r"(?<=[.!?])\s", text, maxsplit=1)[0] if text else ""
    out += [f"## {name}", "", first, "", f"![{name}](gallery/{png})", "",
            f"`piola run examples/{name}.json -o out/{name} && piola render out/{name} --contact-sheet"
            + (f" {extra[name]}" if name in extra else "") + "`"
            + (" (the obstacles hidden so the body shows)" if name in extra else ""), ""]
missing = sorted(f[:-5] for f in os.listdir(os.path.join(root, "examples"))
                 if f.endswith(".json") and not os.path.exists(os.path.join(root, "docs", "gallery", f[:-5] + ".png")))
if missing:
    out += ["## Not drawn yet", "",
            "These examples have no sheet here yet (they run for many minutes on two cores);",
            "`scripts/gallery.sh build/release/piola NAME` adds one: " + ", ".join(f"`{m}`" for m in missing) + ".", ""]
open(os.path.join(root, "docs", "gallery.md"), "w").write("\n".join(out))
PY
echo "gallery.sh: wrote docs/gallery.md ($(du -ch "$root"/docs/gallery/*.png | tail -1 | cut -f1) of sheets)" >&2
