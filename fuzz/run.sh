#!/usr/bin/env bash
# Builds every libFuzzer target with clang (libFuzzer + AddressSanitizer + UndefinedBehaviorSanitizer),
# generates their seed corpora, fuzzes each for a bounded time and prints, per target, the executions,
# the corpus size and the findings (docs/fuzzing.md).
#
# Usage: fuzz/run.sh SECONDS [EXTRA_SEED_DIR...]
#   SECONDS          fuzzing time of the whole run (wall clock, build excluded), shared evenly by the
#                    targets: with TRM_FUZZ_JOBS targets at a time each gets SECONDS * JOBS / TARGETS
#                    (at least 1 s, at most SECONDS)
#   EXTRA_SEED_DIR   more .trmcap seeds for the receiver and capture targets, e.g. a directory of captures
#                    written by `trm run --capture-out`
# Environment: TRM_FUZZ_TARGETS (default: all of receiver capture rig_answers rig_stream panel
#   link_preset view_size options image video), TRM_FUZZ_JOBS (compiles and fuzzers at a time, default
#   2), TRM_FUZZ_BUILD_DIR (default: $TMPDIR/trm-fuzz-build), CXX (default: clang++).
# Exit status: 0 when every target ends without a finding; 1 on any crash, sanitizer report, leak,
# timeout or out-of-memory (the reproducer is left under artifacts/TARGET/ in the build directory).
set -euo pipefail
{  # read whole before it runs: editing the script during a long run cannot derail it

all_targets=(receiver capture rig_answers rig_stream panel link_preset view_size options image video)
if [[ $# -lt 1 || ! "$1" =~ ^[0-9]+$ || "$1" -lt 1 ]]; then
  echo "usage: $0 SECONDS [EXTRA_SEED_DIR...]   (TRM_FUZZ_TARGETS: ${all_targets[*]})" >&2
  exit 2
fi
seconds=$1
shift
extra=("$@")
read -r -a targets <<<"${TRM_FUZZ_TARGETS:-${all_targets[*]}}"
for t in "${targets[@]}"; do
  [[ " ${all_targets[*]} " == *" $t "* ]] || { echo "$0: unknown target '$t' (targets: ${all_targets[*]})" >&2; exit 2; }
done

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(dirname "$here")
build=${TRM_FUZZ_BUILD_DIR:-${TMPDIR:-/tmp}/trm-fuzz-build}
cxx=${CXX:-clang++}
jobs=${TRM_FUZZ_JOBS:-2}
mkdir -p "$build/obj" "$build/logs"

includes=(-I"$root/link/include" -I"$root/link/src" -I"$root/encoder/include" -I"$root/encoder/src"
          -I"$root/hw_models/include" -I"$root/fixed_point/include" -I"$root/tools/src" -I"$root/tools/rig/include" -isystem /usr/include/opencv4 -isystem /usr/include/eigen3)
common=(-std=c++20 -g -O1 -fno-omit-frame-pointer "${includes[@]}")
sanitize=(-fsanitize=address,undefined -fno-sanitize-recover=undefined)
libs=(-lcharls -ldeflate -lhwy -lopencv_videoio -lopencv_imgcodecs -lopencv_imgproc -lopencv_core)
header_dirs=("$root/link/include" "$root/link/src" "$root/encoder/include" "$root/encoder/src"
             "$root/hw_models/include" "$root/fixed_point/include" "$root/tools/src" "$root/tools/rig/include")

# The library sources the targets reach, instrumented for coverage (fuzzer-no-link) and the sanitizers,
# compiled TRM_FUZZ_JOBS at a time and rebuilt when a source or a project header is newer.
sources=("$root"/link/src/*.cpp "$root"/encoder/src/{frame,transfer,sources,media}.cpp "$root"/encoder/src/scenes/scene_support.cpp
         "$root"/hw_models/src/panel.cpp "$root"/hw_models/src/lc_response.cpp "$root"/hw_models/src/lc_second_order.cpp "$root"/tools/src/view_size.cpp "$root"/tools/rig/src/{protocol,feeder,transport}.cpp
         "$root"/fixed_point/src/vector_pow.cpp)
compile() {  # SOURCE OBJECT HEADER_DIR... -- FLAGS...
  local src=$1 obj=$2 dirs=()
  shift 2
  while [[ $1 != -- ]]; do dirs+=("$1"); shift; done
  shift
  if [[ ! -f "$obj" || "$src" -nt "$obj" || -n "$(find "${dirs[@]}" -name '*.hpp' -newer "$obj" -print -quit)" ]]; then
    "$cxx" "${common[@]}" "${sanitize[@]}" "$@" -c "$src" -o "$obj"
  fi
}
wait_for_slot() {
  while (($(jobs -rp | wc -l) >= jobs)); do wait -n || exit 1; done
}
objects=()
for src in "${sources[@]}"; do
  rel=${src#"$root"/}
  obj="$build/obj/${rel//\//_}"
  obj=${obj%.cpp}.o
  objects+=("$obj")
  # The vector pow includes itself once per instruction set (Highway's foreach_target) and fuses only where glibc's
  # pow does (fixed_point/CMakeLists.txt).
  extra=()
  [[ $src == */vector_pow.cpp ]] && extra=(-I"$root/fixed_point/src" -ffp-contract=off)
  wait_for_slot
  compile "$src" "$obj" "${header_dirs[@]}" -- -fsanitize=fuzzer-no-link "${extra[@]}" &
done
for program in "${targets[@]/#/fuzz_}" make_corpus make_seeds; do
  wait_for_slot
  compile "$here/$program.cpp" "$build/obj/$program.o" "${header_dirs[@]}" "$here" -- -fsanitize=fuzzer-no-link &
done
# The media plugin (encoder/plugin) linked into every program rather than loaded, so that OpenCV's decoders are
# reached by the instrumented code it calls; an object of its own, since a weak reference (the loader's) does not
# pull a member out of an archive.
plugin_object="$build/obj/encoder_plugin_media_plugin.o"
wait_for_slot
compile "$root/encoder/plugin/media_plugin.cpp" "$plugin_object" "${header_dirs[@]}" -- -fsanitize=fuzzer-no-link &
while (($(jobs -rp | wc -l))); do wait -n || exit 1; done
rm -f "$build/libtrm_fuzz.a"
ar rcs "$build/libtrm_fuzz.a" "${objects[@]}"

for t in "${targets[@]}"; do
  wait_for_slot
  "$cxx" "${sanitize[@]}" -fsanitize=fuzzer "$build/obj/fuzz_$t.o" "$plugin_object" "$build/libtrm_fuzz.a" "${libs[@]}" -o "$build/fuzz_$t" &
done
for program in make_corpus make_seeds; do
  wait_for_slot
  "$cxx" "${sanitize[@]}" "$build/obj/$program.o" "$plugin_object" "$build/libtrm_fuzz.a" "${libs[@]}" -o "$build/$program" &
done
while (($(jobs -rp | wc -l))); do wait -n || exit 1; done

# Seeds: regenerated every run; libFuzzer adds what it finds to corpus/TARGET, the seeds stay untouched.
rm -rf "$build/seeds"
"$build/make_corpus" "$build/seeds/receiver"
cp -r "$build/seeds/receiver" "$build/seeds/capture"
"$build/make_seeds" "$build/seeds"

per_target=$((seconds * jobs / ${#targets[@]}))
((per_target >= 1)) || per_target=1
((per_target <= seconds)) || per_target=$seconds
echo "fuzzing ${#targets[@]} targets, $per_target s each, $jobs at a time"
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=1"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:+$UBSAN_OPTIONS:}print_stacktrace=1:halt_on_error=1"
run_target() {  # TARGET
  local t=$1 max_len=4096 more=()
  case $t in
    receiver | capture) max_len=65536; more=("${extra[@]}") ;;
    # OpenCV and the codecs behind it print a line for every rejected input; -close_fd_mask=2 keeps
    # them out of the log (sanitizer reports and libFuzzer's own lines still reach it). Decoders that
    # keep an allocation after a malformed input (docs/fuzzing.md) would make libFuzzer run a full leak
    # scan after nearly every input, 25 times slower: -detect_leaks=0 leaves the leak check to the end of
    # the run, where LeakSanitizer still reports (and fails the target on) any leak of the whole run.
    image | video) max_len=16384; more=(-close_fd_mask=2 -detect_leaks=0) ;;
    panel | link_preset | view_size | options) max_len=256 ;;
  esac
  mkdir -p "$build/corpus/$t" "$build/artifacts/$t"
  rm -f "$build/artifacts/$t"/*
  rm -rf "$build/tmp/$t" && mkdir -p "$build/tmp/$t"  # the targets' scratch files (fuzz_support.hpp)
  local status=0
  TMPDIR="$build/tmp/$t" "$build/fuzz_$t" "$build/corpus/$t" "$build/seeds/$t" "${more[@]}" \
    -max_total_time="$per_target" -timeout=10 -rss_limit_mb=2048 -max_len="$max_len" \
    -artifact_prefix="$build/artifacts/$t/" -print_final_stats=1 >"$build/logs/$t.log" 2>&1 || status=$?
  rm -rf "$build/tmp/$t"
  echo "$status" >"$build/logs/$t.status"
}
for t in "${targets[@]}"; do
  wait_for_slot
  run_target "$t" &
done
wait

failed=0
printf '%-12s %12s %8s %8s  %s\n' target executions exec/s corpus findings
for t in "${targets[@]}"; do
  log="$build/logs/$t.log"
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  corpus=$(find "$build/corpus/$t" "$build/seeds/$t" -type f | wc -l)
  artifacts=$(find "$build/artifacts/$t" -type f | sort | tr '\n' ' ')
  status=$(cat "$build/logs/$t.status")
  findings=0
  if [[ -n "$artifacts" ]]; then
    findings=$artifacts
  elif [[ "$status" != 0 ]]; then
    findings="exit status $status, no artifact (see $log)"
  fi
  [[ "$findings" == 0 ]] || failed=1
  printf '%-12s %12s %8s %8s  %s\n' "$t" "${execs:-?}" "${rate:-?}" "$corpus" "$findings"
done
if ((failed)); then
  echo "fuzzing found something: the logs are in $build/logs, the reproducers under $build/artifacts" >&2
  exit 1
fi
exit 0
}
