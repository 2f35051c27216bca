#!/usr/bin/env bash
# The whole test suite, as CI runs it (.ci/run calls exactly this). Works on a fresh machine:
# the Rust toolchain is the machine's; everything else it needs it installs.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== system packages"
# The profile plots label their axes with DejaVu Sans (Debian fonts-dejavu-core).
if [ ! -f /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf ]; then
  apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq fonts-dejavu-core
fi

echo "== formatting and lints"
cargo fmt --check
cargo clippy --release --all-targets -- -D warnings

echo "== tests (release build: the solver runs in them)"
cargo test --release --all-targets 2>&1 | tee /tmp/verdem-test.log
