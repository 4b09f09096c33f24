#!/usr/bin/env bash
# Installs everything animat needs on Debian 12: apt packages and a project virtualenv (.venv).
# Idempotent and quiet when everything is already there.
set -euo pipefail
cd "$(dirname "$0")/.."

APT_PACKAGES=(build-essential cmake ninja-build pkg-config python3-venv
  libbox2d-dev libcgal-dev libeigen3-dev libspdlog-dev libfmt-dev googletest libgtest-dev
  libtomlplusplus-dev nlohmann-json3-dev libcli11-dev libbenchmark-dev
  libopenmpi-dev openmpi-bin
  chromium)  # the headless browser of tests/python/test_explore.py (driven by playwright)
if [[ "${ANIMAT_EXTRA_APT:-}" != "" ]]; then read -r -a extra <<<"$ANIMAT_EXTRA_APT"; APT_PACKAGES+=("${extra[@]}"); fi

missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing Debian packages: ${missing[*]}"
  SUDO=""; [[ $(id -u) -ne 0 ]] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

REQ=requirements-dev.txt
STAMP=.venv/.animat-requirements
if [[ ! -x .venv/bin/python ]] || ! cmp -s "$REQ" "$STAMP"; then
  echo "setup: preparing .venv with Python packages from $REQ"
  [[ -x .venv/bin/python ]] || python3 -m venv .venv
  .venv/bin/python -m pip install -q --disable-pip-version-check --upgrade pip >/dev/null
  .venv/bin/python -m pip install -q --disable-pip-version-check -r "$REQ"
  cp "$REQ" "$STAMP"
fi
