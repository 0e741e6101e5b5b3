//! Anthropometry of the figure, scaled from body height and body mass.
//!
//! Lower body (dynamics and leg kinematics): table B-1 of Bruderlin & Calvert (1989), appendix B
//! ("relative anthropometric data": lengths are fractions of body height, masses fractions of body
//! mass, centres of mass `r_i` fractions of the segment length from the proximal end except the
//! whole leg `r_1`, which is measured from the distal end, radii of gyration `γ_i` fractions of the
//! segment length about the centre of mass). The table's masses, centres of mass and radii of
//! gyration are those of Dempster (1955) as tabulated by Winter, *Biomechanics and Motor Control of
//! Human Movement*, 4th ed. (2009), Table 4.1 ("thigh", "foot and leg", "total leg", "HAT").
//!
//! Upper body (not in table B-1): segment lengths from the Drillis & Contini (1966) proportions
//! reproduced in Winter (2009), Fig. 4.1 (shoulder height 0.818·h, chin 0.870·h, chest 0.720·h,
//! biacromial width 0.259·h, upper arm 0.186·h, forearm 0.146·h, hand 0.108·h); arm and head/trunk
//! masses, centres of mass and radii of gyration from Winter (2009), Table 4.1. The spine joint
//! heights (L5/S1 0.555·h, T12/L1 0.640·h, T7 0.720·h) are gaitfit's choices, documented on
//! [`Anthropometry::from_height`].
//!
//! Moments of inertia: `I = m·(γ·l)²` (γ·l is the radius of gyration in metres). The paper's
//! worked thigh example prints `I₃ = m₃·(l₃·r₃)² = 0.0276 kg·m²` for h = 1.8 m, m = 80 kg, which
//! multiplies two lengths inside the square (units kg·m⁴) and does not use γ₃; the table gives
//! `I₃ = 8 kg · (0.323 · 0.426 m)² = 0.1515 kg·m²`, which is what gaitfit uses
//! (see [`Segment::moment_of_inertia_kg_m2`], tested in `tests/figure_anthropometry.rs`).
//!
//! Every value is a public field and can be overridden after [`Anthropometry::from_height`];
//! [`Anthropometry::validate`] then rejects anatomically absurd values, naming the field.
use super::GenerateError;

/// Table B-1 of Bruderlin & Calvert (1989) and the upper-body fractions, as published.
pub mod table {
    /// l₀, pelvis: distance between the hip joint centres, fraction of body height.
    pub const PELVIS_L0: f64 = 0.10059;
    /// r₁, whole leg: centre of mass from the *distal* end, fraction of the leg length.
    pub const LEG_R1_FROM_DISTAL: f64 = 0.553;
    /// γ₁, whole leg: radius of gyration about the centre of mass, fraction of the leg length.
    pub const LEG_GAMMA1: f64 = 0.326;
    /// l₂, upper body (head, arms, trunk): length, fraction of body height.
    pub const UPPER_BODY_L2: f64 = 0.47;
    /// m₂, upper body: mass, fraction of body mass.
    pub const UPPER_BODY_M2: f64 = 0.678;
    /// r₂, upper body: centre of mass from the proximal (hip) end, fraction of l₂.
    pub const UPPER_BODY_R2: f64 = 0.5;
    /// γ₂, upper body: radius of gyration, fraction of l₂.
    pub const UPPER_BODY_GAMMA2: f64 = 0.496;
    /// l₃, thigh: length, fraction of body height.
    pub const THIGH_L3: f64 = 0.23669;
    /// m₃, thigh: mass, fraction of body mass.
    pub const THIGH_M3: f64 = 0.1;
    /// r₃, thigh: centre of mass from the hip, fraction of l₃.
    pub const THIGH_R3: f64 = 0.433;
    /// γ₃, thigh: radius of gyration, fraction of l₃.
    pub const THIGH_GAMMA3: f64 = 0.323;
    /// l₄, shank: length (knee to ankle), fraction of body height.
    pub const SHANK_L4: f64 = 0.24556;
    /// m₄, shank *and foot*: mass, fraction of body mass (Winter's "foot and leg").
    pub const SHANK_M4: f64 = 0.061;
    /// r₄, shank and foot: centre of mass from the knee, fraction of l₄.
    pub const SHANK_R4: f64 = 0.606;
    /// γ₄, shank and foot: radius of gyration, fraction of l₄.
    pub const SHANK_GAMMA4: f64 = 0.416;
    /// l₅, mid foot: horizontal distance ankle → 1st metatarsal joint (foot flat).
    pub const MID_FOOT_L5: f64 = 0.0858;
    /// l₆, toe: horizontal distance 1st metatarsal joint → toe tip (foot flat).
    pub const TOE_L6: f64 = 0.04734;
    /// l₈, hind foot: horizontal distance heel → ankle (foot flat).
    pub const HIND_FOOT_L8: f64 = 0.02959;
    /// l₉, ankle–footbase: height of the ankle joint above the sole.
    pub const ANKLE_FOOTBASE_L9: f64 = 0.03846;
    /// l₁₁, heel–ankle distance.
    pub const HEEL_ANKLE_L11: f64 = 0.04853;
    /// l₁₂, ankle–1st metatarsal distance.
    pub const ANKLE_METATARSAL_L12: f64 = 0.08901;
    /// l₁₃, 1st metatarsal–toe tip distance.
    pub const METATARSAL_TOE_L13: f64 = 0.0496;

    /// Drillis & Contini (Winter 2009, Fig. 4.1): shoulder (acromion) height, fraction of h.
    pub const SHOULDER_HEIGHT: f64 = 0.818;
    /// Drillis & Contini: chin height; gaitfit puts the head (C1) joint there.
    pub const CHIN_HEIGHT: f64 = 0.870;
    /// Drillis & Contini: chest (nipple) height; gaitfit puts the T7 joint there.
    pub const CHEST_HEIGHT: f64 = 0.720;
    /// gaitfit's choice: L5/S1 height, fraction of h (about 6 cm above the hip joint centres
    /// of a 1.8 m figure).
    pub const L5S1_HEIGHT: f64 = 0.555;
    /// gaitfit's choice: T12/L1 height, fraction of h (midway between L5/S1 and T7, slightly
    /// high).
    pub const T12L1_HEIGHT: f64 = 0.640;
    /// Drillis & Contini: biacromial (shoulder) width, fraction of h; gaitfit uses it as the
    /// distance between the shoulder joint centres.
    pub const SHOULDER_WIDTH: f64 = 0.259;
    /// gaitfit's choice: distance between the two clavicle (sternoclavicular) joints, fraction
    /// of h.
    pub const CLAVICLE_BASE_WIDTH: f64 = 0.04;
    /// Drillis & Contini: upper arm length (shoulder → elbow), fraction of h.
    pub const UPPER_ARM: f64 = 0.186;
    /// Drillis & Contini: forearm length (elbow → wrist), fraction of h.
    pub const FOREARM: f64 = 0.146;
    /// Drillis & Contini: hand length (wrist → knuckle II), fraction of h.
    pub const HAND: f64 = 0.108;
    /// Winter Table 4.1: upper arm mass, centre of mass (proximal), radius of gyration.
    pub const UPPER_ARM_M_R_GAMMA: (f64, f64, f64) = (0.028, 0.436, 0.322);
    /// Winter Table 4.1: forearm mass, centre of mass (proximal), radius of gyration.
    pub const FOREARM_M_R_GAMMA: (f64, f64, f64) = (0.016, 0.430, 0.303);
    /// Winter Table 4.1: hand mass, centre of mass (proximal), radius of gyration.
    pub const HAND_M_R_GAMMA: (f64, f64, f64) = (0.006, 0.506, 0.297);
    /// Winter Table 4.1: head and neck mass fraction.
    pub const HEAD_NECK_M: f64 = 0.081;
    /// Winter Table 4.1: trunk (greater trochanter → glenohumeral joint) mass fraction.
    pub const TRUNK_M: f64 = 0.497;
}

/// One rigid segment: length, mass, centre of mass and radius of gyration, all absolute (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Length, m.
    pub length_m: f64,
    /// Mass, kg.
    pub mass_kg: f64,
    /// Distance of the centre of mass from the proximal end, m.
    pub com_from_proximal_m: f64,
    /// Radius of gyration about the centre of mass (sagittal axis), m.
    pub radius_of_gyration_m: f64,
}

impl Segment {
    /// A segment from its length, mass, and the table's relative centre of mass (fraction of the
    /// length from the proximal end) and radius of gyration (fraction of the length).
    pub fn from_fractions(length_m: f64, mass_kg: f64, com_fraction: f64, gamma: f64) -> Segment {
        Segment {
            length_m,
            mass_kg,
            com_from_proximal_m: com_fraction * length_m,
            radius_of_gyration_m: gamma * length_m,
        }
    }

    /// Distance of the centre of mass from the distal end, m (KLAW's `r₁` for the whole leg).
    pub fn com_from_distal_m(&self) -> f64 {
        self.length_m - self.com_from_proximal_m
    }

    /// Moment of inertia about the centre of mass, `I = m·(γ·l)²`, kg·m² (appendix B of
    /// Bruderlin & Calvert 1989, with the table's γ; the worked example's `m·(l·r)²` is
    /// dimensionally wrong, see the module docs).
    pub fn moment_of_inertia_kg_m2(&self) -> f64 {
        self.mass_kg * self.radius_of_gyration_m * self.radius_of_gyration_m
    }

    /// Moment of inertia about the proximal joint (parallel-axis theorem), kg·m².
    pub fn moment_about_proximal_kg_m2(&self) -> f64 {
        self.moment_of_inertia_kg_m2() + self.mass_kg * self.com_from_proximal_m.powi(2)
    }
}

/// Foot geometry of table B-1 (foot flat on the ground, sagittal plane, metres).
///
/// The table's distances are consistent with this picture (checked in the tests to 1e-4·h):
/// the ankle joint is `ankle_height_m` (l₉) above the sole; the heel's sole point is
/// `hind_foot_m` (l₈) behind it, so the heel–ankle distance is l₁₁ = √(l₈² + l₉²); the first
/// metatarsal (ball) joint is `mid_foot_m` (l₅) ahead of the ankle and `metatarsal_height_m`
/// above the sole, so that the ankle–metatarsal distance is l₁₂; the toe tip is on the sole
/// `toe_m` (l₆) ahead of the metatarsal joint, so that the metatarsal–toe tip distance is l₁₃.
/// The table does not list the metatarsal joint height; it follows from l₅, l₉ and l₁₂:
/// `l₉ − √(l₁₂² − l₅²)` = 0.01477·h (2.7 cm at h = 1.8 m), and l₁₃ then agrees with
/// √(l₆² + that²) to 1e-5·h, which is why gaitfit reads the table this way.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FootGeometry {
    /// l₈: heel sole point → ankle, horizontal, m.
    pub hind_foot_m: f64,
    /// l₅: ankle → metatarsal joint, horizontal, m.
    pub mid_foot_m: f64,
    /// l₆: metatarsal joint → toe tip, horizontal, m.
    pub toe_m: f64,
    /// l₉: ankle joint height above the sole, m.
    pub ankle_height_m: f64,
    /// Metatarsal (ball) joint centre height above the sole, m (derived from l₅, l₉, l₁₂).
    pub metatarsal_height_m: f64,
}

impl FootGeometry {
    /// l₁₁: heel–ankle distance, m.
    pub fn heel_ankle_m(&self) -> f64 {
        self.hind_foot_m.hypot(self.ankle_height_m)
    }
    /// l₁₂: ankle–metatarsal joint distance, m.
    pub fn ankle_metatarsal_m(&self) -> f64 {
        self.mid_foot_m
            .hypot(self.ankle_height_m - self.metatarsal_height_m)
    }
    /// l₁₃: metatarsal joint–toe tip distance, m.
    pub fn metatarsal_toe_m(&self) -> f64 {
        self.toe_m.hypot(self.metatarsal_height_m)
    }
    /// Heel to toe tip along the sole, m (l₈ + l₅ + l₆).
    pub fn length_m(&self) -> f64 {
        self.hind_foot_m + self.mid_foot_m + self.toe_m
    }
}

/// The figure's dimensions and mass distribution, SI units. Build with [`Anthropometry::from_height`],
/// override any field, then [`Anthropometry::validate`] (or [`super::skeleton::Skeleton::new`],
/// which validates).
#[derive(Debug, Clone, PartialEq)]
pub struct Anthropometry {
    /// Body height (stature), m.
    pub height_m: f64,
    /// Body mass, kg.
    pub mass_kg: f64,
    /// l₀: distance between the hip joint centres, m.
    pub hip_width_m: f64,
    /// Segment 3 of table B-1: thigh (hip → knee).
    pub thigh: Segment,
    /// Segment 4 of table B-1: shank (knee → ankle); its mass, centre of mass and radius of
    /// gyration are those of shank *and foot* (Winter's "foot and leg"), as in the paper.
    pub shank: Segment,
    /// Segment 2 of table B-1: upper body (head, arms and trunk as one segment, from the hips).
    pub upper_body: Segment,
    /// Foot geometry (l₅, l₆, l₈, l₉ and the metatarsal joint height).
    pub foot: FootGeometry,
    /// Hip joint centres' midpoint → L5/S1 (the `lumbar` joint), vertical, m.
    pub pelvis_to_lumbar_m: f64,
    /// L5/S1 → T12/L1 (the `thoracic_lower` joint), m.
    pub lumbar_to_thoracic_lower_m: f64,
    /// T12/L1 → T7 (the `thoracic_upper` joint), m.
    pub thoracic_lower_to_upper_m: f64,
    /// T7 → C7/T1 (the `neck` joint, at shoulder height), m.
    pub thoracic_upper_to_neck_m: f64,
    /// C7/T1 → the head joint (C1, at chin height), m.
    pub neck_to_head_m: f64,
    /// Head joint → vertex (top of the head), m.
    pub head_to_vertex_m: f64,
    /// Distance between the two clavicle joints (sternoclavicular), m.
    pub clavicle_base_width_m: f64,
    /// Distance between the shoulder joint centres, m.
    pub shoulder_width_m: f64,
    /// Upper arm (shoulder → elbow).
    pub upper_arm: Segment,
    /// Forearm (elbow → wrist).
    pub forearm: Segment,
    /// Hand (wrist → knuckle II, the `hand` end site).
    pub hand: Segment,
    /// Head and neck mass, kg (Winter Table 4.1).
    pub head_neck_mass_kg: f64,
    /// Trunk mass (greater trochanter → glenohumeral joint), kg (Winter Table 4.1).
    pub trunk_mass_kg: f64,
}

/// Body heights [`Anthropometry::from_height`] accepts, m (a standing human).
pub const HEIGHT_RANGE_M: (f64, f64) = (0.8, 2.6);
/// Body masses [`Anthropometry::from_height`] accepts, kg (a human).
pub const MASS_RANGE_KG: (f64, f64) = (10.0, 300.0);

impl Anthropometry {
    /// The figure of body height `height_m` (m) and mass `mass_kg` (kg) with every value taken
    /// from the tables (see the module docs), validated.
    ///
    /// Vertical layout of the rest pose (fractions of h): ankle l₉ = 0.03846, knee l₉ + l₄,
    /// hip joint centres l₉ + l₄ + l₃ = 0.52071 (table B-1); L5/S1 0.555, T12/L1 0.640 (gaitfit's
    /// choices), T7 0.720 (chest), C7/T1 and shoulders 0.818, head joint 0.870 (chin), vertex
    /// 1.000 (Drillis & Contini) — so the rest pose is exactly `height_m` tall.
    ///
    /// ```
    /// use gaitfit::generator::anthropometry::Anthropometry;
    /// let a = Anthropometry::from_height(1.8, 80.0).unwrap();
    /// assert!((a.thigh.length_m - 0.426).abs() < 5e-4); // appendix B: l₃ = 0.426 m
    /// assert!((a.thigh.moment_of_inertia_kg_m2() - 0.1515).abs() < 5e-4);
    /// ```
    pub fn from_height(height_m: f64, mass_kg: f64) -> Result<Anthropometry, GenerateError> {
        check_range(
            "height_m",
            height_m,
            HEIGHT_RANGE_M.0,
            HEIGHT_RANGE_M.1,
            "m: body height of a standing human",
        )?;
        check_range(
            "mass_kg",
            mass_kg,
            MASS_RANGE_KG.0,
            MASS_RANGE_KG.1,
            "kg: body mass of a human",
        )?;
        let a = Self::from_height_unchecked(height_m, mass_kg);
        a.validate()?;
        Ok(a)
    }

    /// The table values without validation (the caller validates after overriding).
    fn from_height_unchecked(h: f64, m: f64) -> Anthropometry {
        use table::*;
        let l9 = ANKLE_FOOTBASE_L9 * h;
        let l5 = MID_FOOT_L5 * h;
        let l12 = ANKLE_METATARSAL_L12 * h;
        let mtp_height = l9 - (l12 * l12 - l5 * l5).sqrt();
        let hip_fraction = ANKLE_FOOTBASE_L9 + SHANK_L4 + THIGH_L3;
        let seg =
            |len: f64, (mf, r, g): (f64, f64, f64)| Segment::from_fractions(len, mf * m, r, g);
        Anthropometry {
            height_m: h,
            mass_kg: m,
            hip_width_m: PELVIS_L0 * h,
            thigh: Segment::from_fractions(THIGH_L3 * h, THIGH_M3 * m, THIGH_R3, THIGH_GAMMA3),
            shank: Segment::from_fractions(SHANK_L4 * h, SHANK_M4 * m, SHANK_R4, SHANK_GAMMA4),
            upper_body: Segment::from_fractions(
                UPPER_BODY_L2 * h,
                UPPER_BODY_M2 * m,
                UPPER_BODY_R2,
                UPPER_BODY_GAMMA2,
            ),
            foot: FootGeometry {
                hind_foot_m: HIND_FOOT_L8 * h,
                mid_foot_m: l5,
                toe_m: TOE_L6 * h,
                ankle_height_m: l9,
                metatarsal_height_m: mtp_height,
            },
            pelvis_to_lumbar_m: (L5S1_HEIGHT - hip_fraction) * h,
            lumbar_to_thoracic_lower_m: (T12L1_HEIGHT - L5S1_HEIGHT) * h,
            thoracic_lower_to_upper_m: (CHEST_HEIGHT - T12L1_HEIGHT) * h,
            thoracic_upper_to_neck_m: (SHOULDER_HEIGHT - CHEST_HEIGHT) * h,
            neck_to_head_m: (CHIN_HEIGHT - SHOULDER_HEIGHT) * h,
            head_to_vertex_m: (1.0 - CHIN_HEIGHT) * h,
            clavicle_base_width_m: CLAVICLE_BASE_WIDTH * h,
            shoulder_width_m: SHOULDER_WIDTH * h,
            upper_arm: seg(UPPER_ARM * h, UPPER_ARM_M_R_GAMMA),
            forearm: seg(FOREARM * h, FOREARM_M_R_GAMMA),
            hand: seg(HAND * h, HAND_M_R_GAMMA),
            head_neck_mass_kg: HEAD_NECK_M * m,
            trunk_mass_kg: TRUNK_M * m,
        }
    }

    /// Segment 1 of table B-1: the whole leg (hip → ankle), l₁ = l₃ + l₄, m₁ = m₃ + m₄, with the
    /// table's r₁ = 0.553 (from the distal end) and γ₁ = 0.326 applied to the current l₁.
    pub fn leg(&self) -> Segment {
        let l1 = self.thigh.length_m + self.shank.length_m;
        Segment::from_fractions(
            l1,
            self.thigh.mass_kg + self.shank.mass_kg,
            1.0 - table::LEG_R1_FROM_DISTAL,
            table::LEG_GAMMA1,
        )
    }

    /// Height of the hip joint centres above the ground when standing (l₉ + l₄ + l₃), m. This is
    /// the leg length gaitfit reports for generated figures.
    pub fn hip_height_m(&self) -> f64 {
        self.foot.ankle_height_m + self.shank.length_m + self.thigh.length_m
    }

    /// Height of the C7/T1 (`neck`) joint and of the shoulder joints in the rest pose, m.
    pub fn shoulder_height_m(&self) -> f64 {
        self.hip_height_m()
            + self.pelvis_to_lumbar_m
            + self.lumbar_to_thoracic_lower_m
            + self.thoracic_lower_to_upper_m
            + self.thoracic_upper_to_neck_m
    }

    /// Height of the vertex in the rest pose (the figure's stature from its segments), m.
    pub fn standing_height_m(&self) -> f64 {
        self.shoulder_height_m() + self.neck_to_head_m + self.head_to_vertex_m
    }

    /// Checks every value against anatomical limits. Lengths must lie within 0.5–2× their table
    /// value for this `height_m`, masses within 0.3–3× theirs, centres of mass inside their
    /// segment, radii of gyration positive and shorter than the segment; the foot must stand
    /// (metatarsal joint below the ankle); the segments must add up to within 10 % of `height_m`.
    /// The error names the field (e.g. `thigh.length_m`) and the accepted range.
    pub fn validate(&self) -> Result<(), GenerateError> {
        check_range(
            "height_m",
            self.height_m,
            0.8,
            2.6,
            "m: body height of a standing human",
        )?;
        check_range(
            "mass_kg",
            self.mass_kg,
            10.0,
            300.0,
            "kg: body mass of a human",
        )?;
        let t = Self::from_height_unchecked(self.height_m, self.mass_kg);
        let len = |name: &str, v: f64, default: f64| {
            check_range(
                name,
                v,
                0.5 * default,
                2.0 * default,
                &format!(
                    "m: 0.5–2× the table value {default:.4} m for a {:.2} m figure",
                    self.height_m
                ),
            )
        };
        let mass = |name: &str, v: f64, default: f64| {
            check_range(
                name,
                v,
                0.3 * default,
                3.0 * default,
                &format!(
                    "kg: 0.3–3× the table value {default:.3} kg for a {:.1} kg figure",
                    self.mass_kg
                ),
            )
        };
        let segment = |name: &str, s: &Segment, d: &Segment| -> Result<(), GenerateError> {
            len(&format!("{name}.length_m"), s.length_m, d.length_m)?;
            mass(&format!("{name}.mass_kg"), s.mass_kg, d.mass_kg)?;
            check_range(
                &format!("{name}.com_from_proximal_m"),
                s.com_from_proximal_m,
                0.0,
                s.length_m,
                "m: the centre of mass must lie on the segment",
            )?;
            check_range(
                &format!("{name}.radius_of_gyration_m"),
                s.radius_of_gyration_m,
                1e-6,
                s.length_m,
                "m: positive and shorter than the segment",
            )
        };
        len("hip_width_m", self.hip_width_m, t.hip_width_m)?;
        segment("thigh", &self.thigh, &t.thigh)?;
        segment("shank", &self.shank, &t.shank)?;
        segment("upper_body", &self.upper_body, &t.upper_body)?;
        let (f, tf) = (&self.foot, &t.foot);
        len("foot.hind_foot_m", f.hind_foot_m, tf.hind_foot_m)?;
        len("foot.mid_foot_m", f.mid_foot_m, tf.mid_foot_m)?;
        len("foot.toe_m", f.toe_m, tf.toe_m)?;
        len("foot.ankle_height_m", f.ankle_height_m, tf.ankle_height_m)?;
        check_range(
            "foot.metatarsal_height_m",
            f.metatarsal_height_m,
            0.0,
            0.9 * f.ankle_height_m,
            "m: at or above the sole and below the ankle",
        )?;
        len(
            "pelvis_to_lumbar_m",
            self.pelvis_to_lumbar_m,
            t.pelvis_to_lumbar_m,
        )?;
        len(
            "lumbar_to_thoracic_lower_m",
            self.lumbar_to_thoracic_lower_m,
            t.lumbar_to_thoracic_lower_m,
        )?;
        len(
            "thoracic_lower_to_upper_m",
            self.thoracic_lower_to_upper_m,
            t.thoracic_lower_to_upper_m,
        )?;
        len(
            "thoracic_upper_to_neck_m",
            self.thoracic_upper_to_neck_m,
            t.thoracic_upper_to_neck_m,
        )?;
        len("neck_to_head_m", self.neck_to_head_m, t.neck_to_head_m)?;
        len(
            "head_to_vertex_m",
            self.head_to_vertex_m,
            t.head_to_vertex_m,
        )?;
        len(
            "clavicle_base_width_m",
            self.clavicle_base_width_m,
            t.clavicle_base_width_m,
        )?;
        len(
            "shoulder_width_m",
            self.shoulder_width_m,
            t.shoulder_width_m,
        )?;
        if self.shoulder_width_m <= self.clavicle_base_width_m {
            return Err(GenerateError::Parameter {
                name: "shoulder_width_m".into(),
                value: self.shoulder_width_m,
                message: format!(
                    "must exceed clavicle_base_width_m = {:.4} m (the shoulders lie outside the \
                     clavicle joints)",
                    self.clavicle_base_width_m
                ),
            });
        }
        segment("upper_arm", &self.upper_arm, &t.upper_arm)?;
        segment("forearm", &self.forearm, &t.forearm)?;
        segment("hand", &self.hand, &t.hand)?;
        mass(
            "head_neck_mass_kg",
            self.head_neck_mass_kg,
            t.head_neck_mass_kg,
        )?;
        mass("trunk_mass_kg", self.trunk_mass_kg, t.trunk_mass_kg)?;
        let stature = self.standing_height_m();
        if (stature - self.height_m).abs() > 0.1 * self.height_m {
            return Err(GenerateError::Parameter {
                name: "height_m".into(),
                value: self.height_m,
                message: format!(
                    "the segments add up to a standing height of {stature:.3} m, more than 10 % \
                     away from height_m; scale the overridden lengths or set height_m to match"
                ),
            });
        }
        Ok(())
    }
}

/// `Err` naming `name` unless `lo ≤ value ≤ hi` (and finite).
fn check_range(name: &str, value: f64, lo: f64, hi: f64, what: &str) -> Result<(), GenerateError> {
    if value.is_finite() && value >= lo && value <= hi {
        Ok(())
    } else {
        Err(GenerateError::Parameter {
            name: name.to_string(),
            value,
            message: format!("must be within [{lo:.4}, {hi:.4}] {what}"),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rest_pose_is_exactly_the_body_height() {
        for h in [1.5, 1.8, 2.0] {
            let a = Anthropometry::from_height(h, 70.0).unwrap();
            assert!((a.standing_height_m() - h).abs() < 1e-12);
        }
    }

    #[test]
    fn rejects_absurd_values_naming_the_field() {
        let mut a = Anthropometry::from_height(1.8, 80.0).unwrap();
        a.thigh.length_m = 2.0;
        let e = a.validate().unwrap_err().to_string();
        assert!(e.contains("thigh.length_m"), "{e}");
        let mut a = Anthropometry::from_height(1.8, 80.0).unwrap();
        a.foot.metatarsal_height_m = 0.2;
        let e = a.validate().unwrap_err().to_string();
        assert!(e.contains("foot.metatarsal_height_m"), "{e}");
        let mut a = Anthropometry::from_height(1.8, 80.0).unwrap();
        a.shank.mass_kg = f64::NAN;
        assert!(a
            .validate()
            .unwrap_err()
            .to_string()
            .contains("shank.mass_kg"));
        assert!(Anthropometry::from_height(5.0, 80.0)
            .unwrap_err()
            .to_string()
            .contains("height_m"));
    }
}
