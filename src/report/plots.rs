//! Per-relation plots (plotters; SVG and PNG): the data with the refit curve, its 95 % band and
//! the published curve (in the style of the running paper's Figure 2), residuals against fitted
//! values, and a normal Q–Q plot of the residuals.
//!
//! PNG text needs a font: plotters is built without system fonts, so DejaVu Sans (bundled in
//! `assets/fonts/`, with its licence) is registered once through `register_font`.
use super::ReportError;
use crate::fit::pipeline::FitOutcome;
use crate::fit::stats::normal_quantile;
use crate::fsio::write_atomic_bytes;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::sync::Once;

static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

fn register_font() {
    REGISTER.call_once(|| {
        // The bundled font is valid; if registration failed PNGs would lack text, not fail.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

const W: u32 = 800;
const H: u32 = 560;

fn perr(path: &Path, e: impl std::fmt::Display) -> ReportError {
    ReportError::Plot {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

fn pad(lo: f64, hi: f64) -> (f64, f64) {
    let span = (hi - lo).abs().max(1e-9);
    (lo - 0.05 * span, hi + 0.05 * span)
}

/// Data, refit curve with 95 % band, published curve.
fn main_plot<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    o: &FitOutcome,
) -> Result<(), String> {
    let rel = o.refit.as_ref();
    let inputs = rel.inputs();
    let resp = rel.response();
    let n = o.prepared.obs.len().max(1) as f64;
    // Other inputs at their means (e.g. body height).
    let mut mean_x = [0.0; crate::relations::MAX_INPUTS];
    for obs in &o.prepared.obs {
        for (m, v) in mean_x.iter_mut().zip(obs.x) {
            *m += v / n;
        }
    }
    let (xlo, xhi) = o
        .prepared
        .obs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |a, b| {
            (a.0.min(b.x[0]), a.1.max(b.x[0]))
        });
    let (xlo, xhi) = pad(xlo, xhi);
    const K: usize = 200;
    // One curve per output (kb-mu's four μ-functions), else one at the other inputs' means.
    let n_out = rel.outputs();
    // (x, refit, band low, band high, published) per abscissa point.
    type Curve = Vec<(f64, f64, f64, f64, f64)>;
    let curves: Vec<Curve> = (0..n_out)
        .map(|out| {
            (0..=K)
                .map(|k| {
                    let x0 = xlo + (xhi - xlo) * k as f64 / K as f64;
                    let mut x = mean_x;
                    if n_out > 1 {
                        rel.select_output(&mut x, out);
                    }
                    x[0] = x0;
                    let (m, lo, hi) = o.band(&x);
                    (x0, m, lo, hi, o.published.predict(&x))
                })
                .collect()
        })
        .collect();
    let ys = o
        .prepared
        .obs
        .iter()
        .map(|o| o.y)
        .chain(curves.iter().flatten().flat_map(|c| [c.1, c.2, c.3, c.4]));
    let (ylo, yhi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |a, y| {
        (a.0.min(y), a.1.max(y))
    });
    let (ylo, yhi) = pad(ylo, yhi);
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let others: Vec<String> = inputs
        .iter()
        .enumerate()
        .skip(1)
        .map(|(j, v)| format!("{} = {:.3} {} (mean)", v.symbol, mean_x[j], v.unit))
        .collect();
    let caption = if n_out > 1 {
        format!(
            "{} — one curve per output ({})",
            rel.id(),
            (0..n_out)
                .map(|k| rel.output_name(k))
                .collect::<Vec<_>>()
                .join(", ")
        )
    } else if others.is_empty() {
        format!("{} — {}", rel.id(), rel.citation().equation)
    } else {
        format!("{} — curves at {}", rel.id(), others.join(", "))
    };
    let mut chart = ChartBuilder::on(root)
        .caption(caption, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(xlo..xhi, ylo..yhi)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(format!("{} ({})", inputs[0].symbol, inputs[0].unit))
        .y_desc(format!("{} ({})", resp.symbol, resp.unit))
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| e.to_string())?;
    let band_color = RGBColor(120, 160, 230).mix(0.35);
    chart
        .draw_series(curves.iter().map(|curve| {
            Polygon::new(
                curve
                    .iter()
                    .map(|c| (c.0, c.3))
                    .chain(curve.iter().rev().map(|c| (c.0, c.2)))
                    .collect::<Vec<_>>(),
                band_color.filled(),
            )
        }))
        .map_err(|e| e.to_string())?
        .label("refit 95 % band")
        .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 18, y + 5)], band_color.filled()));
    chart
        .draw_series(
            o.prepared
                .obs
                .iter()
                .map(|ob| Cross::new((ob.x[0], ob.y), 3, BLACK.mix(0.5).stroke_width(1))),
        )
        .map_err(|e| e.to_string())?
        .label(format!("data (n = {})", o.prepared.obs.len()))
        .legend(|(x, y)| Cross::new((x + 9, y), 4, BLACK));
    for curve in curves.iter().skip(1) {
        chart
            .draw_series(LineSeries::new(
                curve.iter().map(|c| (c.0, c.1)),
                BLUE.stroke_width(2),
            ))
            .map_err(|e| e.to_string())?;
        chart
            .draw_series(LineSeries::new(
                curve.iter().map(|c| (c.0, c.4)),
                RED.stroke_width(2),
            ))
            .map_err(|e| e.to_string())?;
    }
    let curve = &curves[0];
    chart
        .draw_series(LineSeries::new(
            curve.iter().map(|c| (c.0, c.1)),
            BLUE.stroke_width(2),
        ))
        .map_err(|e| e.to_string())?
        .label("refit")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], BLUE.stroke_width(2)));
    chart
        .draw_series(LineSeries::new(
            curve.iter().map(|c| (c.0, c.4)),
            RED.stroke_width(2),
        ))
        .map_err(|e| e.to_string())?
        .label("published")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], RED.stroke_width(2)));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 14))
        .position(SeriesLabelPosition::UpperLeft)
        .draw()
        .map_err(|e| e.to_string())?;
    Ok(())
}

fn scatter_plot<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    title: &str,
    xdesc: &str,
    ydesc: &str,
    pts: &[(f64, f64)],
    reference: Option<(f64, f64)>,
) -> Result<(), String> {
    let (xlo, xhi) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
        (a.0.min(p.0), a.1.max(p.0))
    });
    let (ylo, yhi) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, p| {
        (a.0.min(p.1), a.1.max(p.1))
    });
    let (xlo, xhi) = pad(xlo, xhi);
    let (ylo, yhi) = pad(ylo, yhi);
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 20))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(xlo..xhi, ylo..yhi)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(xdesc)
        .y_desc(ydesc)
        .label_style(("sans-serif", 14))
        .draw()
        .map_err(|e| e.to_string())?;
    if let Some((slope, icpt)) = reference {
        chart
            .draw_series(LineSeries::new(
                [(xlo, icpt + slope * xlo), (xhi, icpt + slope * xhi)],
                RED.stroke_width(1),
            ))
            .map_err(|e| e.to_string())?;
    }
    chart
        .draw_series(
            pts.iter()
                .map(|&(x, y)| Circle::new((x, y), 2, BLUE.mix(0.6).filled())),
        )
        .map_err(|e| e.to_string())?;
    Ok(())
}

/// Writes `<dir>/<id>.{svg,png}`, `<id>-residuals.{svg,png}` and `<id>-qq.{svg,png}`.
pub fn write_plots(dir: &Path, o: &FitOutcome) -> Result<Vec<PathBuf>, ReportError> {
    let id = o.record.relation.clone();
    if o.prepared.obs.is_empty() {
        return Ok(Vec::new());
    }
    let mut out = Vec::new();
    out.extend(write_pair(
        &dir.join(&id),
        |a| main_plot(a, o),
        |a| main_plot(a, o),
    )?);
    let resp = o.refit.response();
    let rf: Vec<(f64, f64)> = o
        .fitted
        .iter()
        .zip(&o.residuals)
        .map(|(f, r)| (*f, *r))
        .collect();
    let title = format!("{} — residuals vs fitted", id);
    let xd = format!("fitted {} ({})", resp.symbol, resp.unit);
    let yd = format!("residual ({})", resp.unit);
    out.extend(write_pair(
        &dir.join(format!("{id}-residuals")),
        |a| scatter_plot(a, &title, &xd, &yd, &rf, Some((0.0, 0.0))),
        |a| scatter_plot(a, &title, &xd, &yd, &rf, Some((0.0, 0.0))),
    )?);
    let mut r = o.residuals.clone();
    r.sort_by(f64::total_cmp);
    let n = r.len();
    let mean = r.iter().sum::<f64>() / n as f64;
    let sd = (r.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n.max(2) - 1) as f64).sqrt();
    let qq: Vec<(f64, f64)> = r
        .iter()
        .enumerate()
        .map(|(i, e)| (normal_quantile((i as f64 + 0.5) / n as f64), *e))
        .collect();
    let title = format!("{} — normal Q–Q plot of residuals", id);
    out.extend(write_pair(
        &dir.join(format!("{id}-qq")),
        |a| scatter_plot(a, &title, "normal quantile", &yd, &qq, Some((sd, mean))),
        |a| scatter_plot(a, &title, "normal quantile", &yd, &qq, Some((sd, mean))),
    )?);
    Ok(out)
}

/// Draws into `<stem>.svg` and `<stem>.png`, both written atomically (temporary file + rename);
/// two closures because the drawing code is generic over the backend.
fn write_pair<F, G>(stem: &Path, svg_draw: F, png_draw: G) -> Result<Vec<PathBuf>, ReportError>
where
    F: Fn(&DrawingArea<SVGBackend, Shift>) -> Result<(), String>,
    G: Fn(&DrawingArea<BitMapBackend, Shift>) -> Result<(), String>,
{
    register_font();
    let svg_path = stem.with_extension("svg");
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (W, H)).into_drawing_area();
        svg_draw(&root).map_err(|e| perr(&svg_path, e))?;
        root.present().map_err(|e| perr(&svg_path, e))?;
    }
    write_atomic_bytes(&svg_path, svg.as_bytes())?;
    let png_path = stem.with_extension("png");
    let dir = png_path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir).map_err(|e| perr(dir, e))?;
    let tmp = tempfile::Builder::new()
        .prefix(".gaitfit-tmp-")
        .suffix(".png")
        .tempfile_in(dir)
        .map_err(|e| perr(&png_path, e))?;
    {
        let root = BitMapBackend::new(tmp.path(), (W, H)).into_drawing_area();
        png_draw(&root).map_err(|e| perr(&png_path, e))?;
        root.present().map_err(|e| perr(&png_path, e))?;
    }
    tmp.persist(&png_path)
        .map_err(|e| perr(&png_path, e.error))?;
    Ok(vec![svg_path, png_path])
}
