#!/usr/bin/env bash
# Installs what building nesy needs on a fresh Debian/Ubuntu machine, and nothing that is
# already there: a Rust toolchain (rustup, with rustfmt and clippy), CPython 3.11 and its
# shared library (nesy-policy embeds it), and the PyPI `mcap` reader the MCAP cross-check
# test uses. Idempotent; safe to run on every CI start.
set -euo pipefail

log() { printf '\n==> %s\n' "$*"; }
as_root() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }

log "toolchain"
if ! command -v cargo >/dev/null 2>&1; then
  [ -f "$HOME/.cargo/env" ] || curl -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal
  # shellcheck disable=SC1091
  . "$HOME/.cargo/env"
fi
rustup component add rustfmt clippy >/dev/null 2>&1 || true
cargo --version

log "system packages"
need_apt=()
[ -x /usr/bin/python3.11 ] || need_apt+=(python3.11)
[ -e /usr/lib/x86_64-linux-gnu/libpython3.11.so ] || need_apt+=(libpython3.11-dev)
python3.11 -m pip --version >/dev/null 2>&1 || need_apt+=(python3-pip)
if [ ${#need_apt[@]} -gt 0 ]; then
  as_root apt-get update -qq
  DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq "${need_apt[@]}"
fi

log "python packages"
if ! python3.11 -c 'import mcap' >/dev/null 2>&1; then
  python3.11 -m pip install --quiet --break-system-packages mcap 2>/dev/null \
    || python3.11 -m pip install --quiet mcap \
    || echo "warning: could not install the PyPI mcap package; the MCAP cross-reader test will say so"
fi
