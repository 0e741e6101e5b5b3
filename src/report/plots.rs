//! Per-relation plots (plotters; SVG and PNG of each), in the style of the running paper's
//! Figure 2:
//!
//! - `<id>`: the data with the refit curve, its 95 % band and the published curve; relations
//!   with further inputs (body height) or per-subject levels also get each colour group's refit
//!   at its own mean inputs and level (run-sl-v: one curve per subject at its height); a
//!   relation with several outputs (kb-mu's four μ) gets one labelled panel per output;
//! - `<id>-residuals`: residuals against fitted values;
//! - `<id>-residuals-inputs`: residuals against each input (one panel per input and output);
//! - `<id>-qq`: a normal Q–Q plot of the residuals.
//!
//! What of the data is drawn is decided in [`super::layers`]: up to
//! [`MAX_SCATTER_POINTS`] rows every row is a point,
//! coloured by subject (within data set) or by data set; above that the density of all rows is
//! drawn, with each colour group's binned mean over it, and the Q–Q plot draws exact order
//! statistics at fixed ranks ([`super::qq`]). Curves and bands are evaluated at
//! [`CURVE_POINTS`] abscissae, never at the rows. So the files' sizes and the time to draw them
//! do not grow with the rows; every figure's legend and its caption in `summary.md` say what
//! was drawn.
//!
//! PNG text is drawn by [`super::raster`] (plotters 0.3.7 misplaces ab_glyph glyphs); the SVG
//! backend lays text out with plotters' ab_glyph font, registered once from the bundled DejaVu
//! Sans (`assets/fonts/`, with its licence).
use super::layers::{
    Axis, DataLayer, Density, Extent, Frame, GroupBy, GroupInputs, Groups, Source,
    MAX_SCATTER_POINTS, MEAN_BINS, MIN_MEAN_BIN_ROWS, PALETTE,
};
use super::{qq, raster, ticks, Figure, ReportError};
use crate::fit::pipeline::FitOutcome;
use crate::fsio::write_atomic_bytes;
use crate::relations::{Inputs, Relation, MAX_INPUTS};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Once;

mod draw;
use draw::*;

static REGISTER: Once = Once::new();

fn register_font() {
    REGISTER.call_once(|| {
        // The bundled font is valid; if registration failed SVGs would lack text, not fail.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, raster::FONT_BYTES);
    });
}

/// Figure size, px.
pub const SIZE: (u32, u32) = (960, 600);
/// Width of the legend strip at the figure's right, px (room for a 30-character label).
const LEGEND_W: u32 = 240;
/// Abscissae at which every curve and band is evaluated (≈ 3 px apart on a full panel).
pub const CURVE_POINTS: usize = 240;
/// Density cells of a full-width panel (≈ 7 px square on the ~660 × 450 px plotting area);
/// panels of a grid get proportionally fewer, so a cell stays ~7 px.
const DENSITY_CELLS: (usize, usize) = (96, 64);

const FONT: &str = "sans-serif";
const PUBLISHED: RGBColor = RGBColor(200, 0, 0);
const BAND: RGBColor = RGBColor(90, 110, 150);

fn perr(path: &Path, e: impl std::fmt::Display) -> ReportError {
    ReportError::Plot {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

fn pad(lo: f64, hi: f64) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite()) {
        return (0.0, 1.0);
    }
    let span = (hi - lo).abs().max(1e-9 * lo.abs().max(1.0));
    (lo - 0.04 * span, hi + 0.04 * span)
}

fn group_color(g: u16) -> RGBColor {
    let (r, gg, b) = PALETTE[g as usize % PALETTE.len()];
    RGBColor(r, gg, b)
}

/// How a line is drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
enum LineKind {
    /// The refit for the average subject.
    Refit,
    /// The published relation.
    Published,
    /// A colour group's refit at its own inputs and level.
    GroupCurve(u16),
    /// A colour group's binned mean (over a density).
    GroupMean(u16),
    /// A reference line (residual 0, the normal line of a Q–Q plot).
    Reference,
    /// The paper's constraint where it gives ranges, not values (Ko–Badler's α): the region
    /// of admissible curves and the point they all pass through.
    Constraint,
}

/// What a paper that gives a range, not a value, for some coefficients says about the curve
/// (Ko–Badler appendix A: α₁ ∈ [0, 0.3], α₂…α₄ > 0, with μᵢ* at sl* given): every curve with
/// those coefficients anywhere in their ranges and the others at the paper's values.
#[derive(Debug, Clone, Default)]
struct Constraint {
    /// `(x, lo, hi)`: the admissible curves' extent at `x`, clipped to the panel.
    region: Vec<(f64, f64, f64)>,
    /// Where every admissible curve passes (μ* at sl*), if they share a point in the panel.
    pivot: Option<(f64, f64)>,
}

#[derive(Debug, Clone)]
struct Line {
    pts: Vec<(f64, f64)>,
    kind: LineKind,
}

#[derive(Debug, Clone)]
struct Panel {
    /// The rows drawn (`None`: the data layer is filled in directly, as the Q–Q plot's).
    source: Option<Source>,
    title: Option<String>,
    x_desc: String,
    y_desc: String,
    x: (f64, f64),
    y: (f64, f64),
    data: DataLayer,
    /// `(x, lo, hi)` of the refit's 95 % band.
    band: Vec<(f64, f64, f64)>,
    lines: Vec<Line>,
    /// The paper's constraint (drawn under the data), when it gives ranges, not values.
    constraint: Option<Constraint>,
}

/// A figure, fully reduced: drawing it costs the same whatever the number of rows.
#[derive(Debug, Clone)]
struct Spec {
    stem: String,
    title: String,
    panels: Vec<Panel>,
    grid: (usize, usize),
    /// Whether a density draws each colour group's binned mean.
    group_means: bool,
    /// Legend lines about the data layer (first line names what was drawn).
    data_legend: Vec<String>,
    groups: Option<(String, Vec<String>)>,
    /// The largest density count (a colour bar is drawn when some).
    density_max: Option<u32>,
    lines_legend: Vec<(LineKind, String)>,
    shows: String,
    drawn: String,
}

/// The curve-evaluation point for output `out` (0 when `None`) with input 0 at `x0` and other
/// inputs at `base`.
fn at(base: &[f64; MAX_INPUTS], out: Option<usize>, x0: f64) -> Inputs {
    let mut x = Inputs {
        values: *base,
        output: out.unwrap_or(0),
    };
    x.values[0] = x0;
    x
}

/// Whether the paper gives every coefficient of the published curve (no line otherwise: a
/// curve through made-up values would look like the paper's).
fn published_given(o: &FitOutcome) -> bool {
    let rel = o.published.relation();
    rel.card()
        .parameters
        .iter()
        .all(|s| s.cited && s.published.is_finite())
}

/// The coefficients the paper gives only a range for: `(index, lo, hi)` of every parameter it
/// does not cite a value for but bounds (Ko–Badler's α); empty when it cites every value, or
/// when some uncited coefficient has no range either (then the paper says nothing to draw).
fn ranged_only(o: &FitOutcome) -> Vec<(usize, f64, f64)> {
    let rel = o.published.relation();
    let mut out = Vec::new();
    for (i, s) in rel.card().parameters.iter().enumerate() {
        if s.cited && s.published.is_finite() {
            continue;
        }
        let (lo, hi) = rel.bounds(i);
        if !(lo.is_finite() || hi.is_finite()) || !s.published.is_finite() {
            return Vec::new();
        }
        out.push((i, lo, hi));
    }
    // 2^m corners per evaluation point.
    if out.len() > 8 {
        return Vec::new();
    }
    out
}

/// Stand-in for an infinite bound when the admissible curves are evaluated: its curves leave
/// any panel, and the region is clipped to the panel (the half-fan of α > 0).
const UNBOUNDED: f64 = 1e9;

/// The paper's constraint for output `out` over `[xlo, xhi]` (other inputs at `base`): at each
/// x the extent of the curves with the ranged coefficients at the corners of their ranges (exact
/// for coefficients that enter linearly, as α does), and the point all of them pass through.
/// Returns the region before clipping (`finite`: the corners of finite bounds only, for the
/// axis range; `all`: with infinite bounds at ±[`UNBOUNDED`]) and the pivot.
#[allow(clippy::type_complexity)]
fn constraint_family(
    o: &FitOutcome,
    ranged: &[(usize, f64, f64)],
    out: Option<usize>,
    base: &[f64; MAX_INPUTS],
    xlo: f64,
    xhi: f64,
) -> (
    Vec<(f64, f64, f64)>,
    Vec<(f64, f64, f64)>,
    Option<(f64, f64)>,
) {
    let rel = o.published.relation();
    let p0: Vec<f64> = rel.card().parameters.iter().map(|s| s.published).collect();
    let eval = |p: &[f64], x0: f64| rel.predict_with(p, 0.0, &at(base, out, x0));
    // The pivot: where the curve stops depending on each ranged coefficient that matters here
    // (a sign change of the unit-step difference between grid points, linear in between).
    let grid: Vec<f64> = xs(xlo, xhi).collect();
    let mut pivot_x: Option<f64> = None;
    let mut consistent = true;
    for &(i, _, _) in ranged {
        let mut p1 = p0.clone();
        p1[i] += 1.0;
        let d: Vec<f64> = grid.iter().map(|&x| eval(&p1, x) - eval(&p0, x)).collect();
        if d.iter().all(|v| v.abs() < 1e-12) {
            continue; // this coefficient does not act on this output
        }
        let root = (0..grid.len()).find_map(|k| {
            if d[k] == 0.0 {
                Some(grid[k])
            } else if k + 1 < grid.len() && d[k].signum() != d[k + 1].signum() && d[k + 1] != 0.0 {
                Some(grid[k] + (grid[k + 1] - grid[k]) * d[k] / (d[k] - d[k + 1]))
            } else {
                None
            }
        });
        match (root, pivot_x) {
            (None, _) => consistent = false,
            (Some(r), None) => pivot_x = Some(r),
            (Some(r), Some(q)) => {
                if (r - q).abs() > 1e-9 * (xhi - xlo) {
                    consistent = false;
                }
            }
        }
    }
    let pivot = pivot_x.filter(|_| consistent).map(|x| (x, eval(&p0, x)));
    let mut xs_all = grid;
    if let Some((x, _)) = pivot {
        let k = xs_all.partition_point(|&v| v < x);
        xs_all.insert(k, x);
    }
    let corners = |finite_only: bool| -> Vec<Vec<f64>> {
        let mut sets: Vec<Vec<f64>> = vec![p0.clone()];
        for &(i, lo, hi) in ranged {
            let mut vals = Vec::new();
            for b in [lo, hi] {
                if b.is_finite() {
                    vals.push(b);
                } else if !finite_only {
                    vals.push(b.signum() * UNBOUNDED);
                }
            }
            if vals.is_empty() {
                continue;
            }
            sets = sets
                .into_iter()
                .flat_map(|s| {
                    vals.iter().map(move |&v| {
                        let mut s = s.clone();
                        s[i] = v;
                        s
                    })
                })
                .collect();
        }
        sets
    };
    let extent = |sets: &[Vec<f64>]| -> Vec<(f64, f64, f64)> {
        xs_all
            .iter()
            .map(|&x| {
                let (lo, hi) = sets
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
                        let y = eval(p, x);
                        (a.0.min(y), a.1.max(y))
                    });
                (x, lo, hi)
            })
            .collect()
    };
    let finite = extent(&corners(true));
    let all = extent(&corners(false));
    (finite, all, pivot)
}

fn xs(lo: f64, hi: f64) -> impl Iterator<Item = f64> {
    (0..=CURVE_POINTS).map(move |k| lo + (hi - lo) * k as f64 / CURVE_POINTS as f64)
}

fn fmt_num(v: f64) -> String {
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        format!("{v:.3e}")
    } else {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

fn thousands(n: usize) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Cells of one panel of a `grid` figure.
fn cells(grid: (usize, usize)) -> (usize, usize) {
    (
        (DENSITY_CELLS.0 / grid.1).max(8),
        (DENSITY_CELLS.1 / grid.0).max(8),
    )
}

fn grid_for(n: usize) -> (usize, usize) {
    match n {
        0 | 1 => (1, 1),
        2 => (1, 2),
        3 | 4 => (2, 2),
        5 | 6 => (2, 3),
        _ => (n.div_ceil(3), 3),
    }
}

/// What a figure with this frame draws of its rows (legend lines and the caption's words).
fn data_words(
    frame: &Frame,
    what: &str,
    grid: (usize, usize),
    means: bool,
) -> (Vec<String>, String) {
    let n = thousands(frame.len());
    let groups = frame.groups;
    if frame.dense() {
        let (nx, ny) = cells(grid);
        let mut legend = vec![
            format!("density of all {n} {what}"),
            format!("({nx} × {ny} cells per panel;"),
            "colour: rows per cell, log scale)".to_string(),
        ];
        let mut caption = format!(
            "the density of all {n} {what} (2-D histogram, {nx} × {ny} cells per panel, rows per \
             cell on a log colour scale; more than {} rows, so no single points)",
            thousands(MAX_SCATTER_POINTS)
        );
        if means && groups.len() > 1 {
            legend.push(format!("lines: mean per x bin ({MEAN_BINS} bins,"));
            legend.push(format!("≥ {MIN_MEAN_BIN_ROWS} rows) of each group"));
            caption.push_str(&format!(
                ", with each colour group's mean per x bin ({MEAN_BINS} bins, bins of at least \
                 {MIN_MEAN_BIN_ROWS} rows), {}",
                groups.describe()
            ));
        }
        (legend, caption)
    } else {
        (
            vec![format!("all {n} {what} as points")],
            format!("all {n} {what} as points, {}", groups.describe()),
        )
    }
}

fn groups_legend(groups: &Groups) -> Option<(String, Vec<String>)> {
    (groups.len() > 1 || groups.by != GroupBy::Single).then(|| {
        let title = match groups.by {
            GroupBy::Subject => "colour: subject · data set",
            GroupBy::DataSet => "colour: data set",
            GroupBy::Single => "one colour",
        };
        let labels = groups
            .labels
            .iter()
            .zip(&groups.rows)
            .map(|(l, r)| format!("{l} ({})", thousands(*r)))
            .collect();
        (title.to_string(), labels)
    })
}

/// The legend's words for the paper's constraint, `None` when there is none to draw.
fn constraint_words(o: &FitOutcome, ranged: &[(usize, f64, f64)]) -> Option<String> {
    if ranged.is_empty() {
        return None;
    }
    let specs = o.published.card().parameters;
    let range = |lo: f64, hi: f64| match (lo.is_finite(), hi.is_finite()) {
        (true, true) => format!("∈ [{}, {}]", fmt_num(lo), fmt_num(hi)),
        (true, false) => format!("≥ {}", fmt_num(lo)),
        _ => format!("≤ {}", fmt_num(hi)),
    };
    let ranges: Vec<String> = ranged
        .iter()
        .map(|&(i, lo, hi)| format!("{} {}", specs[i].name, range(lo, hi)))
        .collect();
    let pivot = if o.record.relation == crate::relations::kb_mu::ID {
        "μ* at sl* (the prototype's angles at its step length) and "
    } else {
        "the point they share and "
    };
    Some(format!(
        "the paper's constraint: {pivot}the curves its ranges admit ({}); no values given",
        ranges.join(", ")
    ))
}

/// The data figure's sources: one panel per output.
fn main_sources(rel: &dyn Relation) -> Vec<Source> {
    let outs: Vec<Option<usize>> = if rel.card().outputs.len() > 1 {
        (0..rel.card().outputs.len()).map(Some).collect()
    } else {
        vec![None]
    };
    outs.into_iter()
        .map(|output| Source {
            x: Axis::Input(0),
            y: Axis::Response,
            output,
        })
        .collect()
}

/// Builds the data figure (one panel per output), its data layer still empty.
fn main_spec(frame: &Frame, sources: &[Source], ext: &[Extent], gin: &[GroupInputs]) -> Spec {
    let o = frame.o;
    let rel = o.refit.relation();
    let id = &o.record.relation;
    let n_out = rel.card().outputs.len();
    let inputs = rel.card().inputs;
    let resp = rel.card().response;
    let outs: Vec<Option<usize>> = sources.iter().map(|s| s.output).collect();
    let total: usize = gin.iter().map(|g| g.n).sum();
    let mut mean_x = [0.0; MAX_INPUTS];
    for g in gin {
        for (m, v) in mean_x.iter_mut().zip(g.mean) {
            *m += v * g.n as f64 / total.max(1) as f64;
        }
    }
    // Other continuous inputs (body height): curves are drawn at their mean, and per group.
    let others: Vec<usize> = (1..inputs.len()).collect();
    let levels = o.refit.subject_levels();
    let per_group =
        frame.groups.len() > 1 && (!others.is_empty() || rel.card().subject_effect.is_some());
    let published = published_given(o);
    let ranged = if published {
        Vec::new()
    } else {
        ranged_only(o)
    };
    let grid = grid_for(outs.len());
    let mut panels = Vec::new();
    for (src, e) in sources.iter().zip(ext) {
        let out = src.output;
        let (xlo, xhi) = pad(e.x.0, e.x.1);
        let mut band = Vec::with_capacity(CURVE_POINTS + 1);
        let mut refit = Vec::with_capacity(CURVE_POINTS + 1);
        let mut publ = Vec::new();
        for x0 in xs(xlo, xhi) {
            let x = at(&mean_x, out, x0);
            let (m, lo, hi) = o.band(&x);
            band.push((x0, lo, hi));
            refit.push((x0, m));
            if published {
                publ.push((x0, o.published.predict(&x)));
            }
        }
        let mut lines = Vec::new();
        if per_group {
            for (g, gi) in gin.iter().enumerate() {
                if gi.n == 0 || gi.x0.1 < gi.x0.0 {
                    continue;
                }
                let level = frame.groups.subject[g]
                    .and_then(|s| o.prepared.subjects.get(s))
                    .and_then(|name| levels.get(name))
                    .copied()
                    .unwrap_or(0.0);
                let pts = xs(gi.x0.0, gi.x0.1)
                    .map(|x0| {
                        let x = at(&gi.mean, out, x0);
                        (x0, rel.predict_with(&o.values, level, &x))
                    })
                    .collect();
                lines.push(Line {
                    pts,
                    kind: LineKind::GroupCurve(g as u16),
                });
            }
        }
        lines.push(Line {
            pts: publ,
            kind: LineKind::Published,
        });
        lines.push(Line {
            pts: refit,
            kind: LineKind::Refit,
        });
        let (mut ylo, mut yhi) = e.y;
        for &(_, lo, hi) in &band {
            ylo = ylo.min(lo);
            yhi = yhi.max(hi);
        }
        for l in &lines {
            for &(_, y) in &l.pts {
                if y.is_finite() {
                    ylo = ylo.min(y);
                    yhi = yhi.max(y);
                }
            }
        }
        let mut constraint = None;
        if !ranged.is_empty() {
            let (finite, all, pivot) = constraint_family(o, &ranged, out, &mean_x, xlo, xhi);
            for &(_, lo, hi) in &finite {
                if lo.is_finite() && hi.is_finite() {
                    ylo = ylo.min(lo);
                    yhi = yhi.max(hi);
                }
            }
            constraint = Some((all, pivot));
        }
        let y = pad(ylo, yhi);
        let constraint = constraint.map(|(all, pivot)| Constraint {
            region: all
                .into_iter()
                .map(|(x, lo, hi)| (x, lo.clamp(y.0, y.1), hi.clamp(y.0, y.1)))
                .collect(),
            pivot: pivot.filter(|p| p.1 >= y.0 && p.1 <= y.1),
        });
        let y_desc = match out {
            Some(k) => format!("{} ({})", rel.card().outputs[k].name, resp.unit),
            None => format!("{} ({})", resp.symbol, resp.unit),
        };
        panels.push(Panel {
            source: Some(*src),
            title: out.map(|k| output_title(rel, k)),
            x_desc: format!("{} ({})", inputs[0].symbol, inputs[0].unit),
            y_desc,
            x: (xlo, xhi),
            y,
            data: DataLayer::Points(Vec::new()),
            band,
            lines,
            constraint,
        });
    }
    let at_means = others
        .iter()
        .map(|&j| {
            format!(
                "{} = {} {}",
                inputs[j].symbol,
                fmt_num(mean_x[j]),
                inputs[j].unit
            )
        })
        .collect::<Vec<_>>()
        .join(", ");
    let mut lines_legend = vec![(
        LineKind::Refit,
        if at_means.is_empty() {
            "refit".to_string()
        } else {
            format!("refit, average subject at {at_means} (mean)")
        },
    )];
    let constraint_words = constraint_words(o, &ranged);
    if published {
        lines_legend.push((LineKind::Published, "published".into()));
    } else if let Some(w) = &constraint_words {
        lines_legend.push((LineKind::Constraint, w.clone()));
    } else {
        lines_legend.push((
            LineKind::Reference,
            "no published curve: the paper gives no value for some coefficients".into(),
        ));
    }
    if per_group {
        let who = match frame.groups.by {
            GroupBy::Subject => "each subject's",
            _ => "each data set's",
        };
        let mut what = format!("{who} refit");
        if !others.is_empty() {
            let syms: Vec<&str> = others.iter().map(|&j| inputs[j].symbol).collect();
            what.push_str(&format!(" at its mean {}", syms.join(", ")));
        }
        if rel.card().subject_effect.is_some() && frame.groups.by == GroupBy::Subject {
            what.push_str(if others.is_empty() {
                " with its level"
            } else {
                " and its level"
            });
        }
        what.push_str(", over its own range");
        lines_legend.push((LineKind::GroupCurve(0), what));
    }
    let (data_legend, drawn) = data_words(frame, "rows", grid, !per_group);
    let mut shows = format!(
        "{} against {} with the refit ({}) and its 95 % confidence band",
        resp.symbol,
        inputs[0].symbol,
        if at_means.is_empty() {
            "average subject".into()
        } else {
            format!("average subject at {at_means}")
        }
    );
    if published {
        shows.push_str(", and the published curve");
    } else if let Some(w) = &constraint_words {
        shows.push_str(&format!("; red: {w}, so no published curve"));
    } else {
        shows.push_str("; no published curve (the paper gives no value for some coefficients)");
    }
    if per_group {
        shows.push_str(&format!(
            "; thin coloured curves: {}",
            lines_legend.last().map_or("", |l| l.1.as_str())
        ));
    }
    if n_out > 1 {
        shows.push_str(&format!("; one panel per output ({n_out})"));
    }
    let mut title = format!("{id} — {}", rel.card().citation.equation);
    if n_out > 1 {
        title = format!("{id} — one panel per output");
    }
    Spec {
        stem: id.clone(),
        title,
        panels,
        grid,
        // Group curves already stand for the groups: no binned means over the density.
        group_means: !per_group,
        data_legend,
        groups: groups_legend(frame.groups),
        density_max: None,
        lines_legend,
        shows,
        drawn,
    }
}

/// The label of output `k`'s panel.
fn output_title(rel: &dyn Relation, k: usize) -> String {
    rel.card().outputs[k].label.to_string()
}

/// The sources of the residual figures: against fitted values, or against each input (one
/// panel per input and output).
fn residual_sources(rel: &dyn Relation, against_inputs: bool) -> Vec<Source> {
    let mut sources = Vec::new();
    if against_inputs {
        let outs: Vec<Option<usize>> = if rel.card().outputs.len() > 1 {
            (0..rel.card().outputs.len()).map(Some).collect()
        } else {
            vec![None]
        };
        for out in outs {
            for j in 0..rel.card().inputs.len() {
                sources.push(Source {
                    x: Axis::Input(j),
                    y: Axis::Residual,
                    output: out,
                });
            }
        }
    } else {
        sources.push(Source {
            x: Axis::Fitted,
            y: Axis::Residual,
            output: None,
        });
    }
    sources
}

/// A residual figure (see [`residual_sources`]), its data layer still empty.
fn residual_spec(frame: &Frame, sources: &[Source], ext: &[Extent], against_inputs: bool) -> Spec {
    let o = frame.o;
    let rel = o.refit.relation();
    let id = &o.record.relation;
    let resp = rel.card().response;
    let grid = grid_for(sources.len());
    let panels: Vec<Panel> = sources
        .iter()
        .zip(ext)
        .map(|(src, e)| {
            let x = pad(e.x.0, e.x.1);
            let y = pad(e.y.0.min(0.0), e.y.1.max(0.0));
            let x_desc = match src.x {
                Axis::Input(j) => {
                    let v = rel.card().inputs[j];
                    format!("{} ({})", v.symbol, v.unit)
                }
                _ => format!("fitted {} ({})", resp.symbol, resp.unit),
            };
            Panel {
                source: Some(*src),
                title: src.output.map(|k| output_title(rel, k)),
                x_desc,
                y_desc: format!("residual ({})", resp.unit),
                x,
                y,
                lines: vec![Line {
                    pts: vec![(x.0, 0.0), (x.1, 0.0)],
                    kind: LineKind::Reference,
                }],
                data: DataLayer::Points(Vec::new()),
                band: Vec::new(),
                constraint: None,
            }
        })
        .collect();
    let (data_legend, drawn) = data_words(frame, "residuals", grid, true);
    let (stem, title, shows) = if against_inputs {
        (
            format!("{id}-residuals-inputs"),
            format!("{id} — residuals against each input"),
            "residuals (measured − refit, each row with its subject's level) against each input"
                .to_string(),
        )
    } else {
        (
            format!("{id}-residuals"),
            format!("{id} — residuals against fitted values"),
            "residuals (measured − refit) against fitted values".to_string(),
        )
    };
    Spec {
        stem,
        title,
        panels,
        grid,
        group_means: true,
        data_legend,
        groups: groups_legend(frame.groups),
        density_max: None,
        lines_legend: {
            let mut l = vec![(LineKind::Reference, "residual 0".to_string())];
            if frame.dense() && frame.groups.len() > 1 {
                l.push((
                    LineKind::GroupMean(0),
                    "mean residual per x bin, one line per colour group".into(),
                ));
            }
            l
        },
        shows,
        drawn,
    }
}

/// The normal Q–Q plot of the residuals.
fn qq_spec(frame: &Frame) -> Spec {
    let o = frame.o;
    let id = &o.record.relation;
    let resp = o.refit.card().response;
    let q = qq::qq_points(&o.residuals, MAX_SCATTER_POINTS);
    let (pts, n, mean, sd) = (q.pts, q.n, q.mean, q.sd);
    let (xlo, xhi) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
        (a.0.min(p.0), a.1.max(p.0))
    });
    let (ylo, yhi) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
        (a.0.min(p.1), a.1.max(p.1))
    });
    let x = pad(xlo, xhi);
    let y = pad(ylo.min(mean + sd * xlo), yhi.max(mean + sd * xhi));
    let all = pts.len() == n;
    let nn = thousands(n);
    let (data_legend, drawn) = if all {
        (
            vec![format!("all {nn} residuals")],
            format!("all {nn} residuals as points"),
        )
    } else {
        (
            vec![
                format!("{} order statistics of", pts.len()),
                format!("all {nn} residuals (exact;"),
                "even in normal quantile,".into(),
                "min and max included)".into(),
            ],
            format!(
                "{} exact order statistics of all {nn} residuals, at ranks evenly spaced in \
                 normal quantile (smallest and largest included; more than {} residuals, so \
                 not every one)",
                pts.len(),
                thousands(MAX_SCATTER_POINTS)
            ),
        )
    };
    let panel = Panel {
        source: None,
        title: None,
        x_desc: "normal quantile".into(),
        y_desc: format!("residual ({})", resp.unit),
        x,
        y,
        data: DataLayer::Points(pts.into_iter().map(|(a, b)| (a, b, 0)).collect()),
        band: Vec::new(),
        lines: vec![Line {
            pts: vec![(x.0, mean + sd * x.0), (x.1, mean + sd * x.1)],
            kind: LineKind::Reference,
        }],
        constraint: None,
    };
    Spec {
        stem: format!("{id}-qq"),
        title: format!("{id} — normal Q–Q plot of residuals"),
        panels: vec![panel],
        grid: (1, 1),
        group_means: false,
        data_legend,
        groups: None,
        density_max: None,
        lines_legend: vec![(
            LineKind::Reference,
            format!("normal: mean {}, sd {}", fmt_num(mean), fmt_num(sd)),
        )],
        shows: "normal Q–Q plot of the residuals (all subjects pooled), with the normal line \
                of their mean and standard deviation"
            .into(),
        drawn,
    }
}

fn with_density_max(mut s: Spec) -> Spec {
    s.density_max = s
        .panels
        .iter()
        .filter_map(|p| match &p.data {
            DataLayer::Density(d) => Some(d.max),
            DataLayer::Points(_) => None,
        })
        .max();
    // One colour scale for all panels: each panel's cells are coloured by the figure's max.
    if let Some(m) = s.density_max {
        for p in &mut s.panels {
            if let DataLayer::Density(d) = &mut p.data {
                d.max = m;
            }
        }
    }
    s
}

/// The figures of one fit, reduced (no drawing yet): two passes over the rows for all figures
/// (extents; then points or density cells), plus the Q–Q plot's passes over the residuals.
fn specs(o: &FitOutcome) -> Vec<Spec> {
    let rel = o.refit.relation();
    let groups = Groups::new(&o.prepared);
    let frame = Frame::new(o, &groups);
    let src = [
        main_sources(rel),
        residual_sources(rel, false),
        residual_sources(rel, true),
    ];
    let all: Vec<Source> = src.iter().flatten().copied().collect();
    let (ext, gin) = frame.extents(&all);
    let (e0, rest) = ext.split_at(src[0].len());
    let (e1, e2) = rest.split_at(src[1].len());
    let mut specs = vec![
        main_spec(&frame, &src[0], e0, &gin),
        residual_spec(&frame, &src[1], e1, false),
        residual_spec(&frame, &src[2], e2, true),
    ];
    let mut sources = Vec::new();
    let mut ranges = Vec::new();
    let mut cells_of = Vec::new();
    for s in &specs {
        for p in &s.panels {
            if let Some(src) = p.source {
                sources.push(src);
                ranges.push((p.x, p.y));
                cells_of.push(cells(s.grid));
            }
        }
    }
    let mut layers = frame.layers(&sources, &ranges, &cells_of).into_iter();
    for s in &mut specs {
        let means = s.group_means;
        for p in s.panels.iter_mut().filter(|p| p.source.is_some()) {
            if let Some(mut d) = layers.next() {
                if let (DataLayer::Density(den), false) = (&mut d, means) {
                    den.means.iter_mut().for_each(Vec::clear);
                }
                p.data = d;
            }
        }
    }
    specs.push(qq_spec(&frame));
    specs.into_iter().map(with_density_max).collect()
}

/// Draws `s` into `<dir>/<stem>.svg` and `.png`, each written atomically.
fn write_spec(dir: &Path, s: &Spec) -> Result<Vec<PathBuf>, ReportError> {
    register_font();
    let svg_path = dir.join(format!("{}.svg", s.stem));
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        draw_spec(&root, s).map_err(|e| perr(&svg_path, e))?;
        root.present().map_err(|e| perr(&svg_path, e))?;
    }
    write_atomic_bytes(&svg_path, svg.as_bytes())?;
    let png_path = dir.join(format!("{}.png", s.stem));
    let png =
        raster::render_png(SIZE, |root| draw_spec(root, s)).map_err(|e| perr(&png_path, e))?;
    write_atomic_bytes(&png_path, &png)?;
    Ok(vec![svg_path, png_path])
}

/// Writes the figures of `o` (see the module docs) into `dir`; returns the files written and a
/// caption per figure. Nothing is written for a fit without rows.
pub fn write_plots(dir: &Path, o: &FitOutcome) -> Result<(Vec<PathBuf>, Vec<Figure>), ReportError> {
    use rayon::prelude::*;
    if o.prepared.obs.is_empty() {
        return Ok((Vec::new(), Vec::new()));
    }
    let specs = specs(o);
    let files = specs
        .par_iter()
        .map(|s| write_spec(dir, s))
        .collect::<Result<Vec<_>, _>>()?;
    let figures = specs
        .iter()
        .map(|s| Figure {
            stem: s.stem.clone(),
            shows: s.shows.clone(),
            drawn: s.drawn.clone(),
        })
        .collect();
    Ok((files.into_iter().flatten().collect(), figures))
}
