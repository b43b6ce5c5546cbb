"""A 1:1 print template tiled onto paper pages: each page is an SVG of the
paper's size (A4 or Letter, millimetres, one user unit = 1 mm) showing one window of the
template at 1:1, with

- a 100 mm scale bar (ticks every 10 mm) to check the print: measure it, it must be 100 mm;
- overlap marks: neighbouring windows share `overlap_mm` of the drawing; the shared band is
  marked by dashed lines and the page names its neighbours, so the pages are trimmed or laid
  over each other along those lines and taped;
- a caption: the template's name, the page's row letter and column number, "print at 100 %".

One file per page (browsers and printers take one page per SVG file); the pages of a template
are named STEM-A1.svg, STEM-A2.svg, ... (row letter, column number). bpy-free; pure Python.
"""
import math
import os
import xml.etree.ElementTree as ET

SVG_NS = "http://www.w3.org/2000/svg"
ET.register_namespace("", SVG_NS)

PAPERS = {"A4": (210.0, 297.0), "LETTER": (215.9, 279.4)}  # width, height (mm), portrait
MARGIN_MM = 10.0  # blank paper edge: what most printers cannot print on
FOOTER_MM = 18.0  # below the window: the scale bar and the caption
OVERLAP_MM = 10.0  # drawing shared by neighbouring pages
SCALE_BAR_MM = 100.0
SCALE_BAR_COLOUR = "#008000"  # the scale bar alone has this colour (the tests find it by it)


def _mm(value):
    """A length attribute in mm ("210mm", "210") as a number; ValueError for other units."""
    value = value.strip()
    if value.endswith("mm"):
        return float(value[:-2])
    return float(value)  # a plain number: user units, 1 mm each in our templates


def layout(width_mm, height_mm, paper="A4", overlap_mm=OVERLAP_MM):
    """The tiles of a template of width_mm x height_mm: {"paper": (w, h), "window": (x, y, w, h)
    where a page shows the drawing, "tiles": [{"row", "col", "name", "x", "y"}]} with (x, y) the
    template coordinates (mm) at the window's top-left corner. Neighbouring windows overlap by
    overlap_mm; the tiles cover the template."""
    key = paper.upper()
    if key not in PAPERS:
        raise ValueError(f"paper must be one of {', '.join(sorted(PAPERS))}, got {paper!r}")
    pw, ph = PAPERS[key]
    ww, wh = pw - 2 * MARGIN_MM, ph - 2 * MARGIN_MM - FOOTER_MM
    if not (0 <= overlap_mm < min(ww, wh) / 2):
        raise ValueError(f"overlap_mm must be between 0 and {min(ww, wh) / 2:g} mm, got {overlap_mm}")
    if not (width_mm > 0 and height_mm > 0):
        raise ValueError("a template to tile needs a positive width and height")

    def count(extent, window):
        return max(1, math.ceil((extent - overlap_mm) / (window - overlap_mm) - 1e-9))

    cols, rows = count(width_mm, ww), count(height_mm, wh)
    tiles = [{"row": r, "col": c, "name": f"{_row_name(r)}{c + 1}",
              "x": c * (ww - overlap_mm), "y": r * (wh - overlap_mm)}
             for r in range(rows) for c in range(cols)]
    return {"paper": (pw, ph), "window": (MARGIN_MM, MARGIN_MM, ww, wh), "rows": rows, "cols": cols,
            "tiles": tiles, "overlap": overlap_mm}


def _row_name(r):
    name = ""
    r += 1
    while r:
        r, k = divmod(r - 1, 26)
        name = chr(ord("A") + k) + name
    return name


def _el(parent, tag, **attrs):
    return ET.SubElement(parent, f"{{{SVG_NS}}}{tag}", {k.rstrip("_").replace("_", "-"): str(v)
                                                       for k, v in attrs.items()})


def _f(v):
    return f"{v:.3f}"


def page(template_svg, tiles, tile, title):
    """The SVG text of one page: `tile` of layout `tiles` of the template (its SVG text)."""
    root = ET.fromstring(template_svg)
    pw, ph = tiles["paper"]
    wx, wy, ww, wh = tiles["window"]
    overlap = tiles["overlap"]
    out = ET.Element(f"{{{SVG_NS}}}svg", {"version": "1.1", "width": f"{_f(pw)}mm", "height": f"{_f(ph)}mm",
                                          "viewBox": f"0 0 {_f(pw)} {_f(ph)}"})
    _el(out, "rect", x="0", y="0", width=_f(pw), height=_f(ph), fill="#ffffff", class_="paper")
    # the template itself as a nested <svg>: its viewBox is this tile's window of the drawing and its
    # viewport the page's window, both ww x wh mm: 1:1, and clipped to the window
    window = ET.SubElement(out, root.tag, dict(root.attrib))
    window.set("x", _f(wx))
    window.set("y", _f(wy))
    window.set("width", _f(ww))
    window.set("height", _f(wh))
    window.set("viewBox", f"{_f(tile['x'])} {_f(tile['y'])} {_f(ww)} {_f(wh)}")
    window.set("overflow", "hidden")
    window.set("class", "window")
    window.extend(list(root))
    # the window's frame, and dashed lines where the neighbours' windows begin
    _el(out, "rect", x=_f(wx), y=_f(wy), width=_f(ww), height=_f(wh), fill="none", stroke="#808080",
        stroke_width="0.2", class_="frame")
    r, c = tile["row"], tile["col"]
    marks = []
    if c + 1 < tiles["cols"]:
        marks.append((wx + ww - overlap, wy, wx + ww - overlap, wy + wh, f"{_row_name(r)}{c + 2} →"))
    if c > 0:
        marks.append((wx + overlap, wy, wx + overlap, wy + wh, f"← {_row_name(r)}{c}"))
    if r + 1 < tiles["rows"]:
        marks.append((wx, wy + wh - overlap, wx + ww, wy + wh - overlap, f"{_row_name(r + 1)}{c + 1} ↓"))
    if r > 0:
        marks.append((wx, wy + overlap, wx + ww, wy + overlap, f"↑ {_row_name(r - 1)}{c + 1}"))
    for x1, y1, x2, y2, label in marks:
        _el(out, "line", x1=_f(x1), y1=_f(y1), x2=_f(x2), y2=_f(y2), stroke="#808080", stroke_width="0.2",
            stroke_dasharray="2 2", class_="overlap")
        vertical = x1 == x2
        tx, ty = (x1 + (-2 if "←" not in label else 2), wy - 2) if vertical else (wx + 2, y1 - 1)
        text = _el(out, "text", x=_f(tx), y=_f(ty), font_family="sans-serif", font_size="3", fill="#808080",
                   class_="overlap-label")
        if vertical and "←" not in label:
            text.set("text-anchor", "end")
        text.text = label
    # the scale bar: a 100 mm line with ticks every 10 mm, in the footer
    bx, by = wx, wy + wh + 7.0
    bar = _el(out, "g", class_="scale-bar", stroke=SCALE_BAR_COLOUR, fill="none")
    _el(bar, "line", x1=_f(bx), y1=_f(by), x2=_f(bx + SCALE_BAR_MM), y2=_f(by), stroke_width="0.6",
        stroke_linecap="butt")
    for k in range(11):
        tick = 3.0 if k % 5 == 0 else 1.5
        _el(bar, "line", x1=_f(bx + 10 * k), y1=_f(by - tick), x2=_f(bx + 10 * k), y2=_f(by), stroke_width="0.3",
            stroke_linecap="butt")
    label = _el(out, "text", x=_f(bx + SCALE_BAR_MM + 3), y=_f(by + 1.2), font_family="sans-serif", font_size="3.5",
                fill="#000000", class_="scale-label")
    label.text = "100 mm"
    caption = _el(out, "text", x=_f(bx), y=_f(by + 7.5), font_family="sans-serif", font_size="3.5", fill="#000000",
                  class_="caption")
    caption.text = (f"{title}: page {tile['name']} ({tiles['rows']} x {tiles['cols']} pages, "
                    f"{_f(overlap).rstrip('0').rstrip('.')} mm overlap): print at 100 %, the bar must measure 100 mm")
    return '<?xml version="1.0" encoding="UTF-8" standalone="no"?>\n' + ET.tostring(out, encoding="unicode") + "\n"


def write_pages(template_svg, folder, stem, title, paper="A4", overlap_mm=OVERLAP_MM):
    """Writes the pages of one template into `folder` as STEM-A1.svg, ... (atomically, each);
    returns their paths in reading order (rows top to bottom, columns left to right)."""
    root = ET.fromstring(template_svg)
    tiles = layout(_mm(root.get("width")), _mm(root.get("height")), paper, overlap_mm)
    os.makedirs(folder, exist_ok=True)
    paths = []
    for tile in tiles["tiles"]:
        path = os.path.join(folder, f"{stem}-{tile['name']}.svg")
        tmp = path + ".tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(page(template_svg, tiles, tile, title))
        os.replace(tmp, path)
        paths.append(path)
    return paths
