#!/usr/bin/env python3
"""State-estimator accuracy against MuJoCo's true state, per preset, for both estimators.

Runs sim_demo on every listed preset with `estimator=stance` and `estimator=kinematic_inertial`,
noise off and on (seed 1: white noise, IMU biases and heading drift), and prints one markdown
table of RMS / max errors (docs/controller.md, "State estimator"). The errors are computed by the
run itself (sim_demo/run.cpp: EstimatorAccuracy) from the controller's estimate and MuJoCo's state.

    python3 tools/estimator_accuracy.py [--sim build/sim_demo/sim_demo] [--jobs 2] [--out DIR]
"""
import argparse
import concurrent.futures
import json
import os
import subprocess
import sys
import tempfile

PRESETS = ["stand", "push_x", "push_y", "seesaw_x", "seesaw_y", "skate_x", "skate_y", "skate_z",
           "skate_roll", "skate_pitch", "skate_yaw", "skate_mixed"]
ESTIMATORS = ["stance", "kinematic_inertial"]
QUANTITIES = [("base_position_mm", "base pos (mm)"), ("base_velocity_mm_s", "base vel (mm/s)"),
              ("orientation_deg", "orient. (°)"), ("com_mm", "CoM (mm)"),
              ("com_velocity_mm_s", "CoM vel (mm/s)"), ("support_velocity_mm_s", "support vel (mm/s)")]


def run(sim, out, preset, estimator, noise):
    d = os.path.join(out, f"{preset}_{estimator}_{'noise' if noise else 'clean'}")
    cmd = [sim, "--scenario", preset, "--no-video", "--no-plots", "--out", d,
           "--set", f"estimator={estimator}"]
    if noise:
        cmd += ["--set", "noise=true", "--set", "seed=1"]
    subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=False)
    with open(os.path.join(d, preset, "summary.json")) as f:
        j = json.load(f)
    return preset, estimator, noise, j


def cell(e, key):
    v = e.get(key, {})
    rms, mx = v.get("rms"), v.get("max")
    fmt = "{:.2f}" if key == "orientation_deg" else "{:.1f}"
    return "–" if rms is None else f"{fmt.format(rms)} / {fmt.format(mx)}"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sim", default="build/sim_demo/sim_demo")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--out", default=None)
    ap.add_argument("--presets", nargs="*", default=PRESETS)
    a = ap.parse_args()
    out = a.out or tempfile.mkdtemp(prefix="estimator_accuracy_")
    jobs = [(p, e, n) for p in a.presets for n in (False, True) for e in ESTIMATORS]
    results = {}
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.jobs) as ex:
        for p, e, n, j in ex.map(lambda t: run(a.sim, out, *t), jobs):
            results[(p, e, n)] = j
    print("| preset | noise | estimator | result | " + " | ".join(q[1] for q in QUANTITIES) + " |")
    print("|---|---|---|---|" + "---|" * len(QUANTITIES))
    for p, e, n in jobs:
        j = results[(p, e, n)]
        err = j.get("estimator_error", {})
        res = "PASS" if j["passed"] else (f"fell {j['fall_time']:.2f} s" if j["fell"] else "FAIL")
        print(f"| {p} | {'on' if n else 'off'} | {e} | {res} | " +
              " | ".join(cell(err, q[0]) for q in QUANTITIES) + " |")
    print(f"\n(RMS / max over the run until a fall; positions after removing the first tick's offset; outputs in {out})",
          file=sys.stderr)


if __name__ == "__main__":
    main()
