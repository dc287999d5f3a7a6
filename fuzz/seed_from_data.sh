#!/usr/bin/env bash
# Fills a fuzzer's seed corpus: small files (<= 200 KB) of the fuzzer's format from the shared
# data folder plus the malformed files in tests/data/bad.
# usage: seed_from_data.sh NAME DIR   (NAME: gmsh medit vega tetgen obj off stl vtu)
set -euo pipefail
name=$1; dir=$2
root="$(cd "$(dirname "$0")/.." && pwd)"
data="${PIOLA_DATA_DIR:-$root/../shared/data}"
bad="$root/tests/data/bad"
mkdir -p "$dir"
small() { find "$@" -type f -size -200k 2>/dev/null || true; }
copy_ext() { for f in $(small "$data" "$bad" -name "*.$1"); do cp "$f" "$dir/$(basename "$(dirname "$f")")_$(basename "$f")"; done; }
case "$name" in
  gmsh) copy_ext msh ;;
  medit) copy_ext mesh ;;
  vega) copy_ext veg ;;
  obj) copy_ext obj ;;
  off) copy_ext off ;;
  stl) copy_ext stl ;;
  vtu) for f in "$root"/tests/data/*.vtu; do cp "$f" "$dir/"; done ;;
  tetgen)
    # node + "%%" + ele in one input
    for node in $(small "$data" "$bad" -name "*.node"); do
      ele="${node%.node}.ele"
      [ -f "$ele" ] || continue
      { cat "$node"; printf '\n%%%%\n'; cat "$ele"; } > "$dir/$(basename "${node%.node}").tetgen"
    done ;;
  *) echo "unknown fuzzer name $name" >&2; exit 2 ;;
esac
# A few generated seeds so every reader sees its format even without the data folder.
case "$name" in
  off) printf 'OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n4 1 2 3 1\n' > "$dir/gen_tet.off" ;;
  stl) printf 'solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n' > "$dir/gen.stl" ;;
esac
