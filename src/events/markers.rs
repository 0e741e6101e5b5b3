//! Which markers play which role (pelvis, heel, toe, metatarsal, ankle, knee, hip), with presets
//! for the marker sets of the shared data sets and for gaitfit's own generated landmarks.
//!
//! A role is a list of alternatives separated by `|`; an alternative is one marker or the mean of
//! several joined by `+` (`RASI+LASI+RPSI+LPSI|RASI+LASI`). The first alternative whose markers
//! all exist in the trial is used.
use super::{EventError, Side};
use crate::ingest::types::MarkerSet;
use serde::{Deserialize, Serialize};

/// The marker roles of one foot and leg.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct LegMarkers {
    /// Heel (calcaneus): heel strike, foot flat, heel off, step length.
    pub heel: String,
    /// Toe (or the forefoot marker nearest to the toe tip): toe off.
    pub toe: String,
    /// Metatarsal heads (ball of the foot): foot-sole line, meta off.
    pub meta: String,
    /// Ankle (lateral malleolus or ankle joint centre).
    pub ankle: String,
    /// Knee (lateral epicondyle or knee joint centre).
    pub knee: String,
    /// Hip (greater trochanter or hip joint centre).
    pub hip: String,
}

/// A marker-name mapping for event detection.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct MarkerMap {
    /// Preset name, or "custom".
    pub name: String,
    /// The pelvis reference (Zeni et al. use the sacrum; the mean of the pelvis markers is as
    /// good and survives a missing marker through the alternatives).
    pub pelvis: String,
    /// Left leg.
    pub left: LegMarkers,
    /// Right leg.
    pub right: LegMarkers,
}

/// The names of the built-in presets, in the order [`MarkerMap::auto`] tries them.
pub const PRESETS: &[&str] = &["gaitfit", "opensim", "cortex", "schreiber", "pig", "winter"];

fn leg(
    p: &str,
    heel: &str,
    toe: &str,
    meta: &str,
    ankle: &str,
    knee: &str,
    hip: &str,
) -> LegMarkers {
    let f = |s: &str| s.replace('#', p);
    LegMarkers {
        heel: f(heel),
        toe: f(toe),
        meta: f(meta),
        ankle: f(ankle),
        knee: f(knee),
        hip: f(hip),
    }
}

impl MarkerMap {
    /// A built-in preset by name (see [`PRESETS`]).
    ///
    /// - `gaitfit`: the landmarks of `Motion::to_trial()` (`pelvis`, `l_heel`, `l_ball`,
    ///   `l_toe`, `l_ankle`, `l_knee`, `l_hip`, …).
    /// - `opensim`: the OpenSim running marker set of Hamner & Delp (2013) and BMClab's running
    ///   trial (`RCAL`, `RTOE`, `RMT5`, `RASI`/`RPSI`, joint centres `RAJC`/`RKJC`/`RHJC`).
    /// - `cortex`: BMClab's Cortex walking set (`R.Heel`, `R.MT1`/`R.MT2`/`R.MT5`, `R.Ankle`,
    ///   `R.Knee`, `R.GTR`, `R.ASIS`/`R.PSIS`); no toe-tip marker, the 2nd metatarsal head
    ///   stands in for the toe (as Plug-in Gait's `RTOE` does).
    /// - `schreiber`: the ISB-style set of Schreiber & Moissenet (2019) (`R_FCC`, `R_FM1`,
    ///   `R_FM2`, `R_FM5`, `R_FAL`, `R_FLE`, `R_FTC`, `R_IAS`/`R_IPS`).
    /// - `pig`: Vicon Plug-in Gait (`RHEE`, `RTOE`, `RANK`, `RKNE`, `RASI`/`RPSI`/`SACR`).
    /// - `winter`: Winter's Table A.1 (`RIGHT HEEL`, `RIGHT TOE`, `RIGHT MT5`, `RIGHT ANKLE`,
    ///   `RIGHT KNEE`, `RIGHT HIP`; right side only; the hip marker stands in for the pelvis).
    pub fn preset(name: &str) -> Option<MarkerMap> {
        let (pelvis, l, r) = match name {
            "gaitfit" => {
                let g = |p: &str| leg(p, "#_heel", "#_toe", "#_ball", "#_ankle", "#_knee", "#_hip");
                ("pelvis".to_string(), g("l"), g("r"))
            }
            "opensim" => {
                let g = |p: &str| {
                    leg(
                        p,
                        "#CAL|#HEE",
                        "#TOE",
                        "#MT5|#MT2",
                        "#AJC|#LMAL+#MMAL|#LMAL",
                        "#KJC|#LFC+#MFC|#LFC",
                        "#HJC",
                    )
                };
                (
                    "RASI+LASI+RPSI+LPSI|RASI+LASI|Mid_ASIS+Mid_PSIS".to_string(),
                    g("L"),
                    g("R"),
                )
            }
            "cortex" => {
                let g = |p: &str| {
                    leg(
                        p,
                        "#.Heel",
                        "#.MT2|#.Toe|#.MT1",
                        "#.MT1+#.MT5|#.MT2",
                        "#.Ankle+#.Ankle.Medial|#.Ankle",
                        "#.Knee+#.Knee.Medial|#.Knee",
                        "#.GTR",
                    )
                };
                (
                    "R.ASIS+L.ASIS+R.PSIS+L.PSIS|R.ASIS+L.ASIS|V.Sacral".to_string(),
                    g("L"),
                    g("R"),
                )
            }
            "schreiber" => {
                let g = |p: &str| {
                    leg(
                        p,
                        "#_FCC",
                        "#_FM2|#_FM1",
                        "#_FM1+#_FM5|#_FM2",
                        "#_FAL+#_TAM|#_FAL",
                        "#_FLE+#_FME|#_FLE",
                        "#_FTC",
                    )
                };
                (
                    "R_IAS+L_IAS+R_IPS+L_IPS|R_IAS+L_IAS".to_string(),
                    g("L"),
                    g("R"),
                )
            }
            "pig" => {
                let g = |p: &str| leg(p, "#HEE", "#TOE", "#TOE", "#ANK", "#KNE", "#HJC");
                (
                    "RASI+LASI+RPSI+LPSI|RASI+LASI+SACR|RASI+LASI+VSAC|RASI+LASI+VSACR|RASI+LASI"
                        .to_string(),
                    g("L"),
                    g("R"),
                )
            }
            "winter" => {
                let g = |p: &str| leg(p, "# HEEL", "# TOE", "# MT5", "# ANKLE", "# KNEE", "# HIP");
                ("RIGHT HIP|LEFT HIP".to_string(), g("LEFT"), g("RIGHT"))
            }
            _ => return None,
        };
        Some(MarkerMap {
            name: name.to_string(),
            pelvis,
            left: l,
            right: r,
        })
    }

    /// The gaitfit landmark preset (what the generators' `Motion::to_trial()` produces).
    pub fn gaitfit() -> MarkerMap {
        Self::preset("gaitfit").unwrap_or_default()
    }

    /// The leg markers of `side`.
    pub fn leg(&self, side: Side) -> &LegMarkers {
        match side {
            Side::Left => &self.left,
            Side::Right => &self.right,
        }
    }

    /// Mutable leg markers of `side`.
    pub fn leg_mut(&mut self, side: Side) -> &mut LegMarkers {
        match side {
            Side::Left => &mut self.left,
            Side::Right => &mut self.right,
        }
    }

    /// How many of the event-critical roles (pelvis; heel and toe of each side) resolve in
    /// `markers`, and how many roles resolve in all.
    fn score(&self, markers: &MarkerSet) -> (usize, usize) {
        let mut critical = usize::from(resolve_spec(&self.pelvis, markers).is_some());
        let mut all = critical;
        for side in [Side::Left, Side::Right] {
            let l = self.leg(side);
            for (spec, crit) in [
                (&l.heel, true),
                (&l.toe, true),
                (&l.meta, false),
                (&l.ankle, false),
                (&l.knee, false),
                (&l.hip, false),
            ] {
                if resolve_spec(spec, markers).is_some() {
                    all += 1;
                    critical += usize::from(crit);
                }
            }
        }
        (critical, all)
    }

    /// The preset that resolves the most roles in `markers` (event-critical roles first).
    pub fn auto(markers: &MarkerSet) -> MarkerMap {
        let mut best: Option<((usize, usize), MarkerMap)> = None;
        for name in PRESETS {
            if let Some(m) = Self::preset(name) {
                let s = m.score(markers);
                if best.as_ref().is_none_or(|(bs, _)| s > *bs) {
                    best = Some((s, m));
                }
            }
        }
        best.map(|(_, m)| m).unwrap_or_else(Self::gaitfit)
    }

    /// Applies `role=SPEC` overrides, e.g. `pelvis=SACR`, `r_heel=RHEE`, `l_toe=LTOE|LMT2`.
    /// Roles: `pelvis`, and `{l,r}_{heel,toe,meta,ankle,knee,hip}`.
    pub fn set(&mut self, assignment: &str) -> Result<(), EventError> {
        let (role, spec) = assignment.split_once('=').ok_or_else(|| {
            EventError::Options(format!(
                "marker mapping '{assignment}': expected ROLE=NAME, e.g. r_heel=RHEE"
            ))
        })?;
        let role = role.trim().to_ascii_lowercase();
        let spec = spec.trim().to_string();
        if role == "pelvis" {
            self.pelvis = spec;
            self.name = "custom".into();
            return Ok(());
        }
        let bad = || {
            EventError::Options(format!(
                "marker mapping '{assignment}': unknown role '{role}'; use pelvis or \
                 l_/r_ followed by heel, toe, meta, ankle, knee or hip"
            ))
        };
        let (side, part) = role.split_once('_').ok_or_else(bad)?;
        let side = Side::parse(side).ok_or_else(bad)?;
        let l = self.leg_mut(side);
        match part {
            "heel" => l.heel = spec,
            "toe" => l.toe = spec,
            "meta" | "ball" => l.meta = spec,
            "ankle" => l.ankle = spec,
            "knee" => l.knee = spec,
            "hip" => l.hip = spec,
            _ => return Err(bad()),
        }
        self.name = "custom".into();
        Ok(())
    }
}

/// The marker indices of the first alternative of `spec` whose markers all exist.
pub fn resolve_spec(spec: &str, markers: &MarkerSet) -> Option<(String, Vec<usize>)> {
    for alt in spec.split('|') {
        let names: Vec<&str> = alt
            .split('+')
            .map(str::trim)
            .filter(|s| !s.is_empty())
            .collect();
        if names.is_empty() {
            continue;
        }
        let idx: Option<Vec<usize>> = names.iter().map(|n| markers.index(n)).collect();
        if let Some(idx) = idx {
            return Some((alt.trim().to_string(), idx));
        }
    }
    None
}

/// The trajectory of `spec` (the mean of its markers; `NaN` where any is missing), with the
/// alternative that was used.
pub fn trajectory(spec: &str, markers: &MarkerSet) -> Option<(String, Vec<[f64; 3]>)> {
    let (name, idx) = resolve_spec(spec, markers)?;
    let n = markers.len();
    let k = idx.len() as f64;
    let mut out = vec![[0.0; 3]; n];
    for &i in &idx {
        for (o, p) in out.iter_mut().zip(&markers.positions[i]) {
            for a in 0..3 {
                o[a] += p[a] / k;
            }
        }
    }
    Some((name, out))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn set(names: &[&str]) -> MarkerSet {
        MarkerSet {
            rate_hz: 100.0,
            time_s: vec![0.0, 0.01],
            names: names.iter().map(|s| s.to_string()).collect(),
            positions: names
                .iter()
                .enumerate()
                .map(|(i, _)| vec![[i as f64, 1.0, 2.0], [i as f64, 1.0, f64::NAN]])
                .collect(),
        }
    }

    #[test]
    fn auto_picks_the_matching_preset() {
        let hamner = set(&[
            "RASI", "LASI", "RPSI", "LPSI", "RCAL", "RTOE", "RMT5", "LCAL", "LTOE", "LMT5",
        ]);
        assert_eq!(MarkerMap::auto(&hamner).name, "opensim");
        let cortex = set(&["R.ASIS", "L.ASIS", "R.Heel", "L.Heel", "R.MT2", "L.MT2"]);
        assert_eq!(MarkerMap::auto(&cortex).name, "cortex");
        let gen = set(&[
            "pelvis", "l_heel", "r_heel", "l_toe", "r_toe", "l_ball", "r_ball",
        ]);
        assert_eq!(MarkerMap::auto(&gen).name, "gaitfit");
    }

    #[test]
    fn mean_of_alternative_and_nan_propagation() {
        let m = set(&["RASI", "LASI"]);
        let (name, t) = trajectory("RASI+LASI+RPSI+LPSI|RASI+LASI", &m).unwrap();
        assert_eq!(name, "RASI+LASI");
        assert_eq!(t[0][0], 0.5);
        assert!(t[1][2].is_nan());
        assert!(trajectory("XX|YY", &m).is_none());
    }

    #[test]
    fn overrides() {
        let mut m = MarkerMap::gaitfit();
        m.set("r_heel=RHEE").unwrap();
        assert_eq!(m.right.heel, "RHEE");
        m.set("pelvis = SACR").unwrap();
        assert_eq!(m.pelvis, "SACR");
        assert!(m.set("r_elbow=X").is_err());
        assert!(m.set("nonsense").is_err());
    }
}
