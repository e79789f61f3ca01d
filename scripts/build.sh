#!/usr/bin/env bash
# Configure and build elastolearn (Release) into ./build with 2 jobs (or $JOBS).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release ${ELASTOLEARN_CMAKE_ARGS:-} >/dev/null
cmake --build build -j "${JOBS:-2}"
