#!/usr/bin/env bash
# Every malformed scene in tests/bad/ (its first line: "# expect LINE:COL TEXT"),
# plus an empty file, a 10 MB line, a directory and a missing file: snell must
# exit 2 with "FILE:LINE:COL: error: ..." naming that position and containing
# TEXT, and leave an existing output file untouched.
set -u
: "${SNELL:?}" "${BAD:?}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
pass=0 fail=0

check() {  # check FILE LINE COL TEXT
  local file=$1 line=$2 col=$3 text=$4 status
  echo "precious" >"$work/out.png"
  "$SNELL" render "$file" -o "$work/out.png" >"$work/stdout" 2>"$work/stderr"; status=$?
  local first
  first=$(head -n 1 "$work/stderr")
  if [ $status -ne 2 ]; then
    echo "FAIL: $file: exit status $status, want 2 ($first)"; fail=$((fail + 1)); return
  fi
  case "$first" in
    "$file:$line:$col: error: "*"$text"*) ;;
    *) echo "FAIL: $file: got '$first', want '$file:$line:$col: error: ...$text...'"; fail=$((fail + 1)); return ;;
  esac
  if [ "$(cat "$work/out.png")" != "precious" ] || ls "$work" | grep -q tmp; then
    echo "FAIL: $file: the output file was touched"; fail=$((fail + 1)); return
  fi
  pass=$((pass + 1))
}

for f in "$BAD"/*.scn; do
  expectation=$(head -n 1 "$f" | sed -n 's/^# expect \([0-9]*\):\([0-9]*\) \(.*\)$/\1 \2 \3/p')
  if [ -z "$expectation" ]; then echo "FAIL: $f has no '# expect LINE:COL TEXT' first line"; fail=$((fail + 1)); continue; fi
  read -r line col text <<<"$expectation"
  check "$f" "$line" "$col" "$text"
done

: >"$work/empty.scn"
check "$work/empty.scn" 1 1 "missing 'view'"
{ printf 'view 16 0.5\nmove 1 2 3 '; head -c 10000000 /dev/zero | tr '\0' '7'; printf '\n'; } >"$work/long-line.scn"
check "$work/long-line.scn" 2 12 "too many arguments"
mkdir "$work/a-directory.scn"
check "$work/a-directory.scn" 1 1 "directory"
check "$work/missing.scn" 1 1 "cannot open"

echo "bad inputs: $pass passed, $fail failed"
[ $fail -eq 0 ]
