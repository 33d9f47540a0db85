//! The argument types the subcommands share: the machine names, `X,Y`
//! pairs and numbers above 0.

use clap::ValueEnum;
use taut_logic::machine::Machine;

/// The plotters and the arm (`$machine=` names).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plotter {
    Flatbed,
    Drum,
    Whiteboard,
    Scara,
}

impl From<Plotter> for Machine {
    fn from(p: Plotter) -> Machine {
        match p {
            Plotter::Flatbed => Machine::Flatbed,
            Plotter::Drum => Machine::Drum,
            Plotter::Whiteboard => Machine::Whiteboard,
            Plotter::Scara => Machine::Scara,
        }
    }
}

/// Every machine, for `preview`.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum AnyMachine {
    Flatbed,
    Drum,
    Whiteboard,
    Scara,
    #[value(name = "string_art")]
    StringArt,
}

impl From<AnyMachine> for Machine {
    fn from(p: AnyMachine) -> Machine {
        match p {
            AnyMachine::Flatbed => Machine::Flatbed,
            AnyMachine::Drum => Machine::Drum,
            AnyMachine::Whiteboard => Machine::Whiteboard,
            AnyMachine::Scara => Machine::Scara,
            AnyMachine::StringArt => Machine::StringArt,
        }
    }
}

/// `X,Y`: two numbers.
pub fn pair(v: &str) -> Result<[f64; 2], String> {
    let bad = || format!("{v:?}: expected two numbers, X,Y");
    let (a, b) = v.split_once(',').ok_or_else(bad)?;
    Ok([
        a.trim().parse().map_err(|_| bad())?,
        b.trim().parse().map_err(|_| bad())?,
    ])
}

/// A number above 0.
pub fn positive(v: &str) -> Result<f64, String> {
    match v.parse::<f64>() {
        Ok(x) if x > 0.0 && x.is_finite() => Ok(x),
        Ok(_) => Err(format!("{v}: must be above 0")),
        Err(_) => Err(format!("{v}: not a number")),
    }
}
