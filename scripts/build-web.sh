#!/usr/bin/env bash
# Builds the browser playground into web/dist/: the library compiled to WebAssembly
# (crates/pdyn-web), its JS glue (wasm-bindgen), and the static site (Vite).
#
#   scripts/build-web.sh            # install what is missing (as root: apt), then build
#   SKIP_INSTALL=1 scripts/build-web.sh
#
# What it needs, all from Debian's and the registries' packages (nothing else is downloaded):
# - Debian's rustc-web, cargo-web and rust-web-src (Rust 1.96 with the standard library's
#   sources): the standard library is built for wasm32-unknown-unknown with -Z build-std
#   (RUSTC_BOOTSTRAP=1), linked by rust-lld (lld-22);
# - wasm-bindgen-cli from crates.io, the same version as the wasm-bindgen crate of
#   crates/pdyn-web/Cargo.toml (installed with cargo install when missing);
# - Node.js and npm (front-end packages from the npm registry, pinned in web/package-lock.json);
# - for the browser tests (web/tests, scripts/test-web.sh): Debian's chromium.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

WASM_BINDGEN_VERSION=$(sed -n 's/^wasm-bindgen = "=\(.*\)"/\1/p' crates/pdyn-web/Cargo.toml)
if [ -z "$WASM_BINDGEN_VERSION" ]; then
    echo "error: crates/pdyn-web/Cargo.toml must pin wasm-bindgen as \"=X.Y.Z\"" >&2
    exit 2
fi

if [ -z "${SKIP_INSTALL:-}" ]; then
    missing=()
    [ -x /usr/bin/rustc ] && /usr/bin/rustc --version | grep -q '^rustc 1\.9[6-9]' || missing+=(rustc-web)
    [ -x /usr/bin/cargo ] || missing+=(cargo-web)
    [ -d /usr/lib/rustlib/src/rust/library ] || missing+=(rust-web-src)
    [ -x /usr/bin/rust-lld ] && /usr/bin/rust-lld -flavor wasm --version >/dev/null 2>&1 || missing+=(lld-22)
    [ -x /usr/bin/chromium ] || missing+=(chromium)
    command -v npm >/dev/null || missing+=(npm)
    if [ ${#missing[@]} -gt 0 ]; then
        if [ "$(id -u)" -ne 0 ]; then
            echo "error: missing Debian packages: ${missing[*]} (sudo apt-get install ${missing[*]})" >&2
            exit 2
        fi
        echo "installing ${missing[*]} (apt)" >&2
        apt-get update -qq
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq rustc-web cargo-web rust-web-src lld-22 chromium >/dev/null
        command -v npm >/dev/null || DEBIAN_FRONTEND=noninteractive apt-get install -y -qq npm >/dev/null
    fi
fi

# wasm-bindgen-cli at the crate's version: on PATH, else in cargo's bin directory, else
# installed there from crates.io (once per machine: a few minutes).
bindgen=""
for candidate in "$(command -v wasm-bindgen || true)" "${CARGO_HOME:-$HOME/.cargo}/bin/wasm-bindgen"; do
    if [ -n "$candidate" ] && [ -x "$candidate" ] && "$candidate" --version | grep -q " $WASM_BINDGEN_VERSION\$"; then
        bindgen="$candidate"
        break
    fi
done
if [ -z "$bindgen" ]; then
    echo "installing wasm-bindgen-cli $WASM_BINDGEN_VERSION (cargo install)" >&2
    cargo install --quiet --root "${CARGO_HOME:-$HOME/.cargo}" wasm-bindgen-cli --version "$WASM_BINDGEN_VERSION"
    bindgen="${CARGO_HOME:-$HOME/.cargo}/bin/wasm-bindgen"
fi

# The library for the browser: Debian's Rust 1.96 builds std for the target from its sources.
# Its own target directory, so the native build's is untouched.
echo "building crates/pdyn-web for wasm32-unknown-unknown" >&2
RUSTC=/usr/bin/rustc RUSTC_BOOTSTRAP=1 CARGO_TARGET_DIR="$root/target/wasm" \
    /usr/bin/cargo build --quiet --release -p pdyn-web --target wasm32-unknown-unknown \
    -Z build-std=std,panic_abort
"$bindgen" --target web --out-dir web/src/wasm --out-name pdyn_web \
    target/wasm/wasm32-unknown-unknown/release/pdyn_web.wasm

cd web
if [ ! -d node_modules ] || [ package-lock.json -nt node_modules/.package-lock.json ]; then
    npm ci --no-audit --no-fund --loglevel=error
fi
npx vite build --logLevel warn
echo "web/dist/ built:" >&2
ls -la dist dist/assets | sed 's/^/  /' >&2
