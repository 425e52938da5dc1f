#!/usr/bin/python3
"""Self-test of plot_ablation.py on synthetic data (ctest: sim_plot_ablation).

The moving RMS and the RMS over joints against values known by construction; the PNG of a
synthetic two-scenario ablation (one run fell, one CSV missing); a record without runs is refused.
"""
import json
import os
import struct
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import plot_ablation  # noqa: E402

JOINTS = [f"{s}_{j}" for s in ("l", "r") for j in
          ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")]
FAILURES = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        FAILURES.append(what)


def png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    if head[:8] != b"\x89PNG\r\n\x1a\n":
        return None
    return struct.unpack(">II", head[16:24])


def write_csv(path, t, err, push_at=None):
    """A CSV with time, push force and tau_err_* columns (err: per-tick array, the same on all joints)."""
    names = ["time", "push_fx", "push_fy", "push_fz"] + ["tau_err_" + j for j in JOINTS]
    push = np.zeros_like(t)
    if push_at is not None:
        push[(t >= push_at) & (t < push_at + 0.01)] = 1000.0
    cols = [t, push, np.zeros_like(t), np.zeros_like(t)] + [err] * len(JOINTS)
    with open(path, "w") as f:
        f.write(",".join(names) + "\n")
        for row in np.column_stack(cols):
            f.write(",".join("nan" if not np.isfinite(x) else f"{x:.6g}" for x in row) + "\n")


def record(scenario, variant, csv, rms, fell=False):
    return {"scenario": scenario, "variant": variant, "fell": fell, "torque_tracking_rms_Nm": rms,
            "torque_tracking_link_rms_Nm": rms, "torque_tracking_rms_joint_Nm": {"l_knee": rms, "r_knee": rms},
            "feet": [{"zmp_tracking_rms_mm": 3.0}, {"zmp_tracking_rms_mm": None}], "files": {"csv": csv}}


def main():
    # Moving RMS: a constant stays constant; a step from 0 to 2 at sample 100 with a 50-sample
    # window is sqrt(4 k / 50) k samples after the step, then 2; NaN samples do not count.
    t = np.arange(300) * 0.001
    check(np.allclose(plot_ablation.moving_rms(t, np.full(300, 3.0), 0.05), 3.0), "moving RMS of a constant")
    e = np.where(np.arange(300) >= 100, 2.0, 0.0)
    m = plot_ablation.moving_rms(t, e, 0.05)
    k = np.arange(1, 51)
    check(np.allclose(m[99 + k], np.sqrt(4.0 * k / 50)), "moving RMS over a step")
    check(np.allclose(m[160:], 2.0) and np.allclose(m[:100], 0.0), "moving RMS before and after the step")
    e2 = np.full(300, 1.0)
    e2[10:20] = np.nan
    m2 = plot_ablation.moving_rms(t, e2, 0.05)
    check(np.allclose(m2[np.isfinite(m2)], 1.0) and np.isfinite(m2[15]), "moving RMS skips NaN samples")

    with tempfile.TemporaryDirectory() as d:
        tt = np.arange(2000) * 0.001
        runs = []
        for scen in ("push_x", "stand"):
            for v, level in (("on", 0.5), ("off", 1.0), ("low", 0.7)):
                csv = os.path.join(d, f"{scen}_{v}.csv")
                n = len(tt) if not (scen == "stand" and v == "low") else 700  # this one fell at 0.7 s
                write_csv(csv, tt[:n], np.full(n, level), push_at=1.0 if scen == "push_x" else None)
                runs.append(record(scen, v, csv, level, fell=n < len(tt)))
        runs.append(record("stand", "high", os.path.join(d, "missing.csv"), 0.6))
        js = os.path.join(d, "ablation.json")
        with open(js, "w") as f:
            json.dump({"scenario": "friction_ablation", "controller": "hqp", "runs": runs}, f)
        # joint_rms of the CSV: every joint carries `level`.
        import plot_scenario
        r = plot_scenario.Run(os.path.join(d, "push_x_off.csv"))
        check(np.allclose(plot_ablation.joint_rms(r), 1.0), "RMS over the joints")
        png = os.path.join(d, "out.png")
        p = subprocess.run([sys.executable, os.path.join(HERE, "plot_ablation.py"), js, "--out", png],
                           capture_output=True, text=True)
        check(p.returncode == 0, f"plot_ablation.py runs (exit {p.returncode}: {p.stderr[-300:]})")
        size = png_size(png) if os.path.exists(png) else None
        check(size is not None and size[0] > 1500 and size[1] > 900, f"PNG written, two rows of panels ({size})")
        empty = os.path.join(d, "empty.json")
        with open(empty, "w") as f:
            json.dump({"runs": []}, f)
        p = subprocess.run([sys.executable, os.path.join(HERE, "plot_ablation.py"), empty, "--out", png],
                           capture_output=True, text=True)
        check(p.returncode == 2, "a record without runs is refused")
    print(f"{len(FAILURES)} failure(s)")
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
