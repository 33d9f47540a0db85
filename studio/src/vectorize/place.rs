//! Where a drawing goes on the machine: its size, turn and corner, and
//! the paper it is drawn on.
//!
//! The drawing's frame is mm, y up, its extent a box. It is turned by
//! `rotate` degrees (counter-clockwise), then, with `--fit`, scaled to
//! fill the paper within its margins; its (turned) box is centred on the
//! paper (within the margins when fitted), or its lower left corner put
//! at `--at`. The paper's lower left corner is the machine's origin (the
//! whiteboard's paper is centred on its origin, which is the middle of its
//! reach). Without a paper the drawing's corner is the origin (the
//! whiteboard: centred), as it always was.

use taut_logic::config::MachineConfig;
use taut_logic::machine::Machine;

/// Paper sizes, portrait, mm.
pub const PAPERS: [(&str, [f64; 2]); 7] = [
    ("A5", [148.0, 210.0]),
    ("A4", [210.0, 297.0]),
    ("A3", [297.0, 420.0]),
    ("A2", [420.0, 594.0]),
    ("letter", [215.9, 279.4]),
    ("legal", [215.9, 355.6]),
    ("tabloid", [279.4, 431.8]),
];

/// `A4`, `letter`, … (any case) or `WxH` in mm.
pub fn paper(v: &str) -> Result<[f64; 2], String> {
    if let Some((_, size)) = PAPERS.iter().find(|(n, _)| n.eq_ignore_ascii_case(v)) {
        return Ok(*size);
    }
    let names: Vec<&str> = PAPERS.iter().map(|p| p.0).collect();
    let bad = || format!("{v:?}: {} or WIDTHxHEIGHT in mm", names.join(", "));
    let (w, h) = v.split_once(['x', 'X']).ok_or_else(bad)?;
    match (w.trim().parse::<f64>(), h.trim().parse::<f64>()) {
        (Ok(w), Ok(h)) if w > 0.0 && h > 0.0 => Ok([w, h]),
        _ => Err(bad()),
    }
}

#[derive(Clone, Debug, PartialEq, Default)]
pub struct Layout {
    /// The paper, as it lies (landscape already turned), mm.
    pub paper: Option<[f64; 2]>,
    /// Room `fit` leaves at each edge of the paper, mm.
    pub margin: f64,
    pub fit: bool,
    /// The drawing's lower left corner, mm.
    pub at: Option<[f64; 2]>,
    /// Degrees, counter-clockwise.
    pub rotate: f64,
}

/// A drawing's frame to the machine's: turned, scaled, moved.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Place {
    pub scale: f64,
    cos: f64,
    sin: f64,
    pub offset: [f64; 2],
    /// The paper's lower left corner on the machine, and its size.
    pub paper: Option<([f64; 2], [f64; 2])>,
}

impl Place {
    pub fn apply(&self, p: [f64; 2]) -> [f64; 2] {
        [
            self.scale * (self.cos * p[0] - self.sin * p[1]) + self.offset[0],
            self.scale * (self.sin * p[0] + self.cos * p[1]) + self.offset[1],
        ]
    }
}

/// Where the paper's lower left corner goes.
fn paper_corner(machine: Machine, size: [f64; 2]) -> [f64; 2] {
    crate::plot::default_corner(machine, size)
}

/// The placement of a drawing whose extent is the box `lo`…`hi`.
pub fn place(
    lo: [f64; 2],
    hi: [f64; 2],
    layout: &Layout,
    machine: Machine,
) -> Result<Place, String> {
    let r = layout.rotate.to_radians();
    let (cos, sin) = (r.cos(), r.sin());
    let turned = [
        [lo[0], lo[1]],
        [hi[0], lo[1]],
        [hi[0], hi[1]],
        [lo[0], hi[1]],
    ]
    .map(|p| [cos * p[0] - sin * p[1], sin * p[0] + cos * p[1]]);
    let tlo = [0, 1].map(|i| turned.iter().map(|p| p[i]).fold(f64::MAX, f64::min));
    let thi = [0, 1].map(|i| turned.iter().map(|p| p[i]).fold(f64::MIN, f64::max));
    let size = [thi[0] - tlo[0], thi[1] - tlo[1]];
    if !(size[0] > 0.0 || size[1] > 0.0) {
        return Err("the drawing is empty".into());
    }
    let paper = layout.paper.map(|p| (paper_corner(machine, p), p));
    let scale = match (layout.fit, paper) {
        (false, _) => 1.0,
        (true, None) => return Err("--fit needs the paper to fit to: --paper A4, letter, …".into()),
        (true, Some((_, p))) => {
            let room = [p[0] - 2.0 * layout.margin, p[1] - 2.0 * layout.margin];
            if room[0] <= 0.0 || room[1] <= 0.0 {
                return Err(format!(
                    "--margin-mm {} leaves no room on the paper",
                    layout.margin
                ));
            }
            let k = |i: usize| match size[i] > 0.0 {
                true => room[i] / size[i],
                false => f64::MAX,
            };
            k(0).min(k(1))
        }
    };
    let scaled = [size[0] * scale, size[1] * scale];
    let corner = match (layout.at, paper) {
        (Some(at), _) => at,
        (None, Some((pc, p))) => [
            pc[0] + (p[0] - scaled[0]) / 2.0,
            pc[1] + (p[1] - scaled[1]) / 2.0,
        ],
        (None, None) => crate::plot::default_corner(machine, scaled),
    };
    if let (Some((pc, p)), false) = (paper, layout.fit) {
        let fits = scaled[0] <= p[0] + 1e-6 && scaled[1] <= p[1] + 1e-6;
        if !fits && layout.at.is_none() {
            return Err(format!(
                "the drawing ({:.1} × {:.1} mm) is larger than the paper ({:.1} × {:.1} mm): use --fit, a smaller size or a larger --paper",
                scaled[0], scaled[1], p[0], p[1]
            ));
        }
        let _ = pc;
    }
    Ok(Place {
        scale,
        cos,
        sin,
        offset: [corner[0] - scale * tlo[0], corner[1] - scale * tlo[1]],
        paper,
    })
}

/// Refuses a drawing whose box leaves a Cartesian machine's travel (the
/// axes with soft limits), naming the axis and both ranges. The arms and
/// the whiteboard are checked line by line by the firmware's kinematics
/// when the G-code is read back.
pub fn check_travel(lo: [f64; 2], hi: [f64; 2], machine: Machine) -> Result<(), String> {
    let cfg = MachineConfig::defaults(machine);
    if !matches!(machine, Machine::Flatbed | Machine::Drum) {
        return Ok(());
    }
    for (i, name) in ["X", "Y"].into_iter().enumerate() {
        let axis = cfg.axis(i);
        if !axis.soft_limits {
            continue;
        }
        let (min, max) = (
            f64::from(axis.travel.0 .0) / 1000.0,
            f64::from(axis.travel.1 .0) / 1000.0,
        );
        if lo[i] < min - 1e-6 || hi[i] > max + 1e-6 {
            return Err(format!(
                "the drawing spans {name} {:.1}…{:.1} mm; the {}'s {name} travel is {min:.0}…{max:.0} mm: \
                 make it smaller (--width-mm, --fit with a --paper that fits) or move it (--at)",
                lo[i],
                hi[i],
                machine.name()
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn near(a: [f64; 2], b: [f64; 2]) -> bool {
        (a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9
    }

    #[test]
    fn papers_by_name_or_size() {
        assert_eq!(paper("a4"), Ok([210.0, 297.0]));
        assert_eq!(paper("Letter"), Ok([215.9, 279.4]));
        assert_eq!(paper("100x50"), Ok([100.0, 50.0]));
        assert!(paper("B5").unwrap_err().contains("A4"));
    }

    #[test]
    fn fit_turn_centre_and_corner() {
        let m = Machine::Drum;
        // 100 × 50 drawing on A4 with 10 mm margins: 190 wide.
        let l = Layout {
            paper: Some([210.0, 297.0]),
            margin: 10.0,
            fit: true,
            ..Layout::default()
        };
        let p = place([0.0, 0.0], [100.0, 50.0], &l, m).unwrap();
        assert!((p.scale - 1.9).abs() < 1e-9);
        assert!(near(p.apply([0.0, 0.0]), [10.0, (297.0 - 95.0) / 2.0]));
        // Turned a quarter: 50 wide, 100 tall, fits 277 tall: 2.77.
        let l = Layout { rotate: 90.0, ..l };
        let p = place([0.0, 0.0], [100.0, 50.0], &l, m).unwrap();
        assert!((p.scale - 2.77).abs() < 1e-9);
        let a = p.apply([0.0, 0.0]);
        let b = p.apply([100.0, 0.0]);
        assert!((b[0] - a[0]).abs() < 1e-9 && (b[1] - a[1] - 277.0).abs() < 1e-9);
        // --at puts the corner there; no paper: the origin.
        let at = Layout {
            at: Some([5.0, 7.0]),
            ..Layout::default()
        };
        assert!(near(
            place([2.0, 3.0], [12.0, 13.0], &at, m)
                .unwrap()
                .apply([2.0, 3.0]),
            [5.0, 7.0]
        ));
        let p = place(
            [0.0, 0.0],
            [10.0, 10.0],
            &Layout::default(),
            Machine::Whiteboard,
        )
        .unwrap();
        assert!(near(p.apply([0.0, 0.0]), [-5.0, -5.0]));
        // Too large for the paper, and fit without a paper.
        let big = Layout {
            paper: Some([210.0, 297.0]),
            ..Layout::default()
        };
        assert!(place([0.0, 0.0], [300.0, 10.0], &big, m)
            .unwrap_err()
            .contains("larger than the paper"));
        let fit = Layout {
            fit: true,
            ..Layout::default()
        };
        assert!(place([0.0, 0.0], [3.0, 1.0], &fit, m)
            .unwrap_err()
            .starts_with("--fit needs"));
    }

    #[test]
    fn the_flatbeds_travel_is_named() {
        let e = check_travel([0.0, 0.0], [150.0, 20.0], Machine::Flatbed).unwrap_err();
        assert!(
            e.contains("X 0.0…150.0 mm; the flatbed's X travel is 0…140 mm"),
            "{e}"
        );
        assert!(check_travel([0.0, -500.0], [140.0, 900.0], Machine::Flatbed).is_ok());
    }
}
