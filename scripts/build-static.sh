#!/usr/bin/env bash
# Builds a self-contained `nesy` binary: libpython 3.11 linked statically (Debian's
# libpython3.11-pic.a), glibc linked statically (static-pie via +crt-static), and the
# standard-library modules the policy runtime needs embedded as a STORED zip that the
# binary serves from a memfd at start-up. The result runs on x86-64 Linux machines without
# Python and without any shared library (it needs /proc mounted: the embedded stdlib is read
# through /proc/self/fd/N and the worker re-executes /proc/self/exe).
#
# usage: scripts/build-static.sh [--test]
#   --test   also run the binary inside an empty chroot that holds only the binary, the input
#            files of each command and a /proc mount (needs root): `nesy run` on a fixture
#            policy and scene; the quick-start job, `nesy adapt --execute` on the bundled demo
#            with the model's answers replayed from its cassette (and the images it references);
#            `nesy verify` on a blocksworld domain and problem with a valid and an invalid
#            plan; and `nesy demo import` of the authors'-format fixture and of the bundled
#            H.264 video (keyframes found automatically). Each check prints
#            `== chroot ...: ok`; the first that fails stops the script.
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

# shellcheck source=scripts/static/env.sh
. scripts/static/env.sh
out=${NESY_STATIC_OUT:-$target_dir/nesy-static}
cargo build --release --target "$STATIC_TARGET" -p nesy-cli --features "$STATIC_FEATURES"

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
  # nesy run: a worked example policy on its scene.
  cp crates/nesy-policy/policies/pick_place.py "$root/policy.py"
  cp fixtures/scenes/pick_place_finger.json "$root/scene.json"
  # nesy adapt: the demo, the target scene and the cassette under the same relative paths as
  # in the checkout (chroot starts in /), plus the images the cassette names, which are kept
  # as blobs/<sha256>.<ext> beside it.
  cassette=fixtures/cassettes/adapt-realstyle.json
  mkdir -p "$root/fixtures/demos" "$root/fixtures/cassettes/blobs"
  cp -r fixtures/demos/adapt-realstyle "$root/fixtures/demos/"
  cp "$cassette" "$root/$cassette"
  { grep -o 'blob:sha256:[0-9a-f]*\.[a-z]*' "$cassette" || true; } | sort -u | while read -r blob; do
    cp "fixtures/cassettes/blobs/${blob#blob:sha256:}" "$root/fixtures/cassettes/blobs/"
  done
  # nesy demo import: the authors'-format demo (JPEG frames decoded in the binary).
  cp -r fixtures/demos/authors-format fixtures/demos/video "$root/fixtures/demos/"
  # nesy verify: blocksworld's Sussman anomaly with a valid plan and one that fails at step 1.
  mkdir -p "$root/pddl"
  cp fixtures/pddl/blocksworld/domain.pddl fixtures/pddl/blocksworld/sussman.pddl \
    fixtures/pddl/blocksworld/sussman.valid.plan fixtures/pddl/blocksworld/sussman.unmet.plan "$root/pddl/"
  mount -t proc proc "$root/proc"
  echo "== chroot contents (files per top-level entry):" \
    "$(cd "$root" && find . -path ./proc -prune -o -type f -print | cut -d/ -f2 | sort | uniq -c |
      awk '{printf "%s (%d) ", $2, $1}')"

  # Runs `nesy ARGS...` in the chroot with its stdout and stderr in $root/NAME.out (shown
  # afterwards) and sets `status` to its exit status.
  in_chroot() {
    local name=$1
    shift
    status=0
    chroot "$root" /nesy "$@" > "$root/$name.out" 2>&1 || status=$?
    cat "$root/$name.out"
  }
  fail() {
    echo "== chroot $1: FAILED" >&2
    exit 1
  }

  in_chroot run run --policy /policy.py --scene /scene.json
  [ "$status" -eq 0 ] || fail "run (exit $status)"
  chroot "$root" /nesy run --policy /policy.py --scene /scene.json --json > "$root/result.json" ||
    fail "run --json (exit $?)"
  grep -q '"kind": "ok"' "$root/result.json" || fail "run --json (no \"kind\": \"ok\" outcome)"
  echo "== chroot run: ok"

  in_chroot adapt adapt --demo fixtures/demos/adapt-realstyle \
    --target fixtures/demos/adapt-realstyle/target.json \
    --vlm "replay:$cassette" --execute --out /run-adapt
  [ "$status" -eq 0 ] || fail "adapt --execute (exit $status)"
  grep -q '^nesy adapt: SUCCEEDED' "$root/adapt.out" || fail "adapt --execute (no SUCCEEDED)"
  echo "== chroot adapt --execute: ok"

  in_chroot import demo import fixtures/demos/authors-format/episode_0 --out /imported
  [ "$status" -eq 0 ] || fail "demo import (exit $status)"
  grep -qF 'imported 9 keyframe(s) of 9 frame(s), views top, front, back' "$root/import.out" ||
    fail "demo import (unexpected report)"
  [ -s "$root/imported/contact_sheet.png" ] || fail "demo import (no contact sheet)"
  in_chroot import-video demo import fixtures/demos/video/held-keyframes.mp4 --out /imported-video \
    --keyframes auto --instruction "Place all cylinder blocks in the prismatic drawer." \
    --objects red_cylinder,drawer_body
  [ "$status" -eq 0 ] || fail "demo import, video (exit $status)"
  grep -qF 'imported 9 keyframe(s) of 45 frame(s), views camera' "$root/import-video.out" ||
    fail "demo import, video (unexpected report)"
  echo "== chroot demo import: ok"

  in_chroot verify-valid verify --domain /pddl/domain.pddl --problem /pddl/sussman.pddl \
    --plan /pddl/sussman.valid.plan
  [ "$status" -eq 0 ] || fail "verify, valid plan (exit $status)"
  grep -qxF 'Plan valid: 6 step(s) executed, goal satisfied.' "$root/verify-valid.out" ||
    fail "verify, valid plan (unexpected verdict)"
  in_chroot verify-unmet verify --domain /pddl/domain.pddl --problem /pddl/sussman.pddl \
    --plan /pddl/sussman.unmet.plan
  [ "$status" -eq 1 ] || fail "verify, invalid plan (exit $status, expected 1)"
  grep -qF 'step 1 (pick-up a) (plan line 2)' "$root/verify-unmet.out" ||
    fail "verify, invalid plan (unexpected verdict)"
  echo "== chroot verify: ok"
fi
