//! A per-trial check plot (SVG): the vertical ground reaction force of every plate (top) and the
//! heel and toe positions relative to the pelvis along the direction of progression (bottom,
//! the Zeni signals), with the detected events drawn as vertical ticks: force events on the
//! force panel, Zeni coordinate events on the marker panel, reference events (C3D) as dashed
//! lines on both. Left foot blue, right foot red; heel strike solid, toe off dotted.
//!
//! The SVG is written directly (polylines and text elements) so that it needs no font file; the
//! viewer renders the text.
use super::{Analysis, EventKind, GaitEvent, Side};
use std::fmt::Write as _;
use std::path::Path;

const W: f64 = 1000.0;
const PANEL_H: f64 = 260.0;
const LEFT: f64 = 70.0;
const RIGHT: f64 = 20.0;
const TOP: f64 = 40.0;
const GAP: f64 = 50.0;

fn colour(side: Side) -> &'static str {
    match side {
        Side::Left => "#1f5fbf",
        Side::Right => "#c8321e",
    }
}

struct Panel {
    y0: f64,
    t0: f64,
    t1: f64,
    v0: f64,
    v1: f64,
}

impl Panel {
    fn x(&self, t: f64) -> f64 {
        LEFT + (t - self.t0) / (self.t1 - self.t0).max(1e-9) * (W - LEFT - RIGHT)
    }
    fn y(&self, v: f64) -> f64 {
        self.y0 + PANEL_H - (v - self.v0) / (self.v1 - self.v0).max(1e-12) * PANEL_H
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

fn polyline(svg: &mut String, p: &Panel, t: &[f64], v: &[f64], colour: &str, dash: &str) {
    // Thin long records to at most ~4000 points per line.
    let step = (t.len() / 4000).max(1);
    let mut pts = String::new();
    let mut open = false;
    for i in (0..t.len().min(v.len())).step_by(step) {
        if v[i].is_finite() {
            let _ = write!(pts, "{:.1},{:.1} ", p.x(t[i]), p.y(v[i]));
            open = true;
        } else if open {
            let _ = writeln!(
                svg,
                r#"<polyline fill="none" stroke="{colour}" stroke-width="1.2" {dash} points="{pts}"/>"#
            );
            pts.clear();
            open = false;
        }
    }
    if open {
        let _ = writeln!(
            svg,
            r#"<polyline fill="none" stroke="{colour}" stroke-width="1.2" {dash} points="{pts}"/>"#
        );
    }
}

fn axes(svg: &mut String, p: &Panel, title: &str, unit: &str) {
    let _ = writeln!(
        svg,
        r##"<rect x="{LEFT}" y="{}" width="{}" height="{PANEL_H}" fill="none" stroke="#444"/>"##,
        p.y0,
        W - LEFT - RIGHT
    );
    let _ = writeln!(
        svg,
        r#"<text x="{LEFT}" y="{}" font-size="13" font-family="sans-serif">{}</text>"#,
        p.y0 - 8.0,
        escape(title)
    );
    for k in 0..=4 {
        let v = p.v0 + (p.v1 - p.v0) * k as f64 / 4.0;
        let y = p.y(v);
        let _ = writeln!(
            svg,
            r##"<line x1="{}" x2="{LEFT}" y1="{y:.1}" y2="{y:.1}" stroke="#444"/><text x="{}" y="{:.1}" font-size="11" text-anchor="end" font-family="sans-serif">{v:.2}</text>"##,
            LEFT - 4.0,
            LEFT - 6.0,
            y + 4.0
        );
    }
    let span = p.t1 - p.t0;
    let dt = [0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .find(|d| span / d <= 12.0)
        .unwrap_or(20.0);
    let mut t = (p.t0 / dt).ceil() * dt;
    while t <= p.t1 + 1e-9 {
        let x = p.x(t);
        let yb = p.y0 + PANEL_H;
        let _ = writeln!(
            svg,
            r##"<line x1="{x:.1}" x2="{x:.1}" y1="{yb}" y2="{}" stroke="#444"/><text x="{x:.1}" y="{}" font-size="11" text-anchor="middle" font-family="sans-serif">{t:.1}</text>"##,
            yb + 4.0,
            yb + 16.0
        );
        t += dt;
    }
    let _ = writeln!(
        svg,
        r#"<text x="14" y="{:.1}" font-size="11" font-family="sans-serif" transform="rotate(-90 14 {:.1})" text-anchor="middle">{}</text>"#,
        p.y0 + PANEL_H / 2.0,
        p.y0 + PANEL_H / 2.0,
        escape(unit)
    );
}

fn ticks(svg: &mut String, p: &Panel, events: &[GaitEvent], dashed: bool) {
    for e in events {
        if e.kind != EventKind::HeelStrike && e.kind != EventKind::ToeOff {
            continue;
        }
        if e.time_s < p.t0 || e.time_s > p.t1 {
            continue;
        }
        let x = p.x(e.time_s);
        let dash = match (dashed, e.kind) {
            (true, _) => r#"stroke-dasharray="6 3""#,
            (false, EventKind::ToeOff) => r#"stroke-dasharray="2 2""#,
            _ => "",
        };
        let _ = writeln!(
            svg,
            r#"<line x1="{x:.1}" x2="{x:.1}" y1="{}" y2="{}" stroke="{}" stroke-width="1" {dash} opacity="0.8"/>"#,
            p.y0,
            p.y0 + PANEL_H,
            colour(e.side)
        );
    }
}

/// The SVG text of the check plot of one analysed trial.
pub fn render_svg(an: &Analysis) -> String {
    let mut t0 = f64::INFINITY;
    let mut t1 = f64::NEG_INFINITY;
    for v in &an.force.vertical {
        if let (Some(a), Some(b)) = (v.time_s.first(), v.time_s.last()) {
            t0 = t0.min(*a);
            t1 = t1.max(*b);
        }
    }
    if let Some(k) = &an.kinematics {
        if let (Some(a), Some(b)) = (k.time_s.first(), k.time_s.last()) {
            t0 = t0.min(*a);
            t1 = t1.max(*b);
        }
    }
    if !t0.is_finite() {
        t0 = 0.0;
        t1 = 1.0;
    }
    let height = TOP + 2.0 * PANEL_H + GAP + 40.0;
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{height}" viewBox="0 0 {W} {height}">"#
    );
    let _ = writeln!(svg, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let _ = writeln!(
        svg,
        r#"<text x="{LEFT}" y="18" font-size="14" font-family="sans-serif" font-weight="bold">{} — events from {:?} (left blue, right red; heel strike solid, toe off dotted, reference dashed)</text>"#,
        escape(&an.events.trial),
        an.events.primary
    );
    // Force panel.
    let fmax = an
        .force
        .vertical
        .iter()
        .flat_map(|v| v.force_n.iter().copied())
        .filter(|v| v.is_finite())
        .fold(100.0f64, f64::max);
    let pf = Panel {
        y0: TOP,
        t0,
        t1,
        v0: -0.05 * fmax,
        v1: 1.05 * fmax,
    };
    axes(
        &mut svg,
        &pf,
        "vertical ground reaction force (filtered, baseline removed)",
        "N",
    );
    for v in &an.force.vertical {
        let c = v.side.map(colour).unwrap_or("#555");
        polyline(&mut svg, &pf, &v.time_s, &v.force_n, c, "");
    }
    ticks(&mut svg, &pf, &an.events.force, false);
    ticks(&mut svg, &pf, &an.events.reference, true);
    // Marker panel.
    let pm_y0 = TOP + PANEL_H + GAP;
    if let Some(k) = &an.kinematics {
        let mut lines: Vec<(Vec<f64>, &str, &str)> = Vec::new();
        for side in [Side::Left, Side::Right] {
            let l = k.leg(side);
            if let Some(h) = &l.heel {
                lines.push((k.relative_forward(h), colour(side), ""));
            }
            if let Some(t) = &l.toe {
                lines.push((
                    k.relative_forward(t),
                    colour(side),
                    r#"stroke-dasharray="4 2""#,
                ));
            }
        }
        let (lo, hi) = lines
            .iter()
            .flat_map(|l| l.0.iter().copied())
            .filter(|v| v.is_finite())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
                (a.min(v), b.max(v))
            });
        let (lo, hi) = if lo.is_finite() {
            (lo, hi)
        } else {
            (-1.0, 1.0)
        };
        let pad = 0.05 * (hi - lo).max(1e-3);
        let pm = Panel {
            y0: pm_y0,
            t0,
            t1,
            v0: lo - pad,
            v1: hi + pad,
        };
        axes(
            &mut svg,
            &pm,
            "heel (solid) and toe (dashed) forward of the pelvis — Zeni coordinate events",
            "m",
        );
        for (v, c, d) in &lines {
            polyline(&mut svg, &pm, &k.time_s, v, c, d);
        }
        ticks(&mut svg, &pm, &an.events.zeni_coordinate, false);
        ticks(&mut svg, &pm, &an.events.reference, true);
    } else {
        let _ = writeln!(
            svg,
            r#"<text x="{LEFT}" y="{}" font-size="13" font-family="sans-serif">no markers in this trial</text>"#,
            pm_y0 + 20.0
        );
    }
    let _ = writeln!(
        svg,
        r#"<text x="{}" y="{}" font-size="12" text-anchor="middle" font-family="sans-serif">time (s)</text>"#,
        W / 2.0,
        height - 6.0
    );
    svg.push_str("</svg>\n");
    svg
}

/// Writes the check plot of `an` to `path` (SVG), atomically.
pub fn write_svg(path: &Path, an: &Analysis) -> Result<(), super::EventError> {
    crate::fsio::write_atomic_bytes(path, render_svg(an).as_bytes())?;
    Ok(())
}
