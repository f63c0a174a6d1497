#!/usr/bin/env python3
"""The mesh example's blades as many obstacle files (a fixture or an assembly of bodies, a CAM
export with one file a body): each blade cut along its chord into PIECES closed pieces, one STL
each, and scene.yaml's obstacles listing them; with --one-file the same pieces in one STL (the
peer: the same geometry, so the same path.cl). The cuts add caps inside the blades, which the
field samples: the path differs a little from blades.stl's. Run make_part.py into DIR first.
Usage: blade_bodies.py DIR PIECES [--one-file]   (PIECES 1: one file a blade)"""
import re
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "examples" / "mesh_impeller"))
import make_part as mp  # noqa: E402


def piece(k, t0, t1, n_t, n_w):
    """Closed triangles of blade k between chord fractions t0 and t1 (make_part.blade_mesh's
    sweep and caps over that span)."""
    t = np.linspace(t0, t1, n_t)[:, None]
    s = np.linspace(0.0, 1.0, n_w)[None, :]
    ring = np.concatenate([mp.blade_side_point(t, s, k, +1),
                           mp.blade_side_point(t, s, k, -1)[:, ::-1]], axis=1)
    m = ring.shape[1]
    a, b = ring[:-1], ring[1:]
    a1, b1 = np.roll(a, -1, axis=1), np.roll(b, -1, axis=1)
    sides = np.concatenate([np.stack([a, b, b1], axis=2).reshape(-1, 3, 3),
                            np.stack([a, b1, a1], axis=2).reshape(-1, 3, 3)])
    j = np.arange(n_w - 1)
    cap = np.concatenate([np.stack([j, j + 1, m - 2 - j], axis=1),
                          np.stack([j, m - 2 - j, m - 1 - j], axis=1)])
    tris = np.concatenate([sides, ring[0][cap], ring[-1][cap[:, ::-1]]])
    return tris if mp.signed_volume(tris) > 0 else tris[:, ::-1]


def main(out, pieces, one_file):
    n_t, n_w = mp.BLADE_STATIONS
    per = max(1, (n_t - 1) // pieces)
    bodies = {f"blade{k}_{c}.stl": piece(k, c / pieces, (c + 1) / pieces, per + 1, n_w)
              for k in range(mp.N_BLADES) for c in range(pieces)}
    if one_file:
        bodies = {"pieces.stl": np.concatenate(list(bodies.values()))}
    names = list(bodies)
    for name, tris in bodies.items():
        mp.write_atomically(out / name, mp.stl_bytes(tris, name))
    scene = (out / "scene.yaml").read_text()
    listed = "".join(f"  - mesh: {n}\n" for n in names)
    scene, found = re.subn(r"^  - mesh: blades\.stl.*\n", lambda _: listed, scene, flags=re.M)
    assert found == 1, "no '  - mesh: blades.stl' line in scene.yaml"
    (out / "scene.yaml").write_text(scene)
    print(f"{out}: {len(names)} obstacle files")


if __name__ == "__main__":
    main(Path(sys.argv[1]), int(sys.argv[2]), "--one-file" in sys.argv[3:])
