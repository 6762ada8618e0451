#!/usr/bin/env bash
# Browser tests of the explorer page: installs Debian's chromium if it is missing (as root,
# with apt-get, as scripts/slurm/test-cluster.sh installs Slurm) and the node packages of
# package-lock.json (npm ci: puppeteer-core, which drives /usr/bin/chromium and downloads no
# browser), builds the native CLI the page is compared with, and runs the node tests against
# web/dist served on 127.0.0.1. Build the page first:
#
#   bash scripts/build-web.sh && bash web/tests/run.sh
#
# Prints the measured timings (time to first diagram, recomputation in the browser and
# natively). Screenshots go to web/tests/artifacts/ (ignored by git). Needs node >= 18.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)

if ! command -v chromium >/dev/null; then
    if [ "$(id -u)" -ne 0 ]; then
        echo "web/tests/run.sh: chromium is missing and installing it needs root (apt-get)" >&2
        exit 2
    fi
    apt-get update
    DEBIAN_FRONTEND=noninteractive apt-get install -y chromium
fi
if [ ! -f "$repo/web/dist/index.html" ]; then
    echo "web/tests/run.sh: web/dist is missing: run bash scripts/build-web.sh first" >&2
    exit 2
fi

# The reference: the native command line.
DRUMROLL=$(cd "$repo" && cargo build --release -p drumroll --message-format=json-render-diagnostics \
    | grep -o '"executable":"[^"]*/drumroll"' | tail -n 1 | sed 's/^"executable":"//; s/"$//')
if [ ! -x "$DRUMROLL" ]; then
    echo "web/tests/run.sh: cargo reported no drumroll binary" >&2
    exit 1
fi
export DRUMROLL
export CHROMIUM
CHROMIUM=$(command -v chromium)

cd "$here"
# puppeteer-core downloads no browser; the environment variable says so to older versions too.
PUPPETEER_SKIP_DOWNLOAD=1 npm ci --no-audit --no-fund
node --test --test-concurrency=1 browser.test.mjs
