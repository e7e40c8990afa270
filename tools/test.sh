#!/usr/bin/env bash
# Quick start 2: install what is missing, build, and run the whole test suite.
# Usage: tools/test.sh [BUILD_DIR] [extra cmake args...]   (default build dir: build/)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${1:-$here/build}"
shift || true
bash "$here/tools/setup.sh" "$build_dir" "$@"
jobs="$(nproc 2>/dev/null || echo 2)"
ctest --test-dir "$build_dir" --output-on-failure -j "$jobs" --timeout 900
