#!/usr/bin/env bash
# Runs the full ON-DEM shear benchmark (cases/shear_flow.toml: 2e8 steps, a save every 50000) and
# records its result in golden/full_run/ with provenance. About 2 hours on 2 cores; it writes a
# checkpoint every 2e6 steps and, started again, resumes from it bit for bit.
#   OUT=DIR   run folder (default out/full_run); the saves (~2.4 GB) stay there
#   NOTE=...  a line of provenance to add (e.g. which binaries ran which steps)
#   INIT=F    start from this configuration (e.g. data/GranularShearFlow.data, the official one;
#             default: the case's generated scene)
#   THREADS=N threads of the run (default: the case's)
#   G=DIR     where the record goes (default golden/full_run)
#   COMMIT=H  the commit whose binary ran (default: HEAD)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${OUT:-out/full_run}
G=${G:-golden/full_run}
cargo build --release
BIN=target/release/verdem
NAME=shear_flow
ARGS=(--out "$OUT" --checkpoint-every 2000000)
if [ -n "${INIT:-}" ]; then ARGS+=(--init "$INIT"); fi
if [ -n "${THREADS:-}" ]; then ARGS+=(--threads "$THREADS"); fi
RESUME=()
if [ -f "$OUT/$NAME.checkpoint" ]; then
  RESUME=(--resume "$OUT/$NAME.checkpoint")
fi
if [ ! -f "$OUT/$NAME.summary.toml" ]; then
  "$BIN" run cases/shear_flow.toml "${ARGS[@]}" "${RESUME[@]}"
fi
mkdir -p "$G"
LAST=$(grep '^step =' "$OUT/$NAME.summary.toml" | awk '{print $3}')
SAVE=$(printf '%04d' $((LAST / 50000)))
cp "$OUT/$NAME.data.$SAVE" "$G/$NAME.final.data"
for f in profiles.csv profiles.png checks.txt summary.toml diagnostics.csv profiles_inrun.csv; do
  if [ -f "$OUT/$NAME.$f" ]; then cp "$OUT/$NAME.$f" "$G/$NAME.$f"; fi
done
cat > "$G/provenance.toml" <<EOF
# How $G/ was made (written by ci/record_full_run.sh).
case = "cases/shear_flow.toml"
command = "verdem run cases/shear_flow.toml ${ARGS[*]}"
init = "${INIT:-the generated scene of the case}"
commit = "${COMMIT:-$(git rev-parse HEAD)}"
recorded = "$(date -u +%Y-%m-%dT%H:%M:%SZ)"
machine = "$(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs)"
final_state = "$NAME.final.data (save $SAVE, step $LAST)"
final_state_sha256 = "$(sha256sum "$G/$NAME.final.data" | cut -d' ' -f1)"
profiles = "$NAME.profiles.csv: saves 2001..4000 (the second half), 100 slices, Heaviside kernel, 10 blocks"
${NOTE:+note = \"$NOTE\"}
EOF
echo "recorded in $G"
