#!/usr/bin/env bash
# The whole test suite, as CI runs it (.ci/run calls exactly this). Works on a fresh machine:
# the Rust toolchain is the machine's; everything else it needs it installs.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== formatting and lints"
cargo fmt --check
cargo clippy --release --all-targets -- -D warnings

echo "== tests (release build: the solver runs in them)"
cargo test --release --all-targets 2>&1 | tee /tmp/verdem-test.log
