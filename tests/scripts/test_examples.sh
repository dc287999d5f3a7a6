#!/usr/bin/env bash
# Every scene in examples/ is runnable as it is: it loads (meshes found, keys valid) and
# simulates its first frames without error, NaN or an inverted-beyond-repair state. Scenes
# whose bodies touch within those frames must show it in stats.csv's `contacts` column
# (self_collision counts shells and solids alike).
expect_contacts=" cloth_on_jelly "
# Scenes too large to step for 2 frames here (115K tets: minutes on a shared machine) are
# only checked (`piola check`: they load, mesh, build and time a few steps); their physics
# is tested on a coarser mesh (tests/test_fracture_examples.c).
check_only=" ductile_fracture "
set -euo pipefail
: "${PIOLA:?path of the piola program}" "${PIOLA_SOURCE_DIR:?}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
failed=0
for scene in "$PIOLA_SOURCE_DIR"/examples/*.json; do
  name=$(basename "$scene" .json)
  if [[ "$check_only" == *" $name "* ]]; then
    if "$PIOLA" check "$scene" --timing-seconds 0.1 > "$work/$name.log" 2>&1; then echo "ok   $name (check only)"
    else echo "FAIL $name:"; cat "$work/$name.log"; failed=1; fi
    continue
  fi
  if "$PIOLA" run "$scene" -o "$work/$name" --frames 2 > "$work/$name.log" 2>&1; then
    rows=$(($(wc -l < "$work/$name/stats.csv") - 1))
    if [ "$rows" -ne 3 ]; then
      echo "FAIL $name: stats.csv has $rows frame rows, expected 3 (frames 0..2)"; failed=1
    elif [[ "$expect_contacts" == *" $name "* ]] &&
         ! awk -F, 'NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "contacts") c = i }
                    NR > 1 && c && $c > 0 { found = 1 } END { exit !found }' "$work/$name/stats.csv"; then
      echo "FAIL $name: no contacts counted in stats.csv within 2 frames"; failed=1
    else
      echo "ok   $name"
    fi
  else
    echo "FAIL $name:"; cat "$work/$name.log"; failed=1
  fi
done
exit $failed
