#!/usr/bin/env bash
# The last classes of bad input are refused before use, each at once (a hang is caught by
# `timeout`) with the documented exit code and a message saying what is wrong: named pipes,
# devices and folders given as meshes or scenes, a NUL escape in a scene path, an output
# folder that cannot be written, control bytes from a file in a message, a scene implying
# absurd work (and the documented override), refinement_levels outside 0..6.
set -uo pipefail
: "${PIOLA:?path of the piola program}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }

# expect CODE SUBSTRING -- COMMAND...: exit code and message (stderr) of one command
expect() {
  local code=$1 text=$2
  shift 3
  timeout 20 "$@" >stdout 2>stderr
  local rc=$?
  [[ $rc -eq 124 ]] && { fail "$*: hung (killed after 20 s)"; return; }
  [[ $rc -eq $code ]] || { fail "$*: exit $rc, expected $code: $(cat stderr)"; return; }
  grep -qF -- "$text" stderr || { fail "$*: message lacks '$text': $(cat stderr)"; return; }
  echo "ok   $* -> $rc: $(head -c 200 stderr)"
}

box='{"generate": "box", "half_extents": [0.1, 0.1, 0.1], "cell_size": 0.1}'
mkfifo pipe.msh pipe.json
mkdir folder.msh
ln -s /dev/zero zero.msh
expect 1 "not a regular file (a named pipe)" -- "$PIOLA" mesh info pipe.msh
expect 1 "not a regular file (a character device)" -- "$PIOLA" mesh info zero.msh
expect 1 "not a regular file (a folder)" -- "$PIOLA" mesh info folder.msh
expect 1 "not a regular file (a named pipe)" -- "$PIOLA" mesh convert pipe.msh out.vtu
for m in pipe.msh zero.msh folder.msh; do
  echo "{\"fps\": 10, \"frames\": 1, \"solids\": [{\"mesh\": \"$m\"}]}" >"scene_$m.json"
  expect 2 "solids[0].mesh: ./$m: not a regular file" -- "$PIOLA" run "scene_$m.json" -o "out_$m"
  [[ -e "out_$m" ]] && fail "run with mesh $m created its output folder"
done
expect 2 "pipe.json: not a regular file (a named pipe)" -- "$PIOLA" run pipe.json -o out_pipe

# an embedded NUL would cut the path to cube.msh, which exists
"$PIOLA" mesh generate box --half-extents 0.1,0.1,0.1 --cell-size 0.1 -o cube.msh >/dev/null 2>&1 ||
  "$PIOLA" mesh convert "${PIOLA_DATA_DIR:-$PIOLA_SOURCE_DIR/../shared/data}/tetgen/octahedron.node" cube.msh >/dev/null
[[ -s cube.msh ]] || fail "could not make cube.msh"
printf '{"fps": 10, "frames": 1,\n "solids": [{"mesh": "cube.msh\\u0000.bad"}]}\n' >nul.json
expect 2 'nul.json:2:31: a string holds \u0000' -- "$PIOLA" run nul.json -o out_nul
[[ -e out_nul ]] && fail "the NUL scene created its output folder"

# output folders that cannot be written: before the scene is even read (exit 2)
echo "{\"fps\": 10, \"frames\": 1, \"solids\": [{\"mesh\": $box}]}" >good.json
expect 2 "cannot write in /proc" -- "$PIOLA" run good.json -o /proc/forbidden
expect 2 "output folder" -- "$PIOLA" run good.json -o /proc/sys/forbidden/deeper
expect 2 "Not a directory" -- "$PIOLA" run good.json -o good.json/sub
expect 2 "exists and is not a folder" -- "$PIOLA" run good.json -o good.json
expect 2 "cannot write in /proc" -- "$PIOLA" run pipe.json -o /proc/forbidden  # the folder first

# a material out of range is named by its key path (the C library checks it, under
# solids[i].material)
echo "{\"solids\": [{\"mesh\": $box, \"material\": {\"model\": \"spline\", \"spline\": {\"compression_stretch\": 0.2}}}]}" >spline.json
expect 2 "solids[0].material.spline.compression_stretch must be in (inversion.threshold = 0.3, 1), got 0.2" -- "$PIOLA" check spline.json

echo '{"solids": [{"mesh": '"$box"'}], "obstacles": [{"type": "mesh", "path": "missing.obj"}]}' >obstacle.json
expect 2 "obstacles[0].path: " -- "$PIOLA" check obstacle.json

# control bytes of a file never reach the terminal
printf '1 3 0 0\n1 0 0 \033[2J\033]0;title\007\n' >esc.node
printf '1 4 0\n1 1 1 1 1\n' >esc.ele
timeout 20 "$PIOLA" mesh info esc.node >/dev/null 2>stderr
[[ -s stderr ]] || fail "esc.node: no message"
LC_ALL=C grep -q $'[\x01-\x08\x0b-\x1f\x7f]' stderr && fail "esc.node: control bytes in the message: $(od -c stderr | head)"
printf '{"fps": 10, "frames": 1, "solids": [{"mesh": "\033[2J\302\233\377.msh"}]}' >esc.json
expect 2 './\x1b[2J\xc2\x9b\xff.msh: cannot open' -- "$PIOLA" run esc.json -o out_esc
LC_ALL=C grep -q $'[\x01-\x08\x0b-\x1f\x7f]' stderr && fail "esc.json: control bytes in the message"

# the time-budget guard and its override
echo "{\"fps\": 1e-300, \"frames\": 1, \"solids\": [{\"mesh\": $box}]}" >slow.json
expect 2 "raise the limit with --max-steps" -- "$PIOLA" run slow.json -o out_slow
[[ -e out_slow ]] && fail "the refused run created its output folder"
grep -q "backward_euler" stderr && fail "slow.json: the deformed-start hint for a step at max_dt: $(cat stderr)"
# a start scrambled far past its rest size: the first step is far below the rest state's, and
# the refusal says why and names the implicit integrator
echo "{\"fps\": 30, \"frames\": 1, \"gravity\": [0, 0, 0], \"solids\": [{\"mesh\": $box, \"material\": {\"model\": \"stvk\"}, \"initial\": {\"scramble\": 5}}]}" >scrambled.json
expect 2 'If a solid starts deformed (initial.scramble, initial.matrix), it is far stiffer where it is stretched, and the explicit step stays that short until it recovers: "integrator": {"type": "backward_euler"}' -- "$PIOLA" run scrambled.json -o out_scrambled --max-steps 10
[[ -e out_scrambled ]] && fail "the refused scrambled run created its output folder"
# a start past what positions can hold (1e6 times the solid's size): refused, naming the keys
for big in '"scramble": 1e100' '"scramble": 1e300' '"matrix": [[1e300, 0, 0], [0, 1, 0], [0, 0, 1]]'; do
  echo "{\"fps\": 30, \"frames\": 1, \"solids\": [{\"mesh\": $box, \"initial\": {$big}}]}" >huge_start.json
  expect 2 "solids[0]: solid 0 ('solid0'): its initial state (initial.matrix, initial.scramble) puts a node" -- "$PIOLA" run huge_start.json -o out_huge
  [[ -e out_huge ]] && fail "the refused huge start ($big) created its output folder"
done
# an implicit scene refused for a tiny integrator.dt: the hint is about integrator.dt, not the
# explicit step
echo "{\"fps\": 30, \"frames\": 1, \"integrator\": {\"type\": \"backward_euler\", \"dt\": 1e-7}, \"solids\": [{\"mesh\": $box}]}" >tiny_dt.json
expect 2 'integrator.dt (1e-07 s) is' -- "$PIOLA" run tiny_dt.json -o out_tiny --max-steps 10
grep -q 'the explicit step' stderr && fail "tiny_dt.json: the explicit step's hint for an implicit scene: $(cat stderr)"
[[ -e out_tiny ]] && fail "the refused tiny-dt run created its output folder"
echo "{\"fps\": 0.5, \"frames\": 1, \"integrator\": {\"max_dt\": 0.01}, \"solids\": [{\"mesh\": $box}]}" >two_seconds.json
expect 2 "more than the limit of 10 steps" -- "$PIOLA" run two_seconds.json -o out_two --max-steps 10
expect 0 "done" -- "$PIOLA" run two_seconds.json -o out_two --max-steps 1e4
expect 2 "--max-steps needs a number" -- "$PIOLA" run two_seconds.json -o out_x --max-steps 0
# a scene without solids: the refusal gives no hint about tets it does not have
echo "{\"fps\": 1e-300, \"frames\": 1, \"shells\": [{\"mesh\": {\"generate\": \"rectangle\", \"size\": [0.2, 0.2], \"resolution\": [2, 2]}}]}" >shell_slow.json
expect 2 "raise the limit with --max-steps" -- "$PIOLA" run shell_slow.json -o out_shell_slow
grep -q "times shorter" stderr && fail "shell_slow.json: a hint about the smallest tet: $(cat stderr)"
# piola check refuses what piola run would, with the same limit and message
expect 2 "piola check: slow.json: 1 frames at 1e-300 fps" -- "$PIOLA" check slow.json --timing-seconds 0
expect 2 "more than the limit of 10 steps" -- "$PIOLA" check two_seconds.json --timing-seconds 0 --max-steps 10
timeout 20 "$PIOLA" check two_seconds.json --timing-seconds 0 --max-steps 1e4 >stdout 2>stderr ||
  fail "check two_seconds.json --max-steps 1e4: exit $?: $(cat stderr)"
grep -q "^estimate:  [0-9]* steps per frame" stdout || fail "check two_seconds.json: no estimate: $(cat stdout)"
# a step longer than a frame still takes one per frame: 300 frames are 300 steps, not 10
echo "{\"fps\": 30, \"frames\": 300, \"integrator\": {\"type\": \"backward_euler\", \"dt\": 1}, \"solids\": [{\"mesh\": $box}]}" >long_dt.json
expect 2 "about 300 steps of 1 s: more than the limit of 100 steps" -- "$PIOLA" run long_dt.json -o out_long --max-steps 100
[[ -e out_long ]] && fail "the refused implicit run created its output folder"

# refinement levels: 0..6 as documented
echo "{\"fps\": 10, \"frames\": 0, \"solids\": [{\"mesh\": {\"generate\": \"sphere\", \"radius\": 0.1, \"cell_size\": 0.05, \"refinement_levels\": 7}}]}" >refine.json
expect 2 "solids[0].mesh.refinement_levels" -- "$PIOLA" run refine.json -o out_refine

[[ $fails -eq 0 ]] && echo "all checks passed" || echo "$fails check(s) failed"
exit $((fails > 0))
