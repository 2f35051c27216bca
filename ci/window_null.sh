#!/usr/bin/env bash
# Calibrates the in-run gates of tests/full_run.rs: 30 windows of the same physics as its short
# run — `cases/shear_flow_quick.toml`, 2e6 steps, in-run averaging over the second half — each
# started from a save of the official full run (saves 2100, 2150, …, 4000 of the second half, 39:
# 180 time units apart, independent but for the bed's slow drift), against the full run's
# in-run profiles (golden/full_run_official). Per profile it writes the windows' χ²/dof, with
# each window's errors' degrees of freedom ν taken out (× (ν − 2)/ν, the mean of a squared
# Student t), their mean m, the effective number k of independent slices (2m²/variance: the
# 72 core slices are correlated, a particle spans ~4.5 of them) and the gate, m times the
# 99.9 % quantile of χ²_k/k (Wilson & Hilferty, PNAS 17:684, 1931). vx is judged less its
# common offset (the bed's drift). Also per profile the windows' spread over their own errors
# (spread_ratio, 1 when honest), which calibrated cg::blocking::REFERENCE_TAU. Writes
# golden/full_run_official/window_null.toml.
#   RUN=DIR   the official full run's folder with all its saves (default out/official_full,
#             made by `OUT=out/official_full INIT=data/GranularShearFlow.data ci/record_full_run.sh`)
#   JOBS=N    windows at once (default 2, one thread each)
set -euo pipefail
cd "$(dirname "$0")/.."
RUN=${RUN:-out/official_full}
JOBS=${JOBS:-2}
W=out/window_null
cargo build --release
mkdir -p "$W"
seq 2100 50 4000 | xargs -P "$JOBS" -I{} sh -c "target/release/verdem run cases/shear_flow_quick.toml \
  --init $RUN/shear_flow.data.{} --steps 2000000 --save-every 50000 --threads 1 --quiet --force \
  --out $W/w{} > $W/w{}.log 2>&1"
python3 - "$W" > golden/full_run_official/window_null.toml <<'PY'
import csv, glob, math, sys
def load(p):
    r = list(csv.reader(open(p)))
    return r[0], [list(map(float, x)) for x in r[1:]]
head, ref = load("golden/full_run_official/shear_flow.profiles_inrun.csv")
core = [k for k, row in enumerate(ref) if 3.0 <= row[0] <= 19.0]
windows = sorted(glob.glob(sys.argv[1] + "/w*/shear_flow_quick.profiles_inrun.csv"))
print("# The in-run gates of tests/full_run.rs (written by ci/window_null.sh): per profile, χ²/dof")
print(f"# of {len(windows)} same-physics windows against golden/full_run_official's in-run profiles,")
print("# core z in [3, 19], × (ν − 2)/ν; m their mean, k = 2m²/variance, limit = m·q999(χ²_k)/k.")
for name in ["nu", "vx", "T", "pressure", "shear_xz"]:
    i, j = head.index(name), head.index(name + "_se")
    vals = []
    for w in windows:
        _, t = load(w)
        dof = {r[0]: float(r[5]) for r in list(csv.reader(open(w.replace(".profiles_inrun.csv", ".profiles_inrun_errors.csv"))))[1:]}[name]
        d = [t[k][i] - ref[k][i] for k in core]
        v = [t[k][j] ** 2 + ref[k][j] ** 2 for k in core]
        lost = 0
        if name == "vx":
            wsum = sum(1 / x for x in v)
            off = sum(a / x for a, x in zip(d, v)) / wsum
            d = [a - off for a in d]
            lost = 1
        chi = sum(a * a / x for a, x in zip(d, v)) / (len(d) - lost)
        vals.append(chi * (dof - 2) / dof)
    n = len(vals)
    m = sum(vals) / n
    var = sum((x - m) ** 2 for x in vals) / (n - 1)
    k = 2 * m * m / var
    z = 3.090232  # standard normal 99.9 % quantile
    q = (1 - 2 / (9 * k) + z * math.sqrt(2 / (9 * k))) ** 3
    # per core slice the windows' variance about their own mean over their mean squared error
    # (1 when the errors are honest; docs/statistics.md), the median over the slices
    # (vx less each window's common offset against the reference, as it is judged)
    tables = [load(w)[1] for w in windows]
    shift = [0.0] * n
    if name == "vx":
        for w, t in enumerate(tables):
            v = [t[row][j] ** 2 + ref[row][j] ** 2 for row in core]
            d = [t[row][i] - ref[row][i] for row in core]
            shift[w] = sum(a / x for a, x in zip(d, v)) / sum(1 / x for x in v)
    ratios = []
    for row in core:
        x = [t[row][i] - shift[w] for w, t in enumerate(tables)]
        mx = sum(x) / n
        se2 = sum(t[row][j] ** 2 for t in tables) / n
        if se2 > 0:
            ratios.append(sum((a - mx) ** 2 for a in x) / (n - 1) / se2)
    ratios.sort()
    print(f"[{name}]")
    print(f"windows = {n}\nmean = {m:.3f}\nsd = {math.sqrt(var):.3f}\nk = {k:.1f}\nlargest = {max(vals):.3f}\nlimit = {m * q:.3f}")
    print(f"spread_ratio = {ratios[len(ratios) // 2]:.3f}")
PY
echo "recorded in golden/full_run_official/window_null.toml"
