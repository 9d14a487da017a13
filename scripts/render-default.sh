#!/usr/bin/env bash
# Quick start 1: set up, build, and render the default scene headless to showcase.png.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
./build/snell render scenes/showcase.scn -o showcase.png --stats
echo "wrote $(pwd)/showcase.png" >&2
