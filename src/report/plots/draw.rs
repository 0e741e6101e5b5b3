//! Drawing a figure [`super::Spec`] with plotters, on any backend (SVG, or the PNG raster of
//! [`crate::report::raster`]): panels (axes, data layer, curves, bands, constraint regions),
//! the density shading and the legend strip. What a figure shows is decided in [`super`].
use super::*;

pub(super) fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

pub(super) fn draw_line<DB: DrawingBackend>(
    chart: &mut ChartContext<
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    l: &Line,
) -> Result<(), String> {
    let pts: Vec<(f64, f64)> = l.pts.iter().copied().filter(|p| p.1.is_finite()).collect();
    if pts.len() < 2 {
        return Ok(());
    }
    let (color, width, dashed) = match l.kind {
        LineKind::Refit => (BLACK, 2, false),
        LineKind::Published => (PUBLISHED, 2, true),
        LineKind::GroupCurve(g) => (group_color(g), 2, false),
        LineKind::GroupMean(g) => (group_color(g), 2, false),
        LineKind::Reference => (RGBColor(90, 90, 90), 1, true),
        LineKind::Constraint => (PUBLISHED, 1, true),
    };
    // A white halo keeps the fitted curves readable over points and density cells.
    if matches!(
        l.kind,
        LineKind::Refit | LineKind::Published | LineKind::GroupCurve(_)
    ) {
        chart
            .draw_series(LineSeries::new(
                pts.iter().copied(),
                WHITE.stroke_width(width + 2),
            ))
            .map_err(err)?;
    }
    if dashed {
        chart
            .draw_series(DashedLineSeries::new(
                pts.iter().copied(),
                8,
                5,
                color.stroke_width(width),
            ))
            .map_err(err)?;
    } else {
        chart
            .draw_series(LineSeries::new(
                pts.iter().copied(),
                color.stroke_width(width),
            ))
            .map_err(err)?;
    }
    Ok(())
}

/// Grey of the emptiest (1 row) and the fullest density cell: light enough that coloured lines
/// and points read over every cell, dark enough that a lone row shows on white.
const DENSITY_LIGHT: f64 = 215.0;
const DENSITY_DARK: f64 = 40.0;

/// The grey of a density cell at position `t` ∈ [0, 1] of the log colour scale.
pub(super) fn density_grey(t: f64) -> RGBColor {
    let v = (DENSITY_LIGHT + (DENSITY_DARK - DENSITY_LIGHT) * t.clamp(0.0, 1.0)).round() as u8;
    RGBColor(v, v, v)
}

/// The colour of a density cell with `c` rows when the fullest has `max` (log scale).
pub(super) fn density_color(c: u32, max: u32) -> RGBColor {
    let t = if max > 1 {
        (c as f64).ln() / (max as f64).ln()
    } else {
        1.0
    };
    density_grey(t)
}

pub(super) fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    p: &Panel,
) -> Result<(), String> {
    let mut cb = ChartBuilder::on(area);
    cb.margin(8).x_label_area_size(42).y_label_area_size(62);
    if let Some(t) = &p.title {
        cb.caption(t, (FONT, 15));
    }
    let mut chart = cb
        .build_cartesian_2d(p.x.0..p.x.1, p.y.0..p.y.1)
        .map_err(err)?;
    let dx = ticks::decimals(p.x.0, p.x.1, ticks::LABELS);
    let dy = ticks::decimals(p.y.0, p.y.1, ticks::LABELS);
    let fx = move |v: &f64| ticks::label(*v, dx);
    let fy = move |v: &f64| ticks::label(*v, dy);
    chart
        .configure_mesh()
        .x_labels(ticks::LABELS)
        .y_labels(ticks::LABELS)
        .x_label_formatter(&fx)
        .y_label_formatter(&fy)
        .x_desc(p.x_desc.as_str())
        .y_desc(p.y_desc.as_str())
        .label_style((FONT, 13))
        .axis_desc_style((FONT, 14))
        .bold_line_style(BLACK.mix(0.10))
        .light_line_style(BLACK.mix(0.03))
        .draw()
        .map_err(err)?;
    if let Some(c) = &p.constraint {
        if c.region.len() >= 2 {
            chart
                .draw_series(std::iter::once(Polygon::new(
                    c.region
                        .iter()
                        .map(|r| (r.0, r.2))
                        .chain(c.region.iter().rev().map(|r| (r.0, r.1)))
                        .collect::<Vec<_>>(),
                    PUBLISHED.mix(0.10).filled(),
                )))
                .map_err(err)?;
            for edge in [
                c.region.iter().map(|r| (r.0, r.1)).collect::<Vec<_>>(),
                c.region.iter().map(|r| (r.0, r.2)).collect::<Vec<_>>(),
            ] {
                chart
                    .draw_series(DashedLineSeries::new(
                        edge,
                        6,
                        4,
                        PUBLISHED.mix(0.7).stroke_width(1),
                    ))
                    .map_err(err)?;
            }
        }
    }
    match &p.data {
        DataLayer::Points(pts) => {
            chart
                .draw_series(
                    pts.iter().map(|&(x, y, g)| {
                        Circle::new((x, y), 2, group_color(g).mix(0.75).filled())
                    }),
                )
                .map_err(err)?;
        }
        DataLayer::Density(d) => {
            draw_density(&mut chart, d)?;
        }
    }
    if p.band.len() >= 2 {
        chart
            .draw_series(std::iter::once(Polygon::new(
                p.band
                    .iter()
                    .map(|c| (c.0, c.2))
                    .chain(p.band.iter().rev().map(|c| (c.0, c.1)))
                    .collect::<Vec<_>>(),
                BAND.mix(0.30).filled(),
            )))
            .map_err(err)?;
        for edge in [
            p.band.iter().map(|c| (c.0, c.1)).collect::<Vec<_>>(),
            p.band.iter().map(|c| (c.0, c.2)).collect::<Vec<_>>(),
        ] {
            chart
                .draw_series(LineSeries::new(edge, BAND.mix(0.8).stroke_width(1)))
                .map_err(err)?;
        }
    }
    if let DataLayer::Density(d) = &p.data {
        for (g, m) in d.means.iter().enumerate() {
            draw_line(
                &mut chart,
                &Line {
                    pts: m.clone(),
                    kind: LineKind::GroupMean(g as u16),
                },
            )?;
            // Markers too: a group at one value of x (one subject's height) has one bin.
            let c = group_color(g as u16);
            chart
                .draw_series(m.iter().map(|&p| Circle::new(p, 3, c.filled())))
                .map_err(err)?;
        }
    }
    for l in &p.lines {
        draw_line(&mut chart, l)?;
    }
    if let Some((x, y)) = p.constraint.as_ref().and_then(|c| c.pivot) {
        // A diamond (not a circle: circles are data), white-rimmed.
        let shape = |r: i32| vec![(0, -r), (r, 0), (0, r), (-r, 0)];
        chart
            .draw_series(std::iter::once(
                EmptyElement::at((x, y))
                    + Polygon::new(shape(7), WHITE.filled())
                    + Polygon::new(shape(5), PUBLISHED.filled()),
            ))
            .map_err(err)?;
    }
    Ok(())
}

pub(super) fn draw_density<DB: DrawingBackend>(
    chart: &mut ChartContext<
        DB,
        Cartesian2d<plotters::coord::types::RangedCoordf64, plotters::coord::types::RangedCoordf64>,
    >,
    d: &Density,
) -> Result<(), String> {
    let wx = (d.x.1 - d.x.0) / d.nx as f64;
    let wy = (d.y.1 - d.y.0) / d.ny as f64;
    chart
        .draw_series((0..d.ny).flat_map(|cy| {
            (0..d.nx).filter_map(move |cx| {
                let c = d.counts[cy * d.nx + cx];
                (c > 0).then(|| {
                    let x0 = d.x.0 + cx as f64 * wx;
                    let y0 = d.y.0 + cy as f64 * wy;
                    Rectangle::new(
                        [(x0, y0), (x0 + wx, y0 + wy)],
                        density_color(c, d.max).filled(),
                    )
                })
            })
        }))
        .map_err(err)?;
    Ok(())
}

/// Splits `text` into lines of at most `width` px at font `size`.
pub(super) fn wrap(text: &str, size: f64, width: f64) -> Vec<String> {
    let mut out = Vec::new();
    let mut cur = String::new();
    for w in text.split_whitespace() {
        let cand = if cur.is_empty() {
            w.to_string()
        } else {
            format!("{cur} {w}")
        };
        if !cur.is_empty() && raster::text_box(&cand, size).0 > width {
            out.push(std::mem::replace(&mut cur, w.to_string()));
        } else {
            cur = cand;
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

pub(super) fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    s: &Spec,
) -> Result<(), String> {
    const FS: f64 = 12.0;
    const LH: i32 = 15;
    let (w, _) = area.dim_in_pixel();
    let text_w = w as f64 - 16.0;
    let style = (FONT, FS).into_font().color(&BLACK);
    let bold = (FONT, FS).into_font().style(FontStyle::Bold).color(&BLACK);
    let mut y = 8;
    let text = |t: &str, x: i32, y: i32, st: &TextStyle| -> Result<(), String> {
        area.draw(&Text::new(t.to_string(), (x, y), st.clone()))
            .map_err(err)
    };
    text("data drawn", 6, y, &bold)?;
    y += LH + 2;
    for l in &s.data_legend {
        for line in wrap(l, FS, text_w) {
            text(&line, 6, y, &style)?;
            y += LH;
        }
    }
    if let Some(max) = s.density_max {
        y += 4;
        let bar_w = (w as i32 - 24).max(40);
        for k in 0..bar_w {
            let t = k as f64 / (bar_w - 1) as f64;
            let c = density_grey(t);
            area.draw(&Rectangle::new([(8 + k, y), (9 + k, y + 12)], c.filled()))
                .map_err(err)?;
        }
        y += 14;
        // Ticks at 1 and powers of ten up to the maximum (position ln c / ln max).
        let mut marks = vec![1u32];
        let mut p = 10u32;
        while p < max && marks.len() < 7 {
            marks.push(p);
            p = p.saturating_mul(10);
        }
        for m in marks
            .iter()
            .copied()
            .chain(std::iter::once(max).filter(|&m| m > 1))
        {
            let t = if max > 1 {
                (m as f64).ln() / (max as f64).ln()
            } else {
                0.0
            };
            let x = 8 + (t * (bar_w - 1) as f64) as i32;
            let label = thousands(m as usize);
            let lw = raster::text_box(&label, 10.0).0 as i32;
            let last = m == max;
            // The maximum's label goes below the others when they would overlap.
            let ly = if last { y + 12 } else { y };
            let lx = (x - lw / 2).clamp(2, w as i32 - lw - 2);
            text(&label, lx, ly, &(FONT, 10).into_font().color(&BLACK))?;
        }
        y += 28;
    }
    if let Some((title, labels)) = &s.groups {
        y += 6;
        text(title, 6, y, &bold)?;
        y += LH + 2;
        for (g, l) in labels.iter().enumerate() {
            area.draw(&Rectangle::new(
                [(8, y + 2), (20, y + 12)],
                group_color(g as u16).filled(),
            ))
            .map_err(err)?;
            let mut l = l.clone();
            while raster::text_box(&l, FS).0 > text_w - 20.0 && l.chars().count() > 4 {
                l.pop();
                l.pop();
                l.push('…');
            }
            text(&l, 26, y, &style)?;
            y += LH;
        }
    }
    y += 6;
    text("lines", 6, y, &bold)?;
    y += LH + 2;
    let has_band = s.panels.iter().any(|p| !p.band.is_empty());
    let mut entries: Vec<(Option<LineKind>, String)> = s
        .lines_legend
        .iter()
        .map(|(k, t)| (Some(*k), t.clone()))
        .collect();
    if has_band {
        entries.insert(1, (None, "refit's 95 % confidence band".into()));
    }
    for (kind, t) in entries {
        let sw = |a: &DrawingArea<DB, Shift>| -> Result<(), String> {
            let mid = y + 7;
            match kind {
                None => a
                    .draw(&Rectangle::new(
                        [(8, y + 2), (26, y + 12)],
                        BAND.mix(0.35).filled(),
                    ))
                    .map_err(err),
                Some(LineKind::Constraint) => {
                    a.draw(&Rectangle::new(
                        [(8, y + 1), (26, y + 13)],
                        PUBLISHED.mix(0.10).filled(),
                    ))
                    .map_err(err)?;
                    let (cx, cy) = (17, y + 7);
                    a.draw(&Polygon::new(
                        vec![(cx, cy - 5), (cx + 5, cy), (cx, cy + 5), (cx - 5, cy)],
                        PUBLISHED.filled(),
                    ))
                    .map_err(err)
                }
                Some(k) => {
                    let (c, wdt) = match k {
                        LineKind::Refit => (BLACK, 2),
                        LineKind::Published => (PUBLISHED, 2),
                        LineKind::GroupCurve(g) | LineKind::GroupMean(g) => (group_color(g), 2),
                        LineKind::Reference | LineKind::Constraint => (RGBColor(90, 90, 90), 1),
                    };
                    a.draw(&PathElement::new(
                        vec![(8, mid), (26, mid)],
                        c.stroke_width(wdt),
                    ))
                    .map_err(err)
                }
            }
        };
        sw(area)?;
        for line in wrap(&t, FS, text_w - 26.0) {
            text(&line, 32, y, &style)?;
            y += LH;
        }
    }
    Ok(())
}

pub(super) fn draw_spec<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    s: &Spec,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(err)?;
    let body = root.titled(&s.title, (FONT, 19)).map_err(err)?;
    let (w, _) = body.dim_in_pixel();
    let (plots, legend) = body.split_horizontally(w.saturating_sub(LEGEND_W));
    for (area, p) in plots.split_evenly(s.grid).iter().zip(&s.panels) {
        draw_panel(area, p)?;
    }
    draw_legend(&legend, s)
}
