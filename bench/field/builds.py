#!/usr/bin/env python3
"""The voxel build's backends side by side on one machine, same run (issue 15): runs
`fieldpath field build SCENE --voxel H --refine-tolerance T --backend B` for each backend,
alternating, REPEATS times, and prints the medians of the build's own seconds (build, nodes,
refinement) and of the process's user + system CPU seconds, with each backend's speed-up against
the first one.

  bench/field/builds.py FIELDPATH SCENE H T REPEATS BACKEND[,BACKEND...] [--study-scene]

--study-scene: the scene with field.sample_step 0.5 (the study's 20400-25000 samples) instead of
its own. The .vdb goes to a temporary folder (its write is not in the build's seconds).
"""
import os, re, resource, statistics, subprocess, sys, tempfile

fieldpath, scene, h, tol, repeats, backends = sys.argv[1:7]
backends = backends.split(",")
tmp = tempfile.mkdtemp(prefix="fp_builds_")
if "--study-scene" in sys.argv:
    text = open(scene).read()
    patched = re.sub(r"sample_step: 1\.0 ", "sample_step: 0.5 ", text)
    assert patched != text, "no 'sample_step: 1.0 ' in the scene"
    scene = os.path.join(os.path.dirname(os.path.abspath(scene)), ".study_scene_tmp.yaml")
    open(scene, "w").write(patched)
pattern = re.compile(r"build ([0-9.]+) s \((\w+) nodes ([0-9.]+) s, refinement ([0-9.]+) s\)")
runs = {b: [] for b in backends}
samples = nodes = None
try:
    for rep in range(int(repeats)):
        for b in backends:
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            out = subprocess.run([fieldpath, "--quiet", "field", "build", scene, "--voxel", h,
                                  "--refine-tolerance", tol, "--backend", b, "--out",
                                  os.path.join(tmp, "f.vdb")], capture_output=True, text=True,
                                 check=True).stdout
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
            m = pattern.search(out)
            samples = re.search(r"(\d+) samples", out).group(1)
            nodes = re.search(r"active nodes: (\d+)", out).group(1)
            runs[b].append((float(m.group(1)), float(m.group(3)), float(m.group(4)), cpu))
            print(f"rep {rep + 1} {b}: build {m.group(1)} s, nodes {m.group(3)} s, refinement "
                  f"{m.group(4)} s, process CPU {cpu:.2f} s", flush=True)
finally:
    if "--study-scene" in sys.argv:
        os.remove(scene)
print(f"\n{samples} samples, {nodes} active nodes, h {h} mm, refine tolerance {tol}, "
      f"medians of {repeats}, load average at the end {os.getloadavg()}")
print("| backend | build s | nodes s | refinement s | process CPU s | build × vs "
      f"{backends[0]} | CPU × vs {backends[0]} |")
print("|---|---:|---:|---:|---:|---:|---:|")
first = None
for b in backends:
    med = [statistics.median(r[k] for r in runs[b]) for k in range(4)]
    first = first or med
    print(f"| {b} | {med[0]:.3f} | {med[1]:.3f} | {med[2]:.3f} | {med[3]:.2f} | "
          f"{first[0] / med[0]:.2f} | {first[3] / med[3]:.2f} |")
