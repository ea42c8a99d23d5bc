#!/usr/bin/env bash
# Installs exactly the Debian 12 packages lampnav's build, tests and demo need.
# Idempotent: packages already installed are skipped, and apt is not touched when nothing is missing.
# Runs as root on a bare Debian 12 image (uses sudo when not root and sudo exists).
set -euo pipefail

packages=(
  # toolchain
  g++ cmake ninja-build ccache pkg-config make git
  # libraries
  libeigen3-dev libboost-graph-dev libopencv-dev libvisp-dev nlohmann-json3-dev libcli11-dev
  libcairo2-dev libzstd-dev
  # least squares for map building (mapping/)
  libceres-dev
  # YAML calibration files of ROS and Kalibr (io/, robot import), as ROS reads them
  libyaml-cpp-dev
  # OpenCV's XML calibration files (io/), read by the XML parser ROS 2 itself uses
  libtinyxml2-dev
  # ROS 2 bags in rosbag2's sqlite3 storage (.db3, the default up to Humble), read by SQLite
  libsqlite3-dev
  # the ROS 2 wire (ros/, lampnav node): eProsima Fast DDS, ROS 2's default DDS
  libfastrtps-dev libfastcdr-dev
  # tests and benchmarks; Chromium opens the report headless in a test
  libgtest-dev libgmock-dev libbenchmark-dev chromium
  # coverage-guided fuzzing (make fuzz): clang with libFuzzer and the sanitizer runtimes
  clang libclang-rt-14-dev
)
# Node.js and npm run the MCAP interoperability test (@mcap/core). A machine that already has
# them (from any source) keeps its own.
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  packages+=(nodejs npm)
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present" >&2
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "install-deps: missing packages (${missing[*]}) and not root; run as root" >&2
    exit 1
  fi
fi

echo "install-deps: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done" >&2
