# The static binary's build environment, sourced (from the repository root) by
# scripts/build-static.sh and `scripts/build-wheel.sh --static`: checks the Debian inputs,
# writes the stdlib zip and pyo3's configuration under $NESY_STATIC_TARGET_DIR/inputs, and
# exports what cargo needs. Sets target_dir, STATIC_TARGET and STATIC_FEATURES.

config_dir=/usr/lib/python3.11/config-3.11-x86_64-linux-gnu
for need in /usr/bin/python3.11 "$config_dir/libpython3.11-pic.a" /usr/lib/x86_64-linux-gnu/libexpat.a \
  /usr/lib/x86_64-linux-gnu/libz.a /usr/lib/x86_64-linux-gnu/libc.a; do
  [ -e "$need" ] || { echo "missing $need (apt-get install python3.11 libpython3.11-dev libexpat1-dev zlib1g-dev libc6-dev)" >&2; exit 2; }
done

target_dir=${NESY_STATIC_TARGET_DIR:-$PWD/target/static}
work=$target_dir/inputs
mkdir -p "$work"

# 1. The stdlib zip, compiled by the same CPython minor version that is linked. The module set
#    is derived from the runtime's own Python; scripts/static/check_stdlib_zip.py (run by
#    `cargo test -p nesy-policy`) checks that the runtime works from the zip alone.
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

# 3. The build's environment. An explicit --target (STATIC_TARGET) keeps RUSTFLAGS away from
#    build scripts and proc macros.
export PYO3_CONFIG_FILE="$work/pyo3-static.cfg"
export NESY_STDLIB_ZIP="$work/stdlib.zip"
export RUSTFLAGS="-C target-feature=+crt-static"
export CARGO_PROFILE_RELEASE_LTO=false
export CARGO_PROFILE_RELEASE_DEBUG=false
export CARGO_TARGET_DIR="$target_dir"
STATIC_TARGET=x86_64-unknown-linux-gnu
STATIC_FEATURES=nesy-policy/embedded-stdlib
