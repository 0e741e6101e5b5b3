#!/usr/bin/env python3
"""Reference force events: 20 N on the *unfiltered* vertical force, computed without gaitfit.

numpy only, and a different algorithm from gaitfit's (which finds contacts on the filtered
force and then times them on the unfiltered one): per foot channel, the unloaded level is the
median of the samples below 20 N; the force above it is thresholded at 20 N; loaded runs
separated by less than 50 ms are joined (the WBDS export has isolated zero samples inside
contacts, e.g. 121, 0, 83, 0, 0, 0, 56, 0, 0, 29 N while the foot unloads), runs shorter than
50 ms (unless the record cuts them) or never reaching 50 N are dropped; heel strike is the linear interpolation of the 20 N crossing between the last
unloaded and the first loaded sample of a run, toe off between the last loaded and the first
unloaded sample. Runs that touch the record's ends have no event there.

- WBDS subject 04 (Fukuchi, Fukuchi & Duarte 2018, PeerJ 6:e4640, CC BY 4.0): 300 Hz, one belt
  per foot; the belt carrying the right foot is the one whose mean centre of pressure (loaded
  samples) lies further along +Z (right = forward × up in a right-handed lab frame, forward +X,
  up +Y).
- Hamner & Delp (2013), as republished by Fox (2024): `R_`/`L_ground_force_vy`, 1000 Hz.

Double support (the walking paper's t_ds, one period) for WBDS: from each heel strike to the
other foot's next toe off, when no toe off of the same foot comes first. The variant
`naive` (no joining: a contact ends at the first zero sample of the unloading tail) is printed
for comparison with figures computed that way.

Run from the repository root (shared data in ../shared/data or $GAITFIT_SHARED_DATA):
    /work/venv/bin/python tools/events/force_truth.py
It writes, beside this script, wbds04_force_events.csv and hamner_force_events.csv (every
event) and wbds04_double_support.csv (per trial); tests/events_force_timing.rs compares
gaitfit with them.
"""
import csv
import glob
import os
import sys

import numpy as np

LEVEL_N = 20.0
WBDS_RATE_HZ = 300.0  # the Time column holds sample numbers
MIN_GAP_S = 0.05
MIN_RUN_S = 0.05
CONFIRM_N = 50.0
HERE = os.path.dirname(os.path.abspath(__file__))


def shared():
    root = os.environ.get("GAITFIT_SHARED_DATA") or os.path.join("..", "shared", "data")
    if not os.path.isdir(os.path.join(root, "wbds")):
        sys.exit(f"no shared data in {root} (set GAITFIT_SHARED_DATA)")
    return root


def runs(mask):
    """(start, end) inclusive index pairs of the True runs of mask."""
    d = np.diff(np.concatenate(([0], mask.astype(int), [0])))
    return list(zip(np.where(d == 1)[0], np.where(d == -1)[0] - 1))


def events(t, force, min_gap_s=MIN_GAP_S):
    """Heel strikes and toe offs (s) of one foot's raw vertical force sampled at times t."""
    base = np.median(force[force < LEVEL_N])
    g = force - base
    n = len(g)
    joined = []
    for s, e in runs(g > LEVEL_N):
        if joined and t[s] - t[joined[-1][1]] < min_gap_s:
            joined[-1] = (joined[-1][0], e)
        else:
            joined.append((s, e))
    hs, to = [], []
    for s, e in joined:
        if g[s : e + 1].max() < CONFIRM_N:
            continue  # never loaded enough to be a foot
        if t[e] - t[s] < MIN_RUN_S and 0 < s and e < n - 1:
            continue  # a blip; a run cut by the record is a contact of unknown length
        if s > 0:
            a, b = g[s - 1], g[s]
            hs.append(t[s - 1] + (LEVEL_N - a) / (b - a) * (t[s] - t[s - 1]))
        if e < n - 1:
            a, b = g[e], g[e + 1]
            to.append(t[e] + (a - LEVEL_N) / (a - b) * (t[e + 1] - t[e]))
    return hs, to


def double_support(ev):
    ds = []
    for i, (t, side, kind) in enumerate(ev):
        if kind != "heel_strike":
            continue
        for u, s2, k2 in ev[i + 1:]:
            if k2 == "toe_off":
                if s2 != side:
                    ds.append(u - t)
                break
    return ds


def wbds(root):
    rows, summary = [], []
    print("WBDS04 double support, s (mean ± SD): joined dropouts | naive")
    for k in (5, 6, 7, 8):
        name = f"WBDS04walkT0{k}grf.txt"
        data = np.genfromtxt(os.path.join(root, "wbds", name), delimiter="\t", names=True)
        t = (data["Time"] - 1) / WBDS_RATE_HZ
        cop = {b: np.mean(data[f"COPz{b}"][data[f"Fy{b}"] > LEVEL_N]) for b in (1, 2)}
        right = max(cop, key=cop.get)
        trial = name[: -len("grf.txt")]
        res = {}
        for variant, gap in (("joined", MIN_GAP_S), ("naive", 0.0)):
            ev = []
            for b in (1, 2):
                hs, to = events(t, data[f"Fy{b}"], gap)
                side = "right" if b == right else "left"
                ev += [(x, side, "heel_strike") for x in hs]
                ev += [(x, side, "toe_off") for x in to]
            ev.sort()
            res[variant] = (ev, double_support(ev))
        ev, ds = res["joined"]
        naive = res["naive"][1]
        print(f"  {trial:<14} n {len(ds):3d}  {np.mean(ds):.4f} ± {np.std(ds, ddof=1):.4f}"
              f"  | {np.mean(naive):.4f} ± {np.std(naive, ddof=1):.4f}")
        rows += [(trial, side, kind, f"{x:.5f}") for x, side, kind in ev]
        summary.append((trial, len(ds), f"{np.mean(ds):.5f}", f"{np.std(ds, ddof=1):.5f}"))
    write("wbds04_force_events.csv", ["trial", "side", "event", "time_s"], rows)
    write("wbds04_double_support.csv",
          ["trial", "n", "double_support_mean_s", "double_support_sd_s"], summary)


def hamner(root):
    rows = []
    for path in sorted(glob.glob(os.path.join(root, "hamner2013", "subject*", "Run_*_grf.mot"))):
        with open(path) as f:
            skip = next(i for i, line in enumerate(f) if line.strip() == "endheader") + 1
        data = np.genfromtxt(path, delimiter="\t", names=True, skip_header=skip)
        subject = os.path.basename(os.path.dirname(path))
        trial = os.path.basename(path)[: -len("_grf.mot")]
        for side, col in (("right", "R_ground_force_vy"), ("left", "L_ground_force_vy")):
            hs, to = events(data["time"], data[col])
            rows += [(subject, trial, side, "heel_strike", f"{x:.5f}") for x in hs]
            rows += [(subject, trial, side, "toe_off", f"{x:.5f}") for x in to]
    write("hamner_force_events.csv", ["subject", "trial", "side", "event", "time_s"], rows)


def write(name, header, rows):
    out = os.path.join(HERE, name)
    with open(out, "w", newline="") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow(header)
        w.writerows(rows)
    print(f"wrote {out} ({len(rows)} rows)")


if __name__ == "__main__":
    r = shared()
    wbds(r)
    hamner(r)
