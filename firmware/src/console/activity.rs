//! What the console is doing (for the status report), and who may move
//! the machine.

use super::{Console, Sleep};

/// What the console is doing, for the status report.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Activity {
    /// Reading and carrying out lines.
    Lines,
    Homing,
    Jogging,
    /// `$C`: checking lines without moving.
    Checking,
    /// `$SLP`: the drivers off until a reset.
    Sleeping,
}

/// Who may move the machine now.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Owner {
    Console,
    /// A string-art job is drilling or winding (or paused in it).
    Job,
}

impl Console {
    /// What the console is doing.
    pub fn activity(&self) -> Activity {
        match self.homing {
            _ if self.sleep != Sleep::Awake => Activity::Sleeping,
            Some(_) => Activity::Homing,
            _ if self.checking => Activity::Checking,
            _ if self.jogging => Activity::Jogging,
            _ => Activity::Lines,
        }
    }
}
