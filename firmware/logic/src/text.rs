//! What the machine's text inputs share — the job files on the card, the
//! `machine.txt` overrides and the `$` settings: numbers parsed straight into
//! integers and fixed point, and what can be wrong with a value.

pub mod error;
pub mod num;

pub use error::ErrorKind;
