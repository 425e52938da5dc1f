#!/usr/bin/python3
"""A plot like Fig. 7 of the paper from a torque-prediction CSV.

Reads the CSV that `hqp_identification_rig` (rig_validation_torques.csv) and
`hqp_identify --predict` write: a `time` column, then per joint `tau_<joint>`
(measured), `tau_id_<joint>` (identified base parameters) and `tau_cad_<joint>`
(CAD model). Draws one panel per joint (by default the left leg, joints whose
name starts with `l_`) with the three torques over time, and the RMS error of
both models against the measured torque in each panel's title.

    /usr/bin/python3 tools/plot_identification.py rig_validation_torques.csv -o fig7.png

Needs matplotlib (Debian: python3-matplotlib) and numpy.
"""

import argparse
import csv
import math
import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def read_prediction(path):
    """Returns (time, {joint: (measured, identified, cad)}) with the joints in file order."""
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    if len(rows) < 3:
        sys.exit(f"{path}: needs a header and at least two samples")
    header = rows[0]
    try:
        data = np.array([[float(x) for x in r] for r in rows[1:]])
    except ValueError as e:
        sys.exit(f"{path}: not a number ({e})")
    if data.shape[1] != len(header):
        sys.exit(f"{path}: {len(header)} header fields but {data.shape[1]} values per line")
    col = {name: i for i, name in enumerate(header)}
    if "time" not in col:
        sys.exit(f"{path}: no 'time' column")
    joints = [h[len("tau_id_"):] for h in header if h.startswith("tau_id_")]
    out = {}
    for j in joints:
        names = ("tau_" + j, "tau_id_" + j, "tau_cad_" + j)
        missing = [n for n in names if n not in col]
        if missing:
            sys.exit(f"{path}: missing column(s) {', '.join(missing)}")
        out[j] = tuple(data[:, col[n]] for n in names)
    if not out:
        sys.exit(f"{path}: no tau_id_<joint> columns")
    return data[:, col["time"]], out


def rms(e):
    return float(np.sqrt(np.mean(np.square(e))))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv", help="torque prediction CSV (time, tau_*, tau_id_*, tau_cad_*)")
    ap.add_argument("-o", "--out", default="fig7.png", help="output image (PNG, SVG or PDF by extension)")
    ap.add_argument("--prefix", default="l_", help="plot the joints whose name starts with this ('' = all)")
    ap.add_argument("--columns", type=int, default=2, help="panels per row")
    ap.add_argument("--title", default="Validation trajectory: joint torques of the left leg",
                    help="figure title")
    ap.add_argument("--dpi", type=int, default=130)
    args = ap.parse_args()

    t, joints = read_prediction(args.csv)
    names = [j for j in joints if j.startswith(args.prefix)]
    if not names:
        sys.exit(f"{args.csv}: no joint starts with '{args.prefix}' (joints: {', '.join(joints)})")
    cols = max(1, min(args.columns, len(names)))
    rows = math.ceil(len(names) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(6.2 * cols, 2.6 * rows + 0.8), sharex=True,
                             squeeze=False)
    for ax, j in zip(axes.flat, names):
        measured, ident, cad = joints[j]
        ax.plot(t, measured, color="tab:red", linestyle=":", linewidth=0.8, alpha=0.7, label="measured")
        ax.plot(t, ident, color="tab:blue", linewidth=1.3, label="identified (base parameters)")
        ax.plot(t, cad, color="black", linestyle="--", linewidth=1.0, label="CAD model (URDF, no friction)")
        ax.set_title(f"{j}   RMS error vs measured: identified {rms(ident - measured):.2f} N·m, "
                     f"CAD {rms(cad - measured):.2f} N·m", fontsize=9)
        ax.set_ylabel("torque (N·m)")
        ax.grid(True, alpha=0.3)
        ax.margins(x=0)
    for ax in axes.flat[len(names):]:
        ax.set_visible(False)
    for c in range(cols):
        # the lowest visible panel of each column carries the time axis
        for r in reversed(range(rows)):
            if r * cols + c < len(names):
                axes[r][c].set_xlabel("time (s)")
                axes[r][c].tick_params(labelbottom=True)
                break
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper center", ncol=3, frameon=False, bbox_to_anchor=(0.5, 0.965))
    fig.suptitle(args.title, y=0.995)
    fig.tight_layout(rect=(0, 0, 1, 0.93))
    fig.savefig(args.out, dpi=args.dpi)
    print(f"wrote {args.out} ({len(names)} joints)")


if __name__ == "__main__":
    main()
