#!/usr/bin/env bash
# Re-writes the golden snapshots (golden/*.snap) from the current code. Legitimate only when the
# physics or the output was changed on purpose; the commit must say which files and why.
set -euo pipefail
cd "$(dirname "$0")/.."
INSTA_UPDATE=always INSTA_FORCE_PASS=1 cargo test --release --test golden
git status --short golden/
