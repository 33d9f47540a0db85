//! A plotter file's toolpath read independently of the firmware, to check
//! the drawing a real file makes from the pulses: plain `f64`, from the
//! words' meanings in Grbl's documents (`G0 G1 G2 G3`, `G90 G91`, `G20
//! G21`, `G92`, `G10 L20 P1`), the pen from `M3`/`M4`/`M5`, `M300 S`
//! (the unicorn extension's angles) and `Z` (down at 0 or below, `M300`
//! over 180 leaves it alone). Not the firmware's parser or executor.

use crate::drawing::Toolpath;
use taut_logic::config::MachineConfig;

/// What a file draws, in machine mm: the strokes with the pen down, the
/// travel with it up, every corner the pen turns at while down, and where
/// it ends.
pub struct Strokes {
    pub drawn: Vec<Toolpath>,
    pub travel: Vec<Toolpath>,
    pub corners: Vec<[f64; 2]>,
    pub end: [f64; 2],
}

impl Strokes {
    /// Distance from `p` to the nearest stroke (`down`) or travel.
    pub fn distance(&self, p: [f64; 2], down: bool) -> f64 {
        let paths = if down { &self.drawn } else { &self.travel };
        paths
            .iter()
            .map(|t| match t.0.len() {
                1 => (t.0[0][0] - p[0]).hypot(t.0[0][1] - p[1]),
                _ => t.distance(p),
            })
            .fold(f64::MAX, f64::min)
    }
}

struct Reader {
    /// Machine position, and the work offset (work = machine − offset).
    at: [f64; 2],
    offset: [f64; 2],
    z: f64,
    z_offset: f64,
    absolute: bool,
    inch: bool,
    motion: u8,
    down: bool,
    servo_off: bool,
    pen_down_deg: f64,
    out: Strokes,
}

/// The toolpath of `text` run on a machine whose work zero (`G10 L20 P1
/// X0 Y0`) is at machine `zero`, the pen up.
pub fn read(text: &str, zero: [f64; 2], cfg: &MachineConfig) -> Strokes {
    let mut r = Reader {
        at: zero,
        offset: zero,
        z: 0.0,
        z_offset: 0.0,
        absolute: true,
        inch: false,
        motion: 0,
        down: false,
        servo_off: false,
        pen_down_deg: f64::from(cfg.pen.down_deg),
        out: Strokes {
            drawn: Vec::new(),
            travel: vec![Toolpath(vec![zero])],
            corners: Vec::new(),
            end: zero,
        },
    };
    for line in text.lines() {
        r.line(&words(line));
    }
    r.out.end = r.at;
    r.out
}

/// The words of a line: comments, spaces and `/` dropped, upper case.
fn words(line: &str) -> Vec<(char, f64)> {
    let mut kept = String::new();
    let mut comment = false;
    for c in line.chars() {
        match c {
            '(' => comment = true,
            ')' => comment = false,
            ';' if !comment => break,
            c if comment || c.is_whitespace() || c == '/' || c == '\u{feff}' => {}
            c => kept.push(c.to_ascii_uppercase()),
        }
    }
    let mut out = Vec::new();
    let mut rest = kept.as_str();
    while let Some(letter) = rest.chars().next().filter(char::is_ascii_alphabetic) {
        rest = &rest[1..];
        let end = rest
            .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-' || c == '+'))
            .unwrap_or(rest.len());
        if let Ok(v) = rest[..end].parse() {
            out.push((letter, v));
        }
        rest = &rest[end..];
    }
    out
}

impl Reader {
    fn unit(&self, v: f64) -> f64 {
        if self.inch {
            v * 25.4
        } else {
            v
        }
    }

    fn line(&mut self, w: &[(char, f64)]) {
        let get = |l: char| w.iter().find(|(c, _)| *c == l).map(|(_, v)| *v);
        let codes = |l: char| w.iter().filter(move |(c, _)| *c == l).map(|(_, v)| *v);
        let mut offset_line = None;
        for g in codes('G') {
            match g {
                g if g == 0.0 || g == 1.0 || g == 2.0 || g == 3.0 => self.motion = g as u8,
                90.0 => self.absolute = true,
                91.0 => self.absolute = false,
                20.0 => self.inch = true,
                21.0 => self.inch = false,
                g if g == 92.0 || g == 10.0 => offset_line = Some(g),
                _ => {}
            }
        }
        for m in codes('M') {
            match m as u32 {
                3 | 4 => self.pen(true),
                5 => self.pen(false),
                300 => {
                    let s = get('S').unwrap_or(0.0);
                    self.servo_off = s > 180.0;
                    if !self.servo_off {
                        self.pen((s - self.pen_down_deg).abs() < 0.5);
                    }
                }
                _ => {}
            }
            if m as u32 == 3 || m as u32 == 4 || m as u32 == 5 {
                self.servo_off = false;
            }
        }
        let (x, y, z) = (get('X'), get('Y'), get('Z'));
        if offset_line.is_some() {
            // G92 and G10 L20 P1 (the only work system here): the machine
            // stands where it does, the words name it.
            for (i, v) in [x, y].into_iter().enumerate() {
                if let Some(v) = v {
                    self.offset[i] = self.at[i] - self.unit(v);
                }
            }
            if let Some(v) = z {
                self.z_offset = self.z - self.unit(v);
            }
            return;
        }
        if x.is_none() && y.is_none() && z.is_none() {
            return;
        }
        let mut to = self.at;
        for (i, v) in [x, y].into_iter().enumerate() {
            if let Some(v) = v {
                to[i] = match self.absolute {
                    true => self.unit(v) + self.offset[i],
                    false => self.at[i] + self.unit(v),
                };
            }
        }
        if let Some(v) = z {
            self.z = match self.absolute {
                true => self.unit(v) + self.z_offset,
                false => self.z + self.unit(v),
            };
            if !self.servo_off {
                self.pen(self.z - self.z_offset <= 0.0);
            }
        }
        match self.motion {
            2 | 3 => {
                let centre = match (get('I'), get('J'), get('R')) {
                    (_, _, Some(r)) => self.centre_of(to, self.unit(r), self.motion == 2),
                    (i, j, None) => [
                        self.at[0] + self.unit(i.unwrap_or(0.0)),
                        self.at[1] + self.unit(j.unwrap_or(0.0)),
                    ],
                };
                self.arc(centre, to, self.motion == 3);
            }
            _ => self.go(to),
        }
    }

    /// The centre of the arc of radius `r` to `to` (Grbl's rule: the
    /// shorter arc, the longer for a negative `r`).
    fn centre_of(&self, to: [f64; 2], r: f64, cw: bool) -> [f64; 2] {
        let (x, y) = (to[0] - self.at[0], to[1] - self.at[1]);
        let d = x.hypot(y);
        let mut h = -(4.0 * r * r - d * d).max(0.0).sqrt() / d;
        if !cw {
            h = -h;
        }
        if r < 0.0 {
            h = -h;
        }
        [
            self.at[0] + 0.5 * (x - y * h),
            self.at[1] + 0.5 * (y + x * h),
        ]
    }

    fn pen(&mut self, down: bool) {
        if down != self.down {
            self.down = down;
            let here = Toolpath(vec![self.at]);
            match down {
                true => self.out.drawn.push(here),
                false => self.out.travel.push(here),
            }
            if down {
                self.out.corners.push(self.at);
            }
        }
    }

    fn path(&mut self) -> &mut Toolpath {
        let list = if self.down {
            &mut self.out.drawn
        } else {
            &mut self.out.travel
        };
        list.last_mut().unwrap()
    }

    fn go(&mut self, to: [f64; 2]) {
        self.path().line_to(to);
        self.at = to;
        if self.down {
            self.out.corners.push(to);
        }
    }

    fn arc(&mut self, centre: [f64; 2], to: [f64; 2], ccw: bool) {
        self.path().arc_to(centre, to, ccw);
        self.at = to;
        if self.down {
            self.out.corners.push(to);
        }
    }
}
