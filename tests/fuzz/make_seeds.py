#!/usr/bin/env python3
"""Writes the seed corpus of one fuzzer (docs/fuzzing.md): COUNT inputs from a fixed random
seed, so every run of the CI regression starts from the same files.
  make_seeds.py <fuzzer> <out_dir> [count]
fuzz_urdf_generator gets the URDFs of tests/data and robots/ plus random small trees; the
others get random byte strings (their harnesses decode any bytes)."""
import glob
import os
import random
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
LENGTHS = {"fuzz_active_set_qp": (8, 160), "fuzz_dual_qp": (8, 160), "fuzz_hqp": (6, 120),
           "fuzz_controller_tick": (8, 200), "fuzz_urdf_generator": None}


def number(rng):
    return rng.choice(["0", "1", "-1", "0.5", "1e-3", "10", "-0.25", "3", "0.01"]) \
        if rng.random() < 0.7 else repr(rng.uniform(-5, 5))


def random_urdf(rng, k):
    n = rng.randint(1, 6)
    lines = ['<?xml version="1.0"?>', f'<robot name="r{k}">']
    for i in range(n + 1):
        m = abs(float(number(rng))) + 0.1
        d = abs(float(number(rng))) + 0.01
        lines.append(f'  <link name="l{i}"><inertial><origin xyz="{number(rng)} 0 {number(rng)}"/>'
                     f'<mass value="{m}"/><inertia ixx="{d}" iyy="{d}" izz="{d}" ixy="0" ixz="0" iyz="0"/>'
                     f'</inertial></link>')
    for i in range(1, n + 1):
        t = rng.choice(["revolute", "continuous", "prismatic", "fixed"])
        parent = rng.randint(0, i - 1)
        axis = " ".join(number(rng) for _ in range(3))
        lo = -abs(float(number(rng)))
        lim = (f'<limit lower="{lo}" upper="{-lo + 0.5}" effort="{abs(float(number(rng))) + 1}" '
               f'velocity="{abs(float(number(rng))) + 1}"/>') if t != "fixed" else ""
        lines.append(f'  <joint name="j{i}" type="{t}"><parent link="l{parent}"/><child link="l{i}"/>'
                     f'<origin xyz="{number(rng)} {number(rng)} {number(rng)}" rpy="{number(rng)} 0 0"/>'
                     f'<axis xyz="{axis}"/>{lim}</joint>')
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


def main():
    fuzzer, out = sys.argv[1], sys.argv[2]
    count = int(sys.argv[3]) if len(sys.argv) > 3 else 300
    if fuzzer not in LENGTHS:
        sys.exit(f"unknown fuzzer {fuzzer}")
    os.makedirs(out, exist_ok=True)
    rng = random.Random(f"hqp-{fuzzer}-2026")
    if LENGTHS[fuzzer] is None:
        files = sorted(glob.glob(os.path.join(ROOT, "tests/data/*.urdf")) +
                       glob.glob(os.path.join(ROOT, "robots/*/*.urdf")))
        for f in files:
            with open(f, "rb") as src, open(os.path.join(out, "file_" + os.path.basename(f)), "wb") as dst:
                dst.write(src.read())
        for k in range(count - len(files)):
            with open(os.path.join(out, f"seed_{k:04d}.urdf"), "w") as dst:
                dst.write(random_urdf(rng, k))
        return
    lo, hi = LENGTHS[fuzzer]
    for k in range(count):
        data = bytes(rng.getrandbits(8) for _ in range(rng.randint(lo, hi)))
        with open(os.path.join(out, f"seed_{k:04d}"), "wb") as dst:
            dst.write(data)


if __name__ == "__main__":
    main()
