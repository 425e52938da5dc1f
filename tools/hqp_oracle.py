#!/usr/bin/env python3
"""Independent optimum of every level of HqpWbc's solutions (docs/hqp-tuning.md, "The last level
on nearly dependent rows").

Reads the JSON of `hqp_corpus dump FILE OUT.json` (rows, bounds, the warm solve's x). For each
instance and level p it minimizes the level's weighted residual ||W_p^1/2 (A_p x - b_p)||^2 over
x = x_hat + N z, where x_hat is the solver's x and N spans the null space of the higher levels'
task rows (their optimal values are unique, so every optimal point of the higher levels has
them), within every bound of the levels <= p. scipy's SLSQP from z = 0, and where it does not end
cleanly trust-constr then SLSQP from there; the lowest objective feasible to --feas-tol counts.
The solver's level is flagged if its objective exceeds that by more than --rel-tol (relative).
Exit status 1 if any level is flagged, 0 otherwise.

  python3 tools/hqp_oracle.py dump.json [--rel-tol 1e-6] [--only K ...]
"""
import argparse
import json
import sys
import warnings

import numpy as np
from scipy.optimize import LinearConstraint, minimize


def bounds(values, side):
    inf = np.inf if side > 0 else -np.inf
    return np.array([inf if v is None else v for v in values], dtype=float)


def null_space(M, rank_tol=1e-9):
    """Orthonormal basis of null(M) (columns); singular values ≤ rank_tol · the largest count as 0."""
    if M.size == 0:  # no rows, or no columns
        return np.eye(M.shape[1])
    _, s, vt = np.linalg.svd(M)
    return vt[int((s > rank_tol * max(s[0], 1e-300)).sum()):].T


def level_optimum(A, b, w, D, lo, up, x_hat, t0, t1, c, feas_tol):
    """Lowest weighted residual of rows [t0, t1) over x_hat + null(A[:t0]) within rows [0, c)."""
    N = null_space(A[:t0])
    sw = np.sqrt(w[t0:t1])
    Ap, bp = A[t0:t1] * sw[:, None], b[t0:t1] * sw
    M = Ap @ N
    H, g = M.T @ M, M.T @ (Ap @ x_hat - bp)
    Dn, l, u = D[:c] @ N, lo[:c] - D[:c] @ x_hat, up[:c] - D[:c] @ x_hat

    def objective(z):
        e = Ap @ (x_hat + N @ z) - bp
        return float(e @ e)

    def violation(z):
        if c == 0:
            return 0.0
        d = Dn @ z
        return float(max(0.0, np.max(l - d), np.max(d - u)))

    fl, fu = np.isfinite(l), np.isfinite(u)
    cons = []
    if fl.any():
        cons.append({"type": "ineq", "fun": lambda z: (Dn @ z - l)[fl], "jac": lambda z: Dn[fl]})
    if fu.any():
        cons.append({"type": "ineq", "fun": lambda z: (u - Dn @ z)[fu], "jac": lambda z: -Dn[fu]})
    q = lambda z: 0.5 * z @ H @ z + g @ z
    dq = lambda z: H @ z + g
    z0 = np.zeros(N.shape[1])
    candidates = [z0]  # the solver's own point: never flagged, but checked if feasible
    r = minimize(q, z0, jac=dq, constraints=cons, method="SLSQP", options={"ftol": 1e-15, "maxiter": 5000})
    candidates.append(r.x)
    if r.status != 0 or violation(r.x) > feas_tol:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            lin = [LinearConstraint(Dn, l, u)] if c > 0 else []
            r2 = minimize(q, z0, jac=dq, hess=lambda z: H, constraints=lin, method="trust-constr",
                          options={"gtol": 1e-12, "xtol": 1e-15, "maxiter": 20000})
        r3 = minimize(q, r2.x, jac=dq, constraints=cons, method="SLSQP", options={"ftol": 1e-15, "maxiter": 5000})
        candidates += [r2.x, r3.x]
    feasible = [objective(z) for z in candidates if violation(z) <= feas_tol]
    return min(feasible) if feasible else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dump")
    ap.add_argument("--rel-tol", type=float, default=1e-6)
    ap.add_argument("--abs-tol", type=float, default=1e-9)
    ap.add_argument("--feas-tol", type=float, default=1e-10)
    ap.add_argument("--only", type=int, nargs="*", default=[])
    a = ap.parse_args()
    with open(a.dump) as f:
        doc = json.load(f)
    to, co = doc["task_offset"], doc["constraint_offset"]
    levels = len(to) - 1
    flagged, unchecked, checked = [], 0, 0
    for k, inst in enumerate(doc["instances"]):
        if a.only and k not in a.only:
            continue
        A, b, w = np.array(inst["A"], float), np.array(inst["b"], float), np.array(inst["w"], float)
        D = np.array(inst["D"], float)
        lo, up = bounds(inst["lower"], -1), bounds(inst["upper"], +1)
        x = np.array(inst["x"], float)
        for p in range(levels):
            e = A[to[p]:to[p + 1]] @ x - b[to[p]:to[p + 1]]
            ours = float((w[to[p]:to[p + 1]] * e * e).sum())
            best = level_optimum(A, b, w, D, lo, up, x, to[p], to[p + 1], co[p + 1], a.feas_tol)
            if best is None:
                unchecked += 1
                continue
            checked += 1
            if ours > best * (1 + a.rel_tol) + a.abs_tol:
                flagged.append((k, p, ours, best, inst["status"][p]))
            if a.only:
                print(f"instance {k} level {p + 1}: {ours:.12g} (independent optimum {best:.12g})")
    for k, p, ours, best, status in flagged:
        print(f"{doc['source']} instance {k} level {p + 1}: {status} at {ours:.12g}, "
              f"independent optimum {best:.12g} ({ours / max(best, 1e-300):.4g}x)")
    print(f"{doc['source']}: {len(doc['instances'])} instances, {checked} levels checked, "
          f"{unchecked} without a feasible independent point, {len(flagged)} above the optimum")
    return 1 if flagged else 0


if __name__ == "__main__":
    sys.exit(main())
