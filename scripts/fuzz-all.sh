#!/usr/bin/env bash
# One cargo-fuzz run of every target in fuzz/, each for SECS seconds (default 60), seeded from
# the bundled fixtures and fuzz/seeds/. Prints one Markdown table row per target: the runs
# libFuzzer made, the corpus size at the end, and whether it stopped on a crash. Needs a
# nightly toolchain and `cargo install cargo-fuzz`.
#
#   scripts/fuzz-all.sh [SECS] [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
secs=${1:-60}
shift || true
targets=("$@")
set -- "${targets[@]}"
[ ${#targets[@]} -gt 0 ] || mapfile -t targets < <(sed -n 's/^name = "\(.*\)"$/\1/p' Cargo.toml | grep -v '^nesy-fuzz$')

seed() { # seed TARGET FILE...
  local dir="corpus/$1"
  shift
  mkdir -p "$dir"
  for f in "$@"; do
    if [ -f "$f" ]; then cp "$f" "$dir/"; fi
  done
}
seed scene ../fixtures/scenes/*.json
seed scenario_config ../fixtures/benchmark/*.json
seed demo_mcap ../fixtures/demos/adapt-realstyle/demo.mcap
seed cassette ../fixtures/cassettes/*.json
seed manifest seeds/manifest/*
seed unit_records seeds/unit_records/*
seed policy_source seeds/policy_source/*
seed vocabulary_file ../fixtures/vocabulary/*.toml
seed video_truth seeds/video_truth/*
seed pddl ../fixtures/pddl/*/*.pddl ../assets/pddl/*.pddl ../fixtures/planning/*.pddl
seed plan ../fixtures/pddl/*/*.plan

if [ $# -eq 0 ]; then
  cargo +nightly fuzz build --release >&2
else
  for t in "${targets[@]}"; do cargo +nightly fuzz build --release "$t" >&2; done
fi
echo "| target | seconds | runs | corpus files | result |"
echo "|---|---|---|---|---|"
for t in "${targets[@]}"; do
  mkdir -p "corpus/$t"
  # Large seeds (a demo's MCAP, a cassette) need a larger input bound than libFuzzer's 4 KB.
  max_len=65536
  case $t in demo_mcap | cassette) max_len=1048576 ;; esac
  log=$(mktemp)
  if cargo +nightly fuzz run --release "$t" -- -max_total_time="$secs" -max_len="$max_len" \
      -print_final_stats=1 >"$log" 2>&1; then
    result="no crash"
  else
    result="CRASH (see fuzz/artifacts/$t)"
  fi
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  if [ "$t" = demo_folder ]; then
    # The target keeps the real manifest beside the inputs; add it to the corpus for next time.
    cp /tmp/nesy-fuzz-demo-folder-*/manifest.orig.json "corpus/$t/real-manifest.json" 2>/dev/null || true
  fi
  echo "| \`$t\` | $secs | ${runs:-?} | $(find "corpus/$t" -type f | wc -l) | $result |"
  rm -f "$log"
done
