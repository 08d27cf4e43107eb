#!/usr/bin/env bash
# The README's steps on a fresh minimal Debian root file system: builds the root with
# debootstrap (minbase variant, APT's Recommends turned off), then inside it, as a newcomer
# would: installs git, clones this repository, runs `scripts/quickstart.sh`, sources
# ~/.cargo/env as the installer says, and runs `cargo test --workspace`. Nothing from the
# host is used but the committed repository (cloned over a read-only bind mount), the host's
# local CA certificates, and the network to the package registries and Rust's release host.
#
#   scripts/fresh-root-test.sh bookworm /work/roots/bookworm   # Debian 12
#   scripts/fresh-root-test.sh trixie   /work/roots/trixie     # Debian 13
#   DEBIAN_MIRROR=http://archive.ubuntu.com/ubuntu \
#   DEBOOTSTRAP_ARGS="--no-check-gpg --components=main,universe" \
#     scripts/fresh-root-test.sh noble /work/roots/noble        # Ubuntu 24.04
#
# (A Debian host's debootstrap may lack a script for a newer Ubuntu release: `ln -s gutsy
# /usr/share/debootstrap/scripts/noble` adds it; without Ubuntu's keyring, --no-check-gpg.)
#
# Needs root and debootstrap. The log of each step goes to ROOT.log; the last line says
# PASSED or FAILED with the step. A root that already exists is reused as it is.
set -euo pipefail
suite=${1:?usage: fresh-root-test.sh SUITE ROOT}
root=${2:?usage: fresh-root-test.sh SUITE ROOT}
repo=$(cd "$(dirname "$0")/.." && pwd)
mirror=${DEBIAN_MIRROR:-http://deb.debian.org/debian}
log="$root.log"

say() { printf '[fresh-root %s] %s\n' "$suite" "$*" | tee -a "$log"; }
[ "$(id -u)" -eq 0 ] || { echo "fresh-root-test.sh needs root (debootstrap, chroot, mounts)" >&2; exit 2; }
command -v debootstrap >/dev/null || { echo "fresh-root-test.sh needs debootstrap (apt-get install debootstrap)" >&2; exit 2; }

: >"$log"
if [ ! -e "$root/etc/os-release" ]; then
  say "debootstrap --variant=minbase $suite"
  # shellcheck disable=SC2086
  debootstrap --variant=minbase ${DEBOOTSTRAP_ARGS:-} "$suite" "$root" "$mirror" >>"$log" 2>&1
fi
printf 'APT::Install-Recommends "false";\nAPT::Install-Suggests "false";\n' \
  >"$root/etc/apt/apt.conf.d/99no-recommends"
cp /etc/resolv.conf "$root/etc/resolv.conf"
# A network that intercepts TLS (a sandbox's egress proxy) signs with a local CA the host
# trusts; the root trusts it too once the installer's ca-certificates picks these up.
mkdir -p "$root/usr/local/share/ca-certificates"
cp /usr/local/share/ca-certificates/*.crt "$root/usr/local/share/ca-certificates/" 2>/dev/null || true
# (A reused root may have ca-certificates already: refresh its bundle.)
if [ -x "$root/usr/sbin/update-ca-certificates" ]; then chroot "$root" update-ca-certificates >/dev/null 2>&1 || true; fi

mounted=()
mount_in() { mkdir -p "$root$2"; mount "${@:3}" "$1" "$root$2"; mounted=("$root$2" "${mounted[@]}"); }
cleanup() { for m in "${mounted[@]}"; do umount -l "$m" 2>/dev/null || true; done; }
trap cleanup EXIT
mount_in proc /proc -t proc
mount_in /sys /sys --rbind
mount_in /dev /dev --rbind
mount_in "$repo" /src --bind -o ro
mount -o remount,ro,bind "$root/src"

# Everything below runs inside the root, as root, from a login shell's environment.
step() {
  local name=$1
  shift
  say "$name"
  local started=$SECONDS
  if chroot "$root" /usr/bin/env -i HOME=/root TERM=dumb PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    bash -lc "$*" >>"$log" 2>&1; then
    say "$name: ok in $((SECONDS - started)) s"
  else
    say "FAILED at: $name (see $log)"
    exit 1
  fi
}
say "$(. "$root/etc/os-release" && echo "$PRETTY_NAME") ($(uname -m)); Recommends off"
step "apt-get install git" "apt-get update -qq && apt-get install -y -qq git"
step "git clone" "rm -rf /root/nesy && git clone -q /src /root/nesy"
step "scripts/quickstart.sh" "set -o pipefail; cd /root/nesy && scripts/quickstart.sh | tee /root/quickstart.out && grep -q 'nesy adapt: SUCCEEDED' /root/quickstart.out"
step "cargo test --workspace" '. "$HOME/.cargo/env" && cd /root/nesy && cargo test --workspace'
say "CPython: $(chroot "$root" bash -c 'cd /root/nesy && scripts/system-python --version')"
say "PASSED"
