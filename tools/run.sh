#!/usr/bin/env bash
# Quick start 1: install what is missing, build, and run the main job (`trm run`, built-in default scene).
# Extra arguments go to `trm run`.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$here/tools/setup.sh" "$here/build"
exec "$here/build/trm" run "$@"
