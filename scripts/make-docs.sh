#!/usr/bin/env bash
# Generate snell's man page and bash completion from its own --help text, so
# they never drift from the command line: make-docs.sh SNELL OUT_DIR
# VERSION (run by the build; installed by `cmake --install`).
set -euo pipefail
snell=$1
out=$2
version=$3
# Only --help is run, which touches no Vulkan; a sanitizer build must not fail on exit.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0}
mkdir -p "$out"
subcommands=(render preview bench check compare devices)

escape() { sed -e 's/\\/\\e/g' -e 's/^\([.'"'"']\)/\\\&\1/'; }
{
  echo ".TH SNELL 1 \"\" \"snell ${version:-unknown}\" \"User Commands\""
  echo ".SH NAME"
  echo "snell \\- a Whitted-style ray tracer whose renderer is a Vulkan compute shader"
  echo ".SH SYNOPSIS"
  for s in "${subcommands[@]}"; do echo ".B snell $s"; echo "[OPTIONS]"; echo ".br"; done
  echo ".SH DESCRIPTION"
  echo ".nf"
  "$snell" --help | escape
  echo ".fi"
  for s in "${subcommands[@]}"; do
    echo ".SH SNELL $(echo "$s" | tr a-z A-Z)"
    echo ".nf"
    "$snell" "$s" --help | escape
    echo ".fi"
  done
  echo ".SH FILES"
  echo "Compiled pipelines: \$SNELL_CACHE_DIR, else \$XDG_CACHE_HOME/snell, else ~/.cache/snell."
  echo ".SH SEE ALSO"
  echo "The scene format: SPEC.md and README.md of the snell sources."
} >"$out/snell.1"

# Completion: the subcommands, and each one's options as --help lists them.
{
  echo "# bash completion for snell, generated from 'snell SUBCOMMAND --help'"
  echo "_snell() {"
  echo "  local cur=\${COMP_WORDS[COMP_CWORD]} sub=\${COMP_WORDS[1]} words"
  echo "  if [ \"\$COMP_CWORD\" -eq 1 ]; then"
  echo "    COMPREPLY=(\$(compgen -W \"${subcommands[*]} --help --version\" -- \"\$cur\")); return"
  echo "  fi"
  echo "  case \$sub in"
  for s in "${subcommands[@]}"; do
    options=$("$snell" "$s" --help | grep -oE '(^|[ ,])--?[a-zA-Z][-a-zA-Z0-9]*' | tr -d ' ,' | sort -u | tr '\n' ' ')
    echo "    $s) words=\"$options\";;"
  done
  echo "    *) words=\"\";;"
  echo "  esac"
  echo "  if [[ \$cur == -* ]]; then COMPREPLY=(\$(compgen -W \"\$words\" -- \"\$cur\"))"
  echo "  else COMPREPLY=(\$(compgen -f -- \"\$cur\")); fi"
  echo "}"
  echo "complete -o filenames -F _snell snell"
} >"$out/snell.bash"
