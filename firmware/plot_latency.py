#!/usr/bin/env python3
"""Histograms of hqp_rt_loop tick samples (rt_ticks.csv): wake-up latency and compute time,
with cyclictest's latency histograms alongside, and the markdown table of docs/realtime.md.

usage: plot_latency.py OUT.png LABEL=rt_ticks.csv [...] [--cyclictest LABEL=histfile ...]

A cyclictest histogram is the file of `cyclictest -h N --histfile=FILE` (1 µs bins).
"""
import math
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read_ticks(path):
    wake, compute, rt = [], [], True
    with open(path) as f:
        for line in f:
            if line.startswith("#"):
                rt = rt and "NOT RT" not in line
                continue
            if line.startswith("tick"):
                continue
            c = line.split(",")
            wake.append(float(c[1]))
            compute.append(float(c[2]))
    return wake, compute, rt


def read_cyclictest(path):
    """cyclictest --histfile: lines 'us count' (one thread), then '# Avg Latencies', '# Max
    Latencies' and '# Histogram Overflows' (samples beyond the last bin)."""
    us, counts, info = [], [], {}
    with open(path) as f:
        for line in f:
            if line.startswith("#"):
                if ":" in line:
                    k, v = line[1:].split(":", 1)
                    info[k.strip()] = v.strip()
                continue
            c = line.split()
            if len(c) >= 2 and c[0].isdigit():
                us.append(int(c[0]))
                counts.append(int(c[1]))
    return us, counts, info


def quantiles_of_samples(v):
    v = sorted(v)
    q = lambda p: v[min(len(v) - 1, max(0, math.ceil(p * len(v)) - 1))]
    return v[0], sum(v) / len(v), q(0.99), q(0.999), v[-1], len(v)


def quantiles_of_histogram(us, counts, info):
    """Min, mean, p99, p99.9, max: mean and max as cyclictest reports them (the overflows beyond
    the last bin are counted in n; a quantile among them reads '>' the last bin)."""
    over = int(info.get("Histogram Overflows", "0"))
    n = sum(counts) + over
    nz = [u for u, c in zip(us, counts) if c > 0]

    def q(p):
        k, acc = math.ceil(p * n), 0
        for u, c in zip(us, counts):
            acc += c
            if acc >= k:
                return str(u)
        return f"> {us[-1]}"

    return nz[0], float(info["Avg Latencies"]), q(0.99), q(0.999), int(info["Max Latencies"]), n


def table(loops, cyclic):
    """loops: (label, read_ticks(...)); cyclic: (label, read_cyclictest(...))."""
    print("| source | samples | min | mean | p99 | p99.9 | max |")
    print("|---|---|---|---|---|---|---|")
    for label, hist in cyclic:
        mn, mean, p99, p999, mx, n = quantiles_of_histogram(*hist)
        print(f"| cyclictest, {label} | {n} | {mn} | {mean:.0f} | {p99} | {p999} | {mx} |")
    for label, (wake, compute, rt) in loops:
        tag = "" if rt else " (NOT RT)"
        for what, v in (("wake-up", wake), ("compute", compute)):
            mn, mean, p99, p999, mx, n = quantiles_of_samples(v)
            print(f"| rt_loop {what}, {label}{tag} | {n} | {mn:.1f} | {mean:.1f} | {p99:.1f} | {p999:.1f} | {mx:.1f} |")


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    out, loops, cyclic, target = argv[1], [], [], None
    for a in argv[2:]:
        if a == "--cyclictest":
            target = cyclic
            continue
        label, path = a.split("=", 1)
        (target if target is not None else loops).append((label, path))
    # Each file read once (a 60 000-tick log is a few MB).
    loops = [(label, read_ticks(path)) for label, path in loops]
    cyclic = [(label, read_cyclictest(path)) for label, path in cyclic]
    table(loops, cyclic)
    fig, (ax_w, ax_c) = plt.subplots(1, 2, figsize=(12, 4.5))
    # Log-spaced bins for both panels: on a shared VM the tails (vCPU stalls) span three to four
    # decades, which linear bins would squeeze the body of the distribution into one bin beside.
    top = 1.0
    for label, (wake, compute, _) in loops:
        top = max(top, max(wake), max(compute))
    for label, (_, _, info) in cyclic:
        top = max(top, float(info["Max Latencies"]))
    edges = [10 ** (k / 40.0) for k in range(0, int(40 * math.log10(top)) + 2)]
    for label, (wake, compute, rt) in loops:
        tag = "" if rt else " (NOT RT)"
        ax_w.hist(wake, bins=edges, histtype="step", log=True, label=f"rt_loop {label}{tag}")
        ax_c.hist(compute, bins=edges, histtype="step", log=True, label=f"{label}{tag}")
    for label, (us, counts, _) in cyclic:  # 1 µs bins, regrouped into the same edges
        regrouped = [0] * (len(edges) - 1)
        for u, c in zip(us, counts):
            for k in range(len(edges) - 1):
                if edges[k] <= u + 0.5 < edges[k + 1]:
                    regrouped[k] += c
                    break
        ax_w.stairs(regrouped, edges, label=f"cyclictest {label} (overflows beyond 2 ms not drawn)")
    ax_w.set_xscale("log")
    ax_w.set_yscale("log")
    ax_w.set_xlabel("wake-up latency (µs)")
    ax_w.set_ylabel("ticks")
    ax_w.set_title("Wake-up latency at 1 kHz")
    ax_w.legend(fontsize=8)
    ax_c.set_xscale("log")
    ax_c.set_xlabel("Controller::tick compute time (µs)")
    ax_c.set_ylabel("ticks")
    ax_c.set_title("Compute time per tick")
    ax_c.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
