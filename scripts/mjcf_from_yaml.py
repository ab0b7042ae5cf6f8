#!/usr/bin/env python3
"""mjcf_from_yaml.py: the MuJoCo MJCF of an mbcc rigid-body model (make bench's peer).

Usage: mjcf_from_yaml.py MODEL.yaml OUT.xml

The same bodies (mass, inertia about the centre of mass, design position),
gravity and joints, written in MuJoCo's global coordinates (MuJoCo 2.2's
<compiler coordinate="global">): every body frame at its centre of mass with
axes parallel to the global axes, as mbcc's design configuration.  MuJoCo works
in joint coordinates on a kinematic tree, so the joints are split: a spanning
tree from the ground (revolute -> hinge, prismatic -> slide, spherical -> ball;
a body not connected to the ground becomes the root of a free joint), and every
joint that closes a loop becomes an equality 'connect' at its point (a
spherical joint exactly; a revolute one whose rotations the tree already keeps,
as in a planar loop).  Force elements are not written: the peer program applies
mbcc's own element forces (bench/peers/mujoco_peer.c), so both codes integrate
the same loads.  The constraints are made as hard as MuJoCo allows (solimp
0.9999, a short solref, Newton solver at a tight tolerance) so that the
accelerations agree with mbcc's exact constraints to about 1e-4.
"""
import sys
from collections import deque

import yaml


def fail(msg):
    sys.stderr.write("mjcf_from_yaml: error: %s\n" % msg)
    sys.exit(2)


def vec(x):
    return " ".join(repr(float(v)) for v in x)


def main():
    if len(sys.argv) != 3:
        fail("usage: mjcf_from_yaml.py MODEL.yaml OUT.xml")
    with open(sys.argv[1]) as f:
        doc = yaml.safe_load(f)
    bodies = doc.get("bodies") or {}
    joints = doc.get("joints") or {}
    for name, b in bodies.items():
        if b.get("type", "rigid") != "rigid":
            fail("body '%s': only rigid bodies have a MuJoCo peer" % name)
        if "orientation" in b:
            fail("body '%s': design orientations other than the global axes are not supported" % name)
    # spanning tree, breadth first from the ground, joints in file order
    parent = {}  # body -> (parent body or None for the world, joint name, joint)
    placed = {"ground"}
    loops = []
    order = []
    roots = ["ground"] + list(bodies)
    for root in roots:
        if root in placed and root != "ground":
            continue
        if root != "ground":
            parent[root] = (None, "free", None)
            placed.add(root)
            order.append(root)
        queue = deque([root])
        while queue:
            cur = queue.popleft()
            for jn, j in joints.items():
                a, b = j["bodies"]
                if cur not in (a, b):
                    continue
                other = b if cur == a else a
                if other in placed:
                    continue
                if j["type"] not in ("revolute", "prismatic", "spherical"):
                    fail("joint '%s': type %s has no MuJoCo counterpart here" % (jn, j["type"]))
                parent[other] = (None if cur == "ground" else cur, jn, j)
                placed.add(other)
                order.append(other)
                queue.append(other)
    tree_joints = {p[1] for p in parent.values()}
    for jn, j in joints.items():
        if jn in tree_joints:
            continue
        if j["type"] not in ("spherical", "revolute"):
            fail("joint '%s': a loop-closing %s joint has no connect equivalent" % (jn, j["type"]))
        loops.append((jn, j))

    children = {}
    for b in order:
        children.setdefault(parent[b][0], []).append(b)

    out = []
    w = out.append
    g = doc.get("gravity", [0, 0, -9.81])
    w('<mujoco model="%s">' % doc.get("name", "model"))
    w('  <!-- written by scripts/mjcf_from_yaml.py from %s; do not edit -->' % sys.argv[1])
    w('  <compiler coordinate="global" angle="radian" inertiafromgeom="false"/>')
    w('  <option gravity="%s" timestep="0.0001" solver="Newton" iterations="200" tolerance="1e-15"/>' % vec(g))
    w('  <default><equality solref="0.0002 1" solimp="0.9999 0.9999 0.001"/></default>')
    w('  <worldbody>')

    def emit(b, depth):
        ind = "  " * depth
        bd = bodies[b]
        pos = bd.get("position", [0, 0, 0])
        w('%s<body name="%s" pos="%s">' % (ind, b, vec(pos)))
        inert = bd.get("inertia")
        if len(inert) == 3:
            iattr = 'diaginertia="%s"' % vec(inert)
        elif len(inert) == 6:
            iattr = 'fullinertia="%s"' % vec(inert)
        else:
            fail("body '%s': inertia needs 3 or 6 values" % b)
        w('%s  <inertial pos="%s" mass="%r" %s/>' % (ind, vec(pos), float(bd["mass"]), iattr))
        _, jn, j = parent[b]
        if j is None:
            w('%s  <freejoint name="%s_free"/>' % (ind, b))
        else:
            kind = {"revolute": "hinge", "prismatic": "slide", "spherical": "ball"}[j["type"]]
            attrs = 'name="%s" type="%s" pos="%s"' % (jn, kind, vec(j["point"]))
            if kind != "ball":
                attrs += ' axis="%s"' % vec(j["axis"])
            w('%s  <joint %s/>' % (ind, attrs))
        for c in children.get(b, []):
            emit(c, depth + 1)
        w('%s</body>' % ind)

    for b in children.get(None, []):
        emit(b, 2)
    w('  </worldbody>')
    if loops:
        w('  <equality>')
        for jn, j in loops:
            a, b = j["bodies"]
            if a == "ground":
                a, b = b, a
            # global coordinates: MuJoCo 2.2 converts the anchor like every position
            anchor = j["point"]
            attrs = 'name="%s" body1="%s" anchor="%s"' % (jn, a, vec(anchor))
            if b != "ground":
                attrs += ' body2="%s"' % b
            w('    <connect %s/>' % attrs)
        w('  </equality>')
    w('</mujoco>')
    with open(sys.argv[2], "w") as f:
        f.write("\n".join(out) + "\n")


if __name__ == "__main__":
    main()
