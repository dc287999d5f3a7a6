#!/usr/bin/env bash
# Every malformed file in tests/data/bad is refused by `piola mesh info` with exit code 2 and
# a message on stderr that names the file (and the line, as listed in EXPECTED.txt); none
# crashes (a signal gives an exit code above 128).
set -u
PIOLA=${PIOLA:?path of the piola binary}
dir="$PIOLA_SOURCE_DIR/tests/data/bad"
failures=0
checked=0
while IFS=$'\t' read -r file expected; do
  case "$file" in ''|'#'*) continue ;; esac
  err=$("$PIOLA" mesh info "$dir/$file" 2>&1 >/dev/null)
  rc=$?
  checked=$((checked + 1))
  if [ "$rc" -ne 2 ]; then
    echo "FAIL $file: exit code $rc, expected 2 ($err)"; failures=$((failures + 1)); continue
  fi
  case "$err" in
    *"$expected"*) echo "ok   $file: $err" ;;
    *) echo "FAIL $file: message '$err' lacks '$expected'"; failures=$((failures + 1)) ;;
  esac
done < "$dir/EXPECTED.txt"
# Files not listed must still fail cleanly (exit 2, no crash).
for f in "$dir"/*; do
  name=$(basename "$f")
  case "$name" in EXPECTED.txt|*.ele) continue ;; esac
  grep -q "^$name	" "$dir/EXPECTED.txt" && continue
  "$PIOLA" mesh info "$f" >/dev/null 2>&1; rc=$?
  checked=$((checked + 1))
  [ "$rc" -eq 2 ] || { echo "FAIL $name: exit code $rc"; failures=$((failures + 1)); }
done
# Usage errors.
"$PIOLA" mesh info >/dev/null 2>&1; [ $? -eq 2 ] || { echo "FAIL: missing file argument"; failures=$((failures + 1)); }
"$PIOLA" mesh frobnicate >/dev/null 2>&1; [ $? -eq 2 ] || { echo "FAIL: unknown subcommand"; failures=$((failures + 1)); }
"$PIOLA" mesh info /nonexistent/file.msh >/dev/null 2>&1; [ $? -eq 1 ] || { echo "FAIL: missing file should exit 1"; failures=$((failures + 1)); }
echo "$checked files checked, $failures failures"
[ "$failures" -eq 0 ] && [ "$checked" -ge 14 ]
