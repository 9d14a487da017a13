#!/usr/bin/env bash
# Install snell's Debian 12 dependencies (when missing) and build it into build/.
# Used by both quick-start commands; safe to run again.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(cmake ninja-build g++ pkg-config
          libvulkan-dev mesa-vulkan-drivers vulkan-tools vulkan-validationlayers
          glslang-tools libglm-dev libglfw3-dev libstb-dev libpng-dev libtinyexr-dev libcli11-dev libgtest-dev
          clang-14 libclang-rt-14-dev xvfb povray python3)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "snell setup: installing ${missing[*]}" >&2
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build --parallel
