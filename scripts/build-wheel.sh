#!/usr/bin/env bash
# Builds the Python wheel of python/ with maturin: the `nesy` binary (installed into the
# environment's scripts directory) and the `nesy` package (the Python API, the robot server
# base class and the examples).
#
#   scripts/build-wheel.sh [--release] [--out DIR]      (default: the dev profile, target/wheels)
#
# The binary embeds the system CPython (scripts/system-python), so the wheel is tagged for
# that CPython and needs its libpython where it is installed; the static binary of
# scripts/build-static.sh has no such need. maturin is taken from $MATURIN, from PATH, or
# installed once into target/maturin-venv from the package index.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
profile=dev
out="$ROOT/target/wheels"
while [ $# -gt 0 ]; do
  case "$1" in
    --release) profile=release ;;
    --out) out=$(realpath -m "$2"); shift ;;
    *) echo "usage: scripts/build-wheel.sh [--release] [--out DIR]" >&2; exit 2 ;;
  esac
  shift
done
python=$("$ROOT/scripts/system-python" -c 'import sys; print(sys.executable)')
maturin=${MATURIN:-$(command -v maturin || true)}
if [ -z "$maturin" ]; then
  venv="$ROOT/target/maturin-venv"
  if [ ! -x "$venv/bin/maturin" ]; then
    "$python" -m venv "$venv"
    "$venv/bin/pip" install -q "maturin>=1.5,<2"
  fi
  maturin="$venv/bin/maturin"
fi
mkdir -p "$out"
cd "$ROOT/python"
# `--compatibility linux`: the binary links the system's libpython, which no manylinux
# policy allows; the wheel is for machines with that CPython.
"$maturin" build --profile "$profile" --compatibility linux --interpreter "$python" --out "$out"
