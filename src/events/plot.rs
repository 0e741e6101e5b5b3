//! A per-trial check plot (SVG and PNG): the vertical ground reaction force of every plate (top) and the
//! heel and toe positions relative to the pelvis along the direction of progression (bottom,
//! the Zeni signals), with the detected events drawn as vertical ticks: force events on the
//! force panel, Zeni coordinate events on the marker panel, reference events (C3D) as dashed
//! lines on both. Left foot blue, right foot red; heel strike solid, toe off dotted.
//!
//! The SVG is written directly (polylines and text elements) so that it needs no font file; the
//! viewer renders the text. The PNG ([`write_png`]) draws the same layout with plotters' bitmap
//! backend and the bundled DejaVu Sans (`assets/fonts/`).
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

/// The time axis of the plot: everything the force plates and the markers cover.
fn time_span(an: &Analysis) -> (f64, f64) {
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
    if t0.is_finite() {
        (t0, t1)
    } else {
        (0.0, 1.0)
    }
}

/// The largest vertical force (at least 100 N, so an empty panel still has a scale).
fn force_max(an: &Analysis) -> f64 {
    an.force
        .vertical
        .iter()
        .flat_map(|v| v.force_n.iter().copied())
        .filter(|v| v.is_finite())
        .fold(100.0f64, f64::max)
}

/// The finite range of the traces, (−1, 1) when there is none.
fn range<'a>(lines: impl Iterator<Item = &'a [f64]>) -> (f64, f64) {
    let (lo, hi) = lines
        .flat_map(|l| l.iter().copied())
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if lo.is_finite() {
        (lo, hi)
    } else {
        (-1.0, 1.0)
    }
}

/// The SVG text of the check plot of one analysed trial.
pub fn render_svg(an: &Analysis) -> String {
    let (t0, t1) = time_span(an);
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
    let fmax = force_max(an);
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
        let (lo, hi) = range(lines.iter().map(|l| l.0.as_slice()));
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

/// The same check plot as a PNG (plotters' bitmap backend; text in the bundled DejaVu Sans, so
/// no system font is needed). Plotters encodes PNGs only into a file, so the image is drawn into
/// a private temporary file first and then written to `path` through
/// [`crate::fsio::write_atomic_bytes`].
pub fn write_png(path: &Path, an: &Analysis) -> Result<(), super::EventError> {
    let err = |e: &dyn std::fmt::Display| super::EventError::Write {
        path: path.display().to_string(),
        message: e.to_string(),
    };
    png::register_font();
    let tmp = tempfile::Builder::new()
        .prefix("gaitfit-plot-")
        .suffix(".png")
        .tempfile()
        .map_err(|e| err(&e))?;
    {
        use plotters::prelude::*;
        let height = (TOP + 2.0 * PANEL_H + GAP + 40.0) as u32;
        let root = BitMapBackend::new(tmp.path(), (W as u32, height)).into_drawing_area();
        png::draw(&root, an).map_err(|e| err(&e))?;
        root.present().map_err(|e| err(&e))?;
    }
    let bytes = std::fs::read(tmp.path()).map_err(|e| err(&e))?;
    crate::fsio::write_atomic_bytes(path, &bytes)?;
    Ok(())
}

/// The PNG drawing: the layout of [`render_svg`] through plotters' primitives.
mod png {
    use super::{colour, Analysis, EventKind, GaitEvent, Panel, Side, GAP, LEFT, PANEL_H, RIGHT};
    use super::{TOP, W};
    use plotters::coord::Shift;
    use plotters::prelude::*;
    use std::sync::Once;

    static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
    static REGISTER: Once = Once::new();

    /// Registers the bundled font under the family plotters asks for.
    pub(super) fn register_font() {
        REGISTER.call_once(|| {
            // The bundled font is valid; if registration failed the PNG would lack text only.
            let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
        });
    }

    fn rgb(hex: &str) -> RGBColor {
        let v = u32::from_str_radix(hex.trim_start_matches('#'), 16).unwrap_or(0x555555);
        RGBColor((v >> 16) as u8, (v >> 8) as u8, v as u8)
    }

    type R = Result<(), String>;

    fn px(v: f64) -> i32 {
        v.round() as i32
    }

    fn text<DB: DrawingBackend>(
        a: &DrawingArea<DB, Shift>,
        s: &str,
        x: f64,
        y: f64,
        size: f64,
        pos: plotters::style::text_anchor::HPos,
    ) -> R {
        use plotters::style::text_anchor::{Pos, VPos};
        let style = TextStyle::from(("sans-serif", size).into_font())
            .color(&BLACK)
            .pos(Pos::new(pos, VPos::Bottom));
        a.draw(&Text::new(s.to_string(), (px(x), px(y)), style))
            .map_err(|e| e.to_string())
    }

    fn line<DB: DrawingBackend>(
        a: &DrawingArea<DB, Shift>,
        pts: Vec<(i32, i32)>,
        c: RGBColor,
        w: u32,
    ) -> R {
        a.draw(&PathElement::new(pts, c.stroke_width(w)))
            .map_err(|e| e.to_string())
    }

    /// A vertical line with dashes of `on` px and gaps of `off` px (`off` = 0: solid).
    fn vline<DB: DrawingBackend>(
        a: &DrawingArea<DB, Shift>,
        x: f64,
        y0: f64,
        y1: f64,
        c: RGBColor,
        on: f64,
        off: f64,
    ) -> R {
        if off <= 0.0 {
            return line(a, vec![(px(x), px(y0)), (px(x), px(y1))], c, 1);
        }
        let mut y = y0;
        while y < y1 {
            line(a, vec![(px(x), px(y)), (px(x), px((y + on).min(y1)))], c, 1)?;
            y += on + off;
        }
        Ok(())
    }

    fn axes<DB: DrawingBackend>(a: &DrawingArea<DB, Shift>, p: &Panel, title: &str) -> R {
        use plotters::style::text_anchor::HPos;
        let grey = RGBColor(0x44, 0x44, 0x44);
        let (x0, x1, y0, y1) = (LEFT, W - RIGHT, p.y0, p.y0 + PANEL_H);
        line(
            a,
            vec![
                (px(x0), px(y0)),
                (px(x1), px(y0)),
                (px(x1), px(y1)),
                (px(x0), px(y1)),
                (px(x0), px(y0)),
            ],
            grey,
            1,
        )?;
        text(a, title, LEFT, p.y0 - 6.0, 13.0, HPos::Left)?;
        for k in 0..=4 {
            let v = p.v0 + (p.v1 - p.v0) * k as f64 / 4.0;
            let y = p.y(v);
            line(a, vec![(px(LEFT - 4.0), px(y)), (px(LEFT), px(y))], grey, 1)?;
            text(
                a,
                &format!("{v:.2}"),
                LEFT - 6.0,
                y + 5.0,
                11.0,
                HPos::Right,
            )?;
        }
        let span = p.t1 - p.t0;
        let dt = [0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0]
            .into_iter()
            .find(|d| span / d <= 12.0)
            .unwrap_or(20.0);
        let mut t = (p.t0 / dt).ceil() * dt;
        while t <= p.t1 + 1e-9 {
            let x = p.x(t);
            line(a, vec![(px(x), px(y1)), (px(x), px(y1 + 4.0))], grey, 1)?;
            text(a, &format!("{t:.1}"), x, y1 + 17.0, 11.0, HPos::Center)?;
            t += dt;
        }
        Ok(())
    }

    fn trace<DB: DrawingBackend>(
        a: &DrawingArea<DB, Shift>,
        p: &Panel,
        t: &[f64],
        v: &[f64],
        c: RGBColor,
    ) -> R {
        let step = (t.len() / 4000).max(1);
        let mut pts = Vec::new();
        for i in (0..t.len().min(v.len())).step_by(step) {
            if v[i].is_finite() {
                pts.push((px(p.x(t[i])), px(p.y(v[i]))));
            } else if !pts.is_empty() {
                line(a, std::mem::take(&mut pts), c, 1)?;
            }
        }
        if !pts.is_empty() {
            line(a, pts, c, 1)?;
        }
        Ok(())
    }

    fn ticks<DB: DrawingBackend>(
        a: &DrawingArea<DB, Shift>,
        p: &Panel,
        events: &[GaitEvent],
        dashed: bool,
    ) -> R {
        for e in events {
            let hs_or_to = e.kind == EventKind::HeelStrike || e.kind == EventKind::ToeOff;
            if !hs_or_to || e.time_s < p.t0 || e.time_s > p.t1 {
                continue;
            }
            let (on, off) = match (dashed, e.kind) {
                (true, _) => (6.0, 3.0),
                (false, EventKind::ToeOff) => (2.0, 2.0),
                _ => (1.0, 0.0),
            };
            let c = rgb(colour(e.side));
            vline(a, p.x(e.time_s), p.y0, p.y0 + PANEL_H, c, on, off)?;
        }
        Ok(())
    }

    /// Draws the check plot of `an` (see [`super::render_svg`] for what it shows).
    pub(super) fn draw<DB: DrawingBackend>(a: &DrawingArea<DB, Shift>, an: &Analysis) -> R {
        use plotters::style::text_anchor::HPos;
        a.fill(&WHITE).map_err(|e| e.to_string())?;
        let (t0, t1) = super::time_span(an);
        text(
            a,
            &format!(
                "{} — events from {:?} (left blue, right red; heel strike solid, toe off \
                 dotted, reference dashed)",
                an.events.trial, an.events.primary
            ),
            LEFT,
            22.0,
            14.0,
            HPos::Left,
        )?;
        let fmax = super::force_max(an);
        let pf = Panel {
            y0: TOP,
            t0,
            t1,
            v0: -0.05 * fmax,
            v1: 1.05 * fmax,
        };
        axes(
            a,
            &pf,
            "vertical ground reaction force, N (filtered, baseline removed)",
        )?;
        for v in &an.force.vertical {
            let c = v.side.map(colour).unwrap_or("#555555");
            trace(a, &pf, &v.time_s, &v.force_n, rgb(c))?;
        }
        ticks(a, &pf, &an.events.force, false)?;
        ticks(a, &pf, &an.events.reference, true)?;
        let pm_y0 = TOP + PANEL_H + GAP;
        let Some(k) = &an.kinematics else {
            return text(
                a,
                "no markers in this trial",
                LEFT,
                pm_y0 + 20.0,
                13.0,
                HPos::Left,
            );
        };
        let mut lines: Vec<(Vec<f64>, RGBColor)> = Vec::new();
        for side in [Side::Left, Side::Right] {
            let l = k.leg(side);
            let c = rgb(colour(side));
            if let Some(h) = &l.heel {
                lines.push((k.relative_forward(h), c));
            }
            if let Some(t) = &l.toe {
                // Toe traces lighter than the heel's (the SVG dashes them).
                let RGBColor(r, g, b) = c;
                let mix = |x: u8| ((x as u16 + 2 * 255) / 3) as u8;
                lines.push((k.relative_forward(t), RGBColor(mix(r), mix(g), mix(b))));
            }
        }
        let (lo, hi) = super::range(lines.iter().map(|l| l.0.as_slice()));
        let pad = 0.05 * (hi - lo).max(1e-3);
        let pm = Panel {
            y0: pm_y0,
            t0,
            t1,
            v0: lo - pad,
            v1: hi + pad,
        };
        axes(
            a,
            &pm,
            "heel (dark) and toe (light) forward of the pelvis, m — Zeni coordinate events",
        )?;
        for (v, c) in &lines {
            trace(a, &pm, &k.time_s, v, *c)?;
        }
        ticks(a, &pm, &an.events.zeni_coordinate, false)?;
        ticks(a, &pm, &an.events.reference, true)?;
        let h = TOP + 2.0 * PANEL_H + GAP + 40.0;
        text(a, "time (s)", W / 2.0, h - 4.0, 12.0, HPos::Center)
    }
}
