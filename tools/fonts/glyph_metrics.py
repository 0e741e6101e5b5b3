"""Glyph metrics of the bundled font (DejaVu Sans) read with fontTools, for the PNG text test.

The test (`src/report/raster.rs`, `tests::png_label_glyphs_sit_where_the_font_puts_them`)
renders a label through the PNG path and compares it with each glyph placed at the pen position
these numbers give: advance widths (hmtx) plus the legacy `kern` table pairs (what ab_glyph
applies; GPOS pairs are listed for information), and the glyph's outline box (glyf). The pixel
scale of a PxScale is size / (ascent - descent), ascent/descent as ab_glyph reads them (hhea,
or OS/2 typo metrics when USE_TYPO_METRICS is set).

Run from the repository root:  python tools/fonts/glyph_metrics.py "t_cycle"
"""
import sys

from fontTools.ttLib import TTFont

FONT = "assets/fonts/DejaVuSans.ttf"


def main(text: str) -> None:
    f = TTFont(FONT)
    os2 = f["OS/2"]
    if os2.fsSelection & (1 << 7):
        asc, desc = os2.sTypoAscender, os2.sTypoDescender
    else:
        asc, desc = f["hhea"].ascent, f["hhea"].descent
    cmap = f.getBestCmap()
    kern = {}
    if "kern" in f:
        for t in f["kern"].kernTables:
            kern.update(t.kernTable)
    names = [cmap[ord(c)] for c in text]
    print(f"// {FONT}: unitsPerEm {f['head'].unitsPerEm}, ascent {asc}, descent {desc}")
    print(f"const HEIGHT_UNITS: f64 = {asc - desc}.0;")
    cap = f["glyf"]["H"].yMax
    print(f"const CAP_HEIGHT_UNITS: f64 = {cap}.0;")
    print(f"const LABEL: &str = {text!r};".replace("'", '"'))
    print("/// Per glyph: (pen x before it incl. kerning, xMin, xMax, yMin, yMax), font units.")
    print("const GLYPHS: &[(f64, f64, f64, f64, f64)] = &[")
    pen = 0
    prev = None
    for c, g in zip(text, names):
        if prev is not None:
            pen += kern.get((prev, g), 0)
        gl = f["glyf"][g]
        box = (gl.xMin, gl.xMax, gl.yMin, gl.yMax) if hasattr(gl, "xMin") else (0, 0, 0, 0)
        print(f"    ({pen}.0, {box[0]}.0, {box[1]}.0, {box[2]}.0, {box[3]}.0), // {c!r} {g}")
        pen += f["hmtx"][g][0]
        prev = g
    print("];")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "t_cycle")
