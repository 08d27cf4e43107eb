#!/usr/bin/env bash
# Builds the Python wheel of python/ with maturin: the `nesy` binary (installed into the
# environment's scripts directory) and the `nesy` package (the Python API, the robot server
# base class and the examples).
#
#   scripts/build-wheel.sh [--release | --static] [--out DIR]   (default: the dev profile, target/wheels)
#
# The binary embeds the system CPython (scripts/system-python), so the wheel is tagged for
# that CPython and needs its libpython where it is installed. `--static` puts the static
# binary of scripts/build-static.sh in the wheel instead (built with the same environment,
# scripts/static/env.sh): it needs no Python and no shared library where it is installed,
# though maturin still tags the wheel for CPython 3.11, whose libpython it links. maturin is taken from $MATURIN, from PATH, or
# installed once into target/maturin-venv from the package index.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
profile=dev
static=false
out="$ROOT/target/wheels"
while [ $# -gt 0 ]; do
  case "$1" in
    --release) profile=release ;;
    --static) static=true ;;
    --out) out=$(realpath -m "$2"); shift ;;
    *) echo "usage: scripts/build-wheel.sh [--release | --static] [--out DIR]" >&2; exit 2 ;;
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
if $static; then
  cd "$ROOT"
  # shellcheck source=scripts/static/env.sh
  . scripts/static/env.sh
  cd "$ROOT/python"
  "$maturin" build --release --strip --target "$STATIC_TARGET" --features "$STATIC_FEATURES" \
    --compatibility linux --interpreter /usr/bin/python3.11 --out "$out"
  exit 0
fi
cd "$ROOT/python"
# `--compatibility linux`: the binary links the system's libpython, which no manylinux
# policy allows; the wheel is for machines with that CPython.
"$maturin" build --profile "$profile" --compatibility linux --interpreter "$python" --out "$out"
