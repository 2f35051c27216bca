#!/usr/bin/env bash
# The whole test suite, as CI runs it (.ci/run calls exactly this). Works on a fresh machine:
# the Rust toolchain is the machine's; everything else it needs it installs.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== system packages"
# The peers of the cross-runs and timings (Debian lammps, liggghts, with OpenMPI's mpirun) and
# the font the profile plots label their axes with (fonts-dejavu-core).
if ! command -v lmp >/dev/null || ! command -v liggghts >/dev/null || ! command -v mpirun >/dev/null \
   || [ ! -f /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf ]; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq lammps liggghts openmpi-bin fonts-dejavu-core >/dev/null
fi

echo "== formatting and lints"
cargo fmt --check
cargo clippy --release --all-targets -- -D warnings

echo "== tests (release build: the solver runs in them)"
cargo test --release --all-targets 2>&1 | tee /tmp/verdem-test.log
