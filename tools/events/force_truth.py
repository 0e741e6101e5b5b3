#!/usr/bin/env python3
"""Reference force events: 20 N on the *unfiltered* vertical force, computed without gaitfit.

numpy only, and a different algorithm from gaitfit's (which finds contacts on the filtered
force and then times them on the unfiltered one): per foot channel, the unloaded level is the
median of the samples below 20 N; the force above it is thresholded at 20 N; runs shorter than
50 ms are blips (unless the record cuts them), the others less than 50 ms apart are one
contact (no swing lasts a few samples), contacts never reaching 50 N are dropped; heel strike is
the linear interpolation of the 20 N crossing between the last unloaded and the first loaded
sample of a contact, toe off between the last loaded and the first unloaded sample. Contacts
that touch the record's ends have no event there. This "plain" reading is the developers'
guide's force-plate truth (20 N on the unfiltered vertical force) and gaitfit's default.

- WBDS subject 04 (Fukuchi, Fukuchi & Duarte 2018, PeerJ 6:e4640, CC BY 4.0): 300 Hz, one belt
  per foot; the belt carrying the right foot is the one whose mean centre of pressure (loaded
  samples) lies further along +Z (right = forward × up in a right-handed lab frame, forward +X,
  up +Y).
- Hamner & Delp (2013), as republished by Fox (2024): `R_`/`L_ground_force_vy`, 1000 Hz.
- Schreiber & Moissenet (2019), the 12 overground C3D trials: two plates, analog 1500 Hz, read
  by ezc3d's own force-platform extraction (`extract_forceplat_data`: channels, calibration and
  plate corners → force in the lab frame), not by gaitfit's C3D reader; the vertical force is
  the lab-Z component (sign taken so that the loaded plate reads positive). Each plate's
  contact goes to the foot whose heel–second-metatarsal midpoint (markers `*_FCC`, `*_FM2`),
  averaged over the loaded marker frames, lies nearest the mean centre of pressure. Times from
  the first sample (analog sample k at k/1500 s, marker frame i at i/100 s).
- BMClab overground walks `walk1`/`walk2` (Cortex export): `.forces`, 7 plates at 450 Hz, the
  vertical force is `FYk` (Y up), the centre of pressure (`Xk`, `Zk`, mm); the export zeroes
  the force below ≈ 30 N (first nonzero sample at contact 37–53 N), so the 20 N crossing is
  interpolated from the zeroed sample, within one 2.2 ms sample of the true one. Feet as for
  Schreiber, with the TRC's `R.Heel`/`R.MT2` and `L.Heel`/`L.MT2` (150 Hz). Sample k (the
  `#Sample` column minus 1) at k/450 s, TRC frame i at its Time column.

Double support (the walking paper's t_ds, one period) for WBDS: from each heel strike to the
other foot's next toe off, when no toe off of the same foot comes first. The variant
`bridged` (every run kept, runs less than 50 ms apart joined: the fragments of an unloading
tail after an exported zero extend the contact; gaitfit's `--bridge-dropouts`) is printed and
written beside it (wbds04_force_events_bridged.csv, bridged_double_support_mean_s).

The case for bridging (printed as "dropout evidence"; issue 19 quotes WBDS04 double support
0.070/0.060/0.050/0.047 s, the plain reading within 4 ms): the WBDS export zeroes every
channel of a belt together (force, moment, and the centre of pressure set to one fixed point)
on some samples, and in the unloading tail the samples it leaves nonzero look like the foot's
load, not noise:
  - nonzero samples after the first zero fall monotonically (267 of 270 consecutive pairs on the
    four trials): a tail still unloading, not noise around zero;
  - they occur only within ~30 ms of the cut (46 % of the 2nd sample after the last loaded one,
    5 % of the 6th, none after the 10th), and never in mid swing (1 sample > 20 N in 20 232);
  - at the first zero the foot's force drops by ~100 N in one sample (5× the tail's rate before)
    while the other belt's force changes by its usual amount, i.e. the body's vertical force
    would drop by 100 N in 3.3 ms and come back on the next nonzero sample.
So the foot is probably still loaded until the last of those samples; ending the contact at the
zero shortens the mean double support by 8–16 ms (T08–T05). The truth stays the plain reading
(the guide's definition; the issue's figures); gaitfit warns when a batch has such dropouts.

Run from the repository root (shared data in ../shared/data or $GAITFIT_SHARED_DATA):
    /work/venv/bin/python tools/events/force_truth.py
It writes, beside this script, wbds04_force_events.csv, wbds04_force_events_bridged.csv and
hamner_force_events.csv, schreiber_force_events.csv and bmclab_walk_force_events.csv (every event) and wbds04_double_support.csv
(per trial); tests/events_force_timing.rs compares gaitfit's force events with them and
tests/events_walk_kinematic.rs scores the walking marker events against the Schreiber ones.
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


def events(t, force, bridged=False):
    """Heel strikes and toe offs (s) of one foot's raw vertical force sampled at times t.

    Plain (the default, the guide's truth): the runs above 20 N lasting at least 50 ms (shorter
    ones are blips, unless the record cuts them) make the contacts, runs less than 50 ms apart
    taken as one contact (no swing lasts a few samples); heel strike where the first run of a
    contact rises through 20 N, toe off where its last falls through it. A zeroed sample in an
    unloading tail therefore ends the contact (the tail's later fragments are blips).
    Bridged: every run is kept and runs less than 50 ms apart are joined, so the fragments of
    an unloading tail after a zeroed sample extend the contact.
    """
    base = np.median(force[force < LEVEL_N])
    g = force - base
    n = len(g)
    kept = [(s, e) for s, e in runs(g > LEVEL_N)
            if bridged or t[e] - t[s] >= MIN_RUN_S or s == 0 or e == n - 1]
    joined = []
    for s, e in kept:
        if joined and t[s] - t[joined[-1][1]] < MIN_GAP_S:
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


def dropout_evidence(data):
    """Counts showing that the nonzero samples after a contact's first zero are its load."""
    falling = pairs = 0
    after = np.zeros(12)
    seen = np.zeros(12)
    swing_hi = swing_n = 0
    for b in (1, 2):
        f = data[f"Fy{b}"]
        n = len(f)
        hi = f > LEVEL_N
        cuts = [e for e in np.where(hi[:-1] & (f[1:] == 0))[0] if hi[max(0, e - 30): e + 1].all()]
        lands = [s for s in np.where((f[:-1] == 0) & hi[1:])[0] + 1 if hi[s: s + 30].all()]
        for e in cuts:
            nxt = min([s for s in lands if s > e], default=n)
            tail = f[e + 1: nxt]
            for j, v in enumerate(tail[:12]):
                seen[j] += 1
                after[j] += v > LEVEL_N
            kept = [f[e]] + [v for v in tail[:15] if v > LEVEL_N]
            pairs += len(kept) - 1
            falling += sum(c < a for a, c in zip(kept, kept[1:]))
            mid = f[e + 31: nxt - 15]
            swing_hi += int((mid > LEVEL_N).sum())
            swing_n += len(mid)
    return falling, pairs, after, seen, swing_hi, swing_n


def wbds(root):
    rows, brows, summary = [], [], []
    ev_tot = [0, 0, np.zeros(12), np.zeros(12), 0, 0]
    print("WBDS04 double support, s (mean ± SD): plain (20 N, the truth) | dropouts bridged")
    for k in (5, 6, 7, 8):
        name = f"WBDS04walkT0{k}grf.txt"
        data = np.genfromtxt(os.path.join(root, "wbds", name), delimiter="\t", names=True)
        t = (data["Time"] - 1) / WBDS_RATE_HZ
        cop = {b: np.mean(data[f"COPz{b}"][data[f"Fy{b}"] > LEVEL_N]) for b in (1, 2)}
        right = max(cop, key=cop.get)
        trial = name[: -len("grf.txt")]
        for i, x in enumerate(dropout_evidence(data)):
            ev_tot[i] = ev_tot[i] + x
        res = {}
        for variant in ("plain", "bridged"):
            ev = []
            for b in (1, 2):
                hs, to = events(t, data[f"Fy{b}"], variant == "bridged")
                side = "right" if b == right else "left"
                ev += [(x, side, "heel_strike") for x in hs]
                ev += [(x, side, "toe_off") for x in to]
            ev.sort()
            res[variant] = (ev, double_support(ev))
        ev, ds = res["plain"]
        bridged = res["bridged"][1]
        print(f"  {trial:<14} n {len(ds):3d}  {np.mean(ds):.4f} ± {np.std(ds, ddof=1):.4f}"
              f"  | {np.mean(bridged):.4f} ± {np.std(bridged, ddof=1):.4f}")
        rows += [(trial, side, kind, f"{x:.5f}") for x, side, kind in ev]
        brows += [(trial, side, kind, f"{x:.5f}") for x, side, kind in res["bridged"][0]]
        summary.append((trial, len(ds), f"{np.mean(ds):.5f}", f"{np.std(ds, ddof=1):.5f}",
                        len(bridged), f"{np.mean(bridged):.5f}"))
    falling, pairs, after, seen, swing_hi, swing_n = ev_tot
    print("dropout evidence (all four trials): nonzero samples after a contact's first zero")
    print(f"  fall monotonically in {falling} of {pairs} consecutive pairs")
    print("  P(> 20 N) at 1..12 samples after the cut:",
          " ".join(f"{a / max(s, 1):.2f}" for a, s in zip(after, seen)))
    print(f"  samples > 20 N in mid swing: {swing_hi} of {swing_n}")
    write("wbds04_force_events.csv", ["trial", "side", "event", "time_s"], rows)
    write("wbds04_force_events_bridged.csv", ["trial", "side", "event", "time_s"], brows)
    write("wbds04_double_support.csv",
          ["trial", "n", "double_support_mean_s", "double_support_sd_s",
           "bridged_n", "bridged_double_support_mean_s"], summary)


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


def schreiber(root):
    import ezc3d  # only this data set needs it

    rows = []
    for path in sorted(glob.glob(os.path.join(root, "schreiber2019", "*", "dynamic", "*.c3d"))):
        c = ezc3d.c3d(path, extract_forceplat_data=True)
        par = c["parameters"]
        rate = float(par["ANALOG"]["RATE"]["value"][0])
        prate = float(par["POINT"]["RATE"]["value"][0])
        labels = [x.strip() for x in par["POINT"]["LABELS"]["value"]]
        pts = c["data"]["points"]
        foot = {side: 0.5 * (pts[:3, labels.index(f"{p}_FCC")] + pts[:3, labels.index(f"{p}_FM2")])
                for side, p in (("left", "L"), ("right", "R"))}
        trial = os.path.basename(path)[: -len(".c3d")]
        subject = trial.split("_")[0]
        for plate in c["data"]["platform"]:
            fz = plate["force"][2]
            fz = fz if fz.max() >= -fz.min() else -fz
            t = np.arange(len(fz)) / rate
            hs, to = events(t, fz)
            loaded = fz > CONFIRM_N
            if not loaded.any():
                continue
            cop = np.nanmean(plate["center_of_pressure"][:3, loaded], axis=1)
            frames = np.unique(np.floor(t[loaded] * prate + 0.5).astype(int))
            frames = frames[frames < pts.shape[2]]
            dist = {side: np.linalg.norm(np.nanmean(m[:, frames], axis=1) - cop)
                    for side, m in foot.items()}
            side = min(dist, key=dist.get)
            rows += [(subject, trial, side, "heel_strike", f"{x:.5f}") for x in hs]
            rows += [(subject, trial, side, "toe_off", f"{x:.5f}") for x in to]
    write("schreiber_force_events.csv", ["subject", "trial", "side", "event", "time_s"], rows)


def read_trc(path):
    """Time (s) and markers (name → n × 3 array, file units) of a TRC file."""
    with open(path) as f:
        lines = f.read().split("\n")
    names = lines[3].split("\t")
    rows = [line.split("\t") for line in lines[5:] if line.strip()]
    t = np.array([float(r[1]) for r in rows])
    out = {}
    for i, name in enumerate(names):
        if i >= 2 and name.strip():
            out[name.strip()] = np.array(
                [[float(r[i + k]) if i + k < len(r) and r[i + k].strip() else np.nan
                  for k in range(3)] for r in rows])
    return t, out


def bmclab(root):
    rows = []
    for trial in ("walk1", "walk2"):
        base = os.path.join(root, "bmclab", trial)
        with open(base + ".forces") as f:
            head = [next(f) for _ in range(4)]
        rate = float(next(x for x in head if x.startswith("SampleRate=")).split("=")[1])
        data = np.genfromtxt(base + ".forces", delimiter="\t", names=True, skip_header=4,
                             deletechars="")
        tm, markers = read_trc(base + ".trc")
        foot = {side: 0.5 * (markers[f"{p}.Heel"] + markers[f"{p}.MT2"])
                for side, p in (("left", "L"), ("right", "R"))}
        t = np.arange(len(data)) / rate
        for k in range(1, 8):
            fy = data[f"FY{k}"]
            loaded = fy > CONFIRM_N
            if not loaded.any():
                continue
            hs, to = events(t, fy)
            cop = np.array([np.mean(data[f"X{k}"][loaded]), np.mean(data[f"Z{k}"][loaded])])
            frames = np.unique(np.clip(np.searchsorted(tm, t[loaded]), 0, len(tm) - 1))
            dist = {side: np.linalg.norm(np.nanmean(m[frames][:, [0, 2]], axis=0) - cop)
                    for side, m in foot.items()}
            side = min(dist, key=dist.get)
            rows += [(trial, side, "heel_strike", f"{x:.5f}") for x in hs]
            rows += [(trial, side, "toe_off", f"{x:.5f}") for x in to]
    write("bmclab_walk_force_events.csv", ["trial", "side", "event", "time_s"], rows)


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
    schreiber(r)
    bmclab(r)
