#!/usr/bin/env bash
# Regenerate the README's gallery in docs/gallery/ from the current code:
#
#   scripts/gallery.sh            # builds the release binary, then draws every figure
#
# fig1: the paper's Fig. 1 layout, u(t) and F_ts(t) over two periods of the Biolever on mica at
#       A/A0 = 0.5 (three impacts per period);
# fig2: the paper's Fig. 2 layout, phase vs A/A0 for its four cases, (a)-(d);
# fig2-overlay: the four cases on shared axes with their retract branches;
# approach: a time-domain approach and retract of the Biolever on mica at 4 nm/s;
# map: the regime map of the Biolever on mica over the free amplitude A0 = 5..20 nm (G1-G3
#      in the (A0, Z) and (A0, A/A0) planes, regions named by impacts per period);
# contrast, contrast-viscoelastic: phase, dissipated energy and the second harmonic against
#      A/A0 (`--panels`) on mica (conservative: E_ts = 0) and on the viscoelastic soft sample;
# jkr: approach and retract on the sticky JKR sample with the pull-off grazings.
# Uses DRUMROLL=/path/to/drumroll when set instead of building. Each figure is SVG (the
# README shows these); change the extension to .png or .pdf for the other formats.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -z "${DRUMROLL:-}" ]; then
    cargo build --release --quiet -p drumroll
    DRUMROLL=${CARGO_TARGET_DIR:-target}/release/drumroll
fi
out=docs/gallery
mkdir -p "$out"
"$DRUMROLL" --quiet simulate --case biolever-mica --amplitude-ratio 0.5 --plot "$out/fig1.svg" > /dev/null
"$DRUMROLL" --quiet continue --case biolever-mica --case biolever-soft --case maclever-mica \
    --case maclever-soft --plot "$out/fig2.svg" > /dev/null
"$DRUMROLL" --quiet continue --case biolever-mica --case biolever-soft --case maclever-mica \
    --case maclever-soft --retract --overlay --plot "$out/fig2-overlay.svg" > /dev/null
"$DRUMROLL" --quiet approach --case biolever-mica --from 10.2 --to 0 --rate 4 --retract \
    --plot "$out/approach.svg" > /dev/null
"$DRUMROLL" --quiet map --case biolever-mica --vary a0 --from 5 --to 20 --plot "$out/map.svg" > /dev/null
"$DRUMROLL" --quiet scan --feedback pi --scan-rate 2000 --pixels 128 --direction both \
    --plot "$out/scan.svg" > /dev/null
"$DRUMROLL" --quiet continue --case biolever-mica --panels phase,dissipated,harmonic-2 \
    --plot "$out/contrast.svg" > /dev/null
"$DRUMROLL" --quiet continue --case biolever-soft-viscoelastic --panels phase,dissipated,harmonic-2 \
    --plot "$out/contrast-viscoelastic.svg" > /dev/null
"$DRUMROLL" --quiet continue --case biolever-sticky --retract --plot "$out/jkr.svg" > /dev/null
ls -l "$out"
