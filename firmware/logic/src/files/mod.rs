//! The job files on the card, read by streaming parsers: fed in chunks of
//! any size as the card delivers them, O(1) memory, every error located.
//!
//! - `param.txt` ([`param`]): shape, nails, board radius.
//! - `poradi.txt` ([`poradi`]): the connection count, then the nail indices;
//!   validated in one pass, then streamed again while winding.
//! - `machine.txt` ([`machine`]): optional overrides of the machine settings.

pub mod check;
pub mod cursor;
pub mod error;
pub mod kv;
pub mod list;
pub mod machine;
pub mod param;
pub mod poradi;

pub use error::{FileError, FileName};
