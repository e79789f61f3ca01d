#!/usr/bin/env bash
# Install dependencies, build, and run the end-to-end demo.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
./build/apps/elastolearn/elastolearn demo "$@"
