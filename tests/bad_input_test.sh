#!/usr/bin/env bash
# Every malformed scene in tests/bad/ (it opens with one "# expect LINE:COL TEXT"
# line per mistake, in file order), plus an empty file, a 10 MB line, a
# directory and a missing file (reported as "FILE: error: ...", with no
# position): snell must exit 2, report each mistake as
# "FILE:LINE:COL: error: ..." naming that position and containing TEXT, in that
# order and no other (SPEC §7: the first one is the one SPEC names), and leave
# an existing output file untouched.
set -u
: "${SNELL:?}" "${BAD:?}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
pass=0 fail=0

check() {  # check FILE EXPECTATION... (each "LINE COL TEXT")
  local file=$1 status
  shift
  echo "precious" >"$work/out.png"
  "$SNELL" render "$file" -o "$work/out.png" >"$work/stdout" 2>"$work/stderr"; status=$?
  local first
  first=$(head -n 1 "$work/stderr")
  if [ $status -ne 2 ]; then
    echo "FAIL: $file: exit status $status, want 2 ($first)"; fail=$((fail + 1)); return
  fi
  # The report's errors: the lines that start with the file's name (its
  # warnings, among them by line, aside).
  local reported=() l
  while IFS= read -r l; do
    case "$l" in "$file:"*": warning: "*) ;; "$file:"*) reported+=("$l") ;; esac
  done <"$work/stderr"
  if [ ${#reported[@]} -ne $# ]; then
    echo "FAIL: $file: ${#reported[@]} error lines, want $#:"; sed 's/^/  /' "$work/stderr"
    fail=$((fail + 1)); return
  fi
  local k=0 expectation line col text
  for expectation in "$@"; do
    read -r line col text <<<"$expectation"
    # Line 0: a problem of the whole file (it cannot be read), named without a position.
    local want="$file:$line:$col: error: "
    [ "$line" -eq 0 ] && want="$file: error: "
    case "${reported[k]}" in
      "$want"*"$text"*) ;;
      *) echo "FAIL: $file: error $((k + 1)) is '${reported[k]}', want '$want...$text...'"
         fail=$((fail + 1)); return ;;
    esac
    k=$((k + 1))
  done
  if [ "$(cat "$work/out.png")" != "precious" ] || ls "$work" | grep -q tmp; then
    echo "FAIL: $file: the output file was touched"; fail=$((fail + 1)); return
  fi
  pass=$((pass + 1))
}

for f in "$BAD"/*.scn; do
  # The leading "# expect" lines, as "LINE COL TEXT".
  mapfile -t expectations < <(LC_ALL=C awk '!/^# expect [0-9]+:[0-9]+ / { exit }
    { sub(/^# expect /, ""); sub(/:/, " "); print }' "$f")
  if [ ${#expectations[@]} -eq 0 ]; then echo "FAIL: $f has no '# expect LINE:COL TEXT' first line"; fail=$((fail + 1)); continue; fi
  check "$f" "${expectations[@]}"
done

: >"$work/empty.scn"
check "$work/empty.scn" "1 1 missing 'view'"
{ printf 'view 16 0.5\nmove 1 2 3 '; head -c 10000000 /dev/zero | tr '\0' '7'; printf '\n'; } >"$work/long-line.scn"
check "$work/long-line.scn" "2 12 too many arguments"
mkdir "$work/a-directory.scn"
check "$work/a-directory.scn" "0 0 directory"
check "$work/missing.scn" "0 0 cannot open"

echo "bad inputs: $pass passed, $fail failed"
[ $fail -eq 0 ]
