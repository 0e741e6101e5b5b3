//! PNG output: plotters' bitmap backend with text drawn by this module, then encoded with `png`.
//!
//! **Why text is drawn here.** plotters 0.3.7 draws ab_glyph text by placing each glyph's
//! bitmap at the pen position and dropping the glyph's left side bearing (`px_bounds().min.x`
//! of the outline, `style/font/ab_glyph.rs`). Glyphs with a wide bearing then sit too far left:
//! DejaVu Sans's `l` (bearing 0.09 em) touches the `c` before it, and "t_cycle" read "t_cyde"
//! in the PNGs. The SVGs were right (viewers set their text). [`GlyphBackend`] wraps the bitmap
//! backend and draws text itself: every glyph is positioned at pen x + kerning by ab_glyph, with
//! its own bearing and sub-pixel offset, from the same bundled font. Layout widths are those
//! plotters computes (advances + kerning), so anchors and label areas agree with the SVG.
//!
//! The text test in this module compares a rendered label with glyph positions taken from
//! fontTools (`tools/fonts/glyph_metrics.py`), not from this code.
use plotters::prelude::*;
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingErrorKind,
};
use std::sync::OnceLock;

use ab_glyph::{Font, FontRef, PxScale, ScaleFont};

/// The bundled font (DejaVu Sans, licence in `assets/fonts/`), used for every PNG label.
pub(crate) static FONT_BYTES: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// The parsed bundled font (`None` only if the bundled file were corrupt: text is then
/// skipped, the plot still drawn).
pub(crate) fn font() -> Option<&'static FontRef<'static>> {
    static F: OnceLock<Option<FontRef<'static>>> = OnceLock::new();
    F.get_or_init(|| FontRef::try_from_slice(FONT_BYTES).ok())
        .as_ref()
}

/// plotters' text box height per pixel of font size (its `ab_glyph` layout: size / 1.24); kept
/// so label areas and anchors match the SVG's.
const BOX_HEIGHT_PER_SIZE: f64 = 1.0 / 1.24;

/// Width (advances plus kerning, as plotters lays text out) and box height of `text`, px.
pub(crate) fn text_box(text: &str, size: f64) -> (f64, f64) {
    let Some(f) = font() else {
        return (0.0, size * BOX_HEIGHT_PER_SIZE);
    };
    let sf = f.as_scaled(PxScale::from(size as f32));
    let mut w = 0f32;
    let mut prev = None;
    for c in text.chars() {
        let id = sf.glyph_id(c);
        if let Some(p) = prev {
            w += sf.kern(p, id);
        }
        w += sf.h_advance(id);
        prev = Some(id);
    }
    (w as f64, size * BOX_HEIGHT_PER_SIZE)
}

/// Calls `put(x, y, coverage)` for every inked pixel of `text` laid out from the top-left of its
/// box (unrotated), baseline where capitals and digits are centred in the box.
pub(crate) fn rasterize_text(text: &str, size: f64, mut put: impl FnMut(i32, i32, f32)) {
    let Some(f) = font() else {
        return;
    };
    let scale = PxScale::from(size as f32);
    let sf = f.as_scaled(scale);
    // Cap height from the font's own `H`, so digits and capitals sit in the middle of the box
    // (y tick labels are anchored at their box's centre).
    let cap = f
        .outline(f.glyph_id('H'))
        // ab_glyph's unscaled outline box keeps font units, y up, with `min.y` = yMax.
        .map_or(0.0, |o| {
            o.bounds.min.y.max(o.bounds.max.y) * sf.scale_factor().vertical
        });
    let baseline = 0.5 * (size * BOX_HEIGHT_PER_SIZE) as f32 + 0.5 * cap;
    let mut pen = 0f32;
    let mut prev = None;
    for c in text.chars() {
        let id = sf.glyph_id(c);
        if let Some(p) = prev {
            pen += sf.kern(p, id);
        }
        let glyph = id.with_scale_and_position(scale, ab_glyph::point(pen, baseline));
        if let Some(og) = f.outline_glyph(glyph) {
            let b = og.px_bounds();
            og.draw(|x, y, cov| put(b.min.x as i32 + x as i32, b.min.y as i32 + y as i32, cov));
        }
        pen += sf.h_advance(id);
        prev = Some(id);
    }
}

/// plotters' bitmap backend with text drawn by this module (see the module docs).
pub struct GlyphBackend<'a> {
    inner: BitMapBackend<'a>,
}

impl<'a> GlyphBackend<'a> {
    /// Draws into `buf` (RGB, `size.0 × size.1 × 3` bytes).
    pub fn new(buf: &'a mut [u8], size: (u32, u32)) -> GlyphBackend<'a> {
        GlyphBackend {
            inner: BitMapBackend::with_buffer(buf, size),
        }
    }
}

type DErr = DrawingErrorKind<<BitMapBackend<'static> as DrawingBackend>::ErrorType>;

impl DrawingBackend for GlyphBackend<'_> {
    type ErrorType = <BitMapBackend<'static> as DrawingBackend>::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }
    fn ensure_prepared(&mut self) -> Result<(), DErr> {
        self.inner.ensure_prepared()
    }
    fn present(&mut self) -> Result<(), DErr> {
        self.inner.present()
    }
    fn draw_pixel(&mut self, point: BackendCoord, color: BackendColor) -> Result<(), DErr> {
        self.inner.draw_pixel(point, color)
    }
    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DErr> {
        self.inner.draw_line(from, to, style)
    }
    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DErr> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }
    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DErr> {
        self.inner.draw_path(path, style)
    }
    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DErr> {
        self.inner.draw_circle(center, radius, style, fill)
    }
    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DErr> {
        self.inner.fill_polygon(vert, style)
    }
    fn blit_bitmap(&mut self, pos: BackendCoord, size: (u32, u32), src: &[u8]) -> Result<(), DErr> {
        self.inner.blit_bitmap(pos, size, src)
    }
    fn estimate_text_size<TStyle: BackendTextStyle>(
        &self,
        text: &str,
        style: &TStyle,
    ) -> Result<(u32, u32), DErr> {
        let (w, h) = text_box(text, style.size());
        Ok((w as u32, h as u32))
    }
    fn draw_text<TStyle: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &TStyle,
        pos: BackendCoord,
    ) -> Result<(), DErr> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        // Anchoring and rotation as plotters' default `draw_text`.
        let (w, h) = text_box(text, style.size());
        let (w, h) = (w as i32, h as i32);
        let dx = match style.anchor().h_pos {
            HPos::Left => 0,
            HPos::Right => -w,
            HPos::Center => -w / 2,
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0,
            VPos::Center => -h / 2,
            VPos::Bottom => -h,
        };
        let trans = style.transform();
        let mut result = Ok(());
        rasterize_text(text, style.size(), |x, y, cov| {
            if result.is_err() || cov <= 0.0 {
                return;
            }
            let (x, y) = trans.transform(x + dx, y + dy);
            let c = BackendColor {
                alpha: color.alpha * f64::from(cov.min(1.0)),
                rgb: color.rgb,
            };
            result = self.inner.draw_pixel((pos.0 + x, pos.1 + y), c);
        });
        result
    }
}

/// Encodes an RGB buffer as PNG: 8-bit RGB, zlib level 1 (png's stream writer with
/// `Compression::Fast`), adaptive row filters. Level 1 writes these flat-colour plots at ~2× the
/// size of level 6 in a third of the time, far under the 300 kB bound; png's one-shot writer
/// would use fdeflate (Huffman and runs only), which left the text-heavy panels near 400 kB.
pub(crate) fn encode_png(buf: &[u8], (w, h): (u32, u32)) -> Result<Vec<u8>, String> {
    use std::io::Write;
    let mut out = Vec::with_capacity(buf.len() / 8);
    {
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Fast);
        enc.set_adaptive_filter(png::AdaptiveFilterType::Adaptive);
        let mut wr = enc.write_header().map_err(|e| e.to_string())?;
        {
            let mut sw = wr.stream_writer().map_err(|e| e.to_string())?;
            sw.write_all(buf).map_err(|e| e.to_string())?;
            sw.finish().map_err(|e| e.to_string())?;
        }
        wr.finish().map_err(|e| e.to_string())?;
    }
    Ok(out)
}

/// Draws a figure with `draw` into a `size` PNG, returned as bytes.
pub(crate) fn render_png(
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<GlyphBackend<'_>, plotters::coord::Shift>) -> Result<(), String>,
) -> Result<Vec<u8>, String> {
    let mut buf = vec![255u8; size.0 as usize * size.1 as usize * 3];
    {
        let root = GlyphBackend::new(&mut buf, size).into_drawing_area();
        draw(&root)?;
        root.present().map_err(|e| e.to_string())?;
    }
    encode_png(&buf, size)
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::style::FontTransform;

    // From `python tools/fonts/glyph_metrics.py "t_cycle"` (fontTools 4.68 on the bundled font).
    // assets/fonts/DejaVuSans.ttf: unitsPerEm 2048, ascent 1901, descent -483
    const HEIGHT_UNITS: f64 = 2384.0;
    const CAP_HEIGHT_UNITS: f64 = 1493.0;
    const LABEL: &str = "t_cycle";
    /// Per glyph: (pen x before it incl. kerning, xMin, xMax, yMin, yMax), font units.
    const GLYPHS: &[(f64, f64, f64, f64, f64)] = &[
        (0.0, 55.0, 754.0, 0.0, 1438.0),        // 't' t
        (803.0, -20.0, 1044.0, -483.0, -340.0), // '_' underscore
        (1827.0, 113.0, 999.0, -29.0, 1147.0),  // 'c' c
        (2953.0, 61.0, 1151.0, -426.0, 1120.0), // 'y' y
        (4165.0, 113.0, 999.0, -29.0, 1147.0),  // 'c' c
        (5291.0, 193.0, 377.0, 0.0, 1556.0),    // 'l' l
        (5860.0, 113.0, 1151.0, -29.0, 1147.0), // 'e' e
    ];
    const SIZE: f64 = 72.0;
    const W: u32 = 360;
    const H: u32 = 320;

    /// Renders `LABEL` through the PNG path (backend, encoder) and decodes the file: ink
    /// coverage per pixel (0 white … 1 black).
    fn rendered(pos: (i32, i32), transform: FontTransform) -> Vec<f64> {
        let png = render_png((W, H), |root| {
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            let style = ("sans-serif", SIZE)
                .into_font()
                .transform(transform)
                .color(&BLACK);
            root.draw(&Text::new(LABEL, pos, style))
                .map_err(|e| e.to_string())
        })
        .unwrap();
        let dec = png::Decoder::new(std::io::Cursor::new(png));
        let mut r = dec.read_info().unwrap();
        let mut buf = vec![0; r.output_buffer_size()];
        let info = r.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (W, H));
        buf.chunks(3).map(|p| 1.0 - p[0] as f64 / 255.0).collect()
    }

    /// The label as the font's metrics place it: each glyph's outline rasterised alone at its
    /// fontTools pen position, composited; in box coordinates (unrotated, origin top left).
    fn expected_box() -> Vec<((i32, i32), f64)> {
        let f = font().unwrap();
        let s = SIZE / HEIGHT_UNITS;
        let baseline = 0.5 * SIZE * BOX_HEIGHT_PER_SIZE + 0.5 * CAP_HEIGHT_UNITS * s;
        let mut cov = std::collections::BTreeMap::<(i32, i32), f64>::new();
        for (c, g) in LABEL.chars().zip(GLYPHS) {
            let glyph = f.glyph_id(c).with_scale_and_position(
                PxScale::from(SIZE as f32),
                ab_glyph::point((g.0 * s) as f32, baseline as f32),
            );
            let og = f.outline_glyph(glyph).unwrap();
            let b = og.px_bounds();
            og.draw(|x, y, v| {
                let e = cov
                    .entry((b.min.x as i32 + x as i32, b.min.y as i32 + y as i32))
                    .or_insert(0.0);
                *e = 1.0 - (1.0 - *e) * (1.0 - v.min(1.0) as f64);
            });
        }
        cov.into_iter().collect()
    }

    #[test]
    fn png_label_glyphs_sit_where_the_font_puts_them() {
        let pos = (20, 30);
        let img = rendered(pos, FontTransform::None);
        let mut want = vec![0.0; (W * H) as usize];
        for ((x, y), v) in expected_box() {
            want[((pos.1 + y) as u32 * W + (pos.0 + x) as u32) as usize] = v;
        }
        let worst = img
            .iter()
            .zip(&want)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < 0.02,
            "rendered label differs from the font's layout by {worst}"
        );

        // Independent of any rasteriser: the rows above `t`'s top (1438 units) and below `l`'s
        // (1556) hold only `l`'s stem, whose ink spans xMin..xMax = 193..377 units from its pen
        // (5291). plotters' own text drawing put this stem 5.8 px further left ("t_cyde").
        let s = SIZE / HEIGHT_UNITS;
        let baseline = 0.5 * SIZE * BOX_HEIGHT_PER_SIZE + 0.5 * CAP_HEIGHT_UNITS * s;
        let l = GLYPHS[5];
        let (lo, hi) = (
            pos.0 as f64 + (l.0 + l.1) * s,
            pos.0 as f64 + (l.0 + l.2) * s,
        );
        let y_top = pos.1 as f64 + baseline - l.4 * s;
        let y_t = pos.1 as f64 + baseline - GLYPHS[0].4 * s;
        let rows = (y_top.ceil() as u32)..(y_t.floor() as u32);
        assert!(rows.len() >= 2, "{rows:?}");
        for y in rows {
            let ink: Vec<u32> = (0..W)
                .filter(|&x| img[(y * W + x) as usize] > 0.5)
                .collect();
            let (a, b) = (*ink.first().unwrap(), *ink.last().unwrap());
            assert!(
                (a as f64 - lo).abs() <= 1.0 && (b as f64 + 1.0 - hi).abs() <= 1.0,
                "row {y}: stem ink at {a}..={b} px, font says {lo:.1}..{hi:.1}"
            );
        }
    }

    #[test]
    fn rotated_png_label_is_the_same_label_turned() {
        // Axis descriptions on y are drawn turned by 270°: box (x, y) lands at (y, −x).
        let pos = (40, 300);
        let img = rendered(pos, FontTransform::Rotate270);
        let mut want = vec![0.0; (W * H) as usize];
        for ((x, y), v) in expected_box() {
            let (px, py) = (pos.0 + y, pos.1 - x);
            want[(py as u32 * W + px as u32) as usize] = v;
        }
        let worst = img
            .iter()
            .zip(&want)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 0.02, "rotated label differs by {worst}");
    }

    #[test]
    fn png_is_small_and_decodes_to_what_was_drawn() {
        let png = render_png((300, 200), |root| {
            root.fill(&WHITE).map_err(|e| e.to_string())?;
            root.draw(&Rectangle::new([(10, 10), (50, 40)], RED.filled()))
                .map_err(|e| e.to_string())
        })
        .unwrap();
        let mut r = png::Decoder::new(std::io::Cursor::new(&png))
            .read_info()
            .unwrap();
        let mut buf = vec![0; r.output_buffer_size()];
        r.next_frame(&mut buf).unwrap();
        let px = |x: usize, y: usize| &buf[(y * 300 + x) * 3..(y * 300 + x) * 3 + 3];
        assert_eq!(px(20, 20), &[255, 0, 0]);
        assert_eq!(px(100, 100), &[255, 255, 255]);
        assert!(png.len() < 2_000, "{}", png.len());
    }
}
