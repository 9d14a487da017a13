#!/usr/bin/env bash
# Install snell's Debian 12 dependencies (when missing) and build it into build/.
# Used by both quick-start commands; safe to run again.
#
# lavapipe (Mesa's CPU Vulkan driver) comes from bookworm-backports, Mesa 25:
# measured 1.5-3.4x as fast on snell's shader as Debian 12's own Mesa 22.3
# (docs/performance.md). SNELL_LAVAPIPE=stock keeps the stock driver. Either
# way the other one is unpacked beside the build (build/lavapipe-*/, used
# through VK_DRIVER_FILES, the system's untouched) so the tests run on both.
set -euo pipefail
cd "$(dirname "$0")/.."

SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
apt_updated=""
apt_update() { [ -n "$apt_updated" ] || { $SUDO apt-get update -q; apt_updated=1; }; }

packages=(cmake ninja-build g++ pkg-config
          libvulkan-dev mesa-vulkan-drivers vulkan-tools vulkan-validationlayers
          glslang-tools spirv-tools libglm-dev libglfw3-dev libstb-dev libpng-dev libopenexr-dev libcli11-dev libgtest-dev
          clang-14 libclang-rt-14-dev xvfb povray python3 python3-matplotlib)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "snell setup: installing ${missing[*]}" >&2
  apt_update
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# --- lavapipe: Mesa 25 from bookworm-backports by default. ------------------
# The URI of the first enabled source of the bookworm suite itself, in
# one-line (sources.list) or deb822 (.sources) form; Debian's default if none.
debian_mirror() {
  local uri
  uri=$(cat /etc/apt/sources.list /etc/apt/sources.list.d/*.list 2>/dev/null |
        awk '$1 == "deb" { for (i = 2; i <= NF; i++) if ($i !~ /^\[/ && $i !~ /\]$/) break;
                           if ($(i + 1) == "bookworm") { print $i; exit } }' || true)
  if [ -z "$uri" ]; then
    uri=$(cat /etc/apt/sources.list.d/*.sources 2>/dev/null |
          awk 'BEGIN { RS = ""; FS = "\n" }
               { uris = ""; suites = ""; enabled = 1
                 for (i = 1; i <= NF; i++) {
                   if ($i ~ /^URIs:/) { uris = $i; sub(/^URIs:[ \t]*/, "", uris) }
                   if ($i ~ /^Suites:/) { suites = " " $i " "; sub(/^ Suites:/, "", suites) }
                   if ($i ~ /^Enabled:[ \t]*no/) enabled = 0 }
                 if (enabled && suites ~ /[ \t]bookworm[ \t]/) { split(uris, u, /[ \t]+/); print u[1]; exit } }' || true)
  fi
  echo "${uri:-http://deb.debian.org/debian}"
}
mesa_version() { dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null; }
second_icd=""
codename=$(. /etc/os-release 2>/dev/null && echo "${VERSION_CODENAME:-}")
if [ "$codename" = bookworm ]; then
  if ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/; then
    # The mirror the machine already takes bookworm from (a machine behind a
    # local mirror or proxy may reach no other), else Debian's own.
    mirror=$(debian_mirror)
    echo "snell setup: adding bookworm-backports from $mirror to apt's sources (for Mesa 25's lavapipe)" >&2
    printf 'Types: deb\nURIs: %s\nSuites: bookworm-backports\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' "$mirror" |
      $SUDO tee /etc/apt/sources.list.d/snell-bookworm-backports.sources >/dev/null
    apt_updated=""
  fi
  # Debian's own lavapipe: the newest version that is not a backport.
  stock() { apt-cache madison mesa-vulkan-drivers 2>/dev/null | awk -F'|' '{gsub(/ /, "", $2)} $2 !~ /bpo/ {print $2; exit}'; }
  stock_version=$(stock)
  [ -n "$stock_version" ] || { apt_update; stock_version=$(stock); }
  if [ "${SNELL_LAVAPIPE:-backports}" = stock ]; then
    echo "snell setup: SNELL_LAVAPIPE=stock: keeping lavapipe from mesa-vulkan-drivers $(mesa_version)" >&2
  else
    case "$(mesa_version)" in
      *bpo*) ;;
      *) echo "snell setup: installing lavapipe from bookworm-backports (SNELL_LAVAPIPE=stock keeps Debian's $(mesa_version))" >&2
         apt_update
         DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends -t bookworm-backports mesa-vulkan-drivers ;;
    esac
    echo "snell setup: lavapipe is mesa-vulkan-drivers $(mesa_version) from bookworm-backports" >&2
    # Debian's stock lavapipe beside it, for the tests on both drivers.
    if [ -n "$stock_version" ]; then
      dir="build/lavapipe-$stock_version"
      icd="$PWD/$dir/lvp_icd.json"
      if [ ! -f "$icd" ]; then
        rm -rf "$dir" && mkdir -p "$dir"
        (cd "$dir" && apt-get download -q "mesa-vulkan-drivers=$stock_version" >/dev/null 2>&1 ||
           { apt_update >/dev/null; apt-get download -q "mesa-vulkan-drivers=$stock_version" >/dev/null; })
        dpkg-deb -x "$dir"/mesa-vulkan-drivers_*.deb "$dir/root"
        library=$(find "$PWD/$dir/root" -name libvulkan_lvp.so | head -n 1)
        manifest=$(find "$dir/root" -name 'lvp_icd.*.json' | head -n 1)
        sed "s|\"library_path\": *\"[^\"]*\"|\"library_path\": \"$library\"|" "$manifest" >"$icd"
      fi
      second_icd="$icd"
    fi
  fi
fi

# ccache where present (a fresh machine has none; nothing needs it).
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DSNELL_SECOND_LAVAPIPE_ICD="$second_icd" "${launcher[@]}" >/dev/null
cmake --build build --parallel
