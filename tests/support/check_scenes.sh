#!/usr/bin/env bash
# Runs every shipped scene that declares "checks" with `monolith run --check` and prints one line
# per scene (exit code, wall time). Long scenes (fluids at full resolution, pyramid_20) make this
# a benchmark-sized run (minutes), so ctest runs only the short ones (test_checks.cpp).
# usage: tests/support/check_scenes.sh [BUILD_DIR] [OUT_DIR]
set -u
cd "$(dirname "$0")/../.."
build=${1:-build}
out=${2:-/tmp/monolith-check-scenes}
failed=0
for scene in scenarios/scenes/*.json; do
  grep -q '"checks"' "$scene" || continue
  name=$(basename "$scene" .json)
  start=$(date +%s.%N)
  "$build/monolith" run "$scene" --out "$out/$name" --quiet --no-frames --check > "$out.$name.log" 2>&1
  rc=$?
  printf '%-24s exit %d  %6.1f s\n' "$name" "$rc" "$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { print b - a }')"
  grep '^check ' "$out.$name.log" | sed 's/^/    /'
  [ "$rc" -eq 0 ] || failed=1
done
exit $failed
