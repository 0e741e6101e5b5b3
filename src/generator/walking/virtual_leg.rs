//! The virtual leg (§4.2, figure 6): a full leg (hip, knee, ankle, metatarsal joint, toe)
//! superimposed on the telescopic stance leg. The hip comes from the dynamics, the foot's
//! pivot is fixed on the ground, and rules about the foot's motion pick one configuration out of
//! the infinitely many:
//! - *normal period*: after heel strike the foot rotates about the heel, with the knee straight,
//!   until it is flat (the leg's reach decides: while the flat foot's ankle is out of reach of the
//!   extended leg the foot stays pitched up, and if the hip passes its closest approach with the
//!   flat ankle still just out of reach — a stance leg locked longer than `l1` — the foot rocks
//!   over flat onto its ball, straight into heel off); then the foot stays flat and the knee takes up the
//!   telescopic leg's shortening, until the ankle's dorsiflexion θ5 reaches its limit or the
//!   foot has to roll for the leg to reach;
//! - *heel-off period*: the foot rolls about the metatarsal joint (toes flat) just enough to keep
//!   the ankle within reach of the (straightened) leg — the telescopic leg's extension beyond
//!   `l1` is the plantar flexion it simulates — until the toe bend θ6 reaches its limit;
//! - *meta-off period*: the whole foot rolls about the toe tip while the knee flexes (C¹ blend
//!   from rest, ending at [`TOE_OFF_KNEE_RATE`] at most) to its toe-off value — through the
//!   double support, when the leg's stance is completed kinematically (§3), until toe-off; θ5
//!   at toe-off follows (the paper: "known from the
//!   kinematic meta-off period").
//!
//! All the rules are one-dimensional roots in the foot's roll coordinate `ρ`
//! ([`FootShape::rolled`]); `ρ` never decreases after the foot is flat. Distances are measured in
//! three dimensions (the hip's lateral offset from the foot, `dz`, is included), so the leg drawn
//! in 3D reaches its ankle exactly.
use super::attributes::WalkAttributes;
use super::body::Body;
use super::foot::{toe_blend, FootShape};
use crate::generator::curves::smoothstep;
use std::f64::consts::FRAC_PI_2;

/// Width of the knee's soft straightening in late stance, m.
pub const KNEE_SOFT: f64 = 0.0015;

/// How many landing times after the shortest valid one [`VirtualLeg::plan_heel_rocker`] also tries
/// (on its ×1.1 grid: up to ≈ 1.5 × the shortest), keeping the one whose knee Hermite has the least
/// peak acceleration `max(|k̈(0)|, |k̈(T)|)` (a cubic's second derivative is linear, so its peak is
/// at an end).
pub const ROCKER_SCAN: usize = 4;

/// Knee flexion rate at toe-off, rad/s (at most; less when the meta-off knee flexion is slow).
pub const TOE_OFF_KNEE_RATE: f64 = 8.0;

/// How far the foot may roll about the toe tip beyond the toe-bend limit, rad (80°).
const RHO_CAP: f64 = 1.4;

/// The periods of the stance foot (§4.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FootPeriod {
    /// Rotating about the heel after heel strike.
    HeelRocker,
    /// Flat on the ground.
    Flat,
    /// Heel off: rolling about the metatarsal joint.
    HeelOff,
    /// Meta off: rolling about the toe tip.
    MetaOff,
}

/// One evaluated configuration of the virtual leg (sagittal plane of its foot).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LegPose {
    /// Roll coordinate.
    pub rho: f64,
    /// Ankle position (x, y), m.
    pub ankle: [f64; 2],
    /// Foot pitch (toes up positive), rad.
    pub pitch: f64,
    /// Toe bend θ6, rad.
    pub toe_bend: f64,
    /// Knee flexion, rad (≥ 0).
    pub knee: f64,
    /// Thigh angle θ3 from the vertical (positive: knee behind the hip), rad.
    pub thigh: f64,
    /// Ankle angle θ5, rad.
    pub theta5: f64,
    /// Whether the leg reaches its ankle.
    pub reached: bool,
    /// The period.
    pub period: FootPeriod,
}

/// The stance leg's foot rules and their state.
#[derive(Debug, Clone, PartialEq)]
pub struct VirtualLeg {
    /// The foot.
    pub foot: FootShape,
    /// Thigh and shank lengths, m.
    pub l3: f64,
    /// Shank length, m.
    pub l4: f64,
    /// Flat-foot ankle position (x, y), m.
    pub flat_ankle: [f64; 2],
    /// Dorsiflexion limit of θ5 that starts heel-off, rad.
    pub theta5_max: f64,
    /// Toe-bend limit θ6 that starts meta-off, rad.
    pub theta6_max: f64,
    /// Knee flexion at toe-off, reached through the meta-off period, rad.
    pub knee_toe_off: f64,
    /// Time of toe-off in the leg's own clock, s (set when known).
    pub toe_off_time: f64,
    /// Shortest duration of the meta-off knee flexion, s: when meta-off begins late (a leg
    /// that rolled slowly), the knee flexes at this pace and has not quite reached its toe-off
    /// value at toe-off, rather than snapping there — the swing starts from the knee's rate.
    pub min_knee_blend: f64,
    /// Largest knee flexion rate at toe-off, rad/s ([`TOE_OFF_KNEE_RATE`]; 0: the paper's
    /// knee, at rest at toe-off).
    pub toe_off_knee_rate: f64,
    /// Current period.
    pub period: FootPeriod,
    /// Current roll.
    pub rho: f64,
    /// Start of meta-off: time and knee flexion then.
    pub meta_start: Option<(f64, f64)>,
    /// Times the periods began (foot flat, heel off, meta off), s.
    pub transitions: [Option<f64>; 3],
    /// The planned heel rocker (see [`VirtualLeg::plan_heel_rocker`]); `None`: the foot
    /// lowers as fast as the straight leg allows.
    pub rocker: Option<HeelRocker>,
    /// Width of the knee's soft straightening in late stance, m (see [`KNEE_SOFT`]; narrower
    /// when a planned heel rocker lands with the knee nearly straight).
    pub knee_soft: f64,
    /// Whether a planned heel rocker may start the knee slower than its mean rate, down to
    /// rest, in slow walks (see [`VirtualLeg::plan_heel_rocker`]). The walk's steps do; the
    /// stop's landing does not (measured worse there: 3 km/h 2.9 → 4.0, 5 km/h 6.0 → 7.8).
    pub slow_knee_start: bool,
    /// Longest hip–ankle span the flat and heel-off rules draw, m: `l3 + l4` (the paper's
    /// straight knee), shorter where the stance leg locked short of `l1` at speed
    /// (`StanceSpec::drawn_span`): the knee then keeps that flexion through midstance and heel
    /// off, and the heel rises as soon as the hip is farther than this from the flat ankle. The
    /// heel rocker's landing is planned against it too (the flat foot must be within it).
    pub span_max: f64,
    /// How far the flat foot's ankle was beyond the straight leg's reach at the last sample of a
    /// heel rocker without a plan, m (`None` before the first): while it shrinks the foot rolls
    /// about the heel toward flat; once it grows again the foot rocks over (see
    /// [`VirtualLeg::advance`]).
    pub rocker_gap: Option<f64>,
}

/// A planned heel rocker: the foot's roll at the leg's samples from heel strike (`−pitch`) to
/// `end`, when it is flat (see [`VirtualLeg::plan_heel_rocker`]).
#[derive(Debug, Clone, PartialEq)]
pub struct HeelRocker {
    /// When the foot is flat, s (leg clock).
    pub end: f64,
    /// `(t, ρ)` samples up to `end`.
    pub table: Vec<(f64, f64)>,
}

impl HeelRocker {
    /// The roll `ρ` at `t` (linear between samples, 0 from `end` on).
    pub fn rho_at(&self, t: f64) -> f64 {
        if t >= self.end {
            return 0.0;
        }
        let k = self.table.partition_point(|s| s.0 <= t);
        if k == 0 {
            return self.table.first().map_or(0.0, |s| s.1);
        }
        let (a, b) = match self.table.get(k) {
            Some(&b) => (self.table[k - 1], b),
            None => (self.table[k - 1], (self.end, 0.0)),
        };
        if b.0 <= a.0 {
            return b.1;
        }
        a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0)
    }
}

/// Knee flexion of a two-link leg (`l3`, `l4`) spanning `d`, rad.
fn knee_for(l3: f64, l4: f64, d: f64) -> f64 {
    crate::generator::ik::flexion_for_span(l3, l4, d)
}

/// Length of a two-link leg with knee flexion `knee`, m.
fn span_for(l3: f64, l4: f64, knee: f64) -> f64 {
    crate::generator::ik::span_for_flexion(l3, l4, knee)
}

/// The root of `g` between `pos` (`g > 0`) and `neg` (`g ≤ 0`), to 1e-10, returned from the
/// `g ≤ 0` side: the Illinois variant of regula falsi (superlinear, a handful of evaluations of
/// the leg's geometry instead of bisection's thirty-odd), bisecting whenever it stalls.
fn root_nonpositive_side(g: &impl Fn(f64) -> f64, pos: f64, neg: f64) -> f64 {
    root_from(g, (pos, g(pos)), (neg, g(neg)))
}

/// [`root_nonpositive_side`] from two points whose values of `g` are already known (`ga > 0`,
/// `gb ≤ 0`): a scan has just evaluated them, and `g` is a pure function, so the answer is the
/// same without evaluating them twice.
fn root_from(g: &impl Fn(f64) -> f64, pos: (f64, f64), neg: (f64, f64)) -> f64 {
    let stop = crate::generator::numeric::Stop {
        f_tol: 0.0,
        x_tol: 1e-10,
        max_evals: 100,
    };
    if pos.1 <= 0.0 {
        return pos.0;
    }
    crate::generator::numeric::illinois(g, pos, neg, stop).b.0
}

impl VirtualLeg {
    /// A leg of `body` with its foot flat at `flat_x` (ankle at the flat foot's height `l9`), the
    /// foot limits of the attributes (θ5max, θ6max, knee at toe-off), in `period` at roll `rho`,
    /// and nothing planned or recorded yet (no toe-off time, rocker, transitions or knee ease).
    pub fn new(
        foot: FootShape,
        body: &Body,
        a: &WalkAttributes,
        flat_x: f64,
        period: FootPeriod,
        rho: f64,
    ) -> VirtualLeg {
        VirtualLeg {
            foot,
            l3: body.l3,
            l4: body.l4,
            flat_ankle: [flat_x, body.l9],
            theta5_max: a.ankle_dorsiflexion_max_deg.to_radians(),
            theta6_max: a.metatarsal_max_deg.to_radians(),
            knee_toe_off: a.knee_toe_off_deg.to_radians(),
            toe_off_time: 0.0,
            min_knee_blend: 0.0,
            toe_off_knee_rate: TOE_OFF_KNEE_RATE,
            period,
            rho,
            meta_start: None,
            transitions: [None; 3],
            rocker: None,
            knee_soft: KNEE_SOFT,
            slow_knee_start: true,
            span_max: body.l3 + body.l4,
            rocker_gap: None,
        }
    }

    /// Evaluates the leg for the hip at `hip` (x, y) with lateral offset `dz` for roll `rho`.
    pub fn pose_at(&self, hip: [f64; 2], dz: f64, rho: f64) -> LegPose {
        let (ankle, pitch, toe_bend) = self.foot.rolled(self.flat_ankle, rho, self.theta6_max);
        let dx = hip[0] - ankle[0];
        let dy_in_plane = ((hip[1] - ankle[1]).powi(2) + dz * dz).sqrt();
        let d = dx.hypot(dy_in_plane);
        let (l3, l4) = (self.l3, self.l4);
        let reached = d <= l3 + l4 && d >= (l3 - l4).abs();
        let dc = d.clamp((l3 - l4).abs() + 1e-12, l3 + l4);
        // In the leg plane: hip at (dx, dy) from the ankle; the knee bends forward.
        let knee = knee_for(l3, l4, dc);
        // Angle at the ankle between the ankle–hip line and the shank.
        let cos_a = ((l4 * l4 + dc * dc - l3 * l3) / (2.0 * l4 * dc)).clamp(-1.0, 1.0);
        let line = dx.atan2(dy_in_plane); // forward tilt of the ankle–hip line
        let shank_tilt = line + cos_a.acos(); // knee forward of that line
        let knee_pos = [l4 * shank_tilt.sin(), l4 * shank_tilt.cos()];
        let thigh = (dx - knee_pos[0]).atan2(dy_in_plane - knee_pos[1]);
        LegPose {
            rho,
            ankle,
            pitch,
            toe_bend,
            knee,
            thigh,
            theta5: FRAC_PI_2 + pitch + shank_tilt,
            reached,
            period: self.period,
        }
    }

    /// The least roll `ρ ≥ from` at which the leg, hip at `hip` with lateral offset `dz`, spans
    /// no more than a knee flexion of `knee` does (the foot rolls on until the knee is at least
    /// that flexed); `from` itself when it already is.
    pub fn roll_for_knee(&self, hip: [f64; 2], dz: f64, from: f64, knee: f64) -> f64 {
        let d_target = span_for(self.l3, self.l4, knee);
        let g = |r: f64| self.span_at(hip, dz, r) - d_target;
        let cap = (self.theta6_max + RHO_CAP).max(from);
        self.smallest(from, cap, g)
    }

    /// The hip–ankle distance (in the leg's plane, lateral offset `dz` included) at roll `rho`,
    /// m: the only part of [`VirtualLeg::pose_at`] the roll scans test. Why: those scans
    /// evaluate dozens of rolls per frame, and the full pose (two acos, two atan2, a sin/cos)
    /// was most of the walk's kinematics; this is the same arithmetic on the same rolled ankle,
    /// so the scans' answers are bit-identical.
    #[inline]
    fn span_at(&self, hip: [f64; 2], dz: f64, rho: f64) -> f64 {
        let (ankle, _, _) = self.foot.rolled(self.flat_ankle, rho, self.theta6_max);
        let dy = ((hip[1] - ankle[1]).powi(2) + dz * dz).sqrt();
        (hip[0] - ankle[0]).hypot(dy)
    }

    /// Finds the first `ρ ≥ lo` (continuing from `lo`, the previous roll) with `g(ρ) ≤ 0`: a
    /// scan in small increments, then bisection inside the increment — `g` need not be monotone,
    /// and the roll never jumps to a distant root.
    fn smallest(&self, lo: f64, hi: f64, g: impl Fn(f64) -> f64) -> f64 {
        let mut gb = g(lo);
        if gb <= 0.0 {
            return lo;
        }
        let step = 0.004;
        let (mut a, mut ga);
        let mut b = lo;
        loop {
            if b >= hi {
                return hi;
            }
            (a, ga) = (b, gb);
            b = (b + step).min(hi);
            gb = g(b);
            if gb <= 0.0 {
                break;
            }
        }
        root_from(&g, (a, ga), (b, gb))
    }

    /// Plans the heel rocker from the hip's path `samples` (`(t, hip, dz)` in time order, the
    /// leg's clock starting at heel strike with the leg's current roll `ρ = −pitch`).
    ///
    /// The paper lets the foot rotate about the heel with the knee straight until it is flat;
    /// taken literally (the largest roll the straight leg reaches) the foot slaps down within
    /// 2–5 frames of heel strike (KLAW's hip approaches the foot at ≈ 1 m/s just after the
    /// collision) and the knee snaps from straight to the flat period's flexion (continuity
    /// ratios 10–40). Here the *knee* is planned instead: from straight at heel strike it
    /// flexes along a cubic Hermite curve (leaving at the slowest of 1–3× its mean rate that
    /// works, or slower — down to rest, C¹ with the swing's locked knee — where the flat foot's
    /// knee rate exceeds the mean: slow walks) to the flat foot's knee
    /// flexion and rate at the end `T`; at each sample the roll is the one that puts the ankle
    /// at the distance that knee spans (clamped to the heel-strike pitch and to flat, never
    /// decreasing). At `T` the roll reaches 0 at rest (the flat foot's knee is met with its rate),
    /// so the foot lands without a slap. `T` is on a ×1.1 grid from `min_duration`, one for
    /// which the flat foot's ankle is then within the flat period's soft leg length (so it
    /// does not roll forward the moment it lands): of the shortest such `T` and the next
    /// [`ROCKER_SCAN`] ones, the one whose knee curve has the least peak acceleration (see
    /// there). The ankle is never out of reach (the knee
    /// only flexes). If no such `T` exists before the last sample, `rocker` stays `None` and the
    /// straight-leg rule is used. Returns whether a rocker was planned.
    pub fn plan_heel_rocker(
        &mut self,
        samples: &[(f64, [f64; 2], f64)],
        min_duration: f64,
    ) -> bool {
        self.rocker = None;
        if self.period != FootPeriod::HeelRocker || self.rho >= 0.0 || samples.len() < 3 {
            return false;
        }
        let d_flat: Vec<f64> = samples
            .iter()
            .map(|&(_, hip, dz)| {
                let p = self.pose_at(hip, dz, 0.0);
                let dy = ((hip[1] - p.ankle[1]).powi(2) + dz * dz).sqrt();
                (hip[0] - p.ankle[0]).hypot(dy)
            })
            .collect();
        // First the flat period's own soft leg length; failing that (slow walks, whose hip
        // never comes lower than about the straight leg: the foot is flat only in passing), any
        // landing within reach by 0.3 mm (then 0.03 mm), as early as 0.3 × `min_duration`, the
        // knee's soft straightening then narrowed so the flat foot does not roll forward the
        // moment it lands.
        let min_soft = 0.00015;
        for (soft, shortest, scan) in [
            (self.knee_soft, min_duration, ROCKER_SCAN),
            (min_soft, 0.3 * min_duration, ROCKER_SCAN),
            (0.1 * min_soft, 0.3 * min_duration, 0),
        ] {
            if self.plan_with(samples, shortest, soft, &d_flat, scan) {
                return true;
            }
        }
        false
    }

    fn plan_with(
        &mut self,
        samples: &[(f64, [f64; 2], f64)],
        min_duration: f64,
        soft: f64,
        d_flat: &[f64],
        scan: usize,
    ) -> bool {
        let (l3, l4) = (self.l3, self.l4);
        let l1 = l3 + l4;
        let pitch = -self.rho;
        let dist = |rho: f64, hip: [f64; 2], dz: f64| self.span_at(hip, dz, rho);
        // The flat period's soft leg length (see `span_max`).
        let a0 = self.span_max.min(l1) - 2.0 * soft;
        let t_first = samples[0].0;
        let mut duration = min_duration;
        let mut best: Option<(f64, HeelRocker, f64, f64)> = None;
        let mut left = usize::MAX;
        for _ in 0..30 {
            let kt = samples.partition_point(|s| s.0 < t_first + duration);
            if left == 0 || kt + 1 >= samples.len() {
                break;
            }
            duration *= 1.1;
            if d_flat[kt] > a0 || d_flat[kt - 1] > a0 || d_flat[kt + 1] > a0 {
                continue;
            }
            let end = samples[kt].0;
            let big_t = end - t_first;
            let k_end = knee_for(l3, l4, d_flat[kt]);
            let k_rate = (knee_for(l3, l4, d_flat[kt + 1]) - knee_for(l3, l4, d_flat[kt - 1]))
                / (samples[kt + 1].0 - samples[kt - 1].0);
            let knee_at = |t: f64, start_rate: f64| {
                let u = (t - t_first) / big_t;
                let h01 = (3.0 - 2.0 * u) * u * u;
                let h10 = ((u - 2.0) * u + 1.0) * u;
                let h11 = (u - 1.0) * u * u;
                k_end * h01 + big_t * (start_rate * h10 + k_rate * h11)
            };
            // The slowest start (mean rate × 1, 1.25, …, 3) whose knee stays at least as flexed
            // as the flat foot would make it: the foot then lands only at `end`.
            let valid = |f: f64| {
                let r0 = f * k_end / big_t;
                samples[..kt]
                    .iter()
                    .zip(d_flat)
                    .all(|(&(t, _, _), &df)| knee_at(t, r0) >= knee_for(l3, l4, df.min(l1)) - 1e-6)
            };
            let Some(f_mean) = [1.0, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0]
                .into_iter()
                .find(|&f| valid(f))
            else {
                continue;
            };
            let table_for = |f: f64| {
                let start_rate = f * k_end / big_t;
                let mut table = Vec::with_capacity(kt);
                let mut last = -pitch;
                for &(t, hip, dz) in &samples[..kt] {
                    let knee = knee_at(t, start_rate);
                    let target = span_for(l3, l4, knee.max(0.0)).min(l1);
                    let g = |r: f64| dist(r, hip, dz) - target;
                    let r = if g(0.0) <= 0.0 {
                        0.0
                    } else if g(-pitch) >= 0.0 {
                        -pitch
                    } else {
                        root_nonpositive_side(&g, 0.0, -pitch)
                    };
                    last = r.max(last);
                    table.push((t, last));
                }
                table
            };
            // When the flat foot's knee rate at `end` exceeds the mean rate (slow walks: the hip
            // still descends as the foot lands) the knee leaves heel strike at the slowest valid
            // rate below the mean, down to rest (C¹ with the swing's locked knee), unless the
            // landing is already within ×1.2 of its shortest (why: docs/klaw.md).
            let mut f = f_mean;
            if self.slow_knee_start
                && f_mean == 1.0
                && k_rate * big_t > k_end
                && big_t >= 1.2 * min_duration
            {
                for slower in [0.75, 0.5, 0.25, 0.0] {
                    if !valid(slower) {
                        break;
                    }
                    f = slower;
                }
            }
            let table = table_for(f);
            let landing = d_flat[kt - 1].max(d_flat[kt]).max(d_flat[kt + 1]);
            // The Hermite's second derivative at its ends (see `ROCKER_SCAN`).
            let r0 = f * k_end / big_t;
            let acc0 = (6.0 * k_end - big_t * (4.0 * r0 + 2.0 * k_rate)) / (big_t * big_t);
            let acc1 = (-6.0 * k_end + big_t * (2.0 * r0 + 4.0 * k_rate)) / (big_t * big_t);
            let cost = acc0.abs().max(acc1.abs());
            if best.as_ref().is_none_or(|b| cost < b.0) {
                best = Some((cost, HeelRocker { end, table }, landing, soft));
            }
            left = left.min(scan + 1) - 1;
        }
        let Some((_, rocker, landing, soft)) = best else {
            return false;
        };
        self.rocker = Some(rocker);
        self.knee_soft = self.knee_soft.min(soft.max(0.5 * (l1 - landing)));
        true
    }

    /// Advances the rules to time `t` (leg clock) with the hip at `hip` and lateral offset `dz`
    /// and returns the configuration. Calls must come in time order.
    pub fn advance(&mut self, t: f64, hip: [f64; 2], dz: f64) -> LegPose {
        let l1 = self.l3 + self.l4;
        // How far `leg`'s ankle at roll `r` is beyond the straight leg's reach, m.
        let reach = |leg: &VirtualLeg, r: f64| leg.span_at(hip, dz, r) - l1;
        if self.period == FootPeriod::HeelRocker {
            if let Some((end, rho)) = self.rocker.as_ref().map(|r| (r.end, r.rho_at(t))) {
                if t < end {
                    self.rho = rho.max(self.rho);
                    return self.pose_at(hip, dz, self.rho);
                }
                self.period = FootPeriod::Flat;
                self.rho = 0.0;
                self.transitions[0] = Some(end);
            }
        }
        if self.period == FootPeriod::HeelRocker {
            // Largest ρ ≤ 0 within reach of the straight leg: reach(ρ) increases with ρ here.
            let g = |r: f64| reach(self, r);
            let gap = g(0.0);
            // The hip has passed its closest approach to the flat ankle, which stayed just out of
            // the straight leg's reach, and the held roll is out of reach too: the foot rocks
            // through flat onto its ball (foot flat and heel off at once), where the heel-off
            // rule keeps the ankle within reach, instead of hovering pitched a little up and
            // being lifted off the ground by the straight leg (why: docs/klaw.md).
            let rocks_over = self.rocker_gap.is_some_and(|last| gap > last) && g(self.rho) > 0.0;
            if gap <= 0.0 || rocks_over {
                self.period = FootPeriod::Flat;
                self.rho = 0.0;
                self.transitions[0] = Some(t);
                // The straight leg lands the foot (no planned rocker: slow walks, whose hip
                // never comes within the straight leg's reach of the flat ankle).
            } else {
                let a = -1.2;
                // Out of reach even steeply pitched: hold the roll (pitching the foot up to
                // the bound, 69°, and snapping it down later is no help to the leg).
                if g(a) <= 0.0 {
                    self.rho = root_nonpositive_side(&g, 0.0, a).max(self.rho);
                }
                self.rocker_gap = Some(gap);
                let mut p = self.pose_at(hip, dz, self.rho);
                p.period = self.period;
                return p;
            }
        }
        let cap = self.theta6_max + RHO_CAP;
        if self.period != FootPeriod::MetaOff {
            // Normal (flat) and heel-off: the least roll that keeps the ankle within reach of the
            // leg (so the knee straightens before the heel rises, as in late stance). The normal
            // period ends — heel-off begins — when θ5 reaches its dorsiflexion limit or the foot
            // must roll, whichever comes first.
            // The knee straightens smoothly: the leg's length is the soft reach
            // (`ik::soft_reach`) of the hip–flat-ankle distance, saturating at l − σ (a knee
            // flexion of about 5° at σ = 1.5 mm for l = l1), so the knee comes to rest without a
            // kink; l = `span_max` (l1, or the shorter locked leg at speed).
            let d_flat = reach(self, 0.0) + l1;
            let sigma = self.knee_soft;
            let lm = self.span_max.min(l1);
            let d_t = crate::generator::ik::soft_reach(d_flat, lm, sigma);
            // `reach(r) + l1`, not the span itself: the same rounding as before the scans
            // stopped evaluating the whole pose.
            let g = |r: f64| reach(self, r) + l1 - d_t;
            let lo = self.rho.max(0.0);
            let rho = self.smallest(lo, cap, g);
            if self.period == FootPeriod::Flat
                && (rho > 0.0 || self.pose_at(hip, dz, rho).theta5 >= self.theta5_max)
            {
                self.period = FootPeriod::HeelOff;
                self.transitions[1] = Some(t);
            }
            // Meta-off begins where the ball leaves the ground: the start of the forefoot → toe
            // rocker blend of `FootShape::rolled`, δ before the toe bend's limit.
            let meta_off_rho = self.theta6_max - toe_blend(self.theta6_max);
            if rho <= meta_off_rho {
                self.rho = rho;
                let mut p = self.pose_at(hip, dz, rho);
                p.period = self.period;
                return p;
            }
            // The toe bend reached its limit: meta-off.
            if self.period == FootPeriod::Flat {
                self.transitions[1] = Some(t);
            }
            self.period = FootPeriod::MetaOff;
            self.transitions[2] = Some(t);
            // Start from the roll the heel-off rule found for this sample (a little past
            // `meta_off_rho`, by at most one sample's roll), not from `meta_off_rho` itself:
            // dropping back to it moved the ankle away from the hip within one 2 ms sample
            // (docs/klaw.md).
            self.rho = rho.max(self.rho);
            let p = self.pose_at(hip, dz, self.rho);
            self.meta_start = Some((t, p.knee));
        }
        // Meta-off: the knee flexes (C¹ blend) toward its toe-off value; the foot rolls about the
        // toe tip just enough to close the chain.
        let (t_ms, knee_ms) = self.meta_start.unwrap_or((t, 0.0));
        let big_t = (self.toe_off_time - t_ms)
            .max(self.min_knee_blend)
            .max(1e-6);
        let u = ((t - t_ms) / big_t).clamp(0.0, 1.0);
        let delta = self.knee_toe_off - knee_ms;
        // A blend of the smoothstep (which ends at rest) and u² (which ends at 2Δ/T), so the knee
        // flexes at min(2Δ/T, toe_off_knee_rate) at toe-off: the swing starts from that rate.
        let ease = if delta.abs() > 1e-9 {
            (self.toe_off_knee_rate * big_t / (2.0 * delta.abs())).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let s = (1.0 - ease) * smoothstep(u) + ease * u * u;
        let knee = knee_ms + (self.knee_toe_off - knee_ms) * s;
        let (l3, l4) = (self.l3, self.l4);
        let d_target = (l3 * l3 + l4 * l4 + 2.0 * l3 * l4 * knee.cos()).sqrt();
        let g = |r: f64| self.span_at(hip, dz, r) - d_target;
        let rho = self.smallest(self.rho, cap.max(self.rho), g);
        self.rho = rho;
        let mut p = self.pose_at(hip, dz, rho);
        p.period = self.period;
        p
    }
}

/// Test fixture: `body`'s virtual leg with the default attributes (θ5max 100°, θ6max 30°, knee
/// at toe off 35°) in `period` at roll `rho`, toe-off at 1 s, nothing planned yet.
#[cfg(test)]
pub(crate) fn test_leg(body: &Body, period: FootPeriod, rho: f64) -> VirtualLeg {
    let mut leg = VirtualLeg::new(
        FootShape::new(body),
        body,
        &WalkAttributes::default(),
        0.0,
        period,
        rho,
    );
    leg.toe_off_time = 1.0;
    leg
}

#[cfg(test)]
mod tests {
    use super::*;

    use super::test_leg as leg;

    /// A hip that lands behind the foot with the straight leg reaching the pitched ankle, then
    /// moves forward and down (as KLAW's does after the collision): the flat foot comes within
    /// reach after a few milliseconds.
    fn hip_path(body: &Body, pitch: f64) -> Vec<(f64, [f64; 2], f64)> {
        let l = leg(body, FootPeriod::HeelRocker, -pitch);
        let (ankle, _, _) = l.foot.rolled(l.flat_ankle, -pitch, l.theta6_max);
        let a = 22f64.to_radians();
        let l1 = body.l3 + body.l4;
        let hip0 = [ankle[0] - l1 * a.sin(), ankle[1] + l1 * a.cos()];
        (0..=250)
            .map(|i| {
                let t = 0.002 * i as f64;
                let drop = 0.03 * (1.0 - (-t / 0.05).exp());
                (t, [hip0[0] + 1.3 * t, hip0[1] - drop], 0.0)
            })
            .collect()
    }

    /// Peak knee acceleration (second differences of the drawn knee over 2 ms samples) of a
    /// leg advanced through `hips` up to its planned landing, and that landing.
    fn drawn_knee_peak_acc(mut l: VirtualLeg, hips: &[(f64, [f64; 2], f64)]) -> (f64, f64) {
        let end = l.rocker.as_ref().unwrap().end;
        let knees: Vec<f64> = hips
            .iter()
            .take_while(|h| h.0 <= end)
            .map(|h| l.advance(h.0, h.1, h.2).knee)
            .collect();
        let peak = knees
            .windows(3)
            .map(|w| ((w[2] - 2.0 * w[1] + w[0]) / 0.002f64.powi(2)).abs())
            .fold(0.0, f64::max);
        (peak, end)
    }

    #[test]
    fn a_shorter_span_keeps_the_knee_flexed_and_raises_the_heel() {
        let body = Body::from_height(1.8, 75.0).unwrap();
        let mut leg = test_leg(&body, FootPeriod::Flat, 0.0);
        let full = leg.l3 + leg.l4;
        leg.span_max = full - 0.012;
        let sigma = leg.knee_soft;
        let [x, y] = leg.flat_ankle;
        // Within the shorter span: the foot flat, the knee spanning the hip–ankle distance.
        // The hip behind the ankle (the shank about vertical, θ5 below its limit).
        let back = 0.15;
        let hip = |d: f64| [x - back, y + (d * d - back * back).sqrt()];
        let d = leg.span_max - 3.0 * sigma;
        let p = leg.advance(0.0, hip(d), 0.0);
        assert_eq!(p.period, FootPeriod::Flat);
        assert!(p.rho == 0.0 && (p.knee - knee_for(leg.l3, leg.l4, d)).abs() < 1e-9);
        // Beyond it (still within the straight leg's reach): the knee keeps the shorter span's
        // flexion and the heel rises instead.
        let p = leg.advance(0.01, hip(leg.span_max + 0.005), 0.0);
        assert_eq!(p.period, FootPeriod::HeelOff);
        assert!(p.rho > 0.0);
        let k = knee_for(leg.l3, leg.l4, leg.span_max - sigma);
        assert!((p.knee - k).abs() < 1e-6, "knee {} against {k}", p.knee);
        assert!(k > 0.2, "{k}");
    }

    #[test]
    fn the_rocker_lands_where_its_knee_accelerates_least() {
        let body = Body::from_height(1.8, 75.0).unwrap();
        let pitch = 0.35;
        let hips = hip_path(&body, pitch);
        let d_flat: Vec<f64> = {
            let l = leg(&body, FootPeriod::HeelRocker, -pitch);
            hips.iter()
                .map(|&(_, hip, dz)| {
                    let p = l.pose_at(hip, dz, 0.0);
                    (hip[0] - p.ankle[0]).hypot(((hip[1] - p.ankle[1]).powi(2) + dz * dz).sqrt())
                })
                .collect()
        };
        let mut shortest = leg(&body, FootPeriod::HeelRocker, -pitch);
        assert!(shortest.plan_with(&hips, 0.04, KNEE_SOFT, &d_flat, 0));
        let mut scanned = leg(&body, FootPeriod::HeelRocker, -pitch);
        assert!(scanned.plan_with(&hips, 0.04, KNEE_SOFT, &d_flat, ROCKER_SCAN));
        let (acc_short, end_short) = drawn_knee_peak_acc(shortest, &hips);
        let (acc_scan, end_scan) = drawn_knee_peak_acc(scanned, &hips);
        // Lands later (within the scan's ×1.1⁴ of the grid), its knee accelerating less.
        assert!(
            end_scan > end_short && end_scan <= 1.1f64.powi(5) * end_short,
            "{end_short} → {end_scan}"
        );
        assert!(
            acc_scan < 0.8 * acc_short,
            "{acc_short} → {acc_scan} rad/s²"
        );
    }

    #[test]
    fn planned_heel_rocker_stays_in_reach_and_lands_flat_at_rest() {
        let body = Body::from_height(1.8, 75.0).unwrap();
        let pitch = 0.35;
        let hips = hip_path(&body, pitch);
        let l1 = body.l3 + body.l4;
        // The straight-leg rule: the foot slaps down and the knee snaps.
        let mut rule = leg(&body, FootPeriod::HeelRocker, -pitch);
        let rule_poses: Vec<LegPose> = hips.iter().map(|h| rule.advance(h.0, h.1, h.2)).collect();
        let flat_rule = rule.transitions[0].unwrap();
        let mut planned = leg(&body, FootPeriod::HeelRocker, -pitch);
        assert!(planned.plan_heel_rocker(&hips, 0.08));
        let end = planned.rocker.as_ref().unwrap().end;
        assert!(end >= 0.08 && end > flat_rule, "{end} {flat_rule}");
        let poses: Vec<LegPose> = hips
            .iter()
            .map(|h| planned.advance(h.0, h.1, h.2))
            .collect();
        assert_eq!(planned.transitions[0], Some(end));
        let mut prev_rho = -pitch;
        let mut max_dk: f64 = 0.0;
        let mut max_drho: f64 = 0.0;
        for (h, p) in hips.iter().zip(&poses) {
            // Within reach of the leg, the roll never decreasing.
            let d = (h.1[0] - p.ankle[0]).hypot(h.1[1] - p.ankle[1]);
            assert!(d <= l1 + 1e-9, "out of reach by {} at t = {}", d - l1, h.0);
            assert!(p.rho >= prev_rho - 1e-12);
            if h.0 <= end {
                max_drho = max_drho.max(p.rho - prev_rho);
            }
            prev_rho = p.rho;
        }
        for w in poses.windows(2) {
            max_dk = max_dk.max((w[1].knee - w[0].knee).abs());
        }
        // The roll arrives at 0 at rest: the last increment before flat is a small fraction of
        // the largest.
        let k_end = hips.iter().position(|h| h.0 >= end).unwrap();
        let last_inc = poses[k_end].rho - poses[k_end - 1].rho;
        assert!(last_inc <= 0.05 * max_drho, "{last_inc} vs {max_drho}");
        // The knee flexes without the rule's snap: its largest 2 ms change is well below the
        // straight-leg rule's.
        let max_dk_rule = rule_poses
            .windows(2)
            .map(|w| (w[1].knee - w[0].knee).abs())
            .fold(0.0, f64::max);
        assert!(max_dk < 0.5 * max_dk_rule, "{max_dk} vs rule {max_dk_rule}");
    }

    #[test]
    fn meta_off_knee_reaches_toe_off_flexing_at_the_capped_rate() {
        // A hip held still ahead of the foot; meta-off from t = 0 (knee 0.1 rad) to toe-off at
        // T: the knee flexes from rest to 35° and arrives at min(2Δ/T, TOE_OFF_KNEE_RATE).
        let body = Body::from_height(1.8, 75.0).unwrap();
        for (big_t, want) in [(0.1, TOE_OFF_KNEE_RATE), (0.4, 2.0 * (0.6109 - 0.1) / 0.4)] {
            let mut l = leg(&body, FootPeriod::MetaOff, 0.4);
            l.meta_start = Some((0.0, 0.1));
            l.toe_off_time = big_t;
            // The hip ahead of the trailing foot, at the start's knee span from its ankle.
            let (ankle, _, _) = l.foot.rolled(l.flat_ankle, 0.4, l.theta6_max);
            let d0 = span_for(l.l3, l.l4, 0.1);
            let a = 25f64.to_radians();
            let hip = [ankle[0] + d0 * a.sin(), ankle[1] + d0 * a.cos()];
            let h = 1e-4;
            let n = (big_t / h).round() as usize;
            let knees: Vec<f64> = (0..=n)
                .map(|i| l.advance(i as f64 * h, hip, 0.0).knee)
                .collect();
            let end_rate = (knees[n] - knees[n - 1]) / h;
            let start_rate = (knees[1] - knees[0]) / h;
            assert!((knees[n] - 35f64.to_radians()).abs() < 1e-3, "{}", knees[n]);
            assert!(
                (end_rate - want).abs() < 0.05 * want,
                "{end_rate} vs {want}"
            );
            assert!(start_rate.abs() < 0.05, "{start_rate}");
        }
    }
}
