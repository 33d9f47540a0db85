//! The job's card: `param.txt` and `poradi.txt` as the firmware reads
//! them, checked by the firmware's own parsers (`taut_logic::files`), and
//! what the job will cost: thread and machine time (the firmware's own
//! job state machine, planner and trapezoids).

use crate::board::nail_mm;
use taut_logic::config::MachineConfig;
use taut_logic::files::check::{Files, Next};
use taut_logic::files::poradi::PoradiReader;
use taut_logic::files::{FileError, FileName};
use taut_logic::geometry::Board;
use taut_logic::stringart::{estimate, BlendWinder, WindError};

/// The board as the card describes it: shape (0 circle, n ≥ 3 n-gon),
/// nails, radius in µm.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Spec {
    pub shape: u16,
    pub nails: u16,
    pub radius_um: u32,
}

impl Spec {
    /// `param.txt`, in the original firmware's keys.
    pub fn param_txt(&self) -> String {
        let cm = format!("{}.{:04}", self.radius_um / 10_000, self.radius_um % 10_000);
        let cm = cm.trim_end_matches('0').trim_end_matches('.');
        format!(
            "tvar = {}\npocet_hrebiku = {}\npolomer_matrice = {cm}\n",
            self.shape, self.nails
        )
    }

    /// The board, if the firmware would take it: `param.txt` through the
    /// firmware's parser (its limits, its messages), then the geometry.
    pub fn board(&self) -> Result<Board, String> {
        let mut files = Files::new();
        let base = MachineConfig::STRING_ART;
        files.push(self.param_txt().as_bytes()).map_err(show)?;
        files.end(&base).map_err(show)?;
        let radius = taut_logic::units::Milli(self.radius_um as i32);
        let board =
            Board::new(self.shape, self.nails, radius).map_err(|e| e.message().to_string())?;
        // The firmware's own check (its `bad board`): the blended winder
        // needs room for the needle in every gap.
        BlendWinder::new(board, &base).map_err(|e| match e {
            WindError::GapTooNarrow(g) => format!(
                "nails {g} and {} stand too close for the needle to pass between them",
                (g + 1) % self.nails
            ),
            _ => "the board is too small to wind".to_string(),
        })?;
        Ok(board)
    }
}

/// `poradi.txt`: the count, then the nails, twenty to a line.
pub fn poradi_txt(pattern: &[u16]) -> String {
    let mut text = format!("{},\n", pattern.len());
    for (k, line) in pattern.chunks(20).enumerate() {
        if k > 0 {
            text.push_str(",\n");
        }
        let nails: Vec<String> = line.iter().map(u16::to_string).collect();
        text.push_str(&nails.join(","));
    }
    text.push('\n');
    text
}

/// Both files through the firmware's card check (`param.txt`, no
/// `machine.txt`, `poradi.txt`), then `poradi.txt` read back nail by nail
/// as the winder streams it. Returns the nails read.
pub fn check(param: &[u8], poradi: &[u8]) -> Result<Vec<u16>, String> {
    let base = MachineConfig::STRING_ART;
    let mut files = Files::new();
    files.push(param).map_err(show)?;
    files.end(&base).map_err(show)?;
    files.missing(&base).map_err(show)?;
    files.push(poradi).map_err(show)?;
    let checked = match files.end(&base).map_err(show)? {
        Next::Done => *files.checked().expect("checked"),
        other => return Err(format!("the card check did not finish: {other:?}")),
    };
    let mut reader = PoradiReader::new(checked.params.nails);
    let (mut at, mut nails) = (0, Vec::new());
    while at < poradi.len() {
        let (used, nail) = reader.next(&poradi[at..]).map_err(show)?;
        at += used;
        nails.extend(nail);
    }
    nails.extend(reader.finish().map_err(show)?);
    if nails.len() != checked.count as usize {
        return Err(format!(
            "{} nails read, {} declared",
            nails.len(),
            checked.count
        ));
    }
    Ok(nails)
}

/// A file error as the firmware prints it (`poradi.txt:1:7: …`).
pub fn show(e: FileError) -> String {
    let mut s = Text(String::new());
    ufmt::uwrite!(s, "{}", e).expect("writing to a String");
    s.0
}

struct Text(String);

impl ufmt::uWrite for Text {
    type Error = std::convert::Infallible;
    fn write_str(&mut self, s: &str) -> Result<(), Self::Error> {
        self.0.push_str(s);
        Ok(())
    }
}

/// Thread between nail centres, mm, from nail 0 (where it is tied)
/// through the pattern. Wraps round the nails and the knot come on top.
pub fn thread_mm(board: &Board, pattern: &[u16]) -> f64 {
    let mut at = nail_mm(board, 0);
    pattern
        .iter()
        .map(|&n| {
            let p = nail_mm(board, n);
            let d = (p[0] - at[0]).hypot(p[1] - at[1]);
            at = p;
            d
        })
        .sum()
}

/// Machine time, s, of drilling and of winding the job whose files are
/// `param` and `poradi`, as the firmware runs it: its own job state
/// machine, planner and trapezoids (`taut_logic::stringart::estimate`).
pub fn machine_seconds(param: &[u8], poradi: &[u8]) -> Result<(f64, f64), String> {
    let e = estimate::card(|f| match f {
        FileName::Param => Some(param),
        FileName::Machine => None,
        FileName::Poradi => Some(poradi),
    })
    .map_err(|e| format!("the job cannot be timed: {e:?}"))?;
    Ok((e.firmware.drilling_s, e.firmware.winding_s))
}

#[cfg(test)]
mod tests {
    use super::*;

    const SPEC: Spec = Spec {
        shape: 0,
        nails: 250,
        radius_um: 402_000,
    };

    #[test]
    fn the_files_read_back_through_the_firmware() {
        assert_eq!(
            SPEC.param_txt(),
            "tvar = 0\npocet_hrebiku = 250\npolomer_matrice = 40.2\n"
        );
        let pattern: Vec<u16> = (0..45).map(|k| (k * 37 % 250) as u16).collect();
        let text = poradi_txt(&pattern);
        assert!(text.starts_with("45,\n0,37,74,"));
        assert_eq!(
            check(SPEC.param_txt().as_bytes(), text.as_bytes()),
            Ok(pattern)
        );
        let bad = check(SPEC.param_txt().as_bytes(), b"2,4,250\n").unwrap_err();
        assert_eq!(bad, "poradi.txt:1:5: nail 250 out of range (nails: 250)");
    }

    #[test]
    fn impossible_boards_get_the_firmwares_words() {
        let spec = |shape, nails, radius_um| Spec {
            shape,
            nails,
            radius_um,
        };
        assert_eq!(
            spec(2, 250, 402_000).board().unwrap_err(),
            "param.txt:1:8: expected 0 or 3 to 1000"
        );
        assert_eq!(
            spec(0, 2, 402_000).board().unwrap_err(),
            "param.txt:2:17: expected 3 to 10000"
        );
        assert_eq!(
            spec(0, 10_001, 402_000).board().unwrap_err(),
            "param.txt:2:17: expected 3 to 10000"
        );
        assert_eq!(
            spec(4, 50, 40_000).board().unwrap_err(),
            "param.txt:3:19: expected more than 4.3284 cm"
        );
        assert_eq!(
            spec(0, 50, 352_500).param_txt().lines().last(),
            Some("polomer_matrice = 35.25")
        );
        assert!(spec(1000, 3, 10_000_000).board().is_ok());
        // What the firmware's blended winder refuses: 0.25 mm between nails.
        assert_eq!(
            spec(0, 10_000, 402_000).board().unwrap_err(),
            "nails 0 and 1 stand too close for the needle to pass between them"
        );
        assert!(spec(0, 600, 402_000).board().is_ok());
    }

    #[test]
    fn thread_and_time_of_a_small_job() {
        let board = Spec {
            shape: 0,
            nails: 4,
            radius_um: 115_000,
        }
        .board()
        .unwrap();
        // Nail 0 → 2 → 1: a diameter (200 mm) and a side (100·√2).
        let mm = thread_mm(&board, &[2, 1]);
        assert!((mm - 200.0 - 100.0 * 2f64.sqrt()).abs() < 0.01, "{mm}");
        let spec = Spec {
            shape: 0,
            nails: 4,
            radius_um: 115_000,
        };
        let time =
            |p: &[u16]| machine_seconds(spec.param_txt().as_bytes(), poradi_txt(p).as_bytes());
        let (drill, wind) = time(&[2, 1]).unwrap();
        assert!(drill > 4.0 * 2.0 && wind > 2.0 * 4.0, "{drill} {wind}");
        let (_, more) = time(&[2, 1, 3, 1]).unwrap();
        assert!(more > wind);
    }
}
