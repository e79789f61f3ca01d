#!/usr/bin/env bash
# Fail if a tracked C++ source (*.cpp, *.hpp) differs from what clang-format makes of it with the
# repository's .clang-format. The reference is clang-format 14 (Debian 12's): other major versions
# format some constructs differently, so with one of those (or none) the check is skipped.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v clang-format >/dev/null 2>&1; then
  echo "check-format: clang-format not installed; skipped"
  exit 0
fi
version=$(clang-format --version | sed -n 's/.*clang-format version \([0-9][0-9]*\)\..*/\1/p')
if [[ "$version" != 14 ]]; then
  echo "check-format: found clang-format ${version:-of unknown version}, the reference is 14; skipped"
  exit 0
fi

if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  list_sources() { git ls-files -z -- '*.cpp' '*.hpp'; }
else # an exported tree: the same folders git tracks
  list_sources() { find apps bench python src tests -type f \( -name '*.cpp' -o -name '*.hpp' \) -print0; }
fi
# Batches over ${JOBS:-2} processes; clang-format prints each offending line and fails.
if ! list_sources | xargs -0 -n 32 -P "${JOBS:-2}" clang-format --dry-run -Werror; then
  echo "check-format: the files above differ from clang-format 14's output; run" \
    "'clang-format -i <file>' on them" >&2
  exit 1
fi
echo "check-format: all sources formatted"
