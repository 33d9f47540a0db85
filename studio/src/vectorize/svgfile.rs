//! An SVG file read with `usvg` (paths, basic shapes, `use`, transforms,
//! groups, CSS, `viewBox` and physical units all resolved by it) into
//! layers of outlines in millimetres: the page's lower left corner at the
//! origin, y up (the G-code's frame).
//!
//! Layers are the top-level Inkscape layers (`<g inkscape:groupmode=
//! "layer">`, named by their `inkscape:label`; a sublayer belongs to its
//! layer; a layer whose name starts with `%` is not drawn, as the AxiDraw
//! extension does), in document order. A file without layers is split by
//! colour (a shape's stroke colour, or its fill's when it has no stroke),
//! in the order the colours first appear. Hidden elements are dropped by
//! usvg. A shape with a stroke is drawn along its outline; a filled shape
//! is outlined and hatched inside (by its fill rule). Text elements and
//! pictures are not drawn and counted, so the maker can be told.

use super::fill::Rule;
use super::trace::Polyline;
use usvg::tiny_skia_path::{PathSegment, Transform};

/// A piece of outline in mm: a start and the segments after it.
#[derive(Clone, Debug, PartialEq)]
pub struct Outline {
    pub start: [f64; 2],
    pub segments: Vec<Segment>,
    pub closed: bool,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Segment {
    Line([f64; 2]),
    Quad([f64; 2], [f64; 2]),
    Cubic([f64; 2], [f64; 2], [f64; 2]),
}

/// One SVG shape: its outlines, whether they are stroked, and the fill
/// rule when filled.
#[derive(Clone, Debug, PartialEq)]
pub struct Shape {
    pub outlines: Vec<Outline>,
    pub stroked: bool,
    pub fill: Option<Rule>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Layer {
    pub name: String,
    pub shapes: Vec<Shape>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Document {
    /// The page, mm.
    pub size: [f64; 2],
    pub layers: Vec<Layer>,
    /// Elements not drawn: text not converted to paths, pictures.
    pub texts: usize,
    pub images: usize,
}

const INKSCAPE: &str = "http://www.inkscape.org/namespaces/inkscape";

/// Millimetres a CSS pixel (the SVG user unit at 96 dpi).
pub const MM_PER_PX: f64 = 25.4 / 96.0;

/// Reads SVG bytes.
pub fn read(bytes: &[u8]) -> Result<Document, String> {
    let text = std::str::from_utf8(bytes).map_err(|e| format!("SVG: not UTF-8 ({e})"))?;
    let xml = usvg::roxmltree::Document::parse_with_options(
        text,
        usvg::roxmltree::ParsingOptions {
            allow_dtd: true,
            ..Default::default()
        },
    )
    .map_err(|e| format!("SVG: {e}"))?;
    // Top-level layers: id → label.
    let mut layers: Vec<(String, String)> = Vec::new();
    let (mut texts, mut images) = (0, 0);
    for node in xml.descendants().filter(|n| n.is_element()) {
        match node.tag_name().name() {
            "text" => texts += 1,
            "image" => images += 1,
            "g" if node.attribute((INKSCAPE, "groupmode")) == Some("layer") => {
                let nested = node.ancestors().skip(1).any(|a| {
                    a.is_element() && a.attribute((INKSCAPE, "groupmode")) == Some("layer")
                });
                if !nested {
                    let id = node.attribute("id").unwrap_or("").to_string();
                    let label = node
                        .attribute((INKSCAPE, "label"))
                        .unwrap_or(&id)
                        .to_string();
                    layers.push((id, label));
                }
            }
            _ => {}
        }
    }
    let tree =
        usvg::Tree::from_str(text, &usvg::Options::default()).map_err(|e| format!("SVG: {e}"))?;
    let size = [
        f64::from(tree.size().width()) * MM_PER_PX,
        f64::from(tree.size().height()) * MM_PER_PX,
    ];
    let mut found: Vec<(Option<String>, String, Shape)> = Vec::new();
    collect(tree.root(), None, &layers, size[1], &mut found);
    let named = layers.iter().any(|(id, _)| !id.is_empty());
    let mut out: Vec<Layer> = Vec::new();
    if named {
        // In document order of the layers; shapes outside any layer form
        // one more, first.
        for (layer, _, shape) in found {
            let name = layer.unwrap_or_else(|| "(no layer)".into());
            match out.iter_mut().find(|l| l.name == name) {
                Some(l) => l.shapes.push(shape),
                None => out.push(Layer {
                    name,
                    shapes: vec![shape],
                }),
            }
        }
        out.retain(|l| !l.name.starts_with('%'));
    } else {
        for (_, colour, shape) in found {
            match out.iter_mut().find(|l| l.name == colour) {
                Some(l) => l.shapes.push(shape),
                None => out.push(Layer {
                    name: colour,
                    shapes: vec![shape],
                }),
            }
        }
    }
    Ok(Document {
        size,
        layers: out,
        texts,
        images,
    })
}

/// The shapes under `group`, each with its layer and colour.
fn collect(
    group: &usvg::Group,
    layer: Option<&str>,
    layers: &[(String, String)],
    page_height: f64,
    out: &mut Vec<(Option<String>, String, Shape)>,
) {
    for node in group.children() {
        match node {
            usvg::Node::Group(g) => {
                let here = match layer {
                    Some(l) => Some(l),
                    None => layers
                        .iter()
                        .find(|(id, _)| !id.is_empty() && id == g.id())
                        .map(|(_, label)| label.as_str()),
                };
                collect(g, here, layers, page_height, out);
            }
            usvg::Node::Path(p) if p.is_visible() => {
                let colour = p
                    .stroke()
                    .map(|s| s.paint())
                    .or(p.fill().map(|f| f.paint()))
                    .map(paint_name)
                    .unwrap_or_default();
                let shape = Shape {
                    outlines: outlines(p.data(), p.abs_transform(), page_height),
                    stroked: p.stroke().is_some(),
                    fill: p.fill().map(|f| match f.rule() {
                        usvg::FillRule::EvenOdd => Rule::EvenOdd,
                        usvg::FillRule::NonZero => Rule::NonZero,
                    }),
                };
                out.push((layer.map(String::from), colour, shape));
            }
            _ => {}
        }
    }
}

/// `#rrggbb`, or what kind of paint it is.
fn paint_name(p: &usvg::Paint) -> String {
    match p {
        usvg::Paint::Color(c) => format!("#{:02x}{:02x}{:02x}", c.red, c.green, c.blue),
        usvg::Paint::LinearGradient(_) => "linear gradient".into(),
        usvg::Paint::RadialGradient(_) => "radial gradient".into(),
        usvg::Paint::Pattern(_) => "pattern".into(),
    }
}

/// The path's pieces through `t`, in mm, y up from the page's bottom.
fn outlines(path: &usvg::tiny_skia_path::Path, t: Transform, page_height: f64) -> Vec<Outline> {
    let map = |p: usvg::tiny_skia_path::Point| {
        let (x, y) = (f64::from(p.x), f64::from(p.y));
        let (sx, kx, ky, sy) = (
            f64::from(t.sx),
            f64::from(t.kx),
            f64::from(t.ky),
            f64::from(t.sy),
        );
        let (px, py) = (
            sx * x + kx * y + f64::from(t.tx),
            ky * x + sy * y + f64::from(t.ty),
        );
        [px * MM_PER_PX, page_height - py * MM_PER_PX]
    };
    let mut out: Vec<Outline> = Vec::new();
    for seg in path.segments() {
        match seg {
            PathSegment::MoveTo(p) => out.push(Outline {
                start: map(p),
                segments: Vec::new(),
                closed: false,
            }),
            PathSegment::Close => {
                if let Some(o) = out.last_mut() {
                    o.closed = true;
                }
            }
            other => {
                let s = match other {
                    PathSegment::LineTo(p) => Segment::Line(map(p)),
                    PathSegment::QuadTo(a, p) => Segment::Quad(map(a), map(p)),
                    PathSegment::CubicTo(a, b, p) => Segment::Cubic(map(a), map(b), map(p)),
                    _ => unreachable!(),
                };
                if let Some(o) = out.last_mut() {
                    o.segments.push(s);
                }
            }
        }
    }
    out.retain(|o| !o.segments.is_empty());
    out
}

impl Outline {
    /// The outline as a polyline whose chords stay within `tolerance` of
    /// the curves (Wang's bound on a Bézier's distance from its chords:
    /// n pieces for a second difference M, a degree d curve: n² ≥
    /// d(d−1)·M / (8·tolerance)). A closed outline ends where it began.
    pub fn flatten(&self, tolerance: f64) -> Polyline {
        let mut pts = vec![self.start];
        let mut at = self.start;
        let d2 = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
            (a[0] - 2.0 * b[0] + c[0]).hypot(a[1] - 2.0 * b[1] + c[1])
        };
        let pieces =
            |m: f64, k: f64| ((k * m / (8.0 * tolerance)).sqrt().ceil() as usize).clamp(1, 10_000);
        for s in &self.segments {
            match *s {
                Segment::Line(p) => {
                    pts.push(p);
                    at = p;
                }
                Segment::Quad(a, p) => {
                    let n = pieces(d2(at, a, p), 2.0);
                    for i in 1..=n {
                        let t = i as f64 / n as f64;
                        let m = 1.0 - t;
                        pts.push([
                            m * m * at[0] + 2.0 * m * t * a[0] + t * t * p[0],
                            m * m * at[1] + 2.0 * m * t * a[1] + t * t * p[1],
                        ]);
                    }
                    at = p;
                }
                Segment::Cubic(a, b, p) => {
                    let n = pieces(d2(at, a, b).max(d2(a, b, p)), 6.0);
                    for i in 1..=n {
                        let t = i as f64 / n as f64;
                        let m = 1.0 - t;
                        let (k0, k1, k2, k3) =
                            (m * m * m, 3.0 * m * m * t, 3.0 * m * t * t, t * t * t);
                        pts.push([
                            k0 * at[0] + k1 * a[0] + k2 * b[0] + k3 * p[0],
                            k0 * at[1] + k1 * a[1] + k2 * b[1] + k3 * p[1],
                        ]);
                    }
                    at = p;
                }
            }
        }
        if self.closed && pts.last() != Some(&self.start) {
            pts.push(self.start);
        }
        pts
    }

    /// The outline moved by `f` (an affine map: Béziers map through their
    /// control points).
    pub fn map(&self, f: impl Fn([f64; 2]) -> [f64; 2]) -> Outline {
        Outline {
            start: f(self.start),
            segments: self
                .segments
                .iter()
                .map(|s| match *s {
                    Segment::Line(p) => Segment::Line(f(p)),
                    Segment::Quad(a, p) => Segment::Quad(f(a), f(p)),
                    Segment::Cubic(a, b, p) => Segment::Cubic(f(a), f(b), f(p)),
                })
                .collect(),
            closed: self.closed,
        }
    }

    /// Every point that bounds the outline (ends and control points).
    pub fn hull(&self) -> impl Iterator<Item = [f64; 2]> + '_ {
        std::iter::once(self.start).chain(self.segments.iter().flat_map(|s| match *s {
            Segment::Line(p) => vec![p],
            Segment::Quad(a, p) => vec![a, p],
            Segment::Cubic(a, b, p) => vec![a, b, p],
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn doc(body: &str) -> Document {
        let svg = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:inkscape=\"{INKSCAPE}\" \
             width=\"100mm\" height=\"50mm\" viewBox=\"0 0 200 100\">{body}</svg>"
        );
        read(svg.as_bytes()).unwrap()
    }

    #[test]
    fn units_view_box_and_transforms_give_millimetres_y_up() {
        // viewBox 200 × 100 on 100 × 50 mm: a user unit is 0.5 mm.
        let d = doc("<g transform=\"translate(10 20)\"><rect x=\"10\" y=\"10\" width=\"40\" height=\"20\" stroke=\"black\" fill=\"none\"/></g>");
        assert!(
            (d.size[0] - 100.0).abs() < 1e-4 && (d.size[1] - 50.0).abs() < 1e-4,
            "{:?}",
            d.size
        );
        assert_eq!(d.layers.len(), 1);
        assert_eq!(d.layers[0].name, "#000000");
        let s = &d.layers[0].shapes[0];
        assert!(s.stroked && s.fill.is_none());
        let p = s.outlines[0].flatten(0.01);
        // Corner (20, 30) user units: x 10 mm, y 50 − 15 = 35 mm.
        let near =
            |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs() < 1e-3 && (a[1] - b[1]).abs() < 1e-3;
        assert!(near(p[0], [10.0, 35.0]), "{p:?}");
        assert!(p.iter().any(|q| near(*q, [30.0, 25.0])), "{p:?}");
        assert_eq!(p.first(), p.last());
    }

    #[test]
    fn curves_flatten_within_the_tolerance() {
        let d = doc("<circle cx=\"100\" cy=\"50\" r=\"40\" fill=\"none\" stroke=\"red\"/>");
        let o = &d.layers[0].shapes[0].outlines[0];
        for tol in [0.1, 0.0125] {
            let p = o.flatten(tol);
            // Chord midpoints from the centre (50, 25) mm, radius 20 mm.
            for w in p.windows(2) {
                let m = [(w[0][0] + w[1][0]) / 2.0, (w[0][1] + w[1][1]) / 2.0];
                let r = (m[0] - 50.0).hypot(m[1] - 25.0);
                assert!(20.0 - r <= tol + 1e-3, "{tol}: {r}");
            }
        }
    }

    #[test]
    fn layers_colours_fills_and_what_is_not_drawn() {
        let d = doc(
            "<g inkscape:groupmode=\"layer\" id=\"l1\" inkscape:label=\"Outline\">\
               <path d=\"M0 0 L10 10\" stroke=\"blue\"/>\
               <g inkscape:groupmode=\"layer\" id=\"l1a\" inkscape:label=\"Sub\"><path d=\"M0 5 L10 5\" stroke=\"red\"/></g>\
             </g>\
             <g inkscape:groupmode=\"layer\" id=\"l2\" inkscape:label=\"Fill\">\
               <rect width=\"10\" height=\"10\" fill=\"#123456\" fill-rule=\"evenodd\"/>\
               <text x=\"1\" y=\"1\">hi</text>\
             </g>\
             <g inkscape:groupmode=\"layer\" id=\"l3\" inkscape:label=\"%notes\"><path d=\"M0 0 L1 1\" stroke=\"black\"/></g>\
             <g inkscape:groupmode=\"layer\" id=\"l4\" style=\"display:none\"><path d=\"M0 0 L1 1\" stroke=\"black\"/></g>",
        );
        let names: Vec<&str> = d.layers.iter().map(|l| l.name.as_str()).collect();
        assert_eq!(names, ["Outline", "Fill"]);
        assert_eq!(d.layers[0].shapes.len(), 2);
        assert_eq!(d.layers[1].shapes[0].fill, Some(Rule::EvenOdd));
        assert!(!d.layers[1].shapes[0].stroked);
        assert_eq!((d.texts, d.images), (1, 0));
        // Without layers: by colour, in order of appearance.
        let d = doc("<path d=\"M0 0 L1 1\" stroke=\"red\"/><path d=\"M0 0 L2 1\" stroke=\"#00f\"/><path d=\"M0 0 L3 1\" stroke=\"red\"/>");
        let names: Vec<&str> = d.layers.iter().map(|l| l.name.as_str()).collect();
        assert_eq!(names, ["#ff0000", "#0000ff"]);
        assert_eq!(d.layers[0].shapes.len(), 2);
        assert!(read(b"<svg").unwrap_err().starts_with("SVG: "));
    }
}
