//! gaitfit's per-frame CSV: for data in any other format, exported to one comma-separated table
//! with one row per frame and the unit in every header.
//!
//! ```text
//! # gait = walk
//! # vertical = y
//! # forward = +x
//! # belt_speed_m_per_s = 1.3
//! # subject = s01
//! # body_height_m = 1.80
//! # leg_length_m = 0.92
//! # mass_kg = 70
//! time_s,RHEE_x_mm,RHEE_y_mm,RHEE_z_mm,…,r_belt_fx_n,r_belt_fy_n,r_belt_fz_n,r_belt_cop_x_mm,…
//! 0.000,101.2,52.0,310.4,…,3.1,612.0,-4.2,1200.5,…
//! ```
//! Rules:
//! - Lines starting with `#` before the header are `key = value` settings (all optional):
//!   `gait` (walk/run), `vertical` (x/y/z), `forward` (±x/y/z), `belt_speed_m_per_s` (a treadmill
//!   trial), `subject`, `body_height_m`, `leg_length_m`, `mass_kg`.
//! - The first column is `time_s` (or `time_ms`), strictly increasing.
//! - Marker columns: `<name>_x_<u>`, `<name>_y_<u>`, `<name>_z_<u>` with `u` = `m`, `cm` or
//!   `mm`; a marker with only x and y is 2-D (z = 0). An empty cell or `NaN` is a missing sample.
//! - Force columns: `<plate>_fx_n`, `<plate>_fy_n`, `<plate>_fz_n` (or `_kn`) — the ground
//!   reaction on the body —, optional `<plate>_cop_x_<u>` … (length units as above) and
//!   `<plate>_tz_n_m` (or `_n_mm`), the free moment about the vertical. A plate named `r…`/
//!   `right…` (`l…`/`left…`) carries that foot only. Force cells must be finite.
//! - Contact columns `l_contact`, `r_contact` (0/1, as gaitfit's generators write them): the
//!   writer's own contact state of that foot. They become reference events of source
//!   [`EventSource::Generated`] (a heel strike where a foot's flag turns 1, a toe off where it
//!   turns 0, at the first frame of the new state): kept for comparison, never used in place of
//!   detection (the point of reading a generated motion back is to measure it).
//! - Angle columns `<name>_x_deg`, `<name>_y_deg`, `<name>_z_deg` (or `_rad`), e.g. the
//!   generators' joint angles: checked to be numbers, counted in the notes, not used by event
//!   detection.
//! - Any other column is an error naming it (so a misspelt unit is never silently dropped).
//!
//! So the motion CSV that `gaitfit generate … -o motion.csv` writes
//! ([`crate::export::motion_csv`]) reads back as a trial of its landmarks (metres).
use super::frame_detect::Direction;
use super::text::{self, Num};
use super::types::{Axis, ForcePlate, MarkerSet, Setting, Trial};
use super::{finish, IngestError, ReadOptions};
use crate::gait::{EventKind, EventSource, Gait, GaitEvent, Side};
use std::path::Path;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Role {
    Time(f64),
    Marker(usize, usize, f64),
    Force(usize, usize, f64),
    Cop(usize, usize, f64),
    Moment(usize, f64),
    /// A foot's 0/1 contact flag.
    Contact(Side),
    /// A joint angle (validated, not kept).
    Angle,
}

fn axis_of(s: &str) -> Option<Axis> {
    match s {
        "x" => Some(Axis::X),
        "y" => Some(Axis::Y),
        "z" => Some(Axis::Z),
        _ => None,
    }
}

/// Reads a per-frame CSV into a trial.
pub fn read(path: &Path, opts: &ReadOptions) -> Result<Trial, IngestError> {
    let bytes = text::read_bytes(path)?;
    parse(&bytes, path, opts)
}

/// [`read`] on bytes in memory.
pub fn parse(bytes: &[u8], path: &Path, opts: &ReadOptions) -> Result<Trial, IngestError> {
    let mut it = text::lines(bytes);
    let mut settings: Vec<(String, String, usize)> = Vec::new();
    let (hl, header) = loop {
        let (ln, line) = it
            .next()
            .ok_or_else(|| IngestError::malformed(path, "no header line"))?;
        let t = text::text(line);
        if let Some(rest) = t.strip_prefix('#') {
            if let Some((k, v)) = rest.split_once('=') {
                settings.push((k.trim().to_ascii_lowercase(), v.trim().to_string(), ln));
            }
            continue;
        }
        if t.is_empty() {
            continue;
        }
        break (ln, line);
    };
    let names: Vec<String> = text::cells(header, b',').map(text::text).collect();
    let mut markers: Vec<String> = Vec::new();
    let mut plates: Vec<String> = Vec::new();
    let mut roles = Vec::with_capacity(names.len());
    let bad_unit = |col: &str, accepted: &str| IngestError::UnknownUnit {
        path: path.to_path_buf(),
        column: col.to_string(),
        message: format!("accepted: {accepted}"),
    };
    for (c, name) in names.iter().enumerate() {
        let lower = name.to_ascii_lowercase();
        if c == 0 {
            roles.push(match lower.as_str() {
                "time_s" => Role::Time(1.0),
                "time_ms" => Role::Time(1e-3),
                _ => {
                    return Err(IngestError::MissingColumn {
                        path: path.to_path_buf(),
                        column: "time_s".into(),
                        message: format!("line {hl}: the first column must be time_s or time_ms"),
                    })
                }
            });
            continue;
        }
        match lower.as_str() {
            "l_contact" | "left_contact" => {
                roles.push(Role::Contact(Side::Left));
                continue;
            }
            "r_contact" | "right_contact" => {
                roles.push(Role::Contact(Side::Right));
                continue;
            }
            _ => {}
        }
        let parts: Vec<&str> = lower.rsplitn(4, '_').collect(); // reversed
        let index_of = |list: &mut Vec<String>, n: &str| -> usize {
            list.iter().position(|x| x == n).unwrap_or_else(|| {
                list.push(n.to_string());
                list.len() - 1
            })
        };
        // The marker/plate name as written: the header minus its last k `_` parts.
        let orig_prefix = |k: usize| -> String {
            let cut: usize = parts.iter().take(k).map(|p| p.len() + 1).sum();
            name.get(..name.len().saturating_sub(cut))
                .unwrap_or_default()
                .to_string()
        };
        // <plate>_tz_n_m / _n_mm
        if lower.ends_with("_tz_n_m") || lower.ends_with("_tz_n_mm") {
            let s = if lower.ends_with("_n_mm") { 1e-3 } else { 1.0 };
            let p = index_of(&mut plates, &orig_prefix(3));
            roles.push(Role::Moment(p, s));
            continue;
        }
        // <plate>_cop_<axis>_<unit>
        if parts.len() == 4 && parts[2] == "cop" {
            let ax =
                axis_of(parts[1]).ok_or_else(|| bad_unit(name, "<plate>_cop_x|y|z_m|cm|mm"))?;
            let s = text::length_scale(parts[0])
                .filter(|_| matches!(parts[0], "m" | "cm" | "mm"))
                .ok_or_else(|| bad_unit(name, "<plate>_cop_x_m, _cm or _mm"))?;
            let p = index_of(&mut plates, &orig_prefix(3));
            roles.push(Role::Cop(p, ax.index(), s));
            continue;
        }
        if parts.len() >= 3 {
            let (unit, comp) = (parts[0], parts[1]);
            // <plate>_f<axis>_<n|kn>
            if let Some(ax) = comp.strip_prefix('f').and_then(axis_of) {
                let s = match unit {
                    "n" => 1.0,
                    "kn" => 1e3,
                    _ => return Err(bad_unit(name, "<plate>_fx_n or _kn")),
                };
                let p = index_of(&mut plates, &orig_prefix(2));
                roles.push(Role::Force(p, ax.index(), s));
                continue;
            }
            // <joint>_<axis>_deg|rad
            if axis_of(comp).is_some() && matches!(unit, "deg" | "rad") {
                roles.push(Role::Angle);
                continue;
            }
            // <marker>_<axis>_<unit>
            if let Some(ax) = axis_of(comp) {
                let s = text::length_scale(unit)
                    .filter(|_| matches!(unit, "m" | "cm" | "mm"))
                    .ok_or_else(|| bad_unit(name, "<marker>_x_m, _cm or _mm"))?;
                let m = index_of(&mut markers, &orig_prefix(2));
                roles.push(Role::Marker(m, ax.index(), s));
                continue;
            }
        }
        return Err(IngestError::cell(
            path,
            hl,
            name.clone(),
            "not a per-frame column: expected <marker>_x_mm, <plate>_fy_n, <plate>_cop_x_mm or \
             <plate>_tz_n_m, l_contact/r_contact or <joint>_x_deg (see ingest::frame_csv)",
        ));
    }
    // Each plate needs its three force components.
    for (p, pn) in plates.iter().enumerate() {
        for (k, c) in ["fx", "fy", "fz"].iter().enumerate() {
            if !roles
                .iter()
                .any(|r| matches!(r, Role::Force(q, a, _) if *q == p && *a == k))
            {
                return Err(IngestError::MissingColumn {
                    path: path.to_path_buf(),
                    column: format!("{pn}_{c}_n"),
                    message: "a plate needs fx, fy and fz".into(),
                });
            }
        }
    }
    let ncol = names.len();
    let mut time = Vec::new();
    let mut lines_of = Vec::new();
    let mut mpos: Vec<Vec<[f64; 3]>> = vec![Vec::new(); markers.len()];
    let mut has_z = vec![false; markers.len()];
    for r in &roles {
        if let Role::Marker(m, 2, _) = r {
            has_z[*m] = true;
        }
    }
    let mut force: Vec<Vec<[f64; 3]>> = vec![Vec::new(); plates.len()];
    let mut cop: Vec<Vec<[f64; 3]>> = vec![Vec::new(); plates.len()];
    let mut moment: Vec<Vec<f64>> = vec![Vec::new(); plates.len()];
    let mut has_cop = vec![false; plates.len()];
    // Per foot (left, right): the contact flag of the previous row, and the events it implies.
    let mut contact_prev: [Option<bool>; 2] = [None, None];
    let mut contact_events: Vec<GaitEvent> = Vec::new();
    let n_contact = roles
        .iter()
        .filter(|r| matches!(r, Role::Contact(_)))
        .count();
    let n_angle = roles.iter().filter(|r| matches!(r, Role::Angle)).count();
    for (ln, line) in it {
        if text::is_blank(line) {
            continue;
        }
        for (m, p) in mpos.iter_mut().enumerate() {
            p.push([0.0, 0.0, if has_z[m] { f64::NAN } else { 0.0 }]);
        }
        for p in 0..plates.len() {
            force[p].push([0.0; 3]);
            cop[p].push([f64::NAN; 3]);
            moment[p].push(f64::NAN);
        }
        let mut n = 0;
        for (c, cell) in text::cells(line, b',').enumerate().take(ncol) {
            n = c + 1;
            match roles[c] {
                Role::Time(s) => time.push(text::finite(cell, path, ln, &names[c])? * s),
                Role::Marker(m, k, s) => {
                    let v = match text::num(cell) {
                        Num::Empty => f64::NAN,
                        Num::Value(v) if !v.is_infinite() => v * s,
                        _ => {
                            return Err(IngestError::cell(
                                path,
                                ln,
                                names[c].clone(),
                                format!(
                                    "{:?} is not a number (leave it empty if missing)",
                                    text::text(cell)
                                ),
                            ))
                        }
                    };
                    if let Some(last) = mpos[m].last_mut() {
                        last[k] = v;
                    }
                }
                Role::Force(p, k, s) => {
                    let v = text::finite(cell, path, ln, &names[c])? * s;
                    if let Some(last) = force[p].last_mut() {
                        last[k] = v;
                    }
                }
                Role::Cop(p, k, s) => {
                    has_cop[p] = true;
                    let v = match text::num(cell) {
                        Num::Empty => f64::NAN,
                        Num::Value(v) if !v.is_infinite() => v * s,
                        _ => {
                            return Err(IngestError::cell(
                                path,
                                ln,
                                names[c].clone(),
                                "not a number",
                            ))
                        }
                    };
                    if let Some(last) = cop[p].last_mut() {
                        last[k] = v;
                    }
                }
                Role::Moment(p, s) => {
                    let v = text::finite(cell, path, ln, &names[c])? * s;
                    if let Some(last) = moment[p].last_mut() {
                        *last = v;
                    }
                }
                Role::Contact(side) => {
                    let v = text::finite(cell, path, ln, &names[c])?;
                    let on = if v == 0.0 {
                        false
                    } else if v == 1.0 {
                        true
                    } else {
                        return Err(IngestError::cell(
                            path,
                            ln,
                            names[c].clone(),
                            format!("{v} is not a contact flag (0 or 1)"),
                        ));
                    };
                    let k = usize::from(side == Side::Right);
                    if let (Some(prev), Some(&t)) = (contact_prev[k], time.last()) {
                        if prev != on {
                            contact_events.push(GaitEvent {
                                time_s: t,
                                side,
                                kind: if on {
                                    EventKind::HeelStrike
                                } else {
                                    EventKind::ToeOff
                                },
                                source: EventSource::Generated,
                            });
                        }
                    }
                    contact_prev[k] = Some(on);
                }
                Role::Angle => {
                    if matches!(text::num(cell), Num::Bad) {
                        return Err(IngestError::cell(
                            path,
                            ln,
                            names[c].clone(),
                            format!("{:?} is not a number", text::text(cell)),
                        ));
                    }
                }
            }
        }
        if n < ncol {
            return Err(IngestError::cell(
                path,
                ln,
                names[n].clone(),
                format!("row has {n} of {ncol} columns: the file is truncated or corrupt"),
            ));
        }
        lines_of.push(ln);
    }
    if time.len() < 2 {
        return Err(IngestError::malformed(path, "fewer than two data rows"));
    }
    text::check_time(&time, &lines_of, path, &names[0])?;
    let rate = text::rate_from_time(&time).unwrap_or(f64::NAN);
    let name = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut trial = Trial::new(path, name);
    trial.notes.push(format!(
        "per-frame CSV: {} markers, {} plates, {} rows at {rate} Hz",
        markers.len(),
        plates.len(),
        time.len()
    ));
    if n_contact > 0 {
        trial.notes.push(format!(
            "{n_contact} contact column(s): {} contact change(s) kept as the writer's reference \
             events (source generated; not used in place of detection)",
            contact_events.len()
        ));
    }
    if n_angle > 0 {
        trial.notes.push(format!(
            "{n_angle} angle column(s) read and checked; event detection does not use them"
        ));
    }
    contact_events.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    trial.reference_events = contact_events;
    if !markers.is_empty() {
        trial.markers = Some(MarkerSet {
            rate_hz: rate,
            time_s: time.clone(),
            names: markers,
            positions: mpos,
        });
    }
    for (p, pn) in plates.iter().enumerate() {
        let l = pn.to_ascii_lowercase();
        let side = if l == "r" || l.starts_with("r_") || l.starts_with("right") {
            Some(Side::Right)
        } else if l == "l" || l.starts_with("l_") || l.starts_with("left") {
            Some(Side::Left)
        } else {
            None
        };
        trial.plates.push(ForcePlate {
            name: pn.clone(),
            rate_hz: rate,
            time_s: time.clone(),
            force_n: std::mem::take(&mut force[p]),
            cop_m: std::mem::take(&mut cop[p]),
            free_moment_nm: if moment[p].iter().all(|v| v.is_nan()) {
                Vec::new()
            } else {
                std::mem::take(&mut moment[p])
            },
            side,
        });
    }
    // Settings.
    let mut opts = opts.clone();
    let mut declared = None;
    for (k, v, ln) in &settings {
        let bad = |what: &str| IngestError::cell(path, *ln, k.clone(), format!("{v:?}: {what}"));
        let num = || -> Result<f64, IngestError> {
            v.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| bad("not a number"))
        };
        match k.as_str() {
            "gait" => trial.gait = Some(Gait::parse(v).ok_or_else(|| bad("walk or run"))?),
            "vertical" => {
                let a = axis_of(v.trim_start_matches('+').to_ascii_lowercase().as_str())
                    .ok_or_else(|| bad("x, y or z"))?;
                declared = Some(Direction {
                    axis: a,
                    sign: 1.0,
                    how: format!("vertical = +{a:?} from the file's settings"),
                });
                opts.vertical = opts.vertical.or(Some(a));
            }
            "forward" => {
                let l = v.to_ascii_lowercase();
                let (sign, ax) = match l.strip_prefix('-') {
                    Some(r) => (-1.0, r.to_string()),
                    None => (1.0, l.trim_start_matches('+').to_string()),
                };
                let a = axis_of(&ax).ok_or_else(|| bad("±x, ±y or ±z"))?;
                opts.forward = opts.forward.or(Some((a, sign)));
            }
            "belt_speed_m_per_s" => {
                trial.setting = Setting::Treadmill {
                    belt_speed_m_per_s: num()?,
                }
            }
            "subject" => trial.subject.id = Some(v.clone()),
            "body_height_m" => trial.subject.body_height_m = Some(num()?),
            "leg_length_m" => trial.subject.leg_length_m = Some(num()?),
            "mass_kg" => trial.subject.mass_kg = Some(num()?),
            _ => trial
                .notes
                .push(format!("setting {k:?} (line {ln}) ignored")),
        }
    }
    if let Some(v) = &declared {
        let k = v.axis.index();
        for p in &mut trial.plates {
            for (f, c) in p.force_n.iter().zip(p.cop_m.iter_mut()) {
                if f[k] < opts.cop_min_force_n {
                    *c = [f64::NAN; 3];
                }
            }
        }
    }
    if trial.plates.iter().any(|p| !p.cop_m.is_empty())
        && has_cop.iter().any(|h| !h)
        && !trial.plates.is_empty()
    {
        trial
            .notes
            .push("plates without COP columns have NaN centre of pressure".into());
    }
    finish(&mut trial, &opts, declared);
    Ok(trial)
}

#[cfg(test)]
mod tests {
    use super::*;

    const CSV: &str = "# gait = walk\n# vertical = y\n# forward = -x\n# mass_kg = 70\n\
        time_s,RHEE_x_mm,RHEE_y_mm,RHEE_z_mm,r_belt_fx_n,r_belt_fy_n,r_belt_fz_n,r_belt_cop_x_mm,r_belt_cop_y_mm,r_belt_cop_z_mm\n\
        0.00,100,50,10,1,600,2,1000,0,200\n\
        0.01,,,,1,10,2,1000,0,200\n\
        0.02,102,50,10,1,610,2,1010,0,200\n";

    #[test]
    fn reads_markers_plates_and_settings() {
        let t = parse(CSV.as_bytes(), Path::new("f.csv"), &ReadOptions::default()).unwrap();
        let m = t.markers.as_ref().unwrap();
        assert_eq!(m.names, vec!["RHEE"]);
        assert!((m.positions[0][1][0] - 0.101).abs() < 1e-12, "gap filled");
        assert_eq!(t.plates[0].side, Some(Side::Right));
        assert_eq!(t.plates[0].force_n[0], [1.0, 600.0, 2.0]);
        assert!(t.plates[0].cop_m[1][0].is_nan());
        assert_eq!(t.plates[0].cop_m[2], [1.01, 0.0, 0.2]);
        assert_eq!(t.gait, Some(Gait::Walk));
        assert_eq!(t.subject.mass_kg, Some(70.0));
        let f = t.frame.unwrap();
        assert_eq!(
            (f.vertical, f.forward, f.forward_sign),
            (Axis::Y, Axis::X, -1.0)
        );
    }

    #[test]
    fn bad_columns_are_errors() {
        let p = Path::new("f.csv");
        let e = parse(
            CSV.replace("RHEE_z_mm", "RHEE_z_furlong").as_bytes(),
            p,
            &ReadOptions::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("RHEE_z_furlong"), "{e}");
        let e = parse(
            CSV.replace("0.02,102", "0.005,102").as_bytes(),
            p,
            &ReadOptions::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("row 8") && e.contains("time_s"), "{e}");
        let e = parse(
            CSV.replace(",600,", ",inf,").as_bytes(),
            p,
            &ReadOptions::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("r_belt_fy_n"), "{e}");
        let e = parse(
            CSV.replace("r_belt_fz_n", "speed").as_bytes(),
            p,
            &ReadOptions::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("speed"), "{e}");
    }

    #[test]
    fn contact_and_angle_columns_of_the_motion_csv() {
        let csv = "time_s,pelvis_x_m,pelvis_y_m,pelvis_z_m,l_contact,r_contact,l_knee_z_deg\n\
            0.00,0.0,1.0,0.0,1,0,-5.0\n\
            0.01,0.1,1.0,0.0,1,1,-6.0\n\
            0.02,0.2,1.0,0.0,0,1,-7.5\n\
            0.03,0.3,1.0,0.0,0,1,-9.0\n";
        let t = parse(csv.as_bytes(), Path::new("m.csv"), &ReadOptions::default()).unwrap();
        assert_eq!(t.markers.as_ref().unwrap().names, vec!["pelvis"]);
        let ev: Vec<(f64, Side, EventKind, EventSource)> = t
            .reference_events
            .iter()
            .map(|e| (e.time_s, e.side, e.kind, e.source))
            .collect();
        assert_eq!(
            ev,
            vec![
                (
                    0.01,
                    Side::Right,
                    EventKind::HeelStrike,
                    EventSource::Generated
                ),
                (0.02, Side::Left, EventKind::ToeOff, EventSource::Generated),
            ]
        );
        let p = Path::new("m.csv");
        let e = parse(
            csv.replace(",1,0,-5.0", ",2,0,-5.0").as_bytes(),
            p,
            &ReadOptions::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("l_contact") && e.contains("0 or 1"), "{e}");
        let e = parse(
            csv.replace("-6.0", "x").as_bytes(),
            p,
            &ReadOptions::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("l_knee_z_deg"), "{e}");
    }
}
