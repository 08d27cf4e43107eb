#!/usr/bin/env bash
# Installs what building nesy needs on a fresh Debian or Ubuntu machine, and nothing that is
# already there: a C and a C++ compiler (OpenH264, the video decoder, is C++) and linker,
# curl and CA certificates (for rustup and cargo), the system's CPython 3.11, 3.12 or 3.13
# with its shared library (nesy-policy embeds it) and pip, a Rust toolchain (rustup, with
# rustfmt and clippy), and the PyPI `mcap` reader the MCAP cross-check test uses. Works
# with APT's Recommends off. Idempotent; safe to run on every CI start.
set -euo pipefail

log() { printf '\n==> %s\n' "$*"; }
as_root() { if [ "$(id -u)" -eq 0 ]; then "$@"; else sudo "$@"; fi; }
apt_install() {
  if [ -z "${apt_updated:-}" ]; then
    as_root apt-get update -qq
    apt_updated=1
  fi
  # -o Dpkg::Use-Pty=0 and -qq keep dpkg's progress out of the log.
  DEBIAN_FRONTEND=noninteractive as_root apt-get install -y -qq -o Dpkg::Use-Pty=0 \
    --no-install-recommends "$@" >/dev/null
}
# The interpreter the build embeds (scripts/system-python chooses it), or nothing.
supported_python() {
  "$(dirname "$0")/system-python" -I -S -c 'import sys; print(sys.executable)' 2>/dev/null
}

if ! command -v apt-get >/dev/null 2>&1; then
  echo "install-prereqs.sh supports Debian and Ubuntu (apt-get). Elsewhere install a C and a C++ compiler, curl, CPython 3.11-3.13 with its shared library and pip, and rustup by hand." >&2
  exit 2
fi

log "system packages"
need=()
command -v cc >/dev/null 2>&1 || need+=(gcc libc6-dev)
# OpenH264 (the video decoder nesy-import builds from source) is C++.
command -v c++ >/dev/null 2>&1 || need+=(g++)
command -v curl >/dev/null 2>&1 || need+=(curl)
[ -e /etc/ssl/certs/ca-certificates.crt ] || need+=(ca-certificates)
command -v git >/dev/null 2>&1 || need+=(git)
if ! supported_python >/dev/null; then
  # Debian 12 and Ubuntu 22.04 name it python3.11; Debian 13 and Ubuntu 24.04 ship a
  # supported python3.
  if apt-cache show python3.11 >/dev/null 2>&1; then
    need+=(python3.11)
  else
    need+=(python3)
  fi
fi
[ ${#need[@]} -eq 0 ] || apt_install "${need[@]}"
python=$(supported_python) || {
  echo "nesy needs CPython 3.11, 3.12 or 3.13, and this system's packages offer none ($(/usr/bin/python3 --version 2>&1 || echo 'no python3'))." >&2
  exit 2
}
version=$("$python" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")')
libdir=$("$python" -c 'import sysconfig; print(sysconfig.get_config_var("LIBDIR"))')
need=()
[ -e "$libdir/libpython$version.so" ] || need+=("libpython$version-dev")
"$python" -m pip --version >/dev/null 2>&1 || need+=(python3-pip)
# Virtual environments (the Python package's wheel is tested in a fresh one).
"$python" -c 'import ensurepip' >/dev/null 2>&1 || need+=("python$version-venv")
[ ${#need[@]} -eq 0 ] || apt_install "${need[@]}"
echo "CPython $version ($python)"

log "toolchain"
if ! command -v cargo >/dev/null 2>&1; then
  if [ ! -f "$HOME/.cargo/env" ]; then
    # rustup-init straight from its release host (what https://sh.rustup.rs downloads too),
    # which machines limited to package registries and Rust's own hosts can still reach.
    # The file must be called rustup-init: rustup decides what to be from its own name.
    scratch=$(mktemp -d)
    curl -sSf --proto '=https' --tlsv1.2 -o "$scratch/rustup-init" \
      "https://static.rust-lang.org/rustup/dist/$(uname -m)-unknown-linux-gnu/rustup-init"
    chmod +x "$scratch/rustup-init"
    "$scratch/rustup-init" -y --profile minimal >/dev/null
    rm -rf "$scratch"
  fi
  # shellcheck disable=SC1091
  . "$HOME/.cargo/env"
  installed_rustup=1
fi
rustup component add rustfmt clippy >/dev/null 2>&1 || true
cargo --version

log "python packages"
if ! "$python" -c 'import mcap' >/dev/null 2>&1; then
  "$python" -m pip install --quiet --break-system-packages mcap 2>/dev/null \
    || "$python" -m pip install --quiet mcap \
    || echo "warning: could not install the PyPI mcap package; the MCAP cross-reader test will say so"
fi

if [ -n "${installed_rustup:-}" ]; then
  printf '\nRust was installed under ~/.cargo. Before running cargo in this shell:\n    . "$HOME/.cargo/env"\n(new login shells pick it up by themselves).\n'
fi
