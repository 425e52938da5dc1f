#!/usr/bin/env python3
"""Survivable skateboard envelope: the largest right-board peak velocity Walker3 survives along each
axis, against the board's frequency (docs/scenarios.md, "Skateboard envelope").

    /usr/bin/python3 tools/skate_envelope.py [--sim build/sim_demo/sim_demo] [--out out/skate_envelope]
        [--axes x,y,z,roll,pitch,yaw] [--frequencies 0.5,1,1.5,2,3] [--jobs 2] [-- extra sim_demo args]

For each (axis, frequency) it runs `sim_demo --scenario skate_sweep --set sweep_directions=AXIS
--set sweep_frequency=F` (a bisection on the amplitude, with the scenario's pass rules), several at
a time, then writes envelope.json, envelope.md (with the peak acceleration A (2 pi f)^2 of each
largest survived motion: what a hand must produce) and envelope.png (one panel per axis, the paper's
peak as a dashed line, lines of constant peak acceleration dotted).
"""
import argparse
import concurrent.futures as cf
import json
import math
import os
import subprocess
import sys

PAPER = {"x": 0.94, "y": 0.89, "z": 0.47, "roll": 1.8, "pitch": 1.4, "yaw": 0.5}


def run_one(sim, out, axis, f, extra):
    d = os.path.join(out, "runs", "%s_%g" % (axis, f))
    os.makedirs(d, exist_ok=True)
    cmd = [sim, "--scenario", "skate_sweep", "--no-video", "--no-plots", "--out", d,
           "--set", "sweep_directions=" + axis, "--set", "sweep_frequency=%g" % f] + extra
    with open(os.path.join(d, "log.txt"), "w") as log:
        subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT, check=False)
    try:
        with open(os.path.join(d, "summary.json")) as fh:
            rec = json.load(fh)[0]
        dd = rec["directions"][0]
        return {"axis": axis, "frequency_hz": f, "largest_survived": dd["largest_passed"],
                "first_failure": dd["smallest_failed"], "unit": dd["unit"]}
    except (OSError, ValueError, KeyError, IndexError):
        return {"axis": axis, "frequency_hz": f, "error": "no summary; see " + os.path.join(d, "log.txt")}


def main():
    argv = sys.argv[1:]
    extra = []
    if "--" in argv:
        i = argv.index("--")
        argv, extra = argv[:i], argv[i + 1:]
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sim", default="build/sim_demo/sim_demo")
    ap.add_argument("--out", default="out/skate_envelope")
    ap.add_argument("--axes", default="x,y,z,roll,pitch,yaw")
    ap.add_argument("--frequencies", default="0.5,1,1.5,2,3")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    a = ap.parse_args(argv)
    axes = a.axes.split(",")
    freqs = [float(x) for x in a.frequencies.split(",")]
    for ax in axes:
        if ax not in PAPER:
            ap.error("unknown axis %r (expected %s)" % (ax, ", ".join(PAPER)))
    os.makedirs(a.out, exist_ok=True)
    jobs = [(ax, f) for ax in axes for f in freqs]
    results = []
    with cf.ThreadPoolExecutor(max_workers=max(1, a.jobs)) as ex:
        futs = [ex.submit(run_one, a.sim, a.out, ax, f, extra) for ax, f in jobs]
        for k, fu in enumerate(cf.as_completed(futs), 1):
            results.append(fu.result())
            print("  skate envelope: %d / %d sweeps done" % (k, len(jobs)), flush=True)
    results.sort(key=lambda r: (axes.index(r["axis"]), r["frequency_hz"]))
    for r in results:
        if "largest_survived" in r:
            w = 2 * math.pi * r["frequency_hz"]
            r["peak_acceleration"] = r["largest_survived"] * w
            r["amplitude"] = r["largest_survived"] / w
    with open(os.path.join(a.out, "envelope.json"), "w") as fh:
        json.dump({"paper_peak": PAPER, "results": results}, fh, indent=2)
    lines = ["| axis | frequency (Hz) | largest peak velocity survived | amplitude | peak acceleration | paper's peak |",
             "|---|---|---|---|---|---|"]
    for r in results:
        if "largest_survived" not in r:
            lines.append("| %s | %g | error: %s | | | |" % (r["axis"], r["frequency_hz"], r["error"]))
            continue
        lin = len(r["axis"]) == 1
        # No failure up to the sweep's bracket end (sweep_max x the paper's peak): a lower bound.
        bound = "≥ " if r.get("first_failure") is None else ""
        lines.append("| %s | %g | %s%.2f %s | %.3f %s | %.1f %s | %.2f |" % (
            r["axis"], r["frequency_hz"], bound, r["largest_survived"], r["unit"], r["amplitude"], "m" if lin else "rad",
            r["peak_acceleration"], "m/s²" if lin else "rad/s²", PAPER[r["axis"]]))
    with open(os.path.join(a.out, "envelope.md"), "w") as fh:
        fh.write("\n".join(lines) + "\n")
    print("\n".join(lines))
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("no matplotlib: envelope.png skipped")
        return 0
    fig, axs = plt.subplots(2, 3, figsize=(12, 6.5), squeeze=False)
    for i, ax in enumerate(axes):
        p = axs[i // 3][i % 3]
        rs = [r for r in results if r["axis"] == ax and "largest_survived" in r]
        fs = [r["frequency_hz"] for r in rs]
        p.plot(fs, [r["largest_survived"] for r in rs], "o-", label="survived (largest)")
        p.axhline(PAPER[ax], ls="--", color="k", lw=1, label="paper's peak")
        top = max([PAPER[ax] * 1.6] + [r["largest_survived"] * 1.1 for r in rs])
        fmax = max(fs + [1.0]) * 1.1
        fgrid = [fmax * k / 100.0 for k in range(3, 101)]
        for acc in (5.0, 10.0, 20.0):
            p.plot(fgrid, [acc / (2 * math.pi * f) for f in fgrid], ":", color="gray", lw=0.8)
            y = acc / (2 * math.pi * fmax)
            if y < top:
                p.text(fmax, y, "%g " % acc, fontsize=7, color="gray", va="bottom", ha="right")
        bounded = [r for r in rs if r.get("first_failure") is None]
        if bounded:  # no failure up to the sweep's bracket end: a lower bound
            p.plot([r["frequency_hz"] for r in bounded], [r["largest_survived"] for r in bounded], "^",
                   mfc="white", color="C0", label="no failure up to the bracket end")
        p.set_ylim(0, top)
        p.set_xlim(0, fmax)
        unit = "m/s" if len(ax) == 1 else "rad/s"
        p.set_title("%s (dotted: peak acceleration, %s²)" % (ax, "m/s" if len(ax) == 1 else "rad/s"), fontsize=9)
        p.set_xlabel("board frequency (Hz)", fontsize=8)
        p.set_ylabel("peak velocity (%s)" % unit, fontsize=8)
        if i == 0:
            p.legend(fontsize=7)
    for j in range(len(axes), 6):
        axs[j // 3][j % 3].set_visible(False)
    fig.suptitle("Walker3: largest right-board peak velocity survived vs frequency (pass rules on)", fontsize=10)
    fig.tight_layout()
    png = os.path.join(a.out, "envelope.png")
    fig.savefig(png, dpi=120)
    print("envelope: %s/envelope.md, envelope.json, %s" % (a.out, png))
    return 0


if __name__ == "__main__":
    sys.exit(main())
