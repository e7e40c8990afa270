#!/usr/bin/env bash
# Installs the Debian packages trm needs (only those missing) and configures + builds.
# Usage: tools/setup.sh [BUILD_DIR] [extra cmake args...]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${1:-$here/build}"
shift || true

packages=(
  build-essential cmake pkg-config
  libopencv-dev            # image/video I/O, reference filters (GaussianBlur, resize), DFT
  libopencv-contrib-dev    # SSIM (the quality module) for the perceptual metrics
  libusb-1.0-0-dev         # USB bulk rig feeder
  libhidapi-dev            # HID rig feeder (hidraw + libusb backends)
  libgtest-dev libgmock-dev
  libbenchmark-dev         # Google Benchmark
  libsystemc-dev           # sc_fixed: independent oracle for the fixed-point type; the decoder as a SystemC module
  libcli11-dev             # command-line parsing
  nlohmann-json3-dev       # report.json
  libdeflate-dev           # CRC-32 of link packets, captures and rig frames (carry-less multiply, chosen at run time)
  libcharls-dev            # JPEG-LS lossless link codec
  libplplot-dev            # the plots (PLplot)
  libeigen3-dev            # Levenberg-Marquardt least squares of `trm calibrate` (Eq. 7 fit); the matrix exponential of the second-order LC model; head-pose quaternions and slerp
  libhwy-dev               # Google Highway: the streaming decoder's line kernels in SIMD, dispatched at run time to the CPU's widest instruction set
  plplot-driver-cairo      # PLplot's pngcairo driver, a package of its own: PNG without a display
  fonts-dejavu-core        # the plots' text on a machine with no desktop fonts
  umockdev libumockdev-dev # emulated USB/HID devices for rig tests
  clang libclang-rt-14-dev # libFuzzer for the link receiver
  python3-dev pybind11-dev python3-pybind11  # the Python module `trm` (tools/python), built for /usr/bin/python3
  python3-numpy python3-pytest               # its arrays and its test suite (tests/python)
  verilator                # the decoder as a DPI-C golden model in an HDL simulation (tests/hdl)
  slurm-wlm munge          # tools/slurm/sweep.sh's test: a one-node Slurm cluster (slurmctld, slurmd, munged) on localhost
)

missing=()
for p in "${packages[@]}"; do
  [[ "$p" == \#* ]] && continue
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  echo "trm setup: installing missing Debian packages: ${missing[*]}" >&2
  sudo_cmd=()
  if [[ $(id -u) -ne 0 ]]; then sudo_cmd=(sudo); fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

jobs="$(nproc 2>/dev/null || echo 2)"
if [[ ! -f "$build_dir/CMakeCache.txt" ]]; then
  cmake -S "$here" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release "$@"
fi
cmake --build "$build_dir" -j "$jobs"
