//! How full a queue between tasks got and how often a sender was turned
//! away (the firmware's rings, `rt::Ring`, keep one each).

/// One queue's counters, read out by the `$Q` console report and logged at
/// the end of a job. Counters saturate rather than wrap.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QueueStats {
    /// Messages accepted.
    pub sent: u32,
    /// Sends refused because the queue was full (back-pressure events).
    pub refused: u32,
    /// Largest length seen right after a send (a ring holds at most 255:
    /// a byte, a byte of RAM less for each of the firmware's queues).
    pub high_water: u8,
}

impl QueueStats {
    pub const fn new() -> Self {
        QueueStats {
            sent: 0,
            refused: 0,
            high_water: 0,
        }
    }

    /// Records an accepted message; `len_after` is the queue length with it.
    pub fn on_send(&mut self, len_after: usize) {
        self.sent = self.sent.saturating_add(1);
        let len = u8::try_from(len_after).unwrap_or(u8::MAX);
        if len > self.high_water {
            self.high_water = len;
        }
    }

    pub fn on_refused(&mut self) {
        self.refused = self.refused.saturating_add(1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_sends_and_refusals_and_keeps_the_peak() {
        let mut s = QueueStats::new();
        s.on_send(1);
        s.on_send(2);
        s.on_refused();
        s.on_send(1);
        assert_eq!(
            s,
            QueueStats {
                sent: 3,
                refused: 1,
                high_water: 2
            }
        );
    }

    #[test]
    fn counters_saturate() {
        let mut s = QueueStats {
            sent: u32::MAX,
            refused: u32::MAX,
            high_water: 0,
        };
        s.on_send(70_000);
        s.on_refused();
        assert_eq!(s.sent, u32::MAX);
        assert_eq!(s.refused, u32::MAX);
        assert_eq!(s.high_water, u8::MAX);
    }
}
