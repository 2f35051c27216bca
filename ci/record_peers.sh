#!/usr/bin/env bash
# Records golden/peers/: the peers named as arguments (default: every peer `verdem peers` lists;
# LAMMPS, LIGGGHTS and Yade, Debian packages), 1 MPI rank or thread each, all at once, run the
# shear case from verdem's steady state golden/full_run/shear_flow.final.data, a save every 50000
# steps; verdem converts their dumps into MercuryCG saves and coarse-grains them, and runs the
# same steps in each peer's convention (`verdem cross`). Then verdem itself (its default, MercuryDPM's
# convention, 2 threads) runs the same case from the same state for the same steps. Kept, with
# provenance: each series' profiles (all saves, 10 blocks) and cg checks, the peers' input
# scripts and cross-run tables, verdem's diagnostics, the comparison table (compare.md, every
# peer recorded in golden/peers/) and one overlay of the codes (profiles.png). About 70 minutes
# of the machine for 1e7 steps of LAMMPS and LIGGGHTS; Yade, at 300-900 steps/s, takes hours.
#   ci/record_peers.sh [PEER ...]
#   ci/record_peers.sh --inrun [PEER ...]
#   STEPS=N   steps of each run (default 10000000; with --inrun 1000000)
#   STATE=F   the start state (default: the full run's final state)
# With --inrun only the in-run comparison is recorded, and no other file of golden/peers is
# touched: the peers named (default lammps, liggghts and yade; those with in-run dumps), 1 rank
# or thread each, all at once, average in-run (`verdem cross --inrun`: contact stress and wall
# forces every 8 contact durations, particle fields every 24, from their dumps; Yade, at a few
# hundred steps/s, takes about an hour for 1e6 steps), as do verdem in each peer's convention
# and verdem in MercuryDPM's, over the same steps. Kept: each run's in-run profiles
# (PEER.profiles_inrun.csv, verdem_as_PEER.profiles_inrun.csv, verdem.profiles_inrun.csv) and
# compare_inrun.md (the core means with 95 % intervals, with provenance).
set -euo pipefail
cd "$(dirname "$0")/.."
INRUN=0
if [ "${1:-}" = "--inrun" ]; then
  INRUN=1
  shift
fi
if [ "$INRUN" = 1 ]; then STEPS=${STEPS:-1000000}; else STEPS=${STEPS:-10000000}; fi
STATE=${STATE:-golden/full_run/shear_flow.final.data}
OUT=out/record_peers
G=golden/peers
COMMIT=$(git rev-parse HEAD)
cargo build --release
mkdir -p "$G" "$OUT"
# the binary of this commit for the whole recording, whatever is built meanwhile
BIN="$OUT/verdem"
cp target/release/verdem "$BIN"
START_SHA=$(sha256sum "$STATE" | cut -d' ' -f1)
if [ "$INRUN" = 1 ]; then
  [ $# -gt 0 ] || set -- lammps liggghts yade
  IN="$OUT/inrun"
  for peer in "$@"; do
    "$BIN" cross "$peer" cases/shear_flow.toml --from "$STATE" --steps "$STEPS" --every 50000 \
      --np 1 --out "$IN" --inrun --force > "$OUT/$peer.inrun.log" 2>&1 &
  done
  wait
  own=
  for peer in "$@"; do
    bin=$("$BIN" peers "$peer" | cut -f2)
    dir="$IN/$bin"
    cp "$dir/$bin.profiles_inrun.csv" "$G/$peer.profiles_inrun.csv"
    cp "$dir/verdem.profiles_inrun.csv" "$G/verdem_as_$peer.profiles_inrun.csv"
    # verdem's own run is the same run in every cross-run (one thread, one state)
    if [ -z "$own" ]; then
      own="$dir/verdem_own.profiles_inrun.csv"
    else
      cmp "$own" "$dir/verdem_own.profiles_inrun.csv"
    fi
  done
  cp "$own" "$G/verdem.profiles_inrun.csv"
  {
    echo "# The cross-code comparison with in-run averaging in every code (written by ci/record_peers.sh --inrun)"
    echo
    echo "Recorded $(date -u +%Y-%m-%dT%H:%M:%SZ) at commit $COMMIT, from $STATE (SHA-256 $START_SHA),"
    echo "$STEPS steps of cases/shear_flow.toml, 1 MPI rank or thread per run, all cross-runs at once. Commands:"
    echo
    for peer in "$@"; do
      echo "- \`verdem cross $peer cases/shear_flow.toml --from $STATE --steps $STEPS --every 50000 --np 1 --inrun\` ($("$BIN" peers "$peer" | cut -f5); the peer run as \`$("$BIN" peers "$peer" | cut -f4)\`)"
    done
    echo
    echo "Each runs the peer, its dumps read by verdem's in-run accumulator, then verdem in the"
    echo "peer's convention and verdem in the case's own (MercuryDPM's)."
    for peer in "$@"; do
      bin=$("$BIN" peers "$peer" | cut -f2)
      echo
      echo "## $peer"
      echo
      cat "$IN/$bin/inrun.md"
    done
  } > "$G/compare_inrun.md"
  echo "recorded in $G/compare_inrun.md"
  exit 0
fi
# each peer's line of `verdem peers` (an unknown name stops here, with the known ones):
# name, binary, tangential convention, command of a 1-rank run, installed version
if [ $# -gt 0 ]; then LIST=$("$BIN" peers "$(IFS=,; echo "$*")"); else LIST=$("$BIN" peers); fi
declare -A BINARY CONVENTION COMMAND VERSION
PEERS=()
while IFS=$'\t' read -r name bin convention command version; do
  PEERS+=("$name")
  BINARY[$name]=$bin
  CONVENTION[$name]=$convention
  COMMAND[$name]=$command
  VERSION[$name]=$version
done <<< "$LIST"
for peer in "${PEERS[@]}"; do
  "$BIN" cross "$peer" cases/shear_flow.toml --from "$STATE" \
    --steps "$STEPS" --every 50000 --np 1 --out "$OUT" --force > "$OUT/$peer.log" 2>&1 &
done
wait
# coarse-grains a series over all its saves (as the cross-runs do) and keeps its checks
checks() {
  "$BIN" cg "$1" --from 0 --case cases/shear_flow.toml > /dev/null
  cp "$1.checks.txt" "$2"
}
for peer in "${PEERS[@]}"; do
  bin=${BINARY[$peer]}
  dir="$OUT/$bin"
  cp "$dir/$bin.profiles.csv" "$G/$peer.profiles.csv"
  cp "$dir/verdem.profiles.csv" "$G/verdem_as_$peer.profiles.csv"
  # the generated input: in.BINARY (the LAMMPS family) or in.BINARY.py (Yade)
  for f in "$dir/$bin/in.$bin" "$dir/$bin/in.$bin.py"; do [ -f "$f" ] && cp "$f" "$G/$peer.in"; done
  cp "$dir/cross.md" "$G/$peer.cross.md"
  checks "$dir/$bin/shear_flow" "$G/$peer.checks.txt"
  checks "$dir/verdem/shear_flow" "$G/verdem_as_$peer.checks.txt"
  cat > "$G/$peer.toml" <<TOML
# How golden/peers/$peer.* and verdem_as_$peer.* were made (written by ci/record_peers.sh).
peer = "$peer"
package = "${VERSION[$peer]}"
command = "verdem cross $peer cases/shear_flow.toml --from $STATE --steps $STEPS --every 50000 --np 1"
peer_command = "${COMMAND[$peer]}"
verdem_as_peer = "verdem, 1 thread, tangential convention ${CONVENTION[$peer]}, history update at setup and normal-force clipping as the peer's (verdem cross)"
start_state_sha256 = "$START_SHA"
steps = $STEPS
every = 50000
commit = "$COMMIT"
recorded = "$(date -u +%Y-%m-%dT%H:%M:%SZ)"
profiles = "$peer.profiles.csv, verdem_as_$peer.profiles.csv: all saves 0..$((STEPS / 50000)), 100 slices, Heaviside kernel, 10 blocks"
TOML
done
own="$OUT/verdem_run"
"$BIN" run cases/shear_flow.toml --init "$STATE" --steps "$STEPS" --threads 2 --out "$own" --force \
  --quiet > "$OUT/verdem.log" 2>&1
checks "$own/shear_flow" "$G/verdem.checks.txt"
cp "$own/shear_flow.profiles.csv" "$G/verdem.profiles.csv"
cp "$own/shear_flow.diagnostics.csv" "$G/verdem.diagnostics.csv"
hash=$(sed -n 's/^hash = "\(.*\)"/\1/p' "$own/shear_flow.summary.toml")
cat > "$G/verdem.toml" <<TOML
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
TOML
# every peer of verdem's list with a recording in golden/peers/, in the list's order; labels
# are the names in capitals
RECORDED=()
for peer in $("$BIN" peers | cut -f1); do
  [ -f "$G/$peer.profiles.csv" ] && RECORDED+=("$peer")
done
tables=() labels=verdem
for peer in "${RECORDED[@]}"; do
  tables+=("$G/$peer.profiles.csv")
  labels+=",${peer^^}"
done
as_tables=() as_labels=
for peer in "${RECORDED[@]}"; do
  as_tables+=("$G/verdem_as_$peer.profiles.csv")
  as_labels+=",verdem as ${peer^^}"
done
{
  echo "# The long runs of golden/peers compared (written by ci/record_peers.sh)"
  echo
  echo "## Each code against verdem (MercuryDPM's convention)"
  echo
  "$BIN" compare "$G/verdem.profiles.csv" "${tables[@]}" "${as_tables[@]}" \
    --labels "$labels$as_labels"
  for peer in "${RECORDED[@]}"; do
    echo
    echo "## $peer against verdem in $peer's convention (the same equations: noise alone)"
    echo
    "$BIN" compare "$G/$peer.profiles.csv" "$G/verdem_as_$peer.profiles.csv" \
      --labels "$peer","verdem as $peer"
  done
} > "$G/compare.md"
"$BIN" compare "$G/verdem.profiles.csv" "${tables[@]}" \
  --labels "$labels" --plot "$G/profiles.png" > /dev/null
echo "recorded in $G"
