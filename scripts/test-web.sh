#!/usr/bin/env bash
# The browser playground's tests: builds web/dist (scripts/build-web.sh) and the pdyn binary
# the page is compared with, then runs web/tests in headless Chromium (node's test runner).
#
#   scripts/test-web.sh
#   SKIP_BUILD=1 scripts/test-web.sh     # web/dist and target/debug/pdyn already built
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -z "${SKIP_BUILD:-}" ]; then
    scripts/build-web.sh
    # The binary `cargo test --workspace` builds (see scripts/test-all.sh).
    cargo test --workspace --no-run --quiet
fi
cd web
PDYN_BIN="${PDYN_BIN:-$(pwd)/../target/debug/pdyn}" node --test --test-reporter=spec tests/
