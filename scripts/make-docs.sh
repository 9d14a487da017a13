#!/usr/bin/env bash
# Generate snell's man page and bash completion from its own --help text, so
# they never drift from the command line:
#   make-docs.sh SNELL OUT_DIR VERSION [DOCDIR]
# (run by the build; installed by `cmake --install`). The subcommands are
# those `snell --help` lists; each one's section and completion come from
# `snell SUBCOMMAND --help`. DOCDIR is where docs/scene-format.md is
# installed, relative to the prefix unless absolute (default share/doc/snell).
set -euo pipefail
snell=$1
out=$2
version=$3
docdir=${4:-share/doc/snell}
# Only --help is run, which touches no Vulkan; a sanitizer build must not fail on exit.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0}
mkdir -p "$out"
case $docdir in
  /*) scene_format=$docdir/scene-format.md ;;
  *) scene_format=PREFIX/$docdir/scene-format.md ;;
esac

help=$("$snell" --help)
# CLI11 lists the subcommands as "  NAME   description" lines after a line
# "Subcommands:", up to the next blank line (a long description may go on
# on lines indented further, which are not names).
mapfile -t subcommands < <(printf '%s\n' "$help" |
  awk '/^Subcommands:/ { on = 1; next } on && /^$/ { exit } on && /^  [^ ]/ { print $1 }')
if [ ${#subcommands[@]} -eq 0 ]; then
  echo "make-docs.sh: '$snell --help' lists no subcommands" >&2
  exit 1
fi
declare -A sub_help
for s in "${subcommands[@]}"; do sub_help[$s]=$("$snell" "$s" --help); done

# Text from --help in roff: backslashes kept, minus signs as minus signs (so
# options copy as typed), a leading '.' or "'" not taken for a request.
escape() { sed -e 's/\\/\\e/g' -e 's/-/\\-/g' -e 's/^\([.'"'"']\)/\\\&\1/'; }
# A subcommand's usage line without the program name: "render [OPTIONS] scene".
usage_of() { printf '%s\n' "${sub_help[$1]}" | sed -n '/^Usage: /{s/^Usage: [^ ]* //p;q;}'; }
# A subcommand's help without its usage line (the section's synopsis shows
# it) and without the exit-status paragraph (EXIT STATUS has it).
body_of() {
  printf '%s\n' "${sub_help[$1]}" |
    awk '/^Usage: / { next } /^Exit status:/ { skip = 1 } skip && /^$/ { skip = 0; next } skip { next }
         /^$/ { blank++; next } { while (blank) { print ""; blank-- } print }'
}
# One synopsis line: "snell SUBCOMMAND" in bold, the rest as --help gives it.
synopsis() {
  local usage rest
  usage=$(usage_of "$1")
  rest=${usage#"$1"}
  echo ".B snell $1"
  [ -z "${rest# }" ] || printf '%s\n' "${rest# }" | escape
}

{
  echo ".TH SNELL 1 \"\" \"snell ${version:-unknown}\" \"User Commands\""
  echo ".SH NAME"
  echo "snell \\- a Whitted-style ray tracer whose renderer is a Vulkan compute shader"

  echo ".SH SYNOPSIS"
  for s in "${subcommands[@]}"; do synopsis "$s"; echo ".br"; done
  echo ".B snell"
  echo "\\-\\-help | \\-\\-version"

  echo ".SH DESCRIPTION"
  cat <<'EOF'
.B snell
reads a scene file (see
.B SCENE FORMAT
below) and renders it with a Vulkan compute shader, on any Vulkan 1.2
device, Mesa's lavapipe CPU driver included, or with its double-precision
CPU reference
.RB ( "render \-\-cpu" ).
Each subcommand has a section below, with the text that
.B snell
.I SUBCOMMAND
.B \-\-help
prints.
.PP
By default each pixel's ray tree is traced until its truncation bound (how
far, at most, the pixel may be from the image of the infinitely deep tree)
is within half an 8\-bit step
.RB ( \-\-tolerance );
.B \-\-depth
or
.B \-\-min\-weight
alone ask for one fixed tree instead.
.PP
Standard output carries only data: an image written to
.B "\-o \-"
(binary PPM, the only format there; refused when standard output is a
terminal: redirect it or pipe it to a converter),
or the JSON of
.B \-\-stats
and
.BR \-\-json .
Messages, warnings and the progress bar go to standard error. An image is
written under a temporary name and renamed once complete, so a failed or
interrupted command never leaves a partial file or clobbers an old one;
every file a render writes is checked before it starts.
.PP
A mistake on the command line is one line,
.BI "snell: error: " COMMAND ": " MESSAGE,
pointing to
.BI "snell " COMMAND " \-\-help" ;
status 2.
.PP
EOF
  echo ".nf"
  # The scene format is described here (SCENE FORMAT), not in files of the sources.
  printf '%s\n' "$help" | grep -v '^Scene format:' | escape
  echo ".fi"

  for s in "${subcommands[@]}"; do
    echo ".SH SNELL $(echo "$s" | tr '[:lower:]' '[:upper:]')"
    synopsis "$s"
    echo ".PP"
    echo ".nf"
    body_of "$s" | escape
    echo ".fi"
  done

  cat <<'EOF'
.SH ENVIRONMENT
.TP
.B SNELL_GPU
The Vulkan device to use, by its index in the list
.B snell devices
prints; the same as
.B \-\-gpu
of render, preview and bench, which wins when both are given. Unset: the
best device found. Like the two below, it is not read by
.BR "render \-\-cpu" ,
which refuses the options themselves.
.TP
.B SNELL_TRAVERSAL
How render and preview search scenes with a BVH, the same as
.BR \-\-traversal :
bvh (snell's own walk), ray-query (the device's ray traversal,
VK_KHR_ray_query), or auto (ray queries on a GPU that has them, else bvh).
.TP
.B SNELL_VALIDATION
Set to 1, the same as
.BR \-\-validation :
run under the Khronos validation layer (VK_LAYER_KHRONOS_validation, which
must be installed); a render fails on any message from it. Kernels are then
pipelines, never shader objects, which the layer of Debian 12 cannot check.
.TP
.B SNELL_CACHE_DIR
The directory that keeps compiled pipelines, specialised kernels and the
driver's kernel binaries between runs (see
.BR FILES ).
.TP
.B XDG_CACHE_HOME
Without
.BR SNELL_CACHE_DIR ,
the pipeline cache is in its
.I snell
subdirectory; without either, in
.IR ~/.cache/snell ,
and with no
.B HOME
either, there is none.
.TP
.BR VK_DRIVER_FILES ", " VK_ICD_FILENAMES
Read by the Vulkan loader, not by snell: a colon\-separated list of driver
manifests (JSON files) to load instead of the installed ones, such as
lavapipe's
.IR lvp_icd.x86_64.json .
VK_ICD_FILENAMES is the older name, the only one loaders before 1.3.207
know.
.TP
.B LP_NUM_THREADS
Read by Mesa's lavapipe: how many threads run the shader (by default, one
per processor). Lower it to leave processors free.
.TP
.BR DISPLAY ", " WAYLAND_DISPLAY
The display
.B snell preview
opens its window on; without one it fails (under
.BR Xvfb (1),
.B xvfb\-run
provides one).
.TP
.BR SNELL_INJECT_FAULT ", " SNELL_LOOP_BUDGET
Hooks for snell's tests (a simulated GPU failure; the shader's
suspend\-and\-resume path forced with a small loop budget). Leave them
unset.
.SH FILES
.TP
.I \%~/.cache/snell/pipelines.bin
Compute pipelines compiled by the Vulkan driver, kept so that later runs
start faster; beside it,
.IR modules/ ,
the kernel of each scene structure with its specialisation constants
folded in (the driver then compiles less: on lavapipe, 14\(en21 ms less a
start; up to 256 are kept), and
.IR shaders/ ,
the driver's binary of each such kernel, where the device has shader
objects (VK_EXT_shader_object: lavapipe of Mesa 25, recent GPU drivers); a
kernel made from its binary skips the driver's translation of SPIR-V (on
lavapipe, 45 ms less a start; up to 256 are kept), and
.IR probes/ ,
whether the driver ends long shader loops (lavapipe before Mesa 24 does),
found once by a tiny kernel. With
.B SNELL_CACHE_DIR
or
.B XDG_CACHE_HOME
set, they lie in the directory they name instead (see
.BR ENVIRONMENT ).
Removing them is harmless.
EOF
  echo ".TP"
  echo ".I \\%$scene_format"
  cat <<'EOF'
The scene format in full: every command with its arguments, ranges and
defaults, the camera, the transform order, the errors, and a complete
example scene.
EOF
  case $docdir in /*) ;; *) echo "PREFIX is where snell was installed (its executable is PREFIX/bin/snell)." ;; esac
  cat <<'EOF'
.TP
.I \%PREFIX/share/bash\-completion/completions/snell
Bash completion of subcommands, options and file names.
.SH EXIT STATUS
.TP
.B 0
Success.
.TP
.B 1
A failure at run time: no usable Vulkan device (the message says what to
install), the device lost, out of memory, an image that cannot be read or
written.
.TP
.B 2
A bad scene file, reported as
.IR FILE : LINE : COL ": error: " MESSAGE ,
or a bad command line, including trace settings that could make a ray tree
grow without end (see
.BR "render \-\-allow\-runaway" ).
.TP
.B 128+N
Ended by signal N: 130 for Ctrl\-C (SIGINT), 143 for SIGTERM, 129 for
SIGHUP. The image being written is removed.
EOF
  # A subcommand whose statuses mean more, as --help states it ("compare: ...").
  for s in "${subcommands[@]}"; do
    line=$(printf '%s\n' "$help" | sed -n "/^$s: /{s/^$s: //p;q;}")
    [ -z "$line" ] || { echo ".PP"; echo ".B snell $s:"; printf '%s\n' "$line" | escape; }
  done
  cat <<'EOF'
.SH EXAMPLES
Check a scene, then render it at its own size to
.IR scene.png :
.PP
.RS
.nf
snell check scene.scn
snell render scene.scn
.fi
.RE
.PP
Render it at 1024\(mu1024 pixels to a floating\-point OpenEXR image, with
timings and ray counts as JSON on standard output:
.PP
.RS
.nf
snell render scene.scn \-s 1024 \-o scene.exr \-\-stats
.fi
.RE
.PP
Measure the GPU's image against the double\-precision CPU reference, with a
false\-colour difference image:
.PP
.RS
.nf
snell render scene.scn \-\-cpu \-o exact.pfm
snell compare scene.png exact.pfm \-\-diff diff.png
.fi
.RE
.PP
Render the two halves of a 1024\(mu1024 image separately (on two machines,
say) and join them:
.PP
.RS
.nf
snell render scene.scn \-s 1024 \-\-region 0 0 1024 512 \-o top.exr
snell render scene.scn \-s 1024 \-\-region 0 512 1024 1024 \-o bottom.exr
snell assemble \-o whole.exr top.exr bottom.exr
.fi
.RE
.PP
Look at the scene in a window, re\-rendered each time the file is saved,
and list the Vulkan devices:
.PP
.RS
.nf
snell preview scene.scn
snell devices
.fi
.RE
.SH SCENE FORMAT
A scene file is text with one command and its arguments per line;
.B #
starts a comment anywhere on a line. Numbers are decimal; colours and
coefficients are 0 or more.
.TP
.BI "view " "n d"
An
.IR n \(mu n
image of the square from (\-d,\-d,0) to (d,d,0), seen from the eye at
(0,0,1) looking along \-z. Required, once.
.TP
.B sphere
The unit sphere at the origin, through the current transform, with the
current material and refraction.
.TP
.BI "scale " "sx sy sz"
Scale the current transform (factors not 0).
.TP
.BI "move " "x y z"
Translate the current transform.
.TP
.BI "rotate " "a x y z"
Rotate the current transform by
.I a
degrees about the axis (x,y,z), counter\-clockwise as the axis points at
you.
.TP
.BI "light " "r g b x y z"
A point light of colour (r,g,b) at (x,y,z); transforms do not move it.
.TP
.BI "background " "r g b"
The colour of rays that hit nothing (default black).
.TP
.BI "ambient " "r g b"
The ambient light (default none).
.TP
.BR group ", " groupend
Save, and restore, the transform, material and refraction.
.TP
.BI "material " "dr dg db sr sg sb p"
Diffuse kd, specular ks, Phong exponent p (default kd 1 1 1, ks 0 0 0, p
1).
.TP
.BI "refraction " "r g b i"
Transmission kt and index of refraction i (default kt 0 0 0, i 1.0002926).
.TP
.BI "supersample " s
.IR s \(mu s
rays per pixel (default 1).
.PP
Transforms apply to a sphere in the reverse of the order they are written:
the one nearest
.B sphere
acts first. The whole format, with ranges, errors and an example scene, is in
EOF
  echo ".IR \\%$scene_format ."
  echo ".SH SEE ALSO"
  echo ".IR \\%$scene_format ;"
  echo "README.md and docs/ of the snell sources."
} >"$out/snell.1"

# Completion: the subcommands, and each one's options as --help lists them
# (its lines "  -o,--output TEXT  ..."; options named in descriptions are not its).
{
  echo "# bash completion for snell, generated from 'snell --help' and 'snell SUBCOMMAND --help'"
  echo "_snell() {"
  echo "  local cur=\${COMP_WORDS[COMP_CWORD]} sub=\${COMP_WORDS[1]} words"
  echo "  if [ \"\$COMP_CWORD\" -eq 1 ]; then"
  echo "    COMPREPLY=(\$(compgen -W \"${subcommands[*]} --help --version\" -- \"\$cur\")); return"
  echo "  fi"
  echo "  case \$sub in"
  for s in "${subcommands[@]}"; do
    options=$(printf '%s\n' "${sub_help[$s]}" | awk '/^  -/ { print $1 }' | tr ',' '\n' |
      { grep -E '^--?[a-zA-Z][-a-zA-Z0-9]*$' || true; } | sort -u | tr '\n' ' ')
    echo "    $s) words=\"$options\";;"
  done
  echo "    *) words=\"\";;"
  echo "  esac"
  echo "  if [[ \$cur == -* ]]; then COMPREPLY=(\$(compgen -W \"\$words\" -- \"\$cur\"))"
  echo "  else COMPREPLY=(\$(compgen -f -- \"\$cur\")); fi"
  echo "}"
  echo "complete -o filenames -F _snell snell"
} >"$out/snell.bash"
