#!/usr/bin/env bash
# README command 1: set up, build, and run animat_evolve on its embedded default config (short demo).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
./build/animat_evolve "$@"
