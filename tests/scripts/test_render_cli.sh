#!/usr/bin/env bash
# `piola run` leaves a preview (DIR/preview.png, DIR/scene.json, and with --render one PNG per
# frame); `piola render DIR` writes PNGs of the requested size, a contact sheet and an MP4
# that ffprobe decodes to exactly one frame per PNG; --every thins both; obstacles from the
# scene copy are drawn; stress colouring works with the scene; the inverted colouring shows red exactly for a frame with inverted
# tets (pixels decoded by ffmpeg, an independent PNG reader); bad input exits 2.
set -euo pipefail
: "${PIOLA:?path of the piola program}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

cat >"$work/tiny.json" <<'JSON'
{"fps": 20, "frames": 3, "gravity": [0, 0, -9.81],
 "solids": [{"name": "cube", "mesh": {"generate": "box", "center": [0, 0, 0.15], "half_extents": [0.1, 0.1, 0.1], "cell_size": 0.1},
             "material": {"youngs_modulus": 1e4, "poisson_ratio": 0.3}}],
 "obstacles": [{"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]},
               {"type": "sphere", "center": [0.3, 0.2, 0.1], "radius": 0.1}]}
JSON
# the same cube mirrored at the start: every tet inverted in frame 0
sed 's/"material"/"initial": {"matrix": [[-1, 0, 0], [0, 1, 0], [0, 0, 1]]}, "material"/' \
  "$work/tiny.json" >"$work/mirrored.json"

"$PIOLA" run "$work/tiny.json" -o "$work/out" --threads 2 --render >"$work/log" 2>&1 || { cat "$work/log"; fail "piola run"; }
out="$work/out"
[[ -s "$out/preview.png" ]] || fail "no preview.png"
[[ -s "$out/scene.json" ]] || fail "no scene.json copy"
for f in 0 1 2 3; do
  [[ -s "$out/render/frame_000$f.png" ]] || fail "piola run --render: no render/frame_000$f.png"
done

# PNG size from the IHDR chunk
png_size() { python3 -c "import struct,sys; d=open(sys.argv[1],'rb').read(24); assert d[:8]==b'\x89PNG\r\n\x1a\n'; print('%dx%d' % struct.unpack('>II', d[16:24]))" "$1"; }
[[ $(png_size "$out/preview.png") == 1280x720 ]] || fail "preview.png is $(png_size "$out/preview.png")"

"$PIOLA" render "$out" --width 320 --height 240 --contact-sheet --fps 10 >"$work/log" 2>&1 || { cat "$work/log"; fail "piola render"; }
for f in 0 1 2 3; do
  [[ $(png_size "$out/render/frame_000$f.png") == 320x240 ]] || fail "frame $f size"
done
[[ -s "$out/render/contact_sheet.png" ]] || fail "no contact sheet"
frames_in() { ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames -of csv=p=0 "$1"; }
if command -v ffmpeg >/dev/null && command -v ffprobe >/dev/null; then
  [[ -s "$out/render/movie.mp4" ]] || { cat "$work/log"; fail "no movie.mp4"; }
  n=$(frames_in "$out/render/movie.mp4")
  [[ $n -eq 4 ]] || fail "movie has $n frames, expected 4"
else
  echo "ffmpeg/ffprobe not installed: movie checks skipped"
fi

# --every 2: frames 0 and 2 are rendered again, and nothing this call did not make is
# deleted: frames 1 and 3 and the contact sheet of the earlier render stay, as does a file
# of the user's
echo mine >"$out/render/notes.txt"
"$PIOLA" render "$out" --width 160 --height 120 --every 2 >"$work/log" 2>&1 || { cat "$work/log"; fail "--every 2"; }
[[ $(png_size "$out/render/frame_0002.png") == 160x120 ]] || fail "--every 2 did not rewrite frame 2"
[[ $(png_size "$out/render/frame_0001.png") == 320x240 ]] || fail "--every 2 touched frame 1"
[[ -s "$out/render/contact_sheet.png" && -s "$out/render/notes.txt" ]] || fail "an earlier file was deleted"
[[ -z $(find "$out/render" -name '.movie_*') ]] || fail "the movie's temporary folder was left"
if command -v ffprobe >/dev/null; then
  n=$(frames_in "$out/render/movie.mp4")
  [[ $n -eq 2 ]] || fail "--every 2 movie has $n frames"
  # a later --no-movie render keeps the movie
  "$PIOLA" render "$out" --width 160 --height 120 --no-movie >/dev/null 2>&1 || fail "--no-movie"
  [[ -s "$out/render/movie.mp4" ]] || fail "--no-movie deleted the earlier movie.mp4"
fi

# thread count, --range auto and the default range give the same bytes
"$PIOLA" render "$out" --width 160 --height 120 --no-movie --color energy --threads 1 >/dev/null 2>&1 || fail "--threads 1"
cp "$out/render/frame_0003.png" "$work/t1.png"
"$PIOLA" render "$out" --width 160 --height 120 --no-movie --color energy --threads 2 --range auto >/dev/null 2>&1 || fail "--threads 2"
cmp -s "$out/render/frame_0003.png" "$work/t1.png" || fail "--threads 2 --range auto differs from --threads 1"

# hiding obstacles: all of them, by type, by index and by name change the picture the
# same way (the scene's only non-plane obstacle is the sphere "ball"); a name that names
# nothing is refused
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); d['obstacles'][1]['name']='ball'; json.dump(d, open(sys.argv[2], 'w'))" "$out/scene.json" "$work/named.json"
render0() { "$PIOLA" render "$out" --width 160 --height 120 --no-movie --scene "$work/named.json" "$@" >"$work/log" 2>&1 || { cat "$work/log"; fail "render $*"; }; cp "$out/render/frame_0000.png" "$work/hide.png"; }
render0 --frame-obstacles; cp "$work/hide.png" "$work/shown.png"
render0 --frame-obstacles --hide-obstacle ball; cp "$work/hide.png" "$work/by_name.png"
cmp -s "$work/shown.png" "$work/by_name.png" && fail "--hide-obstacle ball changed nothing"
render0 --frame-obstacles --hide-obstacle sphere; cmp -s "$work/hide.png" "$work/by_name.png" || fail "by type differs from by name"
render0 --frame-obstacles --hide-obstacle 'obstacles[1]'; cmp -s "$work/hide.png" "$work/by_name.png" || fail "by index differs from by name"
render0 --frame-obstacles --hide-obstacles; cmp -s "$work/hide.png" "$work/by_name.png" && fail "--hide-obstacles kept the plane"
cp "$work/hide.png" "$work/none.png"
render0 --frame-obstacles --hide-obstacle all; cmp -s "$work/hide.png" "$work/none.png" || fail "--hide-obstacle all differs from --hide-obstacles"
# a field the frames lack is named with the frame that lacks it
set +e
"$PIOLA" render "$out" --no-movie --width 160 --height 120 --field bogus >"$work/log" 2>&1
rc=$?
set -e
[[ $rc -eq 2 ]] && grep -q "frame_0000.vtu: frame has no cell field 'bogus'" "$work/log" ||
  { cat "$work/log"; fail "--field bogus: exit $rc, expected 2 naming the frame"; }
set +e
"$PIOLA" render "$out" --no-movie --scene "$work/named.json" --hide-obstacle bal >"$work/log" 2>&1
rc=$?
set -e
[[ $rc -eq 2 ]] && grep -q "ball (sphere)" "$work/log" || { cat "$work/log"; fail "--hide-obstacle bal: exit $rc, expected 2 naming ball"; }
# ... and so is any name where there is no scene to take obstacles from
mkdir "$work/noscene"
cp -r "$out/frames" "$out/sim.pvd" "$work/noscene/"
set +e
"$PIOLA" render "$work/noscene" --no-movie --width 160 --height 120 --hide-obstacle ball >"$work/log" 2>&1
rc=$?
set -e
[[ $rc -eq 2 ]] && grep -q "names nothing" "$work/log" || { cat "$work/log"; fail "--hide-obstacle without a scene: exit $rc, expected 2"; }
# a folder of OBJ surfaces draws in plain colours, and refuses the inverted colouring
mkdir "$work/objonly"
cp -r "$out/surface" "$work/objonly/"
"$PIOLA" render "$work/objonly" --no-movie --width 160 --height 120 >"$work/log" 2>&1 || { cat "$work/log"; fail "render of OBJ surfaces"; }
set +e
"$PIOLA" render "$work/objonly" --no-movie --width 160 --height 120 --color inverted >"$work/log" 2>&1
rc=$?
set -e
[[ $rc -eq 2 ]] && grep -q "needs the VTU frames" "$work/log" || { cat "$work/log"; fail "--color inverted on OBJ surfaces: exit $rc, expected 2"; }

# up from gravity: a scene whose gravity points along -y renders as with --up 0,1,0
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); d['gravity']=[0, -9.81, 0]; json.dump(d, open(sys.argv[2], 'w'))" "$work/named.json" "$work/yup.json"
render0 --scene "$work/yup.json"; cp "$work/hide.png" "$work/gravity_up.png"
render0 --scene "$work/yup.json" --up 0,1,0; cmp -s "$work/hide.png" "$work/gravity_up.png" || fail "gravity -y is not up +y"
render0 --scene "$work/yup.json" --up 0,0,1; cmp -s "$work/hide.png" "$work/gravity_up.png" && fail "--up 0,0,1 did not override the gravity"

# pixels, decoded by ffmpeg: count strongly red ones (the inverted highlight)
red_pixels() {
  ffmpeg -v error -i "$1" -f rawvideo -pix_fmt rgb24 - | python3 -c "
import sys
d = sys.stdin.buffer.read()
print(sum(1 for i in range(0, len(d), 3) if d[i] > 60 and 2 * d[i + 1] < d[i] and 2 * d[i + 2] < d[i]))"
}
if command -v ffmpeg >/dev/null; then
  # obstacles from the scene copy change the picture; without the copy they are absent
  "$PIOLA" render "$out" --width 160 --height 120 --no-movie --color inverted >/dev/null 2>&1
  [[ $(red_pixels "$out/render/frame_0000.png") -eq 0 ]] || fail "red pixels without inverted tets"
  cp "$out/render/frame_0000.png" "$work/with_scene.png"
  mv "$out/scene.json" "$work/scene_copy.json"
  "$PIOLA" render "$out" --width 160 --height 120 --no-movie --color inverted >/dev/null 2>&1
  cmp -s "$out/render/frame_0000.png" "$work/with_scene.png" && fail "obstacles not drawn (same image without the scene)"
  "$PIOLA" render "$out" --width 160 --height 120 --no-movie --color inverted --scene "$work/scene_copy.json" >/dev/null 2>&1
  cmp -s "$out/render/frame_0000.png" "$work/with_scene.png" || fail "--scene differs from the scene copy"

  "$PIOLA" run "$work/mirrored.json" -o "$work/mirror" --frames 0 >"$work/log" 2>&1 || { cat "$work/log"; fail "mirrored run"; }
  "$PIOLA" render "$work/mirror" --width 160 --height 120 --no-movie --color inverted >/dev/null 2>&1
  n=$(red_pixels "$work/mirror/render/frame_0000.png")
  [[ $n -gt 50 ]] || fail "inverted frame shows only $n red pixels"
  "$PIOLA" render "$work/mirror" --width 160 --height 120 --no-movie --color plain >/dev/null 2>&1
  [[ $(red_pixels "$work/mirror/render/frame_0000.png") -eq 0 ]] || fail "plain colouring shows red"
fi

# energy colouring works; stress is computed from the displacements and the scene's
# materials, so it needs the scene
"$PIOLA" render "$out" --width 160 --height 120 --no-movie --color energy >/dev/null 2>&1 || fail "--color energy"
"$PIOLA" render "$out" --width 160 --height 120 --no-movie --color stress --scene "$work/tiny.json" >"$work/log" 2>&1 ||
  { cat "$work/log"; fail "--color stress --scene"; }
rm -f "$out/scene.json"
expect2() {
  set +e
  "$PIOLA" render "$@" >"$work/log" 2>&1
  local rc=$?
  set -e
  [[ $rc -eq 2 ]] || { cat "$work/log"; fail "piola render $*: exit $rc, expected 2"; }
  [[ -s "$work/log" ]] || fail "piola render $*: no message"
}
expect2 "$out" --color stress --no-movie
expect2 "$out" --color purple
expect2 "$out" --width 0
expect2 "$out" --camera-position 1,2
expect2 "$out" --bogus
expect2 "$work/does-not-exist"
mkdir "$work/empty"
expect2 "$work/empty"
expect2 "$out" --scene "$work/nope.json"
expect2
echo "piola render ok"
