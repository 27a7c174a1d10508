#!/usr/bin/env bash
# Installs the Debian bookworm packages the station needs (idempotent: installs only what is
# missing). Usage: deploy/install-deps.sh [--tests]   (--tests adds the independent peers
# the test suite runs against).
set -euo pipefail

build_pkgs=(
  g++ cmake ninja-build pkg-config git
  libeigen3-dev libfftw3-dev libmodbus-dev libsqlite3-dev libspdlog-dev nlohmann-json3-dev
  libcpp-httplib-dev libcli11-dev libgtest-dev libssl-dev zlib1g-dev libasound2-dev
  libsndfile1-dev libsystemd-dev prometheus-cpp-dev libcairo2-dev libmosquitto-dev libpq-dev
  help2man
)
test_pkgs=(
  python3 python3-numpy python3-scipy python3-pymodbus python3-serial-asyncio python3-can
  can-utils socat sqlite3 mosquitto python3-paho-mqtt postgresql-15 openssl
  chromium dpkg-dev pulseaudio libasound2-plugins clang-format systemd fonts-noto-cjk
  clang-14 libclang-rt-14-dev
)

pkgs=("${build_pkgs[@]}")
if [[ "${1:-}" == "--tests" ]]; then pkgs+=("${test_pkgs[@]}"); fi

missing=()
# The browser test drives chromium with playwright-core from npm: node.js is needed, from
# Debian unless the machine already has one.
if [[ "${1:-}" == "--tests" ]] && ! command -v node >/dev/null 2>&1; then pkgs+=(nodejs npm); fi
for p in "${pkgs[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#pkgs[@]} packages present"
  exit 0
fi

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get -o DPkg::Lock::Timeout=600 update -qq
$SUDO apt-get -o DPkg::Lock::Timeout=600 install -y -qq --no-install-recommends "${missing[@]}"
