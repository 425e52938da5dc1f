#!/usr/bin/python3
"""Markdown results table from one or more hqp_sim summary.json files.

Each argument is a summary.json file (one JSON object per run, a list of them, or an object with a
"runs" list) or a directory searched recursively for summary.json. Prints the table; `--md FILE`
also writes it to FILE. Missing keys are shown as "–". A push_sweep record (one with
"directions") gets one row with the largest impulse survived per direction.
Standard library only.
"""
import argparse
import json
import os
import sys

DASH = "–"

HEADER = ["scenario", "controller", "result", "max torso pitch", "CoM x range", "max foot pitch",
          "ZMP margin", "tick mean / p99.9", "RTF"]
WIDE_HEADER = ["max torso roll", "lowest-level error max", "QP ≠ optimal", "tick max"]

# Section VI-A of the paper (the real Walker3, eight pushes along x up to 12 N*s) and its Fig. 13
# (whole loop: mean 0.363 ms, max 0.639 ms).
PAPER_ROW = ["paper, push_x (real robot)", "HQP (qpOASES)", "survived 12 N·s", "25.7°", "-29 … 56 mm", "1.5°",
             DASH, "363 / max 639 µs", "1.0"]
PAPER_WIDE = [DASH, "~1e+03 peaks", DASH, "639 µs"]


def num(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and v == v  # excludes NaN


def fmt(v, spec, unit=""):
    return f"{v:{spec}}{unit}" if num(v) else DASH


def result(s):
    passed = s.get("passed")
    if passed is None:
        return DASH
    if passed:
        return "PASS"
    why = []
    if s.get("fell"):
        ft = s.get("fall_time")
        why.append(f"fall at {ft:.2f} s" if num(ft) else "fall")
        if s.get("fall_reason"):
            why[-1] += f": {s['fall_reason']}"
    elif s.get("zmp_inside") is False:
        why.append("ZMP left a sole")
    elif num(s.get("safe_mode_ticks")) and s["safe_mode_ticks"] > 0:
        why.append("safe mode")
    return "FAIL" + (f" ({'; '.join(why)})" if why else "")


def non_optimal(s):
    """Ticks with a QP status other than optimal, summed over levels (keys in either spelling)."""
    counts = s.get("level_status_counts")
    if not isinstance(counts, list) or not counts:
        return None
    total = 0
    for c in counts:
        if not isinstance(c, dict):
            return None
        total += sum(v for k, v in c.items() if num(v) and k.lower() != "optimal")
    return total


def sweep_result(s):
    parts = []
    for d in s.get("directions") or []:
        if isinstance(d, dict):
            parts.append(f"{d.get('direction', '?')} {fmt(d.get('largest_passed'), '.1f')}")
    verdict = {True: "PASS", False: "FAIL"}.get(s.get("passed"), DASH)
    return verdict + (f" (largest survived, N·s: {', '.join(parts)})" if parts else "")


def row(s, wide):
    ctrl = s.get("controller")
    base = [str(s.get("scenario", DASH)), str(ctrl) if ctrl else DASH]
    if "directions" in s:  # push_sweep: a bisection over many runs
        p999 = s.get("tick_p999_us_worst_trial", s.get("tick_p999_us"))
        r = base + [sweep_result(s), DASH, DASH, DASH, DASH, f"{DASH} / {fmt(p999, '.0f')} µs (worst run)", DASH]
        return r + ([DASH, DASH, DASH, fmt(s.get("tick_max_us"), ".0f", " µs")] if wide else [])
    lo, hi = s.get("com_x_min_mm"), s.get("com_x_max_mm")
    com = f"{lo:.0f} … {hi:.0f} mm" if num(lo) and num(hi) else DASH
    mean, p999 = s.get("tick_mean_us"), s.get("tick_p999_us")
    tick = f"{fmt(mean, '.0f')} / {fmt(p999, '.0f')} µs" if num(mean) or num(p999) else DASH
    r = base + [result(s), fmt(s.get("max_torso_pitch_deg"), ".1f", "°"), com,
                fmt(s.get("max_foot_pitch_deg"), ".2f", "°"), fmt(s.get("zmp_margin_mm"), ".1f", " mm"), tick,
                fmt(s.get("real_time_factor"), ".1f")]
    if wide:
        bad = non_optimal(s)
        r += [fmt(s.get("max_torso_roll_deg"), ".1f", "°"), fmt(s.get("lowest_level_error_max"), ".3g"),
              DASH if bad is None else str(bad), fmt(s.get("tick_max_us"), ".0f", " µs")]
    return r


def escape(cell):
    return cell.replace("|", "\\|")


def table(rows, header):
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(escape(c) for c in r) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def load(paths):
    """Run records in argument order; directories are searched for summary.json (sorted)."""
    files = []
    for p in paths:
        if os.path.isdir(p):
            found = []
            for root, _, names in os.walk(p):
                found += [os.path.join(root, n) for n in names if n == "summary.json"]
            if not found:
                raise ValueError(f"{p}: no summary.json below this directory")
            files += sorted(found)
        else:
            files.append(p)
    out = []
    for f in files:
        try:
            with open(f, "r") as fh:
                d = json.load(fh)
        except OSError as e:
            raise ValueError(f"{f}: {e.strerror}")
        except json.JSONDecodeError as e:
            raise ValueError(f"{f}: not valid JSON ({e})")
        if isinstance(d, dict) and isinstance(d.get("runs"), list):
            d = d["runs"]
        items = d if isinstance(d, list) else [d]
        for s in items:
            if not isinstance(s, dict):
                raise ValueError(f"{f}: expected a JSON object per run")
            out.append(s)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description="Markdown table of hqp_sim runs from their summary.json files.")
    ap.add_argument("summaries", nargs="+", help="summary.json files (or directories holding them)")
    ap.add_argument("--md", help="also write the table to this file")
    ap.add_argument("--paper", action="store_true", help="add the paper's push_x figures as a reference row")
    ap.add_argument("--wide", action="store_true",
                    help="add torso roll, lowest-level error max, non-optimal QP ticks and tick max")
    ap.add_argument("--strict", action="store_true", help="exit with 1 if any run failed")
    a = ap.parse_args(argv)
    try:
        runs = load(a.summaries)
    except ValueError as e:
        print(f"summary_table: {e}", file=sys.stderr)
        return 2
    rows = [row(s, a.wide) for s in runs]
    if a.paper:
        rows.append(PAPER_ROW + (PAPER_WIDE if a.wide else []))
    text = table(rows, HEADER + (WIDE_HEADER if a.wide else []))
    sys.stdout.write(text)
    if a.md:
        d = os.path.dirname(a.md)
        if d:
            os.makedirs(d, exist_ok=True)
        with open(a.md, "w") as fh:
            fh.write(text)
    return 1 if a.strict and any(s.get("passed") is False for s in runs) else 0


if __name__ == "__main__":
    sys.exit(main())
