//! The stop: after the last (half) step's heel strike the walker comes to a quiet standing
//! posture (§2.4 and §5: "even the extreme cases of starting and stopping are possible").
//!
//! The paper shows the stop (Fig. 8) but does not describe how the trailing foot is brought
//! alongside or how the body comes to rest; the last dynamic step ends at a heel strike with the
//! body still moving. We close the walk kinematically — the paper itself regards the dynamics as
//! "an interpolation method between key frames" — from the dynamic state at that heel strike:
//! - the pelvis comes to rest above the feet: its forward position and the leading leg's
//!   hip-to-ankle distance follow quintics from their values, rates and accelerations at the
//!   heel strike (so the path is C² there) to rest, the hip just ahead of the ankles
//!   ([`STAND_HIP_AHEAD`]), monotone (no stepping back), and the legs
//!   straight but for a soft knee (`STAND_KNEE_SLACK`); the height follows from the leg length,
//!   so the leading foot's heel rocker ends flat and the foot then stays flat;
//! - the lateral sway decays from its rate at the heel strike to the feet's midline (zero rate);
//! - the trailing leg completes its stance (heel off, meta off, toe off after the double support
//!   `t_ds`, through the virtual leg as in every step), then its ankle moves on a minimum-jerk
//!   path, lifted by the toe clearance, to land flat beside the stance foot at the end of the
//!   swing time of the last step (stride width kept), with zero velocity;
//! - the trunk's lean returns to its reference angle.
use super::foot::FootShape;
use super::track::interp_rho;
use super::virtual_leg::{FootPeriod, LegPose, VirtualLeg};
use crate::events::Side;
use crate::generator::curves::{smootherstep, Quintic};

/// Knee slack of the standing legs.
pub const STAND_KNEE_SLACK: f64 = 0.001;

/// How far the hip comes to rest ahead of the ankles, m (in quiet standing the line of gravity
/// falls a few centimetres in front of the ankle joints; it also lengthens the stop).
pub const STAND_HIP_AHEAD: f64 = 0.03;

/// Extra lift of the trailing ankle at mid-swing over the toe clearance, m (the foot is brought
/// alongside, not stepped over an obstacle).
const SWING_LIFT: f64 = 0.02;

/// The trunk and pelvis state at the last heel strike (pre-impact, as drawn), and the geometry
/// of the stop.
#[derive(Debug, Clone, PartialEq)]
pub struct StopStart {
    /// Dynamic hip (x, y): position, rate, acceleration.
    pub hip: [[f64; 3]; 2],
    /// Lateral position of the pelvis centre: position, rate, acceleration.
    pub lateral: [f64; 3],
    /// Trunk lean θ2: angle, rate, acceleration.
    pub lean: [f64; 3],
    /// Trunk lean at rest, rad.
    pub lean_ref: f64,
    /// Flat-ankle x of the leading (new stance) foot, m.
    pub stance_ankle_x: f64,
    /// Ankle height of a flat foot, m.
    pub ankle_height: f64,
    /// Lateral offsets of the hips from the pelvis centre, m: stance, trailing.
    pub hip_z: [f64; 2],
    /// Lateral positions of the ankles, m: stance, trailing (the stride width is kept).
    pub ankle_z: [f64; 2],
    /// Leg length `l1`, m.
    pub l1: f64,
    /// Double support and swing durations of the last step, s.
    pub t_ds: f64,
    /// Swing duration, s.
    pub t_swing: f64,
    /// Toe clearance, m.
    pub clearance: f64,
    /// The trailing leg's clock at the heel strike, s.
    pub trail_clock: f64,
    /// Shortest meta-off knee flexion of the trailing leg, s.
    pub min_knee_blend: f64,
    /// Shortest planned heel rocker of the leading leg, s (as in the walk's steps:
    /// `heel_rocker_fraction` × the last step's duration; see
    /// [`VirtualLeg::plan_heel_rocker`]).
    pub heel_rocker_min: f64,
}

/// The closing motion after the last heel strike (times from that heel strike).
#[derive(Debug, Clone, PartialEq)]
pub struct Closing {
    /// Global time of the last heel strike, s.
    pub start: f64,
    /// Length of the closing motion (the last frames stand still), s.
    pub duration: f64,
    /// The new stance side (the foot that landed last).
    pub stance: Side,
    /// Toe-off of the trailing foot, s.
    pub toe_off: f64,
    /// Landing of the trailing foot beside the stance foot, s.
    pub landing: f64,
    /// Foot-flat of the stance foot, s (if its heel rocker ends).
    pub stance_flat: Option<f64>,
    /// Heel-off and meta-off of the trailing foot, s (if within the double support).
    pub trail_transitions: [Option<f64>; 2],
    x: Quintic,
    r: Quintic,
    lean: Quintic,
    lateral: Quintic,
    geo: StopStart,
    stance_leg: VirtualLeg,
    stance_rho: Vec<(f64, f64)>,
    /// The landing foot's ankle angle θ5 from the heel strike to [`EARLY`] s after the leg's
    /// reach, `(t, θ5)`.
    stance_theta5: Vec<(f64, f64)>,
    /// When the straight leg first reaches the landing foot's pitched ankle, s (the rocker's
    /// roll starts there; see [`Closing::contact_ankle_rate`]).
    stance_reach: f64,
    trail_leg: VirtualLeg,
    trail_rho: Vec<(f64, f64)>,
    ankle_x: Quintic,
    ankle_y: Quintic,
    toe_off_pose: (f64, f64),
    lift: f64,
}

/// One frame of the closing motion: everything [`super::generate`] needs to draw it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosingFrame {
    /// Dynamic hip (x, y) of the pelvis centre's sagittal plane, m.
    pub hip: [f64; 2],
    /// Lateral position of the pelvis centre, m.
    pub lateral: f64,
    /// Trunk lean θ2, rad.
    pub lean: f64,
    /// Stance foot: ankle (x, y), pitch, toe bend.
    pub stance_foot: ([f64; 2], f64, f64),
    /// Trailing foot: ankle (x, y), pitch, toe bend.
    pub trail_foot: ([f64; 2], f64, f64),
    /// Whether the trailing foot is on the ground.
    pub trail_contact: bool,
}

/// How long the landing foot's early ankle angle is kept, s (see
/// [`Closing::contact_ankle_rate`]).
const EARLY: f64 = 0.05;

/// Minimum-jerk bump: 0 with zero rate and acceleration at both ends, 1 at the middle.
fn bump(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    64.0 * (s * (1.0 - s)).powi(3)
}

impl Closing {
    /// Plans the stop from the state at the last heel strike (global time `start`).
    /// `stance_leg` is the leading foot's virtual leg (heel rocker from its landing pitch),
    /// `trail_leg` the trailing foot's, whose clock reads `geo.trail_clock` at the heel strike.
    pub fn new(
        start: f64,
        stance: Side,
        geo: StopStart,
        mut stance_leg: VirtualLeg,
        mut trail_leg: VirtualLeg,
        foot: &FootShape,
    ) -> Closing {
        let g = &geo;
        let (trail_clock, min_knee_blend) = (g.trail_clock, g.min_knee_blend);
        let [hx, hy] = g.hip;
        let ax = g.stance_ankle_x;
        // Forward motion: rest with the hip over the ankles. A quintic from rate v0 to rest over
        // d stays monotone while v0·d < 2.5·(distance); d is the swing's end (the body settles
        // as the foot lands) unless the hip arrives sooner.
        let x_end = ax + STAND_HIP_AHEAD;
        let dist = (x_end - hx[0]).max(1e-3);
        let v0 = hx[1].max(1e-6);
        let d_land = g.t_ds + g.t_swing;
        let mut d = d_land.min(2.4 * dist / v0);
        let mut x = Quintic::new(hx, [x_end, 0.0, 0.0], d);
        // The start's acceleration can still make it overshoot: shorten until it does not.
        for _ in 0..20 {
            // Near the end the rate is ∝ (1 − s)²: its sign shows only close to s = 1.
            let samples = (1..100).map(|k| k as f64 / 100.0).chain([0.995, 0.999]);
            if samples.into_iter().all(|s| x.at(d * s)[1] >= 0.0) {
                break;
            }
            d *= 0.9;
            x = Quintic::new(hx, [x_end, 0.0, 0.0], d);
        }
        // Leading leg's hip-to-flat-ankle distance r (3-D), its rate and acceleration at the
        // heel strike, by the chain rule on r² = dx² + dy² + dz².
        let dz0 = g.lateral[0] + g.hip_z[0] - g.ankle_z[0];
        let rel = [hx[0] - ax, hy[0] - g.ankle_height, dz0];
        let vel = [hx[1], hy[1], g.lateral[1]];
        let acc = [hx[2], hy[2], g.lateral[2]];
        let dot = |a: &[f64; 3], b: &[f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let r0 = dot(&rel, &rel).sqrt();
        let r1 = dot(&rel, &vel) / r0;
        let r2 = (dot(&vel, &vel) + dot(&rel, &acc) - r1 * r1) / r0;
        let r = Quintic::new([r0, r1, r2], [g.l1 - STAND_KNEE_SLACK, 0.0, 0.0], d);
        let lean = Quintic::new(g.lean, [g.lean_ref, 0.0, 0.0], d);
        // The lateral sway comes to rest at the feet's midline.
        let lateral = Quintic::new(
            g.lateral,
            [0.5 * (g.ankle_z[0] + g.ankle_z[1]), 0.0, 0.0],
            d,
        );
        let duration = d.max(d_land) + 0.2;
        let mut c = Closing {
            start,
            duration,
            stance,
            toe_off: g.t_ds,
            landing: d_land,
            stance_flat: None,
            trail_transitions: [None; 2],
            x,
            r,
            lean,
            lateral,
            geo: geo.clone(),
            stance_leg: stance_leg.clone(),
            stance_rho: Vec::new(),
            stance_theta5: Vec::new(),
            stance_reach: 0.0,
            trail_leg: trail_leg.clone(),
            trail_rho: Vec::new(),
            ankle_x: Quintic::new([0.0; 3], [0.0; 3], 1.0),
            ankle_y: Quintic::new([0.0; 3], [0.0; 3], 1.0),
            toe_off_pose: (0.0, 0.0),
            lift: g.clearance + SWING_LIFT,
        };
        // The leading foot: heel rocker until flat, then flat. The rocker is planned as in the
        // walk's steps (the knee flexes from straight along a C¹ curve to the flat foot's knee
        // angle and rate, the roll following): the straight-leg rule slapped the foot flat within
        // 3–5 frames and then snapped the knee from straight to the leg's shortening (its
        // flexion ∝ √(l1 − r)), 0.1 rad in one frame, the hip and arms following (continuity
        // ratios 6–9 at every speed).
        let dt = 2e-3;
        let n = ((c.duration / dt).ceil() as usize).max(2);
        let hips: Vec<(f64, [f64; 2], f64)> = (0..=n)
            .map(|i| {
                let t = c.duration * i as f64 / n as f64;
                let (hip, z) = c.hip_at(t);
                (t, hip, z + g.hip_z[0] - g.ankle_z[0])
            })
            .collect();
        // The heel strike's geometry (eq. 3) is sagittal but the leg is drawn in 3-D, its hip
        // ≈ 4 cm beside the foot: at the heel strike the straight leg may fall up to a millimetre
        // short of the landing pitch's ankle, and a slow walker's hip takes a few frames to come
        // that much closer. The plan's knee starts flexing only once the leg reaches (before, the
        // foot holds its landing pitch and the knee stays straight), else the drawn knee, held
        // straight by the reach, caught up with the plan in one frame (ratio 8–9 at 1 km/h).
        let reach_from = hips
            .iter()
            .position(|&(_, hip, dz)| {
                let p = stance_leg.pose_at(hip, dz, stance_leg.rho);
                let dy = ((hip[1] - p.ankle[1]).powi(2) + dz * dz).sqrt();
                (hip[0] - p.ankle[0]).hypot(dy) <= stance_leg.l3 + stance_leg.l4
            })
            .unwrap_or(0);
        stance_leg.plan_heel_rocker(&hips[reach_from..], g.heel_rocker_min);
        c.stance_reach = hips[reach_from].0;
        let mut flat = false;
        for &(t, hip, dz) in &hips {
            let rho = if flat {
                0.0
            } else {
                let p = stance_leg.advance(t, hip, dz);
                if t <= c.stance_reach + EARLY {
                    c.stance_theta5.push((t, p.theta5));
                }
                if stance_leg.period != FootPeriod::HeelRocker {
                    flat = true;
                    c.stance_flat = Some(t);
                    0.0
                } else {
                    p.rho.min(0.0)
                }
            };
            c.stance_rho.push((t, rho));
        }
        c.stance_leg = stance_leg;
        // The trailing foot completes its stance through the double support.
        trail_leg.toe_off_time = trail_clock + g.t_ds;
        trail_leg.min_knee_blend = min_knee_blend;
        let nv = ((g.t_ds / dt).ceil() as usize).max(3);
        let mut poses: Vec<(f64, LegPose)> = Vec::with_capacity(nv + 1);
        for i in 0..=nv {
            let t = g.t_ds * i as f64 / nv as f64;
            let (hip, z) = c.hip_at(t);
            let p = trail_leg.advance(trail_clock + t, hip, z + g.hip_z[1] - g.ankle_z[1]);
            c.trail_rho.push((t, p.rho));
            poses.push((t, p));
        }
        let tr = trail_leg.transitions;
        for (j, slot) in [1usize, 2].iter().enumerate() {
            c.trail_transitions[j] = tr[*slot]
                .map(|tt| tt - trail_clock)
                .filter(|&tt| (-1e-12..=g.t_ds + 1e-12).contains(&tt));
        }
        c.trail_leg = trail_leg;
        // Toe-off: the ankle's position and rate (backward difference) start the swing path.
        let m = poses.len();
        let (p0, p1) = (poses[m - 1].1, poses[m - 2].1);
        let h = poses[m - 1].0 - poses[m - 2].0;
        let (ankle0, pitch0, bend0) =
            foot.rolled(c.trail_leg.flat_ankle, p0.rho, c.trail_leg.theta6_max);
        let va = [
            (p0.ankle[0] - p1.ankle[0]) / h,
            (p0.ankle[1] - p1.ankle[1]) / h,
        ];
        let ds = d_land - g.t_ds;
        c.ankle_x = Quintic::new([ankle0[0], va[0], 0.0], [ax, 0.0, 0.0], ds);
        c.ankle_y = Quintic::new([ankle0[1], va[1], 0.0], [g.ankle_height, 0.0, 0.0], ds);
        c.toe_off_pose = (pitch0, bend0);
        c
    }

    /// The landing foot's mean ankle rate dθ5/dt from the heel strike to `window` s (at most
    /// `EARLY`, 0.05 s) after the straight leg reaches its pitched ankle, rad/s: the last step's
    /// swing foot lands into it (see [`super::swing::SwingFoot::theta5_rate_hs`]), as every
    /// step's lands into the next step's heel rocker.
    pub fn contact_ankle_rate(&self, window: f64) -> f64 {
        let s = &self.stance_theta5;
        let end = self.stance_reach + window.min(EARLY);
        let (Some(&a), Some(&b)) = (s.first(), s.iter().take_while(|x| x.0 <= end + 1e-9).last())
        else {
            return 0.0;
        };
        if b.0 > a.0 {
            (b.1 - a.1) / (b.0 - a.0)
        } else {
            0.0
        }
    }

    /// The trailing foot's drawn roll through the double support, `(t, ρ)` on the closing's
    /// clock (from [`Closing::start`]).
    pub fn trail_rho(&self) -> &[(f64, f64)] {
        &self.trail_rho
    }

    /// Pelvis centre (dynamic hip x, y) and lateral position at `t`.
    fn hip_at(&self, t: f64) -> ([f64; 2], f64) {
        let g = &self.geo;
        let x = self.x.at(t)[0];
        let z = self.lateral_at(t);
        let dz = z + g.hip_z[0] - g.ankle_z[0];
        let dx = x - g.stance_ankle_x;
        let r = self.r.at(t)[0];
        let dy = (r * r - dx * dx - dz * dz).max(0.0).sqrt();
        ([x, g.ankle_height + dy], z)
    }

    fn lateral_at(&self, t: f64) -> f64 {
        self.lateral.at(t)[0]
    }

    /// The frame at `t` (from the last heel strike).
    pub fn frame(&self, t: f64, foot: &FootShape) -> ClosingFrame {
        let t = t.clamp(0.0, self.duration);
        let (hip, lateral) = self.hip_at(t);
        let rho_s = interp_rho(&self.stance_rho, t);
        let stance_foot = foot.rolled(
            self.stance_leg.flat_ankle,
            rho_s,
            self.stance_leg.theta6_max,
        );
        let (trail_foot, trail_contact) = if t <= self.toe_off {
            let rho = interp_rho(&self.trail_rho, t);
            (
                foot.rolled(self.trail_leg.flat_ankle, rho, self.trail_leg.theta6_max),
                true,
            )
        } else {
            let tt = t - self.toe_off;
            let ds = self.landing - self.toe_off;
            let s = (tt / ds).clamp(0.0, 1.0);
            let k = smootherstep(s);
            let (p0, b0) = self.toe_off_pose;
            (
                (
                    [
                        self.ankle_x.at(tt)[0],
                        self.ankle_y.at(tt)[0] + self.lift * bump(s),
                    ],
                    p0 * (1.0 - k),
                    b0 * (1.0 - k),
                ),
                t >= self.landing,
            )
        };
        ClosingFrame {
            hip,
            lateral,
            lean: self.lean.at(t)[0],
            stance_foot,
            trail_foot,
            trail_contact,
        }
    }
}
