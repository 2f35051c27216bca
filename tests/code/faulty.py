#!/usr/bin/env python3
"""A broken external program for the tests of `verdem verify --code`:

    python3 faulty.py FAULT CASE.toml MOTION.csv --out FORCES.csv

runs contact_law.py (the correct law) and then spoils its forces file, or fails itself:

    crash   raises an exception before writing anything (a traceback, exit code 1)
    short   drops the last row
    nan     writes nan as fx1 of the third row
    header  misspells the column fn
"""

import os
import subprocess
import sys

fault, case, motion, flag, out = sys.argv[1:6]
if fault == "crash":
    raise RuntimeError("the law diverged")
law = os.path.join(os.path.dirname(os.path.abspath(__file__)), "contact_law.py")
subprocess.run([sys.executable, law, case, motion, flag, out], check=True)
with open(out) as f:
    lines = f.read().splitlines()
if fault == "short":
    lines = lines[:-1]
elif fault == "nan":
    fields = lines[3].split(",")
    fields[1] = "nan"
    lines[3] = ",".join(fields)
elif fault == "header":
    lines[0] = lines[0].replace(",fn,", ",f_n,")
with open(out, "w") as f:
    f.write("\n".join(lines) + "\n")
