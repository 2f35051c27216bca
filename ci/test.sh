#!/usr/bin/env bash
# The whole test suite, as CI runs it (.ci/run calls exactly this). Works on a fresh machine:
# the Rust toolchain is the machine's; everything else it needs it installs.
set -euo pipefail
cd "$(dirname "$0")/.."

echo "== system packages"
# The peers of the cross-runs and timings (Debian lammps, liggghts, with OpenMPI's mpirun, and
# yade), the font the plots label their axes with (fonts-dejavu-core), and ParaView's Python
# module (python3-paraview), whose reader opens a run's VTK files in tests/vtk.rs; the LAMMPS and
# LIGGGHTS libraries (liblammps0, libliggghts3) that tests/peer_motion.rs drives in process; the
# C++ compiler (g++) that tests/examples_ci.rs builds the example C++ contact-law wrapper with.
if ! command -v lmp >/dev/null || ! command -v liggghts >/dev/null || ! command -v mpirun >/dev/null \
   || ! ldconfig -p | grep "liblammps.so.0 " >/dev/null || ! ldconfig -p | grep "libliggghts.so.3 " >/dev/null \
   || ! command -v yade >/dev/null || ! command -v g++ >/dev/null \
   || [ ! -f /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf ] \
   || [ ! -f /usr/lib/python3/dist-packages/paraview/simple.py ]; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq lammps liggghts liblammps0 libliggghts3 openmpi-bin yade fonts-dejavu-core python3-paraview g++ >/dev/null
fi

echo "== Slurm (a one-node cluster on localhost for tests/ensemble.rs)"
# Debian's slurm-wlm and munge; ci/slurm_local.sh configures and starts munged, slurmctld and
# slurmd (quick when they already run). The Slurm tests run, and must pass, with VERDEM_SLURM=1.
if ! command -v sbatch >/dev/null || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi
bash ci/slurm_local.sh
export VERDEM_SLURM=1

echo "== Python packages (virtual environment target/venv)"
# Kratos DEM (a peer), meshio (an independent VTK reader) and junitparser (an independent JUnit
# reader of the --junit reports), pinned in ci/requirements.txt.
# The tests find this Python through VERDEM_PYTHON; verdem also finds it unset (docs/cli.md,
# "verdem peers").
stamp=target/venv/requirements.sha256
want=$(sha256sum ci/requirements.txt | cut -d' ' -f1)
if [ ! -x target/venv/bin/python ] || [ "$(cat "$stamp" 2>/dev/null)" != "$want" ]; then
  python3 -m venv target/venv
  target/venv/bin/python -m pip install -q -r ci/requirements.txt
  echo "$want" > "$stamp"
fi
export VERDEM_PYTHON="$PWD/target/venv/bin/python"

echo "== formatting and lints"
cargo fmt --check
cargo clippy --profile ci --all-targets -- -D warnings

echo "== the binary, then the tests (profile ci: optimised, as the solver runs in them; Cargo.toml says why not release)"
# Built alone first, so that its dependencies are compiled with the features a plain build
# gives them: the scratch builds of tests/recipe.rs and tests/recipe_peer.rs copy them and
# compile verdem only.
cargo build --profile ci --bin verdem
cargo test --profile ci --all-targets 2>&1 | tee /tmp/verdem-test.log

echo "== the release build, which users run, gives the tests' build's bits"
cargo build --release --bin verdem
for threads in 1 2; do
  run=(hash cases/shear_flow.toml --init data/states/mercury_t143.85.data --steps 20000 --threads "$threads")
  tested=$(target/ci/verdem "${run[@]}")
  shipped=$(target/release/verdem "${run[@]}")
  if [ "$tested" != "$shipped" ]; then
    echo "release and ci builds differ after 20000 steps on $threads thread(s): $shipped against $tested" >&2
    exit 1
  fi
  echo "$threads thread(s): $shipped"
done
