#!/usr/bin/env bash
# Builds a self-contained `nesy` binary: libpython 3.11 linked statically (Debian's
# libpython3.11-pic.a), glibc linked statically (static-pie via +crt-static), and the
# standard-library modules the policy runtime needs embedded as a STORED zip that the
# binary serves from a memfd at start-up. The result runs on x86-64 Linux machines without
# Python and without any shared library (it needs /proc mounted: the embedded stdlib is read
# through /proc/self/fd/N and the worker re-executes /proc/self/exe).
#
# usage: scripts/build-static.sh [--test]
#   --test   also run `nesy run` on a fixture policy and scene inside an empty chroot that
#            holds only the binary, the two input files and a /proc mount (needs root).
#
# Environment:
#   NESY_STATIC_TARGET_DIR  cargo target dir for the static build (default: target/static).
#   NESY_STATIC_OUT         where the binary is copied (default: $NESY_STATIC_TARGET_DIR/nesy-static).
#
# Needs Debian packages: python3.11, libpython3.11-dev, libexpat1-dev, zlib1g-dev, libc6-dev.
# Normal `cargo build`/`cargo test` are unaffected: they link the system libpython3.11.so.
set -euo pipefail
cd "$(dirname "$0")/.."

run_test=false
[ "${1:-}" = "--test" ] && run_test=true

config_dir=/usr/lib/python3.11/config-3.11-x86_64-linux-gnu
for need in /usr/bin/python3.11 "$config_dir/libpython3.11-pic.a" /usr/lib/x86_64-linux-gnu/libexpat.a \
  /usr/lib/x86_64-linux-gnu/libz.a /usr/lib/x86_64-linux-gnu/libc.a; do
  [ -e "$need" ] || { echo "missing $need (apt-get install python3.11 libpython3.11-dev libexpat1-dev zlib1g-dev libc6-dev)" >&2; exit 2; }
done

target_dir=${NESY_STATIC_TARGET_DIR:-$PWD/target/static}
out=${NESY_STATIC_OUT:-$target_dir/nesy-static}
work=$target_dir/inputs
mkdir -p "$work"

# 1. The stdlib zip, compiled by the same CPython minor version that is linked.
/usr/bin/python3.11 -I -S scripts/static/stdlib_zip.py "$work/stdlib.zip"

# 2. pyo3 links the static, position-independent libpython and its C dependencies.
cat > "$work/pyo3-static.cfg" <<CFG
implementation=CPython
version=3.11
shared=false
abi3=false
lib_name=python3.11-pic
lib_dir=$config_dir
executable=/usr/bin/python3.11
pointer_width=64
build_flags=
suppress_build_script_link_lines=false
extra_build_script_line=cargo:rustc-link-search=native=/usr/lib/x86_64-linux-gnu
extra_build_script_line=cargo:rustc-link-lib=static=expat
extra_build_script_line=cargo:rustc-link-lib=static=z
extra_build_script_line=cargo:rustc-link-lib=m
extra_build_script_line=cargo:rustc-link-lib=util
extra_build_script_line=cargo:rustc-link-lib=dl
extra_build_script_line=cargo:rustc-link-lib=pthread
CFG

# 3. Build. An explicit --target keeps RUSTFLAGS away from build scripts and proc macros.
PYO3_CONFIG_FILE="$work/pyo3-static.cfg" \
NESY_STDLIB_ZIP="$work/stdlib.zip" \
RUSTFLAGS="-C target-feature=+crt-static" \
CARGO_PROFILE_RELEASE_LTO=false \
CARGO_PROFILE_RELEASE_DEBUG=false \
CARGO_TARGET_DIR="$target_dir" \
  cargo build --release --target x86_64-unknown-linux-gnu -p nesy-cli --features nesy-policy/embedded-stdlib

cp "$target_dir/x86_64-unknown-linux-gnu/release/nesy" "$out"
strip "$out" 2>/dev/null || true
echo "== $out"
file "$out"
ldd "$out" 2>&1 || true
ls -l "$out"

# 4. Optional: run it where there is no Python and no shared library at all.
if $run_test; then
  root=$(mktemp -d)
  trap 'umount "$root/proc" 2>/dev/null || true; rm -rf "$root"' EXIT
  mkdir -p "$root/proc" "$root/dev"
  cp "$out" "$root/nesy"
  cp crates/nesy-policy/policies/pick_place.py "$root/policy.py"
  cp fixtures/scenes/pick_place_finger.json "$root/scene.json"
  mount -t proc proc "$root/proc"
  echo "== chroot contents: $(cd "$root" && find . -path ./proc -prune -o -type f -print | tr '\n' ' ')"
  chroot "$root" /nesy run --policy /policy.py --scene /scene.json
  chroot "$root" /nesy run --policy /policy.py --scene /scene.json --json > "$root/result.json"
  grep -q '"kind": "ok"' "$root/result.json" && echo "== chroot run: ok"
fi
