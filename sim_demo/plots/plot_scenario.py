#!/usr/bin/python3
"""Plots of one sim_demo run (docs/simulation.md lists the CSV columns).

Writes, for RUN.csv with stem S:
  DIR/S_fig8.png   right-foot pitch, CoM x, torso pitch over time with the pushes (paper Fig. 8)
  DIR/S_fig9.png   measured vs optimized ZMP per foot in the sole frame, and the lowest-level
                   task error ||A x - b||^2 on a log axis (paper Fig. 9)
  DIR/S_fig13.png  controller compute time per tick and its histogram (paper Fig. 13)
and for runs on moving supports (the CSV has support_<axis> columns):
  DIR/S_fig11.png  right-foot orientation and angular velocity, low-passed at 20 Hz (paper Fig. 11)
  DIR/S_fig12.png  right-foot measured ZMP x and y in the sole frame (paper Fig. 12)
  DIR/S_fig14.png  right-foot linear and angular velocity, low-passed at 20 Hz (paper Fig. 14)

Every column except `time` is optional: what is missing is drawn as a "not logged" panel.
Needs only numpy and matplotlib (Agg).
"""
import argparse
import json
import math
import os
import sys
import warnings

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend choice)

DPI = 150
TICK_BUDGET_US = 1000.0  # 1 kHz loop
MAX_PLOT_POINTS = 4000   # per line, after min/max decimation
# The simulation stops below 0.6 m or beyond 1 rad of tilt (docs/simulation.md, "Fall"), but the
# last row is logged before the step that crossed: test the last row with some margin.
FALL_TORSO_Z = 0.65
FALL_ANGLE = 0.8
PUSH_COLOR = "tab:red"
FALL_COLOR = "black"


# ---- reading --------------------------------------------------------------------------------------

class Run:
    """The columns of one CSV as float arrays; `col(name)` is None when a column is absent."""

    def __init__(self, path):
        self.path = path
        with open(path, "r") as f:
            header = f.readline().strip()
            lines = f.read().splitlines()
        if not header:
            raise ValueError(f"{path}: empty file")
        self.names = [h.strip() for h in header.split(",")]
        self.index = {n: i for i, n in enumerate(self.names)}
        if "time" not in self.index:
            raise ValueError(f"{path}: no 'time' column in the header")
        # A run killed mid-write can leave a partial last line: keep complete rows only.
        commas = len(self.names) - 1
        rows = [ln for ln in lines if ln.count(",") == commas]
        self.dropped = len(lines) - len(rows) - sum(1 for ln in lines if not ln.strip())
        if rows:
            # numpy's C reader; 'nan' parses to NaN. Malformed numbers also become NaN.
            try:
                self.data = np.loadtxt(rows, delimiter=",", dtype=float, ndmin=2)
            except ValueError:
                self.data = np.genfromtxt(rows, delimiter=",", dtype=float).reshape(len(rows), -1)  # slow, tolerant
        else:
            self.data = np.zeros((0, len(self.names)))
        ok = np.isfinite(self.data[:, self.index["time"]])  # a row without a time cannot be placed
        self.dropped += int((~ok).sum())
        self.data = self.data[ok]
        self.t = self.data[:, self.index["time"]]
        self.full = self.data

    def first(self, name):
        """First finite value of a column over the whole run (t0 reference, also inside a window)."""
        c = self.full[:, self.index[name]] if name in self.index else np.zeros(0)
        i = np.flatnonzero(np.isfinite(c))
        return float(c[i[0]]) if len(i) else float("nan")

    def window(self, t0, t1):
        """Keeps the rows with t0 <= time <= t1 (for plotting a time window)."""
        keep = (self.t >= t0) & (self.t <= t1)
        self.data = self.data[keep]
        self.t = self.t[keep]

    def __len__(self):
        return self.data.shape[0]

    def has(self, name):
        return name in self.index

    def col(self, name):
        i = self.index.get(name)
        return None if i is None else self.data[:, i]

    def levels(self):
        """Level numbers N with a `levelN_residual` column, ascending."""
        out = []
        for n in self.names:
            if n.startswith("level") and n.endswith("_residual"):
                try:
                    out.append(int(n[len("level"):-len("_residual")]))
                except ValueError:
                    pass
        return sorted(out)


# ---- helpers --------------------------------------------------------------------------------------

def decimate(t, y, max_points=MAX_PLOT_POINTS):
    """Min/max envelope decimation: keeps every peak (unlike plain striding), keeps NaN gaps."""
    n = len(t)
    if n <= max_points:
        return t, y
    k = int(math.ceil(n / (max_points / 2)))
    nb = n // k
    m = nb * k
    tb = t[:m].reshape(nb, k)
    yb = y[:m].reshape(nb, k)
    all_nan = np.all(np.isnan(yb), axis=1)
    imin = np.argmin(np.where(np.isnan(yb), np.inf, yb), axis=1)
    imax = np.argmax(np.where(np.isnan(yb), -np.inf, yb), axis=1)
    first = np.minimum(imin, imax)
    second = np.maximum(imin, imax)
    r = np.arange(nb)
    t2 = np.column_stack((tb[r, first], tb[r, second])).ravel()
    y2 = np.column_stack((yb[r, first], yb[r, second])).ravel()
    y2[np.repeat(all_nan, 2)] = np.nan
    if m < n:
        t2 = np.concatenate((t2, t[m:]))
        y2 = np.concatenate((y2, y[m:]))
    return t2, y2


def plot_line(ax, t, y, **kw):
    td, yd = decimate(t, y)
    return ax.plot(td, yd, **kw)


def finite_extreme(t, y, mode):
    """(time, value) of the max, min or max-|.| of y ignoring NaN; None if nothing is finite."""
    ok = np.isfinite(y)
    if not np.any(ok):
        return None
    yy = np.where(ok, y, np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        if mode == "max":
            i = int(np.nanargmax(yy))
        elif mode == "min":
            i = int(np.nanargmin(yy))
        else:
            i = int(np.nanargmax(np.abs(yy)))
    return float(t[i]), float(y[i])


def annotate_point(ax, tv, text, color, above=True):
    """Marks a point and labels it; the label goes left of points in the right third of the axes."""
    if tv is None:
        return
    t, v = tv
    x0, x1 = ax.get_xlim()
    left = x1 > x0 and (t - x0) / (x1 - x0) > 0.66
    ax.plot([t], [v], marker="o", ms=4, color=color, zorder=5)
    ax.annotate(text, xy=(t, v), xytext=(-8 if left else 8, 6 if above else -6), textcoords="offset points",
                ha="right" if left else "left", va="bottom" if above else "top", fontsize=8, color=color,
                bbox=dict(boxstyle="round,pad=0.2", fc="white", ec=color, lw=0.5, alpha=0.85), zorder=6)


def not_logged(ax, what):
    ax.set_yticks([])
    ax.text(0.5, 0.5, f"{what}: not logged", transform=ax.transAxes, ha="center", va="center",
            fontsize=11, color="gray", style="italic")


def segments(mask):
    """(start, end) index pairs of the runs of True in a boolean array (end exclusive)."""
    if len(mask) == 0:
        return []
    m = np.concatenate(([False], mask.astype(bool), [False]))
    d = np.diff(m.astype(np.int8))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def detect_pushes(run):
    """[(time, label)] from the applied push force (impulse = its integral) or a ball launch
    (the ball's momentum magnitude jumps up within one tick: only a launch does that)."""
    t = run.t
    out = []
    f = [run.col(c) for c in ("push_fx", "push_fy", "push_fz")]
    if any(c is not None for c in f) and len(t) > 1:
        fv = np.column_stack([c if c is not None else np.zeros_like(t) for c in f])
        fv = np.nan_to_num(fv)
        on = np.linalg.norm(fv, axis=1) > 1e-9
        dt = np.diff(t, append=t[-1] + (t[-1] - t[-2]))
        for a, b in segments(on):
            imp = (fv[a:b] * dt[a:b, None]).sum(axis=0)
            out.append((float(t[a]), impulse_label(imp)))
    p = [run.col(c) for c in ("ball_px", "ball_py", "ball_pz")]
    if all(c is not None for c in p) and len(t) > 1:
        pv = np.nan_to_num(np.column_stack(p))
        mag = np.linalg.norm(pv, axis=1)
        jumps = np.flatnonzero(np.diff(mag) > 1.0) + 1  # > 1 N*s in one tick; gravity adds 0.05
        last = -np.inf
        for i in jumps:
            if t[i] - last > 0.05:  # one launch may span two ticks
                out.append((float(t[i]), "ball " + impulse_label(pv[i])))
            last = t[i]
    return sorted(out)


def impulse_label(v):
    v = np.asarray(v, dtype=float)
    big = [f"{name} {val:+.3g}" for name, val in zip("xyz", v) if abs(val) >= 0.05 * max(np.abs(v).max(), 1e-12)]
    return (", ".join(big) + " N·s") if big else "push"


def detect_fall(run):
    """Time of the last row if it nearly meets the simulation's fall criteria (torso low or tilted)."""
    if len(run) == 0:
        return None
    last = run.data[-1]
    z = last[run.index["torso_z"]] if run.has("torso_z") else np.nan
    pitch = last[run.index["torso_pitch"]] if run.has("torso_pitch") else np.nan
    roll = last[run.index["torso_roll"]] if run.has("torso_roll") else np.nan
    if (np.isfinite(z) and z < FALL_TORSO_Z) or (np.isfinite(pitch) and abs(pitch) > FALL_ANGLE) or \
            (np.isfinite(roll) and abs(roll) > FALL_ANGLE):
        return float(run.t[-1])
    return None


def mark_events(ax, pushes, fall_time, label=False):
    for i, (tp, text) in enumerate(pushes):
        ax.axvline(tp, color=PUSH_COLOR, lw=0.8, ls=":", alpha=0.8,
                   label="push" if (label and i == 0) else None)
    if fall_time is not None:
        ax.axvline(fall_time, color=FALL_COLOR, lw=1.2, ls="-.", label="fall (run ends)" if label else None)


def label_pushes(ax, pushes):
    """Push labels as ticks of a secondary x axis on top of the panel (they never hide data)."""
    if not pushes:
        return
    top = ax.secondary_xaxis("top")
    top.set_xticks([p[0] for p in pushes])
    dense = len(pushes) > 10
    top.set_xticklabels([p[1] for p in pushes], fontsize=7, color=PUSH_COLOR,
                        rotation=30 if dense else 0, ha="left" if dense else "center")
    top.tick_params(axis="x", colors=PUSH_COLOR, length=3, pad=1)
    ax.set_title(ax.get_title(loc="left"), fontsize=10, loc="left", pad=16 if not dense else 30)


def finish(fig, path):
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    print(path)


def time_axis(ax, run, fall_time):
    """x limits from the data (a little room after a fall so that its marker shows)."""
    if len(run):
        t0, t1 = float(run.t[0]), float(run.t[-1])
        t1 = max(t1, t0 + 1e-3)
        ax.set_xlim(t0, t1 + (0.03 * (t1 - t0) if fall_time is not None else 0.0))


def side_legend(ax):
    """Legend outside the axes on the right: it never hides a curve or an annotation."""
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, borderaxespad=0.0)


def suptitle(fig, title, what, run, fall_time):
    dur = f"t = {run.t[0]:.2f} … {run.t[-1]:.2f} s" if len(run) else "no data"
    end = f", FELL at {fall_time:.2f} s" if fall_time is not None else ""
    fig.suptitle(f"{title}: {what}  ({dur}{end})", fontsize=12)


# ---- Fig. 8: foot pitch, CoM x, torso pitch -------------------------------------------------------

def plot_angle(ax, t, y, color, label, note):
    """An angle (deg) with its largest magnitude annotated; note takes (|max|, time)."""
    plot_line(ax, t, y, color=color, lw=1.0, label=label)
    m = finite_extreme(t, y, "abs")
    annotate_point(ax, m, note.format(abs(m[1]), m[0]) if m else "", color)


def fig8(run, out, title, pushes, fall_time):
    fig, axes = plt.subplots(3, 1, figsize=(11, 8.5), sharex=True)
    t = run.t
    deg = 180.0 / math.pi
    time_axis(axes[0], run, fall_time)

    ax = axes[0]
    rp, lp = run.col("r_foot_pitch"), run.col("l_foot_pitch")
    rr = run.col("r_foot_roll")
    if rp is None and lp is None:
        not_logged(ax, "foot pitch (r_foot_pitch)")
    else:
        if rp is not None:
            plot_angle(ax, t, rp * deg, "tab:blue", "right foot pitch", "max |pitch| {:.2f}° at {:.2f} s")
        if lp is not None:
            plot_line(ax, t, lp * deg, color="tab:cyan", lw=0.7, alpha=0.8, label="left foot pitch")
        if rr is not None:
            plot_line(ax, t, rr * deg, color="tab:purple", lw=0.7, ls="--", alpha=0.8, label="right foot roll")
        if rp is None:
            ax.text(0.01, 0.95, "right foot pitch: not logged", transform=ax.transAxes, fontsize=8,
                    color="gray", va="top")
    ax.set_ylabel("foot angle (deg)")
    ax.set_title("(a) right foot pitch in the world (left foot thin, roll dashed)", fontsize=10, loc="left")

    ax = axes[1]
    cx = run.col("com_x")
    if cx is None or len(t) == 0 or not np.any(np.isfinite(cx)):
        not_logged(ax, "CoM x (com_x)")
    else:
        ref = run.first("com_x")
        dx = (cx - ref) * 1000.0
        plot_line(ax, t, dx, color="tab:green", lw=1.0, label="CoM x − CoM x(t₀)")
        hi, lo = finite_extreme(t, dx, "max"), finite_extreme(t, dx, "min")
        annotate_point(ax, hi, f"max {hi[1]:+.1f} mm at {hi[0]:.2f} s", "tab:green")
        annotate_point(ax, lo, f"min {lo[1]:+.1f} mm at {lo[0]:.2f} s", "darkgreen", above=False)
    cy = run.col("com_y")
    if cy is not None and len(t) and np.any(np.isfinite(cy)):
        ref = run.first("com_y")
        plot_line(ax, t, (cy - ref) * 1000.0, color="olive", lw=0.7, ls="--", alpha=0.8,
                  label="CoM y − CoM y(t₀)")
    ax.set_ylabel("CoM rel. t₀ (mm)")
    ax.set_title("(b) CoM position along x (y dashed)", fontsize=10, loc="left")

    ax = axes[2]
    tp, tr = run.col("torso_pitch"), run.col("torso_roll")
    if tp is None and tr is None:
        not_logged(ax, "torso pitch (torso_pitch)")
    else:
        if tp is not None:
            plot_angle(ax, t, tp * deg, "tab:orange", "torso pitch", "max |pitch| {:.2f}° at {:.2f} s")
        if tr is not None:
            plot_line(ax, t, tr * deg, color="tab:brown", lw=0.7, ls="--", alpha=0.8, label="torso roll")
            m = finite_extreme(t, tr * deg, "abs")
            if m is not None and abs(m[1]) > 1.0:
                annotate_point(ax, m, f"max |roll| {abs(m[1]):.1f}° at {m[0]:.2f} s", "tab:brown",
                               above=False)
    ax.set_ylabel("torso angle (deg)")
    ax.set_title("(c) torso pitch (roll dashed)", fontsize=10, loc="left")

    for ax in axes:
        mark_events(ax, pushes, fall_time, label=True)
        ax.grid(True, alpha=0.3)
        side_legend(ax)
        ax.margins(y=0.25)
    label_pushes(axes[0], pushes)
    axes[-1].set_xlabel("time (s)")
    suptitle(fig, title, "foot pitch, CoM x, torso pitch", run, fall_time)
    fig.tight_layout()
    finish(fig, out)


# ---- Fig. 9: ZMP per foot, lowest-level task error ------------------------------------------------

def zmp_panel(ax, run, foot, axis, limit, pushes, fall_time):
    t = run.t
    meas = run.col(f"{foot}_zmp_meas_{axis}")
    src = "measured ZMP"
    if meas is None:
        meas = run.col(f"{foot}_cop_{axis}")  # the simulation's own F/T CoP: same quantity
        src = "measured CoP (F/T)"
    opt = run.col(f"{foot}_zmp_opt_{axis}")
    name = "left" if foot == "l" else "right"
    if meas is None and opt is None:
        not_logged(ax, f"{name} ZMP {axis}")
    if meas is not None:
        plot_line(ax, t, meas * 1000.0, color="tab:blue", lw=0.9, label=src)
    if opt is not None:
        plot_line(ax, t, opt * 1000.0, color="tab:orange", lw=0.9, ls="--", label="optimized ZMP")
    elif meas is not None:
        ax.text(0.01, 0.04, "optimized ZMP: not logged", transform=ax.transAxes, fontsize=8, color="gray")
    for s in (-1, 1):
        ax.axhline(s * limit, color="gray", ls="--", lw=0.9, label="sole limit" if s > 0 else None)
    contact = run.col(f"{foot}_in_contact")
    if contact is not None and len(t):
        off = np.nan_to_num(contact, nan=0.0) < 0.5
        for i, (a, b) in enumerate(segments(off)):
            ax.axvspan(t[a], t[min(b, len(t) - 1)], color="gray", alpha=0.15, lw=0,
                       label="foot not in contact" if i == 0 else None)
    if meas is not None:
        v = meas * 1000.0
        if np.any(np.isfinite(v)):
            worst = float(np.nanmax(np.abs(v)))
            ax.text(0.99, 0.04, f"max |measured| {worst:.1f} mm (limit {limit:g})", transform=ax.transAxes,
                    ha="right", fontsize=8, color="tab:red" if worst > limit else "tab:blue",
                    bbox=dict(fc="white", ec="none", alpha=0.7, pad=1))
    mark_events(ax, pushes, fall_time, label=True)
    lim = 1.35 * limit
    for v in (meas, opt):  # never clip a ZMP that left the sole
        if v is not None and np.any(np.isfinite(v)):
            lim = max(lim, 1.1 * 1000.0 * float(np.nanmax(np.abs(v))))
    ax.set_ylim(-lim, lim)
    ax.set_ylabel(f"ZMP {axis} (mm)")
    ax.set_title(f"{name} foot, ZMP {axis} in the sole frame", fontsize=10, loc="left")
    ax.grid(True, alpha=0.3)


def fig9(run, out, title, pushes, fall_time, sole_x, sole_y):
    fig = plt.figure(figsize=(12, 10))
    gs = fig.add_gridspec(3, 2, height_ratios=[1, 1, 1.1])
    top = fig.add_subplot(gs[0, 0])
    time_axis(top, run, fall_time)
    axes = {("l", "x"): top,
            ("r", "x"): fig.add_subplot(gs[0, 1], sharex=top),
            ("l", "y"): fig.add_subplot(gs[1, 0], sharex=top),
            ("r", "y"): fig.add_subplot(gs[1, 1], sharex=top)}
    for (foot, axis), ax in axes.items():
        zmp_panel(ax, run, foot, axis, sole_x if axis == "x" else sole_y, pushes, fall_time)
    ax = fig.add_subplot(gs[2, :], sharex=top)
    levels = run.levels()
    t = run.t
    if not levels:
        not_logged(ax, "task error (levelN_residual)")
    else:
        n = levels[-1]
        res = run.col(f"level{n}_residual")
        floor = 1e-12
        plot_line(ax, t, np.clip(res, floor, None), color="tab:purple", lw=0.9,
                  label=f"level {n} (lowest priority): ‖Ax − b‖²")
        ax.set_yscale("log")
        status = run.col(f"level{n}_status")
        if status is not None:
            bad = np.nan_to_num(status, nan=0.0) != 0
            if np.any(bad):
                y = np.clip(np.nan_to_num(res[bad], nan=floor), floor, None)
                ax.plot(t[bad], y, "x", color="tab:red", ms=4, label=f"status ≠ optimal ({int(bad.sum())} ticks)")
        counts = []
        for lv in levels:
            st = run.col(f"level{lv}_status")
            if st is not None:
                counts.append(f"L{lv} {int((np.nan_to_num(st, nan=0.0) != 0).sum())}")
        if counts:
            ax.text(0.01, 0.96, "ticks with QP status ≠ optimal: " + ", ".join(counts), transform=ax.transAxes,
                    va="top", fontsize=8, color="dimgray", bbox=dict(fc="white", ec="none", alpha=0.7, pad=1))
        m = finite_extreme(t, res, "max")
        if m is not None and m[1] > 0:
            annotate_point(ax, m, f"max {m[1]:.3g} at {m[0]:.2f} s", "tab:purple")
        if np.any(np.isfinite(res)) and np.nanmin(res) <= floor:
            ax.text(0.99, 0.04, f"values ≤ {floor:g} drawn at {floor:g}", transform=ax.transAxes,
                    ha="right", fontsize=8, color="gray")
        if np.any(np.isfinite(res)):
            clipped = np.clip(res, floor, None)
            top_val = float(np.nanmax(clipped))
            ax.set_ylim(float(np.nanmin(clipped)) / 10.0, top_val * 100.0)  # room for the labels
    mark_events(ax, pushes, fall_time, label=True)
    ax.set_ylabel("task error ‖Ax − b‖²")
    ax.set_xlabel("time (s)")
    ax.set_title("lowest-level task error", fontsize=10, loc="left")
    ax.grid(True, which="major", alpha=0.3)
    # One legend for all panels, under them.
    h, lab = [], []
    for a in list(axes.values()) + [ax]:
        for hh, ll in zip(*a.get_legend_handles_labels()):
            if ll not in lab:
                h.append(hh)
                lab.append(ll)
    for a in axes.values():
        a.tick_params(labelbottom=True)
    label_pushes(top, pushes)
    label_pushes(axes[("r", "x")], pushes)
    suptitle(fig, title, "measured vs optimized ZMP, task error", run, fall_time)
    if h:
        fig.legend(h, lab, loc="lower center", ncol=min(len(h), 5), fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.04 if h else 0, 1, 1))
    finish(fig, out)


# ---- Fig. 13: compute time per tick ---------------------------------------------------------------

def fig13(run, out, title, pushes, fall_time):
    fig, (ax, axh) = plt.subplots(1, 2, figsize=(12, 4.8), gridspec_kw=dict(width_ratios=[2.2, 1]))
    t = run.t
    us = run.col("tick_us")
    stats = None
    if us is not None:
        v = us[np.isfinite(us)]
        if len(v):
            stats = dict(mean=float(v.mean()), max=float(v.max()), p999=float(np.percentile(v, 99.9)),
                         over=int((v > TICK_BUDGET_US).sum()), n=len(v))
    if stats is None:
        not_logged(ax, "compute time (tick_us)")
        not_logged(axh, "compute time")
    else:
        fin = us[np.isfinite(us)]
        # Log axes start at 0.3 x the median: near-zero ticks (safe mode skips the QPs) would
        # otherwise squash the figure; they are counted in a note instead.
        lo = max(0.3 * float(np.median(fin)), 0.01)
        below = int((fin < lo).sum())
        pos = np.clip(us, lo, None)
        plot_line(ax, t, pos, color="lightsteelblue", lw=0.6, label="compute time per tick")
        if len(us) >= 200:  # the trend under the per-tick scatter; a median ignores the outliers
            w = 100
            nb = len(us) // w
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # all-NaN blocks stay NaN
                med = np.nanmedian(us[:nb * w].reshape(nb, w), axis=1)
            tc = t[:nb * w].reshape(nb, w).mean(axis=1)
            ax.plot(tc, med, color="tab:blue", lw=1.0, drawstyle="steps-mid", label=f"median of {w} ticks")
        ax.axhline(stats["mean"], color="tab:green", lw=1.0, label=f"mean {stats['mean']:.1f} µs")
        ax.axhline(stats["p999"], color="tab:orange", lw=1.0, ls="--",
                   label=f"99.9 % {stats['p999']:.1f} µs")
        ax.axhline(TICK_BUDGET_US, color="tab:red", lw=1.2, label=f"budget {TICK_BUDGET_US:g} µs (1 kHz)")
        mx = finite_extreme(t, us, "max")
        ax.plot([mx[0]], [max(mx[1], 0.1)], "v", color="black", ms=6, label=f"max {stats['max']:.1f} µs")
        safe = run.col("safe_mode")
        if safe is not None and len(t):
            for i, (a, b) in enumerate(segments(np.nan_to_num(safe, nan=0.0) > 0.5)):
                ax.axvspan(t[a], t[min(b, len(t) - 1)], color="tab:orange", alpha=0.2, lw=0,
                           label="safe mode" if i == 0 else None)
        if below:
            ax.text(0.01, 0.03, f"{below} tick(s) below {lo:.3g} µs drawn at the axis", transform=ax.transAxes,
                    fontsize=8, color="dimgray", bbox=dict(fc="white", ec="none", alpha=0.7, pad=1))
        ax.set_yscale("log")
        ax.set_ylim(lo, 10.0 * max(TICK_BUDGET_US, stats["max"]))  # a decade of room for the legend
        ax.legend(loc="upper right", fontsize=8, ncol=2)
        mark_events(ax, pushes, fall_time)

        v = np.clip(fin, lo, None)
        bins = np.logspace(math.log10(v.min()), math.log10(max(v.max(), v.min() * 1.01)), 60)
        counts, _, _ = axh.hist(v, bins=bins, color="tab:blue", alpha=0.8)
        axh.set_ylim(0.5, 30.0 * max(float(counts.max()), 1.0))  # room for the legend
        axh.set_xscale("log")
        axh.set_yscale("log")
        axh.axvline(stats["mean"], color="tab:green", lw=1.0, label=f"mean {stats['mean']:.1f} µs")
        axh.axvline(stats["p999"], color="tab:orange", lw=1.0, ls="--", label=f"99.9 % {stats['p999']:.1f} µs")
        axh.axvline(stats["max"], color="black", lw=1.0, ls=":", label=f"max {stats['max']:.1f} µs")
        axh.axvline(TICK_BUDGET_US, color="tab:red", lw=1.2, label=f"budget {TICK_BUDGET_US:g} µs")
        axh.legend(loc="upper right", fontsize=8)
        axh.set_title(f"{stats['n']} ticks, {stats['over']} over budget" +
                      (f", {below} in the first bin" if below else ""), fontsize=10, loc="left")
    ax.set_ylabel("compute time (µs)")
    ax.set_title("controller compute time per 1 ms tick", fontsize=10, loc="left")
    ax.grid(True, which="both", alpha=0.25)
    time_axis(ax, run, fall_time)
    axh.set_xlabel("compute time (µs)")
    axh.set_ylabel("ticks")
    axh.grid(True, which="major", alpha=0.3)
    suptitle(fig, title, "controller compute time", run, fall_time)
    fig.tight_layout()
    finish(fig, out)


# ---- Fig. 11, 12, 14: moving supports ---------------------------------------------------------------

FOOT_VELOCITY_CUTOFF_HZ = 20.0  # the paper low-passes the foot's angular velocity at 20 Hz


def low_pass(t, y, cutoff_hz=FOOT_VELOCITY_CUTOFF_HZ):
    """First-order low-pass (the run's own peak metric uses the same filter); NaN rows hold."""
    out = np.array(y, dtype=float)
    if len(out) < 2:
        return out
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 1e-3
    a = dt / (dt + 1.0 / (2.0 * math.pi * cutoff_hz))
    acc = 0.0
    for i, v in enumerate(out):
        if np.isfinite(v):
            acc += a * (v - acc)
        out[i] = acc
    return out


def support_columns(run):
    return [n for n in run.names if n.startswith("support_")]


def plot_components(ax, run, names, labels, colors, scale, unit, fall_time, pushes):
    """Low-passed components with each one's peak |value| in the legend label."""
    t = run.t
    any_col = False
    for n, lab, c in zip(names, labels, colors):
        y = run.col(n)
        if y is None:
            continue
        any_col = True
        f = low_pass(t, y) * scale
        peak = float(np.nanmax(np.abs(f))) if np.any(np.isfinite(f)) else float("nan")
        plot_line(ax, t, f, color=c, lw=0.9, label=f"{lab} (peak {peak:.2f} {unit})")
    if not any_col:
        not_logged(ax, ", ".join(names))
    mark_events(ax, pushes, fall_time)
    ax.grid(True, alpha=0.3)
    side_legend(ax)


def fig11(run, out, title, pushes, fall_time):
    fig, axes = plt.subplots(2, 1, figsize=(11, 6.5), sharex=True)
    time_axis(axes[0], run, fall_time)
    deg = 180.0 / math.pi
    ax = axes[0]
    for n, lab, c in (("r_foot_roll", "roll (about X)", "tab:blue"), ("r_foot_pitch", "pitch (about Y)", "tab:orange"),
                      ("r_foot_yaw", "yaw (about Z)", "tab:green")):
        y = run.col(n)
        if y is not None:
            y0 = run.first(n)
            plot_angle(ax, run.t, (y - y0) * deg, c, lab, "max {:.2f}° at {:.2f} s")
    ax.set_ylabel("right foot angle (°)\nrelative to t = 0")
    mark_events(ax, pushes, fall_time)
    ax.grid(True, alpha=0.3)
    side_legend(ax)
    plot_components(axes[1], run, ["r_foot_wx", "r_foot_wy", "r_foot_wz"], ["ω x", "ω y", "ω z"],
                    ["tab:blue", "tab:orange", "tab:green"], 1.0, "rad/s", fall_time, pushes)
    axes[1].set_ylabel("angular velocity (rad/s)\n20 Hz low-pass")
    axes[1].set_xlabel("time (s)")
    suptitle(fig, title, "right foot orientation and angular velocity (Fig. 11)", run, fall_time)
    fig.tight_layout()
    finish(fig, out)


def fig12(run, out, title, pushes, fall_time, sole_x, sole_y):
    fig, axes = plt.subplots(2, 1, figsize=(11, 6.5), sharex=True)
    time_axis(axes[0], run, fall_time)
    zmp_panel(axes[0], run, "r", "x", sole_x, pushes, fall_time)
    zmp_panel(axes[1], run, "r", "y", sole_y, pushes, fall_time)
    for ax in axes:
        side_legend(ax)
    axes[1].set_xlabel("time (s)")
    suptitle(fig, title, "right foot ZMP (Fig. 12)", run, fall_time)
    fig.tight_layout()
    finish(fig, out)


def fig14(run, out, title, pushes, fall_time):
    fig, axes = plt.subplots(3, 1, figsize=(11, 8.5), sharex=True)
    time_axis(axes[0], run, fall_time)
    plot_components(axes[0], run, ["r_foot_vx", "r_foot_vy", "r_foot_vz"], ["v x", "v y", "v z"],
                    ["tab:blue", "tab:orange", "tab:green"], 1.0, "m/s", fall_time, pushes)
    axes[0].set_ylabel("right foot velocity (m/s)\n20 Hz low-pass")
    plot_components(axes[1], run, ["r_foot_wx", "r_foot_wy", "r_foot_wz"], ["ω x", "ω y", "ω z"],
                    ["tab:blue", "tab:orange", "tab:green"], 1.0, "rad/s", fall_time, pushes)
    axes[1].set_ylabel("right foot angular\nvelocity (rad/s)")
    ax = axes[2]
    cols = support_columns(run)
    if not cols:
        not_logged(ax, "support_<axis>")
    for n in cols:
        y = run.col(n)
        unit = "m" if n.endswith(("_x", "_y", "_z")) else "rad"
        plot_line(ax, run.t, y, lw=0.9, label=f"{n[len('support_'):]} ({unit})")
    mark_events(ax, pushes, fall_time)
    ax.set_ylabel("support servo\nposition (m or rad)")
    ax.set_xlabel("time (s)")
    ax.grid(True, alpha=0.3)
    side_legend(ax)
    suptitle(fig, title, "right foot velocity on the moving support (Fig. 14)", run, fall_time)
    fig.tight_layout()
    finish(fig, out)


# ---- command line ---------------------------------------------------------------------------------

def read_summary(path, csv_path, stem):
    """The run's record from a summary JSON (an object, a list, or {"runs": [...]}); None if absent.
    Without `path`: summary.json, <stem>.json or <stem>_summary.json next to the CSV, and only a
    record that names this CSV (files.csv) or this scenario."""
    here = os.path.dirname(os.path.abspath(csv_path))
    candidates = [path] if path else [os.path.join(here, n) for n in
                                      ("summary.json", f"{stem}.json", f"{stem}_summary.json")]
    for c in candidates:
        try:
            with open(c, "r") as f:
                d = json.load(f)
        except (OSError, ValueError):
            continue
        if isinstance(d, dict) and isinstance(d.get("runs"), list):
            d = d["runs"]
        records = [r for r in (d if isinstance(d, list) else [d]) if isinstance(r, dict)]
        for r in records:
            csv_name = os.path.basename(str((r.get("files") or {}).get("csv", "")))
            if csv_name == os.path.basename(csv_path) or r.get("scenario") == stem:
                return r
        if path and len(records) == 1:  # named explicitly: trust it
            return records[0]
    return None


def summary_pushes(summ):
    out = []
    for p in summ.get("pushes") or []:
        try:
            out.append((float(p["time"]), impulse_label(p.get("impulse", [0, 0, 0]))))
        except (KeyError, TypeError, ValueError):
            pass
    return sorted(out)


def parse_pushes(text):
    out = []
    for item in text.split(","):
        item = item.strip()
        if item:
            out.append((float(item), "push"))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description="Plots (paper Fig. 8, 9, 13; 11, 12, 14 on moving supports) of one sim_demo CSV log.")
    ap.add_argument("csv", help="the run's CSV log (sim_demo --out DIR writes DIR/<scenario>/<scenario>.csv)")
    ap.add_argument("--out", required=True, help="output directory for the PNGs")
    ap.add_argument("--title", help="figure title (default: the CSV's stem)")
    ap.add_argument("--pushes", help="push times T1,T2,... in s (default: detected from the CSV)")
    ap.add_argument("--window", help="plot only T0:T1 (s), e.g. 4.5:7 to look at one push")
    ap.add_argument("--sole-x", type=float, default=110.0, help="sole half-length in x, mm (default 110)")
    ap.add_argument("--sole-y", type=float, default=50.0, help="sole half-width in y, mm (default 50)")
    ap.add_argument("--fall-time", type=float,
                    help="time of a fall (default: from the run's summary.json, else the last row's torso)")
    ap.add_argument("--summary", help="the run's summary.json (default: summary.json next to the CSV, if it "
                                      "names this CSV or scenario)")
    a = ap.parse_args(argv)

    try:
        run = Run(a.csv)
    except (OSError, ValueError) as e:
        print(f"plot_scenario: {e}", file=sys.stderr)
        return 2
    os.makedirs(a.out, exist_ok=True)
    stem = os.path.splitext(os.path.basename(a.csv))[0]
    title = a.title or stem
    suffix = ""
    if a.window:
        try:
            w0, w1 = (float(x) for x in a.window.split(":"))
        except ValueError:
            print(f"plot_scenario: --window wants T0:T1 in s, got '{a.window}'", file=sys.stderr)
            return 2
        suffix = f"_{w0:g}-{w1:g}s"
    try:
        pushes = parse_pushes(a.pushes) if a.pushes else detect_pushes(run)
    except ValueError:
        print(f"plot_scenario: --pushes wants comma-separated times in s, got '{a.pushes}'", file=sys.stderr)
        return 2
    summ = read_summary(a.summary, a.csv, stem)
    if a.summary and summ is None:
        print(f"plot_scenario: cannot use {a.summary}", file=sys.stderr)
        return 2
    if not pushes and not a.pushes and summ:
        pushes = summary_pushes(summ)
    fall_time = a.fall_time
    if fall_time is None and summ and summ.get("fell"):
        ft = summ.get("fall_time")
        fall_time = float(ft) if isinstance(ft, (int, float)) else (float(run.t[-1]) if len(run) else None)
    if fall_time is None and not (summ and summ.get("fell") is False):
        fall_time = detect_fall(run)  # a fall by contact only shows in the summary
    if run.dropped:
        print(f"plot_scenario: skipped {run.dropped} incomplete line(s) of {a.csv}", file=sys.stderr)
    if len(run) == 0:
        print(f"plot_scenario: {a.csv} has no data rows; the figures are empty", file=sys.stderr)

    times = ", ".join(f"{p[0]:.2f}" for p in pushes)
    print(f"{a.csv}: {len(run)} rows, {len(pushes)} push(es)" + (f" at {times} s" if pushes else "") +
          (f", fall at {fall_time:.2f} s" if fall_time is not None else ", no fall"))
    if a.window:  # events are found on the whole run, then the rows are cut
        run.window(w0, w1)
        pushes = [p for p in pushes if w0 <= p[0] <= w1]
        if fall_time is not None and not w0 <= fall_time <= w1:
            fall_time = None
    fig8(run, os.path.join(a.out, f"{stem}{suffix}_fig8.png"), title, pushes, fall_time)
    fig9(run, os.path.join(a.out, f"{stem}{suffix}_fig9.png"), title, pushes, fall_time, a.sole_x, a.sole_y)
    fig13(run, os.path.join(a.out, f"{stem}{suffix}_fig13.png"), title, pushes, fall_time)
    if support_columns(run):
        fig11(run, os.path.join(a.out, f"{stem}{suffix}_fig11.png"), title, pushes, fall_time)
        fig12(run, os.path.join(a.out, f"{stem}{suffix}_fig12.png"), title, pushes, fall_time, a.sole_x, a.sole_y)
        fig14(run, os.path.join(a.out, f"{stem}{suffix}_fig14.png"), title, pushes, fall_time)
    return 0


if __name__ == "__main__":
    sys.exit(main())
