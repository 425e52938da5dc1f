#!/usr/bin/python3
"""Self-test of plot_scenario.py on synthetic data (ctest: sim_plots).

Synthetic runs: a full controller run with every optional column, a PD run that falls (no driver
columns, no foot angles, a ball launch, a partial last line, NaN CoPs), and a header-only file.
Checks the PNGs (signature, size in pixels and bytes), the push detection and the min/max
decimation against values known by construction, and the rows of the markdown table.
"""
import contextlib
import io
import json
import os
import struct
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import plot_scenario  # noqa: E402

PY = sys.executable
JOINTS = [f"{s}_{j}" for s in ("l", "r") for j in
          ("hip_yaw", "hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")]
FAILURES = []


def check(cond, what, r=None):
    """Records a check; r (a finished script run) is printed when the check fails."""
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        FAILURES.append(what)
        if r is not None:
            print(f"     exit {r.returncode}\n     stdout: {r.stdout}\n     stderr: {r.stderr}")


def base_columns(t):
    """The columns every sim_demo run writes (docs/simulation.md), with plausible values."""
    n = len(t)
    c = {"time": t}
    for j in JOINTS:
        c["q_" + j] = np.zeros(n)
    for j in JOINTS:
        c["tau_" + j] = np.zeros(n)
    for f in ("l", "r"):
        for k in ("fx", "fy", "fz", "mx", "my", "mz"):
            c[f"{f}_ft_{k}"] = np.full(n, 210.0 if k == "fz" else 0.0)
    c["l_cop_x"] = 0.01 * np.sin(t)
    c["l_cop_y"] = np.full(n, 0.005)
    c["r_cop_x"] = 0.02 * np.sin(2 * t)
    c["r_cop_y"] = np.full(n, -0.005)
    c["torso_pitch"] = 0.2 * np.exp(-((t - 1.3) ** 2) / 0.05)  # peak 0.2 rad = 11.46 deg at 1.3 s
    c["torso_roll"] = np.zeros(n)
    c["torso_z"] = np.full(n, 1.2)
    c["com_x"] = 0.03 + 0.05 * np.exp(-((t - 1.4) ** 2) / 0.05)  # +50 mm at 1.4 s
    c["com_y"] = np.zeros(n)
    c["com_z"] = np.full(n, 0.9)
    for k in ("push_fx", "push_fy", "push_fz", "ball_px", "ball_py", "ball_pz"):
        c[k] = np.zeros(n)
    c["tick_us"] = 50.0 + 5.0 * np.sin(37.0 * t)
    c["safe_mode"] = np.zeros(n)
    return c


def write_csv(path, cols, partial_tail=None):
    names = list(cols)
    data = np.column_stack([cols[k] for k in names])
    with open(path, "w") as f:
        f.write(",".join(names) + "\n")
        if len(data):
            np.savetxt(f, data, delimiter=",", fmt="%.6g")
        if partial_tail:
            f.write(partial_tail)


def full_run(path):
    """6 s at 1 kHz, HQP driver columns, foot angles, pushes of 8 and 10 N*s (x) at 1 and 3 s."""
    t = np.round(np.arange(0, 6.0, 0.001), 4)
    c = base_columns(t)
    c["r_foot_pitch"] = np.deg2rad(1.5) * np.exp(-((t - 1.2) ** 2) / 0.01)  # 1.5 deg at 1.2 s
    c["l_foot_pitch"] = 0.5 * c["r_foot_pitch"]
    c["r_foot_roll"] = np.zeros_like(t)
    c["l_foot_roll"] = np.zeros_like(t)
    for t0, imp in ((1.0, 8.0), (3.0, 10.0)):
        on = (t >= t0 - 1e-9) & (t < t0 + 0.010 - 1e-9)  # 10 ms
        c["push_fx"][on] = imp / 0.010
    c["tick_us"][2500] = 3000.0  # one multi-ms outlier
    c["ctrl_status"] = np.zeros_like(t)
    for lvl in range(1, 5):
        c[f"level{lvl}_status"] = np.zeros_like(t)
        res = 1e-6 * (1 + np.sin(t)) ** 2 * lvl
        if lvl == 4:
            res = res + 1e3 * np.exp(-((t - 3.1) ** 2) / 1e-4)  # the paper's 1e3 peak
            res[:100] = 0.0  # exact zeros must not break the log axis
            c["level4_status"][3100:3105] = 2
        c[f"level{lvl}_residual"] = res
        c[f"level{lvl}_active"] = np.full_like(t, 3)
    for f, sgn in (("l", 1), ("r", -1)):
        c[f + "_in_contact"] = np.ones_like(t)
        c[f + "_following"] = np.zeros_like(t)
        c[f + "_zmp_meas_x"] = c[f + "_cop_x"].copy()
        c[f + "_zmp_meas_y"] = c[f + "_cop_y"].copy()
        c[f + "_zmp_opt_x"] = c[f + "_cop_x"] + 0.003
        c[f + "_zmp_opt_y"] = c[f + "_cop_y"] - 0.002
    lift = (t > 4.0) & (t < 4.5)  # left foot unloaded: NaN measured ZMP, not in contact
    c["l_in_contact"][lift] = 0
    c["l_zmp_meas_x"][lift] = np.nan
    c["l_zmp_meas_y"][lift] = np.nan
    for k in ("com_err_x", "com_err_y", "com_err_z", "torso_err_x", "torso_err_y", "torso_err_z",
              "current_saturated"):
        c[k] = np.zeros_like(t)
    write_csv(path, c)


def falling_run(path):
    """PD-like run: no driver columns and no foot angles; ball thrown with 12 N*s along y at 0.8 s;
    falls at 2.3 s (torso below 0.6 m); NaN CoPs while the right foot is unloaded; partial last line."""
    t = np.round(np.arange(0, 2.3005, 0.001), 4)
    c = base_columns(t)
    launch = t >= 0.8 - 1e-9
    c["ball_py"][launch] = np.maximum(12.0 - 40.0 * (t[launch] - 0.8), 2.0)
    c["torso_roll"] = np.where(t > 0.9, (t - 0.9) * 0.6, 0.0)
    c["torso_z"] = np.where(t > 1.5, 1.2 - (t - 1.5) * 0.9, 1.2)
    unloaded = t > 1.8
    c["r_cop_x"][unloaded] = np.nan
    c["r_cop_y"][unloaded] = np.nan
    write_csv(path, c, partial_tail="2.3010,0.0001,0.00")


def support_run(path):
    """4 s on a moving support: the right foot rides a board along x (0.5 m/s peak at 1.5 Hz) with
    200 Hz chatter on its angular velocity; support_r_board_x is the board's position."""
    t = np.round(np.arange(0, 4.0, 0.001), 4)
    c = base_columns(t)
    for f in ("l", "r"):
        c[f + "_foot_pitch"] = np.zeros_like(t)
        c[f + "_foot_roll"] = np.zeros_like(t)
    c["l_foot_yaw"] = np.zeros_like(t)
    c["r_foot_yaw"] = 0.01 * np.sin(t)
    om = 2 * np.pi * 1.5
    for f in ("l", "r"):
        for k in ("wx", "wy", "wz", "vx", "vy", "vz"):
            c[f"{f}_foot_{k}"] = np.zeros_like(t)
    c["r_foot_vx"] = 0.5 * np.cos(om * t)
    c["r_foot_wy"] = 0.3 * np.sin(2 * np.pi * 200.0 * t)
    c["support_r_board_x"] = 0.5 / om * np.sin(om * t)
    write_csv(path, c)


def read_png_size(path):
    with open(path, "rb") as f:
        head = f.read(24)
    if head[:8] != b"\x89PNG\r\n\x1a\n" or head[12:16] != b"IHDR":
        return None
    return struct.unpack(">II", head[16:24])


def check_pngs(outdir, stem, figs=("fig8", "fig9", "fig13")):
    for fig in figs:
        p = os.path.join(outdir, f"{stem}_{fig}.png")
        ok = os.path.isfile(p)
        check(ok, f"{stem}_{fig}.png exists")
        if not ok:
            continue
        size = read_png_size(p)
        check(size is not None, f"{stem}_{fig}.png is a PNG")
        if size:
            w, h = size
            check(1200 <= w <= 2500 and 600 <= h <= 2000, f"{stem}_{fig}.png is {w}x{h} px (150 dpi figure)")
        check(os.path.getsize(p) > 20000, f"{stem}_{fig}.png has content ({os.path.getsize(p)} bytes)")


def run_script(args):
    return subprocess.run([PY] + args, capture_output=True, text=True, timeout=300)


class Result:
    def __init__(self, returncode, stdout, stderr):
        self.returncode, self.stdout, self.stderr = returncode, stdout, stderr


def run_inprocess(main, args):
    """A script's main() in this process (saves importing matplotlib per run); same CLI parsing."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            rc = main(args)
        except SystemExit as e:
            rc = e.code
    return Result(rc, out.getvalue(), err.getvalue())


def test_plots(tmp):
    full = os.path.join(tmp, "push_x.csv")
    fall = os.path.join(tmp, "push_y_fall.csv")
    empty = os.path.join(tmp, "empty.csv")
    full_run(full)
    falling_run(fall)
    with open(empty, "w") as f:
        f.write("time,com_x,tick_us\n")
    out = os.path.join(tmp, "plots")
    script = os.path.join(HERE, "plot_scenario.py")

    r = run_script([script, full, "--out", out, "--title", "push_x (synthetic)"])
    check(r.returncode == 0, "plot_scenario on a full run exits 0", r)
    check_pngs(out, "push_x")

    r = run_inprocess(plot_scenario.main, [fall, "--out", out])
    check(r.returncode == 0, "plot_scenario on a truncated run with NaNs and missing columns exits 0", r)
    check("incomplete line" in r.stderr, "the partial last line is reported")
    check_pngs(out, "push_y_fall")

    r = run_inprocess(plot_scenario.main, [full, "--out", out, "--pushes", "1.0,3.0", "--sole-x", "100",
                                           "--sole-y", "45"])
    check(r.returncode == 0, "plot_scenario with --pushes and sole limits exits 0", r)
    r = run_inprocess(plot_scenario.main, [full, "--out", out, "--window", "2.5:4"])
    check(r.returncode == 0 and all(os.path.isfile(os.path.join(out, f"push_x_2.5-4s_{f}.png"))
                                    for f in ("fig8", "fig9", "fig13")), "--window 2.5:4 gives its own PNGs", r)

    check("2 push(es) at 1.00, 3.00 s, no fall" in r.stdout, "the pushes of the full run are reported")
    # A fall by contact is only in the run's summary.json (found next to the CSV by its scenario).
    sub = os.path.join(tmp, "contact_fall")
    os.makedirs(sub)
    full_run(os.path.join(sub, "push_x.csv"))
    with open(os.path.join(sub, "summary.json"), "w") as f:
        json.dump({"scenario": "push_x", "fell": True, "fall_time": 5.5, "fall_reason": "shank contact"}, f)
    r = run_inprocess(plot_scenario.main, [os.path.join(sub, "push_x.csv"), "--out", out])
    check(r.returncode == 0 and "fall at 5.50 s" in r.stdout, "the fall time is taken from summary.json", r)

    r = run_inprocess(plot_scenario.main, [empty, "--out", out])
    check(r.returncode == 0, "plot_scenario on a header-only CSV exits 0", r)
    check(all(os.path.isfile(os.path.join(out, f"empty_{f}.png")) for f in ("fig8", "fig9", "fig13")),
          "a header-only CSV still gives three PNGs")

    odd = os.path.join(tmp, "odd.csv")  # empty and non-numeric fields, a row without a time
    with open(odd, "w") as f:
        f.write("time,com_x,tick_us,l_zmp_meas_x\n0.000,0.1,50,\n0.001,0.1,x,0.01\n,0.1,60,nan\n0.003,0.1,inf,0\n")
    r = run_inprocess(plot_scenario.main, [odd, "--out", out])
    check(r.returncode == 0 and "3 rows" in r.stdout, "odd fields become NaN, a row without a time is skipped", r)

    r = run_inprocess(plot_scenario.main, [os.path.join(tmp, "missing.csv"), "--out", out])
    check(r.returncode == 2 and "missing.csv" in r.stderr, "a missing CSV is a clear error (exit 2)", r)

    # Push and fall detection against the values put in by construction.
    run = plot_scenario.Run(full)
    pushes = plot_scenario.detect_pushes(run)
    check([round(p[0], 3) for p in pushes] == [1.0, 3.0], f"force pushes found at 1 s and 3 s: {pushes}")
    check("+8 N·s" in pushes[0][1] and "+10 N·s" in pushes[1][1], "push impulses are 8 and 10 N·s")
    check(plot_scenario.detect_fall(run) is None, "no fall detected in the full run")
    run = plot_scenario.Run(fall)
    check(run.dropped == 1 and len(run) == 2301, f"falling run: 2301 complete rows, 1 dropped ({len(run)})")
    pushes = plot_scenario.detect_pushes(run)
    check(len(pushes) == 1 and abs(pushes[0][0] - 0.8) < 1e-9 and "+12 N·s" in pushes[0][1],
          f"ball launch found at 0.8 s with 12 N·s: {pushes}")
    check(abs(plot_scenario.detect_fall(run) - 2.3) < 1e-9, "fall detected at the last row (2.3 s)")

    # Moving supports: Fig. 11, 12, 14 only for runs with support_ columns; the 20 Hz low-pass
    # against its closed-form gain 1 / sqrt(1 + (f / 20)^2).
    skate = os.path.join(tmp, "skate_x.csv")
    support_run(skate)
    r = run_inprocess(plot_scenario.main, [skate, "--out", out])
    check(r.returncode == 0, "plot_scenario on a moving-support run exits 0", r)
    check_pngs(out, "skate_x", ("fig8", "fig9", "fig11", "fig12", "fig13", "fig14"))
    check(not os.path.exists(os.path.join(out, "push_x_fig14.png")), "push runs get no Fig. 14")
    run = plot_scenario.Run(skate)
    lp = plot_scenario.low_pass(run.t, run.col("r_foot_vx"))
    g = 1.0 / np.sqrt(1.0 + (1.5 / 20.0) ** 2)
    check(abs(np.max(np.abs(lp[1000:])) - 0.5 * g) < 0.005, f"1.5 Hz passes the 20 Hz low-pass ({np.max(np.abs(lp[1000:])):.4f})")
    lp = plot_scenario.low_pass(run.t, run.col("r_foot_wy"))
    g = 1.0 / np.sqrt(1.0 + (200.0 / 20.0) ** 2)
    check(abs(np.max(np.abs(lp[1000:])) - 0.3 * g) < 0.1 * 0.3 * g,
          f"200 Hz chatter is cut to 1/10 ({np.max(np.abs(lp[1000:])):.4f} vs {0.3 * g:.4f})")

    # Decimation keeps every extreme and NaN gaps.
    t = np.arange(60000) * 1e-3
    y = np.sin(t)
    y[12345] = 7.0
    y[40000] = -5.0
    y[20000:21000] = np.nan
    td, yd = plot_scenario.decimate(t, y)
    check(len(td) <= plot_scenario.MAX_PLOT_POINTS + 100, f"60000 points decimated to {len(td)}")
    check(np.nanmax(yd) == 7.0 and np.nanmin(yd) == -5.0, "decimation keeps the maximum and the minimum")
    check(np.all(np.diff(td) >= 0), "decimated time is monotonic")
    check(np.any(np.isnan(yd[(td > 20.1) & (td < 20.9)])), "decimation keeps the NaN gap")


def main():
    with tempfile.TemporaryDirectory(prefix="hqp_plots_") as tmp:
        test_plots(tmp)
    if FAILURES:
        print(f"{len(FAILURES)} check(s) failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
