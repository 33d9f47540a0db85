//! Message queues between tasks, measured: every queue knows how full it
//! got and how often a sender was turned away.

use heapless::spsc::Queue;

/// One queue's counters, read out by the `$Q` console report and logged at
/// the end of a job. Counters saturate rather than wrap.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QueueStats {
    /// Messages accepted.
    pub sent: u32,
    /// Sends refused because the queue was full (back-pressure events).
    pub refused: u32,
    /// Largest length seen right after a send.
    pub high_water: u16,
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
        let len = u16::try_from(len_after).unwrap_or(u16::MAX);
        if len > self.high_water {
            self.high_water = len;
        }
    }

    pub fn on_refused(&mut self) {
        self.refused = self.refused.saturating_add(1);
    }
}

/// A fixed-capacity message queue that counts what it refuses.
///
/// Holds `N - 1` messages (heapless 0.9's `spsc::Queue<T, N>` keeps one
/// slot empty to tell full from empty). The firmware shares it between an
/// interrupt and a task inside a critical section, so both ends go through
/// `&mut self`.
pub struct Channel<T, const N: usize> {
    queue: Queue<T, N>,
    stats: QueueStats,
}

impl<T, const N: usize> Channel<T, N> {
    pub const fn new() -> Self {
        Channel {
            queue: Queue::new(),
            stats: QueueStats::new(),
        }
    }

    /// Enqueues `msg`, or hands it back when the queue is full: the sender
    /// keeps it and retries later (back-pressure, never a silent drop).
    pub fn send(&mut self, msg: T) -> Result<(), T> {
        match self.queue.enqueue(msg) {
            Ok(()) => {
                self.stats.on_send(self.queue.len());
                Ok(())
            }
            Err(msg) => {
                self.stats.on_refused();
                Err(msg)
            }
        }
    }

    pub fn recv(&mut self) -> Option<T> {
        self.queue.dequeue()
    }

    pub fn len(&self) -> usize {
        self.queue.len()
    }

    pub fn is_empty(&self) -> bool {
        self.queue.is_empty()
    }

    /// Messages it can hold: `N - 1`.
    pub const fn capacity(&self) -> usize {
        N - 1
    }

    pub fn stats(&self) -> QueueStats {
        self.stats
    }
}

impl<T, const N: usize> Default for Channel<T, N> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn holds_n_minus_one_and_returns_the_refused_message() {
        let mut c: Channel<u8, 4> = Channel::new();
        assert_eq!(c.capacity(), 3);
        for m in 1..=3 {
            assert_eq!(c.send(m), Ok(()));
        }
        assert_eq!(c.send(42), Err(42));
        assert_eq!(c.stats().refused, 1);
        assert_eq!(c.len(), 3);
        assert_eq!(c.recv(), Some(1), "FIFO, nothing overwritten");
        assert_eq!(c.send(4), Ok(()));
        assert_eq!(c.send(43), Err(43));
        let rest: std::vec::Vec<_> = core::iter::from_fn(|| c.recv()).collect();
        assert_eq!(rest, [2, 3, 4]);
        assert!(c.is_empty());
        assert_eq!(
            c.stats(),
            QueueStats {
                sent: 4,
                refused: 2,
                high_water: 3
            }
        );
    }

    #[test]
    fn high_water_keeps_the_peak() {
        let mut c: Channel<u16, 8> = Channel::new();
        c.send(1).unwrap();
        c.send(2).unwrap();
        c.recv();
        c.recv();
        c.send(3).unwrap();
        assert_eq!(c.stats().high_water, 2);
        assert_eq!(c.stats().refused, 0);
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
        assert_eq!(s.high_water, u16::MAX);
    }

    #[test]
    fn const_constructible_and_send_for_a_static_mutex() {
        // The firmware's `static Mutex<RefCell<Channel>>` needs both.
        fn is_send<S: Send>(_: &S) {}
        let c: Channel<u8, 4> = const { Channel::new() };
        is_send(&c);
        assert!(c.is_empty());
        assert_eq!(c.stats(), QueueStats::new());
    }
}
