#!/usr/bin/env bash
# `piola run` refuses bad input before writing anything: every bad scene exits 2 with the
# key path in its message and leaves the output folder exactly as it was; a folder that
# holds anything is refused without --force.
set -euo pipefail
: "${PIOLA:?path of the piola program}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0

good='{"fps": 10, "frames": 2, "solids": [{"mesh": {"generate": "box", "half_extents": [0.1, 0.1, 0.1], "cell_size": 0.1}}]}'

# expect_bad NAME JSON EXPECTED-SUBSTRING
expect_bad() {
  local name=$1 json=$2 expected=$3
  printf '%s\n' "$json" >"$work/$name.json"
  # 1) output folder does not exist: it must still not exist
  set +e
  "$PIOLA" run "$work/$name.json" -o "$work/out_$name" >"$work/stdout" 2>"$work/stderr"
  local rc=$?
  set -e
  if [[ $rc -ne 2 ]]; then echo "FAIL $name: exit code $rc, expected 2"; cat "$work/stderr"; fails=$((fails + 1)); fi
  if ! grep -qF -- "$expected" "$work/stderr"; then
    echo "FAIL $name: message does not name '$expected':"; cat "$work/stderr"; fails=$((fails + 1))
  fi
  if [[ -e "$work/out_$name" ]]; then echo "FAIL $name: created the output folder"; fails=$((fails + 1)); fi
  # 2) an existing folder with results, --force: nothing in it may change
  mkdir -p "$work/kept/frames"
  echo "earlier results" >"$work/kept/stats.csv"
  echo "frame" >"$work/kept/frames/frame_0000.vtu"
  local before after
  before=$(cd "$work/kept" && find . -type f -exec sha256sum {} + | sort)
  set +e
  "$PIOLA" run "$work/$name.json" -o "$work/kept" --force >/dev/null 2>"$work/stderr"
  rc=$?
  set -e
  after=$(cd "$work/kept" && find . -type f -exec sha256sum {} + | sort)
  if [[ $rc -ne 2 ]]; then echo "FAIL $name (--force): exit code $rc, expected 2"; fails=$((fails + 1)); fi
  if [[ "$before" != "$after" ]]; then echo "FAIL $name (--force): the output folder changed"; fails=$((fails + 1)); fi
}

expect_bad poisson '{"solids": [{"mesh": {"generate": "box", "half_extents": [0.1, 0.1, 0.1], "cell_size": 0.1}, "material": {"poisson_ratio": 0.7}}]}' \
  "solids[0].material.poisson_ratio"
expect_bad unknown_key '{"solids": [{"mesh": {"generate": "box", "half_extents": [0.1, 0.1, 0.1], "cell_size": 0.1}, "materiel": {}}]}' \
  "solids[0].materiel: unknown key"
expect_bad wrong_type '{"fps": "fast", "solids": [{"mesh": {"generate": "box", "half_extents": [0.1, 0.1, 0.1], "cell_size": 0.1}}]}' \
  "fps: must be a number"
expect_bad keys_order '{"gravity": [0, 0, {"keys": [[1, 0], [0, -9.81]]}], "solids": [{"mesh": {"generate": "box", "half_extents": [0.1, 0.1, 0.1], "cell_size": 0.1}}]}' \
  "gravity[2].keys[1]: times must increase"
expect_bad obstacle '{"solids": [{"mesh": {"generate": "box", "half_extents": [0.1, 0.1, 0.1], "cell_size": 0.1}}], "obstacles": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 0]}]}' \
  "obstacles[0].normal: must be a nonzero vector"
expect_bad missing_mesh '{"solids": [{"mesh": "no_such_mesh.veg"}]}' "solids[0].mesh"
expect_bad bad_index '{"solids": [{"mesh": {"generate": "box", "half_extents": [0.1, 0.1, 0.1], "cell_size": 0.1}, "fixed": [{"indices": [100000]}]}]}' \
  "solids[0].fixed[0].indices[0]: vertex 100000 is out of range"
expect_bad empty_shells '{"shells": []}' "shells: is empty and there are no solids"
# a shell's driven selector after a fixed one: named by its own key, not by its place in the
# shell's combined constraint list
expect_bad shell_driven_index '{"shells": [{"mesh": {"generate": "rectangle", "size": [0.2, 0.2], "resolution": [4, 4]}, "fixed": [{"indices": [0]}], "driven": [{"indices": [1], "motion": {"velocity": [0, 0, 1]}}, {"indices": [999], "motion": {"velocity": [0, 0, 1]}}]}]}' \
  "shells[0].driven[1].indices[0]: vertex 999 is out of range"
# a closed surface given as a solid's mesh: the message says how to fill it with tets
cp "${PIOLA_DATA_DIR:?}/surface/sphere.obj" "$work/sphere.obj"
expect_bad surface_mesh "{\"solids\": [{\"mesh\": \"$work/sphere.obj\"}]}" \
  "is a surface, not a tet mesh; fill it with tets first: piola mesh generate"
expect_bad not_json '{"solids": [' "invalid JSON"

# a folder that holds anything is refused without --force, and left alone
printf '%s\n' "$good" >"$work/good.json"
mkdir -p "$work/busy"
echo "mine" >"$work/busy/notes.txt"
set +e
"$PIOLA" run "$work/good.json" -o "$work/busy" >/dev/null 2>"$work/stderr"
rc=$?
set -e
if [[ $rc -ne 2 ]]; then echo "FAIL busy folder: exit code $rc, expected 2"; fails=$((fails + 1)); fi
grep -q -- "--force" "$work/stderr" || { echo "FAIL busy folder: message does not mention --force"; cat "$work/stderr"; fails=$((fails + 1)); }
if [[ "$(ls "$work/busy")" != "notes.txt" ]]; then echo "FAIL busy folder: contents changed"; fails=$((fails + 1)); fi

# bad command lines
for args in "" "$work/good.json" "$work/good.json -o" "$work/good.json -o $work/x --threads 0" \
            "$work/good.json -o $work/x --frames -3" "$work/good.json -o $work/x --bogus"; do
  set +e
  # shellcheck disable=SC2086
  "$PIOLA" run $args >/dev/null 2>&1
  rc=$?
  set -e
  if [[ $rc -ne 2 ]]; then echo "FAIL args '$args': exit code $rc, expected 2"; fails=$((fails + 1)); fi
done
[[ -e "$work/x" ]] && { echo "FAIL bad command lines created an output folder"; fails=$((fails + 1)); }

if [[ $fails -ne 0 ]]; then echo "$fails failures"; exit 1; fi
echo "all bad inputs refused with exit code 2 and untouched output folders"
