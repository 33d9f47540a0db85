"""An SVG file read by svgelements, not by usvg (what taut uses): every
visible shape's outline sampled densely, in mm, y up from the page's lower
left corner, with its top-level Inkscape layer, colour and fill rule.

usage: sample_svg.py FILE.svg STEP_MM   (JSON on stdout)
"""
import json
import math
import sys

from svgelements import SVG, Group, Move, Close, Path, Shape

INKSCAPE = "{http://www.inkscape.org/namespaces/inkscape}"
MM_PER_PX = 25.4 / 96.0


def main():
    path, step = sys.argv[1], float(sys.argv[2])
    svg = SVG.parse(path, ppi=96)
    height = svg.height * MM_PER_PX
    out = {"size_mm": [svg.width * MM_PER_PX, height], "shapes": []}

    def mm(p):
        return [p.x * MM_PER_PX, height - p.y * MM_PER_PX]

    def walk(group, layer):
        for child in group:
            if isinstance(child, Group):
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
                for sub in Path(child).as_subpaths():
                    pts = []
                    for seg in sub:
                        if isinstance(seg, Move):
                            pts.append(mm(seg.end))
                            continue
                        length = seg.length() * MM_PER_PX
                        n = max(1, math.ceil(length / step))
                        for k in range(1, n + 1):
                            pts.append(mm(seg.point(k / n)))
                    if len(pts) >= 2:
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
