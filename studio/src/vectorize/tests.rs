//! The vectoriser on the example images and on a drawing by hand.

use super::*;
use std::path::Path;

fn image(name: &str) -> Gray {
    Gray::open(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../examples/images")
            .join(name),
    )
    .unwrap()
}

#[test]
fn the_examples_vectorize_on_every_machine_with_less_pen_up_travel() {
    for (name, mode) in [
        (
            "horse.png",
            Mode::Edges {
                low: 50.0,
                high: 150.0,
            },
        ),
        (
            "camera.jpg",
            Mode::Edges {
                low: 60.0,
                high: 180.0,
            },
        ),
        (
            "horse.png",
            Mode::Hatch {
                threshold: 0.5,
                spacing_mm: 1.5,
                angle: 45.0,
            },
        ),
    ] {
        for machine in [
            Machine::Flatbed,
            Machine::Drum,
            Machine::Whiteboard,
            Machine::Scara,
        ] {
            let mut o = Options::new(machine, 80.0);
            o.mode = mode;
            let v = vectorize(&image(name), &o, name)
                .unwrap_or_else(|e| panic!("{name} {machine:?}: {e}"));
            assert!(!v.strokes.is_empty());
            assert!(
                v.pen_up_ordered_mm <= v.pen_up_traced_mm,
                "{name} {machine:?}"
            );
            // The firmware's reading draws within the picture's frame.
            let (lo, hi) = v.toolpath.bounds();
            let corner = plot::default_corner(
                machine,
                [
                    80.0,
                    80.0 * image(name).height as f64 / image(name).width as f64,
                ],
            );
            assert!(
                hi[0] - lo[0] <= 80.0 + 0.1 && lo[0] >= corner[0].min(0.0) - 0.1,
                "{name} {machine:?}: {lo:?} {hi:?}"
            );
            if machine == Machine::Flatbed {
                eprintln!(
                    "{name} {mode:?}: {} strokes, pen-up {:.0} → {:.0} mm",
                    v.strokes.len(),
                    v.pen_up_traced_mm,
                    v.pen_up_ordered_mm
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
    o.mode = Mode::Hatch {
        threshold: 0.5,
        spacing_mm: 100.0,
        angle: 0.0,
    };
    o.blur = 0.0;
    let v = vectorize(&g, &o, "square").unwrap();
    // One closed outline, 0.5 mm a pixel, halfway between dark and light
    // pixel centres: x 30…40 mm, and image up is +Y: rows 10…30 of 50 are
    // Y 10…20 mm.
    assert_eq!(v.strokes.len(), 1, "{:?}", v.strokes);
    let s = &v.strokes[0];
    assert_eq!(s.first(), s.last());
    // Marching squares cuts each corner by a quarter pixel.
    assert_eq!(s.len(), 9, "{s:?}");
    let (xs, ys): (Vec<f64>, Vec<f64>) = s.iter().map(|p| (p[0], p[1])).unzip();
    let range = |v: &[f64]| {
        (
            v.iter().cloned().fold(f64::MAX, f64::min),
            v.iter().cloned().fold(f64::MIN, f64::max),
        )
    };
    assert_eq!(range(&xs), (30.0, 40.0));
    assert_eq!(range(&ys), (10.0, 20.0));
}

#[test]
fn clear_errors_for_nothing_to_draw_and_drawings_too_big() {
    let white = Gray::new(50, 50, 1.0);
    let o = Options::new(Machine::Flatbed, 50.0);
    assert_eq!(
        vectorize(&white, &o, "").err().unwrap(),
        "no edges found: lower the --canny thresholds"
    );
    let mut h = Options::new(Machine::Flatbed, 50.0);
    h.mode = Mode::Hatch {
        threshold: 0.5,
        spacing_mm: 1.0,
        angle: 0.0,
    };
    assert_eq!(
        vectorize(&white, &h, "").err().unwrap(),
        "nothing darker than --threshold: raise it"
    );
    let wide = Options::new(Machine::Flatbed, 200.0);
    let e = vectorize(&image("horse.png"), &wide, "").err().unwrap();
    assert!(e.starts_with("the drawing does not fit the flatbed"), "{e}");
    let far = Options::new(Machine::Scara, 500.0);
    assert!(vectorize(&image("horse.png"), &far, "")
        .err()
        .unwrap()
        .starts_with("the drawing does not fit the scara"));
}
