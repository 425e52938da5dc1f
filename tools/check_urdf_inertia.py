#!/usr/bin/env python3
"""Sanity checks for the URDF files in robots/ (standard library only).

Checks, per link with an <inertial>: mass > 0, inertial frame rpy = 0, inertia diagonal
(ixy = ixz = iyz = 0, so MuJoCo needs no iterative re-diagonalization), moments > 0 and
strictly satisfying the triangle inequality (MuJoCo rejects the model otherwise).
Per joint: parent and child exist, unit axis, revolute limits ordered with effort and
velocity > 0, non-negative damping and friction. The links must form one tree.

Usage: check_urdf_inertia.py FILE.urdf [--total-mass KG] [--mass-tol KG]
Exit status 0 when every check passes, 1 otherwise.
"""
import argparse
import math
import sys
import xml.etree.ElementTree as ET


def floats(text, n, default):
    if text is None:
        return [default] * n
    vals = [float(x) for x in text.split()]
    if len(vals) != n:
        raise ValueError("expected %d numbers, got %r" % (n, text))
    return vals


def check(path, total_mass=None, mass_tol=1e-9):
    errors = []
    root = ET.parse(path).getroot()
    if root.tag != "robot":
        return ["root element is <%s>, not <robot>" % root.tag], 0.0
    links = {l.get("name"): l for l in root.findall("link")}
    if len(links) != len(root.findall("link")):
        errors.append("duplicate link names")
    mass = 0.0
    for name, link in links.items():
        inertial = link.find("inertial")
        if inertial is None:
            continue
        m = float(inertial.find("mass").get("value"))
        mass += m
        if not m > 0:
            errors.append("%s: mass %g is not positive" % (name, m))
        origin = inertial.find("origin")
        rpy = floats(origin.get("rpy") if origin is not None else None, 3, 0.0)
        if any(r != 0.0 for r in rpy):
            errors.append("%s: inertial rpy %s is not zero" % (name, rpy))
        ine = inertial.find("inertia")
        get = lambda k: float(ine.get(k, "0"))
        ixx, iyy, izz = get("ixx"), get("iyy"), get("izz")
        for k in ("ixy", "ixz", "iyz"):
            if get(k) != 0.0:
                errors.append("%s: %s = %g, inertia must be diagonal" % (name, k, get(k)))
        if min(ixx, iyy, izz) <= 0:
            errors.append("%s: non-positive principal moment (%g, %g, %g)" % (name, ixx, iyy, izz))
        for a, b, c in ((ixx, iyy, izz), (iyy, izz, ixx), (izz, ixx, iyy)):
            if not a + b > c:
                errors.append("%s: triangle inequality fails (%g + %g <= %g)" % (name, a, b, c))

    children = {}
    for joint in root.findall("joint"):
        jname, jtype = joint.get("name"), joint.get("type")
        parent = joint.find("parent").get("link")
        child = joint.find("child").get("link")
        for l in (parent, child):
            if l not in links:
                errors.append("joint %s: unknown link %s" % (jname, l))
        if child in children:
            errors.append("link %s has two parent joints" % child)
        children[child] = parent
        if jtype in ("revolute", "continuous", "prismatic"):
            axis_el = joint.find("axis")  # URDF default axis is x
            axis = floats(axis_el.get("xyz"), 3, 0.0) if axis_el is not None else [1.0, 0.0, 0.0]
            if abs(math.sqrt(sum(a * a for a in axis)) - 1.0) > 1e-9:
                errors.append("joint %s: axis %s is not unit length" % (jname, axis))
            lim = joint.find("limit")
            if jtype != "continuous":
                if lim is None:
                    errors.append("joint %s: no <limit>" % jname)
                else:
                    lo, hi = float(lim.get("lower", "0")), float(lim.get("upper", "0"))
                    if not lo < hi:
                        errors.append("joint %s: lower %g >= upper %g" % (jname, lo, hi))
            if lim is not None:
                for k in ("effort", "velocity"):
                    if not float(lim.get(k, "0")) > 0:
                        errors.append("joint %s: %s must be > 0" % (jname, k))
            dyn = joint.find("dynamics")
            if dyn is not None:
                for k in ("damping", "friction"):
                    if float(dyn.get(k, "0")) < 0:
                        errors.append("joint %s: negative %s" % (jname, k))
        elif jtype != "fixed":
            errors.append("joint %s: unsupported type %s" % (jname, jtype))

    roots = [l for l in links if l not in children]
    if len(roots) != 1:
        errors.append("expected one root link, found %s" % roots)
    for l in links:  # every link must reach the root without a cycle
        seen, cur = set(), l
        while cur in children:
            if cur in seen:
                errors.append("cycle through link %s" % l)
                break
            seen.add(cur)
            cur = children[cur]
    if total_mass is not None and abs(mass - total_mass) > mass_tol:
        errors.append("total mass %.12g differs from %.12g" % (mass, total_mass))
    return errors, mass


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("urdf")
    ap.add_argument("--total-mass", type=float)
    ap.add_argument("--mass-tol", type=float, default=1e-9)
    args = ap.parse_args()
    errors, mass = check(args.urdf, args.total_mass, args.mass_tol)
    for e in errors:
        print("ERROR:", e)
    print("%s: total mass %.12g kg, %s" % (args.urdf, mass, "OK" if not errors else "%d error(s)" % len(errors)))
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
