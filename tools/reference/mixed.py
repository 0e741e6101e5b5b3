"""Reference random-intercept REML fits for `tests/reference_inference.rs` (issue 18, Build 1:
`gaitfit fit --random-subject`).

Data: the bundled trials tables `data/*.csv` (committed), read as gaitfit reads them
(`common.py`). Source: statsmodels `MixedLM(y, X, groups=subject).fit(reml=True)` (a random
intercept per subject, Gaussian), its optimiser run to a tight gradient (method='cg', then
'bfgs', 'lbfgs', gtol 1e-10; 'bfgs' first stopped short of the optimum on walk-sl-sf, REML llf
411.2833 vs 411.2879, k 0.0031706 vs 0.0031694, which a numpy profile of the REML likelihood
over sigma_u^2/sigma_e^2 confirms) so that the comparison measures the estimator, not where an iteration
stopped. Reported: fixed effects, the group variance (`cov_re`), the residual variance
(`scale`) and the REML log-likelihood (`llf`).

Standard errors: the usual REML ones (lme4, nlme, SAS PROC MIXED) are sqrt(diag((XᵀV̂⁻¹X)⁻¹))
with V̂ the fitted covariance; they are computed here densely (numpy, V̂ built per subject from
statsmodels' variance estimates) as `se`. statsmodels' own `bse_fe` inverts the Hessian of
its likelihood over the fixed effects and the variance parameters jointly, whose cross terms
are not zero at a finite sample, so it differs (0.01 % on walk-tds-sf, 2 % on walk-sl-sf);
it is recorded as `se_statsmodels_joint_hessian` for comparison, not tested against. Nothing
here reads gaitfit's output.

Run: /work/venv/bin/python tools/reference/mixed.py  (writes tools/reference/mixed.json)
"""
import os
import warnings

import numpy as np
import statsmodels
import statsmodels.api as sm

from common import bundled, walking_designs, write_json

OUT = os.path.join(os.path.dirname(__file__), "mixed.json")


def mixed(x, y, groups):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m = sm.MixedLM(y, x, groups=groups)
        r = m.fit(reml=True, method=["cg", "bfgs", "lbfgs"], gtol=1e-10, maxiter=5000)
    cov_re = float(np.asarray(r.cov_re)[0, 0])
    xvx = np.zeros((x.shape[1], x.shape[1]))
    for g in np.unique(groups):
        xg = x[groups == g]
        v = r.scale * np.eye(len(xg)) + cov_re * np.ones((len(xg), len(xg)))
        xvx += xg.T @ np.linalg.solve(v, xg)
    se = np.sqrt(np.diag(np.linalg.inv(xvx)))
    return {
        "n": int(len(y)),
        "subjects": int(len(np.unique(groups))),
        "coef": [float(v) for v in r.fe_params],
        "se": [float(v) for v in se],
        "se_statsmodels_joint_hessian": [float(v) for v in r.bse_fe],
        "subject_var": cov_re,
        "residual_var": float(r.scale),
        "reml_llf": float(r.llf),
        "converged": bool(r.converged),
    }


def main():
    df = bundled()
    out = {
        "source": "statsmodels MixedLM(y, X, groups=subject).fit(reml=True, "
        "method=['cg', 'bfgs', 'lbfgs'], gtol=1e-10); se = sqrt(diag((X'V^-1 X)^-1)) at its "
        "estimates (dense numpy); data/*.csv",
        "script": "tools/reference/mixed.py",
        "versions": {"statsmodels": statsmodels.__version__, "numpy": np.__version__},
    }
    for name, x, y, subject in walking_designs(df):
        out[name] = mixed(x, y, subject)
    write_json(out, OUT)


if __name__ == "__main__":
    main()
