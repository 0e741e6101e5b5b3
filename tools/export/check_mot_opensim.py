#!/usr/bin/env python3
"""Independent check of gaitfit's OpenSim motion export with OpenSim itself (optional; `cargo
test` never needs Python; the `opensim` PyPI package, 4.x).

1. OpenSim opens the .mot: `opensim.TimeSeriesTable` (STOFileAdapter) and `opensim.Storage`
   read it; `inDegrees=yes`; row and column counts match the header.
2. OpenSim's kinematics agree with gaitfit's: a model is built with the coordinate definitions of
   OpenSim's gait models (gait2392's joint axes and order: pelvis tilt/list/rotation about
   z/x/y then tx/ty/tz, hips flexion/adduction/rotation about z/x/y with the left x and y axes
   mirrored, knee about z, ankle about z then subtalar about x (left mirrored), mtp about z,
   lumbar extension/bending/rotation about z/x/y, arms flex/add/rot about z/x/y (left mirrored),
   elbow about z) and gaitfit's segment lengths (the OFFSETs of the same motion's BVH). With the
   .mot's coordinates OpenSim places the hip, knee and ankle joint centres and the toe tips,
   which must be where gaitfit's CSV puts them (the toe tips with gaitfit's ankle axial rotation,
   which no gait-model coordinate holds, added from the CSV's `*_ankle_y_deg`); for the arms, whose root sits on gaitfit's spine
   chain (one torso body in OpenSim), the directions of the upper arm and the forearm must agree.

    gaitfit generate walk --speed 5km/h --count 6 -o /tmp/w.mot
    gaitfit generate walk --speed 5km/h --count 6 -o /tmp/w.csv
    gaitfit generate walk --speed 5km/h --count 6 -o /tmp/w.bvh
    /work/venv/bin/python tools/export/check_mot_opensim.py /tmp/w.mot /tmp/w.csv /tmp/w.bvh

Prints the largest disagreement of each kind and exits 1 if a position differs by more than
1e-4 m or a direction by more than 1e-4 rad (the files carry 8 decimals of degrees and 6 of
metres). Add --rajagopal for a file written with --opensim-model rajagopal (knee sign flipped).
"""
import argparse
import csv
import math
import sys

import opensim as osim

GAIT2392_HIP = (-0.0707, -0.0661)  # hip_r in gait2392's pelvis frame (x, y), m


def bvh_offsets(path):
    """Joint name -> OFFSET (m), and joint name -> end-site OFFSET, from a BVH hierarchy."""
    offsets, ends, stack, last = {}, {}, [], None
    scale = 1.0
    with open(path) as f:
        lines = [l.strip() for l in f]
    for i, l in enumerate(lines):
        if l.startswith("MOTION"):
            break
        t = l.split()
        if not t:
            continue
        if t[0] in ("ROOT", "JOINT"):
            last = t[1]
            stack.append(last)
        elif t[0] == "End":
            last = ("end", stack[-1])
            stack.append(last)
        elif t[0] == "OFFSET":
            v = tuple(float(x) for x in t[1:4])
            if isinstance(last, tuple):
                ends[last[1]] = v
            else:
                offsets[last] = v
        elif t[0] == "}":
            stack.pop()
    # Metres or centimetres: the lumbar offset of a human is well under 1 m.
    if abs(offsets["lumbar"][1]) > 1.0:
        scale = 0.01
    sc = lambda v: tuple(scale * x for x in v)
    return {k: sc(v) for k, v in offsets.items()}, {k: sc(v) for k, v in ends.items()}


def vec(v):
    return osim.Vec3(*v)


def add(a, b):
    return tuple(x + y for x, y in zip(a, b))


def custom_joint(model, name, parent, loc, child, rotations, translations=None):
    """A CustomJoint: `rotations` = [(coord, axis), ...] up to 3 (applied in order),
    `translations` = [(coord, axis)] or None."""
    st = osim.SpatialTransform()
    used = []
    # Unused rotation axes (held at 0) must still span 3-D with the used ones.
    axes = [tuple(ax) for _, ax in rotations]
    cross = lambda u, v: (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    while len(axes) < 3:
        if len(axes) == 1:
            b = next(e for e in ((1, 0, 0), (0, 1, 0), (0, 0, 1)) if any(abs(x) > 1e-9 for x in cross(axes[0], e)))
            axes.append(b)
        else:
            axes.append(cross(axes[0], axes[1]))
    for k in range(3):
        ta = st.updTransformAxis(k)
        ta.setAxis(vec(axes[k]))
        if k < len(rotations):
            c, _ = rotations[k]
            ta.setCoordinateNames(osim.ArrayStr(c, 1))
            ta.set_function(osim.LinearFunction())
            used.append(c)
        else:
            ta.set_function(osim.Constant(0))
    for k in range(3):
        ta = st.updTransformAxis(3 + k)
        ta.setAxis(vec([(1, 0, 0), (0, 1, 0), (0, 0, 1)][k]))
        if translations:
            c, _ = translations[k]
            ta.setCoordinateNames(osim.ArrayStr(c, 1))
            ta.set_function(osim.LinearFunction())
            used.append(c)
        else:
            ta.set_function(osim.Constant(0))
    j = osim.CustomJoint(name, parent, vec(loc), vec((0, 0, 0)), child, vec((0, 0, 0)), vec((0, 0, 0)), st)
    model.addJoint(j)
    for k in range(j.numCoordinates()):
        c = j.upd_coordinates(k)
        c.setRangeMin(-1000.0)
        c.setRangeMax(1000.0)
        c.setDefaultClamped(False)
    return j


def body(model, name):
    b = osim.Body(name, 1.0, vec((0, 0, 0)), osim.Inertia(0.01, 0.01, 0.01, 0, 0, 0))
    model.addBody(b)
    return b


def build(off, ends, height, rajagopal):
    s = height / 1.8
    m = osim.Model()
    m.setName("gait2392_coordinates_on_gaitfit_segments")
    pelvis = body(m, "pelvis")
    custom_joint(m, "ground_pelvis", m.getGround(), (0, 0, 0), pelvis,
                 [("pelvis_tilt", (0, 0, 1)), ("pelvis_list", (1, 0, 0)), ("pelvis_rotation", (0, 1, 0))],
                 [("pelvis_tx", None), ("pelvis_ty", None), ("pelvis_tz", None)])
    # gaitfit's root is the hip-centre midpoint; gait2392's pelvis origin is offset from it.
    mid = (-GAIT2392_HIP[0] * s, -GAIT2392_HIP[1] * s, 0.0)
    knee_axis = (0, 0, -1) if rajagopal else (0, 0, 1)
    bodies = {}
    for side, mir in (("r", 1), ("l", -1)):
        femur, tibia, talus, toes = (body(m, f"{b}_{side}") for b in ("femur", "tibia", "talus", "toes"))
        hip = add((-mid[0], -mid[1], 0.0), off[f"{side}_hip"])
        custom_joint(m, f"hip_{side}", pelvis, hip, femur,
                     [(f"hip_flexion_{side}", (0, 0, 1)), (f"hip_adduction_{side}", (mir, 0, 0)),
                      (f"hip_rotation_{side}", (0, mir, 0))])
        custom_joint(m, f"knee_{side}", femur, off[f"{side}_knee"], tibia, [(f"knee_angle_{side}", knee_axis)])
        # gaitfit's ankle also turns about its long axis (toe-in/out), which no gait-model
        # coordinate holds: `ankle_axial_*` is fed from the CSV's `*_ankle_y_deg`.
        custom_joint(m, f"ankle_{side}", tibia, off[f"{side}_ankle"], talus,
                     [(f"ankle_angle_{side}", (0, 0, 1)), (f"subtalar_angle_{side}", (mir, 0, 0)),
                      (f"ankle_axial_{side}", (0, mir, 0))])
        custom_joint(m, f"mtp_{side}", talus, off[f"{side}_metatarsal"], toes, [(f"mtp_angle_{side}", (0, 0, 1))])
        bodies[side] = (femur, tibia, talus, toes)
    torso = body(m, "torso")
    custom_joint(m, "back", pelvis, add((-mid[0], -mid[1], 0.0), off["lumbar"]), torso,
                 [("lumbar_extension", (0, 0, 1)), ("lumbar_bending", (1, 0, 0)), ("lumbar_rotation", (0, 1, 0))])
    arms = {}
    for side, mir in (("r", 1), ("l", -1)):
        humerus, ulna = body(m, f"humerus_{side}"), body(m, f"ulna_{side}")
        custom_joint(m, f"shoulder_{side}", torso, (0, 0, 0), humerus,
                     [(f"arm_flex_{side}", (0, 0, 1)), (f"arm_add_{side}", (mir, 0, 0)), (f"arm_rot_{side}", (0, mir, 0))])
        custom_joint(m, f"elbow_{side}", humerus, off[f"{side}_elbow"], ulna, [(f"elbow_flex_{side}", (0, 0, 1))])
        arms[side] = (humerus, ulna)
    m.finalizeConnections()
    return m, bodies, arms


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mot")
    ap.add_argument("csv")
    ap.add_argument("bvh")
    ap.add_argument("--rajagopal", action="store_true")
    a = ap.parse_args()

    table = osim.TimeSeriesTable(a.mot)
    labels = list(table.getColumnLabels())
    assert table.getTableMetaDataAsString("inDegrees") == "yes", "inDegrees is not yes"
    n_rows = int(table.getTableMetaDataAsString("nRows"))
    assert table.getNumRows() == n_rows, (table.getNumRows(), n_rows)
    storage = osim.Storage(a.mot)
    assert storage.isInDegrees() and storage.getSize() == n_rows
    print(f"{a.mot}: OpenSim reads {n_rows} rows x {len(labels)} coordinates, inDegrees=yes")

    off, ends = bvh_offsets(a.bvh)
    with open(a.csv) as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == n_rows, (len(rows), n_rows)
    # gaitfit's body height from the rest pose: the sole (toe tip) to the hip, then up the spine
    # to the vertex (the head's end site).
    hip_height = -(off["r_knee"][1] + off["r_ankle"][1] + off["r_metatarsal"][1] + ends["r_metatarsal"][1])
    spine = sum(off[j][1] for j in ("lumbar", "thoracic_lower", "thoracic_upper", "neck", "head"))
    height = hip_height + spine + ends["head"][1]
    print(f"  gaitfit figure: body height {height:.4f} m (from the BVH offsets)")
    model, bodies, arms = build(off, ends, height, a.rajagopal)
    state = model.initSystem()
    coords = model.getCoordinateSet()
    names = [coords.get(i).getName() for i in range(coords.getSize())]
    missing = [n for n in names if n not in labels and not n.startswith("ankle_axial")]
    assert not missing, f"coordinates missing from the .mot: {missing}"
    worst = {"joint centres": 0.0, "toe tips": 0.0, "arm directions": 0.0}
    times = table.getIndependentColumn()
    for i in range(n_rows):
        row = table.getRowAtIndex(i)
        r = rows[i]
        for n in names:
            if n.startswith("ankle_axial"):
                side = n[-1]
                v = (1 if side == "r" else -1) * float(r[f"{side}_ankle_y_deg"])
            else:
                v = row[labels.index(n)]
            c = coords.get(n)
            c.setValue(state, v if n in ("pelvis_tx", "pelvis_ty", "pelvis_tz") else math.radians(v), False)
        model.realizePosition(state)
        assert abs(float(r["time_s"]) - times[i]) < 1e-6
        P = lambda name: tuple(float(r[f"{name}_{ax}_m"]) for ax in "xyz")
        dist = lambda p, q: math.dist(p, q)
        for side in ("r", "l"):
            femur, tibia, talus, toes = bodies[side]
            for b, name in ((femur, "hip"), (tibia, "knee"), (talus, "ankle")):
                g = b.getPositionInGround(state)
                worst["joint centres"] = max(worst["joint centres"], dist((g[0], g[1], g[2]), P(f"{side}_{name}")))
            tip = toes.findStationLocationInGround(state, vec(ends[f"{side}_metatarsal"]))
            worst["toe tips"] = max(worst["toe tips"], dist((tip[0], tip[1], tip[2]), P(f"{side}_toe")))
            humerus, ulna = arms[side]
            for b, start, end, seg in ((humerus, "shoulder", "elbow", f"{side}_elbow"), (ulna, "elbow", "wrist", f"{side}_wrist")):
                d_local = off[seg]
                o = b.getPositionInGround(state)
                e = b.findStationLocationInGround(state, vec(d_local))
                u = [e[k] - o[k] for k in range(3)]
                w = [P(f"{side}_{end}")[k] - P(f"{side}_{start}")[k] for k in range(3)]
                cos = sum(x * y for x, y in zip(u, w)) / (math.hypot(*u) * math.hypot(*w))
                worst["arm directions"] = max(worst["arm directions"], math.acos(max(-1.0, min(1.0, cos))))
    ok = True
    for k, v in worst.items():
        unit = "rad" if "direction" in k else "m"
        bad = v > 1e-4
        ok &= not bad
        print(f"  {k}: OpenSim vs gaitfit, largest difference {v:.2e} {unit}{'  TOO LARGE' if bad else ''}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
