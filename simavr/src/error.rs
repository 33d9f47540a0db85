//! Why a simulation could not be set up.

use std::fmt;
use std::path::PathBuf;

#[derive(Debug)]
pub enum Error {
    Io(PathBuf, std::io::Error),
    Elf(String),
    Simavr(String),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Io(path, e) => write!(f, "{}: {e}", path.display()),
            Error::Elf(msg) => write!(f, "bad firmware ELF: {msg}"),
            Error::Simavr(msg) => write!(f, "simavr: {msg}"),
        }
    }
}

impl std::error::Error for Error {}

pub type Result<T> = std::result::Result<T, Error>;
