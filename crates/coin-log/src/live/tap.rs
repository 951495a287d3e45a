//! The recorder's tap of `coin-log live`: channels, messages and the clock.

use super::LiveServer;
use crate::format::{Channel, Encoding, Topic};
use crate::record::{ChannelDeclaration, Tap};
use foxglove::{ChannelBuilder, RawChannel, Schema};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Longest sleep between two looks at the stop flag, so that Ctrl-C is prompt at any speed.
const STOP_POLL: Duration = Duration::from_millis(50);
/// How often the wait for a viewer looks for a subscription.
const WAIT_POLL: Duration = Duration::from_millis(20);
/// After the first subscription, time for the viewer to subscribe to the rest of what its panels show
/// (Foxglove subscribes panel by panel, within tens of milliseconds).
const SETTLE: Duration = Duration::from_millis(300);
/// A viewer connected for this long without subscribing to anything (a layout without panels) starts the
/// clock anyway.
const CONNECT_GRACE: Duration = Duration::from_secs(3);

/// How the run is paced.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pacing {
    speed: f64,
    /// Wait for a viewer before starting the clock.
    pub wait_for_viewer: bool,
}

impl Pacing {
    /// `speed` units of simulated time per second of wall time (1: real time); `None` unless finite and
    /// above 0.
    #[must_use]
    pub fn new(speed: f64, wait_for_viewer: bool) -> Option<Self> {
        (speed.is_finite() && speed > 0.0).then_some(Self {
            speed,
            wait_for_viewer,
        })
    }

    /// Simulated time units per wall second.
    #[must_use]
    pub fn speed(&self) -> f64 {
        self.speed
    }

    /// Wall time from the first sample to a sample `elapsed_ns` of log time later (saturating: a speed so
    /// low that the offset overflows waits until stopped).
    fn wall_offset(&self, elapsed_ns: u64) -> Duration {
        #[allow(clippy::cast_precision_loss)] // ns of log time: exact to 2^53 ns ≈ 104 days
        let seconds = elapsed_ns as f64 * 1e-9 / self.speed;
        Duration::try_from_secs_f64(seconds).unwrap_or(Duration::MAX)
    }
}

/// What the clock does, for the command line to tell the user.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LiveEvent {
    /// The first sample is served; the clock waits for a viewer.
    Waiting,
    /// The clock starts, with this many viewers connected.
    Started {
        /// Viewers connected when the clock started.
        viewers: usize,
    },
}

/// The tap: one raw channel per topic with the file's schema and encodings, each message logged with its
/// log time (latched, see [`super`]); the calling (simulation) thread sleeps before the first message of
/// each new log time until `start + (log time − first log time) / speed`, against the start instant so that
/// the pace never drifts. A simulation slower than the pace is never waited for; the lateness is kept
/// ([`Self::max_lag`]).
pub struct LiveTap<'a, F: FnMut(LiveEvent)> {
    server: &'a LiveServer,
    pacing: Pacing,
    stop: &'a AtomicBool,
    on_event: F,
    channels: Vec<Option<Arc<RawChannel>>>,
    /// (first log time, the current one).
    times: Option<(u64, u64)>,
    /// The wall instant of the first log time, once the clock runs.
    clock: Option<Instant>,
    max_lag: Duration,
    messages: u64,
    error: Option<String>,
}

impl<'a, F: FnMut(LiveEvent)> LiveTap<'a, F> {
    /// A tap serving on `server`, paced by `pacing`; stops waiting and sleeping once `stop` is raised;
    /// tells `on_event` when it waits for a viewer and when the clock starts.
    pub fn new(server: &'a LiveServer, pacing: Pacing, stop: &'a AtomicBool, on_event: F) -> Self {
        Self {
            server,
            pacing,
            stop,
            on_event,
            channels: vec![None; Topic::COUNT],
            times: None,
            clock: None,
            max_lag: Duration::ZERO,
            messages: 0,
            error: None,
        }
    }

    /// Messages served.
    #[must_use]
    pub fn messages(&self) -> u64 {
        self.messages
    }

    /// How far behind the pace a sample was served at worst (the simulation or the machine was slower than
    /// `speed`).
    #[must_use]
    pub fn max_lag(&self) -> Duration {
        self.max_lag
    }

    /// Wall time since the clock started (zero if it never did).
    #[must_use]
    pub fn elapsed(&self) -> Duration {
        self.clock.map_or(Duration::ZERO, |c| c.elapsed())
    }

    /// The first topic that could not be served, and why.
    #[must_use]
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// The first message of a new log time: the first sample is served at once; at the second, once the
    /// first sample's channels are all advertised, the clock starts (after a viewer subscribed, when asked);
    /// every later one waits for its instant.
    fn new_time(&mut self, log_time: u64) {
        let first = match self.times {
            None => {
                self.times = Some((log_time, log_time));
                self.server.handle.broadcast_time(log_time);
                return;
            }
            Some((first, _)) => first,
        };
        self.times = Some((first, log_time));
        let start = match self.clock {
            Some(start) => start,
            None => self.start_clock(),
        };
        let deadline = start.checked_add(self.pacing.wall_offset(log_time.saturating_sub(first)));
        self.sleep_until(deadline);
        self.server.handle.broadcast_time(log_time);
    }

    fn start_clock(&mut self) -> Instant {
        if self.pacing.wait_for_viewer {
            (self.on_event)(LiveEvent::Waiting);
            self.wait_for_viewer();
        }
        if !self.stopped() {
            (self.on_event)(LiveEvent::Started {
                viewers: self.server.clients(),
            });
        }
        *self.clock.insert(Instant::now())
    }

    /// Until a viewer subscribed to a topic (then [`SETTLE`] more), or stayed connected [`CONNECT_GRACE`]
    /// without subscribing, or `stop`.
    fn wait_for_viewer(&self) {
        let mut connected_since: Option<Instant> = None;
        while !self.stopped() {
            if self.channels.iter().flatten().any(|c| c.has_sinks()) {
                std::thread::sleep(SETTLE);
                return;
            }
            if self.server.clients() > 0 {
                if connected_since.get_or_insert_with(Instant::now).elapsed() > CONNECT_GRACE {
                    return;
                }
            } else {
                connected_since = None;
            }
            std::thread::sleep(WAIT_POLL);
        }
    }

    /// Sleeps until `deadline` (`None`: beyond any instant) in steps short enough to notice `stop`.
    fn sleep_until(&mut self, deadline: Option<Instant>) {
        loop {
            if self.stopped() {
                return;
            }
            let now = Instant::now();
            match deadline {
                Some(d) if now >= d => {
                    self.max_lag = self.max_lag.max(now - d);
                    return;
                }
                Some(d) => std::thread::sleep((d - now).min(STOP_POLL)),
                None => std::thread::sleep(STOP_POLL),
            }
        }
    }
}

impl<F: FnMut(LiveEvent)> LiveTap<'_, F> {
    /// Creates the channel of every topic a recording of `channels` can write, in `encoding`, before the
    /// run. The Foxglove server advertises a channel before it accepts subscriptions to it: a viewer that
    /// subscribes at once to a channel created while it is connected can be told "Unknown channel ID"
    /// and never get that topic (seen in about one loopback test run in five). Channels made before the
    /// URL is announced are in every viewer's first advertisement.
    pub fn announce_topics(&mut self, channels: &[Channel], encoding: Encoding) {
        for topic in
            Topic::all().filter(|t| channels.contains(&t.channel()) && t.wire(encoding).is_some())
        {
            self.channel(&ChannelDeclaration::new(topic, encoding));
        }
    }
}

impl<F: FnMut(LiveEvent)> Tap for LiveTap<'_, F> {
    fn channel(&mut self, info: &ChannelDeclaration) {
        if self.channels[info.topic.index()].is_some() {
            return;
        }
        let built = ChannelBuilder::new(info.topic.name())
            .message_encoding(info.message_encoding)
            .schema(Schema::new(
                info.schema_name,
                info.schema_encoding,
                info.schema.to_vec(),
            ))
            .context(&self.server.context)
            .build_raw();
        match built {
            Ok(channel) => {
                self.server.latch.add(channel.clone());
                self.channels[info.topic.index()] = Some(channel);
            }
            Err(e) => {
                self.error
                    .get_or_insert_with(|| format!("topic {}: {e}", info.topic));
            }
        }
    }

    fn message(&mut self, topic: Topic, log_time: u64, data: &[u8]) {
        if self.times.map(|(_, current)| current) != Some(log_time) {
            self.new_time(log_time);
        }
        if let Some(channel) = &self.channels[topic.index()] {
            self.server.latch.log(channel, log_time, data);
            self.messages += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Pacing;
    use std::time::Duration;

    #[test]
    fn speed_must_be_finite_and_positive() {
        for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, -0.0] {
            assert!(Pacing::new(bad, true).is_none(), "speed {bad} accepted");
        }
        assert!(Pacing::new(1e-6, false).is_some());
    }

    /// The wall offset is log time / speed: 1 s of log time at speed 4 is 0.25 s (exact in binary), and an
    /// offset too long for a Duration saturates instead of panicking.
    #[test]
    fn wall_offset_divides_log_time_by_speed() {
        let p = Pacing::new(4.0, false).unwrap_or_else(|| panic!("speed 4"));
        assert_eq!(p.wall_offset(1_000_000_000), Duration::from_millis(250));
        let slow = Pacing::new(1e-300, false).unwrap_or_else(|| panic!("speed 1e-300"));
        assert_eq!(slow.wall_offset(u64::MAX), Duration::MAX);
    }
}
