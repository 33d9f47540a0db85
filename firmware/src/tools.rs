//! The operator's tools on the console (`$wrap_test=<nail>`,
//! `$wrap_step=1`, `$wrap_jump=<k>`, `$drift=<nail>`;
//! `taut_logic::stringart::job::tools`): the console passes them to the
//! job, which refuses them while it moves and logs what they did.

use crate::queues::{Control, TellJob};
use taut_logic::stringart::job::tools;

/// `$key=…` names a tool, not a setting.
pub fn is_tool(key: &str) -> bool {
    tools::parse(key, "0").is_some()
}

/// Hands the tool to the job through the console's end of its queue;
/// `Err(column)` for a bad value, or when the job's queue is full (the
/// job is far behind: try again).
pub fn send(job: &TellJob, key: &str, value: &str) -> Result<(), u8> {
    let at = (key.len() + 3).min(u8::MAX as usize) as u8;
    match tools::parse(key, value) {
        Some(Ok(t)) => job.push(Control::Tool(t)).map_err(|_| 0),
        _ => Err(at),
    }
}
