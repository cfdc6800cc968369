#!/usr/bin/env bash
# Installs the Debian packages wheelins needs, only those that are missing.
# Idempotent: when everything is present it only checks and returns.
# gnuplot-nox draws the plots of `wheelins experiment` and `wheelins study report` (optional at
# run time); parallel (GNU parallel) runs a study's jobs in scripts/study-parallel.sh.
# ROS recordings (`wheelins import`): sqlite3, zstd, lz4 and bzip2 for our readers of ROS 1
# bags, ROS 2 bags and MCAP. The tests write ROS 1 bags with Debian's ROS 1 bag library, an
# implementation independent of our reader. `wheelins live --ros` (the ROS 1 node, a plugin
# the program loads only then) needs roscpp and diagnostic_msgs; its test a roscore, rosbag
# and the messages' Python modules (ros-core, python3-*-msgs). The Python module: pybind11 and Debian's python3
# (/usr/bin/python3) with numpy, pytest and matplotlib (its tests and the example in examples/).
# Optional groups, named as arguments: `fuzz` (clang and its libFuzzer/sanitizer
# runtime, for scripts/fuzz.sh). `no-ros` leaves out the ROS 1 packages, for a build with
# -DWHEELINS_ROS1=OFF (a cluster node, a machine without Debian's ROS packages): the program
# is the same (it links no ROS either way) but has no `live --ros`; the tests that write ROS 1
# bags or start a roscore are skipped.
# Usage: scripts/setup.sh [fuzz] [no-ros]
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev libyaml-cpp-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  gnuplot-nox parallel
  libbz2-dev
  libsqlite3-dev libzstd-dev liblz4-dev
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib python3-yaml
)
ros1=(librosbag-storage-dev libsensor-msgs-dev libnav-msgs-dev libgeometry-msgs-dev libtf2-msgs-dev
      libroscpp-dev libdiagnostic-msgs-dev ros-core python3-rosbag python3-sensor-msgs python3-nav-msgs
      python3-tf2-msgs python3-diagnostic-msgs)
for group in "$@"; do
  case $group in
    fuzz) packages+=(clang libclang-rt-14-dev) ;;
    no-ros) ros1=() ;;
    *) echo "setup: unknown package group '$group' (known: fuzz, no-ros)" >&2; exit 2 ;;
  esac
done
packages+=("${ros1[@]}")

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "setup: installing missing packages: ${missing[*]}"
sudo_cmd=""
if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$sudo_cmd apt-get update -qq
$sudo_cmd apt-get install -y -qq --no-install-recommends "${missing[@]}"
