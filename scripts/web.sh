#!/usr/bin/env bash
# Builds the web demo (WebGPU) and serves it on http://127.0.0.1:8080/.
#
#   bash scripts/web.sh                 build, then serve until Ctrl-C
#   bash scripts/web.sh --build-only    build into target/web and stop
#   bash scripts/web.sh --port 9000     serve on another port
#
# Installs what it needs and is missing: the wasm32-unknown-unknown target and wasm-bindgen-cli
# at the version of the wasm-bindgen crate in Cargo.lock (the two must be equal). The page's
# URL parameters and its scripting contract are in docs/guide.md ("In a browser").
set -euo pipefail
cd "$(dirname "$0")/.."

port=8080
serve=true
while [ $# -gt 0 ]; do
    case "$1" in
        --build-only) serve=false ;;
        --port) port="${2:?--port needs a number}"; shift ;;
        *) echo "web.sh: unknown argument $1 (expected --build-only or --port N)" >&2; exit 2 ;;
    esac
    shift
done

if ! rustup target list --installed | grep -qx wasm32-unknown-unknown; then
    echo "web.sh: installing the wasm32-unknown-unknown target" >&2
    rustup target add wasm32-unknown-unknown
fi
version=$(sed -n '/^name = "wasm-bindgen"$/{n;s/^version = "\(.*\)"$/\1/p;}' Cargo.lock)
[ -n "$version" ] || { echo "web.sh: Cargo.lock names no wasm-bindgen version" >&2; exit 1; }
if ! wasm-bindgen --version 2>/dev/null | grep -qx "wasm-bindgen $version"; then
    echo "web.sh: installing wasm-bindgen-cli $version (a few minutes, once)" >&2
    # Not --locked: its lock file pins a dependency version the registry no longer serves.
    cargo install wasm-bindgen-cli --version "$version"
fi

out=target/web
cargo build -p manylight_web --lib --target wasm32-unknown-unknown --release
wasm-bindgen --target web --no-typescript --out-dir "$out/pkg" \
    target/wasm32-unknown-unknown/release/manylight_web.wasm
cp crates/manylight_web/web/index.html "$out/index.html"
# The page fetches glTF files (`?scene=PATH`) from assets/ beside it.
ln -sfn ../../assets "$out/assets"
echo "web.sh: built $out" >&2

if $serve; then
    echo "web.sh: serving http://127.0.0.1:$port/ (Ctrl-C stops; parameters: ?lights=N&pipeline=NAME&...)" >&2
    exec python3 -m http.server --bind 127.0.0.1 --directory "$out" "$port"
fi
