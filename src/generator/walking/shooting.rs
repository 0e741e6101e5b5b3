//! The root finding that turns step constraints into forces and torques (§4.1): each phase is
//! simulated repeatedly, varying its force parameter(s), until it ends on its final conditions at
//! exactly its duration.
//!
//! As in the paper, a bracketing stage finds a reasonable approximation and a secant stage refines
//! it (the secant "converges fast, but needs a good first approximation"):
//! - one unknown ([`solve_1d`]): the bracket is found by expanding secant steps from the starting
//!   value (the previous step's profile), then refined by the Illinois variant of regula falsi — a
//!   secant iteration kept inside the bracket, with bisection whenever it stalls;
//! - two unknowns (the stance phase's `F_θ1` and `F_w`, [`solve_2d`]): Broyden's method (the
//!   multidimensional secant method) from a finite-difference Jacobian, with step halving; if it
//!   does not converge, alternating one-dimensional bracketed solves supply a better start.
//!
//! Every evaluation of the residual is one simulation of the phase; the counts are reported per
//! phase ([`Solved::iterations`]).

/// Result of a shooting solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solved<const N: usize> {
    /// The force parameters found.
    pub x: [f64; N],
    /// Residuals at `x`.
    pub residual: [f64; N],
    /// Number of phase simulations used.
    pub iterations: usize,
}

/// Solves `f(x) = 0` from `x0` with a first trial step `dx`, to `|f| ≤ tol`, with at most
/// `max_evals` evaluations of `f`.
pub fn solve_1d<F: FnMut(f64) -> f64>(
    mut f: F,
    x0: f64,
    dx: f64,
    tol: f64,
    max_evals: usize,
) -> Result<Solved<1>, String> {
    let mut evals = 0usize;
    let mut eval = |x: f64, evals: &mut usize| {
        *evals += 1;
        f(x)
    };
    let (mut a, mut fa) = (x0, eval(x0, &mut evals));
    let done = |x: f64, r: f64, n: usize| {
        Ok(Solved {
            x: [x],
            residual: [r],
            iterations: n,
        })
    };
    if fa.abs() <= tol {
        return done(a, fa, evals);
    }
    if !fa.is_finite() {
        return Err(format!("residual not finite at the start value {x0}"));
    }
    let (mut b, mut fb) = (x0 + dx, eval(x0 + dx, &mut evals));
    // Bracketing by expanding secant steps.
    while fa.signum() == fb.signum() || !fb.is_finite() {
        if fb.abs() <= tol {
            return done(b, fb, evals);
        }
        if evals >= max_evals {
            return Err(format!(
                "no sign change found after {evals} simulations (last value {b}, residual {fb})"
            ));
        }
        if !fb.is_finite() {
            // Step back toward the good point.
            b = 0.5 * (a + b);
            fb = eval(b, &mut evals);
            continue;
        }
        if fb.abs() > fa.abs() {
            std::mem::swap(&mut a, &mut b);
            std::mem::swap(&mut fa, &mut fb);
        }
        let d = b - a;
        let secant = if fb != fa {
            -fb * d / (fb - fa)
        } else {
            2.0 * d
        };
        // Continue beyond b, between half and eight times the last step.
        let step = d.signum() * secant.abs().clamp(0.5 * d.abs(), 8.0 * d.abs());
        a = b;
        fa = fb;
        b += step;
        fb = eval(b, &mut evals);
    }
    if fb.abs() <= tol {
        return done(b, fb, evals);
    }
    // Illinois on the bracket [a, b].
    let mut side = 0i8;
    let mut last_width = (b - a).abs();
    while evals < max_evals {
        let mut c = (a * fb - b * fa) / (fb - fa);
        let width = (b - a).abs();
        if !(c.is_finite()) || width > 0.7 * last_width && side != 0 && evals % 3 == 0 {
            c = 0.5 * (a + b);
        }
        last_width = width;
        let fc = eval(c, &mut evals);
        if fc.abs() <= tol {
            return done(c, fc, evals);
        }
        if (b - a).abs() < 1e-10 * (1.0 + c.abs()) {
            // The bracket has collapsed onto a jump of the residual (no exact root in floating
            // point): return the better end; the caller reports the remaining error.
            let (x, r) = if fa.abs() < fb.abs() {
                (a, fa)
            } else {
                (b, fb)
            };
            let (x, r) = if fc.abs() < r.abs() { (c, fc) } else { (x, r) };
            return done(x, r, evals);
        }
        if fc.signum() == fb.signum() {
            b = c;
            fb = fc;
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        } else {
            a = c;
            fa = fc;
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        }
    }
    Err(format!(
        "no convergence in {max_evals} simulations (bracket [{a}, {b}])"
    ))
}

/// Solves `f(x) = 0` for two unknowns from `x0` (trial steps `dx` for the finite-difference
/// Jacobian), to `|f_i| ≤ tol_i`, with at most `max_evals` evaluations.
pub fn solve_2d<F: FnMut([f64; 2]) -> [f64; 2]>(
    mut f: F,
    x0: [f64; 2],
    dx: [f64; 2],
    tol: [f64; 2],
    max_evals: usize,
) -> Result<Solved<2>, String> {
    let mut evals = 0usize;
    let ok = |r: &[f64; 2]| r[0].abs() <= tol[0] && r[1].abs() <= tol[1];
    let norm = |r: &[f64; 2]| (r[0] / tol[0]).hypot(r[1] / tol[1]);
    let mut x = x0;
    let mut r = f(x);
    evals += 1;
    if ok(&r) {
        return Ok(Solved {
            x,
            residual: r,
            iterations: evals,
        });
    }
    for attempt in 0..2 {
        // Finite-difference Jacobian.
        let mut jac = [[0.0; 2]; 2];
        for j in 0..2 {
            let mut xp = x;
            xp[j] += dx[j];
            let rp = f(xp);
            evals += 1;
            for i in 0..2 {
                jac[i][j] = (rp[i] - r[i]) / dx[j];
            }
        }
        let mut stalled = false;
        while evals < max_evals {
            let det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0];
            if det == 0.0 || !det.is_finite() {
                stalled = true;
                break;
            }
            let step = [
                -(r[0] * jac[1][1] - jac[0][1] * r[1]) / det,
                -(jac[0][0] * r[1] - jac[1][0] * r[0]) / det,
            ];
            let mut lambda = 1.0;
            let mut accepted = None;
            for _ in 0..6 {
                let xn = [x[0] + lambda * step[0], x[1] + lambda * step[1]];
                let rn = f(xn);
                evals += 1;
                if rn[0].is_finite() && rn[1].is_finite() && norm(&rn) < norm(&r) {
                    accepted = Some((xn, rn));
                    break;
                }
                lambda *= 0.5;
                if evals >= max_evals {
                    break;
                }
            }
            let Some((xn, rn)) = accepted else {
                stalled = true;
                break;
            };
            // Broyden's ("good") rank-one update.
            let s = [xn[0] - x[0], xn[1] - x[1]];
            let y = [rn[0] - r[0], rn[1] - r[1]];
            let ss = s[0] * s[0] + s[1] * s[1];
            if ss > 0.0 {
                for i in 0..2 {
                    let js = jac[i][0] * s[0] + jac[i][1] * s[1];
                    for j in 0..2 {
                        jac[i][j] += (y[i] - js) * s[j] / ss;
                    }
                }
            }
            x = xn;
            r = rn;
            if ok(&r) {
                return Ok(Solved {
                    x,
                    residual: r,
                    iterations: evals,
                });
            }
        }
        if !stalled || attempt == 1 {
            break;
        }
        // Alternating one-dimensional bracketed solves give a better start.
        for _ in 0..3 {
            for j in 0..2 {
                let mut g = |v: f64| {
                    let mut xx = x;
                    xx[j] = v;
                    f(xx)[j]
                };
                let budget = max_evals.saturating_sub(evals).clamp(1, 40);
                match solve_1d(&mut g, x[j], dx[j] * 10.0, tol[j], budget) {
                    Ok(s) => {
                        x[j] = s.x[0];
                        evals += s.iterations;
                    }
                    Err(e) => {
                        return Err(format!(
                            "no convergence in {evals} simulations (unknown {}: {e})",
                            j + 1
                        ))
                    }
                }
            }
        }
        r = f(x);
        evals += 1;
        if ok(&r) {
            return Ok(Solved {
                x,
                residual: r,
                iterations: evals,
            });
        }
    }
    Err(format!(
        "no convergence in {evals} simulations (residuals {:.3e}, {:.3e})",
        r[0], r[1]
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_dimensional_brackets_then_converges() {
        // A monotone, curved residual with the root far from the start.
        let s = solve_1d(|x| x.exp() - 50.0, 0.0, 0.1, 1e-12, 60).unwrap();
        assert!((s.x[0] - 50f64.ln()).abs() < 1e-12);
        assert!(s.iterations < 25, "{}", s.iterations);
        // Started near the root (a carried-over profile): a handful of simulations.
        let s = solve_1d(|x| x.exp() - 50.0, 3.9, 0.01, 1e-12, 60).unwrap();
        assert!(s.iterations <= 8, "{}", s.iterations);
        // Decreasing residual works too.
        let s = solve_1d(|x| 2.0 - x * x * x, -1.0, 0.5, 1e-12, 60).unwrap();
        assert!((s.x[0] - 2f64.cbrt()).abs() < 1e-10);
    }

    #[test]
    fn two_dimensional_secant_solves_a_coupled_system() {
        let f = |x: [f64; 2]| {
            [
                x[0] + 0.3 * x[1].sin() - 1.0,
                x[1] + 0.2 * x[0] * x[0] - 2.0,
            ]
        };
        let s = solve_2d(f, [0.0, 0.0], [1e-3, 1e-3], [1e-12, 1e-12], 50).unwrap();
        let r = f(s.x);
        assert!(r[0].abs() <= 1e-12 && r[1].abs() <= 1e-12);
        assert!(s.iterations < 20, "{}", s.iterations);
    }

    #[test]
    fn failure_is_reported() {
        assert!(solve_1d(|x| x * x + 1.0, 0.0, 0.1, 1e-9, 30).is_err());
    }
}
