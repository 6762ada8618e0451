#!/usr/bin/env bash
# Build the explorer page into web/dist/: the drumroll-web crate (crates/web) compiled to
# WebAssembly, its JavaScript glue made by wasm-bindgen, and the static files of web/.
#
#   bash scripts/build-web.sh          # then: python3 -m http.server -d web/dist
#
# Installs what it needs, once: the Rust target wasm32-unknown-unknown (rustup), and
# wasm-bindgen-cli at exactly the version of the wasm-bindgen crate in Cargo.lock (cargo install
# --locked; the two must match). When Debian's binaryen can be installed (as root, with
# apt-get) its wasm-opt shrinks the module (-O3); without it the module is used as built.
# Prints the .wasm's size. Uses CARGO_TARGET_DIR when set.
set -euo pipefail

repo=$(cd "$(dirname "$0")/.." && pwd)
cd "$repo"
target_dir=${CARGO_TARGET_DIR:-$repo/target}
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

# wasm-opt from Debian's binaryen, when it can be had cheaply (root and apt-get).
if ! command -v wasm-opt >/dev/null && [ "$(id -u)" -eq 0 ] && command -v apt-get >/dev/null; then
    DEBIAN_FRONTEND=noninteractive apt-get install -y binaryen >/dev/null 2>&1 \
        || { apt-get update >/dev/null && DEBIAN_FRONTEND=noninteractive apt-get install -y binaryen >/dev/null; } \
        || echo "build-web.sh: binaryen not installed; the module stays unoptimised by wasm-opt" >&2
fi

# The module: the workspace's `web` profile (release without debug information, fat LTO).
cargo build --profile web --target wasm32-unknown-unknown -p drumroll-web
built="$target_dir/wasm32-unknown-unknown/web/drumroll_web.wasm"

rm -rf "$dist"
mkdir -p "$dist/pkg"
wasm-bindgen --target web --no-typescript --out-dir "$dist/pkg" "$built"
wasm="$dist/pkg/drumroll_web_bg.wasm"
if command -v wasm-opt >/dev/null; then
    # Rust's wasm32 target emits these post-MVP features by default.
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
