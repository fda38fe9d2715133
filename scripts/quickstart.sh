#!/usr/bin/env bash
# Quick start: install dependencies, build pointrast (Release), render the built-in demo scene to demo.png.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release -DPOINTRAST_TESTS=OFF \
  -DPOINTRAST_PYTHON=ON -DPython_EXECUTABLE=/usr/bin/python3 # import pointrast: PYTHONPATH=build/python
cmake --build build -j"$(nproc)"
# XDG_RUNTIME_DIR silences a Mesa warning on machines without a login session.
XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}" ./build/pointrast render -o demo.png
echo "quickstart: wrote $(pwd)/demo.png"
