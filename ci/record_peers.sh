#!/usr/bin/env bash
# Records golden/peers/: LAMMPS and LIGGGHTS (Debian packages, 1 MPI rank each, both at once)
# run the shear case from verdem's steady state golden/full_run/shear_flow.final.data, a save
# every 50000 steps; verdem converts their dumps into MercuryCG saves and coarse-grains them.
# Each peer's profiles, its overlay with verdem's (peer convention) and its input script are
# kept with provenance. About 40 minutes for 1e7 steps.
#   STEPS=N   steps of each run (default 10000000)
#   STATE=F   the start state (default: the full run's final state)
set -euo pipefail
cd "$(dirname "$0")/.."
STEPS=${STEPS:-10000000}
STATE=${STATE:-golden/full_run/shear_flow.final.data}
OUT=out/record_peers
cargo build --release
mkdir -p golden/peers "$OUT"
for peer in lammps liggghts; do
  ./target/release/verdem cross "$peer" cases/shear_flow.toml --from "$STATE" \
    --steps "$STEPS" --every 50000 --np 1 --out "$OUT" > "$OUT/$peer.log" 2>&1 &
done
wait
for peer in lammps liggghts; do
  bin=$([ "$peer" = lammps ] && echo lmp || echo liggghts)
  dir="$OUT/$bin"
  cp "$dir/$bin.profiles.csv" "golden/peers/$peer.profiles.csv"
  cp "$dir/profiles.png" "golden/peers/$peer.profiles.png"
  cp "$dir/$bin/in.$bin" "golden/peers/$peer.in"
  cp "$dir/cross.md" "golden/peers/$peer.cross.md"
  cat > "golden/peers/$peer.toml" <<EOF
# How golden/peers/$peer.* was made (written by ci/record_peers.sh).
peer = "$peer"
package = "$peer $(dpkg-query -W -f='${Version}' "$peer")"
command = "verdem cross $peer cases/shear_flow.toml --from $STATE --steps $STEPS --every 50000 --np 1"
peer_command = "mpirun --allow-run-as-root -np 1 $bin -in in.$bin -log none"
start_state_sha256 = "$(sha256sum "$STATE" | cut -d' ' -f1)"
steps = $STEPS
every = 50000
commit = "$(git rev-parse HEAD)"
recorded = "$(date -u +%Y-%m-%dT%H:%M:%SZ)"
profiles = "$peer.profiles.csv: all saves 0..$((STEPS / 50000)), 100 slices, Heaviside kernel, block standard errors"
EOF
done
echo "recorded in golden/peers"
