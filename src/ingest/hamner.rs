//! The Hamner & Delp (2013) running data set as laid out in `../shared/data/hamner2013/`:
//! `subjectNN/Run_V_grf.mot`, `subjectNN/Run_V.trc`, `subjectNN/static.trc`, and a `README.md`
//! one level up listing each runner's body mass; or OpenSim's distribution of it,
//! `subjectNN/expData/FILE` (no README: the subject id from the folder names, `static.trc` in
//! the subject folder or beside the file).
//!
//! What the files do not say and this module supplies (each with a note):
//! - the belt speed, from the file name (`Run_3` → 3 m/s; treadmill running);
//! - the body mass, from the data set's README (`subject01 72.84` …);
//! - the leg length, from `static.trc`: the mean height of the hip joint centres (`RHJC`,
//!   `LHJC`) above the floor (the lab's vertical origin, checked against the lowest foot
//!   markers), i.e. the greater-trochanter-to-floor convention of WBDS's leg length;
//! - the body height, which is not in the data: estimated from the hip-to-ankle length (thigh +
//!   shank) with the walking paper's Table B-1 (Bruderlin & Calvert 1989, Appendix B:
//!   l₃ + l₄ = (0.23669 + 0.24556)·h = 0.48225·h). The hip-to-ankle length is the chain
//!   HJC–KJC–AJC where the knee and ankle centres are given (subjects 01, 02), else the hip
//!   centre height minus the ankle centre height (midpoint of the malleoli).
use super::frame_detect;
use super::trc;
use super::types::{MarkerSet, Setting, Trial};
use super::{IngestError, ReadOptions};
use crate::gait::Gait;
use std::path::Path;

/// Leg (thigh + shank) length as a fraction of body height, Bruderlin & Calvert (1989) Table B-1.
pub const LEG_FRACTION_OF_HEIGHT: f64 = 0.23669 + 0.24556;

/// The belt speed in a Hamner file name (`Run_3`, `Run_3_grf`, `Run_3.5` → 3, 3, 3.5 m/s).
pub fn belt_speed_from_name(name: &str) -> Option<f64> {
    let lower = name.to_ascii_lowercase();
    let at = lower.find("run_")? + 4;
    let digits: String = lower[at..]
        .chars()
        .take_while(|c| c.is_ascii_digit() || *c == '.')
        .collect();
    digits.parse::<f64>().ok().filter(|v| *v > 0.0)
}

/// The Hamner subject folder of `path` and the data set's README (`None` when there is none),
/// when `path` lies in one of the data set's layouts: `…/subjectNN/FILE` with a README one level
/// up that names Hamner (the shared data), or OpenSim's distribution `…/subjectNN/expData/FILE`
/// (recognised by the folder names alone; `ExpData` in any case).
fn layout(path: &Path) -> Option<(String, Option<std::path::PathBuf>)> {
    let dir = path.parent()?;
    let exp = dir
        .file_name()
        .is_some_and(|n| n.to_string_lossy().eq_ignore_ascii_case("expdata"));
    let subject_dir = if exp { dir.parent()? } else { dir };
    let subject = subject_dir.file_name()?.to_string_lossy().into_owned();
    let digits = subject.strip_prefix("subject")?;
    if digits.is_empty() || !digits.chars().all(|c| c.is_ascii_digit()) {
        return None;
    }
    let readme = subject_dir.parent().map(|p| p.join("README.md"));
    let hamner_readme =
        readme.filter(|r| std::fs::read_to_string(r).is_ok_and(|text| text.contains("Hamner")));
    match (exp, hamner_readme) {
        (_, Some(r)) => Some((subject, Some(r))),
        (true, None) => Some((subject, None)),
        (false, None) => None,
    }
}

/// The body mass listed for `subject` in the README text (`subject01 72.84`).
pub fn mass_from_readme(readme: &str, subject: &str) -> Option<f64> {
    let mut rest = readme;
    while let Some(at) = rest.find(subject) {
        let after = &rest[at + subject.len()..];
        let num: String = after
            .trim_start_matches([' ', ':', '='])
            .chars()
            .take_while(|c| c.is_ascii_digit() || *c == '.')
            .collect();
        if after.starts_with([' ', ':', '=']) {
            if let Ok(v) = num.trim_end_matches('.').parse::<f64>() {
                return Some(v);
            }
        }
        rest = after;
    }
    None
}

/// Leg length, hip-to-ankle length and notes from a static standing trial (see the module docs).
pub fn leg_from_static(m: &MarkerSet) -> Result<(f64, f64, Vec<String>), String> {
    let v = frame_detect::vertical_from_markers(m)
        .ok_or("vertical axis not found from the marker names")?;
    let k = v.axis.index();
    let mean = |name: &str| -> Option<[f64; 3]> {
        let t = m.get(name)?;
        let ok: Vec<&[f64; 3]> = t
            .iter()
            .filter(|p| p.iter().all(|x| x.is_finite()))
            .collect();
        (!ok.is_empty())
            .then(|| [0, 1, 2].map(|j| ok.iter().map(|p| p[j]).sum::<f64>() / ok.len() as f64))
    };
    let up = |p: [f64; 3]| v.sign * p[k];
    let mut notes = Vec::new();
    let lowest = [
        "RCAL", "RTOE", "RMT5", "LCAL", "LTOE", "LMT5", "RHEE", "LHEE",
    ]
    .iter()
    .filter_map(|n| mean(n).map(up))
    .fold(f64::INFINITY, f64::min);
    if !(0.0..=0.12).contains(&lowest) {
        return Err(format!(
            "the lowest foot marker stands {lowest:.3} m above the lab origin: the floor is not \
             at 0"
        ));
    }
    let mut legs = Vec::new();
    let mut chains = Vec::new();
    for s in ["R", "L"] {
        let Some(hjc) = mean(&format!("{s}HJC")) else {
            continue;
        };
        legs.push(up(hjc));
        let kjc = mean(&format!("{s}KJC"));
        let ajc = mean(&format!("{s}AJC")).or_else(|| {
            let a = mean(&format!("{s}LMAL"))?;
            let b = mean(&format!("{s}MMAL"))?;
            Some([0, 1, 2].map(|j| (a[j] + b[j]) / 2.0))
        });
        let dist = |a: [f64; 3], b: [f64; 3]| {
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        };
        match (kjc, ajc) {
            (Some(kj), Some(aj)) => chains.push(dist(hjc, kj) + dist(kj, aj)),
            (None, Some(aj)) => chains.push(up(hjc) - up(aj)),
            _ => {}
        }
    }
    if legs.is_empty() {
        return Err("no hip joint centre (RHJC/LHJC) in the static trial".to_string());
    }
    let leg = legs.iter().sum::<f64>() / legs.len() as f64;
    let chain = if chains.is_empty() {
        f64::NAN
    } else {
        chains.iter().sum::<f64>() / chains.len() as f64
    };
    notes.push(format!(
        "leg length {leg:.3} m = mean hip joint centre height above the floor in static.trc \
         ({} side(s); lowest foot marker {lowest:.3} m above the lab origin)",
        legs.len()
    ));
    Ok((leg, chain, notes))
}

/// Fills in what the Hamner layout implies (belt speed, gait, subject id, mass, leg length,
/// estimated body height) when `path` lies in it; does nothing otherwise. A broken `static.trc`
/// is an error (it names that file).
pub fn apply(trial: &mut Trial, path: &Path, opts: &ReadOptions) -> Result<(), IngestError> {
    let Some((subject, readme)) = layout(path) else {
        return Ok(());
    };
    if readme.is_none() {
        trial.notes.push(format!(
            "OpenSim expData layout: subject {subject} from the folder names"
        ));
    }
    trial.subject.id = Some(subject.clone());
    trial.notes.push(format!(
        "Hamner & Delp (2013) running data set (subject {subject}); cite Hamner & Delp 2013 and \
         Fox 2024"
    ));
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    if let Some(v) = belt_speed_from_name(&stem) {
        if opts.belt_speed_m_per_s.is_none() {
            trial.setting = Setting::Treadmill {
                belt_speed_m_per_s: v,
            };
            trial.notes.push(format!(
                "setting: treadmill, belt speed {v} m/s from the file name"
            ));
        }
        trial.gait = Some(Gait::Run);
    }
    if let Some(text) = readme
        .as_ref()
        .and_then(|r| std::fs::read_to_string(r).ok())
    {
        match mass_from_readme(&text, &subject) {
            Some(m) => {
                trial.subject.mass_kg = Some(m);
                trial.subject.notes.push(format!(
                    "mass {m} kg from {}",
                    readme
                        .as_ref()
                        .map(|r| r.display().to_string())
                        .unwrap_or_default()
                ));
            }
            None => trial.subject.notes.push(format!(
                "mass: {subject} not listed in {}",
                readme
                    .as_ref()
                    .map(|r| r.display().to_string())
                    .unwrap_or_default()
            )),
        }
    }
    // static.trc beside the file, else in the subject folder (expData layout).
    let static_path = [path.with_file_name("static.trc")]
        .into_iter()
        .chain(
            path.parent()
                .and_then(|d| d.parent())
                .map(|d| d.join("static.trc")),
        )
        .find(|p| p.is_file())
        .unwrap_or_else(|| path.with_file_name("static.trc"));
    if static_path.is_file() {
        let (markers, _, _) = trc::read_markers(&static_path)?;
        match leg_from_static(&markers) {
            Ok((leg, chain, notes)) => {
                trial.subject.leg_length_m = Some(leg);
                trial.subject.notes.extend(notes);
                if chain.is_finite() {
                    let h = chain / LEG_FRACTION_OF_HEIGHT;
                    trial.subject.body_height_m = Some(h);
                    trial.notes.push(format!(
                        "warning: body height {h:.3} m estimated (not in the data) from \
                         static.trc's hip-to-ankle length"
                    ));
                    trial.subject.notes.push(format!(
                        "body height {h:.3} m ESTIMATED (not in the data) from the hip-to-ankle \
                         length {chain:.3} m of static.trc as thigh + shank = 0.48225·h \
                         (Bruderlin & Calvert 1989, Table B-1)"
                    ));
                }
            }
            Err(why) => trial.subject.notes.push(format!(
                "leg length not estimated from {}: {why}",
                static_path.display()
            )),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn opensim_exp_data_layout_is_recognised_by_its_folders() {
        let (subject, readme) =
            layout(Path::new("/nowhere/subject03/expData/Run_4_grf.mot")).unwrap();
        assert_eq!((subject.as_str(), readme), ("subject03", None));
        assert!(layout(Path::new("/nowhere/subject03/ExpData/Run_4.trc")).is_some());
        // Without expData, the shared layout needs its README.
        assert!(layout(Path::new("/nowhere/subject03/Run_4_grf.mot")).is_none());
        assert!(layout(Path::new("/nowhere/subjectX/expData/Run_4_grf.mot")).is_none());
    }

    #[test]
    fn speed_and_mass_parsing() {
        assert_eq!(belt_speed_from_name("Run_3"), Some(3.0));
        assert_eq!(belt_speed_from_name("Run_5_grf"), Some(5.0));
        assert_eq!(belt_speed_from_name("static"), None);
        let readme = "| `subjectNN/Run_V_grf.mot` | x |\nBody mass (kg): subject01 72.84, \
                      subject02 76.48.";
        assert_eq!(mass_from_readme(readme, "subject01"), Some(72.84));
        assert_eq!(mass_from_readme(readme, "subject02"), Some(76.48));
        assert_eq!(mass_from_readme(readme, "subject03"), None);
    }
}
