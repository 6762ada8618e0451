#!/usr/bin/env bash
# Record drumroll's outputs on the built-in cases into DIR, so that two builds can be compared
# byte for byte (a refactoring must not change them):
#
#   scripts/output-snapshot.sh /tmp/before          # at the old commit
#   scripts/output-snapshot.sh /tmp/after           # at the new one
#   diff -r /tmp/before /tmp/after && echo identical
#
# Builds the release binary first (or uses DRUMROLL=/path/to/drumroll). Records: `continue
# --json` (with --retract) for every built-in case, `simulate --json` at separations in each
# impact regime of the four paper cases, at a period-4 orbit and inside the MAClever-on-mica
# bistable window (a coexisting orbit), `approach` CSV over G2 of the
# Biolever on mica, and `theory --json` at the paper's A/A0 = 0.95.
set -euo pipefail
out=${1:?usage: scripts/output-snapshot.sh DIR}
cd "$(dirname "$0")/.."
if [ -z "${DRUMROLL:-}" ]; then
    cargo build --release --quiet -p drumroll
    DRUMROLL=target/release/drumroll
fi
mkdir -p "$out"
cases=$(ls fixtures/cases | sed 's/\.json$//')
for case in $cases; do
    "$DRUMROLL" continue --case "$case" --retract --json > "$out/continue-$case.json"
done
for case in biolever-mica biolever-soft maclever-mica maclever-soft; do
    for ratio in 0.95 0.9 0.5; do
        "$DRUMROLL" simulate --case "$case" --amplitude-ratio "$ratio" --json \
            > "$out/simulate-$case-ratio-$ratio.json"
    done
done
for z in 12 8.5 5 2.7; do
    "$DRUMROLL" simulate --case biolever-mica --z "$z" --json > "$out/simulate-biolever-mica-z-$z.json"
done
"$DRUMROLL" simulate --case maclever-mica --z 19.997 --json > "$out/simulate-maclever-mica-bistable.json"
"$DRUMROLL" simulate --case biolever-mica --drive-frequency 72 --z 0.5 --json \
    > "$out/simulate-biolever-mica-72khz-z-0.5.json"
"$DRUMROLL" approach --case biolever-mica --from 8.8 --to 8.65 --rate 1 --every 10 \
    > "$out/approach-biolever-mica.csv"
"$DRUMROLL" theory --case biolever-mica --json > "$out/theory-biolever-mica.json"
echo "recorded $(ls "$out" | wc -l) outputs in $out"
