#!/usr/bin/env bash
# Run every cargo-fuzz target for SECONDS each (default 60), one after the other, on the
# committed corpora (fuzz/corpus/TARGET; new inputs found are added there). Needs a nightly
# toolchain and cargo-fuzz (`cargo install cargo-fuzz`). Exits non-zero on the first crash;
# the crashing input is left in fuzz/artifacts/TARGET/ and the log in fuzz/artifacts/TARGET.log.
# With FUZZ_SCRATCH=1 (CI) new inputs go to a temporary directory and the corpora stay as
# committed. With FUZZ_BUILT=1 the targets are taken as built (`cargo +nightly fuzz build -O`).
set -euo pipefail
cd "$(dirname "$0")/../fuzz"
seconds=${1:-60}
targets=${TARGETS:-"text_reader json_points json_curve fair_methods"}
[ -n "${FUZZ_BUILT:-}" ] || cargo +nightly fuzz build -O
mkdir -p artifacts
for t in $targets; do
  mkdir -p "corpus/$t"
  echo "== fuzz $t for ${seconds}s"
  status=0
  dirs=("corpus/$t")
  if [ -n "${FUZZ_SCRATCH:-}" ]; then dirs=("$(mktemp -d)" "corpus/$t"); fi
  cargo +nightly fuzz run -O "$t" "${dirs[@]}" -- -max_total_time="$seconds" -max_len=4096 \
    -timeout=20 -rss_limit_mb=2048 -print_final_stats=1 >"artifacts/$t.log" 2>&1 || status=$?
  grep -E "^(stat::number_of_executed_units|stat::new_units_added|SUMMARY)|panicked" \
    "artifacts/$t.log" || true
  if [ "$status" -ne 0 ]; then
    tail -40 "artifacts/$t.log"
    exit "$status"
  fi
done
