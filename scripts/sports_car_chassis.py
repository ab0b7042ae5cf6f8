#!/usr/bin/env python3
"""Writes models/sports_car_chassis.fe.yaml: the substitute beam-frame chassis
of the sports car (docs: /work/shared/reference/vehicle-model-spec.md section
10.2, its recipe and tables), as an mbcc YAML FE model (docs/model-format.md,
"FE files").

The frame is built station by station in the order the recipe describes it,
so that the node numbers are those the spec's section 10.4 lists (1-based
there, 0-based here: J1 is node 16).  A node given twice (a rail node shared
by the front subframe and the tub) is created once.

Usage: python3 scripts/sports_car_chassis.py [OUTPUT]   (default: stdout)
Only the Python standard library is needed."""
import math
import sys

ZL, ZCM, XB = 0.15, 0.44, -1.24       # lower plane, CM height, rear bulkhead station
ENGINE_AT, ENGINE_MASS, ENGINE_INERTIA = (-1.9530, 0.0, 0.4832), 195.0, (12.0, 9.9, 13.8)
NSM = {"sill": 2.0, "floor": 0.7554, "bulk": 2.0, "roof": 2.0}   # kg/m
E, G, DENSITY = 210.0e9, 80.8e9, 7850.0

# name: (shape, dimensions in m) -- box h x b x t (h along local z), tube d x t
SECTIONS = {
    "RAIL": ("box", (0.080, 0.050, 0.0020)),
    "SILL": ("box", (0.100, 0.060, 0.0020)),
    "RRAIL": ("box", (0.080, 0.060, 0.0025)),
    "CROSS": ("box", (0.050, 0.050, 0.0015)),
    "CAGE": ("tube", (0.040, 0.0020)),
    "DIAG": ("tube", (0.025, 0.0015)),
    "BRKT": ("box", (0.060, 0.060, 0.0025)),
    "BULK": ("box", (0.080, 0.080, 0.0030)),
    "BDIAG": ("tube", (0.030, 0.0020)),
    "MOUNT": ("tube", (0.040, 0.0040)),
}


def section_area(name):
    shape, dims = SECTIONS[name]
    if shape == "box":
        h, b, t = dims
        return h * b - (h - 2 * t) * (b - 2 * t)
    d, t = dims
    return math.pi * ((d / 2) ** 2 - (d / 2 - t) ** 2)


class Frame:
    def __init__(self):
        self.nodes = []       # [x, y, z]
        self.names = {}       # name -> node
        self.beams = []       # (a, b, section, nsm, what)
        self.masses = []      # (node, mass, inertia or None, what)

    def node(self, p, name=None):
        """The node at p (created if new; positions rounded to the micrometre)."""
        p = [round(v, 6) + 0.0 for v in p]
        for i, q in enumerate(self.nodes):
            if all(abs(a - b) <= 1e-6 + 1e-5 * abs(a) for a, b in zip(q, p)):
                break
        else:
            self.nodes.append(p)
            i = len(self.nodes) - 1
        if name:
            self.names[name] = i
        return i

    def existing(self, p):
        count = len(self.nodes)
        i = self.node(p)
        assert len(self.nodes) == count, "no node at %s" % (p,)
        return i

    def member(self, a, b, section, pieces=1, nsm=0.0, what=""):
        """A member from node a to node b in 'pieces' equal elements."""
        pa, pb = self.nodes[a], self.nodes[b]
        chain = [a] + [self.node([pa[i] + (pb[i] - pa[i]) * k / pieces for i in range(3)])
                       for k in range(1, pieces)] + [b]
        for i in range(pieces):
            self.beams.append((chain[i], chain[i + 1], section, nsm, what))

    def item(self, points, mass, what):
        """A lumped item split equally over the nodes at 'points'."""
        for p in points:
            self.masses.append((self.existing(p), mass / len(points), None, what))


def build():
    f = Frame()
    n, member = f.node, f.member
    sides = (1, -1)
    # front subframe: lower rails (+-0.30, ZL), upper rails (+-0.38, 0.44)
    xf = [0.70, 0.50, 0.30, 0.13, 0.00, -0.18, -0.35]
    low, up = {}, {}
    for x in xf:
        for s in sides:
            low[x, s] = n([x, s * 0.30, ZL])
            up[x, s] = n([x, s * 0.38, 0.44])
    for i in range(len(xf) - 1):
        a, b = xf[i], xf[i + 1]
        for s in sides:
            member(low[a, s], low[b, s], "RAIL", 2, what="front lower rail")
            member(up[a, s], up[b, s], "RAIL", 2, what="front upper rail")
            member(low[a, s], up[b, s], "DIAG", what="front side diagonal")
        s0 = 1 if i % 2 == 0 else -1
        member(low[a, s0], low[b, -s0], "DIAG", what="front floor diagonal")
    for x in xf:
        for s in sides:
            member(low[x, s], up[x, s], "CROSS", what="front side post")
        member(low[x, 1], low[x, -1], "CROSS", 2, what="front lower cross member")
        if x in (0.70, 0.13, 0.00, -0.35):
            member(up[x, 1], up[x, -1], "CROSS", 2, what="front upper cross member")
    for s, side in ((1, "L"), (-1, "R")):
        top = n([0.0, s * 0.48, 0.565], "SD_TOP_F" + side)       # coil-over top mount
        for x in (0.00, 0.13, -0.18):
            member(top, up[x, s], "BRKT", what="suspension tower")
        member(top, low[0.00, s], "BRKT", 2, what="suspension tower")
        rack = n([0.13, s * 0.318, 0.193], "TIEROD_IN_F" + side)  # tie rod, inner ball joint
        member(rack, low[0.13, s], "BRKT", what="steering rack bracket")
    member(f.names["TIEROD_IN_FL"], f.names["TIEROD_IN_FR"], "CROSS", 4, what="steering rack housing")
    f.names.update(J1=low[0.00, 1], J2=up[0.00, 1], J5=low[0.00, -1], J6=up[0.00, -1])

    # cockpit tub: six stations from -0.35 to the rear bulkhead
    xt = [round(-0.35 + (XB + 0.35) * k / 5, 6) for k in range(6)]
    sill_lo, sill_up, floor = {}, {}, {}
    for x in xt:
        for s in sides:
            sill_lo[x, s] = n([x, s * 0.78, ZL])
            sill_up[x, s] = n([x, s * 0.78, ZCM])
            floor[x, s] = n([x, s * 0.30, ZL])
        floor[x, 0] = n([x, 0.0, ZL])
    for i in range(len(xt) - 1):
        a, b = xt[i], xt[i + 1]
        for s in sides:
            member(sill_lo[a, s], sill_lo[b, s], "SILL", 2, NSM["sill"], "lower sill")
            member(sill_up[a, s], sill_up[b, s], "SILL", 2, NSM["sill"], "upper sill")
            member(sill_lo[a, s], sill_up[b, s], "DIAG", what="sill web diagonal")
            member(floor[a, s], floor[b, s], "RAIL", 2, NSM["floor"], "floor rail")
            member(sill_lo[a, s], floor[b, s], "DIAG", nsm=NSM["floor"], what="floor diagonal")
            member(floor[a, s], floor[b, 0], "DIAG", nsm=NSM["floor"], what="floor diagonal")
        member(floor[a, 0], floor[b, 0], "RAIL", 2, NSM["floor"], "centre rail")
    for x in xt:
        for s in sides:
            member(sill_lo[x, s], sill_up[x, s], "CROSS", what="sill post")
            member(sill_lo[x, s], floor[x, s], "CROSS", 2, NSM["floor"], "floor cross member")
            member(floor[x, s], floor[x, 0], "CROSS", nsm=NSM["floor"], what="floor cross member")
    x = -0.35                                    # front bulkhead and scuttle
    for s in sides:
        member(up[x, s], sill_up[x, s], "BRKT", 2, NSM["bulk"], "front bulkhead")
        hinge_top = n([x, s * 0.70, 0.70])
        member(sill_up[x, s], hinge_top, "CAGE", 2, what="hinge pillar")
        member(up[x, s], hinge_top, "DIAG", 2, NSM["bulk"], "front bulkhead diagonal")
    scuttle_mid = n([x, 0.0, 0.70])
    member(n([x, 0.70, 0.70]), scuttle_mid, "CROSS", 2, NSM["bulk"], "scuttle")
    member(scuttle_mid, n([x, -0.70, 0.70]), "CROSS", 2, NSM["bulk"], "scuttle")
    member(scuttle_mid, floor[x, 0], "CROSS", 3, NSM["bulk"], "front bulkhead post")
    xr = [round(-0.80 + (XB + 0.80) * k / 3, 6) for k in range(4)]   # roof stations
    for s in sides:
        member(n([-0.35, s * 0.70, 0.70]), n([-0.80, s * 0.55, 1.05]), "CAGE", 3, what="A-pillar")
        for i in range(3):
            member(n([xr[i], s * 0.55, 1.05]), n([xr[i + 1], s * 0.55, 1.05]), "CAGE", 1, NSM["roof"],
                   "roof rail")
        member(sill_up[XB, s], n([XB, s * 0.66, 0.70]), "CAGE", what="B-pillar, lower")
        member(n([XB, s * 0.66, 0.70]), n([XB, s * 0.55, 1.05]), "CAGE", 2, what="B-pillar, upper")
    for x in (-0.80, XB):
        member(n([x, 0.55, 1.05]), n([x, -0.55, 1.05]), "CAGE", 2, NSM["roof"], "roof cross member")

    # rear bulkhead, carrying the CM node
    x = XB
    cm = n([x, 0.0, ZCM], "CM")
    member(floor[x, 0], cm, "BULK", 1, NSM["bulk"], "rear bulkhead post")
    member(cm, n([x, 0.0, 0.70]), "BULK", 1, NSM["bulk"], "rear bulkhead post")
    for s in sides:
        mid = n([x, s * 0.30, ZCM])
        member(floor[x, s], mid, "BULK", 1, NSM["bulk"], "rear bulkhead post")
        member(mid, n([x, s * 0.30, 0.70]), "BULK", 1, NSM["bulk"], "rear bulkhead post")
        member(cm, mid, "BULK", 1, NSM["bulk"], "rear bulkhead beam at CM height")
        member(mid, sill_up[x, s], "BULK", 2, NSM["bulk"], "rear bulkhead beam at CM height")
        member(n([x, 0.0, 0.70]), n([x, s * 0.30, 0.70]), "BULK", 1, NSM["bulk"], "rear bulkhead top")
        member(n([x, s * 0.30, 0.70]), n([x, s * 0.60, 0.70]), "BULK", 1, NSM["bulk"], "rear bulkhead top")
        member(n([x, s * 0.60, 0.70]), n([x, s * 0.66, 0.70]), "BULK", what="rear bulkhead top")
        member(sill_up[x, s], n([x, s * 0.60, 0.70]), "DIAG", 1, NSM["bulk"], "rear bulkhead diagonal")
        member(cm, n([x, s * 0.30, 0.70]), "BDIAG", what="rear bulkhead diagonal")
        member(cm, floor[x, s], "BDIAG", what="rear bulkhead diagonal")
        member(mid, sill_lo[x, s], "BDIAG", what="rear bulkhead diagonal")

    # rear frame: lower rails (+-0.30, ZL), upper rails (+-0.60, 0.70)
    xs = [XB, -1.46, -1.64, -1.82, -2.00, -2.18, -2.36, -2.54, -2.72, -2.93]
    rlow, rup = {}, {}
    for x in xs:
        for s in sides:
            rlow[x, s] = n([x, s * 0.30, ZL])
            rup[x, s] = n([x, s * 0.60, 0.70])
    for i in range(len(xs) - 1):
        a, b = xs[i], xs[i + 1]
        for s in sides:
            member(rlow[a, s], rlow[b, s], "RRAIL", 2, what="rear lower rail")
            member(rup[a, s], rup[b, s], "RRAIL", 2, what="rear upper rail")
            if i % 2 == 0:
                member(rlow[a, s], rup[b, s], "DIAG", what="rear side diagonal")
            else:
                member(rup[a, s], rlow[b, s], "DIAG", what="rear side diagonal")
    for x in xs[1:]:
        for s in sides:
            member(rlow[x, s], rup[x, s], "CROSS", 2, what="rear side post")
        member(rlow[x, 1], rlow[x, -1], "CROSS", 2, what="rear lower cross member")
        if x in (-2.18, -2.93):
            member(rup[x, 1], rup[x, -1], "CROSS", 3, what="rear upper cross member")
    f.names.update(J9=rup[-2.18, 1], J10=rlow[-2.18, 1], J13=rlow[-2.18, -1], J14=rup[-2.18, -1])

    # engine and transaxle: one node on four mount links
    engine = n(list(ENGINE_AT), "ENGINE")
    for x, s in ((-1.46, 1), (-1.46, -1), (-2.00, 1), (-2.00, -1)):
        member(engine, rlow[x, s], "MOUNT", what="engine mount link")
    f.masses.append((engine, ENGINE_MASS, ENGINE_INERTIA, "engine and transaxle"))

    # lumped items, each split equally over existing nodes
    for s, side in ((1, "left"), (-1, "right")):
        f.item([[-1.46, s * .30, ZL], [-1.46, s * .60, .70], [-1.64, s * .30, ZL], [-1.64, s * .60, .70]],
               32.0, "fuel tank, " + side)
    f.item([[.70, .38, .44], [.70, -.38, .44]], 20.0, "radiator")
    f.item([[.50, .30, ZL], [.50, -.30, ZL]], 18.0, "spare wheel")
    f.item([[XB, .30, .70], [XB, -.30, .70]], 15.0, "battery")
    for s, side in ((1, "left"), (-1, "right")):
        f.item([[xt[3], s * .30, ZL], [xt[3], s * .78, ZL]], 12.0, "seat, " + side)
    f.item([[-.35, .70, .70], [-.35, 0, .70], [-.35, -.70, .70]], 25.0, "dashboard and steering")
    f.item([[.50, .38, .44], [.50, -.38, .44], [.13, .38, .44], [.13, -.38, .44]], 25.0, "front clamshell")
    f.item([[-2.36, .60, .70], [-2.36, -.60, .70], [-2.72, .60, .70], [-2.72, -.60, .70]], 40.0,
           "rear clamshell")
    for s, side in ((1, "left"), (-1, "right")):
        f.item([[xt[2], s * .78, ZCM], [xt[2], s * .78, ZL]], 14.0, "door, " + side)
    f.item([[-.80, .55, 1.05], [-.80, -.55, 1.05], [XB, .55, 1.05], [XB, -.55, 1.05]], 25.0,
           "windscreen and roof panel")
    f.item([[-2.93, .30, ZL], [-2.93, -.30, ZL]], 15.0, "exhaust")
    f.item([[.70, .30, ZL], [.70, -.30, ZL]], 10.0, "front bumper")
    return f


def num(v):
    """Shortest text of a float that reads back exactly; no '-0'."""
    v = v + 0.0
    return repr(v) if v != 0 else "0"


def write(f, out):
    def length(b):
        pa, pb = f.nodes[b[0]], f.nodes[b[1]]
        return math.sqrt(sum((pa[i] - pb[i]) ** 2 for i in range(3)))
    steel = sum(DENSITY * section_area(b[2]) * length(b) for b in f.beams)
    nonstructural = sum(b[3] * length(b) for b in f.beams)
    items = sum(m[1] for m in f.masses)
    w = out.write
    w("# The sports car's chassis: the substitute beam frame of the vehicle spec, section 10.2\n"
      "# (steel space frame, 10 sections, lumped items).  GENERATED by scripts/sports_car_chassis.py\n"
      "# from the spec's recipe and tables: do not edit (make chassis rewrites it; tests/test_chassis.sh\n"
      "# checks it is current).  Node numbers are 0-based (the spec's ids less 1).\n"
      "# %d nodes, %d beams; mass: steel %.1f kg + non-structural %.1f kg + items %.1f kg = %.1f kg\n"
      % (len(f.nodes), len(f.beams), steel, nonstructural, items, steel + nonstructural + items))
    w("description: sports car chassis, substitute beam frame (vehicle spec section 10.2)\n")
    w("theory: euler_bernoulli\n")
    w("materials:\n  steel: {E: %.4g, G: %.4g, density: %s}\n" % (E, G, num(DENSITY)))
    w("material: steel\n")
    w("# box: h along the local z axis; local z = global z made perpendicular to the element\n"
      "# (global x for an element within 18 degrees of vertical), as the spec's element axes\n")
    w("sections:\n")
    for name, (shape, dims) in SECTIONS.items():
        keys = ("h", "b", "t") if shape == "box" else ("d", "t")
        w("  %s: {shape: %s, %s, zaxis: [0, 0, 1]}\n"
          % (name, shape, ", ".join("%s: %s" % (k, num(v)) for k, v in zip(keys, dims))))
    w("node_names:\n")
    for name in sorted(f.names, key=lambda k: (f.names[k], k)):
        w("  %s: %d\n" % (name, f.names[name]))
    w("nodes:\n")
    for i, p in enumerate(f.nodes):
        w("  - [%s]  # %d\n" % (", ".join(num(v) for v in p), i))
    w("beams:\n")
    for a, b, section, nsm, what in f.beams:
        extra = ", nonstructural_mass: %s" % num(nsm) if nsm else ""
        w("  - {nodes: [%d, %d], section: %s%s}  # %s\n" % (a, b, section, extra, what))
    w("point_masses:\n")
    names = {v: k for k, v in f.names.items()}
    for node, mass, inertia, what in f.masses:
        at = names.get(node, str(node))
        extra = ", inertia: [%s]" % ", ".join(num(v) for v in inertia) if inertia else ""
        w("  - {node: %s, mass: %s%s}  # %s\n" % (at, num(mass), extra, what))


def main():
    frame = build()
    if len(sys.argv) > 1:
        with open(sys.argv[1], "w") as out:
            write(frame, out)
    else:
        write(frame, sys.stdout)


if __name__ == "__main__":
    main()
