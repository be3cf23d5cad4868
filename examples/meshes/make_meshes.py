#!/usr/bin/env python3
"""Writes the example meshes (OBJ, millimetres) next to this script:
horseshoe.obj, key.obj and needle.obj, each a polygon extruded into a prism
whose triangles run counter-clockwise seen from outside. Run it again after
changing a shape: python3 examples/meshes/make_meshes.py"""
import math
import os


def area(poly):
    return 0.5 * sum(p[0] * q[1] - q[0] * p[1] for p, q in zip(poly, poly[1:] + poly[:1]))


def ear_clip(poly):
    """Triangles (index triples) of a simple counter-clockwise polygon."""
    idx = list(range(len(poly)))
    tris = []

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    def inside(p, a, b, c):
        return cross(a, b, p) > 0 and cross(b, c, p) > 0 and cross(c, a, p) > 0

    while len(idx) > 3:
        for k in range(len(idx)):
            i, j, l = idx[k - 1], idx[k], idx[(k + 1) % len(idx)]
            a, b, c = poly[i], poly[j], poly[l]
            if cross(a, b, c) <= 0:
                continue
            if any(inside(poly[m], a, b, c) for m in idx if m not in (i, j, l)):
                continue
            tris.append((i, j, l))
            idx.pop(k)
            break
        else:
            raise ValueError("not a simple polygon")
    tris.append(tuple(idx))
    return tris


def prism(poly, thickness, frame):
    """The polygon (x, y), counter-clockwise, extruded along its normal by
    thickness, centred; frame maps (u, v, w) to (x, y, z) by a rotation."""
    if area(poly) < 0:
        poly = poly[::-1]
    n = len(poly)
    verts = [frame(u, v, w) for w in (-0.5 * thickness, 0.5 * thickness) for u, v in poly]
    tris = []
    for a, b, c in ear_clip(poly):
        tris.append((a, c, b))              # bottom, seen from below
        tris.append((a + n, b + n, c + n))  # top
    for k in range(n):
        a, b = k, (k + 1) % n
        tris.append((a, b, b + n))
        tris.append((a, b + n, a + n))
    return verts, tris


def write_obj(name, verts, tris, comment):
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), name)
    with open(path, "w") as f:
        f.write("# " + comment + " (mm; written by make_meshes.py)\n")
        for x, y, z in verts:
            f.write("v %.4f %.4f %.4f\n" % (x, y, z))
        for a, b, c in tris:
            f.write("f %d %d %d\n" % (a + 1, b + 1, c + 1))


def horseshoe():
    """A U opening downwards: arms 10 mm wide, a 16 mm gap, 40 mm tall,
    10 mm deep, the bend a half annulus."""
    r_in, r_out, leg = 8.0, 18.0, 22.0
    poly = []
    for k in range(25):  # outer arc, right to left over the top
        t = math.pi * k / 24
        poly.append((r_out * math.cos(t), leg + r_out * math.sin(t)))
    poly += [(-r_out, 0.0), (-r_in, 0.0)]
    for k in range(25):  # inner arc, left to right
        t = math.pi - math.pi * k / 24
        poly.append((r_in * math.cos(t), leg + r_in * math.sin(t)))
    poly += [(r_in, 0.0), (r_out, 0.0)]
    # (u, v, w) -> (u, -w, v): the U stands in the x-z plane.
    return prism(poly, 10.0, lambda u, v, w: (u, -w, v))


def key():
    """A flat key 54 mm long, 2 mm thick: an octagonal bow, a shank, teeth."""
    # Counter-clockwise: the blade's lower edge with its teeth to the tip,
    # back along the top, then round the bow from its top to its bottom.
    poly = [(-2.0, -4.0), (10.0, -4.0), (12.0, -7.0), (15.0, -4.0), (19.0, -4.0), (21.0, -8.0), (24.0, -4.0),
            (29.0, -4.0), (31.0, -7.0), (34.0, -4.0), (42.0, -4.0), (42.0, 2.0), (40.0, 4.0), (-2.0, 4.0)]
    for k in range(6):
        t = math.radians(67.5 + 45.0 * k)
        poly.append((-12.0 + 11.0 * math.cos(t), 11.0 * math.sin(t)))
    return prism(poly, 2.0, lambda u, v, w: (u, v, w))


def needle():
    """A compass needle: a rhombus 40 mm long, 6 mm wide, 1.5 mm thick."""
    poly = [(-20.0, 0.0), (0.0, -3.0), (20.0, 0.0), (0.0, 3.0)]
    return prism(poly, 1.5, lambda u, v, w: (u, v, w))


if __name__ == "__main__":
    write_obj("horseshoe.obj", *horseshoe(), "a horseshoe magnet")
    write_obj("key.obj", *key(), "a flat steel key")
    write_obj("needle.obj", *needle(), "a compass needle")
