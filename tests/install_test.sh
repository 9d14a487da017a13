#!/usr/bin/env bash
# `cmake --install` into a temporary prefix puts the executable, the man page
# and the bash completion (both generated from --help) in the usual places,
# and they work.
set -u
: "${BUILD:?}"
prefix=$(mktemp -d)
trap 'rm -rf "$prefix"' EXIT
pass=0 fail=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL: $*"; fail=$((fail + 1)); }
cmake --install "$BUILD" --prefix "$prefix" >/dev/null && ok || bad "cmake --install"
[ -x "$prefix/bin/snell" ] && "$prefix/bin/snell" --version | grep -q "^snell [0-9]" && ok || bad "bin/snell --version"
man="$prefix/share/man/man1/snell.1"
[ -s "$man" ] && head -n 1 "$man" | grep -q '^\.TH SNELL 1' && grep -q "Scripted: show N frames" "$man" &&
  grep -q "Exit status" "$man" && ok || bad "man page"
if command -v groff >/dev/null; then
  groff -man -Tutf8 "$man" 2>&1 >/dev/null | grep -q . && bad "groff warnings" || ok
fi
completion="$prefix/share/bash-completion/completions/snell"
[ -s "$completion" ] && ok || bad "bash completion installed"
result=$(bash -c 'source "$1"; COMP_WORDS=(snell pre); COMP_CWORD=1; _snell; echo "${COMPREPLY[*]}"' _ "$completion")
[ "$result" = "preview" ] && ok || bad "completing 'snell pre' gave '$result'"
result=$(bash -c 'source "$1"; COMP_WORDS=(snell render --prec); COMP_CWORD=2; _snell; echo "${COMPREPLY[*]}"' _ "$completion")
[ "$result" = "--precision" ] && ok || bad "completing 'snell render --prec' gave '$result'"
echo "install: $pass passed, $fail failed"
[ $fail -eq 0 ]
