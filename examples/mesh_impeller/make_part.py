#!/usr/bin/python3
"""Generator of the mesh impeller example: a 6-blade impeller given as meshes only, and the nominal
path a CAM system would write for it. Usage: make_part.py OUT_DIR [--no-check]

Writes into OUT_DIR (each file written to a temporary name, then renamed into place):
  hub.stl       the part: the hub, a surface of revolution about +z, z = h(r), r in [R_IN, R_OUT],
                rising towards the axis, concave (fillet-like) profile; an open sheet, normals up
  blades.stl    the obstacles: N_BLADES closed, outward-oriented blade solids standing on the hub,
                wrapped about z along r (WRAP_DEG) and leaning sideways towards +theta (the ruling
                turned from the hub normal across the camber line by LEAN_IN_DEG at the inlet to
                LEAN_OUT_DEG at the outlet, so the blades twist); all of them in one file
  nominal.cl    the nominal path, ball-end R = 3 mm, axis on the hub normal: `x y z i j k` (tip,
                unit axis tip -> spindle) per line, `# pass K` before each pass
  nominal.apt   the same postures as APT CLDATA, RAPID links between passes
  nominal.npy   the same postures, float64, shape (N, 6), no links

Passes: the channels in CHANNELS (between blades k and k + 1); in each, PASSES_V gives the fraction v of the
angular gap between the two blade walls where they meet the hub (v = 0 on the wall of the blade
at the lower angle, which leans over the channel); each pass runs from the inlet (R_IN + margin) to
the outlet (R_OUT - margin), postures evenly spaced along the ball-centre arc.

Then (unless --no-check) an approximate analysis, printed: meshes closed and oriented, chordal
errors, the ball's distance to blades and hub, and the tool + holder of the scene against the blades
at every nominal posture (blade surfaces sampled densely, exact distance to the revolved tool
profile): how many postures collide, and whether tilting the axis about the feed direction away from
the nearest blade clears them. Units: mm, angles in degrees where the name says _DEG. No randomness.
"""
import io
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

# ---- the part --------------------------------------------------------------------------------
R_IN_MM = 24.0             # hub inner radius: blade leading edges (inlet)
R_OUT_MM = 62.0            # hub outer radius: blade trailing edges (outlet), outer diameter 124 mm
HUB_RISE_MM = 18.0         # hub height at R_IN above its height at R_OUT (z = 0 at the outlet)
N_BLADES = 6
BLADE_THICKNESS_MM = 1.8   # constant, measured normal to the camber surface
BLADE_HEIGHT_MM = 17.3     # ruling length x cos(lean): the height above the hub
BLADE_FOOT_MM = 1.5        # the blade's foot reaches this far below the hub (along the ruling)
WRAP_DEG = 30.0            # camber angle at the outlet minus at the inlet: theta = WRAP (t + t^2)/2
LEAN_IN_DEG = 6.0          # lean at the inlet, across the camber line towards +theta (over the
                           # channel on the blade's +theta side)
LEAN_OUT_DEG = 22.0        # lean at the outlet; linear in t = (r - R_IN) / (R_OUT - R_IN)
CHORD_TOL_MM = 0.01        # hub mesh within this of the surface
BLADE_STATIONS = (97, 9)   # blade mesh stations along t (inlet to outlet) and along the ruling

# ---- the nominal path ------------------------------------------------------------------------
BALL_R_MM = 3.0            # ball-end mill radius
CHANNELS = (0,)            # the channels machined (k: between blade k and k + 1): a finishing job
                           # on one channel, repeated by rotation on the machine
PASSES_V = tuple(0.18 + 0.64 * i / 29 for i in range(30))  # fractions of the angular gap
                           # between the walls (hub): 30 passes, stepover 0.7-1.4 mm
MARGIN_MM = 2.5            # passes run over r in [R_IN + MARGIN, R_OUT - MARGIN] (contact radius)
STEP_MM = 0.65             # largest spacing of postures along the ball-centre arc
APT_LIFT_MM = 20.0         # the APT links: up the tool axis by this at a pass end, down at the next
FEED_MMPM = 1000

# ---- the tool of scene.yaml, for the analysis only ------------------------------------------
SHANK_LENGTH_MM = 40.0     # ball + shank of radius BALL_R up to here from the tip
HOLDER = ((40.0, 6.0), (55.0, 6.0), (55.0, 12.0), (90.0, 12.0))  # (z from tip, radius) stations
CLEARANCE_MM = 0.5         # required tool + holder <-> blades
BALL_GAP_MM = 0.6          # required ball <-> blades on the nominal path
SAMPLE_MM = 0.3            # blade sampling step for the analysis
TILT_STEP_DEG = 2.5        # tilt search: 2.5, 5, ..., MAX_TILT_DEG
MAX_TILT_DEG = 35.0

L_MM = R_OUT_MM - R_IN_MM


# ---- hub: z = h(r) ---------------------------------------------------------------------------
def hub_height(r):
    """Hub height (mm) at radius r (mm): concave, rising towards the axis, flat at the outlet."""
    return HUB_RISE_MM * ((R_OUT_MM - r) / L_MM) ** 2


def hub_slope(r):
    """dh/dr (negative: the hub rises towards the axis)."""
    return -2.0 * HUB_RISE_MM * (R_OUT_MM - r) / L_MM**2


HUB_CURVATURE = 2.0 * HUB_RISE_MM / L_MM**2   # d2h/dr2, constant (1/mm)


def hub_point(r, phi):
    """Points (..., 3) of the hub at radius r, angle phi (rad)."""
    r, phi = np.broadcast_arrays(np.asarray(r, float), np.asarray(phi, float))
    return np.stack([r * np.cos(phi), r * np.sin(phi), hub_height(r)], axis=-1)


def hub_normal(r, phi):
    """Unit normals (..., 3) of the hub, up and out of the material: (-h' e_r + e_z) / |.|."""
    r, phi = np.broadcast_arrays(np.asarray(r, float), np.asarray(phi, float))
    s = hub_slope(r)
    norm = np.sqrt(1.0 + s * s)
    return np.stack([-s * np.cos(phi) / norm, -s * np.sin(phi) / norm, 1.0 / norm], axis=-1)


def hub_signed_distance(points):
    """Signed distance (mm, > 0 above) of points (..., 3) to the hub's profile revolved (the
    parabola extended past R_IN, R_OUT): the 2-D distance in the point's meridional plane, by
    Newton on the foot radius."""
    rho = np.hypot(points[..., 0], points[..., 1])
    z = points[..., 2]
    r = rho.copy()
    for _ in range(30):
        h, s = hub_height(r), hub_slope(r)
        f = (r - rho) + (h - z) * s
        df = 1.0 + s * s + (h - z) * HUB_CURVATURE
        r = r - f / df
    h, s = hub_height(r), hub_slope(r)
    d = np.hypot(rho - r, z - h)
    side = np.sign(-(rho - r) * s + (z - h))
    return np.where(side < 0, -d, d)


# ---- blades: a ruled camber surface, thickened along its normal -----------------------------
def camber_angle(t):
    """Camber line angle (rad) of blade 0 at t = (r - R_IN) / L: 0 at the inlet, WRAP at the
    outlet."""
    return math.radians(WRAP_DEG) * 0.5 * (t + t * t)


def lean(t):
    """Lean (rad) at t: the ruling turns from the hub normal by this, about the camber line,
    towards +theta (so the +theta side overhangs the channel next to it by this angle)."""
    return np.radians(LEAN_IN_DEG + (LEAN_OUT_DEG - LEAN_IN_DEG) * np.asarray(t, float))


def ruling_length(t):
    """Camber ruling length (mm) from the hub to the blade tip at t."""
    return BLADE_HEIGHT_MM / np.cos(lean(t))


def camber_point(t, w, k):
    """Camber surface of blade k at (t, w): foot on the hub + w along the leaning ruling."""
    t, w = np.broadcast_arrays(np.asarray(t, float), np.asarray(w, float))
    foot, normal, across = camber_foot(t, k)
    ruling = np.cos(lean(t))[..., None] * normal + np.sin(lean(t))[..., None] * across
    return foot + w[..., None] * ruling, ruling


def camber_foot(t, k):
    """Foot of blade k's camber surface on the hub at t, the hub normal there and the unit
    tangent of the hub across the camber line (normal x camber tangent, to the +theta side)."""
    r = R_IN_MM + t * L_MM
    theta = camber_angle(t) + 2.0 * math.pi * k / N_BLADES
    dt = 1e-6
    r1, r0 = r + dt * L_MM, r - dt * L_MM
    tangent = (hub_point(r1, camber_angle(t + dt) + 2.0 * math.pi * k / N_BLADES)
               - hub_point(r0, camber_angle(t - dt) + 2.0 * math.pi * k / N_BLADES))
    normal = hub_normal(r, theta)
    across = np.cross(normal, tangent)
    across /= np.linalg.norm(across, axis=-1, keepdims=True)
    e_theta = np.stack([-np.sin(theta), np.cos(theta), np.zeros_like(theta)], axis=-1)
    across *= np.sign(np.sum(across * e_theta, axis=-1))[..., None]
    return hub_point(r, theta), normal, across


def blade_side_point(t, s, k, side):
    """Side surface of blade k (side +1: the +theta side, -1: the other) at t and s in [0, 1]
    (s = 0: the foot under the hub, 1: the tip): camber point + side * thickness/2 * unit normal."""
    t, s = np.broadcast_arrays(np.asarray(t, float), np.asarray(s, float))
    w = -BLADE_FOOT_MM + s * (ruling_length(t) + BLADE_FOOT_MM)
    return camber_offset(t, w, k, side * 0.5 * BLADE_THICKNESS_MM)


def camber_offset(t, w, k, offset_mm):
    """Camber point at (t, w) moved by offset_mm along the unit normal that points to +theta."""
    point, ruling = camber_point(t, w, k)
    dt = 1e-6
    along = (camber_point(t + dt, w, k)[0] - camber_point(t - dt, w, k)[0]) / (2 * dt)
    normal = np.cross(along, ruling)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    theta = camber_angle(t) + 2.0 * math.pi * k / N_BLADES
    e_theta = np.stack([-np.sin(theta), np.cos(theta), np.zeros_like(theta)], axis=-1)
    normal *= np.sign(np.sum(normal * e_theta, axis=-1))[..., None]
    return point + np.asarray(offset_mm)[..., None] * normal


# ---- meshes ----------------------------------------------------------------------------------
def hub_mesh():
    """Triangles (T, 3, 3) of the hub annulus, normals up; stations sized for CHORD_TOL_MM."""
    # circumferential chord error r (1 - cos(dphi/2)) <= 0.5 tol at R_OUT (chords below the hub);
    # meridional chords lie above the concave profile by dr^2 h'' / 8 vertically, kept <= 0.2 tol
    # so that a ball on the true hub sits < 5 um into the mesh (check's gouge tolerance)
    dphi = 2.0 * math.acos(1.0 - 0.5 * CHORD_TOL_MM / R_OUT_MM)
    n_phi = N_BLADES * math.ceil(2.0 * math.pi / dphi / N_BLADES)
    n_r = math.ceil(L_MM / math.sqrt(8.0 * 0.2 * CHORD_TOL_MM / HUB_CURVATURE))
    r = np.linspace(R_IN_MM, R_OUT_MM, n_r + 1)
    phi = np.linspace(0.0, 2.0 * math.pi, n_phi, endpoint=False)
    grid = hub_point(r[:, None], phi[None, :])                 # (n_r + 1, n_phi, 3)
    a, b = grid[:-1], grid[1:]                                  # inner, outer ring
    a1, b1 = np.roll(a, -1, axis=1), np.roll(b, -1, axis=1)    # next angle
    tri1 = np.stack([a, b, b1], axis=2).reshape(-1, 3, 3)      # e_r x e_phi = up
    tri2 = np.stack([a, b1, a1], axis=2).reshape(-1, 3, 3)
    return np.concatenate([tri1, tri2])


def blade_rings(k, n_t, n_w):
    """Vertices (n_t, 2 n_w, 3) of blade k: per station t, the ring +side foot -> tip, then
    -side tip -> foot."""
    t = np.linspace(0.0, 1.0, n_t)[:, None]
    s = np.linspace(0.0, 1.0, n_w)[None, :]
    plus = blade_side_point(t, s, k, +1)
    minus = blade_side_point(t, s, k, -1)[:, ::-1]
    return np.concatenate([plus, minus], axis=1)


def blade_mesh(k, n_t, n_w):
    """Triangles (T, 3, 3) of the closed blade k: the ring swept along t, both ends capped."""
    ring = blade_rings(k, n_t, n_w)
    m = ring.shape[1]
    a, b = ring[:-1], ring[1:]
    a1, b1 = np.roll(a, -1, axis=1), np.roll(b, -1, axis=1)
    sides = np.concatenate([np.stack([a, b, b1], axis=2).reshape(-1, 3, 3),
                            np.stack([a, b1, a1], axis=2).reshape(-1, 3, 3)])
    j = np.arange(n_w - 1)      # cap strip between ring index j (+side) and m-1-j (-side)
    cap_idx = np.concatenate([np.stack([j, j + 1, m - 2 - j], axis=1),
                              np.stack([j, m - 2 - j, m - 1 - j], axis=1)])
    cap_in = ring[0][cap_idx]
    cap_out = ring[-1][cap_idx[:, ::-1]]
    tris = np.concatenate([sides, cap_in, cap_out])
    if signed_volume(tris) < 0:
        tris = tris[:, ::-1]
    return tris


def signed_volume(tris):
    """Volume (mm^3) enclosed by triangles (T, 3, 3), > 0 when they face out."""
    return float(np.sum(np.einsum("ij,ij->i", tris[:, 0], np.cross(tris[:, 1], tris[:, 2]))) / 6.0)


def closed_and_oriented(tris):
    """True when every directed edge has exactly one reverse (closed, consistently oriented)."""
    verts, inverse = np.unique(tris.reshape(-1, 3), axis=0, return_inverse=True)
    idx = inverse.reshape(-1, 3)
    edges = np.concatenate([idx[:, [0, 1]], idx[:, [1, 2]], idx[:, [2, 0]]])
    n = len(verts)
    forward = edges[:, 0].astype(np.int64) * n + edges[:, 1]
    backward = edges[:, 1].astype(np.int64) * n + edges[:, 0]
    forward.sort()
    backward.sort()
    unique_forward = len(np.unique(forward)) == len(forward)
    return bool(unique_forward and np.array_equal(forward, backward))


# ---- files -----------------------------------------------------------------------------------
def write_atomically(path, data):
    """Writes bytes to path through a temporary name (no truncated file under the final name)."""
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_bytes(data)
    os.replace(tmp, path)


def stl_bytes(tris, name):
    """Binary STL of triangles (T, 3, 3) (float32, as STL stores them)."""
    tris32 = tris.astype(np.float32)
    normal = np.cross(tris32[:, 1] - tris32[:, 0], tris32[:, 2] - tris32[:, 0])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-30)
    record = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    body = np.zeros(len(tris), dtype=record)
    body["normal"] = normal
    body["v"] = tris32
    header = f"fieldpath examples/mesh_impeller {name}".encode().ljust(80, b" ")
    return header + np.uint32(len(tris)).tobytes() + body.tobytes()


def fmt(x):
    """A number that reads back exactly."""
    return repr(float(x))


def cl_text(passes):
    """nominal.cl: a header, then `# pass K` and one `x y z i j k` line per posture."""
    lines = ["# fieldpath examples/mesh_impeller: nominal path, ball-end R 3 mm, axis on the hub "
             "normal", "# x y z i j k: tool tip (mm), unit axis from the tip to the spindle"]
    for number, postures in enumerate(passes, 1):
        lines.append(f"# pass {number}")
        lines += [" ".join(fmt(x) for x in row) for row in postures]
    return "\n".join(lines) + "\n"


def goto(row):
    """An APT GOTO/x,y,z,i,j,k record."""
    return "GOTO/" + ",".join(fmt(x) for x in row)


def apt_text(passes):
    """nominal.apt: APT CLDATA, the same postures; RAPID links between passes."""
    lines = ["PARTNO/MESH_IMPELLER", "UNITS/MM", "MULTAX/ON", "CUTTER/6,3,0,3,0,0,40"]
    for number, postures in enumerate(passes):
        if number > 0:     # link: up the last axis, across, down to above the next pass start
            last, first = passes[number - 1][-1], postures[0]
            lines += ["RAPID", goto(np.r_[last[:3] + APT_LIFT_MM * last[3:], last[3:]])]
            lines += ["RAPID", goto(np.r_[first[:3] + APT_LIFT_MM * first[3:], first[3:]])]
        lines.append(f"FEDRAT/MMPM,{FEED_MMPM}")
        lines += [goto(row) for row in postures]
    lines.append("FINI")
    return "\n".join(lines) + "\n"


def npy_bytes(postures):
    """nominal.npy: float64, shape (N, 6), C order."""
    buffer = io.BytesIO()
    np.save(buffer, np.ascontiguousarray(postures, dtype="<f8"))
    return buffer.getvalue()


# ---- nominal passes --------------------------------------------------------------------------
def wall_feet(side, n=801):
    """(radius, angle) samples of where the side `side` of blade 0 meets the hub, by bisection on
    the ruling parameter s at each station t."""
    t = np.linspace(0.0, 1.0, n)
    lo, hi = np.zeros(n), np.full(n, 0.5)
    for _ in range(50):
        mid = 0.5 * (lo + hi)
        above = hub_signed_distance(blade_side_point(t, mid, 0, side)) > 0
        hi = np.where(above, mid, hi)
        lo = np.where(above, lo, mid)
    foot = blade_side_point(t, 0.5 * (lo + hi), 0, side)
    rho = np.hypot(foot[:, 0], foot[:, 1])
    assert np.all(np.diff(rho) > 0), "wall foot radius must grow along the blade"
    return rho, np.unwrap(np.arctan2(foot[:, 1], foot[:, 0]))


def nominal_passes():
    """List of (N_k, 6) arrays: tip, axis per posture, channel by channel, v by v."""
    rho_p, phi_p = wall_feet(+1)      # +theta wall of blade k: v = 0 (it leans over the channel)
    rho_m, phi_m = wall_feet(-1)      # -theta wall of blade k + 1: v = 1
    rho = np.linspace(R_IN_MM + MARGIN_MM, R_OUT_MM - MARGIN_MM, 4001)
    wall0 = np.interp(rho, rho_p, phi_p)
    wall1 = np.interp(rho, rho_m, phi_m) + 2.0 * math.pi / N_BLADES
    passes = []
    for k in CHANNELS:
        for v in PASSES_V:
            phi = wall0 + v * (wall1 - wall0) + 2.0 * math.pi * k / N_BLADES
            centre = hub_point(rho, phi) + BALL_R_MM * hub_normal(rho, phi)
            arc = np.r_[0.0, np.cumsum(np.linalg.norm(np.diff(centre, axis=0), axis=1))]
            n_steps = math.ceil(arc[-1] / STEP_MM)
            target = np.linspace(0.0, arc[-1], n_steps + 1)
            r_k = np.interp(target, arc, rho)
            phi_k = np.interp(target, arc, phi)
            passes.append(np.concatenate([hub_point(r_k, phi_k), hub_normal(r_k, phi_k)], axis=1))
    return passes


# ---- analysis: the revolved tool against sampled blades -------------------------------------
def tool_pieces():
    """(kind, radius, z0, z1) of the tool + holder, z from the tip along the axis."""
    pieces = [("ball", BALL_R_MM, BALL_R_MM, BALL_R_MM),
              ("shank", BALL_R_MM, BALL_R_MM, SHANK_LENGTH_MM)]
    for (z0, r0), (z1, r1) in zip(HOLDER[:-1], HOLDER[1:]):
        if z1 > z0:
            pieces.append(("holder", max(r0, r1), z0, z1))   # cylinders here (r0 == r1)
    return pieces


def profile_distance(rho, z):
    """Signed distances (pieces, P) of points at (rho, z) of the tool frame to each tool piece:
    the ball (a sphere), the shank and holder cylinders (boxes in the meridional plane)."""
    out = []
    for kind, radius, z0, z1 in tool_pieces():
        if kind == "ball":
            out.append(np.hypot(rho, z - z0) - radius)
        else:
            qx, qz = rho - radius, np.maximum(z0 - z, z - z1)
            outside = np.hypot(np.maximum(qx, 0.0), np.maximum(qz, 0.0))
            out.append(outside + np.minimum(np.maximum(qx, qz), 0.0))
    return np.array(out)


class BladeSamples:
    """Points on the blade surfaces every ~SAMPLE_MM, bucketed in cubic cells for pruning."""

    CELL_MM = 3.0

    def __init__(self):
        pts = []
        for k in range(N_BLADES):
            n_t = math.ceil(70.0 / SAMPLE_MM)            # blade length < 70 mm along t
            n_w = math.ceil(22.0 / SAMPLE_MM)            # ruling < 22 mm
            t = np.linspace(0.0, 1.0, n_t)[:, None]
            s = np.linspace(0.0, 1.0, n_w)[None, :]
            plus, minus = blade_side_point(t, s, k, +1), blade_side_point(t, s, k, -1)
            f = np.linspace(0.0, 1.0, math.ceil(BLADE_THICKNESS_MM / SAMPLE_MM) + 1)[:, None, None]
            tip = plus[None, :, -1] * (1 - f) + minus[None, :, -1] * f
            ends = [plus[i][None] * (1 - f) + minus[i][None] * f for i in (0, -1)]
            pts += [plus.reshape(-1, 3), minus.reshape(-1, 3), tip.reshape(-1, 3)]
            pts += [e.reshape(-1, 3) for e in ends]
        pts = np.concatenate(pts)
        cell = np.floor(pts / self.CELL_MM).astype(np.int64)
        keys, inverse = np.unique(cell, axis=0, return_inverse=True)
        order = np.argsort(inverse, kind="stable")
        self.points = pts[order]
        counts = np.bincount(inverse, minlength=len(keys))
        self.start = np.r_[0, np.cumsum(counts)[:-1]]
        self.count = counts
        self.centre = np.array([self.points[s:s + c].mean(axis=0)
                                for s, c in zip(self.start, self.count)])
        self.radius = np.array([np.linalg.norm(self.points[s:s + c] - m, axis=1).max()
                                for s, c, m in zip(self.start, self.count, self.centre)])

    def distances(self, tip, axis, reach_mm=3.0):
        """(min distance per tool piece kind {ball, shank, holder}, the blade point nearest to the
        ball) for the tool at (tip, axis); distances above reach_mm are reported as reach_mm (not
        searched; the point is then None)."""
        def frame(points):
            rel = points - tip
            z = rel @ axis
            rho = np.linalg.norm(rel - z[:, None] * axis, axis=1)
            return profile_distance(rho, z)

        centre_d = frame(self.centre).min(axis=0) - self.radius
        cells = np.nonzero(centre_d < reach_mm)[0]
        if len(cells) == 0:
            return {"ball": reach_mm, "shank": reach_mm, "holder": reach_mm}, None
        counts = self.count[cells]
        offsets = np.repeat(self.start[cells] - np.r_[0, np.cumsum(counts)[:-1]], counts)
        points = self.points[offsets + np.arange(counts.sum())]
        d = frame(points)
        result = {}
        for kind in ("ball", "shank", "holder"):
            rows = [i for i, p in enumerate(tool_pieces()) if p[0] == kind]
            result[kind] = float(min(reach_mm, d[rows].min()))
        return result, points[np.argmin(d[0])]     # the blade point nearest to the ball


def tilted(posture, alpha, away):
    """Posture with the axis turned by alpha (rad) about the feed direction, the ball centre held,
    towards the unit direction `away` (orthogonal to feed and axis)."""
    tip, axis = posture[:3], posture[3:]
    centre = tip + BALL_R_MM * axis
    new_axis = math.cos(alpha) * axis + math.sin(alpha) * away
    return centre - BALL_R_MM * new_axis, new_axis


def analyse(passes, samples):
    """Nominal clearance per posture and, where short of CLEARANCE_MM, the least tilt (about the
    feed, away from the nearest blade) that clears."""
    reports = []
    for number, postures in enumerate(passes, 1):
        centres = postures[:, :3] + BALL_R_MM * postures[:, 3:]
        feed = np.gradient(centres, axis=0)
        feed /= np.linalg.norm(feed, axis=1, keepdims=True)
        for i, posture in enumerate(postures):
            d, nearest = samples.distances(posture[:3], posture[3:])
            entry = {"pass": number, "index": i, **d, "tilt_deg": None}
            if min(d.values()) < CLEARANCE_MM:
                axis = posture[3:]
                side = np.cross(axis, feed[i])
                side -= side @ axis * axis
                side /= np.linalg.norm(side)
                away = -side if (nearest - centres[i]) @ side > 0 else side
                alpha = TILT_STEP_DEG
                while alpha <= MAX_TILT_DEG + 1e-9:
                    tip, new_axis = tilted(posture, math.radians(alpha), away)
                    dt, _ = samples.distances(tip, new_axis)
                    if min(dt.values()) >= CLEARANCE_MM:
                        entry["tilt_deg"] = alpha
                        break
                    alpha += TILT_STEP_DEG
            reports.append(entry)
    return reports


def summarise(passes, reports, hub_tris, blade_tris):
    """Prints the checks of the geometry and the collision analysis."""
    print(f"part: hub r {R_IN_MM:g}..{R_OUT_MM:g} mm (outer diameter {2 * R_OUT_MM:g}), rise "
          f"{HUB_RISE_MM:g} mm; {N_BLADES} blades {BLADE_THICKNESS_MM:g} mm thick, "
          f"{BLADE_HEIGHT_MM:g} mm high, wrap {WRAP_DEG:g} deg, lean {LEAN_IN_DEG:g} -> "
          f"{LEAN_OUT_DEG:g} deg; passes at v = {', '.join(f'{v:g}' for v in PASSES_V)}")
    edge_mid = 0.5 * (hub_tris + np.roll(hub_tris, -1, axis=1)).reshape(-1, 3)
    centroid = hub_tris.mean(axis=1)
    hub_err = max(np.abs(hub_signed_distance(edge_mid)).max(),
                  np.abs(hub_signed_distance(centroid)).max())
    probes = np.concatenate([edge_mid, centroid])
    hub_above = (probes[:, 2] - hub_height(np.hypot(probes[:, 0], probes[:, 1]))).max()
    n_t, n_w = BLADE_STATIONS
    # blade chord: mesh edge midpoints along t against the surface at the mid parameter
    t_mid = (np.arange(n_t - 1) + 0.5) / (n_t - 1)
    s = np.linspace(0.0, 1.0, n_w)
    ring = blade_rings(0, n_t, n_w)[:, :n_w]
    blade_err = np.linalg.norm(0.5 * (ring[:-1] + ring[1:])
                               - blade_side_point(t_mid[:, None], s[None, :], 0, +1), axis=2).max()
    tips = np.concatenate([blade_rings(k, n_t, n_w)[:, [n_w - 1, n_w]].reshape(-1, 3)
                           for k in range(N_BLADES)])
    feet = np.concatenate([blade_rings(k, n_t, n_w)[:, [0, -1]].reshape(-1, 3)
                           for k in range(N_BLADES)])
    tip_h, foot_h = hub_signed_distance(tips), hub_signed_distance(feet)
    print(f"hub: {len(hub_tris)} triangles, chordal error {hub_err:.4f} mm (edge midpoints, "
          f"centroids), mesh above the surface by <= {1000 * hub_above:.1f} um vertically")
    print(f"blades: {len(blade_tris)} triangles, {N_BLADES} shells, closed and outward: "
          f"{all(closed_and_oriented(blade_mesh(k, n_t, n_w)) for k in range(N_BLADES))}, "
          f"volume {signed_volume(blade_tris):.0f} mm^3; chord along t {blade_err:.4f} mm; "
          f"tip {tip_h.min():.2f}..{tip_h.max():.2f} mm above the hub, feet "
          f"{-foot_h.max():.2f}..{-foot_h.min():.2f} mm below it")
    allp = np.concatenate(passes)
    centres = allp[:, :3] + BALL_R_MM * allp[:, 3:]
    steps = np.concatenate([np.linalg.norm(np.diff(p[:, :3] + BALL_R_MM * p[:, 3:], axis=0), axis=1)
                            for p in passes])
    print(f"path: {len(passes)} passes, {len(allp)} postures, ball-centre steps "
          f"{steps.min():.3f}..{steps.max():.3f} mm, total {steps.sum():.0f} mm; ball centre to "
          f"hub {hub_signed_distance(centres).min():.4f}..{hub_signed_distance(centres).max():.4f} "
          f"mm (R = {BALL_R_MM})")
    if reports is None:
        return
    ball = np.array([r["ball"] for r in reports])
    body = np.array([min(r["shank"], r["holder"]) for r in reports])
    print(f"ball <-> blades: min {ball.min():.3f} mm (required {BALL_GAP_MM}; sampled every "
          f"{SAMPLE_MM} mm: over-estimates a 0.5 mm distance by < ~{SAMPLE_MM**2 / 2:.2f} mm)")
    def nearest(r):
        return min(r["ball"], r["shank"], r["holder"])

    colliding = [r for r in reports if nearest(r) <= 0.0]
    short = [r for r in reports if nearest(r) < CLEARANCE_MM]
    by_kind = {kind: sum(r[kind] <= 0.0 for r in reports) for kind in ("ball", "shank", "holder")}
    print(f"nominal tool + holder <-> blades: min {min(ball.min(), body.min()):.3f} mm (< 0: "
          f"overlap "
          f"depth, capped at the piece radius); {len(colliding)} postures collide "
          f"({', '.join(f'{k} {v}' for k, v in by_kind.items())}), on passes "
          f"{sorted({r['pass'] for r in colliding})}; {len(short)} below the {CLEARANCE_MM} mm "
          f"clearance, on passes {sorted({r['pass'] for r in short})}")
    for name, group in (("colliding", colliding), (f"below {CLEARANCE_MM} mm", short)):
        cleared = [r["tilt_deg"] for r in group if r["tilt_deg"] is not None]
        counts = ", ".join(f"{sum(t <= limit for t in cleared)}/{len(group)} by <= {limit:.0f} deg"
                           for limit in (20.0, 30.0, MAX_TILT_DEG))
        least = (f"; least tilt median {np.median(cleared):.1f}, max {max(cleared):.1f} deg"
                 if cleared else "")
        print(f"  {name}: tilted about the feed away from the nearest blade (steps of "
              f"{TILT_STEP_DEG} deg), clear by {CLEARANCE_MM} mm: {counts}{least}")


def main(argv):
    if len(argv) < 2 or argv[1].startswith("-"):
        print(__doc__.split("\n\n")[0], file=sys.stderr)
        return 1
    out = Path(argv[1])
    check = "--no-check" not in argv[2:]
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    hub_tris = hub_mesh()
    n_t, n_w = BLADE_STATIONS
    blade_tris = np.concatenate([blade_mesh(k, n_t, n_w) for k in range(N_BLADES)])
    passes = nominal_passes()
    postures = np.concatenate(passes)
    write_atomically(out / "hub.stl", stl_bytes(hub_tris, "hub"))
    write_atomically(out / "blades.stl", stl_bytes(blade_tris, "blades"))
    write_atomically(out / "nominal.cl", cl_text(passes).encode())
    write_atomically(out / "nominal.apt", apt_text(passes).encode())
    write_atomically(out / "nominal.npy", npy_bytes(postures))
    written = time.perf_counter() - start
    sizes = ", ".join(f"{name} {(out / name).stat().st_size / 1e6:.2f} MB"
                      for name in ("hub.stl", "blades.stl", "nominal.cl", "nominal.apt",
                                   "nominal.npy"))
    print(f"mesh_impeller: wrote {sizes} into {out} ({written:.2f} s)")
    reports = analyse(passes, BladeSamples()) if check else None
    summarise(passes, reports, hub_tris, blade_tris)
    print(f"total {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
