#!/usr/bin/env bash
# Short fuzzing runs for CI: each libFuzzer target for
# ${FUZZ_SECONDS:-60} seconds, seeded from its corpus in the tree
# (tests/fuzz/corpus/TARGET: inputs earlier runs found new coverage with,
# minimised), scenes/ and tests/bad/. What a run finds new is kept in
# build-fuzz/corpus/TARGET, so coverage accumulates between local runs;
# `FUZZ_MERGE=1` merges it, minimised, back into the tree's corpus. Any
# crash, sanitizer report or timeout fails; its input is left in
# build-fuzz/findings/ to become a test in tests/bad/.
set -u
cd "$(dirname "$0")/.."
seconds=${FUZZ_SECONDS:-60}
CC=clang-14 CXX=clang++-14 cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DSNELL_FUZZ=ON >/dev/null || exit 1
cmake --build build-fuzz --parallel || exit 1
mkdir -p build-fuzz/findings
pass=0 fail=0
for target in fuzz_parser fuzz_render; do
  seeds=$(mktemp -d)
  for f in scenes/*.scn scenes/hard/*.scn; do cp "$f" "$seeds/$(echo "$f" | tr / _)"; done
  [ "$target" = fuzz_parser ] && for f in tests/bad/*.scn; do cp "$f" "$seeds/$(echo "$f" | tr / _)"; done
  kept="$PWD/tests/fuzz/corpus/$target"
  mkdir -p "build-fuzz/corpus/$target" "$kept"
  # The first directory receives what the run finds new; the others seed it.
  if (cd build-fuzz/findings && "../$target" "../corpus/$target" "$kept" "$seeds" -max_total_time="$seconds" \
        -max_len=4096 -timeout=10 -print_final_stats=1 >"../$target.log" 2>&1); then
    echo "$target: $(grep -o 'Done [0-9]* runs' "build-fuzz/$target.log")"
    pass=$((pass + 1))
  else
    echo "FAIL: $target found a problem; see build-fuzz/$target.log and build-fuzz/findings/"
    grep -E "ERROR|runtime error|SUMMARY" "build-fuzz/$target.log" | head -n 5
    fail=$((fail + 1))
  fi
  if [ "${FUZZ_MERGE:-0}" = 1 ]; then
    merged=$(mktemp -d)
    (cd build-fuzz/findings && "../$target" -merge=1 -max_len=4096 "$merged" "$kept" "../corpus/$target" >/dev/null 2>&1) &&
      rm -rf "$kept" && mkdir -p "$kept" && cp "$merged"/* "$kept"/ && echo "$target: $(ls "$kept" | wc -l) inputs kept in $kept"
    rm -rf "$merged"
  fi
  rm -rf "$seeds"
done
echo "fuzz: $pass passed, $fail failed"
[ $fail -eq 0 ]
