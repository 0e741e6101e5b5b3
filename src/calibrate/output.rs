//! The outputs of `gaitfit calibrate`: `residuals.csv`, `calibrated.json` and `report.html`
//! (one self-contained file, inline SVG, nothing from the network).
use super::drive::{attr_defs, SLOPED};
use super::measure::{rms_corr, Curves, Measurement, CYCLE_POINTS};
use super::solve::value;
use super::{
    CalibrateError, CalibratedAttr, CalibratedFile, CalibratedSubject, Calibration, SubjectResult,
};
use crate::events::Gait;
use std::fmt::Write as _;
use std::path::Path;

/// One row of `residuals.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct ResidualRow {
    /// Subject id.
    pub subject: String,
    /// walk or run.
    pub gait: Gait,
    /// Measured speed, m/s.
    pub speed_m_per_s: f64,
    /// Quantity name.
    pub quantity: String,
    /// Unit.
    pub unit: String,
    /// Measured value.
    pub measured: f64,
    /// Generated value (NaN when the generated motion does not show it).
    pub generated: f64,
    /// generated − measured.
    pub residual: f64,
    /// relations | calibrated.
    pub stage: &'static str,
}

fn scalar_quantities(gait: Gait) -> [(&'static str, &'static str, f64); 5] {
    [
        ("cadence_steps_per_min", "steps/min", 1.0),
        ("step_length_m", "m", 1.0),
        ("contact_time_s", "s", 1.0),
        match gait {
            Gait::Run => ("flight_time_s", "s", 1.0),
            Gait::Walk => ("double_support_pct_cycle", "% cycle", 1.0),
        },
        ("pelvis_excursion_m", "m", 1.0),
    ]
}

/// The residual rows of every subject, condition, quantity and stage. Where both sides have
/// angle curves over the normalised cycle, two rows per angle: `<angle>_rms_deg` (measured = 0,
/// generated = residual = the RMS difference) and `<angle>_corr` (Pearson's r of the two
/// curves, unit 1: measured = 1, generated = r, residual = r − 1), issue 21's "RMS and
/// correlation".
pub fn residual_rows(cal: &Calibration) -> Vec<ResidualRow> {
    let mut out = Vec::new();
    for r in &cal.subjects {
        let s = &r.subject;
        let mut stages = vec![("relations", &r.before), ("calibrated", &r.after)];
        if let Some(kb) = &r.kb {
            stages.push(("ko-badler", kb));
        }
        if let Some(ho) = &r.held_out {
            stages.push(("held-out", ho));
        }
        for (stage_name, stage) in stages {
            for (c, cond) in s.conditions.iter().enumerate() {
                let m = &cond.measured;
                let g = stage.generated[c].as_ref().ok();
                for (q, (name, unit, _)) in scalar_quantities(s.gait).iter().enumerate() {
                    let Some(mv) = value(m, q) else { continue };
                    let gv = g.and_then(|g| value(g, q)).unwrap_or(f64::NAN);
                    out.push(ResidualRow {
                        subject: s.name.clone(),
                        gait: s.gait,
                        speed_m_per_s: cond.speed(),
                        quantity: name.to_string(),
                        unit: unit.to_string(),
                        measured: mv,
                        generated: gv,
                        residual: gv - mv,
                        stage: stage_name,
                    });
                }
                if let (Some(mc), Some(gc)) = (&m.curves, g.and_then(|g| g.curves.as_ref())) {
                    for (name, a, b) in curve_pairs(mc, gc) {
                        let (rms, r) = rms_corr(a, b);
                        for (quantity, unit, measured, generated) in [
                            (format!("{name}_rms_deg"), "deg", 0.0, rms),
                            (format!("{name}_corr"), "1", 1.0, r),
                        ] {
                            out.push(ResidualRow {
                                subject: s.name.clone(),
                                gait: s.gait,
                                speed_m_per_s: cond.speed(),
                                quantity,
                                unit: unit.into(),
                                measured,
                                generated,
                                residual: generated - measured,
                                stage: stage_name,
                            });
                        }
                    }
                }
            }
        }
    }
    out
}

fn curve_pairs<'a>(m: &'a Curves, g: &'a Curves) -> [(&'static str, &'a [f64], &'a [f64]); 3] {
    [
        ("hip_flexion", &m.hip_deg, &g.hip_deg),
        ("knee_flexion", &m.knee_deg, &g.knee_deg),
        ("ankle_dorsiflexion", &m.ankle_deg, &g.ankle_deg),
    ]
}

fn werr(path: &Path, e: impl std::fmt::Display) -> CalibrateError {
    CalibrateError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

/// Writes `residuals.csv` (columns subject, gait, speed_m_per_s, quantity, unit, measured,
/// generated, residual, stage).
pub fn write_residuals(path: &Path, rows: &[ResidualRow]) -> Result<(), CalibrateError> {
    let mut s = String::from(
        "subject,gait,speed_m_per_s,quantity,unit,measured,generated,residual,stage\n",
    );
    let num = |v: f64| {
        if v.is_finite() {
            format!("{v:.6}")
        } else {
            String::new()
        }
    };
    for r in rows {
        let _ = writeln!(
            s,
            "{},{},{:.4},{},{},{},{},{},{}",
            r.subject,
            r.gait,
            r.speed_m_per_s,
            r.quantity,
            r.unit,
            num(r.measured),
            num(r.generated),
            num(r.residual),
            r.stage
        );
    }
    crate::fsio::write_atomic_bytes(path, s.as_bytes()).map_err(|e| werr(path, e))
}

/// The content of `calibrated.json`.
pub fn calibrated_file(cal: &Calibration) -> CalibratedFile {
    CalibratedFile {
        format: CalibratedFile::FORMAT.into(),
        relations: cal.relations_source.clone(),
        subjects: cal
            .subjects
            .iter()
            .map(|r| CalibratedSubject {
                subject: r.subject.name.clone(),
                gait: r.subject.gait,
                body_height_m: r.subject.body_height_m,
                mass_kg: r.subject.mass_kg,
                speeds_m_per_s: r.subject.conditions.iter().map(|c| c.speed()).collect(),
                reference_speed_m_per_s: r.model.slope_scale.map(|_| r.model.reference_speed),
                attributes: attr_defs(r.subject.gait)
                    .iter()
                    .enumerate()
                    .map(|(i, d)| {
                        // The slope of attribute i, if it has one (parameter 3 + k).
                        let k = SLOPED.iter().position(|&j| j == i).map(|k| 3 + k);
                        let k = k.filter(|&k| k < r.model.len());
                        CalibratedAttr {
                            name: d.name.into(),
                            unit: d.unit.into(),
                            before: r.before.params[i],
                            value: r.after.params[i],
                            se: r.se[i],
                            slope_per_m_per_s: k.map(|k| r.after.params[k]),
                            slope_se: k.and_then(|k| r.se[k]),
                        }
                    })
                    .collect(),
                solver: Some(r.termination.clone()),
            })
            .collect(),
    }
}

/// Writes `calibrated.json`.
pub fn write_calibrated(path: &Path, cal: &Calibration) -> Result<(), CalibrateError> {
    let json = serde_json::to_string_pretty(&calibrated_file(cal)).map_err(|e| werr(path, e))?;
    crate::fsio::write_atomic_bytes(path, json.as_bytes()).map_err(|e| werr(path, e))
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The opening of a figure's inline SVG: the `<svg>` element of `size` (width, height), the
/// title and the plot frame inside the margins (left, right, top, bottom).
fn svg_open(title: &str, (w, h): (f64, f64), (ml, mr, mt, mb): (f64, f64, f64, f64)) -> String {
    format!(
        "<svg class=\"fig\" xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
         viewBox=\"0 0 {w} {h}\" role=\"img\" aria-label=\"{t}\">\
         <text x=\"{ml}\" y=\"15\" font-size=\"12\">{t}</text>\
         <rect x=\"{ml}\" y=\"{mt}\" width=\"{pw}\" height=\"{ph}\" fill=\"none\" stroke=\"#999\"/>",
        t = esc(title),
        pw = w - ml - mr,
        ph = h - mt - mb
    )
}

/// An inline SVG of curves over the normalised cycle: (label, colour, dashed, values).
fn curve_svg(title: &str, series: &[(&str, &str, bool, &[f64])]) -> String {
    let (w, h, ml, mr, mt, mb) = (360.0, 220.0, 44.0, 10.0, 24.0, 30.0);
    let all: Vec<f64> = series
        .iter()
        .flat_map(|s| s.3.iter().copied())
        .filter(|v| v.is_finite())
        .collect();
    let (mut lo, mut hi) = all
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    if !(lo.is_finite() && hi.is_finite()) {
        lo = 0.0;
        hi = 1.0;
    }
    if hi - lo < 1e-9 {
        hi = lo + 1.0;
    }
    let pad = 0.05 * (hi - lo);
    let (lo, hi) = (lo - pad, hi + pad);
    let x = |i: usize| ml + (w - ml - mr) * i as f64 / (CYCLE_POINTS - 1) as f64;
    let y = |v: f64| mt + (h - mt - mb) * (1.0 - (v - lo) / (hi - lo));
    let mut s = svg_open(title, (w, h), (ml, mr, mt, mb));
    for k in 0..=4 {
        let v = lo + (hi - lo) * k as f64 / 4.0;
        let _ = write!(
            s,
            "<text x=\"{}\" y=\"{:.1}\" font-size=\"9\" text-anchor=\"end\">{v:.0}</text>",
            ml - 3.0,
            y(v) + 3.0
        );
    }
    for k in 0..=4 {
        let i = k * 25;
        let _ = write!(
            s,
            "<text x=\"{:.1}\" y=\"{}\" font-size=\"9\" text-anchor=\"middle\">{i} %</text>",
            x(i),
            h - mb + 12.0
        );
    }
    for (n, (label, colour, dashed, v)) in series.iter().enumerate() {
        let pts: Vec<String> = v
            .iter()
            .enumerate()
            .filter(|(_, v)| v.is_finite())
            .map(|(i, v)| format!("{:.1},{:.1}", x(i), y(*v)))
            .collect();
        let _ = write!(
            s,
            "<polyline class=\"series\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.6\"{} points=\"{}\"/>",
            if *dashed { " stroke-dasharray=\"5,3\"" } else { "" },
            pts.join(" ")
        );
        let ly = h - 6.0;
        // Up to 110 px per legend entry, fewer when more series share the width.
        let lx = ml + ((w - ml - mr) / series.len() as f64).min(110.0) * n as f64;
        let _ = write!(
            s,
            "<line x1=\"{lx}\" y1=\"{ly}\" x2=\"{}\" y2=\"{ly}\" stroke=\"{colour}\"{}/>\
             <text x=\"{}\" y=\"{}\" font-size=\"9\">{}</text>",
            lx + 14.0,
            if *dashed {
                " stroke-dasharray=\"5,3\""
            } else {
                ""
            },
            lx + 17.0,
            ly + 3.0,
            esc(label)
        );
    }
    s.push_str("</svg>");
    s
}

/// One series of a speed plot: label, colour, dashed, points (speed m/s, value, ± SD).
type SpeedSeries<'a> = (&'a str, &'a str, bool, Vec<(f64, f64, Option<f64>)>);

/// An inline SVG of one fitted quantity against speed, the calibration's fit plot: the measured
/// means (± the step-to-step SD) and each stage's generated values, every point marked (a
/// subject measured at one speed has one point per series) and joined across speeds.
fn speed_svg(title: &str, series: &[SpeedSeries]) -> String {
    let (w, h, ml, mr, mt, mb) = (360.0, 220.0, 44.0, 10.0, 24.0, 30.0);
    let pts: Vec<(f64, f64, Option<f64>)> = series
        .iter()
        .flat_map(|s| s.3.iter().copied())
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .collect();
    let range = |v: &mut dyn Iterator<Item = f64>, min_half: f64| {
        let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
        if !(lo.is_finite() && hi.is_finite()) {
            return (0.0, 1.0);
        }
        let mid = 0.5 * (lo + hi);
        let half = (0.5 * (hi - lo)).max(min_half) * 1.1;
        (mid - half, mid + half)
    };
    let (x0, x1) = range(&mut pts.iter().map(|p| p.0), 0.25);
    let (y0, y1) = range(
        &mut pts
            .iter()
            .flat_map(|p| [p.1 - p.2.unwrap_or(0.0), p.1 + p.2.unwrap_or(0.0)]),
        1e-6,
    );
    let x = |v: f64| ml + (w - ml - mr) * (v - x0) / (x1 - x0);
    let y = |v: f64| mt + (h - mt - mb) * (1.0 - (v - y0) / (y1 - y0));
    let d = (2.0 - (y1 - y0).log10().floor()).clamp(0.0, 4.0) as usize;
    let mut s = svg_open(title, (w, h), (ml, mr, mt, mb));
    for k in 0..=4 {
        let v = y0 + (y1 - y0) * k as f64 / 4.0;
        let u = x0 + (x1 - x0) * k as f64 / 4.0;
        let _ = write!(
            s,
            "<text x=\"{}\" y=\"{:.1}\" font-size=\"9\" text-anchor=\"end\">{v:.d$}</text>\
             <text x=\"{:.1}\" y=\"{}\" font-size=\"9\" text-anchor=\"middle\">{u:.2}</text>",
            ml - 3.0,
            y(v) + 3.0,
            x(u),
            h - mb + 12.0
        );
    }
    for (n, (label, colour, dashed, v)) in series.iter().enumerate() {
        let dash = if *dashed {
            " stroke-dasharray=\"5,3\""
        } else {
            ""
        };
        let v: Vec<_> = v
            .iter()
            .filter(|p| p.0.is_finite() && p.1.is_finite())
            .collect();
        if v.len() > 1 {
            let line: Vec<String> = v
                .iter()
                .map(|p| format!("{:.1},{:.1}", x(p.0), y(p.1)))
                .collect();
            let _ = write!(
                s,
                "<polyline class=\"series\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.4\"{dash} points=\"{}\"/>",
                line.join(" ")
            );
        }
        // A cross at each point, and the ± SD bar.
        let mut marks = String::new();
        for p in &v {
            let (px, py) = (x(p.0), y(p.1));
            let _ = write!(
                marks,
                "M{:.1},{py:.1}L{:.1},{py:.1}M{px:.1},{:.1}L{px:.1},{:.1}",
                px - 4.0,
                px + 4.0,
                py - 4.0,
                py + 4.0
            );
            if let Some(sd) = p.2.filter(|sd| *sd > 0.0) {
                let _ = write!(
                    marks,
                    "M{px:.1},{:.1}L{px:.1},{:.1}",
                    y(p.1 - sd),
                    y(p.1 + sd)
                );
            }
        }
        let _ = write!(
            s,
            "<path class=\"series\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"1.4\" d=\"{marks}\"/>"
        );
        let ly = h - 6.0;
        let lx = ml + ((w - ml - mr) / series.len() as f64).min(110.0) * n as f64;
        let _ = write!(
            s,
            "<line x1=\"{lx}\" y1=\"{ly}\" x2=\"{}\" y2=\"{ly}\" stroke=\"{colour}\"{dash}/>\
             <text x=\"{}\" y=\"{}\" font-size=\"9\">{}</text>",
            lx + 14.0,
            lx + 17.0,
            ly + 3.0,
            esc(label)
        );
    }
    s.push_str("</svg>");
    s
}

/// The fit plots of a subject: cadence, step length and flight or double support against speed
/// (measured ± SD, relations, calibrated, and held out when computed).
fn fit_plots(r: &SubjectResult) -> String {
    let s = &r.subject;
    let mut out = String::new();
    let phase = match s.gait {
        Gait::Run => ("flight (ms)", 1000.0),
        Gait::Walk => ("double support (% cycle)", 1.0),
    };
    for (q, (name, scale)) in [
        (0, ("cadence (steps/min)", 1.0)),
        (1, ("step length (cm)", 100.0)),
        (3, phase),
    ] {
        let of = |st: &[Result<Measurement, String>]| -> Vec<(f64, f64, Option<f64>)> {
            s.conditions
                .iter()
                .zip(st)
                .filter_map(|(c, g)| {
                    let v = value(g.as_ref().ok()?, q)?;
                    Some((c.speed(), scale * v, None))
                })
                .collect()
        };
        let measured: Vec<_> = s
            .conditions
            .iter()
            .filter_map(|c| {
                let v = value(&c.measured, q)?;
                let sd = c.measured.quantities.sd[q].map(|sd| scale * sd);
                Some((c.speed(), scale * v, sd))
            })
            .collect();
        if measured.is_empty() {
            continue;
        }
        let mut series: Vec<SpeedSeries> = vec![
            ("measured ± SD", "#000", false, measured),
            ("relations", "#1f77b4", true, of(&r.before.generated)),
            ("calibrated", "#d62728", false, of(&r.after.generated)),
        ];
        if let Some(ho) = &r.held_out {
            series.push(("held out", "#2ca02c", true, of(&ho.generated)));
        }
        out.push_str(&speed_svg(
            &format!("{}: {name} against speed (m/s)", s.name),
            &series,
        ));
    }
    out
}

fn fmt(v: Option<f64>, d: usize) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{v:.d$}"),
        _ => "—".into(),
    }
}

fn stage_cell(g: &Result<Measurement, String>, q: usize, d: usize, m: Option<f64>) -> String {
    match g {
        Ok(g) => {
            let v = value(g, q);
            match (v, m) {
                (Some(v), Some(m)) => format!("{v:.d$} ({:+.d$})", v - m),
                (v, _) => fmt(v, d),
            }
        }
        Err(e) => format!("<span title=\"{}\">failed</span>", esc(e)),
    }
}

/// Writes `report.html`.
pub fn write_report(path: &Path, cal: &Calibration) -> Result<(), CalibrateError> {
    let mut h = String::from(
        "<!DOCTYPE html><html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>gaitfit calibrate</title><style>\
         body{font-family:sans-serif;margin:1.5em;max-width:1200px}\
         table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:2px 6px;\
         font-size:13px;text-align:right}th{background:#eee}td:first-child{text-align:left}\
         .figs{display:flex;flex-wrap:wrap;gap:8px}.note{color:#555;font-size:12px}\
         </style></head><body>",
    );
    let _ = write!(
        h,
        "<h1>gaitfit calibrate</h1><p>Relations: {}. Generated motions at {} frames/s, {} steady \
         steps per condition, measured by the same event pipeline as the trials. Residual = \
         generated − measured; stage <i>relations</i>: the relations with the generators' default \
         attributes; stage <i>calibrated</i>: the per-subject attributes found by a trust-region Gauss–Newton on \
         the weighted residual objective (weights: the measured step-to-step SD; cadence, step \
         length, flight or double support and pelvis excursion — the contact time is reported, not \
         fitted, being the step time and the flight or double support together); stage \
         <i>Ko–Badler</i> (walks with another condition of the subject): each condition generalized \
         (Ko &amp; Badler 1993, paper's μ-functions) from the subject's own walk at the nearest other \
         speed to the measured step length and duration, nothing calibrated.</p>",
        esc(&cal.relations_source),
        cal.drive.fps,
        cal.drive.steps
    );
    for n in &cal.relation_notes {
        let _ = write!(h, "<p class=\"note\">{}</p>", esc(n));
    }
    if let Some(l) = &cal.kb_leave_one_out {
        h.push_str(&kb_loo_html(l));
    }
    for f in &cal.failed {
        let _ = write!(h, "<p class=\"note\">not measured: {}</p>", esc(f));
    }
    for r in &cal.subjects {
        let s = &r.subject;
        let _ = write!(
            h,
            "<section><h2>{} — {}</h2><p>Body height {:.3} m{}; {} condition(s); objective {:.2} → {:.2}; \
             trust region {}{} ({} objective evaluations).</p>",
            esc(&s.name),
            s.gait,
            s.body_height_m,
            if s.mass_kg > 0.0 {
                format!(", mass {:.1} kg", s.mass_kg)
            } else {
                String::new()
            },
            s.conditions.len(),
            r.before.cost,
            r.after.cost,
            if r.termination.converged {
                ""
            } else {
                "<b>not converged</b>: "
            },
            esc(&if r.termination.converged {
                r.termination.describe()
            } else {
                format!(
                    "{} after {} iteration(s)",
                    r.termination.reason, r.termination.iterations
                )
            }),
            r.termination.evaluations
        );
        for n in &s.notes {
            let _ = write!(h, "<p class=\"note\">{}</p>", esc(n));
        }
        // Attributes.
        h.push_str("<table><tr><th>attribute</th><th>unit</th><th>before</th><th>after</th><th>± SE</th><th>meaning</th></tr>");
        for (i, d) in attr_defs(s.gait).iter().enumerate() {
            let _ = write!(
                h,
                "<tr><td>{}</td><td>{}</td><td>{:.4}</td><td>{:.4}</td><td>{}</td><td style=\"text-align:left\">{}</td></tr>",
                d.name,
                esc(d.unit),
                r.before.params[i],
                r.after.params[i],
                fmt(r.se[i], 4),
                esc(d.doc)
            );
        }
        if r.model.slope_scale.is_some() {
            for (k, &i) in SLOPED.iter().enumerate() {
                let d = &attr_defs(s.gait)[i];
                let _ = write!(
                    h,
                    "<tr><td>{} slope</td><td>{} per m/s</td><td>0</td><td>{:.4}</td><td>{}</td><td style=\"text-align:left\">\
                     change of {} per m/s away from {:.2} m/s (the value above holds there)</td></tr>",
                    d.name,
                    esc(d.unit),
                    r.after.params[3 + k],
                    fmt(r.se[3 + k], 4),
                    d.name,
                    r.model.reference_speed
                );
            }
        }
        h.push_str("</table>");
        // Residual table.
        let mut extra: Vec<(String, &super::solve::Stage)> = Vec::new();
        if let Some(kb) = &r.kb {
            extra.push((
                format!("Ko–Badler, {} variant (resid.)", cal.kb_variant.name()),
                kb,
            ));
        }
        if let Some(ho) = &r.held_out {
            extra.push((
                "held out: calibrated on the other speeds (resid.)".to_string(),
                ho,
            ));
        }
        let kb_head: String = extra
            .iter()
            .map(|(name, _)| format!("<th>{}</th>", esc(name)))
            .collect();
        let _ = write!(h, "<table><tr><th>trial</th><th>speed m/s</th><th>quantity</th><th>measured</th><th>relations (resid.)</th><th>calibrated (resid.)</th>{kb_head}</tr>");
        let kb_cell = |c: usize, f: &dyn Fn(&Result<Measurement, String>) -> String| {
            extra
                .iter()
                .map(|(_, st)| format!("<td>{}</td>", f(&st.generated[c])))
                .collect::<String>()
        };
        for (c, cond) in s.conditions.iter().enumerate() {
            let m = &cond.measured;
            for (q, (name, unit, _)) in scalar_quantities(s.gait).iter().enumerate() {
                let mv = value(m, q);
                if mv.is_none() {
                    continue;
                }
                let d = if unit == &"m" || unit == &"s" { 3 } else { 1 };
                let _ = write!(
                    h,
                    "<tr><td>{}</td><td>{:.2}</td><td>{} [{}]</td><td>{}</td><td>{}</td><td>{}</td>{}</tr>",
                    esc(&cond.trial),
                    cond.speed(),
                    name,
                    esc(unit),
                    fmt(mv, d),
                    stage_cell(&r.before.generated[c], q, d, mv),
                    stage_cell(&r.after.generated[c], q, d, mv),
                    kb_cell(c, &|g| stage_cell(g, q, d, mv))
                );
            }
            if let Some(mc) = &m.curves {
                for (k, name) in ["hip_flexion", "knee_flexion", "ankle_dorsiflexion"]
                    .iter()
                    .enumerate()
                {
                    let cell = |g: &Result<Measurement, String>| match g
                        .as_ref()
                        .ok()
                        .and_then(|g| g.curves.as_ref())
                    {
                        Some(gc) => {
                            let p = curve_pairs(mc, gc);
                            let (rms, cor) = rms_corr(p[k].1, p[k].2);
                            format!("RMS {rms:.1}°, r {cor:.2}")
                        }
                        None => "—".into(),
                    };
                    let _ = write!(
                        h,
                        "<tr><td>{}</td><td>{:.2}</td><td>{} curve</td><td>{} strides</td><td>{}</td><td>{}</td>{}</tr>",
                        esc(&cond.trial),
                        cond.speed(),
                        name,
                        mc.strides,
                        cell(&r.before.generated[c]),
                        cell(&r.after.generated[c]),
                        kb_cell(c, &cell)
                    );
                }
            }
        }
        h.push_str("</table><div class=\"figs\">");
        h.push_str(&fit_plots(r));
        for (c, cond) in s.conditions.iter().enumerate() {
            let Some(mc) = &cond.measured.curves else {
                continue;
            };
            let gb = r.before.generated[c]
                .as_ref()
                .ok()
                .and_then(|g| g.curves.as_ref());
            let ga = r.after.generated[c]
                .as_ref()
                .ok()
                .and_then(|g| g.curves.as_ref());
            let gk =
                r.kb.as_ref()
                    .and_then(|kb| kb.generated[c].as_ref().ok())
                    .and_then(|g| g.curves.as_ref());
            for k in 0..3 {
                let mut series: Vec<(&str, &str, bool, &[f64])> =
                    vec![("measured", "#000", false, curve_pairs(mc, mc)[k].1)];
                if let Some(g) = gb {
                    series.push(("relations", "#1f77b4", true, curve_pairs(g, g)[k].1));
                }
                if let Some(g) = ga {
                    series.push(("calibrated", "#d62728", false, curve_pairs(g, g)[k].1));
                }
                if let Some(g) = gk {
                    series.push(("Ko–Badler", "#2ca02c", true, curve_pairs(g, g)[k].1));
                }
                let title = format!(
                    "{} {:.2} m/s: {} (deg)",
                    cond.trial,
                    cond.speed(),
                    ["hip (thigh)", "knee flexion", "ankle dorsiflexion"][k]
                );
                h.push_str(&curve_svg(&title, &series));
            }
        }
        h.push_str("</div>");
        let mut gen_notes = r.after.notes.clone();
        gen_notes.extend(r.before.notes.iter().cloned());
        if let Some(kb) = &r.kb {
            gen_notes.extend(kb.notes.iter().cloned());
            for (c, g) in kb.generated.iter().enumerate() {
                if let Err(e) = g {
                    gen_notes.push(format!("Ko–Badler {}: {e}", s.conditions[c].trial));
                }
            }
        }
        gen_notes.sort();
        gen_notes.dedup();
        for n in gen_notes.iter().take(8) {
            let _ = write!(h, "<p class=\"note\">generator: {}</p>", esc(n));
        }
        h.push_str("</section>");
    }
    h.push_str("<p class=\"note\">Data: cite the sources of the inputs (see ../shared/data/README.md).</p></body></html>\n");
    crate::fsio::write_atomic_bytes(path, h.as_bytes()).map_err(|e| werr(path, e))
}

/// The Ko–Badler leave-one-out table (paper variant, carried variant, naive scaling).
fn kb_loo_html(l: &super::kb::KbLeaveOneOut) -> String {
    let row = |name: &str, s: &crate::generator::generalize::compare::Scores| {
        format!(
            "<tr><td>{name}</td><td>{:.1}</td><td>{:.1}</td><td>{:.1}</td><td>{:.1}</td></tr>",
            s.hip_deg, s.knee_deg, s.ankle_deg, s.ankle_path_cm
        )
    };
    let m = &l.mean;
    format!(
        "<section><h2>Ko–Badler across subjects (leave-one-out)</h2><p>Each of {} strides of {} \
         walking subjects generalized (ψ then φ) from every other subject's stride of the same leg \
         and condition, scored against the measured stride: RMS over the normalized stride, mean \
         per target then over targets ({} pair(s) left out: a μ out of its range). <i>Paper</i>: \
         the angles of W's rigid two-link drawing. <i>Carried</i>: the source's measured angle \
         curves kept in W — the generalized step drawn with the paper's feet and the hip placed \
         where the drawn angles come nearest the source's measured curves (what `gaitfit generate generalize --kb-variant carried` draws); the \
         ankle path is the paper's. <i>Naive scaling</i>: the source's measured stride unchanged on normalized \
         time, its ankle path scaled by the leg-length ratio.</p><table><tr><th>candidate</th>\
         <th>hip (deg)</th><th>knee (deg)</th><th>ankle (deg)</th><th>swing ankle path (cm)</th>\
         </tr>{}{}{}{}</table><p class=\"note\">The carried variant is closer than the paper's but \
         not as close as naive scaling: φ changes the drawn angles more than a subject's own \
         change of speed does (eq. 27 pins the hip heights and lowers the mid-stance hip of \
         longer steps).</p></section>",
        l.strides,
        l.subjects,
        l.left_out,
        row("paper", &m.generalized_same),
        row("carried", &m.carried_same),
        row("naive scaling", &m.naive_same),
        row("model floor (own step drawn)", &m.floor),
    )
}

/// Writes `residuals.csv`, `calibrated.json` and `report.html` into `dir`.
pub fn write_all(dir: &Path, cal: &Calibration) -> Result<(), CalibrateError> {
    std::fs::create_dir_all(dir).map_err(|e| werr(dir, e))?;
    write_residuals(&dir.join("residuals.csv"), &residual_rows(cal))?;
    write_calibrated(&dir.join("calibrated.json"), cal)?;
    write_report(&dir.join("report.html"), cal)
}
