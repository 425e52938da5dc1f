#!/usr/bin/env python3
"""How many working-set changes a method over all levels at once would take (docs/hqp-tuning.md,
"What a method over all levels at once would start from").

A primal active-set method on the whole lexicographic problem: every constraint row hard from the
start, the working set shared by all levels, each step the lexicographic least-squares point on
the working set's equalities (dense, recomputed each step: only the number of steps counts).
From a feasible vertex (scipy's HiGHS on the constraint rows) with an empty working set, a step
that meets a row adds it; at a full step the working set's multipliers are read level by level,
with the task rows of the levels above and the rows that hold a level above back as free
directions, and the most negative one of the first level that has one is dropped. The result is
compared with the stored solution's level objectives (lexicographically, 1e-7 relative).

Reads the JSON of `hqp_corpus dump FILE OUT.json`. Per instance: whether the deferred attempt's
last level is feasible (an LP on the constraint rows in the null space of the higher task rows,
at their unconstrained minimum), the adds and drops, and the comparison; then a summary.

  python3 tools/hqp_lex_count.py dump.json [--only K ...]
"""
import argparse
import json
import os
import sys

import numpy as np
from scipy.optimize import linprog

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from hqp_oracle import bounds, null_space  # noqa: E402

RANK_TOL = 1e-9  # the multipliers' matrix rank decision (null_space()'s default is the same)
MULT_TOL = 1e-9


def lex_point(Aw, bw, levels, DW, eW):
    """The lexicographic least-squares point of the levels on DW x = eW (minimum norm)."""
    n = Aw.shape[1]
    x = np.linalg.lstsq(DW, eW, rcond=None)[0] if DW.shape[0] else np.zeros(n)
    N = null_space(DW)
    for t0, t1 in levels:
        if N.shape[1] == 0:
            break
        M = Aw[t0:t1] @ N
        x = x + N @ np.linalg.lstsq(M, bw[t0:t1] - Aw[t0:t1] @ x, rcond=1e-12)[0]
        N = N @ null_space(M)
    return x


class Instance:
    def __init__(self, inst, t_off):
        A, b, w = (np.array(inst[k], float) for k in ("A", "b", "w"))
        self.D = np.array(inst["D"], float)
        self.lo, self.up = bounds(inst["lower"], -1), bounds(inst["upper"], 1)
        sw = np.sqrt(w)
        self.Aw, self.bw = A * sw[:, None], b * sw
        self.levels = list(zip(t_off[:-1], t_off[1:]))
        self.x_stored = np.array(inst["x"], float)

    def objectives(self, x):
        r = self.Aw @ x - self.bw
        return [float((r[t0:t1] ** 2).sum()) for t0, t1 in self.levels]

    def feasible_point(self, base, N):
        """A point base + N z within every row (an LP vertex), or None."""
        fu, fl = np.isfinite(self.up), np.isfinite(self.lo)
        DN, Db = self.D @ N, self.D @ base
        A_ub = np.vstack([DN[fu], -DN[fl]])
        b_ub = np.concatenate([self.up[fu] - Db[fu], Db[fl] - self.lo[fl]])
        if N.shape[1] == 0:
            return base if (b_ub >= -1e-9).all() else None
        res = linprog(np.zeros(N.shape[1]), A_ub=A_ub, b_ub=b_ub, bounds=[(None, None)] * N.shape[1],
                      method="highs")
        return base + N @ res.x if res.status == 0 else None

    def deferred_feasible(self):
        above = self.levels[:-1]
        n = self.Aw.shape[1]
        x = lex_point(self.Aw, self.bw, above, np.zeros((0, n)), np.zeros(0))
        N = np.eye(n)
        for t0, t1 in above:
            N = N @ null_space(self.Aw[t0:t1] @ N)
        return self.feasible_point(x, N) is not None

    def multipliers_drop(self, x, W):
        """Index in W of the row to drop, or None at the lexicographic optimum."""
        if not W:
            return None
        DW = self.D[[i for i, _ in W]]
        locked = set()
        for t0, t1 in self.levels:
            Ap = self.Aw[t0:t1]
            g = Ap.T @ (Ap @ x - self.bw[t0:t1])
            K = np.hstack([DW.T, self.Aw[:t0].T])
            lam = np.linalg.lstsq(K, g, rcond=1e-12)[0][: len(W)]
            # the gradient's scale: its terms' sizes, not their (often vanishing) difference
            scale = np.linalg.norm(Ap) * (np.linalg.norm(Ap @ x) + np.linalg.norm(self.bw[t0:t1]))
            tol = MULT_TOL * scale + 1e-300
            ktol = RANK_TOL * np.abs(K).max()
            rank = np.linalg.matrix_rank(K, tol=ktol)
            mu = np.array([lam[a] * (1.0 if s < 0 else -1.0) for a, (_, s) in enumerate(W)])
            worst, drop = -tol, None
            for a, (i, _) in enumerate(W):
                if i in locked or mu[a] >= worst:
                    continue
                # a row in the span of the others cannot move alone: its multiplier is not its own
                if np.linalg.matrix_rank(np.delete(K, a, axis=1), tol=ktol) == rank:
                    continue
                worst, drop = mu[a], a
            if drop is not None:
                return drop
            locked.update(i for a, (i, _) in enumerate(W) if mu[a] > tol)
        return None

    def solve(self, max_changes=1000):
        n = self.Aw.shape[1]
        x = self.feasible_point(np.zeros(n), np.eye(n))
        if x is None:
            return None
        W, adds, drops = [], 0, 0  # W: (row, side), side -1 lower, +1 upper
        rn = np.linalg.norm(self.D, axis=1)
        while adds + drops < max_changes:
            rows = [i for i, _ in W]
            eW = np.array([self.lo[i] if s < 0 else self.up[i] for i, s in W])
            d = lex_point(self.Aw, self.bw, self.levels, self.D[rows], eW) - x
            dn = np.linalg.norm(d)
            if dn > 1e-12 * max(1.0, np.linalg.norm(x)):
                Dd, Dx = self.D @ d, self.D @ x
                alpha, block = 1.0, None
                for i in range(self.D.shape[0]):
                    if i in rows:
                        continue
                    if Dd[i] < -1e-14 * rn[i] * dn and np.isfinite(self.lo[i]):
                        a, side = (self.lo[i] - Dx[i]) / Dd[i], -1
                    elif Dd[i] > 1e-14 * rn[i] * dn and np.isfinite(self.up[i]):
                        a, side = (self.up[i] - Dx[i]) / Dd[i], 1
                    else:
                        continue
                    if a < alpha:
                        alpha, block = max(a, 0.0), (i, side)
                x = x + alpha * d
                if block is not None:
                    W.append(block)
                    adds += 1
                    continue
            drop = self.multipliers_drop(x, W)
            if drop is None:
                return dict(x=x, adds=adds, drops=drops, active=len(W))
            W.pop(drop)
            drops += 1
        return dict(x=x, adds=adds, drops=drops, active=len(W), capped=True)


def compare(fo, fs):
    for o, s in zip(fo, fs):
        if abs(o - s) > 1e-7 * max(1.0, abs(s)):
            return "worse" if o > s else "better"
    return "same"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("dump")
    ap.add_argument("--only", type=int, nargs="*")
    a = ap.parse_args()
    with open(a.dump) as f:
        d = json.load(f)
    ks = a.only if a.only else range(len(d["instances"]))
    stats = {}
    for k in ks:
        raw = d["instances"][k]
        if any(s != "Optimal" for s in raw["status"]):
            print(k, "skipped: stored statuses", " ".join(raw["status"]))
            continue
        inst = Instance(raw, d["task_offset"])
        kind = "deferred" if inst.deferred_feasible() else "cascade"
        r = inst.solve()
        if r is None:
            print(k, kind, "no feasible point")
            continue
        verdict = compare(inst.objectives(r["x"]), inst.objectives(inst.x_stored))
        capped = " capped" if r.get("capped") else ""
        print(f"{k} {kind} adds {r['adds']} drops {r['drops']} active {r['active']} {verdict}{capped}")
        sys.stdout.flush()
        stats.setdefault(kind, []).append((r["adds"] + r["drops"], verdict, bool(capped)))
    for kind, v in sorted(stats.items()):
        ended = [(x, s) for x, s, cap in v if not cap]
        c = np.array([x for x, _ in ended])
        same = sum(1 for _, s in ended if s == "same")
        print(f"{kind}: {len(v)} instances, {len(v) - len(ended)} cycling (capped); the others: "
              f"working-set changes mean {c.mean():.1f} median {np.median(c):.0f} p90 "
              f"{np.percentile(c, 90):.0f} max {c.max()}, stored objectives reached on {same}")


if __name__ == "__main__":
    main()
