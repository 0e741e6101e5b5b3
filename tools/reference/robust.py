"""Reference Huber M-estimates for `tests/reference_inference.rs` (issue 18, Build 4).

Data: the bundled trials tables `data/*.csv` (committed), read as gaitfit reads them
(`common.py`). Source: statsmodels `RLM(y, X, M=HuberT(t=1.345)).fit(scale_est='mad',
cov='H1')` — its defaults, with the IRLS run to a fixed point (conv='coefs', tol=1e-13) so that
the comparison measures the covariance formula, not where two iterations stopped.

Clustered by subject (`se_cr1`): statsmodels RLM has no cluster-robust covariance, so it is
computed here in numpy from RLM's own fit — its residuals `resid`, scale `scale`, and its norm's
`psi` and `psi_deriv` at r = resid/scale — as the sandwich of the estimating equations
Σ ψ(rᵢ) xᵢ = 0 summed by subject: s²·B⁻¹(Σ_g u_g u_gᵀ)B⁻¹·G/(G − 1)·(n − 1)/(n − p) with
B = Σ ψ'(rᵢ) xᵢxᵢᵀ and u_g = Σ_(i in g) ψ(rᵢ) xᵢ (statsmodels' CR1 factor for OLS clusters).
Nothing here reads gaitfit's output.

Run: /work/venv/bin/python tools/reference/robust.py  (writes tools/reference/robust.json)
"""
import os

import numpy as np
import statsmodels
import statsmodels.api as sm

from common import bundled, subject_codes, walking_designs, write_json

OUT = os.path.join(os.path.dirname(__file__), "robust.json")


def rlm(x, y, subjects):
    norm = sm.robust.norms.HuberT(t=1.345)
    r = sm.RLM(y, x, M=norm).fit(
        scale_est="mad", cov="H1", conv="coefs", tol=1e-13, maxiter=1000
    )
    z = r.resid / r.scale
    psi, dpsi = norm.psi(z), norm.psi_deriv(z)
    bread = (x * dpsi[:, None]).T @ x
    codes, _ = subject_codes(subjects)
    g = codes.max() + 1
    u = np.zeros((g, x.shape[1]))
    np.add.at(u, codes, x * psi[:, None])
    bi = np.linalg.inv(bread)
    n, p = x.shape
    cov = r.scale ** 2 * bi @ (u.T @ u) @ bi * g / (g - 1) * (n - 1) / (n - p)
    return {
        "clusters": int(g),
        "se_cr1": [float(v) for v in np.sqrt(np.diag(cov))],
        "n": int(len(y)),
        "coef": [float(v) for v in r.params],
        "se_h1": [float(v) for v in r.bse],
        "scale": float(r.scale),
        "rows_downweighted": int(np.sum(r.weights < 1.0)),
        "iterations": int(r.fit_history["iteration"]),
    }


def main():
    df = bundled()
    out = {
        "source": "statsmodels RLM, HuberT(t=1.345), scale_est='mad', cov='H1' (defaults), "
        "conv='coefs', tol=1e-13; se_cr1: clustered M-sandwich in numpy from RLM's resid, scale, "
        "psi and psi_deriv; data/*.csv",
        "script": "tools/reference/robust.py",
        "versions": {"statsmodels": statsmodels.__version__, "numpy": np.__version__},
    }
    for name, x, y, subject in walking_designs(df):
        out[name] = rlm(x, y, subject)
    write_json(out, OUT)


if __name__ == "__main__":
    main()
