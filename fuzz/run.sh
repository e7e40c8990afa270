#!/usr/bin/env bash
# Builds the link receiver fuzzer with clang (libFuzzer + AddressSanitizer + UndefinedBehaviorSanitizer),
# generates the seed corpus of real captures, and fuzzes for a bounded time.
#
# Usage: fuzz/run.sh SECONDS [EXTRA_SEED_DIR...]
#   SECONDS          total fuzzing time (e.g. 60 in CI)
#   EXTRA_SEED_DIR   more seeds, e.g. a directory of .trmcap files written by `trm run --capture-out`
# Environment: TRM_FUZZ_BUILD_DIR (default: $TMPDIR/trm-fuzz-build), CXX (default: clang++).
# Exit status: 0 when the run ends without a finding; non-zero on a crash, sanitizer report, leak,
# timeout or out-of-memory (the reproducer is left in the build directory under artifacts/).
set -euo pipefail

if [[ $# -lt 1 || ! "$1" =~ ^[0-9]+$ || "$1" -lt 1 ]]; then
  echo "usage: $0 SECONDS [EXTRA_SEED_DIR...]" >&2
  exit 2
fi
seconds=$1
shift

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(dirname "$here")
build=${TRM_FUZZ_BUILD_DIR:-${TMPDIR:-/tmp}/trm-fuzz-build}
cxx=${CXX:-clang++}
mkdir -p "$build/obj" "$build/artifacts" "$build/corpus"

common=(-std=c++20 -g -O1 -fno-omit-frame-pointer
        -I"$root/link/include" -I"$root/link/src" -I"$root/encoder/include"
        -isystem /usr/include/opencv4)
sanitize=(-fsanitize=address,undefined -fno-sanitize-recover=undefined)
libs=(-lcharls -lz -lopencv_imgcodecs -lopencv_imgproc -lopencv_core)

# Library sources, instrumented for coverage (fuzzer-no-link) and the sanitizers; rebuilt when newer.
objects=()
for src in "$root"/link/src/*.cpp "$root"/encoder/src/frame.cpp; do
  obj="$build/obj/$(basename "$(dirname "$(dirname "$src")")")_$(basename "$src" .cpp).o"
  if [[ ! -f "$obj" || "$src" -nt "$obj" || -n "$(find "$root/link/include" "$root/link/src" "$root/encoder/include/trm/frame.hpp" -newer "$obj" -print -quit)" ]]; then
    "$cxx" "${common[@]}" "${sanitize[@]}" -fsanitize=fuzzer-no-link -c "$src" -o "$obj"
  fi
  objects+=("$obj")
done

"$cxx" "${common[@]}" "${sanitize[@]}" -fsanitize=fuzzer "$here/fuzz_receiver.cpp" "${objects[@]}" "${libs[@]}" \
  -o "$build/fuzz_receiver"
"$cxx" "${common[@]}" "${sanitize[@]}" -fsanitize=fuzzer-no-link "$here/make_corpus.cpp" "${objects[@]}" "${libs[@]}" \
  -o "$build/make_corpus"

seeds="$build/seeds"
rm -rf "$seeds"
"$build/make_corpus" "$seeds"

# libFuzzer adds what it finds to the first directory; the seeds stay untouched.
"$build/fuzz_receiver" "$build/corpus" "$seeds" "$@" \
  -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=65536 \
  -artifact_prefix="$build/artifacts/" -print_final_stats=1
