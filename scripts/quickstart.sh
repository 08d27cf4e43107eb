#!/usr/bin/env bash
# The README's first command: installs what is missing on a fresh machine, builds nesy, and
# runs the main job on the bundled fixtures, offline.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-prereqs.sh
[ -f "$HOME/.cargo/env" ] && . "$HOME/.cargo/env"

printf '\n==> nesy verify: the symbolic executor on a bundled PDDL example\n'
cargo run --quiet -p nesy-cli -- verify \
  --domain fixtures/pddl/blocksworld/domain.pddl \
  --problem fixtures/pddl/blocksworld/sussman.pddl \
  --plan fixtures/pddl/blocksworld/sussman.valid.plan
