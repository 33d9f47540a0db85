"""An SVG file read by svgelements, not by usvg (what taut uses): every
visible shape's outline sampled densely, in mm, y up from the page's lower
left corner, with its top-level Inkscape layer, colour and fill rule.

usage: sample_svg.py FILE.svg STEP_MM   (JSON on stdout)
"""
import json
import math
import sys

from svgelements import SVG, Arc, Group, Move, Path, Shape, Use

INKSCAPE = "{http://www.inkscape.org/namespaces/inkscape}"
MM_PER_PX = 25.4 / 96.0


def bound(seg):
    """A cheap bound on a segment's length (its control polygon, an arc's
    radius times its sweep): enough samples without integrating."""
    if isinstance(seg, Arc):
        return max(abs(seg.rx), abs(seg.ry)) * abs(seg.sweep) * 1.01 + 1e-9
    pts = [p for p in (getattr(seg, a, None) for a in ("start", "control1", "control2", "control", "end")) if p is not None]
    return sum(abs(b - a) for a, b in zip(pts, pts[1:])) + 1e-9


def main():
    path, step = sys.argv[1], float(sys.argv[2])
    # Transforms are applied after arcs become cubics: svgelements'
    # transformed elliptical arcs stray (0.2 mm on transforms.svg's skewed
    # circle) where cubics map exactly.
    svg = SVG.parse(path, ppi=96, reify=False)
    height = svg.height * MM_PER_PX
    out = {"size_mm": [svg.width * MM_PER_PX, height], "shapes": []}

    def mm(p):
        return [p.x * MM_PER_PX, height - p.y * MM_PER_PX]

    def walk(group, layer):
        for child in group:
            if isinstance(child, (Group, Use)):
                here = layer
                if layer is None and child.values.get(INKSCAPE + "groupmode") == "layer":
                    here = child.values.get(INKSCAPE + "label", child.id)
                walk(child, here)
            elif isinstance(child, Shape):
                if child.values.get("visibility") in ("hidden", "collapse"):
                    continue
                stroked = child.stroke is not None and child.stroke.value is not None
                filled = child.fill is not None and child.fill.value is not None
                if not (stroked or filled):
                    continue
                subpaths = []
                whole = Path(child)
                whole.approximate_arcs_with_cubics()
                whole.reify()
                for sub in whole.as_subpaths():
                    pts = []
                    for seg in sub:
                        if isinstance(seg, Move):
                            pts.append(mm(seg.end))
                            continue
                        length = bound(seg) * MM_PER_PX
                        n = max(1, math.ceil(length / step))
                        for k in range(1, n + 1):
                            pts.append(mm(seg.point(k / n)))
                    # A subpath of no length ("M x y Z") draws nothing.
                    if any(q != pts[0] for q in pts):
                        subpaths.append(pts)
                paint = child.stroke if stroked else child.fill
                out["shapes"].append({
                    "layer": layer,
                    "colour": paint.hex[:7] if paint is not None else None,
                    "stroked": stroked,
                    "fill_rule": child.values.get("fill-rule", "nonzero") if filled else None,
                    "subpaths": subpaths,
                })

    walk(svg, None)
    json.dump(out, sys.stdout)


main()
