"""The geometry of a motion run's picture, shared by plot_motion (matplotlib) and the report (plotly):
the arm's links at chosen samples (the history's `points`: joint origins and tip, base frame), the
study's [world] obstacles as outlines, all projected onto the plane of the two base axes along which
the motion spreads most. Pure numpy; the study text is the file's /study/text (TOML).
"""
import tomllib

import numpy as np

AXES = "xyz"


def world_of(study_text):
    """(obstacles, link radii) of a study's [world] table: obstacles as dicts of numpy arrays
    ({type, centre, radius} spheres; {type, centre, half, R} boxes, R from rpy [deg]; {type, a, b,
    radius} capsules; each with its velocity [m/s], zero when fixed), radii a list (empty without
    [world])."""
    try:
        world = tomllib.loads(study_text).get("world", {})
    except tomllib.TOMLDecodeError:
        return [], []
    out = []
    for o in world.get("obstacles", []):
        t = o.get("type")
        v = np.array(o.get("velocity", [0.0, 0.0, 0.0]), float)
        if t == "sphere":
            out.append({"type": t, "centre": np.array(o["centre"], float), "radius": float(o["radius"]), "velocity": v})
        elif t == "box":
            r, p, y = np.radians(np.array(o.get("rpy", [0, 0, 0]), float))
            out.append({"type": t, "centre": np.array(o["centre"], float), "half": np.array(o["half"], float),
                        "R": rot_z(y) @ rot_y(p) @ rot_x(r), "velocity": v})
        elif t == "capsule":
            out.append({"type": t, "a": np.array(o["a"], float), "b": np.array(o["b"], float),
                        "radius": float(o["radius"]), "velocity": v})
    return out, [float(r) for r in world.get("link_radius", [])]


def rot_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def at_time(o, t):
    """The obstacle where it is at time t [s] (moved by t times its velocity)."""
    d = t * o.get("velocity", np.zeros(3))
    m = dict(o)
    for key in ("centre", "a", "b"):
        if key in m:
            m[key] = m[key] + d
    return m


def moving(obstacles):
    return any(np.any(o.get("velocity", np.zeros(3)) != 0) for o in obstacles)


def surface_points(o, n=48):
    """Points on (or spanning) an obstacle's surface, enough for its projected outline."""
    ring = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    sphere = np.array([[np.cos(a) * np.sin(b), np.sin(a) * np.sin(b), np.cos(b)]
                       for a in ring for b in np.linspace(0, np.pi, n // 2)])
    if o["type"] == "sphere":
        return o["centre"] + o["radius"] * sphere
    if o["type"] == "box":
        corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)
        return o["centre"] + (corners * o["half"]) @ o["R"].T
    return np.vstack([o["a"] + o["radius"] * sphere, o["b"] + o["radius"] * sphere])


def hull(points2):
    """The convex hull of 2-D points (Andrew's monotone chain), closed (first point repeated)."""
    p = sorted(set(map(tuple, np.round(points2, 12))))
    if len(p) < 3:
        return np.array(p + p[:1])

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower, upper = [], []
    for q in p:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], q) <= 0:
            lower.pop()
        lower.append(q)
    for q in reversed(p):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], q) <= 0:
            upper.pop()
        upper.append(q)
    h = lower[:-1] + upper[:-1]
    return np.array(h + h[:1])


def links_of(points_row):
    """A history row of `points` (3 (n + 1) values) as an (n + 1) x 3 array of link ends."""
    return np.asarray(points_row, float).reshape(-1, 3)


def view_plane(points, obstacles=()):
    """The two base axes (indices) with the largest spread of the arm's points (rows of 3 (n + 1)
    values) and the obstacles' points, in base-axis order: the plane the picture is drawn in."""
    p = np.vstack([np.asarray(points, float).reshape(-1, 3)] + [surface_points(o) for o in obstacles])
    spread = np.ptp(p, axis=0)
    keep = sorted(np.argsort(spread)[-2:])
    return int(keep[0]), int(keep[1])


def frames(n_rows, count):
    """`count` sample indices spread over n_rows samples, first and last included."""
    count = max(2, min(count, n_rows))
    return np.unique(np.round(np.linspace(0, n_rows - 1, count)).astype(int))


def segment_box_distance(a, b, box, n=2001):
    """Distance from the segment [a, b] to a box, by n points along the segment (each point's
    distance to the box is exact: clamp into it in its frame). An independent check of the engine's
    closed-form capsule-box distance, to within the sampling step."""
    t = np.linspace(0.0, 1.0, n)[:, None]
    p = (a + t * (b - a) - box["centre"]) @ box["R"]
    d = np.linalg.norm(p - np.clip(p, -box["half"], box["half"]), axis=1)
    return float(d.min())


def segment_points_distance(a, b, c):
    """The least distance from the segment [a, b] to the points c (m x 3), exact per point."""
    c = np.atleast_2d(c)
    ab = b - a
    t = np.zeros(len(c)) if not ab.any() else np.clip((c - a) @ ab / np.dot(ab, ab), 0.0, 1.0)
    return float(np.linalg.norm(a + t[:, None] * ab - c, axis=1).min())


def clearance(points_row, radii, obstacles, t=0.0):
    """The least clearance of the links (capsules between consecutive points, radii per link) from
    the obstacles at one history row of time t [s] (moving obstacles where they are then) [m]; +inf
    without obstacles. Sphere and capsule distances via point-segment distances on a dense
    subdivision, boxes as segment_box_distance."""
    p = links_of(points_row)
    best = np.inf
    now = [at_time(o, t) for o in obstacles]
    for k in range(len(p) - 1):
        a, b = p[k], p[k + 1]
        for o in now:
            if o["type"] == "sphere":
                d = segment_points_distance(a, b, o["centre"]) - o["radius"]
            elif o["type"] == "box":
                d = segment_box_distance(a, b, o)
            else:
                s = np.linspace(0.0, 1.0, 2001)[:, None]
                d = segment_points_distance(a, b, o["a"] + s * (o["b"] - o["a"])) - o["radius"]
            best = min(best, d - radii[k])
    return best
