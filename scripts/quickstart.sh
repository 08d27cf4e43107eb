#!/usr/bin/env bash
# The README's first command: installs what is missing on a fresh machine, builds nesy, and
# runs the main job on bundled fixtures, offline: `nesy adapt` on a recorded demo and a
# counterfactual target scene, replaying the VLM's answers from a cassette, then executing the
# adapted code policy in the sandboxed simulator.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-prereqs.sh
[ -f "$HOME/.cargo/env" ] && . "$HOME/.cargo/env"

printf '\n==> build (the first build takes about six minutes on two cores)\n'
cargo build -p nesy-cli

printf '\n==> nesy adapt on fixtures/demos/adapt-realstyle (replayed VLM, executed)\n'
cargo run --quiet -p nesy-cli -- adapt \
  --demo fixtures/demos/adapt-realstyle \
  --target fixtures/demos/adapt-realstyle/target.json \
  --vlm replay:fixtures/cassettes/adapt-realstyle.json \
  --execute --out runs/quickstart
printf '\nThe run directory runs/quickstart/ holds report.md, policy.py, adaptation.json and more.\n'
