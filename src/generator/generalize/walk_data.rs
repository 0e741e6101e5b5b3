//! Walk data W(S, sl) = {H, F₁, F₂, F₃, M, A} (Ko & Badler 1993, §3 eq. 4), its timed
//! sequences with linear interpolation (eqs. 1–2), the gait moments FGM, MOM and TOM, and the
//! anthropometry B(S) of Table 2.
//!
//! Frame and time conventions (SI inside: metres, radians):
//! - time is normalized step time, HSM⁻ = 0 and HSM⁺ = 1 (§3);
//! - positions are in the *step frame*: x forward from the floor contact point of the stance
//!   heel at HSM⁻, y up from the floor;
//! - foot (sole) angles are signed, positive when the toes are up (as at heel strike) and
//!   negative when the heel is up (as at toe off); meta angles are positive when the metatarsal
//!   heads are above the toe tip.
//!
//! The sequences are laid out per *foot*, as the paper's F₁–F₃ continuity conditions
//! (t₁ₙ₁ = t₂₁, t₂ₙ₂ = t₃₁) require: F₁ is the stance foot on [0, FGM], F₂ the same foot on
//! [FGM, 1 + TOM] (its toe off falls in the next step, where it is the swing foot), F₃ and A the
//! swing foot on [TOM, 1], and M the stance foot's meta angle on [MOM, 1 + TOM]. Times past 1
//! belong to the next step: the paper writes t₂ₙ₂ = t₃₁, which holds modulo one step.
use crate::generator::GenerateError;

/// A timed sequence Q = {(tᵢ, vᵢ)} with strictly increasing times (eq. 1).
#[derive(Debug, Clone, PartialEq)]
pub struct TimedSequence<const D: usize> {
    times: Vec<f64>,
    values: Vec<[f64; D]>,
}

/// A scalar timed sequence (angles).
pub type AngleSequence = TimedSequence<1>;
/// A planar timed sequence (hip and ankle trajectories).
pub type PathSequence = TimedSequence<2>;

impl<const D: usize> TimedSequence<D> {
    /// Builds a timed sequence; `what` names it in errors. Needs at least two samples, finite
    /// values and strictly increasing times (eq. 1).
    pub fn new(what: &str, times: Vec<f64>, values: Vec<[f64; D]>) -> Result<Self, GenerateError> {
        if times.len() != values.len() {
            return Err(param(
                what,
                times.len() as f64,
                &format!("{} times but {} values", times.len(), values.len()),
            ));
        }
        if times.len() < 2 {
            return Err(param(
                what,
                times.len() as f64,
                "a timed sequence needs at least two samples",
            ));
        }
        for (i, (t, v)) in times.iter().zip(&values).enumerate() {
            if !t.is_finite() || v.iter().any(|x| !x.is_finite()) {
                return Err(param(what, *t, &format!("sample {i} is not finite")));
            }
            if i > 0 && *t <= times[i - 1] {
                return Err(param(
                    what,
                    *t,
                    &format!(
                        "sample {i}: time {t} does not follow {} (times must increase strictly)",
                        times[i - 1]
                    ),
                ));
            }
        }
        Ok(TimedSequence { times, values })
    }

    /// The sample times tᵢ.
    pub fn times(&self) -> &[f64] {
        &self.times
    }
    /// The values vᵢ.
    pub fn values(&self) -> &[[f64; D]] {
        &self.values
    }
    /// Number of samples n.
    pub fn len(&self) -> usize {
        self.times.len()
    }
    /// Always false (a timed sequence has at least two samples); for clippy's `len` convention.
    pub fn is_empty(&self) -> bool {
        self.times.is_empty()
    }
    /// First time t₁.
    pub fn t_first(&self) -> f64 {
        self.times[0]
    }
    /// Last time tₙ.
    pub fn t_last(&self) -> f64 {
        self.times[self.times.len() - 1]
    }
    /// First value v₁.
    pub fn first(&self) -> [f64; D] {
        self.values[0]
    }
    /// Last value vₙ.
    pub fn last(&self) -> [f64; D] {
        self.values[self.values.len() - 1]
    }

    /// `interpolation(Q, t)` of eq. 2. Outside [t₁, tₙ] the end value is held (the generator
    /// never asks there; holding keeps evaluation total).
    pub fn interpolate(&self, t: f64) -> [f64; D] {
        let n = self.times.len();
        if t <= self.times[0] {
            return self.values[0];
        }
        if t >= self.times[n - 1] {
            return self.values[n - 1];
        }
        // First index with times[i] > t; t lies in [times[i-1], times[i]).
        let i = self.times.partition_point(|&ti| ti <= t);
        let (t0, t1) = (self.times[i - 1], self.times[i]);
        let w = (t - t0) / (t1 - t0);
        let (a, b) = (self.values[i - 1], self.values[i]);
        let mut out = [0.0; D];
        for k in 0..D {
            out[k] = a[k] + w * (b[k] - a[k]);
        }
        out
    }

    /// The same times with every value mapped by `f(tᵢ, vᵢ)` (times are invariant under both
    /// generalizations).
    pub(crate) fn map(&self, mut f: impl FnMut(f64, [f64; D]) -> [f64; D]) -> Self {
        TimedSequence {
            times: self.times.clone(),
            values: self
                .times
                .iter()
                .zip(&self.values)
                .map(|(&t, &v)| f(t, v))
                .collect(),
        }
    }
}

impl TimedSequence<1> {
    /// Scalar convenience: `interpolation(Q, t)` of a one-dimensional sequence.
    pub fn at(&self, t: f64) -> f64 {
        self.interpolate(t)[0]
    }
}

fn param(name: &str, value: f64, message: &str) -> GenerateError {
    GenerateError::Parameter {
        name: name.to_string(),
        value,
        message: message.to_string(),
    }
}

/// The anthropometry B(S) that the generalization uses (Table 2), in metres: the two leg
/// segments and the foot. The foot is the rigid triangle heel–ankle–ball plus a toe segment
/// hinged at the ball; N is the foot of the perpendicular from the ankle onto the sole line
/// (heel–ball), so `heel_to_n + ball_to_n` is the heel-to-ball length.
///
/// The toe hinge (metatarsal joint) may sit `ball_height` above the sole, straight above the
/// ball sole point, as in gaitfit's figure ([`crate::generator::skeleton`]); Table 2's foot and
/// the marker-built prototype hinge on the sole (height 0, the default).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Anthropometry {
    thigh: f64,
    shin: f64,
    heel_to_n: f64,
    ball_to_n: f64,
    ankle_to_n: f64,
    ball_to_toe: f64,
    ball_height: f64,
}

impl Anthropometry {
    /// Validated constructor; every length must be positive and finite (metres).
    pub fn new(
        thigh: f64,
        shin: f64,
        heel_to_n: f64,
        ball_to_n: f64,
        ankle_to_n: f64,
        ball_to_toe: f64,
    ) -> Result<Self, GenerateError> {
        for (name, v) in [
            ("thigh", thigh),
            ("shin", shin),
            ("heel_to_n", heel_to_n),
            ("ball_to_n", ball_to_n),
            ("ankle_to_n", ankle_to_n),
            ("ball_to_toe", ball_to_toe),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(param(
                    name,
                    v,
                    "a segment length must be positive and finite (m)",
                ));
            }
        }
        Ok(Anthropometry {
            thigh,
            shin,
            heel_to_n,
            ball_to_n,
            ankle_to_n,
            ball_to_toe,
            ball_height: 0.0,
        })
    }

    /// The same body with the toe hinge `h` above the sole (m, ≥ 0, below the ankle).
    pub fn with_ball_height(mut self, h: f64) -> Result<Self, GenerateError> {
        if !(h.is_finite() && h >= 0.0 && h < self.ankle_to_n) {
            return Err(param(
                "ball_height",
                h,
                "the toe hinge must lie between the sole and the ankle's height (m)",
            ));
        }
        self.ball_height = h;
        Ok(self)
    }

    /// The generalization's view of gaitfit's figure: thigh and shank lengths, and the foot of
    /// [`crate::generator::anthropometry::FootGeometry`] (heel → ankle l₈, ankle height l₉,
    /// ankle → metatarsal l₅, metatarsal → toe l₆, metatarsal joint height).
    pub fn from_figure(
        a: &crate::generator::anthropometry::Anthropometry,
    ) -> Result<Self, GenerateError> {
        let f = &a.foot;
        Anthropometry::new(
            a.thigh.length_m,
            a.shank.length_m,
            f.hind_foot_m,
            f.mid_foot_m,
            f.ankle_height_m,
            f.toe_m,
        )?
        .with_ball_height(f.metatarsal_height_m)
    }

    /// Thigh length, hip to knee (m).
    pub fn thigh(&self) -> f64 {
        self.thigh
    }
    /// Shin length, knee to ankle (m).
    pub fn shin(&self) -> f64 {
        self.shin
    }
    /// Heel to N along the sole (m).
    pub fn heel_to_n(&self) -> f64 {
        self.heel_to_n
    }
    /// Ball to N along the sole (m).
    pub fn ball_to_n(&self) -> f64 {
        self.ball_to_n
    }
    /// Ankle to N: the ankle's height above the sole line (m). Its difference between two
    /// bodies is the ΔaN of eq. 44.
    pub fn ankle_to_n(&self) -> f64 {
        self.ankle_to_n
    }
    /// Ball to toe tip along the sole (m).
    pub fn ball_to_toe(&self) -> f64 {
        self.ball_to_toe
    }
    /// Height of the toe hinge (metatarsal joint) above the sole (m).
    pub fn ball_height(&self) -> f64 {
        self.ball_height
    }
    /// Leg length ll(S) = thigh + shin (§3).
    pub fn leg_length(&self) -> f64 {
        self.thigh + self.shin
    }
    /// Heel to ball (m).
    pub fn heel_to_ball(&self) -> f64 {
        self.heel_to_n + self.ball_to_n
    }
    /// Ankle to heel (m).
    pub fn ankle_to_heel(&self) -> f64 {
        self.heel_to_n.hypot(self.ankle_to_n)
    }
    /// Ankle to ball (m).
    pub fn ankle_to_ball(&self) -> f64 {
        self.ball_to_n.hypot(self.ankle_to_n)
    }
    /// Interior angle of the foot triangle at the heel (rad).
    pub fn heel_angle(&self) -> f64 {
        self.ankle_to_n.atan2(self.heel_to_n)
    }
    /// Interior angle of the foot triangle at the ball (rad).
    pub fn ball_angle(&self) -> f64 {
        self.ankle_to_n.atan2(self.ball_to_n)
    }
    /// Interior angle of the foot triangle at the ankle (rad).
    pub fn ankle_angle(&self) -> f64 {
        std::f64::consts::PI - self.heel_angle() - self.ball_angle()
    }
    /// αS: every length times `alpha` (§3).
    pub fn scaled(&self, alpha: f64) -> Result<Self, GenerateError> {
        Anthropometry::new(
            alpha * self.thigh,
            alpha * self.shin,
            alpha * self.heel_to_n,
            alpha * self.ball_to_n,
            alpha * self.ankle_to_n,
            alpha * self.ball_to_toe,
        )?
        .with_ball_height(alpha * self.ball_height)
    }
    /// S₂/S₁ of eq. 3: the leg-length ratio ll(S₂)/ll(S₁).
    pub fn ratio_to(&self, other: &Anthropometry) -> f64 {
        self.leg_length() / other.leg_length()
    }
}

/// The moments of one step in normalized step time (§3): FGM (stance foot flat), MOM (stance
/// foot's meta off, possibly in the next step, so in (FGM, 1 + TOM)) and TOM (toe off, as the
/// swing foot's time in this step, in (0, 1); the stance foot's own toe off is at 1 + TOM).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Moments {
    fgm: f64,
    mom: f64,
    tom: f64,
}

impl Moments {
    /// Validated constructor: 0 < FGM < 1 + TOM, 0 < TOM < 1, FGM < MOM < 1 + TOM.
    pub fn new(fgm: f64, mom: f64, tom: f64) -> Result<Self, GenerateError> {
        if !(tom.is_finite() && tom > 0.0 && tom < 1.0) {
            return Err(param(
                "TOM",
                tom,
                "toe off must lie inside the step, in (0, 1)",
            ));
        }
        if !(fgm.is_finite() && fgm > 0.0 && fgm < 1.0) {
            return Err(param(
                "FGM",
                fgm,
                "foot flat must lie inside the step, in (0, 1)",
            ));
        }
        if !(mom.is_finite() && mom > fgm && mom < 1.0 + tom) {
            return Err(param(
                "MOM",
                mom,
                &format!(
                    "meta off must lie in (FGM, 1 + TOM) = ({fgm}, {})",
                    1.0 + tom
                ),
            ));
        }
        Ok(Moments { fgm, mom, tom })
    }
    /// Flat ground moment.
    pub fn fgm(&self) -> f64 {
        self.fgm
    }
    /// Meta off moment of the stance foot (may exceed 1).
    pub fn mom(&self) -> f64 {
        self.mom
    }
    /// Toe off moment of the swing foot in this step.
    pub fn tom(&self) -> f64 {
        self.tom
    }
}

/// Walk data W(S, sl) (eq. 4) of subject S stepping sl after a step of length sl_before.
///
/// The paper's W(S, sl) does not name sl_before, but eqs. 28 and 32 use it: a step's hip
/// travel and its initial heel-strike foot angle depend on the step before. Carrying it makes
/// every step renderable on its own and lets steps of different lengths chain continuously.
#[derive(Debug, Clone, PartialEq)]
pub struct WalkData {
    pub(crate) body: Anthropometry,
    pub(crate) step_length: f64,
    pub(crate) step_length_before: f64,
    pub(crate) moments: Moments,
    pub(crate) hip: PathSequence,
    pub(crate) foot1: AngleSequence,
    pub(crate) foot2: AngleSequence,
    pub(crate) foot3: AngleSequence,
    pub(crate) meta: AngleSequence,
    pub(crate) ankle: PathSequence,
}

/// Tolerance (in normalized time) for the sequences' end times to match the moments.
const TIME_TOL: f64 = 1e-9;

impl WalkData {
    /// Validated constructor. The sequences must span their intervals: H [0, 1], F₁ [0, FGM],
    /// F₂ [FGM, 1 + TOM], F₃ [TOM, 1], M [MOM, 1 + TOM], A [TOM, 1]; F₁ ≥ 0, F₂ ≤ 0 and M ≥ 0
    /// (the pivot of the stance foot follows from the sign), and F₁ must end and F₂ and M start
    /// at 0 (foot flat, toes flat).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        body: Anthropometry,
        step_length: f64,
        step_length_before: f64,
        moments: Moments,
        hip: PathSequence,
        foot1: AngleSequence,
        foot2: AngleSequence,
        foot3: AngleSequence,
        meta: AngleSequence,
        ankle: PathSequence,
    ) -> Result<Self, GenerateError> {
        for (name, v) in [
            ("step_length", step_length),
            ("step_length_before", step_length_before),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(param(
                    name,
                    v,
                    "a step length must be positive and finite (m)",
                ));
            }
        }
        let m = moments;
        let spans: [(&str, f64, f64, f64, f64); 6] = [
            ("H", hip.t_first(), hip.t_last(), 0.0, 1.0),
            ("F1", foot1.t_first(), foot1.t_last(), 0.0, m.fgm),
            ("F2", foot2.t_first(), foot2.t_last(), m.fgm, 1.0 + m.tom),
            ("F3", foot3.t_first(), foot3.t_last(), m.tom, 1.0),
            ("M", meta.t_first(), meta.t_last(), m.mom, 1.0 + m.tom),
            ("A", ankle.t_first(), ankle.t_last(), m.tom, 1.0),
        ];
        for (name, a, b, want_a, want_b) in spans {
            if (a - want_a).abs() > TIME_TOL || (b - want_b).abs() > TIME_TOL {
                return Err(param(
                    name,
                    a,
                    &format!("spans [{a}, {b}] but must span [{want_a}, {want_b}]"),
                ));
            }
        }
        let sign_checks: [(&str, &AngleSequence, f64); 3] =
            [("F1", &foot1, 1.0), ("F2", &foot2, -1.0), ("M", &meta, 1.0)];
        for (name, seq, sign) in sign_checks {
            if let Some((i, v)) = seq
                .values()
                .iter()
                .enumerate()
                .find(|(_, v)| v[0] * sign < 0.0)
            {
                return Err(param(
                    name,
                    v[0],
                    &format!(
                        "sample {i} has the wrong sign (F1 and M must be ≥ 0, F2 ≤ 0: the sign \
                         chooses the stance foot's pivot)"
                    ),
                ));
            }
        }
        for (name, v) in [
            ("F1 at FGM", foot1.last()[0]),
            ("F2 at FGM", foot2.first()[0]),
            ("M at MOM", meta.first()[0]),
        ] {
            if v != 0.0 {
                return Err(param(name, v, "must be exactly 0 (foot flat / toes flat)"));
            }
        }
        // The generalizations divide by these (eqs. 32, 33, 36, 39).
        for (name, v, ok) in [
            ("F1 at HSM-", foot1.first()[0], foot1.first()[0] > 0.0),
            ("F2 at TOM", foot2.last()[0], foot2.last()[0] < 0.0),
            ("M at TOM", meta.last()[0], meta.last()[0] > 0.0),
            (
                "A forward travel",
                ankle.last()[0] - ankle.first()[0],
                ankle.last()[0] > ankle.first()[0],
            ),
        ] {
            if !ok {
                return Err(param(
                    name,
                    v,
                    "must be non-zero with its walking sign (F1 > 0 at heel strike, F2 < 0 and \
                     M > 0 at toe off, the swing ankle moving forward)",
                ));
            }
        }
        Ok(WalkData {
            body,
            step_length,
            step_length_before,
            moments,
            hip,
            foot1,
            foot2,
            foot3,
            meta,
            ankle,
        })
    }

    /// The subject's anthropometry B(S).
    pub fn body(&self) -> &Anthropometry {
        &self.body
    }
    /// Step length sl (m).
    pub fn step_length(&self) -> f64 {
        self.step_length
    }
    /// Length of the step before, sl_before (m).
    pub fn step_length_before(&self) -> f64 {
        self.step_length_before
    }
    /// FGM, MOM and TOM.
    pub fn moments(&self) -> &Moments {
        &self.moments
    }
    /// H: hip trajectory on [0, 1] (step frame, m).
    pub fn hip(&self) -> &PathSequence {
        &self.hip
    }
    /// F₁: stance foot angle on [0, FGM] (rad, ≥ 0).
    pub fn foot1(&self) -> &AngleSequence {
        &self.foot1
    }
    /// F₂: stance foot angle on [FGM, 1 + TOM] (rad, ≤ 0).
    pub fn foot2(&self) -> &AngleSequence {
        &self.foot2
    }
    /// F₃: swing foot angle on [TOM, 1] (rad).
    pub fn foot3(&self) -> &AngleSequence {
        &self.foot3
    }
    /// M: stance foot meta angle on [MOM, 1 + TOM] (rad, ≥ 0).
    pub fn meta(&self) -> &AngleSequence {
        &self.meta
    }
    /// A: swing ankle trajectory on [TOM, 1] (step frame, m).
    pub fn ankle(&self) -> &PathSequence {
        &self.ankle
    }

    /// Largest absolute difference between two walk data sets over every number they hold
    /// (lengths, moments, times and values); `None` if their shapes differ. The theorem tests
    /// compare generalizations with it.
    pub fn max_abs_diff(&self, other: &WalkData) -> Option<f64> {
        fn seq<const D: usize>(a: &TimedSequence<D>, b: &TimedSequence<D>) -> Option<f64> {
            if a.len() != b.len() {
                return None;
            }
            let mut m: f64 = 0.0;
            for i in 0..a.len() {
                m = m.max((a.times[i] - b.times[i]).abs());
                for k in 0..D {
                    m = m.max((a.values[i][k] - b.values[i][k]).abs());
                }
            }
            Some(m)
        }
        let (a, b) = (&self.body, &other.body);
        let mut m: f64 = [
            a.thigh - b.thigh,
            a.shin - b.shin,
            a.heel_to_n - b.heel_to_n,
            a.ball_to_n - b.ball_to_n,
            a.ankle_to_n - b.ankle_to_n,
            a.ball_to_toe - b.ball_to_toe,
            a.ball_height - b.ball_height,
            self.step_length - other.step_length,
            self.step_length_before - other.step_length_before,
            self.moments.fgm - other.moments.fgm,
            self.moments.mom - other.moments.mom,
            self.moments.tom - other.moments.tom,
        ]
        .iter()
        .fold(0.0, |m, d| m.max(d.abs()));
        m = m.max(seq(&self.hip, &other.hip)?);
        m = m.max(seq(&self.foot1, &other.foot1)?);
        m = m.max(seq(&self.foot2, &other.foot2)?);
        m = m.max(seq(&self.foot3, &other.foot3)?);
        m = m.max(seq(&self.meta, &other.meta)?);
        m = m.max(seq(&self.ankle, &other.ankle)?);
        Some(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_is_eq_2() {
        let q = TimedSequence::new("q", vec![0.0, 0.5, 2.0], vec![[1.0], [3.0], [0.0]]).unwrap();
        assert_eq!(q.at(0.25), 2.0);
        assert_eq!(q.at(0.5), 3.0);
        assert!((q.at(1.25) - 1.5).abs() < 1e-15);
        assert_eq!(q.at(-1.0), 1.0);
        assert_eq!(q.at(3.0), 0.0);
    }

    #[test]
    fn timed_sequence_rejects_bad_times() {
        assert!(TimedSequence::new("q", vec![0.0, 0.0], vec![[1.0], [2.0]]).is_err());
        assert!(TimedSequence::new("q", vec![0.0], vec![[1.0]]).is_err());
        assert!(TimedSequence::new("q", vec![0.0, 1.0], vec![[1.0]]).is_err());
        assert!(TimedSequence::new("q", vec![0.0, f64::NAN], vec![[1.0], [2.0]]).is_err());
    }

    #[test]
    fn moments_are_validated() {
        assert!(Moments::new(0.15, 1.1, 0.22).is_ok());
        assert!(Moments::new(0.15, 1.3, 0.22).is_err());
        assert!(Moments::new(0.15, 0.1, 0.22).is_err());
        assert!(Moments::new(0.15, 0.9, 1.0).is_err());
    }
}
