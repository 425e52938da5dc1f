#!/usr/bin/python3
"""Plot of a friction_ablation run (docs/scenarios.md, "Friction-compensation ablation").

    plot_ablation.py ABLATION.json --out FILE.png [--window T]

ABLATION.json is the record sim_demo writes (DIR/ablation.json): its runs, each with a variant and
the path of its CSV. One row of panels per base scenario:
  (a) joint torque tracking error tau_opt - delivered, RMS over ticks and joints per variant
      (bars), the knees' RMS (diamonds) and the RMS at the links, rotor inertia off too (bars -);
  (b) ZMP tracking error (measured - optimized), RMS per foot and variant (bars);
  (c) the torque tracking error over time: RMS over the joints, then a moving RMS over
      --window s (default 0.2 s), one line per variant, pushes dotted.
A run that fell is hatched in (a), (b) and ends with an x in (c). Prints the PNG path.
Needs only numpy and matplotlib (Agg); reads the CSVs with plot_scenario.Run.
"""
import argparse
import json
import os
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import plot_scenario  # noqa: E402

DPI = 150
COLORS = {"on": "tab:green", "off": "tab:red", "low": "tab:orange", "high": "tab:purple", "config": "tab:blue",
          "on_kdq0": "tab:olive", "off_kdq0": "tab:brown"}


def moving_rms(t, e, window):
    """sqrt of the mean of e^2 over the trailing `window` seconds (fewer samples at the start);
    NaN samples count as absent."""
    e = np.asarray(e, dtype=float)
    if len(e) == 0:
        return e
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    n = max(1, int(round(window / dt)))
    ok = np.isfinite(e)
    sq = np.concatenate(([0.0], np.cumsum(np.where(ok, e * e, 0.0))))
    cnt = np.concatenate(([0], np.cumsum(ok)))
    i = np.arange(1, len(e) + 1)
    lo = np.maximum(i - n, 0)
    num = sq[i] - sq[lo]
    den = cnt[i] - cnt[lo]
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.sqrt(np.maximum(num, 0.0) / den)
    out[den == 0] = np.nan
    return out


def joint_rms(run):
    """RMS over the joints of the tau_err_* columns per tick (None without them)."""
    cols = [n for n in run.names if n.startswith("tau_err_")]
    if not cols:
        return None
    e = np.column_stack([run.col(c) for c in cols])
    with np.errstate(invalid="ignore"):
        return np.sqrt(np.mean(e * e, axis=1))


def csv_of(rec, json_path):
    path = rec.get("files", {}).get("csv", "")
    if path and not os.path.isabs(path) and not os.path.exists(path):
        path = os.path.join(os.path.dirname(json_path), path)
    return path


def number(x):
    return float(x) if isinstance(x, (int, float)) else float("nan")


def bars(ax, variants, values, fell, ylabel, title, markers=None, marker_label=None, width=0.8, offset=0.0,
         alpha=1.0, label=None):
    x = np.arange(len(variants)) + offset
    colors = [COLORS.get(v, "gray") for v in variants]
    b = ax.bar(x, values, width=width, color=colors, alpha=alpha, edgecolor="black", lw=0.5, label=label)
    for rect, f in zip(b, fell):
        if f:
            rect.set_hatch("///")
    if markers is not None:
        ax.plot(x, markers, "kD", ms=4, label=marker_label)
    ax.set_xticks(np.arange(len(variants)))
    ax.set_xticklabels(variants, rotation=30, ha="right", fontsize=8)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10, loc="left")
    ax.grid(axis="y", alpha=0.3)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("json", help="ablation.json written by sim_demo --scenario friction_ablation")
    ap.add_argument("--out", required=True, help="PNG to write")
    ap.add_argument("--window", type=float, default=0.2, help="moving-RMS window of panel (c), s")
    a = ap.parse_args(argv)
    with open(a.json) as f:
        rec = json.load(f)
    runs = rec.get("runs", [])
    if not runs:
        print(f"{a.json}: no runs", file=sys.stderr)
        return 2
    scenarios = []
    for r in runs:
        if r["scenario"] not in scenarios:
            scenarios.append(r["scenario"])
    fig, axes = plt.subplots(len(scenarios), 3, figsize=(16, 4.9 * len(scenarios)), squeeze=False,
                             gridspec_kw={"width_ratios": [1, 1, 2.2]})
    for row, scen in enumerate(scenarios):
        rs = [r for r in runs if r["scenario"] == scen]
        variants = [r["variant"] for r in rs]
        fell = [bool(r.get("fell")) for r in rs]
        tau = [number(r.get("torque_tracking_rms_Nm")) for r in rs]
        knees = [np.sqrt(np.nanmean([number(r.get("torque_tracking_rms_joint_Nm", {}).get(k)) ** 2
                                     for k in ("l_knee", "r_knee")])) for r in rs]
        link = [number(r.get("torque_tracking_link_rms_Nm")) for r in rs]
        ax = axes[row][0]
        bars(ax, variants, tau, fell, "N·m", f"(a) {scen}: torque tracking RMS", markers=knees,
             marker_label="knees")
        ax.plot(np.arange(len(variants)), link, "k_", ms=22, mew=2, label="at the links (rotor inertia off)")
        ax.legend(fontsize=7, loc="best")
        ax = axes[row][1]
        for k, (foot, off) in enumerate((("left", -0.2), ("right", 0.2))):
            z = [number(r["feet"][k].get("zmp_tracking_rms_mm")) if len(r.get("feet", [])) > k else np.nan for r in rs]
            bars(ax, variants, z, fell, "mm", f"(b) {scen}: ZMP tracking RMS (L | R)", width=0.38, offset=off,
                 alpha=1.0 if foot == "left" else 0.55)
        ax = axes[row][2]
        pushes = []
        for r, v, f in zip(rs, variants, fell):
            path = csv_of(r, a.json)
            if not path or not os.path.exists(path):
                continue
            run = plot_scenario.Run(path)
            e = joint_rms(run)
            if e is None or len(run) == 0:
                continue
            m = moving_rms(run.t, e, a.window)
            plot_scenario.plot_line(ax, run.t, m, color=COLORS.get(v, "gray"), lw=0.9,
                                    label=f"{v} (RMS {number(r.get('torque_tracking_rms_Nm')):.2f} N·m)"
                                    + (" fell" if f else ""))
            if f:
                ax.plot([run.t[-1]], [m[-1]], "x", color=COLORS.get(v, "gray"), ms=9, mew=2)
            if not pushes:
                pushes = plot_scenario.detect_pushes(run)
        plot_scenario.mark_events(ax, pushes, None)
        ax.set_xlabel("time (s)")
        ax.set_ylabel("N·m")
        ax.set_yscale("log")
        ax.set_title(f"(c) {scen}: |tau_opt - delivered| over the joints, moving RMS {a.window:g} s", fontsize=10,
                     loc="left")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=4, frameon=False)
    fig.suptitle(f"Friction-compensation ablation ({rec.get('controller', '?')}): "
                 "on = k_f 1 with the plant's F_c, F_v; off = k_f 0; low / high = model 30 % below / above; "
                 "config = controller.yaml; _kdq0 = without eq. 8", fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    fig.savefig(a.out, dpi=DPI)
    plt.close(fig)
    print(a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
