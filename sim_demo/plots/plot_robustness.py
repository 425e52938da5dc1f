#!/usr/bin/env python3
"""Heatmap of a robustness matrix (sim_demo --scenario robustness writes robustness.json).

    /usr/bin/python3 sim_demo/plots/plot_robustness.py robustness.json --out robustness.png

One panel per controller: rows are experiments, columns perturbations, the colour the pass rate
(red 0 .. green 1), the text the passed/total runs and the cell's margin (largest push or board
velocity survived), if it has one.
"""
import argparse
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("json")
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    with open(a.json) as f:
        rec = json.load(f)
    exps = [e["name"] for e in rec["experiments"]]
    perts = [p["name"] for p in rec["perturbations"]]
    ctrls = rec["controllers"]
    cells = {(c["controller"], c["experiment"], c["perturbation"]): c for c in rec["cells"]}
    fig, axes = plt.subplots(1, len(ctrls), figsize=(1.6 * len(perts) * len(ctrls) + 3, 0.42 * len(exps) + 2.2),
                             squeeze=False)
    for ax, ctrl in zip(axes[0], ctrls):
        rate = np.full((len(exps), len(perts)), np.nan)
        for i, e in enumerate(exps):
            for j, p in enumerate(perts):
                c = cells.get((ctrl, e, p))
                if c is None or c["total"] == 0:
                    continue
                rate[i, j] = c["pass_rate"]
                text = "%d/%d" % (c["passed"], c["total"])
                m = c.get("margin")
                if isinstance(m, dict) and "value" in m:
                    text += "\n%.2f %s" % (m["value"], m["unit"])
                ax.text(j, i, text, ha="center", va="center", fontsize=7)
        ax.imshow(rate, cmap="RdYlGn", vmin=0.0, vmax=1.0, aspect="auto", alpha=0.6)
        ax.set_xticks(range(len(perts)))
        ax.set_xticklabels(perts, rotation=30, ha="right", fontsize=8)
        ax.set_yticks(range(len(exps)))
        ax.set_yticklabels(exps if ax is axes[0][0] else [], fontsize=8)
        ax.set_title("%s: pass rate over seeds%s" % (ctrl.upper(), " (noise on)" if rec.get("noise") else ""), fontsize=9)
    fig.suptitle("Walker3 robustness matrix (margin: largest push or board velocity survived)", fontsize=10)
    fig.tight_layout()
    fig.savefig(a.out, dpi=130)
    print("robustness heatmap: %d experiments x %d perturbations x %d controllers -> %s"
          % (len(exps), len(perts), len(ctrls), a.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
