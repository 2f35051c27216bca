#!/usr/bin/env bash
# Records golden/peers/: LAMMPS and LIGGGHTS (Debian packages, 1 MPI rank each, both at once)
# run the shear case from verdem's steady state golden/full_run/shear_flow.final.data, a save
# every 50000 steps; verdem converts their dumps into MercuryCG saves and coarse-grains them.
# Then verdem itself (its default, MercuryDPM's convention, 2 threads) runs the same case from
# the same state for the same steps. Each code's profiles (all saves, 10 blocks), the peers'
# overlays with verdem's run in their convention, and the peers' input scripts are kept with
# provenance. About 65 minutes of the machine for 1e7 steps.
#   STEPS=N   steps of each run (default 10000000)
#   STATE=F   the start state (default: the full run's final state)
set -euo pipefail
cd "$(dirname "$0")/.."
STEPS=${STEPS:-10000000}
STATE=${STATE:-golden/full_run/shear_flow.final.data}
OUT=out/record_peers
COMMIT=$(git rev-parse HEAD)
cargo build --release
mkdir -p golden/peers "$OUT"
# the binary of this commit for the whole recording, whatever is built meanwhile
BIN="$OUT/verdem"
cp target/release/verdem "$BIN"
START_SHA=$(sha256sum "$STATE" | cut -d' ' -f1)
for peer in lammps liggghts; do
  "$BIN" cross "$peer" cases/shear_flow.toml --from "$STATE" \
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
start_state_sha256 = "$START_SHA"
steps = $STEPS
every = 50000
commit = "$COMMIT"
recorded = "$(date -u +%Y-%m-%dT%H:%M:%SZ)"
profiles = "$peer.profiles.csv: all saves 0..$((STEPS / 50000)), 100 slices, Heaviside kernel, 10 blocks"
EOF
done
own="$OUT/verdem_run"
"$BIN" run cases/shear_flow.toml --init "$STATE" --steps "$STEPS" --threads 2 --out "$own" \
  --quiet > "$OUT/verdem.log" 2>&1
"$BIN" cg "$own/shear_flow" --from 0 --case cases/shear_flow.toml >> "$OUT/verdem.log" 2>&1
cp "$own/shear_flow.profiles.csv" golden/peers/verdem.profiles.csv
cp "$own/shear_flow.diagnostics.csv" golden/peers/verdem.diagnostics.csv
hash=$(sed -n 's/^hash = "\(.*\)"/\1/p' "$own/shear_flow.summary.toml")
cat > golden/peers/verdem.toml <<EOF
# How golden/peers/verdem.* was made (written by ci/record_peers.sh).
command = "verdem run cases/shear_flow.toml --init $STATE --steps $STEPS --threads 2"
convention = "mercury"
start_state_sha256 = "$START_SHA"
steps = $STEPS
every = 50000
final_state_hash = "$hash"
commit = "$COMMIT"
recorded = "$(date -u +%Y-%m-%dT%H:%M:%SZ)"
profiles = "verdem.profiles.csv: all saves 0..$((STEPS / 50000)), 100 slices, Heaviside kernel, 10 blocks"
EOF
echo "recorded in golden/peers"
