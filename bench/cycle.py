"""Time the full cycle (kinematics, build, solve, certificate) on the bundled scenarios.

Usage: .venv/bin/python bench/cycle.py [--repeats 2000] [--json FILE]

Prints, per scenario and per stage, the median and p99 over the repeats, with
the machine it ran on. Speed is measured here, never asserted in a test.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time
from datetime import datetime, timezone
from importlib import metadata
from pathlib import Path

import numpy as np

from grasp_torque_opt.grasp_setup import GraspSetup
from grasp_torque_opt.solve import solve
from grasp_torque_opt.tau_qp import TauQPSolver

ROOT = Path(__file__).resolve().parent.parent
SCENARIOS = ["planar_two_finger.yaml", "allegro_right.yaml"]
STAGES = ["maps", "build", "solve", "certify"]


def machine() -> dict:
    """What this ran on."""
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    versions = {p: metadata.version(p) for p in ("numpy", "pin", "proxsuite", "scipy",
                                                  "clarabel")}
    return {"cpu": cpu, "cores": os.cpu_count(), "python": platform.python_version(),
            "system": platform.platform(), "versions": versions,
            "date": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M UTC")}


def bench(setup: GraspSetup, repeats: int) -> dict:
    """Median and p99 [s] of each stage and the whole cycle, ProxSuite reused across cycles."""
    solver = TauQPSolver()
    for _ in range(50):
        solve(setup, solver=solver)
    samples = {k: [] for k in STAGES + ["total"]}
    for _ in range(repeats):
        t0 = time.perf_counter()
        sol = solve(setup, solver=solver)
        samples["total"].append(time.perf_counter() - t0)
        assert sol.status == "optimal", sol.message
        for k in STAGES:
            samples[k].append(sol.timings[k])
    return {k: {"median_s": float(np.median(v)), "p99_s": float(np.percentile(v, 99))}
            for k, v in samples.items()}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2000)
    parser.add_argument("--json", type=Path, help="also write the results here")
    args = parser.parse_args()
    out = {"machine": machine(), "repeats": args.repeats, "scenarios": {}}
    m = out["machine"]
    print(f"machine: {m['cpu']}, {m['cores']} cores, Python {m['python']}, "
          f"ProxSuite {m['versions']['proxsuite']}, Pinocchio {m['versions']['pin']}; "
          f"{m['date']}")
    print(f"{'scenario':<24}{'stage':<10}{'median [us]':>12}{'p99 [us]':>12}")
    for name in SCENARIOS:
        res = bench(GraspSetup.from_file(ROOT / "config" / name), args.repeats)
        out["scenarios"][name] = res
        for k in STAGES + ["total"]:
            print(f"{name:<24}{k:<10}{1e6 * res[k]['median_s']:>12.1f}"
                  f"{1e6 * res[k]['p99_s']:>12.1f}")
    if args.json:
        args.json.write_text(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
