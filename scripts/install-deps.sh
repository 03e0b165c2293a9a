#!/usr/bin/env bash
# Installs the Debian 12 packages dpc needs to build, run and test.
# Idempotent and non-interactive: packages already present are skipped.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config ccache
  libembree-dev libtbb-dev libglm-dev
  libsndfile1-dev libsamplerate0-dev libfftw3-dev portaudio19-dev libjack-jackd2-dev
  libmysofa-dev robin-map-dev jackd2 libnetcdf-dev netcdf-bin
  nlohmann-json3-dev libtinyobjloader-dev libassimp-dev libcli11-dev catch2
  python3 python3-numpy python3-matplotlib espeak-ng sox
  python3-scipy  # the Ambisonic late field read by SciPy's filters (tests/apps/ambisonic_late_field_check.py)
  pybind11-dev python3-pybind11 python3-pytest  # the Python module and its tests
  python3-dev python3-setuptools python3-wheel python3-venv  # pip install . (docs/python.md)
  clang libclang-rt-dev
  lv2-dev lilv-utils sordi
  jalv python3-jack-client  # the plugin inside a real host (tests/lv2/jalv_test.py)
  ardour  # the plugin in Ardour's headless Lua session (tests/lv2/ardour_test.py)
  libzita-convolver-dev  # dpc-bench convolve only: the yardstick
  libeigen3-dev  # headers only: dpc-analyze --diffuseness (analysis/), the slits' mutual loading (engine/slit.cpp)
  libhdf5-dev hdf5-tools python3-h5py  # dpc-bake's file, its tests (h5diff), the h5py example
  zlib1g-dev  # the bake file's CRC-32 checksums
  libopenmpi-dev openmpi-bin  # dpc-bake under mpirun (optional: without it, single-process)
  libcpp-httplib-dev  # dpc studio's web server (apps/studio)
  chromium  # dpc studio's browser test (tests/studio: headless, driven by npm's puppeteer-core)
)
# The glTF oracle test (tests/gltf/oracle_test.py) runs the Khronos glTF-Validator on Node.js,
# installed by npm, as are dpc studio's three.js and its test's puppeteer-core; a Node.js that brings its own npm (NodeSource's package) is kept.
command -v npm >/dev/null || packages+=(nodejs npm)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep "install ok installed" >/dev/null; then
    missing+=("$p")
  fi
done

if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}" >&2
  SUDO=""
  if [[ $(id -u) -ne 0 ]]; then SUDO=sudo; fi
  export DEBIAN_FRONTEND=noninteractive
  # jackd2 asks whether to enable real-time priority limits; answer no without a prompt.
  echo "jackd2 jackd/tweak_rt_limits boolean false" | $SUDO debconf-set-selections
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
else
  echo "install-deps: all packages present" >&2
fi
