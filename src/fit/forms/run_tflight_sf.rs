//! The fit form of `run-tflight-sf` and `run-tflight-sf-continuous` (running 1996, eqs. 4–5).
//!
//! The cubic in sf ≈ 200 is badly conditioned in the raw basis, so fits are solved in centred,
//! scaled bases u = (sf − m1)/s1 and w = (sf − m2)/s2 and mapped back to raw coefficients; the
//! continuous variant fits with quadratic(k1) = cubic(k1) built into the basis (q0 determined by
//! the others). The knots k1, k2 are profiled with sorted prefix sums of the moments of sf.
use super::{
    sorted_keys, DistinctKeys, FeatureSums, Form, KeyRange, KeyScale, KeySums, LinearMap,
    NormalEquations, Plan, SortedProfile,
};
use crate::relations::run_tflight_sf::{cubic, quad, tflight};
use crate::relations::{Continuity, Inputs, Observation, Relation, RunTflightSf};
use nalgebra::{DMatrix, DVector};

/// The form of [`RunTflightSf`], per variant.
#[derive(Debug, Clone, Copy)]
pub struct TflightForm {
    /// Free pieces or continuous at k1.
    pub continuity: Continuity,
}

/// The form of `run-tflight-sf` (the paper's free pieces).
pub static FREE: TflightForm = TflightForm {
    continuity: Continuity::Free,
};
/// The form of `run-tflight-sf-continuous`.
pub static CONTINUOUS: TflightForm = TflightForm {
    continuity: Continuity::Continuous,
};

/// The published coefficients `[q0, q1, q2, c0, c1, c2, c3, k1, k2]` (the plan's knots).
fn published() -> Vec<f64> {
    RunTflightSf::published().coefficients().to_vec()
}

/// Minimum number of distinct step frequencies a piece needs to be fitted.
const MIN_DISTINCT: usize = 5;

/// The centring of the fitting bases and which blocks are free.
struct Layout {
    qfree: bool,
    cfree: bool,
    continuous: bool,
    m1: f64,
    s1: f64,
    m2: f64,
    s2: f64,
}

impl Layout {
    fn new(p: &[f64], free: &[bool], continuity: Continuity) -> Layout {
        let k1 = p[7];
        // k2 = +∞ (the model without a plateau, tested against) would make the centring of the
        // cubic's basis infinite and every basis value NaN; any finite centring spans the same
        // cubics, so use the published gap.
        let k2 = if p[8].is_finite() { p[8] } else { k1 + 50.0 };
        let s2 = ((k2 - k1) / 2.0).abs().max(1.0);
        Layout {
            qfree: free[0],
            cfree: free[3],
            continuous: continuity == Continuity::Continuous,
            m1: k1 - 25.0,
            s1: 25.0,
            m2: (k1 + k2) / 2.0,
            s2,
        }
    }
    fn nb(&self) -> usize {
        match (self.qfree, self.cfree, self.continuous) {
            (true, true, false) => 7,
            (true, true, true) => 6,
            (false, true, false) => 4,
            (false, true, true) => 3,
            (true, false, false) => 3,
            (true, false, true) => 2,
            (false, false, _) => 0,
        }
    }
}

/// Raw coefficients of Σ βᵢ((x − m)/s)ⁱ: the matrix T with raw = T·β.
fn centred_to_raw(deg: usize, m: f64, s: f64) -> DMatrix<f64> {
    let mut t = DMatrix::zeros(deg + 1, deg + 1);
    for i in 0..=deg {
        let si = s.powi(-(i as i32));
        let mut binom = 1.0;
        for k in 0..=i {
            // C(i, k) (−m)^(i−k) / s^i
            t[(k, i)] = si * binom * (-m).powi((i - k) as i32);
            binom = binom * (i - k) as f64 / (k + 1) as f64;
        }
    }
    t
}

impl Form for TflightForm {
    fn plan(&self, _rel: &dyn Relation, obs: &[Observation]) -> Plan {
        self.plan_sorted(DistinctKeys::new(&sorted_keys(self, obs)))
    }

    fn sorted_profile(&self) -> Option<&dyn SortedProfile> {
        Some(self)
    }

    fn breakpoint_null(&self, i: usize) -> Option<f64> {
        (i == 8).then_some(f64::INFINITY)
    }

    fn basis_len(&self, _rel: &dyn Relation, free: &[bool]) -> usize {
        Layout::new(&published(), free, self.continuity).nb()
    }

    fn basis(
        &self,
        _rel: &dyn Relation,
        p: &[f64],
        free: &[bool],
        x: &Inputs,
        phi: &mut [f64],
    ) -> f64 {
        let l = Layout::new(p, free, self.continuity);
        let sf = x[0];
        let (k1, k2) = (p[7], p[8]);
        let below = sf < k1;
        let w = |s: f64| (s - l.m2) / l.s2;
        let u = |s: f64| (s - l.m1) / l.s1;
        let (u1, w1) = (u(k1), w(k1));
        let nb = l.nb();
        phi[..nb].fill(0.0);
        match (l.qfree, l.cfree, l.continuous) {
            (true, true, false) => {
                if below {
                    let uu = u(sf);
                    phi[0] = 1.0;
                    phi[1] = uu;
                    phi[2] = uu * uu;
                } else {
                    let ww = w(sf.min(k2));
                    phi[3] = 1.0;
                    phi[4] = ww;
                    phi[5] = ww * ww;
                    phi[6] = ww * ww * ww;
                }
                0.0
            }
            (true, true, true) => {
                if below {
                    let uu = u(sf);
                    phi[0] = 1.0;
                    phi[1] = w1;
                    phi[2] = w1 * w1;
                    phi[3] = w1 * w1 * w1;
                    phi[4] = uu - u1;
                    phi[5] = uu * uu - u1 * u1;
                } else {
                    let ww = w(sf.min(k2));
                    phi[0] = 1.0;
                    phi[1] = ww;
                    phi[2] = ww * ww;
                    phi[3] = ww * ww * ww;
                }
                0.0
            }
            (false, true, cont) => {
                if below {
                    quad(p, sf)
                } else {
                    let ww = w(sf.min(k2));
                    if cont {
                        phi[0] = ww - w1;
                        phi[1] = ww * ww - w1 * w1;
                        phi[2] = ww * ww * ww - w1 * w1 * w1;
                        quad(p, k1)
                    } else {
                        phi[0] = 1.0;
                        phi[1] = ww;
                        phi[2] = ww * ww;
                        phi[3] = ww * ww * ww;
                        0.0
                    }
                }
            }
            (true, false, cont) => {
                if below {
                    let uu = u(sf);
                    if cont {
                        phi[0] = uu - u1;
                        phi[1] = uu * uu - u1 * u1;
                        cubic(p, k1)
                    } else {
                        phi[0] = 1.0;
                        phi[1] = uu;
                        phi[2] = uu * uu;
                        0.0
                    }
                } else {
                    cubic(p, sf.min(k2))
                }
            }
            (false, false, _) => tflight(p, sf),
        }
    }

    fn basis_to_params(&self, _rel: &dyn Relation, p: &[f64], free: &[bool]) -> LinearMap {
        let l = Layout::new(p, free, self.continuity);
        let nb = l.nb();
        let (k1, _) = (p[7], p[8]);
        let u1 = (k1 - l.m1) / l.s1;
        let w1 = (k1 - l.m2) / l.s2;
        // Centred-basis coefficients of each piece as affine functions of β.
        let mut aq = DMatrix::zeros(3, nb);
        let mut bq = DVector::zeros(3);
        let mut ac = DMatrix::zeros(4, nb);
        let mut bc = DVector::zeros(4);
        let t1 = centred_to_raw(2, l.m1, l.s1);
        let t2 = centred_to_raw(3, l.m2, l.s2);
        let mut q_held = false;
        let mut c_held = false;
        match (l.qfree, l.cfree, l.continuous) {
            (true, true, false) => {
                for i in 0..3 {
                    aq[(i, i)] = 1.0;
                }
                for i in 0..4 {
                    ac[(i, 3 + i)] = 1.0;
                }
            }
            (true, true, true) => {
                for i in 0..4 {
                    ac[(i, i)] = 1.0;
                    aq[(0, i)] = w1.powi(i as i32);
                }
                aq[(0, 4)] = -u1;
                aq[(0, 5)] = -u1 * u1;
                aq[(1, 4)] = 1.0;
                aq[(2, 5)] = 1.0;
            }
            (false, true, cont) => {
                q_held = true;
                if cont {
                    bc[0] = quad(p, k1);
                    for i in 1..4 {
                        ac[(0, i - 1)] = -w1.powi(i as i32);
                        ac[(i, i - 1)] = 1.0;
                    }
                } else {
                    for i in 0..4 {
                        ac[(i, i)] = 1.0;
                    }
                }
            }
            (true, false, cont) => {
                c_held = true;
                if cont {
                    bq[0] = cubic(p, k1);
                    aq[(0, 0)] = -u1;
                    aq[(0, 1)] = -u1 * u1;
                    aq[(1, 0)] = 1.0;
                    aq[(2, 1)] = 1.0;
                } else {
                    for i in 0..3 {
                        aq[(i, i)] = 1.0;
                    }
                }
            }
            (false, false, _) => {
                q_held = true;
                c_held = true;
            }
        }
        let mut map = DMatrix::zeros(7, nb);
        let mut shift = DVector::zeros(7);
        if q_held {
            for i in 0..3 {
                shift[i] = p[i];
            }
        } else {
            map.rows_mut(0, 3).copy_from(&(&t1 * &aq));
            shift.rows_mut(0, 3).copy_from(&(&t1 * &bq));
        }
        if c_held {
            for i in 0..4 {
                shift[3 + i] = p[3 + i];
            }
        } else {
            map.rows_mut(3, 4).copy_from(&(&t2 * &ac));
            shift.rows_mut(3, 4).copy_from(&(&t2 * &bc));
        }
        LinearMap { map, shift }
    }

    fn subject_column(&self, _rel: &dyn Relation, _free: &[bool]) -> Option<usize> {
        None
    }
}

/// A polynomial in ω = (sf − c)/half_width (c: the piece's centre) of degree ≤ 3, coefficients
/// of 1, ω, ω², ω³: within a piece, every basis column and offset of [`Form::basis`] is one.
type Poly = [f64; 4];

fn pc(c: f64) -> Poly {
    [c, 0.0, 0.0, 0.0]
}
fn padd(a: &Poly, b: &Poly) -> Poly {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2], a[3] + b[3]]
}
fn psub(a: &Poly, b: &Poly) -> Poly {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2], a[3] - b[3]]
}
fn pscale(a: &Poly, c: f64) -> Poly {
    [a[0] * c, a[1] * c, a[2] * c, a[3] * c]
}
/// Product, truncated at degree 3 (the products used here never exceed it).
fn pmul(a: &Poly, b: &Poly) -> Poly {
    let mut r = [0.0; 4];
    for i in 0..4 {
        for j in 0..4 - i {
            r[i + j] += a[i] * b[j];
        }
    }
    r
}
fn quad_poly(p: &[f64], s: &Poly) -> Poly {
    padd(
        &padd(&pc(p[0]), &pscale(s, p[1])),
        &pscale(&pmul(s, s), p[2]),
    )
}
fn cubic_poly(p: &[f64], s: &Poly) -> Poly {
    let s2 = pmul(s, s);
    padd(
        &padd(&pc(p[3]), &pscale(s, p[4])),
        &padd(&pscale(&s2, p[5]), &pscale(&pmul(&s2, s), p[6])),
    )
}

/// Feature slots of the sorted profile: ω⁰…ω⁶, ω⁰y…ω³y, y².
mod feat {
    pub const Y: usize = 7;
    pub const YY: usize = 11;
    pub const N: usize = 12;
}

impl TflightForm {
    /// [`SortedProfile::normal_equations`]; with `tied_plateau` false the rows above k2 are
    /// left out (for [`SortedProfile::window_relaxation`]).
    fn equations(
        &self,
        p: &[f64],
        free: &[bool],
        scale: &KeyScale,
        sums: &dyn KeySums,
        tied_plateau: bool,
    ) -> NormalEquations {
        let l = Layout::new(p, free, self.continuity);
        let nb = l.nb();
        let (k1, k2) = (p[7], p[8]);
        let mut ne = NormalEquations::zeros(nb);
        let h = scale.half_width;
        // Each piece's sums are taken about the middle of its rows' key range, so the
        // polynomials below are well conditioned however narrow the piece.
        let (dlo, dhi) = (scale.centre - h, scale.centre + h);
        let centre = |a: f64, b: f64| {
            let (a, b) = (a.max(dlo), b.min(dhi));
            if a <= b {
                0.5 * (a + b)
            } else {
                scale.centre
            }
        };
        let sf = |c: f64| [c, h, 0.0, 0.0];
        let u = |c: f64| [(c - l.m1) / l.s1, h / l.s1, 0.0, 0.0];
        let w = |c: f64| [(c - l.m2) / l.s2, h / l.s2, 0.0, 0.0];
        // Pieces: sf < k1 quadratic; k1 ≤ sf ≤ k2 cubic; above both, the cubic at k2.
        let cb = centre(f64::NEG_INFINITY, k1);
        let below = sums.range(KeyRange::below(k1, false), cb);
        let mut cols = [[0.0; 4]; 7];
        let off = self.below_polys(&l, p, &u(cb), &sf(cb), &mut cols);
        add_piece(&mut ne, &below, &cols[..nb], &off);
        let plateau = if k1 <= k2 {
            let cm = centre(k1, k2);
            let middle = sums.range(KeyRange::closed(k1, k2), cm);
            let mut cols = [[0.0; 4]; 7];
            let off = self.upper_polys(&l, p, &w(cm), &sf(cm), &mut cols);
            add_piece(&mut ne, &middle, &cols[..nb], &off);
            KeyRange::above(k2, false)
        } else {
            KeyRange::above(k1, true)
        };
        let plateau = if tied_plateau {
            sums.range(plateau, scale.centre)
        } else {
            [0.0; super::MAX_PROFILE_FEATURES]
        };
        if plateau[0] != 0.0 {
            let mut cols = [[0.0; 4]; 7];
            let wk = (k2 - l.m2) / l.s2;
            let off = self.upper_polys(&l, p, &pc(wk), &pc(k2), &mut cols);
            add_piece(&mut ne, &plateau, &cols[..nb], &off);
        }
        ne
    }

    /// The basis columns and offset of the quadratic piece (sf < k1) as polynomials, given u and
    /// sf as polynomials in ω (mirrors [`Form::basis`]).
    fn below_polys(&self, l: &Layout, p: &[f64], u: &Poly, s: &Poly, out: &mut [Poly; 7]) -> Poly {
        let k1 = p[7];
        let u1 = (k1 - l.m1) / l.s1;
        let w1 = (k1 - l.m2) / l.s2;
        let uu = pmul(u, u);
        match (l.qfree, l.cfree, l.continuous) {
            (true, true, false) => {
                out[0] = pc(1.0);
                out[1] = *u;
                out[2] = uu;
                pc(0.0)
            }
            (true, true, true) => {
                out[0] = pc(1.0);
                out[1] = pc(w1);
                out[2] = pc(w1 * w1);
                out[3] = pc(w1 * w1 * w1);
                out[4] = psub(u, &pc(u1));
                out[5] = psub(&uu, &pc(u1 * u1));
                pc(0.0)
            }
            (true, false, true) => {
                out[0] = psub(u, &pc(u1));
                out[1] = psub(&uu, &pc(u1 * u1));
                pc(cubic(p, k1))
            }
            (true, false, false) => {
                out[0] = pc(1.0);
                out[1] = *u;
                out[2] = uu;
                pc(0.0)
            }
            (false, _, _) => quad_poly(p, s),
        }
    }

    /// The same for the cubic piece, given w and s = min(sf, k2) as polynomials in ω.
    fn upper_polys(&self, l: &Layout, p: &[f64], w: &Poly, s: &Poly, out: &mut [Poly; 7]) -> Poly {
        let k1 = p[7];
        let w1 = (k1 - l.m2) / l.s2;
        let ww = pmul(w, w);
        let www = pmul(&ww, w);
        match (l.qfree, l.cfree, l.continuous) {
            (true, true, false) => {
                out[3] = pc(1.0);
                out[4] = *w;
                out[5] = ww;
                out[6] = www;
                pc(0.0)
            }
            (true, true, true) => {
                out[0] = pc(1.0);
                out[1] = *w;
                out[2] = ww;
                out[3] = www;
                pc(0.0)
            }
            (false, true, true) => {
                out[0] = psub(w, &pc(w1));
                out[1] = psub(&ww, &pc(w1 * w1));
                out[2] = psub(&www, &pc(w1 * w1 * w1));
                pc(quad(p, k1))
            }
            (false, true, false) => {
                out[0] = pc(1.0);
                out[1] = *w;
                out[2] = ww;
                out[3] = www;
                pc(0.0)
            }
            (_, false, _) => cubic_poly(p, s),
        }
    }
}

/// Adds the normal equations of the rows summarised by `f` (a piece) whose basis columns and
/// offset are the polynomials `cols`, `off` in ω.
fn add_piece(ne: &mut NormalEquations, f: &FeatureSums, cols: &[Poly], off: &Poly) {
    if f[0] == 0.0 {
        // No rows (their polynomials may not even be finite, e.g. at k2 = +∞).
        return;
    }
    let m = |i: usize, j: usize| f[i + j];
    let my = |i: usize| f[feat::Y + i];
    let mv = |a: &Poly| -> Poly {
        let mut r = [0.0; 4];
        for (i, ri) in r.iter_mut().enumerate() {
            *ri = (0..4).map(|j| m(i, j) * a[j]).sum();
        }
        r
    };
    let dot = |a: &Poly, b: &Poly| a.iter().zip(b).map(|(a, b)| a * b).sum::<f64>();
    let mo = mv(off);
    let ymy: Poly = [my(0), my(1), my(2), my(3)];
    let nb = ne.nb;
    for a in 0..nb {
        if cols[a] == [0.0; 4] {
            continue;
        }
        let ma = mv(&cols[a]);
        ne.xty[a] += dot(&cols[a], &ymy) - dot(&cols[a], &mo);
        for (b, cb) in cols.iter().enumerate().take(nb) {
            if *cb != [0.0; 4] {
                ne.xtx[a * nb + b] += dot(cb, &ma);
            }
        }
    }
    ne.yty += f[feat::YY] - 2.0 * dot(off, &ymy) + dot(off, &mo);
}

impl SortedProfile for TflightForm {
    fn key(&self, x: &[f64]) -> f64 {
        x[0]
    }
    fn n_features(&self) -> usize {
        feat::N
    }
    fn features(&self, scale: &KeyScale, centre: f64, o: &Observation, out: &mut [f64]) {
        let w = scale.omega(o.x[0], centre);
        let mut pw = 1.0;
        for v in out.iter_mut().take(7) {
            *v = pw;
            pw *= w;
        }
        let y = o.y;
        out[feat::Y] = y;
        out[feat::Y + 1] = w * y;
        out[feat::Y + 2] = w * w * y;
        out[feat::Y + 3] = w * w * w * y;
        out[feat::YY] = y * y;
    }
    fn shift(&self, scale: &KeyScale, f: &mut FeatureSums, from: f64, to: f64) {
        // (sf − to)/h = ω + d with ω = (sf − from)/h: binomial expansion of the moments.
        let d = (from - to) / scale.half_width;
        if d == 0.0 {
            return;
        }
        let mut dp = [1.0; 7];
        for k in 1..7 {
            dp[k] = dp[k - 1] * d;
        }
        let shifted = |m: &[f64], k: usize| -> f64 {
            let mut binom = 1.0;
            let mut acc = 0.0;
            for j in (0..=k).rev() {
                // C(k, j) for j = k, k − 1, …: multiply by j/(k − j + 1).
                acc += binom * dp[k - j] * m[j];
                binom = binom * j as f64 / (k - j + 1) as f64;
            }
            acc
        };
        let m: [f64; 7] = [f[0], f[1], f[2], f[3], f[4], f[5], f[6]];
        for k in (1..7).rev() {
            f[k] = shifted(&m, k);
        }
        let my: [f64; 4] = [f[feat::Y], f[feat::Y + 1], f[feat::Y + 2], f[feat::Y + 3]];
        for k in (1..4).rev() {
            f[feat::Y + k] = shifted(&my, k);
        }
    }
    fn normal_equations(
        &self,
        p: &[f64],
        free: &[bool],
        scale: &KeyScale,
        sums: &dyn KeySums,
    ) -> NormalEquations {
        self.equations(p, free, scale, sums, true)
    }
    fn relaxes(&self, i: usize) -> bool {
        // k1 of the free pieces is discrete (searched over partitions, no bound needed).
        i == 8 || (i == 7 && self.continuity == Continuity::Continuous)
    }
    /// - k1 (continuous variant), window below k2: the **free** pieces' equations with k1 = ta
    ///   on the rows outside `[ta, tb)`. For any `t` in the window and any continuous fit, the
    ///   rows below ta are on the quadratic and those from tb to k2 on the cubic for every t, so
    ///   its RSS is a sum of nonnegative terms over more rows, of a model that the free pieces
    ///   (no continuity, a superset) contain: never less than the relaxed fit's.
    /// - k2 (either variant), window above k1: the pieces below ta as the model has them (k2 =
    ///   ta), the rows in `[ta, tb)` dropped, and those from tb on fitted by a constant of
    ///   their own (one extra column). At any `t` in the window the rows in `[k1, ta)` are on
    ///   the cubic, and every row from tb on sits at the cubic's value at `t` — a constant (a row
    ///   at tb itself: the cubic at min(tb, t) = t) — so the relaxed fit contains every fit with
    ///   the plateau at `t`, on fewer rows.
    fn window_relaxation(
        &self,
        p: &[f64],
        free: &[bool],
        i: usize,
        ta: f64,
        tb: f64,
        scale: &KeyScale,
        sums: &dyn KeySums,
    ) -> Option<NormalEquations> {
        let (k1, k2) = (p[7], p[8]);
        let window = ta <= tb && self.relaxes(i);
        if !window {
            return None;
        }
        let mut q = p.to_vec();
        if i == 7 {
            let below_k2 = tb <= k2;
            if !below_k2 {
                return None;
            }
            q[7] = ta;
            return Some(FREE.equations(&q, free, scale, sums, true));
        }
        let above_k1 = k1 < ta && tb.is_finite();
        if !above_k1 {
            return None;
        }
        q[8] = ta;
        let inner = self.equations(&q, free, scale, sums, false);
        let f = sums.range(KeyRange::above(tb, true), scale.centre);
        let nb = inner.nb;
        let mut ne = NormalEquations::zeros(nb + 1);
        for a in 0..nb {
            ne.xtx[a * (nb + 1)..a * (nb + 1) + nb]
                .copy_from_slice(&inner.xtx[a * nb..(a + 1) * nb]);
        }
        ne.xty[..nb].copy_from_slice(&inner.xty);
        ne.xtx[nb * (nb + 1) + nb] = f[0];
        ne.xty[nb] = f[feat::Y];
        ne.yty = inner.yty + f[feat::YY];
        Some(ne)
    }
    fn plan_sorted(&self, d: DistinctKeys) -> Plan {
        let p = published();
        let (k1, k2) = (p[7], p[8]);
        // Counts from positions in the sorted keys (a fold's keys are not copied).
        let n_below = d.partition_point(|&s| s < k1);
        let n_to_k2 = d.partition_point(|&s| s <= k2);
        let n_mid = n_to_k2.saturating_sub(n_below);
        let n_above = d.len() - n_to_k2;
        let mut held: Vec<Option<String>> = vec![None; 9];
        let mut search = vec![None; 9];
        if n_below < MIN_DISTINCT {
            let why = format!(
                "held at the published value: {n_below} distinct step frequencies below k1 = {k1} (need {MIN_DISTINCT})"
            );
            for h in held.iter_mut().take(3) {
                *h = Some(why.clone());
            }
        }
        if n_mid < MIN_DISTINCT {
            let why = format!(
                "held at the published value: {n_mid} distinct step frequencies in [k1, k2] = [{k1}, {k2}] (need {MIN_DISTINCT})"
            );
            for h in held.iter_mut().take(7).skip(3) {
                *h = Some(why.clone());
            }
        }
        let n = d.len();
        if held[0].is_none() && held[3].is_none() && n >= 2 * MIN_DISTINCT {
            let lo = d.get(MIN_DISTINCT - 1);
            // The keys ≤ k2 are the first n_to_k2.
            let hi = if n_to_k2 >= MIN_DISTINCT {
                d.get(n_to_k2 - MIN_DISTINCT)
            } else {
                lo
            };
            if hi > lo {
                search[7] = Some((lo, hi));
            }
        }
        if search[7].is_none() {
            held[7] = Some(
                "held at the published value: the data do not cover both pieces well enough to place the knot"
                    .to_string(),
            );
        }
        if held[3].is_none() && n_above >= 3 && n_mid >= MIN_DISTINCT {
            // The keys in [k1, k2] are positions n_below..n_to_k2.
            let lo = d.get(n_below + n_mid.min(MIN_DISTINCT) - 1).max(k1 + 1.0);
            let hi = d.get(n - 3);
            if hi > lo {
                search[8] = Some((lo, hi));
            }
        }
        if search[8].is_none() {
            held[8] = Some(format!(
                "held at the published value: {n_above} distinct step frequencies above k2 = {k2} (need 3) — the plateau is not in the data"
            ));
        }
        Plan { held, search }
    }
    fn discrete_breakpoint(&self, i: usize) -> bool {
        // Free pieces: k1 only decides which rows each piece fits (no continuity at k1).
        i == 7 && self.continuity == Continuity::Free
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::forms::Fitting;
    use crate::relations::run_tflight_sf::jump;

    /// The published relation of either variant.
    fn variant(cont: Continuity) -> RunTflightSf {
        match cont {
            Continuity::Free => RunTflightSf::published(),
            Continuity::Continuous => RunTflightSf::published_continuous(),
        }
    }

    #[test]
    fn centred_basis_maps_to_the_raw_polynomial() {
        let t = centred_to_raw(3, 205.0, 25.0);
        let beta = DVector::from_vec(vec![0.18, -0.01, 0.003, 0.0004]);
        let raw = &t * &beta;
        for sf in [170.0, 200.0, 230.0] {
            let w: f64 = (sf - 205.0) / 25.0;
            let centred: f64 = (0..4).map(|i| beta[i] * w.powi(i as i32)).sum();
            let rawv: f64 = (0..4).map(|i| raw[i] * sf.powi(i as i32)).sum();
            assert!((centred - rawv).abs() < 1e-12, "{centred} {rawv}");
        }
    }

    #[test]
    fn every_basis_layout_reproduces_predictions_through_its_map() {
        // For any β, Σ φ·β + offset must equal the raw prediction with the mapped coefficients.
        for cont in [Continuity::Free, Continuity::Continuous] {
            let rel = variant(cont);
            let r: &dyn Relation = &rel;
            for (qf, cf) in [(true, true), (false, true), (true, false), (false, false)] {
                let mut free = vec![false; 9];
                for f in free.iter_mut().take(3) {
                    *f = qf;
                }
                for f in free.iter_mut().take(7).skip(3) {
                    *f = cf;
                }
                let p = rel.coefficients().to_vec();
                let nb = r.basis_len(&free);
                let beta: Vec<f64> = (0..nb).map(|i| 0.01 * (i as f64 + 1.0)).collect();
                let m = r.basis_to_params(&p, &free);
                let raw = &m.map * DVector::from_vec(beta.clone()) + &m.shift;
                let mut p2 = p.clone();
                for i in 0..7 {
                    p2[i] = raw[i];
                }
                let mut phi = vec![0.0; 8];
                for sf in [150.0, 179.9, 180.0, 200.0, 229.0, 240.0] {
                    let off = r.basis(&p, &free, &Inputs::new(&[sf]), &mut phi);
                    let y: f64 = off + (0..nb).map(|i| phi[i] * beta[i]).sum::<f64>();
                    let want = tflight(&p2, sf);
                    assert!(
                        (y - want).abs() < 1e-9,
                        "{cont:?} {qf} {cf} sf={sf}: {y} vs {want}"
                    );
                }
                if cont == Continuity::Continuous && (qf || cf) {
                    assert!(jump(&p2).abs() < 1e-9, "{qf} {cf}: jump {}", jump(&p2));
                }
            }
        }
    }

    #[test]
    fn sorted_normal_equations_match_the_basis_rows() {
        // Step frequencies 120–260 with repeats, flight times from the published curve.
        let obs: Vec<Observation> = (0..400)
            .map(|i| {
                let sf = 120.0 + (i % 141) as f64 + 0.37 * ((i * 7) % 3) as f64;
                Observation {
                    x: Inputs::new(&[sf, 0.0, 0.0, 0.0]),
                    y: tflight(RunTflightSf::published().coefficients(), sf)
                        + 0.002 * ((i % 5) as f64 - 2.0),
                }
            })
            .collect();
        for cont in [Continuity::Free, Continuity::Continuous] {
            let base = variant(cont);
            for (k1, k2) in [
                (180.0, 230.0),
                (171.3, 245.0),
                (205.0, 190.0),
                (175.0, f64::INFINITY),
                (180.0, 181.5),
            ] {
                let mut p = base.coefficients().to_vec();
                p[7] = k1;
                p[8] = k2;
                for (qf, cf) in [(true, true), (false, true), (true, false), (false, false)] {
                    let mut free = vec![true; 9];
                    for f in free.iter_mut().take(3) {
                        *f = qf;
                    }
                    for f in free.iter_mut().take(7).skip(3) {
                        *f = cf;
                    }
                    crate::fit::forms::sorted_check::check(&base, &obs, &p, &free, 1e-11);
                }
            }
        }
    }

    #[test]
    fn plan_sorted_is_plan() {
        let r: &dyn Relation = &RunTflightSf::published();
        let form = r.sorted_profile().expect("sorted form");
        let obs: Vec<Observation> = (0..60)
            .map(|i| Observation {
                x: Inputs::new(&[150.0 + 2.0 * (i % 45) as f64, 0.0, 0.0, 0.0]),
                y: 0.1,
            })
            .collect();
        let keys = sorted_keys(form, &obs);
        assert_eq!(r.plan(&obs), form.plan_sorted(DistinctKeys::new(&keys)));
        assert!(r.plan(&obs).search[7].is_some() && r.plan(&obs).search[8].is_some());
    }
}
