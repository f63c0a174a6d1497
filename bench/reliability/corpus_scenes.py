#!/usr/bin/python3
"""The scenes of bench/reliability/corpus.sh: single passes with corners beside walls and CAM
finishing jobs, each a folder with scene.yaml, its STL meshes (binary, closed, facing out) and its
nominal path (nominal.cl, DESIGN.md's `.cl`: `x y z i j k` of the tip and the unit axis, `# pass K`
before each pass). Deterministic: no randomness, the same bytes on every run.

Usage: corpus_scenes.py OUT_DIR            writes OUT_DIR/JOB/ for every job, and OUT_DIR/jobs.txt:
                                          one line a job, `JOB EXPECT [generate flags...]`, EXPECT
                                          `ok` (generate exits 0) or `fail` (on_limit: fail, exit 1)
       corpus_scenes.py --reverse IN OUT   IN's `# pass` blocks each in reverse order, `# link`
                                          blocks dropped (ab_jobs.sh's reverse_cl)
       corpus_scenes.py --unguide IN OUT   the impeller scene IN with its passes read from rev.cl
                                          (no `guide`, the `path` block replaced)
       corpus_scenes.py --apt IN OUT       IN's passes as APT CLDATA the way a CAM system writes it
                                          (OUT .apt or .cls; see write_apt)
       corpus_scenes.py --npy IN OUT f4|f8 6|7
                                          IN's postures as .npy, float32 or float64, N x 6 or N x 7
                                          (a 7th column: a spindle angle); no pass markers
       corpus_scenes.py --shift IN OUT X0 X1 DY
                                          IN with the tips of x in [X0, X1] moved DY along y: a
                                          deliberate collision for `check` of a path fieldpath did
                                          not write
       corpus_scenes.py --small-impeller IN OUT
                                          the impeller scene IN cut to 3 passes over u 0..0.4: a
                                          `study` that takes seconds, not minutes

Jobs (units mm, degrees; the floor, the `part`, is z <= 0 unless said):
  corner_away_T_rR    a pass along x at y = 0, 4.5 mm from a straight wall (y 4.5..8.5, 31 high)
                      on its left, turning right (away from the wall) by T deg at x = 0; the corner
                      sharp (R 0) or filleted R 2 / R 6 on the pass
  corner_pocket_T_rR  the same turn with the wall bent along the pass (a pocket's inner corner,
                      the wall on the outside of the turn, 4.5 mm from both legs)
  corner_boss_T_K     turning left by T round a wedge boss's apex (the wall on the inside of the
                      turn): K = sharp (the offset legs extended to their corner), round (an arc of
                      4.5 about the sharp apex), fillet (the apex rounded R 2, the arc 6.5)
  climb_S_D_T_A       a 3-D corner on a plane sloped S deg: a contour pass beside a wall turning by
                      T in the plane, climbing (D = up, the wall downhill) or descending (D = down,
                      the wall uphill); the axis A = normal (the plane's: leaning downhill, so
                      toward the wall when climbing) or vert
  ramp_B_D_A          a floor running into a ramp of B deg through a concave R 8 blend, a wall
                      beside; D up / down the ramp, axis A = normal (5-axis) or vert (3-axis)
  pocket_rR           a 60 x 40 pocket 30 deep, corner radii R, finished by 6 closed offset loops
                      (ball R 3, shank to 35, holder R 7 / 15); r3 written as its corners and arcs
                      only (path.step 0.5), r3_cw the same loops the other way round (conventional),
                      r0_nominal the r0 job's generate --nominal (upright: clear, 0.98 mm)
  boss_pocket         a 16 x 10 boss (R 3 corners, 20 high) in the R 3 pocket, 2 loops off the
                      walls and 2 round the boss
  lpocket             an L-shaped pocket (60 x 50, a 30 x 25 notch), 3 loops
  draft_pocket        the R 3 pocket with walls drafted 5 deg (wider at the top)
  zigzag              a raster along x over a floor between two walls, one block (the reader splits
                      its legs and step-overs)
  fail_tilt_corner    corner_away_90_r0 with max_tilt_deg 5 and on_limit: fail (expected exit 1)
  fail_tilt_pocket    pocket_r0 with max_tilt_deg 2 and on_limit: fail (expected exit 1)
"""
import math
import os
import struct
import sys

STEP = 0.5            # posture spacing along the tip path, mm
WALL_GAP = 4.5        # pass (tip / ball centre line) to wall face
WALL_T = 4.0          # corner scenes' wall thickness
WALL_TOP = 30.0
POCKET_DEPTH = 30.0


# ---- 2-D helpers ------------------------------------------------------------------------------
def rot(v, deg):
    a = math.radians(deg)
    return (v[0] * math.cos(a) - v[1] * math.sin(a), v[0] * math.sin(a) + v[1] * math.cos(a))


def add(a, b, s=1.0):
    return (a[0] + s * b[0], a[1] + s * b[1])


def left(d):
    return (-d[1], d[0])


def unit(v):
    n = math.hypot(v[0], v[1])
    return (v[0] / n, v[1] / n)


def area2(poly):
    return sum(poly[i][0] * poly[(i + 1) % len(poly)][1] - poly[(i + 1) % len(poly)][0] * poly[i][1]
               for i in range(len(poly)))


def ccw(poly):
    return poly if area2(poly) > 0 else poly[::-1]


def offset_poly(poly, d):
    """A closed polygon's edges moved d to their left (inward for a CCW polygon), mitered."""
    n = len(poly)
    out = []
    for i in range(n):
        p0, p1, p2 = poly[i - 1], poly[i], poly[(i + 1) % n]
        n1, n2 = left(unit(add(p1, p0, -1))), left(unit(add(p2, p1, -1)))
        k = 1.0 + n1[0] * n2[0] + n1[1] * n2[1]
        out.append(add(p1, (n1[0] + n2[0], n1[1] + n2[1]), d / k))
    return out


def arc_pts(c, r, a0, a1, closed_end=True):
    """Points of the arc about c of radius r from angle a0 to a1 (deg), at most 10 deg apart."""
    n = max(1, int(math.ceil(abs(a1 - a0) / 10.0)))
    pts = []
    for k in range(n + 1 if closed_end else n):
        a = math.radians(a0 + (a1 - a0) * k / n)
        pts.append((c[0] + r * math.cos(a), c[1] + r * math.sin(a)))
    return pts


def rounded_rect(x0, y0, x1, y1, r):
    """CCW, starting at the middle of the bottom edge; corners as arcs of 10 deg chords (R 0: sharp)."""
    if r <= 1e-9:
        return [((x0 + x1) / 2, y0), (x1, y0), (x1, y1), (x0, y1), (x0, y0)]
    pts = [((x0 + x1) / 2, y0)]
    pts += arc_pts((x1 - r, y0 + r), r, -90, 0)
    pts += arc_pts((x1 - r, y1 - r), r, 0, 90)
    pts += arc_pts((x0 + r, y1 - r), r, 90, 180)
    pts += arc_pts((x0 + r, y0 + r), r, 180, 270)
    return pts


def densify(pts, step=STEP, closed=False):
    """Points every <= step along the polyline (its vertices kept); closed: back to the start."""
    seq = list(pts) + ([pts[0]] if closed else [])
    out = [seq[0]]
    for a, b in zip(seq, seq[1:]):
        dim = len(a)
        length = math.sqrt(sum((b[i] - a[i]) ** 2 for i in range(dim)))
        if length < 1e-9:
            continue
        n = max(1, int(math.ceil(length / step - 1e-9)))
        for k in range(1, n + 1):
            out.append(tuple(a[i] + (b[i] - a[i]) * k / n for i in range(dim)))
    return out


def fillet_path(start, corner, end, r):
    """start -> corner -> end with the corner filleted R r (arcs in 2-degree chords)."""
    if r <= 1e-9:
        return [start, corner, end]
    d1, d2 = unit(add(corner, start, -1)), unit(add(end, corner, -1))
    turn = math.degrees(math.atan2(d1[0] * d2[1] - d1[1] * d2[0], d1[0] * d2[0] + d1[1] * d2[1]))
    t = r * math.tan(math.radians(abs(turn)) / 2)
    p1 = add(corner, d1, -t)
    side = left(d1) if turn > 0 else (d1[1], -d1[0])
    c = add(p1, side, r)
    a0 = math.degrees(math.atan2(p1[1] - c[1], p1[0] - c[0]))
    n = max(2, int(math.ceil(abs(turn) / 2.0)))
    arc = [(c[0] + r * math.cos(math.radians(a0 + turn * k / n)),
            c[1] + r * math.sin(math.radians(a0 + turn * k / n))) for k in range(n + 1)]
    return [start] + arc + [end]


# ---- meshes -----------------------------------------------------------------------------------
def ear_clip(poly):
    """Triangles (index triples) of a simple CCW polygon."""
    idx = list(range(len(poly)))
    tris = []

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    guard = 0
    while len(idx) > 3 and guard < 100000:
        guard += 1
        for k in range(len(idx)):
            i0, i1, i2 = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            a, b, c = poly[i0], poly[i1], poly[i2]
            if cross(a, b, c) <= 1e-12:
                continue
            if any(cross(a, b, poly[j]) >= 0 and cross(b, c, poly[j]) >= 0 and cross(c, a, poly[j]) >= 0
                   for j in idx if j not in (i0, i1, i2)):
                continue
            tris.append((i0, i1, i2))
            del idx[k]
            break
        else:
            raise ValueError("ear_clip: no ear (not a simple CCW polygon)")
    tris.append(tuple(idx))
    return tris


def prism(poly, z0, z1):
    """A closed solid: the polygon poly (x, y) from z0 to z1, facing out (collinear corners dropped)."""
    poly = ccw(poly)
    while True:
        keep = [p for i, p in enumerate(poly)
                if abs((p[0] - poly[i - 1][0]) * (poly[(i + 1) % len(poly)][1] - poly[i - 1][1])
                       - (p[1] - poly[i - 1][1]) * (poly[(i + 1) % len(poly)][0] - poly[i - 1][0])) > 1e-9]
        if len(keep) == len(poly):
            break
        poly = keep
    n = len(poly)
    tris = []
    for a, b, c in ear_clip(poly):
        tris.append(((*poly[a], z1), (*poly[b], z1), (*poly[c], z1)))
        tris.append(((*poly[a], z0), (*poly[c], z0), (*poly[b], z0)))
    for i in range(n):
        p, q = poly[i], poly[(i + 1) % n]
        tris.append(((*p, z0), (*q, z0), (*q, z1)))
        tris.append(((*p, z0), (*q, z1), (*p, z1)))
    return tris


def ring(inner_bottom, inner_top, thickness, z0, z1):
    """A closed solid round a pocket: the inner wall from the CCW polygon inner_bottom at z0 to
    inner_top at z1 (the same vertex count: a draft), the outer wall the bottom polygon offset out by
    thickness, vertical."""
    ib, it = inner_bottom, inner_top
    ob = offset_poly(ib, -thickness)
    ot = ob
    n = len(ib)
    tris = []

    def quad(a, b, c, d):  # a b c d counter-clockwise seen from outside the solid
        tris.append((a, b, c))
        tris.append((a, c, d))

    for i in range(n):
        j = (i + 1) % n
        # inner wall: faces the pocket (inward), so seen from the pocket the order is i, j reversed
        quad((*ib[j], z0), (*ib[i], z0), (*it[i], z1), (*it[j], z1))
        # outer wall
        quad((*ob[i], z0), (*ob[j], z0), (*ot[j], z1), (*ot[i], z1))
        # top (z1, facing +z) between inner top and outer top
        quad((*it[i], z1), (*ot[i], z1), (*ot[j], z1), (*it[j], z1))
        # bottom (z0, facing -z)
        quad((*ib[i], z0), (*ib[j], z0), (*ob[j], z0), (*ob[i], z0))
    return tris


def hexahedron(c):
    """A closed solid of 8 corners: c[0:4] the bottom CCW seen from above, c[4:8] the top above them."""
    b, t = c[:4], c[4:]
    tris = [(t[0], t[1], t[2]), (t[0], t[2], t[3]), (b[0], b[2], b[1]), (b[0], b[3], b[2])]
    for i in range(4):
        j = (i + 1) % 4
        tris += [(b[i], b[j], t[j]), (b[i], t[j], t[i])]
    return tris


def check_closed(tris, name):
    """Every directed edge once, and its reverse once: closed and consistently wound; volume > 0."""
    edges = {}
    vol = 0.0
    for t in tris:
        for k in range(3):
            e = (t[k], t[(k + 1) % 3])
            edges[e] = edges.get(e, 0) + 1
        a, b, c = t
        vol += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0
    bad = [e for e, k in edges.items() if k != 1 or edges.get((e[1], e[0]), 0) != 1]
    if bad or vol <= 0:
        raise ValueError(f"{name}: not a closed outward solid ({len(bad)} bad edges, volume {vol:.3f})")


def key(p):
    return tuple(round(float(v), 9) for v in p)


def write_stl(path, *solids):
    """Binary STL of closed solids (checked closed, outward); degenerate triangles left out."""
    out = []
    for s in solids:
        s = [tuple(key(p) for p in t) for t in s]
        s = [t for t in s if len(set(t)) == 3 and tri_area(t) > 1e-12]
        check_closed(s, path)
        out += s
    data = bytearray(b"fieldpath corpus".ljust(80, b" "))
    data += struct.pack("<I", len(out))
    for a, b, c in out:
        u = [b[i] - a[i] for i in range(3)]
        v = [c[i] - a[i] for i in range(3)]
        n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        ln = math.sqrt(sum(x * x for x in n)) or 1.0
        data += struct.pack("<12fH", *(x / ln for x in n), *a, *b, *c, 0)
    with open(path, "wb") as f:
        f.write(data)


def tri_area(t):
    a, b, c = t
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    return 0.5 * math.sqrt(sum(x * x for x in n))


def box(x0, x1, y0, y1, z0, z1):
    return prism([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], z0, z1)


# ---- paths and scenes -------------------------------------------------------------------------
def fmt(x):
    s = f"{x:.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def write_cl(path, passes, comment):
    """passes: lists of (x, y, z, i, j, k)."""
    lines = [f"# {comment}"]
    for k, p in enumerate(passes, 1):
        lines.append(f"# pass {k}")
        for q in p:
            ln = math.sqrt(q[3] ** 2 + q[4] ** 2 + q[5] ** 2)
            lines.append(" ".join(fmt(v) for v in (q[0], q[1], q[2], q[3] / ln, q[4] / ln, q[5] / ln)))
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


CORNER_TOOL = ("tool: { shape: ball, radius: 3, length: 15 }\n"
               "holder: [[15, 6], [30, 6], [30, 12], [70, 12]]\n")
POCKET_TOOL = ("tool: { shape: ball, radius: 3, length: 35 }\n"
               "holder: [[35, 7], [50, 7], [50, 15], [100, 15]]\n")


def write_scene(d, title, tool, voxel=0.5, tilt=35, on_limit="clamp", step=None, obstacles=("walls.stl",)):
    path = "path: { nominal: nominal.cl, lead_deg: 0" + (f", step: {step}" if step else "") + " }\n"
    text = (f"# {title}\n"
            "obstacles:\n" + "".join(f"  - mesh: {o}\n" for o in obstacles) +
            "part: floor.stl\n" + tool +
            "clearance: 0.5\n"
            f"field: {{ r0: 5.0, r_min: 0.25, gain: 1.0, sample_step: 1.0, weights: area, voxel_size: {voxel},\n"
            "         interpolation: trilinear }\n"
            "dynamics: { inertia: 1.0, damping: critical, stiffness: 1.0, feed: 1000, rtol: 1.0e-6, atol: 1.0e-9,\n"
            f"            max_tilt_deg: {tilt}, max_lead_deg: 20, on_limit: {on_limit} }}\n" + path +
            "links: { retract: 10, safe_z: auto }\n")
    with open(os.path.join(d, "scene.yaml"), "w") as f:
        f.write(text)


def flat(pts2, z=0.0):
    return [(p[0], p[1], z, 0.0, 0.0, 1.0) for p in pts2]


def corner_job(root, kind, turn, variant, tilt=35, on_limit="clamp", name=None):
    """kind: away (straight wall on the left, turn right), pocket (the wall bent along the pass,
    turn right), boss (a wedge on the left, turn left round its apex)."""
    name = name or f"corner_{kind}_{turn}_{variant}"
    d = os.path.join(root, name)
    os.makedirs(d, exist_ok=True)
    start, c = (-40.0, 0.0), (0.0, 0.0)
    d1 = (1.0, 0.0)
    n1 = left(d1)
    if kind in ("away", "pocket"):
        r = float(variant[1:])
        d2 = rot(d1, -turn)
        end = add(c, d2, 35.0)
        pts = fillet_path(start, c, end, r)
        if kind == "away":
            walls = box(-50, 20, WALL_GAP, WALL_GAP + WALL_T, -1, WALL_TOP)
        else:
            n2 = left(d2)
            k = 1.0 + n1[0] * n2[0] + n1[1] * n2[1]
            mid = lambda o: add(c, (n1[0] + n2[0], n1[1] + n2[1]), o / k)
            a_in, a_out = add(add(c, d1, -50), n1, WALL_GAP), add(add(c, d1, -50), n1, WALL_GAP + WALL_T)
            b_in, b_out = add(add(c, d2, 45), n2, WALL_GAP), add(add(c, d2, 45), n2, WALL_GAP + WALL_T)
            walls = prism([a_in, mid(WALL_GAP), b_in, b_out, mid(WALL_GAP + WALL_T), a_out], -1, WALL_TOP)
    else:  # boss: turn left round a wedge's apex
        d2 = rot(d1, turn)
        n2 = left(d2)
        k = 1.0 + n1[0] * n2[0] + n1[1] * n2[1]
        apex = lambda o: add(c, (n1[0] + n2[0], n1[1] + n2[1]), o / k)
        L = 45.0
        if variant == "sharp":
            p = apex(WALL_GAP)
            poly = [p, add(p, d2, L), add(add(p, d2, L), d1, -L), add(p, d1, -L)]
            end = add(c, d2, 35.0)
            pts = [start, c, end]
        else:
            rb = 0.0 if variant == "round" else 2.0
            q = apex(WALL_GAP + rb)     # the apex arc's centre
            rp = WALL_GAP + rb          # the pass's arc about it
            a0 = math.degrees(math.atan2(-n1[1], -n1[0]))
            a1 = a0 + turn
            if rb > 0:
                b = add(add(q, n2, -rb), d2, L)
                poly = [add(add(q, n1, -rb), d1, -L)] + arc_pts(q, rb, a0, a1) + [b, add(b, d1, -L)]
            else:
                poly = [add(q, d1, -L), q, add(q, d2, L), add(add(q, d2, L), d1, -L)]
            foot1, foot2 = add(q, n1, -rp), add(q, n2, -rp)
            n = max(2, int(math.ceil(turn / 2.0)))
            arc = [(q[0] + rp * math.cos(math.radians(a0 + turn * i / n)),
                    q[1] + rp * math.sin(math.radians(a0 + turn * i / n))) for i in range(n + 1)]
            pts = [add(foot1, d1, -40.0)] + arc + [add(foot2, d2, 35.0)]
        walls = prism(poly, -1, WALL_TOP)
    path = densify(pts)
    xs = [p[0] for p in path]
    ys = [p[1] for p in path]
    write_stl(os.path.join(d, "walls.stl"), walls)
    write_stl(os.path.join(d, "floor.stl"),
              box(min(xs) - 15, max(xs) + 15, min(ys) - 15, max(ys) + 15, -5, 0))
    write_cl(os.path.join(d, "nominal.cl"), [flat(path)], f"{name}: one pass, tip on the floor, axis +z")
    write_scene(d, f"{name}: a pass turning {turn} deg ({kind}, {variant}) beside a wall", CORNER_TOOL,
                tilt=tilt, on_limit=on_limit)
    return name


def climb_job(root, slope, direction, turn, axis):
    """A contour pass on a plane sloped `slope` deg (rising toward +y) along x, turning in the plane by
    `turn`: up the slope (left turn, the wall on the downhill side) or down (right turn, uphill); the
    axis on the plane's normal (leaning downhill) or vertical, the tip R below the ball centre."""
    name = f"climb_{slope}_{direction}_{turn}_{axis}"
    d = os.path.join(root, name)
    os.makedirs(d, exist_ok=True)
    s = math.radians(slope)
    ev = (0.0, math.cos(s), math.sin(s))          # up the slope, in the plane
    nrm = (0.0, -math.sin(s), math.cos(s))        # the plane's normal
    to3 = lambda u, v: (u, v * ev[1], v * ev[2])
    sign = 1 if direction == "up" else -1
    pts2 = densify(fillet_path((-40.0, 0.0), (0.0, 0.0), rot((35.0, 0.0), sign * turn), 0.0))
    if axis == "normal":
        path = [(*to3(u, v), *nrm) for u, v in pts2]
    else:
        path = []
        for u, v in pts2:
            p = to3(u, v)
            path.append((p[0], p[1] + 3.0 * nrm[1], p[2] + 3.0 * nrm[2] - 3.0, 0.0, 0.0, 1.0))
    # a vertical slab WALL_GAP across (in y) from the ball centres of the first leg (y = -R sin S),
    # downhill (up) or uphill (down), from 2 below the plane to WALL_TOP above it
    yc = -3.0 * math.sin(s)
    y0, y1 = ((yc - WALL_GAP - WALL_T, yc - WALL_GAP) if direction == "up"
              else (yc + WALL_GAP, yc + WALL_GAP + WALL_T))
    walls = box(-50, 20, y0, y1, y0 * math.tan(s) - 2.0, y1 * math.tan(s) + WALL_TOP)
    wall_v, far_v = y0 / math.cos(s), y1 / math.cos(s)
    vs = [p[1] for p in pts2]
    v0, v1 = min(vs + [wall_v, far_v]) - 15, max(vs + [wall_v, far_v]) + 15
    u0, u1 = -55.0, 55.0
    corners = [to3(u0, v0), to3(u1, v0), to3(u1, v1), to3(u0, v1)]
    low = min(c[2] for c in corners) - 5.0
    slab = hexahedron([(c[0], c[1], low) for c in corners] + corners)
    write_stl(os.path.join(d, "walls.stl"), walls)
    write_stl(os.path.join(d, "floor.stl"), slab)
    write_cl(os.path.join(d, "nominal.cl"), [path], f"{name}: the ball on a plane sloped {slope} deg, "
             + ("the tip on it, the axis its normal" if axis == "normal" else "the axis +z"))
    write_scene(d, f"{name}: a 3-D corner turning {turn} deg on a {slope} deg slope, going {direction}",
                CORNER_TOOL)
    return name


def ramp_job(root, beta, direction, axis):
    """A floor (z = 0, x < 0) into a ramp of beta deg along x through a concave R 8 blend; the pass at
    y = 0 along x, a wall on its left; the part extruded along y."""
    name = f"ramp_{beta}_{direction}_{axis}"
    d = os.path.join(root, name)
    os.makedirs(d, exist_ok=True)
    R, RB, b = 3.0, 8.0, math.radians(beta)
    xt = RB * math.sin(b)                     # where the blend meets the ramp
    zt = RB * (1 - math.cos(b))
    length = 30.0

    def surf(x):
        """Height and unit normal (nx, nz) of the profile at x."""
        if x <= 0:
            return 0.0, (0.0, 1.0)
        if x <= xt:
            z = RB - math.sqrt(RB * RB - x * x)
            return z, (-x / RB, (RB - z) / RB)
        return zt + (x - xt) * math.tan(b), (-math.sin(b), math.cos(b))

    x_end = xt + length * math.cos(b)
    # contacts every STEP along the ball centre line (the offset of the profile by R)
    samples = [-40.0 + i * 0.01 for i in range(int((x_end + 40.0) / 0.01) + 1)]
    centres = []
    for x in samples:
        z, (nx, nz) = surf(x)
        centres.append((x + R * nx, z + R * nz, nx, nz, x, z))
    path, acc = [centres[0]], 0.0
    for a, c in zip(centres, centres[1:]):
        acc += math.hypot(c[0] - a[0], c[1] - a[1])
        if acc >= STEP - 1e-9:
            path.append(c)
            acc = 0.0
    if path[-1] is not centres[-1]:
        path.append(centres[-1])
    post = []
    for cx, cz, nx, nz, x, z in path:
        if axis == "normal":
            post.append((x, 0.0, z, nx, 0.0, nz))      # tip = the contact point
        else:
            post.append((cx, 0.0, cz - R, 0.0, 0.0, 1.0))
    if direction == "down":
        post = post[::-1]
    xe = x_end + 10.0
    surface = [(x, surf(x)[0]) for x in [xe] + [xt * i / 16 for i in range(16, -1, -1)] + [-50.0]]
    prof = [(-50.0, -5.0), (xe, -5.0)] + surface
    top = max(p[1] for p in prof)
    # the profile in (x, z) extruded along y from -25 to 25: (x, z, y) -> (x, y, z) mirrors, so each
    # triangle is wound back
    m = lambda p: (p[0], p[2], p[1])
    solid = [(m(t[0]), m(t[2]), m(t[1])) for t in prism(prof, -25.0, 25.0)]
    write_stl(os.path.join(d, "walls.stl"), box(-50, x_end + 10, WALL_GAP, WALL_GAP + WALL_T, -1, top + 25))
    write_stl(os.path.join(d, "floor.stl"), solid)
    write_cl(os.path.join(d, "nominal.cl"), [post],
             f"{name}: a floor into a {beta} deg ramp, axis {'on the normal' if axis == 'normal' else '+z'}")
    write_scene(d, f"{name}: a pass over a floor and a {beta} deg ramp ({direction}), a wall beside", CORNER_TOOL)
    return name


def clean(poly):
    """Consecutive points within 1 um merged (a corner radius offset to 0)."""
    out = []
    for p in poly:
        if not out or math.hypot(p[0] - out[-1][0], p[1] - out[-1][1]) > 1e-3:
            out.append(p)
    if len(out) > 1 and math.hypot(out[0][0] - out[-1][0], out[0][1] - out[-1][1]) <= 1e-3:
        out.pop()
    return out


def rr_offset(x0, y0, x1, y1, r, o):
    """The rounded rectangle's inward offset by o (exact: radius max(r - o, 0))."""
    return rounded_rect(x0 + o, y0 + o, x1 - o, y1 - o, max(r - o, 0.0))


def pocket_job(root, name, r, sparse=False, cw=False, draft=0.0, boss=False, tilt=35, on_limit="clamp",
               voxel=1.0):
    d = os.path.join(root, name)
    os.makedirs(d, exist_ok=True)
    x0, y0, x1, y1 = 0.0, 0.0, 60.0, 40.0
    inner = rounded_rect(x0, y0, x1, y1, r)
    top_inner = offset_poly(inner, -POCKET_DEPTH * math.tan(math.radians(draft))) if draft else inner
    bottom_inner = offset_poly(inner, 1.0 * math.tan(math.radians(draft))) if draft else inner
    solids = [ring(bottom_inner, top_inner, 10.0, -1.0, POCKET_DEPTH)]
    if boss:
        solids.append(prism(rounded_rect(22, 15, 38, 25, 3.0), -1.0, 20.0))
        passes = [flat(densify(rr_offset(x0, y0, x1, y1, r, o), closed=True)) for o in (4.0, 6.5)]
        for o in (6.5, 4.0):  # round the boss, outward offsets of its outline, clockwise
            loop = rounded_rect(22 - o, 15 - o, 38 + o, 25 + o, 3.0 + o)
            loop = [loop[0]] + loop[1:][::-1]
            passes.append(flat(densify(loop, closed=True)))
    elif sparse:
        passes = []
        for o in (4.0, 6.5, 9.0, 11.5, 14.0, 16.5):
            loop = clean(rr_offset(x0, y0, x1, y1, r, o))
            if cw:
                loop = [loop[0]] + loop[1:][::-1]
            passes.append(flat(loop + [loop[0]]))
    else:
        passes = []
        for o in (4.0, 6.5, 9.0, 11.5, 14.0, 16.5):
            loop = clean(rr_offset(x0, y0, x1, y1, r, o))
            if cw:
                loop = [loop[0]] + loop[1:][::-1]
            passes.append(flat(densify(loop, closed=True)))
    write_stl(os.path.join(d, "walls.stl"), *solids)
    write_stl(os.path.join(d, "floor.stl"), box(-15, 75, -15, 55, -5, 0))
    write_cl(os.path.join(d, "nominal.cl"), passes,
             f"{name}: closed offset loops in a 60 x 40 pocket {POCKET_DEPTH:g} deep, corner R {r:g}")
    write_scene(d, f"{name}: a 60 x 40 x {POCKET_DEPTH:g} pocket, corner R {r:g}"
                   + (f", walls drafted {draft:g} deg" if draft else "") + (", a boss" if boss else ""),
                POCKET_TOOL, voxel=voxel, tilt=tilt, on_limit=on_limit, step=STEP if sparse else None)
    return name


def lpocket_job(root):
    name = "lpocket"
    d = os.path.join(root, name)
    os.makedirs(d, exist_ok=True)
    inner = [(0.0, 0.0), (60.0, 0.0), (60.0, 25.0), (30.0, 25.0), (30.0, 50.0), (0.0, 50.0)]
    passes = [flat(densify(offset_poly(inner, o), closed=True)) for o in (4.0, 7.0, 10.0)]
    write_stl(os.path.join(d, "walls.stl"), ring(inner, inner, 10.0, -1.0, POCKET_DEPTH))
    write_stl(os.path.join(d, "floor.stl"), box(-15, 75, -15, 65, -5, 0))
    write_cl(os.path.join(d, "nominal.cl"), passes, f"{name}: 3 offset loops of an L pocket")
    write_scene(d, f"{name}: an L pocket 60 x 50 (a 30 x 25 notch), {POCKET_DEPTH:g} deep", POCKET_TOOL,
                voxel=1.0)
    return name


def zigzag_job(root):
    name = "zigzag"
    d = os.path.join(root, name)
    os.makedirs(d, exist_ok=True)
    pts = []
    ys = [4.0 + 2.5 * i for i in range(13)]  # 4 .. 34, the last 6 from the far wall at 40
    for i, y in enumerate(ys):
        xa, xb = (5.0, 55.0) if i % 2 == 0 else (55.0, 5.0)
        pts += [(xa, y), (xb, y)]
    path = densify(pts)
    write_stl(os.path.join(d, "walls.stl"), box(-10, 70, -10, 0, -1, POCKET_DEPTH),
              box(-10, 70, 40, 50, -1, POCKET_DEPTH))
    write_stl(os.path.join(d, "floor.stl"), box(-10, 70, -10, 50, -5, 0))
    write_cl(os.path.join(d, "nominal.cl"), [flat(path)], f"{name}: a zig-zag raster written as one block")
    write_scene(d, f"{name}: a raster along x over a floor between two walls 40 apart, {POCKET_DEPTH:g} high",
                POCKET_TOOL, voxel=1.0)
    return name


def make_all(root):
    os.makedirs(root, exist_ok=True)
    jobs = []  # (name, expect, flags)
    for kind in ("away", "pocket"):
        for turn in (30, 60, 90, 110, 150):
            for r in ("r0", "r2", "r6"):
                jobs.append((corner_job(root, kind, turn, r), "ok", ""))
    for turn in (30, 60, 90, 110, 150):
        for v in ("sharp", "round", "fillet"):
            jobs.append((corner_job(root, "boss", turn, v), "ok", ""))
    for slope, direction, turn, axis in ((20, "up", 90, "normal"), (20, "up", 90, "vert"),
                                         (40, "up", 90, "vert"), (30, "up", 60, "vert"),
                                         (20, "down", 90, "normal"), (40, "down", 90, "normal"),
                                         (30, "down", 120, "normal"), (40, "down", 90, "vert")):
        jobs.append((climb_job(root, slope, direction, turn, axis), "ok", ""))
    for beta, direction, axis in ((15, "up", "normal"), (30, "up", "normal"), (45, "up", "normal"),
                                  (30, "up", "vert"), (30, "down", "normal"), (45, "down", "vert")):
        jobs.append((ramp_job(root, beta, direction, axis), "ok", ""))
    jobs.append((pocket_job(root, "pocket_r0", 0.0), "ok", ""))
    jobs.append((pocket_job(root, "pocket_r3", 3.0, sparse=True), "ok", ""))
    jobs.append((pocket_job(root, "pocket_r3_cw", 3.0, sparse=True, cw=True), "ok", ""))
    jobs.append((pocket_job(root, "pocket_r6", 6.0), "ok", ""))
    jobs.append((pocket_job(root, "pocket_r0_nominal", 0.0), "ok", "--nominal"))
    jobs.append((pocket_job(root, "boss_pocket", 3.0, boss=True), "ok", ""))
    jobs.append((lpocket_job(root), "ok", ""))
    jobs.append((pocket_job(root, "draft_pocket", 3.0, draft=5.0), "ok", ""))
    jobs.append((zigzag_job(root), "ok", ""))
    jobs.append((corner_job(root, "away", 90, "r0", name="corner_away_90_r0_direct"), "ok", "--direct"))
    jobs.append((corner_job(root, "away", 90, "r0", tilt=5, on_limit="fail", name="fail_tilt_corner"),
                 "fail", ""))
    jobs.append((pocket_job(root, "fail_tilt_pocket", 0.0, tilt=2, on_limit="fail"), "fail", ""))
    with open(os.path.join(root, "jobs.txt"), "w") as f:
        for name, expect, flags in jobs:
            f.write(f"{name} {expect} {flags}".rstrip() + "\n")
    return jobs


# ---- the examples' helpers --------------------------------------------------------------------
def reverse_cl(src, dst):
    """Each pass block of a .cl (`# pass` lines start them; `# link` blocks dropped) in reverse order."""
    head, blocks, cur = [], [], None
    for line in open(src):
        s = line.strip()
        if s.startswith("# pass"):
            cur = [line, []]
            blocks.append(cur)
        elif s.startswith("# link"):
            cur = None
        elif cur is None:
            # (the header's comments, less its count of postures: the links are dropped)
            if not blocks and s.startswith("#") and not s.startswith("# postures"):
                head.append(line)
        elif s and not s.startswith("#"):
            cur[1].append(line)
    with open(dst, "w") as out:
        out.writelines(head)
        for title, postures in blocks:
            out.write(title)
            out.writelines(reversed(postures))


def unguide(src, dst):
    import re
    text = open(src).read()
    text = re.sub(r"^guide:.*\n", "", text, flags=re.M)
    text = re.sub(r"^path:\n(  .*\n)*", "path: { nominal: rev.cl, lead_deg: 0 }\n", text, flags=re.M)
    open(dst, "w").write(text)


# ---- the same paths in the other formats (DESIGN.md: path.nominal reads .cl, APT and .npy) ---------
def read_cl(src):
    """The passes of a .cl: lists of the 6 numbers of each posture, as written (strings: the APT
    copy then carries the very digits of the .cl); `# pass` or a blank line starts a pass, `# link`
    blocks are dropped."""
    passes, cur = [], []
    in_link = False
    for line in open(src):
        s = line.split("#", 1)[0].split()
        c = line.strip()
        if c.startswith("# pass") or not c:
            in_link = False
            if cur:
                passes.append(cur)
            cur = []
        elif c.startswith("# link"):
            in_link = True
            if cur:
                passes.append(cur)
            cur = []
        elif s and not in_link:
            cur.append(s[:6])
    if cur:
        passes.append(cur)
    return passes


def apt_num(t):
    """Fixed 6 decimals as posts print them (30 -> 30.000000): the corpus' .cl values exactly (it
    writes 6 decimals at most), so the APT job reads the .cl job's postures; make_part.py's to 1e-6 mm."""
    out = f"{float(t):.6f}"
    return "0.000000" if out == "-0.000000" else out


def write_apt(dst, passes, source):
    """APT CLDATA as CAM systems write it (DESIGN.md "Passes from a nominal path"): `GOTO / x, y, z,
    i, j, k` with spaces, 6-value GOTOs split over two lines by a `$` continuation, a GOTO with 3
    values where the axis is the last one's (kept by the reader), `$$` comments and records the
    reader reads past (TLDATA, LOAD/TOOL, SPINDL, COOLNT, PAINT, MSYS, TOOL PATH, END-OF-PATH); each
    pass: RAPID to 10 mm above its first posture along the axis, FEDRAT, the feed moves, RAPID up
    10 mm again (the rapids are links: the reader drops them, so the passes are exactly IN's)."""
    lines = [f"$$ corpus_scenes.py --apt {source}: the passes of {source} as a CAM system posts them",
             "PARTNO/CORPUS", "UNITS/MM", "MULTAX/ON", "MSYS/0.0,0.0,0.0,1.0,0.0,0.0,0.0,1.0,0.0",
             "TOOL PATH/FINISH,TOOL,BALL6", "TLDATA/MILL,6.0000,3.0000,35.0000,0.0000,0.0000",
             "LOAD/TOOL,1,ADJUST,1", "CUTTER/6.000000,3.000000,0.000000,3.000000,0.000000,0.000000,35.000000",
             "SPINDL/RPM,12000,CLW", "COOLNT/ON", "PAINT/COLOR,186"]
    last_axis = None

    def goto(xyz, axis):
        nonlocal last_axis
        if axis == last_axis:
            return [f"GOTO / {xyz[0]}, {xyz[1]}, {xyz[2]}"]
        last_axis = axis
        return [f"GOTO / {xyz[0]}, {xyz[1]}, {xyz[2]}, $", f"       {axis[0]}, {axis[1]}, {axis[2]}"]

    def lifted(q):
        v = [float(t) for t in q]
        return tuple(apt_num(str(v[i] + 10.0 * v[i + 3])) for i in range(3))

    for k, p in enumerate(passes, 1):
        first, last = p[0], p[-1]
        lines += [f"$$ pass {k}: {len(p)} postures", "PAINT/COLOR,37", "RAPID"]
        lines += goto(lifted(first), tuple(apt_num(t) for t in first[3:6]))
        lines += ["PAINT/COLOR,186", "FEDRAT/MMPM,1000.0000"]
        for q in p:
            lines += goto(tuple(apt_num(t) for t in q[:3]), tuple(apt_num(t) for t in q[3:6]))
        lines += ["RAPID"]
        lines += goto(lifted(last), tuple(apt_num(t) for t in last[3:6]))
    lines += ["COOLNT/OFF", "SPINDL/OFF", "END-OF-PATH", "FINI"]
    with open(dst, "w") as f:
        f.write("\n".join(lines) + "\n")


def write_npy(dst, passes, dtype, cols):
    """NumPy format 1.0 by hand (stdlib only): '<f4' or '<f8', shape (N, cols), C order; the 7th
    column a spindle angle (0.1 rad a posture, mod 2 pi: the reader keeps or ignores it, never
    reads it as a pass break). No pass markers: the reader splits the passes where two tips lie
    farther apart than path.pass_gap (the corpus' passes lie 2.5 mm apart, steps 0.5 mm)."""
    rows = [[float(t) for t in q] for p in passes for q in p]
    if cols == 7:
        rows = [r + [math.fmod(0.1 * n, 2 * math.pi)] for n, r in enumerate(rows)]
    header = f"{{'descr': '<{dtype}', 'fortran_order': False, 'shape': ({len(rows)}, {cols}), }}"
    header += " " * ((64 - (10 + len(header) + 1) % 64) % 64) + "\n"
    code = "<" + ("f" if dtype == "f4" else "d") * cols
    with open(dst, "wb") as f:
        f.write(b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode("latin1"))
        for r in rows:
            f.write(struct.pack(code, *r))


def shift_cl(src, dst, x0, x1, dy):
    """The .cl with the tips of x0 <= x <= x1 moved dy along y (comments kept)."""
    out = []
    for line in open(src):
        s = line.split()
        if s and not line.lstrip().startswith("#") and x0 <= float(s[0]) <= x1:
            s[1] = fmt(float(s[1]) + dy)
            line = " ".join(s) + "\n"
        out.append(line)
    open(dst, "w").writelines(out)


def small_impeller(src, dst):
    """The impeller scene with 3 passes over the first 40 % of the channel (study's lines and its
    middle pass stay in it)."""
    import re
    text = open(src).read()
    text, n1 = re.subn(r"^(\s+u_range:\s*)\[0, 1\]", r"\g<1>[0, 0.4]", text, flags=re.M)
    text, n2 = re.subn(r"^(\s+passes:\s*)7\b", r"\g<1>3", text, flags=re.M)
    if n1 != 1 or n2 != 1:
        sys.exit(f"small_impeller: {src}: no `u_range: [0, 1]` or `passes: 7` to change")
    open(dst, "w").write(text)


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "--reverse":
        reverse_cl(sys.argv[2], sys.argv[3])
    elif len(sys.argv) == 4 and sys.argv[1] == "--unguide":
        unguide(sys.argv[2], sys.argv[3])
    elif len(sys.argv) == 4 and sys.argv[1] == "--apt":
        write_apt(sys.argv[3], read_cl(sys.argv[2]), os.path.basename(sys.argv[2]))
    elif len(sys.argv) == 6 and sys.argv[1] == "--npy" and sys.argv[4] in ("f4", "f8") \
            and sys.argv[5] in ("6", "7"):
        write_npy(sys.argv[3], read_cl(sys.argv[2]), sys.argv[4], int(sys.argv[5]))
    elif len(sys.argv) == 7 and sys.argv[1] == "--shift":
        shift_cl(sys.argv[2], sys.argv[3], *map(float, sys.argv[4:]))
    elif len(sys.argv) == 4 and sys.argv[1] == "--small-impeller":
        small_impeller(sys.argv[2], sys.argv[3])
    elif len(sys.argv) == 2 and not sys.argv[1].startswith("-"):
        jobs = make_all(sys.argv[1])
        print(f"corpus_scenes: {len(jobs)} jobs in {sys.argv[1]}")
    else:
        sys.exit(__doc__)
