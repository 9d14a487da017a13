#!/usr/bin/env bash
# Scene input as a newcomer gives it: input without end (/dev/zero, endless
# pipes, an endless line) or too large ends in an error at a stated limit, in
# bounded memory, for every command that reads a scene; check and render give
# the same warnings, in line order, beside the errors; check --json carries
# errors and warnings with their positions; a UTF-8 byte-order mark is
# accepted; a number's error names its argument.
# shellcheck source=tests/cli_test_support.sh
source "$(dirname "$0")/cli_test_support.sh"

# Runs a command with 1 GiB of memory at most, so that input read without
# bound fails here instead of taking the machine: ulimit -v, or, under
# AddressSanitizer (which reserves terabytes of address space), its RSS limit.
bounded() {
  if LC_ALL=C grep -qa __asan_init "$SNELL"; then
    ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}hard_rss_limit_mb=1024" timeout 60 "$@"
  else
    (ulimit -v 1048576 && exec timeout 60 "$@")
  fi
}

# --- Input without end, or too large: status 2 and the limit named.

# /dev/zero: its first byte, a NUL, is an error where it is read.
for command in "render /dev/zero -o $work/zero.png" "check /dev/zero" "preview /dev/zero"; do
  bounded "$SNELL" $command >/dev/null 2>"$work/err"; status=$?
  [ $status -eq 2 ] && [ "$(cat "$work/err")" = "/dev/zero:1:1: error: NUL byte: a scene file is text, and this is not; stopped reading here" ] &&
    [ ! -e "$work/zero.png" ] && ok || bad "$command (status $status): $(head -c 300 "$work/err")"
done
printf 'view 8 1\nbogus\nsphere \0\nbogus\n' | bounded "$SNELL" check - >/dev/null 2>"$work/err"; status=$?
[ $status -eq 2 ] && [ "$(cut -d: -f1-3 "$work/err" | tr '\n' ' ')" = "<stdin>:2:1 <stdin>:3:8 " ] && ok ||
  bad "the lines before a NUL byte, and none after it (status $status): $(cat "$work/err")"

# An endless pipe of lines that are not a scene: read until the error limit.
yes | bounded "$SNELL" render - -o "$work/yes.png" >/dev/null 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "^<stdin>:1:1: error: unknown command 'y'" "$work/err" &&
  grep -q "^<stdin>: error: at least [0-9]* more errors not shown (stopped reading at line 10000 after 10000 errors)" "$work/err" &&
  [ ! -e "$work/yes.png" ] && ok || bad "yes | render - (status $status): $(tail -c 300 "$work/err")"

# An endless line: an error at the line limit, 16 MiB.
tr '\0' x </dev/zero | bounded "$SNELL" check - >/dev/null 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "^<stdin>:1:16777217: error: line longer than snell's limit of 16 MiB" "$work/err" && ok ||
  bad "an endless line (status $status): $(head -c 300 "$work/err")"

# A file larger than the limit, 2 GiB (sparse: no disk used), refused before it is read.
printf 'view 8 1\nsphere\n' >"$work/huge.scn"
truncate -s 3G "$work/huge.scn"
for command in check render; do
  bounded "$SNELL" $command "$work/huge.scn" >/dev/null 2>"$work/err"; status=$?
  [ $status -eq 2 ] &&
    grep -q "^$work/huge.scn: error: the file's 3221225472 bytes are larger than snell's limit of 2 GiB for a scene (2147483647 bytes)" "$work/err" &&
    ok || bad "$command of a 3 GiB file (status $status): $(head -c 300 "$work/err")"
done
rm -f "$work/huge.scn"

# --- Warnings: the same from check and render, in line order, beside errors.

# SPEC §4: a material with ks + kt > 1 draws a warning, from check as from render.
"$SNELL" check "$SCENES/glass.scn" >"$work/out" 2>"$work/check-warn"; status=$?
grep "^$SCENES/glass.scn:" "$work/check-warn" >"$work/check-scene"
[ $status -eq 0 ] && grep -q "^$SCENES/glass.scn:[0-9]*:[0-9]*: warning: the material of this sphere has ks + kt = 1.05" "$work/check-scene" &&
  grep -q "warnings *$(wc -l <"$work/check-warn")$" "$work/out" && ok ||
  bad "check glass.scn (status $status): $(cat "$work/out" "$work/check-warn")"
"$SNELL" render "$SCENES/glass.scn" --size 16 -o "$work/glass.png" 2>"$work/render-warn" && ok || bad "render glass.scn"
grep "^$SCENES/glass.scn:" "$work/render-warn" | diff "$work/check-scene" - >/dev/null && ok ||
  bad "render and check warn differently: $(cat "$work/check-warn" "$work/render-warn")"

# Without errors: in line order (a sphere's warning at line 4, the unclosed group at 5).
printf 'view 8 1\nlight 1 1 1 0 0 -3\nmove 0 0 -3\nsphere\ngroup\n' >"$work/order.scn"
"$SNELL" check "$work/order.scn" >/dev/null 2>"$work/err"; status=$?
[ $status -eq 0 ] && [ "$(cut -d: -f2-4 "$work/err" | tr '\n' ' ')" = "4:1: warning 5:1: warning " ] && ok ||
  bad "warnings out of line order (status $status): $(cat "$work/err")"

# With errors: errors and the warnings of the lines that parsed, by line; render's the same; -q keeps the errors.
printf 'view 8 1\nlight 1 1 1 0 0 -3\ngroup\nmove 0 0 -3\nsphere\nmove 1 abc 2\nmaterial 0 0 0 0.5 0.5 0.5 1\nrefraction 1 1 1 1.5\nsphere\nbogus\n' >"$work/both.scn"
"$SNELL" check "$work/both.scn" >"$work/out" 2>"$work/check-err"; status=$?
[ $status -eq 2 ] && [ ! -s "$work/out" ] &&
  [ "$(cut -d: -f2-4 "$work/check-err" | tr '\n' ' ')" = "3:1: warning 5:1: warning 6:8: error 9:1: warning 9:1: warning 10:1: error " ] &&
  grep -q "^$work/both.scn:9:1: warning: the material of this sphere has ks + kt = 1.5 in a channel" "$work/check-err" && ok ||
  bad "check of errors and warnings (status $status): $(cat "$work/check-err")"
"$SNELL" render "$work/both.scn" -o "$work/both.png" 2>"$work/render-err"; status=$?
[ $status -eq 2 ] && diff "$work/check-err" "$work/render-err" >/dev/null && [ ! -e "$work/both.png" ] && ok ||
  bad "render of errors and warnings (status $status): $(cat "$work/render-err")"
"$SNELL" render "$work/both.scn" -q -o "$work/both.png" 2>"$work/err"; status=$?
[ $status -eq 2 ] && [ "$(cut -d: -f2-4 "$work/err" | tr '\n' ' ')" = "6:8: error 10:1: error " ] && ok ||
  bad "render -q of errors and warnings (status $status): $(cat "$work/err")"

# --- check --json: one document on stdout, errors or not, positions in it.
"$SNELL" check --json "$work/both.scn" >"$work/json" 2>/dev/null; status=$?
[ $status -eq 2 ] && python3 - "$work/json" "$work/both.scn" <<'PY' && ok || bad "check --json with errors (status $status): $(cat "$work/json")"
import json, sys
d = json.load(open(sys.argv[1]))
where = lambda items: [(i["file"], i["line"], i["column"]) for i in items]
f = sys.argv[2]
assert where(d["errors"]) == [(f, 6, 8), (f, 10, 1)], d["errors"]
assert d["errors"][0]["message"].startswith("expected a number for 'y'"), d["errors"]
assert where(d["warnings"]) == [(f, 3, 1), (f, 5, 1), (f, 9, 1), (f, 9, 1)], d["warnings"]
assert d["errors_not_shown"] == 0 and "spheres" not in d
PY
"$SNELL" check --json "$work/order.scn" >"$work/json" 2>/dev/null; status=$?
[ $status -eq 0 ] && python3 - "$work/json" <<'PY' && ok || bad "check --json (status $status): $(cat "$work/json")"
import json, sys
d = json.load(open(sys.argv[1]))
assert d["errors"] == [] and d["spheres"] == 1, d
assert [(w["line"], w["column"]) for w in d["warnings"]] == [(4, 1), (5, 1)], d["warnings"]
assert "never closed" in d["warnings"][1]["message"], d["warnings"]
PY
"$SNELL" check --json "$work/missing.scn" >"$work/json" 2>/dev/null; status=$?
[ $status -eq 2 ] && python3 - "$work/json" <<'PY' && ok || bad "check --json of a missing file (status $status): $(cat "$work/json")"
import json, sys
e = json.load(open(sys.argv[1]))["errors"]
assert len(e) == 1 and e[0]["line"] is None and e[0]["column"] is None and "cannot open" in e[0]["message"], e
PY

# --- A UTF-8 byte-order mark (Windows editors write one) is accepted.
printf '\xef\xbb\xbfview 8 1\nlight 1 1 1 0 0 5\nmove 0 0 -3\nsphere\n' | "$SNELL" check - >/dev/null 2>"$work/err"; status=$?
[ $status -eq 0 ] && [ ! -s "$work/err" ] && ok || bad "a byte-order mark (status $status): $(cat "$work/err")"
printf '\xef\xbb\xbfview 8 x\n' | "$SNELL" check - >/dev/null 2>"$work/err"; status=$?
[ $status -eq 2 ] && grep -q "^<stdin>:1:8: error: expected a number for 'd'" "$work/err" && ok ||
  bad "columns after a byte-order mark (status $status): $(cat "$work/err")"

# --- A number's error names its argument.
printf 'view 8 1\nlight 1 1 one 0 0 0\n' | "$SNELL" check - >/dev/null 2>"$work/err"; status=$?
[ $status -eq 2 ] &&
  grep -qx "<stdin>:2:11: error: expected a number for 'b' (argument 3 of 'light r g b x y z'), got 'one'" "$work/err" && ok ||
  bad "which argument (status $status): $(cat "$work/err")"

echo "cli input: $pass passed, $fail failed"
[ $fail -eq 0 ]
