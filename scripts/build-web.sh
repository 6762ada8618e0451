#!/usr/bin/env bash
# Build the explorer page into web/dist/: the drumroll-web crate (crates/web) compiled to
# WebAssembly, its JavaScript glue made by wasm-bindgen, and the static files of web/.
#
#   bash scripts/build-web.sh          # then: python3 -m http.server -d web/dist
#
# Installs what it needs, once: the Rust target wasm32-unknown-unknown (rustup), and
# wasm-bindgen-cli at exactly the version of the wasm-bindgen crate in Cargo.lock (cargo install
# --locked; the two must match). A wasm-opt of binaryen 116 or newer found on PATH shrinks the
# module further (-O3); none is installed: the module is under 3 MB without it, and Debian 12's
# binaryen (108) breaks the module's reference-typed table (the page fails to load). Prints the
# .wasm's size.
set -euo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
cd "$repo"
dist=web/dist

if ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
    rustup target add wasm32-unknown-unknown
fi

# The wasm-bindgen version the crate links (Cargo.lock), and the CLI at that version.
bindgen_version=$(awk '/^name = "wasm-bindgen"$/ {getline; gsub(/"/, "", $3); print $3; exit}' Cargo.lock)
if [ -z "$bindgen_version" ]; then
    echo "build-web.sh: no wasm-bindgen in Cargo.lock" >&2
    exit 1
fi
if [ "$(wasm-bindgen --version 2>/dev/null | awk '{print $2}')" != "$bindgen_version" ]; then
    # --locked builds the CLI with its own lock file; should a version pinned there have left
    # the registry's index (yanked), the newest compatible versions are taken instead.
    cargo install wasm-bindgen-cli --version "$bindgen_version" --locked \
        || cargo install wasm-bindgen-cli --version "$bindgen_version"
fi

# The module: the workspace's `web` profile (release without debug information, fat LTO).
# Where cargo wrote it, as cargo reports it (whatever the target directory).
built=$(cargo build --profile web --target wasm32-unknown-unknown -p drumroll-web \
    --message-format=json-render-diagnostics \
    | grep -o '"[^"]*/drumroll_web\.wasm"' | tail -n 1 | tr -d '"')
if [ ! -f "$built" ]; then
    echo "build-web.sh: cargo reported no drumroll_web.wasm" >&2
    exit 1
fi

rm -rf "$dist"
mkdir -p "$dist/pkg"
wasm-bindgen --target web --no-typescript --out-dir "$dist/pkg" "$built"
wasm="$dist/pkg/drumroll_web_bg.wasm"
binaryen_version=$(wasm-opt --version 2>/dev/null | awk '{print $3}' || true)
if [ -n "$binaryen_version" ] && [ "$binaryen_version" -ge 116 ] 2>/dev/null; then
    # Rust's wasm32 target and wasm-bindgen emit these post-MVP features.
    if wasm-opt -O3 --enable-bulk-memory --enable-nontrapping-float-to-int --enable-sign-ext \
        --enable-mutable-globals --enable-reference-types --enable-multivalue \
        "$wasm" -o "$wasm.opt"; then
        mv "$wasm.opt" "$wasm"
    else
        rm -f "$wasm.opt"
        echo "build-web.sh: wasm-opt failed; the module stays as wasm-bindgen wrote it" >&2
    fi
fi

# The page's static files (the tests stay out of dist).
cp web/index.html web/style.css "$dist/"
cp -r web/js "$dist/js"
size=$(stat -c %s "$wasm")
echo "build-web.sh: built $dist (module $wasm: $size bytes, $(awk "BEGIN {printf \"%.2f\", $size / 1048576}") MiB)"
