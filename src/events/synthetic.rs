//! A synthetic treadmill gait with known events, for tests and benchmarks: markers in gaitfit's
//! landmark names (x forward, y up) and one force plate per foot.
//!
//! Relative to the pelvis (fixed over the belt), each foot moves backward at the belt speed
//! during stance and swings forward on a raised-cosine path; heel strike and toe off are the
//! turning points of the heel and toe. The pelvis height follows a ballistic arc in every flight
//! (running) and a cubic between flights, so the flight height of the running paper's eq. 3 is
//! known exactly. The vertical force is a half sine over each stance.
use super::{EventKind, EventSource, GaitEvent, Side};
use crate::ingest::types::{Axis, ForcePlate, LabFrame, MarkerSet, Setting, SubjectInfo, Trial};
use crate::units::G;

/// The parameters of a synthetic gait.
#[derive(Debug, Clone, PartialEq)]
pub struct SyntheticGait {
    /// Belt speed, m/s.
    pub belt_speed_m_per_s: f64,
    /// Stride time, s.
    pub stride_time_s: f64,
    /// Stance time / stride time (above 0.5 walks, below runs).
    pub duty_factor: f64,
    /// Duration, s.
    pub duration_s: f64,
    /// Marker rate, Hz.
    pub marker_rate_hz: f64,
    /// Force rate, Hz.
    pub force_rate_hz: f64,
    /// First right heel strike, s.
    pub first_hs_s: f64,
    /// Pelvis height at toe off and heel strike, m.
    pub pelvis_height_m: f64,
}

impl SyntheticGait {
    /// A walk at 1.3 m/s, 1.1 s strides, 62 % stance.
    pub fn walk() -> Self {
        SyntheticGait {
            belt_speed_m_per_s: 1.3,
            stride_time_s: 1.1,
            duty_factor: 0.62,
            duration_s: 10.0,
            marker_rate_hz: 150.0,
            force_rate_hz: 1000.0,
            first_hs_s: 0.3,
            pelvis_height_m: 0.95,
        }
    }
    /// A run at 3.5 m/s, 0.7 s strides, 36 % stance.
    pub fn run() -> Self {
        SyntheticGait {
            belt_speed_m_per_s: 3.5,
            stride_time_s: 0.7,
            duty_factor: 0.36,
            duration_s: 10.0,
            marker_rate_hz: 150.0,
            force_rate_hz: 1000.0,
            first_hs_s: 0.3,
            pelvis_height_m: 0.95,
        }
    }
    /// Stance time, s.
    pub fn stance_s(&self) -> f64 {
        self.duty_factor * self.stride_time_s
    }
    /// Flight time of each step (running), s; negative values are double support.
    pub fn flight_s(&self) -> f64 {
        0.5 * self.stride_time_s - self.stance_s()
    }
    /// Step length, m.
    pub fn step_length_m(&self) -> f64 {
        0.5 * self.stride_time_s * self.belt_speed_m_per_s
    }

    fn hs_time(&self, side: Side, k: i64) -> f64 {
        let off = if side == Side::Right { 0.0 } else { 0.5 };
        self.first_hs_s + (k as f64 + off) * self.stride_time_s
    }

    /// The true events (heel strike, toe off) within the trial.
    pub fn events(&self) -> Vec<GaitEvent> {
        let mut out = Vec::new();
        let n = (self.duration_s / self.stride_time_s).ceil() as i64 + 2;
        for side in [Side::Left, Side::Right] {
            for k in -2..n {
                let hs = self.hs_time(side, k);
                for (t, kind) in [
                    (hs, EventKind::HeelStrike),
                    (hs + self.stance_s(), EventKind::ToeOff),
                ] {
                    if t > 0.0 && t < self.duration_s {
                        out.push(GaitEvent {
                            time_s: t,
                            side,
                            kind,
                            source: EventSource::Generated,
                        });
                    }
                }
            }
        }
        out.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        out
    }

    /// `(phase in the stride from this foot's heel strike, s)`.
    fn phase(&self, side: Side, t: f64) -> f64 {
        let t0 = self.hs_time(side, 0);
        (t - t0).rem_euclid(self.stride_time_s)
    }

    /// Heel position (forward relative to the pelvis, height) at `t`.
    fn heel(&self, side: Side, t: f64) -> (f64, f64) {
        let v = self.belt_speed_m_per_s;
        let ts = self.stance_s();
        let x_hs = 0.5 * v * ts;
        let x_to = -0.5 * v * ts;
        let p = self.phase(side, t);
        if p < ts {
            // Stance: heel on the belt; it rises in the last 30 % (heel off) for realism.
            let h = if p > 0.7 * ts {
                0.06 * ((p - 0.7 * ts) / (0.3 * ts)).powi(2)
            } else {
                0.0
            };
            (x_hs - v * p, 0.06 + h)
        } else {
            let s = (p - ts) / (self.stride_time_s - ts);
            let x = x_to + (x_hs - x_to) * 0.5 * (1.0 - (std::f64::consts::PI * s).cos());
            let h = 0.06 + 0.06 * (1.0 - s) + 0.08 * (std::f64::consts::PI * s).sin();
            (x, h)
        }
    }

    /// Pelvis height at `t`: a ballistic arc in each flight (running), a cubic in between.
    fn pelvis_height(&self, t: f64) -> f64 {
        let y0 = self.pelvis_height_m;
        let step = 0.5 * self.stride_time_s;
        let tf = self.flight_s();
        let p = (t - self.first_hs_s).rem_euclid(step); // from a heel strike
        if tf <= 0.0 {
            return y0 + 0.02 * (2.0 * std::f64::consts::PI * p / step).cos();
        }
        let ts = step - tf; // stance part of the step
        let vy = G * tf / 2.0;
        if p >= ts {
            let tau = p - ts;
            y0 + vy * tau - 0.5 * G * tau * tau
        } else {
            // Cubic Hermite from (y0, −vy) at landing to (y0, +vy) at take-off.
            let s = p / ts;
            let (h10, h11) = (s * s * s - 2.0 * s * s + s, s * s * s - s * s);
            y0 + h10 * ts * (-vy) + h11 * ts * vy
        }
    }

    /// The trial: markers (`pelvis`, `{l,r}_{heel,ball,toe,ankle,knee,hip}`) and one plate per
    /// foot.
    pub fn trial(&self) -> Trial {
        let nm = (self.duration_s * self.marker_rate_hz) as usize;
        let time_s: Vec<f64> = (0..nm).map(|i| i as f64 / self.marker_rate_hz).collect();
        let mut names = vec!["pelvis".to_string()];
        let mut positions = vec![time_s
            .iter()
            .map(|&t| [0.0, self.pelvis_height(t), 0.0])
            .collect::<Vec<_>>()];
        for side in [Side::Left, Side::Right] {
            let z = if side == Side::Left { -0.1 } else { 0.1 };
            let p = side.prefix();
            let heel: Vec<(f64, f64)> = time_s.iter().map(|&t| self.heel(side, t)).collect();
            let mk = |dx: f64, dy: f64| -> Vec<[f64; 3]> {
                heel.iter().map(|&(x, y)| [x + dx, y + dy, z]).collect()
            };
            names.push(format!("{p}_heel"));
            positions.push(mk(0.0, 0.0));
            names.push(format!("{p}_ball"));
            positions.push(mk(0.16, -0.03));
            names.push(format!("{p}_toe"));
            positions.push(mk(0.21, -0.035));
            names.push(format!("{p}_ankle"));
            positions.push(mk(0.05, 0.03));
            names.push(format!("{p}_knee"));
            positions.push(mk(0.06, 0.45));
            names.push(format!("{p}_hip"));
            positions.push(
                time_s
                    .iter()
                    .map(|&t| [0.0, self.pelvis_height(t), z])
                    .collect(),
            );
        }
        let markers = MarkerSet {
            rate_hz: self.marker_rate_hz,
            time_s,
            names,
            positions,
        };
        let nf = (self.duration_s * self.force_rate_hz) as usize;
        let ft: Vec<f64> = (0..nf).map(|i| i as f64 / self.force_rate_hz).collect();
        let ts = self.stance_s();
        let plates = [Side::Left, Side::Right]
            .into_iter()
            .map(|side| {
                let force_n = ft
                    .iter()
                    .map(|&t| {
                        let p = self.phase(side, t);
                        let fy = if p < ts {
                            750.0 * (std::f64::consts::PI * p / ts).sin()
                        } else {
                            0.0
                        };
                        [0.0, fy, 0.0]
                    })
                    .collect();
                let cop_m = ft
                    .iter()
                    .map(|&t| {
                        let p = self.phase(side, t);
                        if p < ts {
                            let (x, _) = self.heel(side, t);
                            [x + 0.2 * p / ts, 0.0, 0.0]
                        } else {
                            [f64::NAN; 3]
                        }
                    })
                    .collect();
                ForcePlate {
                    name: format!("{side} belt"),
                    rate_hz: self.force_rate_hz,
                    time_s: ft.clone(),
                    force_n,
                    cop_m,
                    free_moment_nm: Vec::new(),
                    side: Some(side),
                }
            })
            .collect();
        let mut trial = Trial::new("synthetic.trc", "synthetic");
        trial.subject = SubjectInfo {
            id: Some("synthetic".into()),
            body_height_m: Some(1.8),
            leg_length_m: Some(0.95),
            mass_kg: Some(70.0),
            notes: Vec::new(),
        };
        trial.setting = Setting::Treadmill {
            belt_speed_m_per_s: self.belt_speed_m_per_s,
        };
        trial.frame = Some(LabFrame {
            vertical: Axis::Y,
            forward: Axis::X,
            forward_sign: 1.0,
            how: "synthetic".into(),
        });
        trial.markers = Some(markers);
        trial.plates = plates;
        trial
    }

    /// The trial as gaitfit's per-frame CSV ([`crate::ingest::frame_csv`]): markers in mm and
    /// one plate per foot (`l_belt`, `r_belt`, N) at the marker rate, with the belt speed and
    /// the subject in `#` settings lines — a raw file for `gaitfit fit --data` and the readers.
    pub fn frame_csv(&self) -> String {
        use std::fmt::Write as _;
        let trial = SyntheticGait {
            force_rate_hz: self.marker_rate_hz,
            ..self.clone()
        }
        .trial();
        let mut s = format!(
            "# gait = {}\n# vertical = y\n# forward = +x\n# belt_speed_m_per_s = {}\n\
             # subject = synthetic\n# body_height_m = 1.8\n# leg_length_m = 0.95\ntime_s",
            if self.duty_factor > 0.5 {
                "walk"
            } else {
                "run"
            },
            self.belt_speed_m_per_s
        );
        let Some(m) = trial.markers.as_ref() else {
            return s;
        };
        for name in &m.names {
            let _ = write!(s, ",{name}_x_mm,{name}_y_mm,{name}_z_mm");
        }
        for p in &trial.plates {
            let side = if p.side == Some(Side::Left) { "l" } else { "r" };
            let _ = write!(s, ",{side}_belt_fx_n,{side}_belt_fy_n,{side}_belt_fz_n");
        }
        s.push('\n');
        for (f, t) in m.time_s.iter().enumerate() {
            let _ = write!(s, "{t:.6}");
            for traj in &m.positions {
                for v in traj[f] {
                    let _ = write!(s, ",{:.3}", v * 1000.0);
                }
            }
            for p in &trial.plates {
                for v in p.force_n.get(f).copied().unwrap_or([0.0; 3]) {
                    let _ = write!(s, ",{v:.3}");
                }
            }
            s.push('\n');
        }
        s
    }

    /// The markers as an OpenSim TRC file (mm, tab-separated), for reading benchmarks and tests
    /// of the readers: save it as `X.trc` beside [`Self::grf_mot`] saved as `X_grf.mot`.
    pub fn trc(&self) -> String {
        let trial = self.trial();
        trial
            .markers
            .as_ref()
            .map_or_else(String::new, |m| trc_text("synthetic.trc", m))
    }

    /// The two belts as an OpenSim GRF `.mot` file (`R_ground_force_*`, `L_ground_force_*`).
    pub fn grf_mot(&self) -> String {
        let trial = self.trial();
        let plate = |side| trial.plates.iter().find(|p| p.side == Some(side));
        let (Some(r), Some(l)) = (plate(Side::Right), plate(Side::Left)) else {
            return String::new();
        };
        grf_mot_text("synthetic_grf.mot", r, l)
    }
}

/// Markers as an OpenSim TRC file (mm, tab-separated; a missing sample — NaN — is an empty
/// cell, as TRC writers leave gaps). `name` goes in the header. Used by the synthetic trials,
/// the benches and the tests that write trials to disk.
pub fn trc_text(name: &str, m: &MarkerSet) -> String {
    use std::fmt::Write as _;
    let (n, k) = (m.len(), m.names.len());
    let mut s = format!("PathFileType\t4\t(X/Y/Z)\t{name}\n");
    s.push_str(
        "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\t\
         OrigDataStartFrame\tOrigNumFrames\n",
    );
    let _ = writeln!(s, "{0}\t{0}\t{n}\t{k}\tmm\t{0}\t1\t{n}", m.rate_hz);
    let mut names = String::from("Frame#\tTime");
    let mut axes = String::from("\t");
    for (i, name) in m.names.iter().enumerate() {
        let _ = write!(names, "\t{name}\t\t");
        let _ = write!(axes, "\tX{0}\tY{0}\tZ{0}", i + 1);
    }
    let _ = writeln!(s, "{names}\n{axes}\n");
    for f in 0..n {
        let _ = write!(s, "{}\t{:.5}", f + 1, m.time_s[f]);
        for traj in &m.positions {
            for v in traj[f] {
                if v.is_finite() {
                    let _ = write!(s, "\t{:.4}", v * 1000.0);
                } else {
                    s.push('\t');
                }
            }
        }
        s.push('\n');
    }
    s
}

/// Two force plates (right, left) as an OpenSim GRF `.mot` file (`R_ground_force_*`,
/// `L_ground_force_*`, torques zero; a missing centre of pressure is written as 0). `name` goes
/// in the header.
pub fn grf_mot_text(name: &str, r: &ForcePlate, l: &ForcePlate) -> String {
    use std::fmt::Write as _;
    let n = r.time_s.len();
    let mut s = format!(
        "name {name}\ndatacolumns 19\ndatarows {n}\nrange {} {}\nendheader\ntime",
        r.time_s.first().copied().unwrap_or(0.0),
        r.time_s.last().copied().unwrap_or(0.0)
    );
    for side in ["R", "L"] {
        for q in ["vx", "vy", "vz", "px", "py", "pz"] {
            let _ = write!(s, "\t{side}_ground_force_{q}");
        }
    }
    for side in ["R", "L"] {
        for q in ["x", "y", "z"] {
            let _ = write!(s, "\t{side}_ground_torque_{q}");
        }
    }
    s.push('\n');
    for i in 0..n {
        let _ = write!(s, "{:.4}", r.time_s[i]);
        for p in [r, l] {
            for v in p.force_n[i] {
                let _ = write!(s, "\t{v:.3}");
            }
            for v in p.cop_m[i] {
                let _ = write!(s, "\t{:.5}", if v.is_finite() { v } else { 0.0 });
            }
        }
        s.push_str("\t0\t0\t0\t0\t0\t0\n");
    }
    s
}
