#!/usr/bin/env python3
"""Speed of two verdem binaries side by side: the same `verdem hash` job (a case from a state,
N steps, T threads) run alternately by each binary (A B, then B A, ...), so that drift of a
shared machine cancels. Prints the median over rounds of the ratio of rates (second binary over
first) with a distribution-free 95 % interval of the median (order statistics of the binomial
with p = 1/2), and refuses to compare binaries whose hashes differ.

Usage: python3 ci/ab_speed.py OLD NEW [--threads T] [--rounds R] [--steps N]
       [--case cases/shear_flow.toml] [--init data/states/mercury_t143.85.data]
"""
import argparse
import math
import subprocess
import time


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--threads", default="1")
    ap.add_argument("--rounds", type=int, default=15)
    ap.add_argument("--steps", default="20000")
    ap.add_argument("--case", default="cases/shear_flow.toml")
    ap.add_argument("--init", default="data/states/mercury_t143.85.data")
    a = ap.parse_args()
    args = ["hash", a.case, "--init", a.init, "--steps", a.steps, "--threads", a.threads]

    def timed(binary):
        start = time.perf_counter()
        out = subprocess.run([binary] + args, capture_output=True, text=True, check=True)
        return time.perf_counter() - start, out.stdout.strip()

    ratios = []
    for r in range(a.rounds):
        order = [a.old, a.new] if r % 2 == 0 else [a.new, a.old]
        seconds = {}
        hashes = set()
        for binary in order:
            seconds[binary], h = timed(binary)
            hashes.add(h)
        if len(hashes) != 1:
            raise SystemExit(f"the binaries' hashes differ: {sorted(hashes)}")
        ratios.append(seconds[a.old] / seconds[a.new])
    ratios.sort()
    n = len(ratios)
    lo = 0
    while sum(math.comb(n, k) for k in range(lo + 1)) / 2**n < 0.025:
        lo += 1
    median = ratios[n // 2] if n % 2 else 0.5 * (ratios[n // 2 - 1] + ratios[n // 2])
    print(
        f"{a.threads} thread(s), {a.steps} steps: rate of {a.new} over {a.old}: median "
        f"{median:.3f} over {n} rounds, 95 % interval {ratios[lo]:.3f}-{ratios[n - 1 - lo]:.3f} "
        f"(hash {hashes.pop()[:8]})"
    )


if __name__ == "__main__":
    main()
