#!/usr/bin/env bash
# Install dependencies, check formatting, build, and run the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/check-format.sh # before the build: a formatting error fails fast
./scripts/build.sh
ctest --test-dir build --output-on-failure -j "${JOBS:-2}"
