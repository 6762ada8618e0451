#!/usr/bin/env bash
# Count the instructions (valgrind --tool=callgrind, PROGRAM TOTALS) of every command the speed
# targets of issues 29 and 33 name, two at a time, into OUT/totals.txt (one "name count" line
# each; the callgrind files and outputs beside it):
#
#   scripts/measure-targets.sh OUT [DRUMROLL [APPROACH_BENCH]]
#
# DRUMROLL defaults to target/release/drumroll (built first), APPROACH_BENCH to the binary of
# `cargo bench -p afm --bench approach --no-run` (built first), run over its window 9 -> 8 nm on one thread.
# Counts are repeatable for one binary; the same source built at another path can count up to
# 1% apart (docs/guide/performance.md), so compare builds made in one checkout.
set -euo pipefail
out=${1:?usage: scripts/measure-targets.sh OUT [DRUMROLL [APPROACH_BENCH]]}
cd "$(dirname "$0")/.."
drumroll=${2:-}
bench=${3:-}
if [ -z "$drumroll" ]; then
    cargo build --release --quiet -p drumroll
    drumroll=target/release/drumroll
fi
if [ -z "$bench" ]; then
    bench=$(cargo bench -p afm --bench approach --no-run --message-format=json 2>/dev/null \
        | sed -n 's/.*"executable":"\([^"]*approach[^"]*\)".*/\1/p' | tail -1)
fi
mkdir -p "$out"
rm -f "$out/totals.txt"
count() {
    local name=$1
    shift
    valgrind --tool=callgrind --callgrind-out-file="$out/$name.cg" "$@" \
        > "$out/$name.out" 2> "$out/$name.err"
    grep -o "Collected : [0-9]*" "$out/$name.err" | awk -v n="$name" '{print n, $3}' \
        >> "$out/totals.txt"
}
two_at_a_time() {
    while [ "$(jobs -r | wc -l)" -ge 2 ]; do sleep 1; done
}
count version "$drumroll" --version
for case in biolever-mica biolever-soft maclever-mica maclever-soft biolever-adhesive \
    biolever-sticky biolever-soft-viscoelastic biolever-mica-acoustic biolever-mica-bimodal \
    biolever-mica-hydration rectangular-air-mica-humid; do
    count "$case" "$drumroll" continue --case "$case" --json &
    two_at_a_time
done
for z in 9.279985 8.518336 2.733157; do
    count "simulate-$z" "$drumroll" simulate --case biolever-mica --z "$z" --json &
    two_at_a_time
done
count bench-window "$bench" --from 9 --to 8 --one-thread &
wait
sort "$out/totals.txt"
