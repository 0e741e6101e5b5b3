#!/usr/bin/env python3
"""gaitkit 1.5 (PyPI) beside gaitfit on the shared files: marker events against the plates.

Optional, not CI. Needs /work/venv (gaitkit, ezc3d, numpy, pandas) and a release build of
gaitfit. Run from the repository root (shared data in ../shared/data or $GAITFIT_SHARED_DATA):
    /work/venv/bin/python tools/events/gaitkit_side_by_side.py [--gaitfit target/release/gaitfit]

Data and references (both scored the same way, by this script):
- Walking: the 12 Schreiber & Moissenet (2019) overground trials (C3D, markers 100 Hz). The
  reference is tools/events/schreiber_force_events.csv from force_truth.py (20 N on the
  unfiltered force of ezc3d's plate extraction, numpy, no gaitfit). Plates see only some steps,
  so only recall and timing are defined there.
- Running: Hamner & Delp (2013) subject01 Run_2–5 (TRC, 100 Hz, treadmill). The reference is
  tools/events/hamner_force_events.csv from force_truth.py (numpy, no gaitfit); the GRF sees
  every contact.

Scoring: every reference heel strike and toe off inside the marker record is scored, those
near the record's ends included; a detection of the same foot and kind within 60 ms is a
match (one-to-one, closest first); error = detected − reference. gaitkit gets the Schreiber
markers through a marker map (heel L_FCC, toe L_FM2, malleoli, epicondyles, ASIS, PSIS) and the
Hamner ones as landmark frames (CAL, TOE, ASIS, PSIS; no malleoli or epicondyles there, so the
ankle and knee are proxies — foot centre, shank cluster — that only gaitkit's angle-based
methods read: zeni, gaitkit's running default, is the fair comparison), Y-up turned Z-up. Methods: gaitkit's default for walking (bike) and for running (zeni), plus
o'connor and hreljac where they run; gaitfit's `--events kinematic` (foot_speed for walks,
foot_jerk for runs) and zeni.
"""
import argparse
import glob
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
import pandas as pd

TOL = 0.06
HERE = os.path.dirname(os.path.abspath(__file__))
SCHREIBER_MAP = {
    "left_heel": "L_FCC", "right_heel": "R_FCC", "left_toe": "L_FM2", "right_toe": "R_FM2",
    "left_ankle": ("L_FAL", "L_TAM"), "right_ankle": ("R_FAL", "R_TAM"),
    "left_knee": ("L_FLE", "L_FME"), "right_knee": ("R_FLE", "R_FME"),
    "left_hip": "L_IAS", "right_hip": "R_IAS", "sacrum": ("L_IPS", "R_IPS"),
}
HAMNER_MAP = {
    "left_heel": ["LCAL"], "right_heel": ["RCAL"], "left_toe": ["LTOE"], "right_toe": ["RTOE"],
    # The running TRCs have no malleolus or epicondyle markers: proxies (foot centre, shank
    # cluster centre) that only gaitkit's angle-based methods read.
    "left_ankle": ["LCAL", "LMT5"], "right_ankle": ["RCAL", "RMT5"],
    "left_knee": ["LTB1", "LTB2", "LTB3"], "right_knee": ["RTB1", "RTB2", "RTB3"],
    "left_hip": ["LASI"], "right_hip": ["RASI"], "sacrum": ["LPSI", "RPSI"],
}


def shared():
    root = os.environ.get("GAITFIT_SHARED_DATA") or os.path.join("..", "shared", "data")
    if not os.path.isdir(os.path.join(root, "schreiber2019")):
        sys.exit(f"no shared data in {root} (set GAITFIT_SHARED_DATA)")
    return root


def read_trc(path):
    lines = open(path).read().split("\n")
    names = lines[3].split("\t")
    rows = [l.split("\t") for l in lines[5:] if l.strip()]
    t = np.array([float(r[1]) for r in rows])
    out = {}
    for i, nm in enumerate(names):
        nm = nm.strip()
        if i < 2 or not nm:
            continue
        out[nm] = np.array([[float(r[i + k]) if i + k < len(r) and r[i + k].strip() else np.nan
                             for k in range(3)] for r in rows])
    return t, out


def hamner_frames(path):
    """gaitkit landmark frames from a Hamner TRC (Y up → Z up, mm)."""
    t, m = read_trc(path)
    frames = []
    for i in range(len(t)):
        lm = {}
        for key, names in HAMNER_MAP.items():
            p = np.nanmean([m[n][i] for n in names], axis=0)
            lm[key] = (float(p[0]), float(-p[2]), float(p[1]))
        frames.append({"frame_index": i, "landmark_positions": lm})
    return t, frames


def gaitkit_events(data, method, fps=None, t0=0.0):
    import gaitkit
    kw = {"fps": fps} if fps else {}
    r = gaitkit.detect(data, method=method, **kw)
    ev = r.events
    out = []
    for _, e in ev.iterrows():
        kind = {"HS": "heel_strike", "TO": "toe_off"}.get(e.event_type)
        if kind:
            out.append((t0 + float(e.time), e.side, kind))
    return out


def gaitfit_events(gaitfit, files, source, cwd):
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "ev.csv")
        subprocess.run([gaitfit, "events", "--events", source, "--events-out", out, *files],
                       cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if not os.path.exists(out):
            return pd.DataFrame(columns=["trial", "time_s", "side", "event"])
        return pd.read_csv(out)


def score(detected, reference):
    """errors (s) and misses of one trial: lists of (time, side, kind)."""
    errs = {"heel_strike": [], "toe_off": []}
    miss = {"heel_strike": 0, "toe_off": 0}
    for kind in errs:
        for side in ("left", "right"):
            d = sorted(x[0] for x in detected if x[1] == side and x[2] == kind)
            r = sorted(x[0] for x in reference if x[1] == side and x[2] == kind)
            pairs = sorted(((abs(a - b), i, j) for i, a in enumerate(d) for j, b in enumerate(r)
                            if abs(a - b) <= TOL))
            used_d, used_r = set(), set()
            for _, i, j in pairs:
                if i in used_d or j in used_r:
                    continue
                used_d.add(i)
                used_r.add(j)
                errs[kind].append(d[i] - r[j])
            miss[kind] += len(r) - len(used_r)
    return errs, miss


def add(table, key, errs, miss):
    e, m = table.setdefault(key, ({"heel_strike": [], "toe_off": []},
                                  {"heel_strike": 0, "toe_off": 0}))
    for k in e:
        e[k] += errs[k]
        m[k] += miss[k]


def render(table, seconds):
    print(f"{'data':<10} {'tool':<8} {'method':<16} {'event':<12} {'n':>4} {'recall':>7} "
          f"{'error ms (mean ± SD)':>22} {'s/trial':>8}")
    for (data, tool, method), (e, m) in table.items():
        for kind in ("heel_strike", "toe_off"):
            n = len(e[kind])
            rec = n / (n + m[kind]) if n + m[kind] else float("nan")
            mean = 1e3 * np.mean(e[kind]) if n else float("nan")
            sd = 1e3 * np.std(e[kind], ddof=1) if n > 1 else float("nan")
            print(f"{data:<10} {tool:<8} {method:<16} {kind:<12} {n:>4} {rec:>7.3f} "
                  f"{mean:>+11.1f} ± {sd:<8.1f} {seconds[(data, tool, method)]:>8.3f}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--gaitfit", default=os.path.join("target", "release", "gaitfit"))
    args = ap.parse_args()
    gaitfit = os.path.abspath(args.gaitfit)
    root = os.path.abspath(shared())
    table, seconds = {}, {}

    # Walking: Schreiber.
    import gaitkit
    files = sorted(glob.glob(os.path.join(root, "schreiber2019", "*", "dynamic", "*.c3d")))
    force = pd.read_csv(os.path.join(HERE, "schreiber_force_events.csv"))
    ref = {tr: [(r.time_s, r.side, r.event) for r in g.itertuples()]
           for tr, g in force.groupby("trial")}
    for method in ("bike", "zeni", "oconnor", "hreljac"):
        key = ("schreiber", "gaitkit", method)
        t = time.time()
        for f in files:
            trial = os.path.basename(f)[:-4]
            try:
                data = gaitkit.load_c3d(f, marker_map=SCHREIBER_MAP)
                n = data["n_frames"] / data["fps"]
                det = gaitkit_events(data, method)
            except Exception as e:  # a method that does not run on a trial scores no events
                print(f"gaitkit {method} on {trial}: {e}", file=sys.stderr)
                det, n = [], None
            refs = [x for x in ref.get(trial, []) if n is None or x[0] <= n]
            add(table, key, *score(det, refs))
        seconds[key] = (time.time() - t) / len(files)
    for source, label in (("kinematic", "kinematic"), ("zeni", "zeni")):
        key = ("schreiber", "gaitfit", label)
        t = time.time()
        det = gaitfit_events(gaitfit, files, source, root)
        seconds[key] = (time.time() - t) / len(files)
        for f in files:
            trial = os.path.basename(f)[:-4]
            d = det[det.trial == trial]
            add(table, key, *score([(r.time_s, r.side, r.event) for r in d.itertuples()],
                                   ref.get(trial, [])))

    # Running: Hamner subject01.
    href = pd.read_csv(os.path.join(HERE, "hamner_force_events.csv"))
    runs = [os.path.join(root, "hamner2013", "subject01", f"Run_{k}.trc") for k in (2, 3, 4, 5)]
    for method in ("zeni", "bike", "oconnor", "hreljac"):
        key = ("hamner01", "gaitkit", method)
        t = time.time()
        for f in runs:
            trial = os.path.basename(f)[:-4]
            tt, frames = hamner_frames(f)
            rate = 1.0 / np.median(np.diff(tt))
            try:
                det = gaitkit_events(frames, method, fps=rate, t0=tt[0])
            except Exception as e:
                print(f"gaitkit {method} on {trial}: {e}", file=sys.stderr)
                det = []
            g = href[(href.subject == "subject01") & (href.trial == trial)]
            refs = [(r.time_s, r.side, r.event) for r in g.itertuples()
                    if tt[0] <= r.time_s <= tt[-1]]
            add(table, key, *score(det, refs))
        seconds[key] = (time.time() - t) / len(runs)
    for source, label in (("kinematic", "kinematic"), ("zeni", "zeni")):
        key = ("hamner01", "gaitfit", label)
        t = time.time()
        det = gaitfit_events(gaitfit, runs, source, root)
        seconds[key] = (time.time() - t) / len(runs)
        for f in runs:
            trial = os.path.basename(f)[:-4]
            tt, _ = read_trc(f)
            d = det[det.trial == trial]
            g = href[(href.subject == "subject01") & (href.trial == trial)]
            refs = [(r.time_s, r.side, r.event) for r in g.itertuples()
                    if tt[0] <= r.time_s <= tt[-1]]
            add(table, key, *score([(r.time_s, r.side, r.event) for r in d.itertuples()], refs))
    render(table, seconds)


if __name__ == "__main__":
    main()
