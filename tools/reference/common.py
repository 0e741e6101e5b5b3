"""Shared helpers of the reference scripts: the bundled trials tables read the way gaitfit
reads them (`src/ingest/trials.rs`: speed/step length/step frequency completed from any two,
rows disagreeing by more than 2 % flagged; double support % derived from its time), and dense
cluster-robust covariances written out from their definitions.

These scripts make the numbers the Rust tests compare with; they never read gaitfit's output.
"""
import glob
import os

import numpy as np
import pandas as pd

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
CONSISTENCY_TOLERANCE = 0.02


def read_table(path):
    """One trials CSV with gaitfit's completion and flagging (SI units, sf in steps/s)."""
    df = pd.read_csv(path, dtype={"subject": str})
    n = len(df)

    def col(name, factor=1.0):
        return df[name].astype(float) * factor if name in df else pd.Series([np.nan] * n)

    v = col("speed_m_per_s")
    sl = col("step_length_m")
    sf = col("step_freq_steps_per_min", 1.0 / 60.0)
    have = sum(name in df for name in ("speed_m_per_s", "step_length_m", "step_freq_steps_per_min"))
    flagged = np.zeros(n, dtype=bool)
    if have >= 2:
        for i in range(n):
            a, b, c = v[i], sl[i], sf[i]
            if np.isnan(a) and not np.isnan(b) and not np.isnan(c):
                v[i] = b * c
            elif np.isnan(b) and not np.isnan(a) and not np.isnan(c) and c > 0:
                sl[i] = a / c
            elif np.isnan(c) and not np.isnan(a) and not np.isnan(b) and b > 0:
                sf[i] = a / b
            elif not (np.isnan(a) or np.isnan(b) or np.isnan(c)):
                prod = b * c
                rel = abs(a - prod) / max(abs(a), abs(prod), 1e-300)
                if rel > CONSISTENCY_TOLERANCE:
                    flagged[i] = True
    dt = col("double_support_time_s")
    dp = col("double_support_pct_cycle")
    if "double_support_time_s" in df:
        for i in range(n):
            t, f = dt[i], sf[i]
            if not np.isnan(t) and not np.isnan(f) and f > 0:
                derived = 100.0 * t * f / 2.0
                p = dp[i]
                if np.isnan(p):
                    dp[i] = derived
                else:
                    rel = abs(p - derived) / max(abs(p), abs(derived), 1e-12)
                    if rel > CONSISTENCY_TOLERANCE and abs(p - derived) > 0.05:
                        flagged[i] = True
    out = pd.DataFrame(
        {
            "subject": df["subject"],
            "gait": df["gait"],
            "v": v,
            "sl": sl,
            "sf": sf,
            "tf": col("flight_time_s"),
            "ds_pct": dp,
            "h": col("body_height_m"),
            "ll": col("leg_length_m"),
            "knee_hs": col("knee_angle_hs_deg", np.pi / 180),
            "foot_hs": col("foot_angle_hs_deg", np.pi / 180),
            "foot_to": col("foot_angle_to_deg", np.pi / 180),
            "meta_to": col("meta_angle_to_deg", np.pi / 180),
            "flagged": flagged,
        }
    )
    return out


def bundled():
    """Every data/*.csv, in file-name order (as `gaitfit fit` reads them)."""
    files = sorted(glob.glob(os.path.join(ROOT, "data", "*.csv")))
    return pd.concat([read_table(f) for f in files], ignore_index=True)


def subject_codes(subjects):
    """Subjects numbered in order of first appearance (gaitfit's order)."""
    codes, names = pd.factorize(subjects)
    return codes, list(names)


def cr1(x, e, g, k=None):
    """CR1 covariance (statsmodels' definition) from a dense design."""
    n, p = x.shape
    k = p if k is None else k
    m = np.linalg.inv(x.T @ x)
    G = g.max() + 1
    meat = np.zeros((p, p))
    for c in range(G):
        u = x[g == c].T @ e[g == c]
        meat += np.outer(u, u)
    return G / (G - 1) * (n - 1) / (n - k) * m @ meat @ m


def cr2(x, e, g):
    """CR2 (Bell–McCaffrey) covariance and the adjustment matrices, dense: A_g = (I − H_gg)^{-1/2}
    by an eigendecomposition of the n_g × n_g block (Moore–Penrose on unit leverages)."""
    n, p = x.shape
    m = np.linalg.inv(x.T @ x)
    G = g.max() + 1
    meat = np.zeros((p, p))
    adj = []
    for c in range(G):
        idx = np.where(g == c)[0]
        xg = x[idx]
        h = xg @ m @ xg.T
        lam, q = np.linalg.eigh(np.eye(len(idx)) - h)
        d = np.array([l ** -0.5 if l > 1e-10 else 0.0 for l in lam])
        ag = (q * d) @ q.T
        u = xg.T @ ag @ e[idx]
        meat += np.outer(u, u)
        adj.append((idx, ag))
    return m @ meat @ m, adj, m


def bm_df(x, g, adj, m, ell):
    """Bell–McCaffrey degrees of freedom of contrast `ell`: (Σλ)²/Σλ², λ = eig(GᵀG) with the
    columns of G = (I − H)[:, g] A_g X_g M ℓ (Imbens & Kolesár 2016, eq. 10), dense."""
    n = x.shape[0]
    imh = np.eye(n) - x @ m @ x.T
    cols = []
    for idx, ag in adj:
        pg = ag @ x[idx] @ m @ ell
        cols.append(imh[:, idx] @ pg)
    gm = np.array(cols).T
    lam = np.linalg.eigvalsh(gm.T @ gm)
    return lam.sum() ** 2 / (lam ** 2).sum()


def rows(df, gait, cols):
    """The unflagged rows of one gait with every column in `cols` present, renumbered."""
    d = df[(df.gait == gait) & (~df.flagged)]
    return d.dropna(subset=cols).reset_index(drop=True)


def write_json(out, path, preview=None):
    """Writes `out` to `path` (one-space indent, trailing newline) and prints it (the first
    `preview` characters when given)."""
    import json

    with open(path, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")
    text = json.dumps(out, indent=1)
    print(text if preview is None else text[:preview])


def walking_designs(df):
    """The two walking relations' designs as gaitfit builds them, in this order:
    (relation id, X, y, subject) for walk-tds-sf (DS % on 1, sf in steps/min) and walk-sl-sf
    (sl on sf·h, no intercept)."""
    d = rows(df, "walk", ["sf", "ds_pct"])
    yield ("walk-tds-sf", np.column_stack([np.ones(len(d)), d.sf.values * 60.0]),
           d.ds_pct.values, d.subject.values)
    d = rows(df, "walk", ["sl", "sf", "h"])
    yield ("walk-sl-sf", (d.sf.values * 60.0 * d.h.values)[:, None], d.sl.values,
           d.subject.values)
