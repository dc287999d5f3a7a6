#!/usr/bin/env bash
# piola as a package: `cmake --install` into a temporary prefix, then a consumer project
# outside the tree (tests/install_consumer) is built against it with CMake's find_package
# (shared and static libraries) and with pkg-config, and run. Also checks what the package
# promises: every exported symbol carries the piola prefix, the core library needs neither
# cJSON nor libpng, and the scene library no libpng.
set -euo pipefail
: "${PIOLA_BUILD_DIR:?the build folder}" "${PIOLA_SOURCE_DIR:?}"
cmake_bin=${CMAKE_COMMAND:-cmake}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
prefix=$work/prefix
failed=0
fail() { echo "FAIL $*"; failed=1; }

"$cmake_bin" --install "$PIOLA_BUILD_DIR" --prefix "$prefix" > "$work/install.log" ||
  { cat "$work/install.log"; exit 1; }
libdir=$prefix/lib
[ -d "$libdir" ] || libdir=$(dirname "$(find "$prefix" -name libpiola.so | head -1)")
for f in include/piola/piola.h include/piola/render.h include/piola/scene.h; do
  [ -f "$prefix/$f" ] || fail "not installed: $f"
done
for lib in piola piola_scene piola_render; do
  [ -f "$libdir/lib$lib.a" ] || fail "not installed: lib$lib.a"
  [ -f "$libdir/lib$lib.so" ] || fail "not installed: lib$lib.so"
done
[ -f "$libdir/cmake/piola/piolaConfig.cmake" ] || fail "not installed: piolaConfig.cmake"
[ -f "$libdir/pkgconfig/piola.pc" ] || fail "not installed: piola.pc"

# exported names: the shared libraries' dynamic symbols and the archives' globals
for lib in piola piola_scene piola_render; do
  bad=$(nm -D --defined-only "$libdir/lib$lib.so" | awk 'NF == 3 && $3 !~ /^piola_/ {print $3}')
  [ -z "$bad" ] || fail "lib$lib.so exports names without the piola_ prefix: $bad"
  # (a sanitizer build adds its own __odr_asan.* / __asan* globals: not piola's names)
  bad=$(nm -g --defined-only "$libdir/lib$lib.a" 2> /dev/null |
        awk 'NF == 3 && $3 !~ /^(piola_|__odr_asan|__asan|__sancov)/ {print $3}' | sort -u)
  [ -z "$bad" ] || fail "lib$lib.a defines globals without the piola prefix: $bad"
done
# layers: the core is dependency-free but for OpenMP and libm
needed() { readelf -d "$libdir/lib$1.so" | awk '/NEEDED/ {print $NF}'; }
needed piola | grep -Eq 'cjson|png' && fail "libpiola.so needs cJSON or libpng: $(needed piola)"
needed piola_scene | grep -q png && fail "libpiola_scene.so needs libpng"
needed piola_render | grep -q piola_scene || fail "libpiola_render.so does not link libpiola_scene"

# 1. CMake: find_package(piola), shared and static
src=$PIOLA_SOURCE_DIR/tests/install_consumer
if "$cmake_bin" -S "$src" -B "$work/cmake-build" -DCMAKE_PREFIX_PATH="$prefix" \
     -DCMAKE_BUILD_TYPE=Release -DCMAKE_C_FLAGS="${PIOLA_SAN_FLAGS:-}" \
     -DCMAKE_EXE_LINKER_FLAGS="${PIOLA_SAN_FLAGS:-}" > "$work/cmake.log" 2>&1 &&
   "$cmake_bin" --build "$work/cmake-build" >> "$work/cmake.log" 2>&1; then
  for kind in shared static; do
    if "$work/cmake-build/consumer_$kind" "$work/$kind.png"; then echo "ok   find_package ($kind)"
    else fail "the find_package consumer ($kind) failed"; fi
  done
else
  cat "$work/cmake.log"; fail "the find_package consumer does not build"
fi

# 2. pkg-config, shared libraries
export PKG_CONFIG_PATH=$libdir/pkgconfig
# shellcheck disable=SC2086 # the flags are words
if cc -std=c17 ${PIOLA_SAN_FLAGS:-} -o "$work/consumer_pc" "$src/consumer.c" \
      $(pkg-config --cflags --libs piola-render) -lm -Wl,-rpath,"$libdir" 2> "$work/pc.log"; then
  if "$work/consumer_pc" "$work/pc.png"; then echo "ok   pkg-config"
  else fail "the pkg-config consumer failed"; fi
else
  cat "$work/pc.log"; fail "the pkg-config consumer does not build (cc ... \$(pkg-config --cflags --libs piola-render))"
fi
exit $failed
