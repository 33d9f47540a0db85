//! The vectoriser on the example images, on pictures made here with known
//! answers, and on SVG.

use super::*;
use crate::vectorize::simplify::distance;

fn image(name: &str) -> Gray {
    Gray::open(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../examples/images")
            .join(name),
    )
    .unwrap()
}

fn picture(g: Gray) -> Source {
    Source::Picture(g)
}

fn svg(body: &str, w_mm: f64, h_mm: f64) -> Source {
    let doc = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:inkscape=\"http://www.inkscape.org/namespaces/inkscape\" \
         width=\"{w_mm}mm\" height=\"{h_mm}mm\" viewBox=\"0 0 {w_mm} {h_mm}\">{body}</svg>"
    );
    Source::Svg(svgfile::read(doc.as_bytes()).unwrap())
}

fn length(s: &[[f64; 2]]) -> f64 {
    super::length(s)
}

#[test]
fn the_examples_vectorize_on_every_machine_with_less_pen_up_travel() {
    for (name, mode) in [
        ("horse.png", Mode::Auto),
        ("camera.jpg", Mode::Edges),
        ("horse.png", Mode::Outline),
    ] {
        let src = picture(image(name));
        for machine in [
            Machine::Flatbed,
            Machine::Drum,
            Machine::Whiteboard,
            Machine::Scara,
        ] {
            let mut o = Options::new(machine, 80.0);
            o.mode = mode;
            o.canny = [60.0, 180.0];
            o.hatch_mm = 1.5;
            let v = vectorize(&src, &o, name).unwrap_or_else(|e| panic!("{name} {machine:?}: {e}"));
            assert!(!v.strokes.is_empty());
            assert!(
                v.pen_up_ordered_mm <= v.pen_up_traced_mm,
                "{name} {machine:?}"
            );
            assert!(v.seconds > 0.0);
            let (lo, hi) = v.toolpath.bounds();
            assert!(
                hi[0] - lo[0] <= 80.0 + 0.1,
                "{name} {machine:?}: {lo:?} {hi:?}"
            );
            if machine == Machine::Flatbed {
                eprintln!(
                    "{name} {:?}: {} strokes, pen-up {:.0} → {:.0} mm, {:.0} s",
                    v.mode,
                    v.strokes.len(),
                    v.pen_up_traced_mm,
                    v.pen_up_ordered_mm,
                    v.seconds
                );
                assert!(v.pen_up_ordered_mm < 0.5 * v.pen_up_traced_mm);
            }
        }
    }
}

#[test]
fn a_dark_square_becomes_its_outline_upright_at_scale() {
    // 100 × 50 px, a dark square from (60, 10) to (80, 30) px.
    let mut g = Gray::new(100, 50, 1.0);
    for y in 10..30 {
        g.pixels[y * 100 + 60..y * 100 + 80].fill(0.0);
    }
    let mut o = Options::new(Machine::Flatbed, 50.0);
    o.mode = Mode::Outline;
    o.blur = 0.0;
    let v = vectorize(&picture(g), &o, "square").unwrap();
    // One closed outline, 0.5 mm a pixel, halfway between dark and light
    // pixel centres: x 30…40 mm; image up is +Y: rows 10…30 of 50 are
    // Y 10…20 mm.
    assert_eq!(v.strokes.len(), 1, "{:?}", v.strokes);
    let s = &v.strokes[0];
    assert_eq!(s.first(), s.last());
    let (lo, hi) = bounds(&v.strokes);
    assert_eq!((lo, hi), ([30.0, 10.0], [40.0, 20.0]));
    assert_eq!(v.mode, Some((Mode::Outline, 0.5)));
}

#[test]
fn clear_errors_for_nothing_to_draw_and_drawings_too_big() {
    let white = picture(Gray::new(50, 50, 1.0));
    let mut o = Options::new(Machine::Flatbed, 50.0);
    o.mode = Mode::Edges;
    assert_eq!(
        vectorize(&white, &o, "").err().unwrap(),
        "no edges found: lower the --canny thresholds"
    );
    o.mode = Mode::Outline;
    o.threshold = Some(0.5);
    assert!(vectorize(&white, &o, "")
        .err()
        .unwrap()
        .starts_with("nothing darker than the threshold 0.50"));
    let horse = picture(image("horse.png"));
    let wide = Options::new(Machine::Flatbed, 200.0);
    let e = vectorize(&horse, &wide, "").err().unwrap();
    assert!(e.contains("the flatbed's X travel is 0…140 mm"), "{e}");
    let far = Options::new(Machine::Scara, 500.0);
    let e = vectorize(&horse, &far, "").err().unwrap();
    assert!(e.starts_with("the drawing does not fit the scara"), "{e}");
    let mut none = Options::new(Machine::Flatbed, 1.0);
    none.width_mm = None;
    assert!(vectorize(&horse, &none, "")
        .err()
        .unwrap()
        .starts_with("give the drawing's size"));
}

/// Line art of known length drawn with a round brush of `r` px into a
/// `w` × `h` picture, anti-aliased.
fn line_art(w: usize, h: usize, lines: &[([f64; 2], [f64; 2])], r: f64) -> (Gray, f64) {
    let mut g = Gray::new(w, h, 1.0);
    for y in 0..h {
        for x in 0..w {
            let p = [x as f64 + 0.5, y as f64 + 0.5];
            let d = lines
                .iter()
                .map(|(a, b)| distance(p, *a, *b))
                .fold(f64::MAX, f64::min);
            g.pixels[y * w + x] = (d - r + 0.5).clamp(0.0, 1.0) as f32;
        }
    }
    let total = lines
        .iter()
        .map(|(a, b)| (b[0] - a[0]).hypot(b[1] - a[1]))
        .sum();
    (g, total)
}

#[test]
fn line_art_is_drawn_once_along_its_centre_lines() {
    // A star of crossing lines, a zigzag and a separate stroke, 3 px wide
    // on a 240 × 160 picture; 0.5 mm a pixel.
    let lines = [
        ([20.0, 80.0], [140.0, 80.0]),
        ([80.0, 20.0], [80.0, 140.0]),
        ([35.0, 35.0], [125.0, 125.0]),
        ([160.0, 30.0], [190.0, 130.0]),
        ([190.0, 130.0], [220.0, 30.0]),
        ([150.0, 145.0], [230.0, 145.0]),
    ];
    let (g, total_px) = line_art(240, 160, &lines, 1.6);
    let l = total_px * 0.5;
    let mut o = Options::new(Machine::Drum, 120.0);
    o.mode = Mode::Auto;
    let v = vectorize(&picture(g), &o, "lines").unwrap();
    assert_eq!(
        v.mode.map(|m| m.0),
        Some(Mode::Centerline),
        "auto picks centre-lines"
    );
    let (down, _) = v.toolpath.lengths();
    assert!(
        (0.95 * l..=1.2 * l).contains(&down),
        "pen down {down:.1} mm for {l:.1} mm of lines"
    );
    // No stroke drawn twice: a point of a stroke is near another stroke
    // only where lines cross or meet.
    let mut shared = 0;
    let mut samples = 0;
    for (i, s) in v.strokes.iter().enumerate() {
        for w in s.windows(2) {
            let n = (length(w) / 0.25).ceil() as usize;
            for k in 0..n {
                let t = k as f64 / n as f64;
                let p = [
                    w[0][0] + t * (w[1][0] - w[0][0]),
                    w[0][1] + t * (w[1][1] - w[0][1]),
                ];
                samples += 1;
                let near = v
                    .strokes
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| *j != i)
                    .any(|(_, o)| o.windows(2).any(|q| distance(p, q[0], q[1]) < 0.4));
                shared += usize::from(near);
            }
        }
    }
    assert!(
        (shared as f64) < 0.04 * samples as f64,
        "{shared} of {samples} points on another stroke"
    );
    // The crossing lines are not cut at the crossings: a handful of strokes.
    assert!(v.strokes.len() <= 6, "{} strokes", v.strokes.len());
    eprintln!(
        "centre-lines: pen down {down:.1} mm for L = {l:.1} mm ({:.3} L), {} strokes, \
         {shared} of {samples} points near another stroke",
        down / l,
        v.strokes.len()
    );
}

#[test]
fn a_grey_ramp_is_hatched_denser_where_it_is_darker() {
    // White at the left to black at the right, 160 × 40 px, 0.5 mm a px.
    let (w, h) = (160, 40);
    let mut g = Gray::new(w, h, 1.0);
    for y in 0..h {
        for x in 0..w {
            g.pixels[y * w + x] = 1.0 - x as f32 / (w - 1) as f32;
        }
    }
    for cross in [false, true] {
        let mut o = Options::new(Machine::Drum, 80.0);
        o.mode = Mode::Auto;
        o.cross = cross;
        o.hatch_mm = 0.5;
        let v = vectorize(&picture(g.clone()), &o, "ramp").unwrap();
        assert_eq!(v.mode.map(|m| m.0), Some(Mode::Hatch), "auto hatches tones");
        // Ink in 8 bands across.
        let mut bands = [0.0f64; 8];
        for m in v.toolpath.moves.iter().filter(|m| m.down) {
            let steps = (m.len() / 0.05).ceil().max(1.0) as usize;
            for k in 0..steps {
                let t = (k as f64 + 0.5) / steps as f64;
                let x = m.from[0] + t * (m.to[0] - m.from[0]);
                let b = ((x / 10.0).floor() as usize).min(7);
                bands[b] += m.len() / steps as f64;
            }
        }
        for k in 1..8 {
            assert!(bands[k] >= bands[k - 1] - 1.0, "cross {cross}: {bands:?}");
        }
        assert!(
            bands[0] < 1.0 && bands[7] > 3.5 * bands[2].max(1.0),
            "cross {cross}: {bands:?}"
        );
        // At least four levels: as many distinct densities across.
        let mut distinct: Vec<f64> = Vec::new();
        for b in bands {
            if distinct.last().is_none_or(|d| b > d * 1.15 + 1.0) {
                distinct.push(b);
            }
        }
        assert!(distinct.len() >= 4, "cross {cross}: {bands:?}");
        eprintln!("grey ramp, cross {cross}: pen down per 10 mm band {bands:.0?}");
    }
}

#[test]
fn lines_lighter_than_the_threshold_are_named_in_a_warning() {
    // Light grey lines (0.7) on white, with a threshold below them.
    let (mut g, _) = line_art(
        120,
        80,
        &[([10.0, 20.0], [110.0, 20.0]), ([10.0, 60.0], [110.0, 60.0])],
        2.0,
    );
    for p in g.pixels.iter_mut() {
        *p = 0.7 + 0.3 * *p;
    }
    // One black dot so something is drawn.
    for y in 38..42 {
        for x in 50..70 {
            g.pixels[y * 120 + x] = 0.0;
        }
    }
    let mut o = Options::new(Machine::Drum, 60.0);
    o.mode = Mode::Centerline;
    o.threshold = Some(0.5);
    let v = vectorize(&picture(g.clone()), &o, "grey").unwrap();
    assert!(
        v.warnings.iter().any(|w| w.contains("is not drawn")),
        "{:?}",
        v.warnings
    );
    // From the histogram, the grey lines are ink.
    o.threshold = None;
    let v = vectorize(&picture(g), &o, "grey").unwrap();
    assert!(v.warnings.is_empty(), "{:?}", v.warnings);
    assert!(v.toolpath.lengths().0 > 80.0, "{}", v.toolpath.lengths().0);
}

#[test]
fn svg_layers_become_passes_with_a_pen_change_between() {
    let src = svg(
        "<g inkscape:groupmode=\"layer\" id=\"a\" inkscape:label=\"Black outline\">\
           <rect x=\"10\" y=\"10\" width=\"30\" height=\"20\" fill=\"none\" stroke=\"black\"/></g>\
         <g inkscape:groupmode=\"layer\" id=\"b\" inkscape:label=\"Red fill\">\
           <circle cx=\"70\" cy=\"30\" r=\"15\" fill=\"red\"/></g>\
         <g inkscape:groupmode=\"layer\" id=\"c\" inkscape:label=\"Blue\">\
           <path d=\"M 10 50 C 30 40 50 60 90 50\" fill=\"none\" stroke=\"blue\"/></g>",
        100.0,
        60.0,
    );
    let o = Options::new(Machine::Drum, 100.0);
    let v = vectorize(&src, &o, "layers").unwrap();
    let names: Vec<&str> = v.layers.iter().map(|l| l.name.as_str()).collect();
    assert_eq!(names, ["Black outline", "Red fill", "Blue"]);
    let pauses: Vec<&str> = v.gcode.lines().filter(|l| l.starts_with("M0")).collect();
    assert_eq!(
        pauses,
        [
            "M0 (MSG, change the pen: pass 2 of 3, Red fill)",
            "M0 (MSG, change the pen: pass 3 of 3, Blue)"
        ]
    );
    // The pen is up at each pause.
    let lines: Vec<&str> = v.gcode.lines().collect();
    for (i, l) in lines
        .iter()
        .enumerate()
        .filter(|(_, l)| l.starts_with("M0"))
    {
        let last_pen = lines[..i].iter().rev().find(|l| **l == "M3" || **l == "M5");
        assert_eq!(last_pen, Some(&"M5"), "line {i}: {l}");
    }
    // The 1:1 page at the origin: the rectangle's corner (10, 10) from
    // the top is (10, 50) mm; the circle filled with lines 0.8 mm apart.
    let p = &v.layers[0].strokes[0];
    assert!(
        p.iter()
            .any(|q| (q[0] - 10.0).abs() < 1e-3 && (q[1] - 50.0).abs() < 1e-3),
        "{p:?}"
    );
    let fill: f64 = v.layers[1].strokes.iter().map(|s| length(s)).sum();
    let area_over_spacing = std::f64::consts::PI * 225.0 / 0.8;
    let outline = std::f64::consts::TAU * 15.0;
    assert!(
        (fill - area_over_spacing - outline).abs() < 0.05 * area_over_spacing,
        "{fill}"
    );
    let one = Options {
        one_pen: true,
        ..o.clone()
    };
    assert!(!vectorize(&src, &one, "").unwrap().gcode.contains("M0"));
}

#[test]
fn svg_on_paper_fitted_turned_and_refused_past_the_travel() {
    let src = svg(
        "<path d=\"M 0 0 L 200 100\" stroke=\"black\"/>",
        200.0,
        100.0,
    );
    let mut o = Options::new(Machine::Flatbed, 1.0);
    o.width_mm = None;
    // 200 mm is past the flatbed's 140 mm of X.
    let e = vectorize(&src, &o, "").err().unwrap();
    assert!(e.contains("X travel is 0…140 mm"), "{e}");
    // On A5 landscape (210 × 148), fitted within 10 mm: 190 × 95 → past
    // the X travel still; turned a quarter on A5 portrait: 128 wide.
    o.layout.paper = Some([148.0, 210.0]);
    o.layout.fit = true;
    o.layout.margin = 10.0;
    o.layout.rotate = 90.0;
    let v = vectorize(&src, &o, "").unwrap();
    let (lo, hi) = bounds(&v.strokes);
    assert!(
        (hi[1] - lo[1] - 190.0).abs() < 0.05 && (hi[0] - lo[0] - 95.0).abs() < 0.05,
        "{lo:?} {hi:?}"
    );
    assert!((lo[0] - (148.0 - 95.0) / 2.0).abs() < 0.05, "{lo:?}");
}
