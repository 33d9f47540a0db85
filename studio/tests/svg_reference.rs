//! SVG in, checked against another reader: each drawing of
//! `examples/svg/` is vectorised for the flatbed at its own size, its
//! G-code read back through the firmware's interpreter, and the toolpath
//! compared with the same file read by Python's svgelements (not usvg,
//! which `taut` uses), sampled every 0.05 mm:
//!
//! - every point the pen draws lies within 0.1 mm of an outline of the
//!   reference, or inside one of its filled shapes (hatching);
//! - every point of the reference's outlines is drawn, within 0.1 mm;
//! - the passes are the reference's Inkscape layers (or colours), in its
//!   order, with a pen change (`M0`) between each two.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use taut_logic::machine::Machine;
use taut_studio::toolpath::Toolpath;
use taut_studio::vectorize::{self, Options, Source};

const WITHIN_MM: f64 = 0.1;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// A filled shape's rings, and whether its rule is even-odd.
type Fill = (bool, Vec<Vec<[f64; 2]>>);

#[derive(Debug)]
struct Reference {
    /// (layer or colour, outline points, fill)
    shapes: Vec<(String, Vec<[f64; 2]>, Option<Fill>)>,
}

/// The drawing as svgelements reads it.
fn reference(svg: &Path) -> Reference {
    let status = Command::new("sh")
        .arg(root().join("studio/tests/reference/install.sh"))
        .status()
        .expect("sh");
    assert!(status.success(), "installing svgelements failed");
    let out = Command::new(root().join("target/clients/svg-venv/bin/python"))
        .arg(root().join("studio/tests/reference/sample_svg.py"))
        .arg(svg)
        .arg("0.05")
        .output()
        .expect("python");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let pt = |p: &serde_json::Value| [p[0].as_f64().unwrap(), p[1].as_f64().unwrap()];
    let shapes = v["shapes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            let name = match s["layer"].as_str() {
                Some(l) => l.to_string(),
                None => s["colour"].as_str().unwrap_or("").to_string(),
            };
            let rings: Vec<Vec<[f64; 2]>> = s["subpaths"]
                .as_array()
                .unwrap()
                .iter()
                .map(|r| r.as_array().unwrap().iter().map(pt).collect())
                .collect();
            let outline = rings.iter().flatten().copied().collect();
            let fill = s["fill_rule"]
                .as_str()
                .map(|rule| (rule == "evenodd", rings.clone()));
            (name, outline, fill)
        })
        .collect();
    Reference { shapes }
}

/// Points in cells of `WITHIN_MM`, for nearest-point questions.
struct Grid(HashMap<(i64, i64), Vec<[f64; 2]>>);

impl Grid {
    fn new(points: impl IntoIterator<Item = [f64; 2]>) -> Grid {
        let mut g: HashMap<(i64, i64), Vec<[f64; 2]>> = HashMap::new();
        for p in points {
            g.entry(Grid::cell(p)).or_default().push(p);
        }
        Grid(g)
    }
    fn cell(p: [f64; 2]) -> (i64, i64) {
        (
            (p[0] / WITHIN_MM).floor() as i64,
            (p[1] / WITHIN_MM).floor() as i64,
        )
    }
    fn near(&self, p: [f64; 2]) -> bool {
        let (x, y) = Grid::cell(p);
        (-1..=1).any(|dx| {
            (-1..=1).any(|dy| {
                self.0.get(&(x + dx, y + dy)).is_some_and(|v| {
                    v.iter()
                        .any(|q| (q[0] - p[0]).hypot(q[1] - p[1]) <= WITHIN_MM)
                })
            })
        })
    }
}

/// Inside the rings by the rule (winding numbers).
fn inside(p: [f64; 2], evenodd: bool, rings: &[Vec<[f64; 2]>]) -> bool {
    let mut winding = 0i32;
    for r in rings {
        let n = r.len();
        for k in 0..n {
            let (a, b) = (r[k], r[(k + 1) % n]);
            if (a[1] <= p[1]) != (b[1] <= p[1]) {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if x > p[0] {
                    winding += if b[1] > a[1] { 1 } else { -1 };
                }
            }
        }
    }
    match evenodd {
        true => winding % 2 != 0,
        false => winding != 0,
    }
}

/// Points along the pen-down moves, every `step` mm.
fn drawn(path: &Toolpath, step: f64) -> Vec<[f64; 2]> {
    let mut out = Vec::new();
    for m in path.moves.iter().filter(|m| m.down) {
        let n = (m.len() / step).ceil().max(1.0) as usize;
        for k in 0..=n {
            let t = k as f64 / n as f64;
            out.push([
                m.from[0] + t * (m.to[0] - m.from[0]),
                m.from[1] + t * (m.to[1] - m.from[1]),
            ]);
        }
    }
    out
}

fn check(file: &str, layers: &[&str]) {
    let svg = root().join("examples/svg").join(file);
    let want = reference(&svg);
    let source = Source::open(&svg).unwrap();
    let mut o = Options::new(Machine::Flatbed, 1.0);
    o.width_mm = None;
    let v = vectorize::vectorize(&source, &o, file).unwrap();

    // The pen is on the drawing.
    let outlines = Grid::new(want.shapes.iter().flat_map(|s| s.1.iter().copied()));
    let fills: Vec<&Fill> = want.shapes.iter().filter_map(|s| s.2.as_ref()).collect();
    let pen = drawn(&v.toolpath, 0.05);
    let off: Vec<&[f64; 2]> = pen
        .iter()
        .filter(|p| !outlines.near(**p) && !fills.iter().any(|(eo, r)| inside(**p, *eo, r)))
        .collect();
    assert!(
        off.is_empty(),
        "{file}: {} of {} drawn points are further than {WITHIN_MM} mm from the drawing, e.g. {:?}",
        off.len(),
        pen.len(),
        &off[..off.len().min(5)]
    );
    // The drawing is all drawn.
    let ink = Grid::new(drawn(&v.toolpath, 0.02));
    let missed: Vec<[f64; 2]> = want
        .shapes
        .iter()
        .flat_map(|s| s.1.iter().copied())
        .filter(|p| !ink.near(*p))
        .collect();
    assert!(
        missed.is_empty(),
        "{file}: {} points of the drawing are not drawn, e.g. {:?}",
        missed.len(),
        &missed[..missed.len().min(5)]
    );
    // Passes and pen changes.
    let mut names: Vec<&str> = Vec::new();
    for s in &want.shapes {
        if !names.contains(&s.0.as_str()) {
            names.push(&s.0);
        }
    }
    assert_eq!(names, layers, "{file}: the reference's layers");
    let passes: Vec<&str> = v.layers.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(passes, layers, "{file}: the passes");
    let pauses = v.gcode.lines().filter(|l| l.starts_with("M0 ")).count();
    assert_eq!(pauses, layers.len() - 1, "{file}: pen changes");
    eprintln!(
        "{file}: {} points drawn, {} of the drawing, all within {WITHIN_MM} mm; {} passes",
        pen.len(),
        want.shapes.iter().map(|s| s.1.len()).sum::<usize>(),
        passes.len()
    );
}

#[test]
fn shapes() {
    check("shapes.svg", &["#000000", "#404040"]);
}

#[test]
fn transforms_and_nested_groups() {
    check("transforms.svg", &["#000000"]);
}

#[test]
fn arcs_and_curves() {
    check("arcs.svg", &["#000000"]);
}

#[test]
fn text_converted_to_paths() {
    check("text-paths.svg", &["#000000"]);
}

#[test]
fn an_inkscape_file_with_layers() {
    check(
        "inkscape-layers.svg",
        &["1 outline black", "2 fill red", "3 title blue"],
    );
}

#[test]
fn a_vpype_drawing_with_named_coloured_layers() {
    check("vpype-generated.svg", &["outline", "ellipses", "title"]);
}

#[test]
fn an_inkscape_file_after_a_vpype_pipeline() {
    check("vpype-processed.svg", &["2", "4"]);
}
