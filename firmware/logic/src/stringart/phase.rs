//! The two phases of the job that move the machine: shared by its events,
//! its progress lines, its batches of steps and its checkpoint.

/// The two phases that move the machine.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    Drilling,
    Winding,
}

impl Phase {
    /// Progress lines start with this: `drill 12/24`, `wind 1234/3000`.
    pub const fn name(self) -> &'static str {
        match self {
            Phase::Drilling => "drill",
            Phase::Winding => "wind",
        }
    }
}
