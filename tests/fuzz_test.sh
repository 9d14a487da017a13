#!/usr/bin/env bash
# Short fuzzing runs: each libFuzzer target (FUZZ_TARGETS, by default both)
# for ${FUZZ_SECONDS:-60} seconds, seeded from its corpus in the tree
# (tests/fuzz/corpus/TARGET: inputs earlier runs found new coverage with,
# minimised), scenes/ and tests/bad/. The targets are those of FUZZ_BUILD
# (CI: the sanitized build, made by clang, runs them from ctest), else of a
# fuzz-only build made here in build-fuzz/. What a run finds new is kept in
# FUZZ_BUILD/corpus/TARGET, so coverage accumulates between local runs;
# `FUZZ_MERGE=1` merges it, minimised, back into the tree's corpus. Any
# crash, sanitizer report or timeout fails; its input is left in
# FUZZ_BUILD/findings/ to become a test in tests/bad/.
set -u
cd "$(dirname "$0")/.."
seconds=${FUZZ_SECONDS:-60}
build=${FUZZ_BUILD:-}
if [ -z "$build" ]; then
  build="$PWD/build-fuzz"
  CC=clang-14 CXX=clang++-14 cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSNELL_FUZZ=ON >/dev/null || exit 1
  cmake --build "$build" --parallel || exit 1
fi
mkdir -p "$build/findings"
pass=0 fail=0
for target in ${FUZZ_TARGETS:-fuzz_parser fuzz_render}; do
  [ -x "$build/$target" ] || { echo "FAIL: no $build/$target (a sanitized build by clang has it)"; fail=$((fail + 1)); continue; }
  seeds=$(mktemp -d)
  for f in scenes/*.scn scenes/hard/*.scn; do cp "$f" "$seeds/$(echo "$f" | tr / _)"; done
  [ "$target" = fuzz_parser ] && for f in tests/bad/*.scn; do cp "$f" "$seeds/$(echo "$f" | tr / _)"; done
  kept="$PWD/tests/fuzz/corpus/$target"
  mkdir -p "$build/corpus/$target" "$kept"
  # The first directory receives what the run finds new; the others seed it.
  if (cd "$build/findings" && "../$target" "../corpus/$target" "$kept" "$seeds" -max_total_time="$seconds" \
        -max_len=4096 -timeout=10 -print_final_stats=1 >"../$target.log" 2>&1); then
    echo "$target: $(grep -o 'Done [0-9]* runs' "$build/$target.log"), $(grep -o 'cov: [0-9]*' "$build/$target.log" | tail -n 1)"
    pass=$((pass + 1))
  else
    echo "FAIL: $target found a problem; see $build/$target.log and $build/findings/"
    grep -E "ERROR|runtime error|SUMMARY" "$build/$target.log" | head -n 5
    fail=$((fail + 1))
  fi
  if [ "${FUZZ_MERGE:-0}" = 1 ]; then
    merged=$(mktemp -d)
    (cd "$build/findings" && "../$target" -merge=1 -max_len=4096 "$merged" "$kept" "../corpus/$target" >/dev/null 2>&1) &&
      rm -rf "$kept" && mkdir -p "$kept" && cp "$merged"/* "$kept"/ && echo "$target: $(ls "$kept" | wc -l) inputs kept in $kept"
    rm -rf "$merged"
  fi
  rm -rf "$seeds"
done
echo "fuzz: $pass passed, $fail failed"
[ $fail -eq 0 ]
