//! The operator's event log as each part of the host keeps it: the latest
//! [`EventLog::CAPACITY`] events, oldest first, the oldest tenth dropped (and counted) when
//! full. A live session runs for days and a flapping sensor or link makes an event a
//! scan; the log must not grow with it.

/// A bounded list of events, oldest first.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EventLog {
    events: Vec<String>,
    dropped: u64,
}

impl EventLog {
    /// Events kept.
    pub const CAPACITY: usize = 1_000;

    /// Adds an event, dropping the oldest tenth first when the log is full.
    pub fn push(&mut self, event: String) {
        if self.events.len() >= Self::CAPACITY {
            let n = Self::CAPACITY / 10;
            self.events.drain(..n);
            self.dropped += n as u64;
        }
        self.events.push(event);
    }

    /// The events kept, oldest first.
    pub fn as_slice(&self) -> &[String] {
        &self.events
    }

    /// Events dropped to keep the log bounded.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// The events kept, oldest first, after a line saying how many older ones were
    /// dropped (when any were), as the log prints them; `what` names the log's part.
    pub fn lines(&self, what: &str) -> Vec<String> {
        let mut lines = Vec::with_capacity(self.events.len() + 1);
        if self.dropped > 0 {
            lines.push(format!("{} older {what} events not kept", self.dropped));
        }
        lines.extend(self.events.iter().cloned());
        lines
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flood_of_events_keeps_the_latest_and_counts_the_rest() {
        let mut log = EventLog::default();
        for i in 0..10_000 {
            log.push(format!("event {i}"));
        }
        assert!(log.as_slice().len() <= EventLog::CAPACITY);
        assert_eq!(
            log.as_slice().last().map(String::as_str),
            Some("event 9999")
        );
        assert_eq!(log.dropped() + log.as_slice().len() as u64, 10_000);
        let lines = log.lines("own-ship");
        assert_eq!(
            lines[0],
            format!("{} older own-ship events not kept", log.dropped())
        );
        assert_eq!(lines.len(), log.as_slice().len() + 1);
    }

    #[test]
    fn a_short_log_is_printed_as_it_is() {
        let mut log = EventLog::default();
        log.push("a".into());
        log.push("b".into());
        assert_eq!(log.lines("link"), ["a", "b"]);
        assert_eq!(log.dropped(), 0);
    }
}
