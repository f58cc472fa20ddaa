#!/usr/bin/env python3
"""Writes the seed inputs of fuzz_cut (tests/fuzz/fuzz_cut.cpp) to seeds/cut/:
dense networks of 400 traces (random, on a coarse grid, through one point, along
the region's edges, overlapping) for each pattern. Byte 0 picks the pattern (and
a tunnel with bit 7); then 4 bytes a trace, each a coordinate on a 0.02 m grid
(value v -> -0.5 + 0.02 * (v % 251))."""
import os
import random

out = os.path.join(os.path.dirname(os.path.abspath(__file__)), "seeds", "cut")
os.makedirs(out, exist_ok=True)
rng = random.Random(1)


def coordinate(x):  # metres -> byte
    return max(0, min(250, round((x + 0.5) / 0.02)))


def write(name, head, traces):
    data = bytes([head]) + bytes(coordinate(v) for t in traces for v in t)
    with open(os.path.join(out, name), "wb") as f:
        f.write(data)


for pattern in range(6):
    for tunnel in (0, 0x80):
        head = pattern | tunnel
        write(f"random_{pattern}_{tunnel >> 7}", head,
              [[rng.uniform(-0.5, 4.5) for _ in range(4)] for _ in range(400)])
        short = []
        for _ in range(400):
            x, y, a, l = rng.uniform(0, 4), rng.uniform(0, 4), rng.uniform(0, 3.1416), rng.uniform(0.1, 1.0)
            import math
            short.append([x, y, x + l * math.cos(a), y + l * math.sin(a)])
        write(f"short_{pattern}_{tunnel >> 7}", head, short)
        grid = [[0.4 * rng.randrange(0, 11) for _ in range(4)] for _ in range(200)]
        write(f"grid_{pattern}_{tunnel >> 7}", head, grid)
        star = [[2.0, 2.0, rng.uniform(-0.5, 4.5), rng.uniform(-0.5, 4.5)] for _ in range(100)]
        write(f"star_{pattern}_{tunnel >> 7}", head, star)
        edges = [[0.0, rng.uniform(0, 4), 0.0, rng.uniform(0, 4)] for _ in range(50)] + \
                [[rng.uniform(0, 4), 4.0, rng.uniform(0, 4), 4.0] for _ in range(50)] + \
                [[1.0, 1.0 + 0.02 * i, 3.0, 1.0 + 0.02 * i] for i in range(50)]
        write(f"edges_{pattern}_{tunnel >> 7}", head, edges)
