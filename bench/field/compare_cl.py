#!/usr/bin/env python3
"""Largest angle between the tool axes of two path.cl files, posture by posture (degrees), and
the largest tip distance (mm): compare_cl.py A.cl B.cl"""
import math, sys

def postures(path):
    out = []
    for line in open(path):
        line = line.split("#")[0].split()
        if len(line) >= 6:
            out.append([float(v) for v in line[:6]])
    return out

a, b = postures(sys.argv[1]), postures(sys.argv[2])
print(f"postures {len(a)} / {len(b)}")
worst = tip = 0.0
for p, q in zip(a, b):
    dot = sum(p[3 + i] * q[3 + i] for i in range(3))
    na = math.sqrt(sum(v * v for v in p[3:])); nb = math.sqrt(sum(v * v for v in q[3:]))
    worst = max(worst, math.degrees(math.acos(max(-1.0, min(1.0, dot / (na * nb))))))
    tip = max(tip, math.dist(p[:3], q[:3]))
print(f"max axis angle {worst:.6f} deg, max tip distance {tip:.6f} mm")
