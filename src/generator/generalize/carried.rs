//! Ko–Badler with the subject's own angle curves carried in W (issue 21 item 5, the *carried*
//! variant beside the paper's).
//!
//! W(S*, sl*) also carries the prototype's measured sagittal angle curves over its stride (hip,
//! knee, ankle on normalized step time, as [`super::angles::measured_angles`] defines them): the
//! subject's character, which the rigid two-link drawing of W does not reproduce (the measured
//! thigh is not rigid, the pelvis-centre estimate moves). A generalized step τ(W) is drawn with
//!
//! - **the feet the paper's**: φ and ψ place them (eqs. 25–48), the stance foot rolls on its
//!   pivots and the swing ankle follows A, exactly as [`super::pose::pose`] draws them; nothing
//!   here moves a foot, so the stance foot neither slides nor penetrates and steps chain as in
//!   the paper;
//! - **the hip (pelvis) the free variable**: each leg's thigh, knee and ankle angles follow from
//!   the pelvis centre's position (two-link IK from the leg's hip joint to its fixed ankle, knee
//!   forward; the thigh angle read from the pelvis centre, as the measured one is; the ankle
//!   angle from the foot's angle). When the prototype's pelvis was measured, W also carries its
//!   rotation and list seen from the side — each hip joint's offset from the pelvis centre
//!   ([`Carried::with_hip_offset`]) — and the stance leg hangs from the centre plus that offset,
//!   the swing leg from the centre minus it, scaled as W's hip travel is
//!   ([`Carried::hip_offset_at`]); without it both legs hang from one hip point. The hip is the least-squares point
//!   min over h of Σ_legs Σ_{hip,knee,ankle} (drawn(h) − carried)², the carried curves read at the
//!   same normalized step time (φ and ψ keep the moments FGM, MOM, TOM, so they need no
//!   re-timing). The three angles weigh equally in radians: the comparison scores each angle's
//!   RMS, and this is the sum of their squares at that instant. The hip stays within leg length
//!   of both ankles (lowered, as the paper's drawing does, where a trial point is out of reach).
//!
//! So the angles keep the subject's shapes as far as the generalized feet allow: what φ and ψ
//! change in the feet (step length, foot angles through μ) changes the drawn angles, and nothing
//! else does. Two constraints (the hip's x and y) against six angles: the drawn angles are the
//! nearest the paper's feet allow, not the carried ones. [`carried_angles`] is what the
//! comparison ([`super::compare`]) scores and what [`super::figure::walk_motion_with`] draws.
//!
//! A first design preferred the generalized step's rendering plus the prototype's
//! measured-minus-rendered residual; it carried φ's change of the rendered angles (eq. 27 pins
//! the hip heights and bends the mid-stance knee of longer steps more than subjects do) and
//! scored 6.2 / 10.2 / 6.8° against these curves' 4.8 / 7.7 / 6.7° (`tests/kb_carried.rs`).
//!
//! Two hip joints (session 7): on the Schreiber subjects the Harrington hip joint centres sit
//! only ≈ 5 mm ahead of / behind the pelvis centre at heel strike (≈ 1.5 % of the step), so the
//! pelvis takes little of a longer step: leave-one-out 4.7 / 7.6 / 6.5° against one hip point's
//! 4.8 / 7.7 / 6.7° (naive scaling 5.3 / 7.7 / 5.7°); the drawn shank at heel strike still
//! responds ≈ 39° per unit of step length / leg length against the subjects' ≈ 16°.
use super::angles::{angles_from_poses, leg_angles, Angles, SAMPLES};
use super::geometry::{knee_position, P2};
use super::mu::MuFunctions;
use super::pose::{pose, LegPose, StepPose};
use super::walk_data::WalkData;
use crate::generator::GenerateError;

/// The angle curves a prototype carries: its measured stride (stance step then swing step,
/// [`SAMPLES`] points each, rad), the posture a generalized step's drawing comes nearest to.
#[derive(Debug, Clone, PartialEq)]
pub struct Carried {
    hip: Vec<f64>,
    knee: Vec<f64>,
    ankle: Vec<f64>,
    pelvis: Option<PelvisOffset>,
}

/// The prototype's pelvis rotation and list seen from the side: the stance leg's hip joint
/// centre relative to the pelvis centre over the step ([`SAMPLES`] points, forward and up, m;
/// the swing leg's is its negative), with the step length and leg length it was measured at.
#[derive(Debug, Clone, PartialEq)]
struct PelvisOffset {
    stance: Vec<[f64; 2]>,
    step_length: f64,
    leg_length: f64,
}

impl Carried {
    /// The curves of `measured` (a prototype's measured stride angles; the ankle path is not
    /// used), and — when the stride's pelvis was measured (`measured.hip_offset`) — its hip
    /// joints' offsets from the pelvis centre, for the step W `prototype` built from it.
    pub fn from_measured(
        measured: &Angles,
        prototype: &WalkData,
    ) -> Result<Carried, GenerateError> {
        let c = Carried::from_curves(
            measured.hip.clone(),
            measured.knee.clone(),
            measured.ankle.clone(),
        )?;
        if measured.hip_offset.is_empty() {
            return Ok(c);
        }
        c.with_hip_offset(
            &measured.hip_offset,
            prototype.step_length(),
            prototype.body().leg_length(),
        )
    }

    /// Adds the pelvis: `stride` is one leg's hip joint centre relative to the pelvis centre
    /// (forward, up; m) over its stride (2·[`SAMPLES`] points: stance step, then swing step),
    /// measured at step length `step_length` with leg length `leg_length`.
    ///
    /// Walking symmetrically, the other leg's hip is the mirror (−offset), so one step's stance
    /// hip offset is the mean of this leg's in its stance step and the negative of this leg's in
    /// its swing step; the two instants a stride measures twice are averaged first (as
    /// [`Carried::from_curves`] does), so the stance hip's offset at the step's end is minus its
    /// start and the hips join across steps.
    pub fn with_hip_offset(
        mut self,
        stride: &[[f64; 2]],
        step_length: f64,
        leg_length: f64,
    ) -> Result<Carried, GenerateError> {
        if stride.len() != 2 * SAMPLES {
            return Err(GenerateError::Parameter {
                name: "carried hip offset".into(),
                value: stride.len() as f64,
                message: format!("needs {} samples (stance and swing step)", 2 * SAMPLES),
            });
        }
        if let Some(i) = stride
            .iter()
            .position(|p| !(p[0].is_finite() && p[1].is_finite()))
        {
            return Err(GenerateError::Parameter {
                name: "carried hip offset".into(),
                value: f64::NAN,
                message: format!("sample {i} is not finite"),
            });
        }
        for (name, v) in [("step length", step_length), ("leg length", leg_length)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(GenerateError::Parameter {
                    name: format!("carried hip offset {name}"),
                    value: v,
                    message: "must be positive".into(),
                });
            }
        }
        let mut d = stride.to_vec();
        for (a, b) in [(SAMPLES - 1, SAMPLES), (2 * SAMPLES - 1, 0)] {
            let m = [0.5 * (d[a][0] + d[b][0]), 0.5 * (d[a][1] + d[b][1])];
            d[a] = m;
            d[b] = m;
        }
        let stance = (0..SAMPLES)
            .map(|i| {
                [
                    0.5 * (d[i][0] - d[SAMPLES + i][0]),
                    0.5 * (d[i][1] - d[SAMPLES + i][1]),
                ]
            })
            .collect();
        self.pelvis = Some(PelvisOffset {
            stance,
            step_length,
            leg_length,
        });
        Ok(self)
    }

    /// The same curves without the pelvis offsets (one hip point for both legs, as before the
    /// pelvis was carried).
    pub fn without_hip_offset(mut self) -> Carried {
        self.pelvis = None;
        self
    }

    /// Whether the pelvis' rotation and list are carried.
    pub fn has_hip_offset(&self) -> bool {
        self.pelvis.is_some()
    }

    /// The stance leg's hip joint relative to the pelvis centre (forward, up; m) in the
    /// generalized step `w` at normalized time `t` (the swing leg's is its negative); zero
    /// without a carried pelvis.
    ///
    /// Scaled as W's own hip travel is scaled: forward by the step length over the prototype's
    /// (ψ's α·x, eq. 43, and φ's ρ on the travel, eq. 26 — the pelvis keeps its share of the
    /// step; across a change of step length the factor runs from sl_before at HSM⁻ to sl at
    /// HSM⁺ so the hips join), up by the leg length over the prototype's (ψ's α·y, eq. 44; φ
    /// leaves heights).
    pub fn hip_offset_at(&self, w: &WalkData, t: f64) -> P2 {
        let Some(p) = &self.pelvis else {
            return [0.0, 0.0];
        };
        let t = t.clamp(0.0, 1.0);
        let x = t * (SAMPLES - 1) as f64;
        let i = (x.floor() as usize).min(SAMPLES - 2);
        let f = x - i as f64;
        let v = |k: usize| p.stance[i][k] + f * (p.stance[i + 1][k] - p.stance[i][k]);
        let sl = (1.0 - t) * w.step_length_before() + t * w.step_length();
        [
            v(0) * sl / p.step_length,
            v(1) * w.body().leg_length() / p.leg_length,
        ]
    }

    /// Curves given directly (rad, 2·[`SAMPLES`] values each: stance step, then swing step).
    /// Two samples stand for each of two instants of a leg's stride — mid-stride (end of the
    /// stance step, start of the swing step) and the stride's ends (a measured stride is not
    /// exactly periodic) — and each pair is replaced by its mean, so that in a chain a leg's
    /// preferred angles at the end of one step are those at the start of the next and the hip
    /// joins across steps.
    pub fn from_curves(
        mut hip: Vec<f64>,
        mut knee: Vec<f64>,
        mut ankle: Vec<f64>,
    ) -> Result<Carried, GenerateError> {
        for (name, v) in [("hip", &hip), ("knee", &knee), ("ankle", &ankle)] {
            if v.len() != 2 * SAMPLES {
                return Err(GenerateError::Parameter {
                    name: format!("carried {name}"),
                    value: v.len() as f64,
                    message: format!("needs {} samples (stance and swing step)", 2 * SAMPLES),
                });
            }
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(GenerateError::Parameter {
                    name: format!("carried {name}"),
                    value: v[i],
                    message: format!("sample {i} is not finite"),
                });
            }
        }
        for v in [&mut hip, &mut knee, &mut ankle] {
            for (a, b) in [(SAMPLES - 1, SAMPLES), (2 * SAMPLES - 1, 0)] {
                let m = 0.5 * (v[a] + v[b]);
                v[a] = m;
                v[b] = m;
            }
        }
        Ok(Carried {
            hip,
            knee,
            ankle,
            pelvis: None,
        })
    }

    /// The carried angles (hip, knee, ankle; rad) of the stance (`swing` false) or swing leg at
    /// normalized step time `t` (linear between samples, clamped to [0, 1]).
    pub fn at(&self, swing: bool, t: f64) -> [f64; 3] {
        let x = t.clamp(0.0, 1.0) * (SAMPLES - 1) as f64;
        let i = (x.floor() as usize).min(SAMPLES - 2);
        let f = x - i as f64;
        let base = if swing { SAMPLES } else { 0 };
        let l = |v: &[f64]| v[base + i] + f * (v[base + i + 1] - v[base + i]);
        [l(&self.hip), l(&self.knee), l(&self.ankle)]
    }
}

/// Iteration cap of the hip's least squares (it converges in a few; the cap only bounds work).
const MAX_ITERS: usize = 60;

/// W sampled at `t` as the carried variant draws it: the paper's feet, the hip at the
/// least-squares point (see the module docs).
pub fn carried_pose(
    w: &WalkData,
    mu: &MuFunctions,
    t: f64,
    carried: &Carried,
) -> Result<StepPose, GenerateError> {
    let p0 = pose(w, mu, t)?;
    if p0.unreachable {
        return Ok(p0);
    }
    let body = w.body();
    let (st, sw) = (p0.stance, p0.swing);
    // Each leg hangs from its own hip joint: the pelvis centre h plus (stance) or minus (swing)
    // the carried offset. The angles are read from the pelvis centre, as the measured ones are.
    let off = carried.hip_offset_at(w, t);
    let leg_hip = |h: P2, sign: f64| [h[0] + sign * off[0], h[1] + sign * off[1]];
    let draw = |h: P2, leg: &LegPose, sign: f64| {
        let (k, _) = knee_position(body, leg_hip(h, sign), leg.foot.ankle);
        leg_angles(h, k, leg.foot.ankle, leg.foot_angle)
    };
    let (ds, dw) = (carried.at(false, t), carried.at(true, t));
    let want = [ds[0], ds[1], ds[2], dw[0], dw[1], dw[2]];
    let reach = body.leg_length();
    // Where the pelvis centre must be within reach of: each ankle shifted by its hip's offset.
    let ankles = [
        [st.foot.ankle[0] - off[0], st.foot.ankle[1] - off[1]],
        [sw.foot.ankle[0] + off[0], sw.foot.ankle[1] + off[1]],
    ];
    // Onto the reachable set: x within reach of both ankles, then the hip lowered under both
    // reach circles (lowering keeps a hip above its ankles within reach).
    let lo = ankles.iter().map(|a| a[0] - reach).fold(f64::MIN, f64::max);
    let hi = ankles.iter().map(|a| a[0] + reach).fold(f64::MAX, f64::min);
    let project = |h: P2| -> P2 {
        let x = h[0].clamp(lo, hi);
        let y = ankles.iter().fold(h[1], |y, a| {
            let dx = x - a[0];
            y.min(a[1] + (reach * reach - dx * dx).max(0.0).sqrt())
        });
        [x, y]
    };
    let resid = |h: P2| -> [f64; 6] {
        let (a, b) = (draw(h, &st, 1.0), draw(h, &sw, -1.0));
        let mut r = [0.0; 6];
        for j in 0..3 {
            r[j] = a[j] - want[j];
            r[3 + j] = b[j] - want[3 + j];
        }
        r
    };
    let cost = |r: &[f64; 6]| r.iter().map(|v| v * v).sum::<f64>();
    let mut h = project(p0.hip);
    let mut r = resid(h);
    let mut f = cost(&r);
    let mut lambda = 1e-3;
    // Finite-difference steps (m): x centred; y backwards, since lowering a reachable hip keeps
    // it reachable (at full reach a forward step would be projected back and read as flat).
    let e = 1e-7 * reach;
    for _ in 0..MAX_ITERS {
        let (rxp, rxm) = (
            resid(project([h[0] + e, h[1]])),
            resid(project([h[0] - e, h[1]])),
        );
        let rym = resid(project([h[0], h[1] - e]));
        let mut jac = [[0.0; 2]; 6];
        for i in 0..6 {
            jac[i][0] = (rxp[i] - rxm[i]) / (2.0 * e);
            jac[i][1] = (r[i] - rym[i]) / e;
        }
        let (mut a, mut g) = ([[0.0; 2]; 2], [0.0; 2]);
        for i in 0..6 {
            for p in 0..2 {
                g[p] += jac[i][p] * r[i];
                for q in 0..2 {
                    a[p][q] += jac[i][p] * jac[i][q];
                }
            }
        }
        let mut improved = false;
        while lambda < 1e12 {
            let m = [
                [a[0][0] * (1.0 + lambda) + 1e-300, a[0][1]],
                [a[1][0], a[1][1] * (1.0 + lambda) + 1e-300],
            ];
            let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
            if !(det.is_finite() && det > 0.0) {
                lambda *= 10.0;
                continue;
            }
            let dx = -(m[1][1] * g[0] - m[0][1] * g[1]) / det;
            let dy = -(m[0][0] * g[1] - m[1][0] * g[0]) / det;
            let hn = project([h[0] + dx, h[1] + dy]);
            let rn = resid(hn);
            let fn_ = cost(&rn);
            if fn_ < f {
                let moved = (hn[0] - h[0]).hypot(hn[1] - h[1]);
                h = hn;
                r = rn;
                f = fn_;
                lambda = (lambda / 3.0).max(1e-9);
                improved = moved > 1e-12 * reach;
                break;
            }
            lambda *= 4.0;
        }
        if !improved {
            break;
        }
    }
    // On a reach boundary (a straight knee) the projected steps above stall short of the
    // constrained optimum: there it is a one-dimensional minimum along that reach circle.
    for a in ankles {
        let (dx, dy) = (h[0] - a[0], h[1] - a[1]);
        if dx.hypot(dy) < reach * (1.0 - 1e-6) {
            continue;
        }
        let on_circle = |th: f64| project([a[0] + reach * th.sin(), a[1] + reach * th.cos()]);
        let th0 = dx.atan2(dy);
        let c = |th: f64| cost(&resid(on_circle(th)));
        let th = golden_min(c, th0 - BOUNDARY_BRACKET_RAD, th0 + BOUNDARY_BRACKET_RAD);
        let hn = on_circle(th);
        let rn = resid(hn);
        if cost(&rn) < f {
            h = hn;
            r = rn;
            f = cost(&r);
        }
    }
    let (k_st, _) = knee_position(body, leg_hip(h, 1.0), st.foot.ankle);
    let (k_sw, _) = knee_position(body, leg_hip(h, -1.0), sw.foot.ankle);
    Ok(StepPose {
        hip: h,
        hip_offset: off,
        stance: LegPose { knee: k_st, ..st },
        swing: LegPose { knee: k_sw, ..sw },
        ..p0
    })
}

/// Half-width of the search along a reach circle (rad of leg angle, ≈ 4 cm of hip travel): the
/// solver above ends within millimetres of the optimum; this only bounds the search.
const BOUNDARY_BRACKET_RAD: f64 = 0.05;

/// Golden-section minimum of `f` on [a, b] (to 1e-13 rad).
fn golden_min(f: impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut c, mut d) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fd) = (f(c), f(d));
    while b - a > 1e-13 {
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    0.5 * (a + b)
}

/// The angles of the step `w` drawn by [`carried_pose`] (the carried variant's candidate in the
/// comparison), on the same grid and with the same definitions as
/// [`super::angles::model_angles`]; the ankle path is the paper's.
pub fn carried_angles(
    w: &WalkData,
    mu: &MuFunctions,
    carried: &Carried,
) -> Result<Angles, GenerateError> {
    let poses = (0..SAMPLES)
        .map(|i| carried_pose(w, mu, i as f64 / (SAMPLES - 1) as f64, carried))
        .collect::<Result<Vec<_>, _>>()?;
    Ok(angles_from_poses(w, &poses))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generator::generalize::synthetic::synthetic_walk;

    /// Carrying W's own rendered angles asks for the paper's drawing: the least squares keeps
    /// the paper's hip.
    #[test]
    fn carrying_the_rendering_is_the_paper_drawing() {
        for seed in 0..6 {
            let (w, mu) = synthetic_walk(seed).unwrap();
            let paper = super::super::angles::model_angles(&w, &mu).unwrap();
            let c = carried_angles(&w, &mu, &Carried::from_measured(&paper, &w).unwrap()).unwrap();
            for (a, b) in paper.knee.iter().zip(&c.knee) {
                assert!((a - b).abs() < 1e-9, "seed {seed}: {a} vs {b}");
            }
        }
    }

    /// The feet stay the paper's, the legs reach them, and a posture the hip can produce is
    /// produced: the angles of W drawn with its hip moved by a known offset lead back to that hip.
    #[test]
    fn a_reachable_preferred_posture_is_found_with_the_feet_unchanged() {
        for seed in 0..6 {
            let (w, mu) = synthetic_walk(seed).unwrap();
            let body = w.body();
            for &t in &[0.3, 0.45, 0.6] {
                let p0 = pose(&w, &mu, t).unwrap();
                let target = [p0.hip[0] + 0.01, p0.hip[1] - 0.02];
                let draw = |h: P2, leg: &LegPose| {
                    let (k, _) = knee_position(body, h, leg.foot.ankle);
                    leg_angles(h, k, leg.foot.ankle, leg.foot_angle)
                };
                let (a1, b1) = (draw(target, &p0.stance), draw(target, &p0.swing));
                // Curves constant in time, the angles at t with the hip moved.
                let mk = |j: usize| -> Vec<f64> {
                    let mut v = vec![a1[j]; SAMPLES];
                    v.extend(vec![b1[j]; SAMPLES]);
                    v
                };
                let c = Carried::from_curves(mk(0), mk(1), mk(2)).unwrap();
                let p = carried_pose(&w, &mu, t, &c).unwrap();
                assert!(
                    (p.hip[0] - target[0]).hypot(p.hip[1] - target[1]) < 1e-6,
                    "seed {seed} t {t}: {:?} vs {target:?}",
                    p.hip
                );
                assert_eq!(p.stance.foot, p0.stance.foot);
                assert_eq!(p.swing.foot, p0.swing.foot);
                for leg in [&p.stance, &p.swing] {
                    let thigh = (leg.knee[0] - p.hip[0]).hypot(leg.knee[1] - p.hip[1]);
                    let shin =
                        (leg.knee[0] - leg.foot.ankle[0]).hypot(leg.knee[1] - leg.foot.ankle[1]);
                    assert!((thigh - body.thigh()).abs() < 1e-9);
                    assert!((shin - body.shin()).abs() < 1e-9);
                }
            }
        }
    }

    /// A stride offset: the stance step's hip `c` ahead/up, the swing step's the mirror.
    fn mirrored_offset(c: P2) -> Vec<P2> {
        let mut v = vec![c; SAMPLES];
        v.extend(vec![[-c[0], -c[1]]; SAMPLES]);
        v
    }

    /// With the pelvis carried, each leg hangs from its own hip joint (centre ± offset, rigid
    /// thigh and shin), the feet stay the paper's, and a posture drawn with a known pelvis centre
    /// is found again — the angles read from the pelvis centre, as the measured ones are.
    #[test]
    fn a_carried_pelvis_hangs_each_leg_from_its_own_hip() {
        for seed in 0..6 {
            let (w, mu) = synthetic_walk(seed).unwrap();
            let body = w.body();
            let off = [0.012, -0.004];
            for &t in &[0.3, 0.45, 0.6] {
                let p0 = pose(&w, &mu, t).unwrap();
                let target = [p0.hip[0] + 0.01, p0.hip[1] - 0.02];
                let draw = |sign: f64, leg: &LegPose| {
                    let hip = [target[0] + sign * off[0], target[1] + sign * off[1]];
                    let (k, _) = knee_position(body, hip, leg.foot.ankle);
                    leg_angles(target, k, leg.foot.ankle, leg.foot_angle)
                };
                let (a1, b1) = (draw(1.0, &p0.stance), draw(-1.0, &p0.swing));
                let mk = |j: usize| -> Vec<f64> {
                    let mut v = vec![a1[j]; SAMPLES];
                    v.extend(vec![b1[j]; SAMPLES]);
                    v
                };
                let c = Carried::from_curves(mk(0), mk(1), mk(2))
                    .unwrap()
                    .with_hip_offset(&mirrored_offset(off), w.step_length(), body.leg_length())
                    .unwrap();
                let near =
                    |a: P2, b: P2| (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12;
                assert!(near(c.hip_offset_at(&w, t), off));
                let p = carried_pose(&w, &mu, t, &c).unwrap();
                assert!(
                    (p.hip[0] - target[0]).hypot(p.hip[1] - target[1]) < 1e-6,
                    "seed {seed} t {t}: {:?} vs {target:?}",
                    p.hip
                );
                assert!(near(p.hip_offset, off), "{:?}", p.hip_offset);
                assert_eq!(p.stance.foot, p0.stance.foot);
                assert_eq!(p.swing.foot, p0.swing.foot);
                for (sign, leg) in [(1.0, &p.stance), (-1.0, &p.swing)] {
                    let hip = [p.hip[0] + sign * off[0], p.hip[1] + sign * off[1]];
                    let thigh = (leg.knee[0] - hip[0]).hypot(leg.knee[1] - hip[1]);
                    let shin =
                        (leg.knee[0] - leg.foot.ankle[0]).hypot(leg.knee[1] - leg.foot.ankle[1]);
                    assert!((thigh - body.thigh()).abs() < 1e-9, "{thigh}");
                    assert!((shin - body.shin()).abs() < 1e-9, "{shin}");
                }
                // Without the pelvis the same curves draw another pelvis centre.
                let q = carried_pose(&w, &mu, t, &c.clone().without_hip_offset()).unwrap();
                assert_eq!(q.hip_offset, [0.0, 0.0]);
                assert!((q.hip[0] - p.hip[0]).hypot(q.hip[1] - p.hip[1]) > 1e-4);
            }
        }
    }

    /// The offsets scale as W's hip travel does (forward with the step length, up with the leg
    /// length), and the stance hip's offset at a step's end is minus the next step's start (the
    /// hips join across steps of different lengths).
    #[test]
    fn the_pelvis_offset_scales_with_the_step_and_joins_across_steps() {
        let (w, mu) = synthetic_walk(3).unwrap();
        let g = super::super::Generalizer::new(w.clone(), mu).unwrap();
        // A stride whose halves differ and whose ends do not quite match (as measured ones).
        let stride: Vec<P2> = (0..2 * SAMPLES)
            .map(|i| {
                let s = i as f64 / (2 * SAMPLES - 1) as f64;
                let a = 2.0 * std::f64::consts::PI * s;
                [0.01 * a.cos() + 0.001 * s, 0.006 * (2.0 * a).sin() + 0.0005]
            })
            .collect();
        let c = Carried::from_measured(&super::super::angles::model_angles(&w, &mu).unwrap(), &w)
            .unwrap()
            .with_hip_offset(&stride, w.step_length(), w.body().leg_length())
            .unwrap();
        let e0 = c.hip_offset_at(&w, 0.0);
        let e1 = c.hip_offset_at(&w, 1.0);
        assert!((e0[0] + e1[0]).abs() < 1e-15 && (e0[1] + e1[1]).abs() < 1e-15);
        let body = w.body().scaled(1.1).unwrap();
        let lengths = [
            w.step_length(),
            1.2 * w.step_length(),
            0.9 * w.step_length(),
        ];
        let steps = g.chain(&body, &lengths).unwrap();
        for k in 1..steps.len() {
            let a = c.hip_offset_at(&steps[k - 1], 1.0);
            let b = c.hip_offset_at(&steps[k], 0.0);
            assert!((a[0] + b[0]).abs() < 1e-12 && (a[1] + b[1]).abs() < 1e-12);
        }
        for &t in &[0.0, 0.3, 0.7, 1.0] {
            let e = c.hip_offset_at(&w, t);
            let f = c.hip_offset_at(&steps[1], t);
            // Step 1 runs from sl_before = sl* to 1.2·sl*; the body is 1.1 times the prototype's.
            let want_x = e[0] * (1.0 - t + t * 1.2);
            let want_y = e[1] * body.leg_length() / w.body().leg_length();
            assert!((f[0] - want_x).abs() < 1e-12, "t {t}: {} vs {want_x}", f[0]);
            assert!((f[1] - want_y).abs() < 1e-12, "t {t}: {} vs {want_y}", f[1]);
        }
    }
}
